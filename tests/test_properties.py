"""Property-based test over the parameter space: whatever the inputs in the
ranges users may choose, the library either refuses them with one ParameterError, or
builds bricks that do not overlap and weigh what their volumes say, and solves an
equilibrium that holds.

Hypothesis draws the parameters (derandomized: the same examples on every run). Models
are built whatever their size; interfaces and the equilibrium are solved for those up to
:data:`SOLVE_LIMIT` bricks, so the test stays within a minute.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from masonry.blocks import HEX_FACES
from masonry.rbe.boundary import analysis_model
from masonry.tolerances import G
from masonry.interfaces import candidate_pairs
from masonry.params import ParameterError, Params, validate
from masonry.scenes import build
from masonry.rbe.solve import ACCURACY, RBEProblem
from masonry.tolerances import Tolerances

SOLVE_LIMIT = 400
"""Largest model (bricks) whose interfaces and equilibrium each example solves."""

SAMPLE_PAIRS = 20_000
"""Largest number of neighbouring brick pairs tested for overlap per example."""

# the 12 edges of a hexahedron, corner index ix + 2 iy + 4 iz
EDGES = np.array([(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7),
                  (0, 4), (1, 5), (2, 6), (3, 7)])
# the 6 tetrahedra of a hexahedron around its diagonal 0-7 (exact for planar faces)
TETRAHEDRA = np.array([(0, 1, 3, 7), (0, 3, 2, 7), (0, 2, 6, 7), (0, 6, 4, 7),
                       (0, 4, 5, 7), (0, 5, 1, 7)])


def log_uniform(low, high):
    return st.floats(np.log10(low), np.log10(high)).map(lambda e: float(10.0**e))


def hexahedron_volumes(corners):
    """(B,) volumes from (B, 8, 3) corners: a formula independent of the library's."""
    a, b, c, d = (corners[:, TETRAHEDRA[:, k]] for k in range(4))
    signed = np.einsum("btk,btk->bt", b - a, np.cross(c - a, d - a)) / 6.0
    return np.abs(signed).sum(axis=1)


def deepest_overlap(corners, pairs):
    """Largest penetration of two convex hexahedra over ``pairs``, by the separating axis
    theorem: the axes are both bodies' face normals and the cross products of their
    edges; two bodies overlap by the least overlap of their projections."""
    worst = -np.inf
    for start in range(0, len(pairs), 2000):
        i, j = pairs[start:start + 2000].T
        a, b = corners[i], corners[j]
        edge_a = a[:, EDGES[:, 1]] - a[:, EDGES[:, 0]]
        edge_b = b[:, EDGES[:, 1]] - b[:, EDGES[:, 0]]
        normals = [np.cross(body[:, f[1]] - body[:, f[0]], body[:, f[3]] - body[:, f[0]])
                   for body in (a, b) for f in HEX_FACES]
        crosses = np.cross(edge_a[:, :, None, :], edge_b[:, None, :, :]).reshape(len(i), -1, 3)
        axes = np.concatenate([np.stack(normals, axis=1), crosses], axis=1)
        length = np.linalg.norm(axes, axis=2, keepdims=True)
        usable = length[..., 0] > 1e-9 * np.linalg.norm(edge_a, axis=2).max(axis=1)[:, None] ** 2
        axes = axes / np.where(length > 0, length, 1.0)
        pa, pb = np.einsum("pvk,pak->pva", a, axes), np.einsum("pvk,pak->pva", b, axes)
        overlap = np.minimum(pa.max(1), pb.max(1)) - np.maximum(pa.min(1), pb.min(1))
        overlap = np.where(usable, overlap, np.inf)
        worst = max(worst, float(overlap.min(axis=1).max()))
    return worst


@settings(max_examples=40, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(stretch=st.floats(0.3, 4.0), n=st.integers(3, 32), r=st.integers(0, 4),
       p=st.integers(1, 20), cut=st.floats(0.0, 0.9), unit=log_uniform(1e-3, 1e2),
       mu=st.floats(0.05, 5.0), density=log_uniform(2.0, 2.0e6),
       boundary=st.sampled_from(["free", "cyclic"]))
@pytest.mark.slow
def test_any_parameters(stretch, n, r, p, cut, unit, mu, density, boundary):
    try:
        params = validate(Params.of(stretch=stretch, n=n, r=r, p=p, cut=cut, unit=unit, mu=mu,
                                 density=density, boundary=boundary))
        scene = build(params)
    except ParameterError as error:
        assert error.name in str(error) and "expected" in str(error)
        event(f"refused: {error.name}")
        return
    blocks = scene.blocks
    corners = blocks.vertices.reshape(-1, 8, 3)
    free = ~blocks.block_is_support

    # every brick weighs what its volume says, and the model what its bricks weigh
    volume = hexahedron_volumes(corners)
    np.testing.assert_allclose(blocks.block_volume, volume, rtol=1e-9)
    assert np.all(volume[free] > 0)

    # no two bricks overlap (touching faces project onto intervals that only meet)
    tol = Tolerances.for_points(blocks.vertices)
    pairs = candidate_pairs(blocks, tol)
    assert len(pairs) >= free.sum() - 1  # neighbours exist and are tested
    if len(pairs) > SAMPLE_PAIRS:
        pairs = pairs[np.random.default_rng(0).choice(len(pairs), SAMPLE_PAIRS, replace=False)]
    assert deepest_overlap(corners, pairs) <= 1e-7 * params.geometry.unit

    if free.sum() > SOLVE_LIMIT:
        event("built, too large to solve here")
        return
    event("built and solved")
    model = analysis_model(scene, params.analysis.boundary)
    problem = RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                         side_rotation=model.side_rotation)
    result = problem.solve(mu=mu, density=density)
    assert result.weight_N == pytest.approx(density * G * volume[free].sum(), rel=1e-9)
    # every solved result satisfies equilibrium, recomputed from the forces
    assert result.x is not None, result.attempts
    system = problem.system.with_material(mu=mu, density=density)
    wrench = system.contact_wrench(result.x) + system.external_wrench()
    scale = np.abs(system.external_wrench()).max()
    limit = ACCURACY[result.accuracy].residual
    assert np.abs(wrench[:, :3]).max() <= limit * scale
    assert np.abs(wrench[:, 3:]).max() <= limit * scale * system.length_ref
    assert result.friction_violation <= limit
    # Coulomb's cone and the signs, vertex by vertex, in newtons
    slack = limit * system.weight_ref
    c, t, f1, f2 = (result.layout.component(result.x, k) for k in ("c", "t", "f1", "f2"))
    reach = mu * (c - (t if result.friction == "net" else 0.0)) + slack
    assert result.friction_model == "circle"
    assert np.all(c >= -slack) and np.all(t >= -slack)
    assert np.all(np.hypot(f1, f2) <= reach)
