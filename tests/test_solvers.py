"""QP backends and accuracy presets (docs/model.md 6.5, 6.6): every path gives the same answer.

The direct paths (OSQP, Clarabel on sparse matrices), the cvxpy reference path and the
semismooth Newton method must agree; the presets must meet their residuals; reuse
between friction models and friction coefficients must not change results. Speed is
measured by ``masonry bench``, never here.
"""

import dataclasses
import functools
import logging

import numpy as np
import pytest

import scipy.linalg
import scipy.sparse as sp

from masonry import forking
from masonry.export.csv import header
from masonry.export.summaries import objective_text
from masonry_benchmarks.bench import (COLUMNS, bench, frontier_png, ratios, ratios_markdown,
                                   table_csv, table_markdown)
from masonry.friction import FrictionCone
from masonry.rbe.equilibrium import assemble
from masonry.pipeline import build_model
from masonry.errors import ParameterError
from masonry.params import Params, from_preset, structure_id
from masonry.rbe import cores as cores_module
from masonry.rbe import solve as solve_module
from masonry.rbe.lp_check import lp_feasible
from masonry.rbe.solve import ACCURACY, LOAD_PATH, RBEProblem, solve_rbe
from masonry.rbe.cores import solver_threads
from masonry.rbe.solvers import BACKENDS, COLLAPSE, RBE, backend, names
from masonry.rbe.solvers import cholesky, net_feasibility, ordering
from masonry.rbe.solvers import direct_clarabel as clarabel_module
from masonry.rbe.solvers import interior as interior_module
from masonry.rbe.solvers.base import Outcome
from masonry.rbe.solvers.cholesky import BlockCholesky
from masonry.rbe.solvers.embedded import Embedded
from masonry.rbe.solvers.highs import highs_lp
from masonry.rbe.solvers.interior import scaling_of, vertex_cones, vertex_inverse
from masonry.rbe.solvers.net_feasibility import decide
from masonry.rbe.solvers.newton import COMPONENTS, NewtonOptions, NewtonSystem
from masonry.rbe.solvers.standard_form import standard_form
from masonry.tolerances import Tolerances
from masonry_cli.main import main


@functools.lru_cache(maxsize=None)
def model(preset, **overrides):
    return build_model(from_preset(preset, **overrides))[1]


def small(boundary):
    """Preset 3 with p = 5: 135 bricks, a free section (infeasible) or cyclic (feasible)."""
    return model("3", p=5, boundary=boundary)


def problem(m):
    return RBEProblem(m.blocks, m.interfaces, side_block=m.side_block,
                      side_rotation=m.side_rotation)


def scale(result):
    return np.abs(result.x).max()


# ---------------------------------------------------------------------- registries
def test_the_registry_declares_problems_and_friction_models():
    circle, pyramid = FrictionCone.parse("circle"), FrictionCone.parse("polygon:16")
    assert names(COLLAPSE) == ("interior", "clarabel", "highs-ipm", "highs-crossover",
                               "highs-simplex")
    assert names(COLLAPSE, circle) == ("interior", "clarabel")
    assert set(names(RBE, pyramid)) == set(names(RBE))
    assert set(names(RBE)) - set(names(RBE, circle)) == {"osqp", "osqp-cvxpy"}
    assert set(names()) == set(names(RBE)) | set(names(COLLAPSE))
    with pytest.raises(ValueError, match="linear constraints only"):
        backend("osqp", RBE, circle)
    with pytest.raises(ValueError, match="unknown solver 'highs-simplex'"):
        backend("highs-simplex", RBE)  # solves the collapse program, not the QP
    with pytest.raises(ValueError, match="unknown collapse method 'newton'"):
        backend("newton", COLLAPSE)


@pytest.mark.parametrize("name, cone", [("newton", "circle"), ("osqp", "polygon:16"),
                                        ("clarabel-cvxpy", "circle")])
def test_every_outcome_carries_residuals_recomputed_from_the_matrices(name, cone):
    system = problem(small("cyclic")).system.with_material(mu=0.7, density=2000.0,
                                                           cone=cone)
    outcome = BACKENDS[name].solve_rbe(system, "net", {}, {})
    x = outcome.x
    residual = (np.abs(system.A_eq @ x + system.f_ext).max()
                / np.abs(system.f_ext).max())
    # the same up to the rounding of the sums (a product in another order)
    assert outcome.residuals.equilibrium == pytest.approx(residual, abs=1e-12)
    c, t, f1, f2 = x.reshape(-1, 4).T
    excess = max(float(system.cone.excess(c - t, f1, f2, system.mu).max()),
                 float((system.lower - x).max()), 0.0)
    assert outcome.residuals.net_friction == pytest.approx(excess, abs=1e-15)
    assert outcome.residuals.equilibrium <= Tolerances().residual


def test_params_accuracy_validation_and_structure_id():
    assert Params.of().analysis.accuracy == "balanced"
    assert Params.of(fast=True).analysis.accuracy == "fast"  # docs/model.md 3, fast mode
    assert Params.of(fast=True, accuracy="accurate").analysis.accuracy == "accurate"
    assert structure_id(from_preset("1")) == "dome0_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1"
    assert structure_id(from_preset("1", accuracy="accurate")).endswith("_accurate")
    assert structure_id(from_preset("1", solver="osqp", friction_cone="polygon:16")).endswith(
        "_conepolygon16_osqp")
    assert structure_id(from_preset("1", friction_cone="square")).endswith("_conesquare")
    with pytest.raises(ParameterError, match="solver"):  # OSQP cannot state the cone
        from_preset("1", solver="osqp")
    with pytest.raises(ParameterError, match="friction_cone"):
        from_preset("1", solver="osqp", friction_cone="circle")
    with pytest.raises(ParameterError, match="friction_cone"):
        from_preset("1", friction_cone="polygon:4")
    # two inputs, two folders: 2011.8216 and 2011.8219 are both 2011.82 to six digits
    assert structure_id(from_preset("1", density=2011.8216)).endswith("_rho2011.8216")
    assert structure_id(from_preset("1", density=2011.8219)).endswith("_rho2011.8219")
    assert structure_id(from_preset("1", density=2500.0, mu=0.3)).endswith("_mu0.3_rho2500")
    with pytest.raises(ParameterError, match="accuracy"):
        from_preset("1", accuracy="exact")
    with pytest.raises(ParameterError, match="solver"):
        from_preset("1", solver="gurobi")


# ---------------------------------------------------------------------- kernels
@pytest.mark.parametrize("name", ["circle", "polygon:8", "polygon:16", "square"])
def test_friction_projection_is_the_nearest_point_and_its_jacobian_is_exact(name):
    cone = FrictionCone.parse(name)
    rng = np.random.default_rng(3)
    points = rng.normal(size=(4000, 3))
    for mu in (0.05, 0.7, 5.0):
        x, jacobian = cone.project(points, mu)
        # inside the model
        assert cone.excess(x[:, 0], x[:, 1], x[:, 2], mu).max() <= 1e-12
        # the projection onto a cone: x . (p - x) = 0 and p - x in the polar cone: for a
        # pyramid (p - x) . ray <= 0 for every edge ray; for the circle
        # mu ||(p - x)_f|| <= -(p - x)_c
        residual = points - x
        assert np.abs(np.einsum("ij,ij->i", x, residual)).max() < 1e-12
        if cone.is_polyhedral:
            assert np.all(residual @ cone.rays(mu) <= 1e-12)
        else:
            assert np.all(mu * np.hypot(residual[:, 1], residual[:, 2])
                          + residual[:, 0] <= 1e-12)
        # the Jacobian: exact for a pyramid's piecewise linear projection; for the
        # circle's, whose surface curves, to second order in the step
        step = rng.normal(size=points.shape) * 1e-7
        moved, _ = cone.project(points + step, mu)
        linear = np.einsum("vij,vj->vi", jacobian, step)
        tolerance = 1e-12 if cone.is_polyhedral else 1e-9
        assert np.abs(moved - x - linear).max() < tolerance


@pytest.mark.parametrize("name", ["circle", "polygon:8", "polygon:16", "square"])
def test_friction_models_carry_coulombs_capacity_within_their_bound(name):
    # the largest friction a model carries at c = 1 in each direction: within its stated
    # range of Coulomb's mu c, and the range is attained
    cone = FrictionCone.parse(name)
    mu = 0.6
    angles = np.linspace(0.0, 2 * np.pi, 3601)
    direction = np.column_stack([np.cos(angles), np.sin(angles)])
    if cone.is_polyhedral:
        # the largest s with s d . normal_k <= apothem for every face
        reach = direction @ cone.face_normals().T
        capacity = cone.apothem(mu) / reach.max(axis=1)
    else:
        capacity = np.full(len(angles), mu)
    least, most = cone.capacity_range
    assert capacity.min() == pytest.approx(least * mu, rel=1e-6)
    assert capacity.max() == pytest.approx(most * mu, rel=1e-6)
    assert cone.capacity_error == pytest.approx(max(1 - least, most - 1), rel=1e-12)
    expected = {"circle": 0.0, "polygon:8": 1 - np.cos(np.pi / 8),
                "polygon:16": 1 - np.cos(np.pi / 16), "square": np.sqrt(2) - 1}[name]
    assert cone.capacity_error == pytest.approx(expected, abs=1e-15)


def test_friction_model_names_are_parsed_and_refused():
    assert FrictionCone.parse("polygon:16").name == "polygon:16"
    assert FrictionCone.parse(" circle ").name == "circle"
    for bad in ("polygon:4", "polygon:", "polygon:1000", "cone", "square:4", 3):
        with pytest.raises(ValueError, match="circle, polygon:K"):
            FrictionCone.parse(bad)


def test_a_larger_graphs_factorization_serves_a_subgraph():
    # a graph's symbolic analysis, in a given order, factors the matrix of a subgraph
    # (the other nodes idle): the same solution as the subgraph's own dense solve
    rng = np.random.default_rng(3)
    n, bs = 40, 6
    edges = np.unique(np.sort(rng.integers(0, n, size=(100, 2)), axis=1), axis=0)
    edges = edges[edges[:, 0] != edges[:, 1]]
    order = rng.permutation(n)
    whole = BlockCholesky(n, edges, block_size=bs, ordering=order)
    assert whole.ordering == "given"  # then postordered: an equivalent order
    with pytest.raises(ValueError, match="permutation"):
        BlockCholesky(n, edges, block_size=bs, ordering=order[1:])
    nodes = np.sort(rng.choice(n, 25, replace=False))
    new = np.full(n, -1)
    new[nodes] = np.arange(len(nodes))
    inner = new[edges]
    inner = inner[(inner >= 0).all(axis=1)]
    sub = Embedded(whole, nodes)
    dense = np.zeros((bs * len(nodes),) * 2)
    values = np.zeros((len(whole.lower_rows), bs, bs))
    for i, j in inner:
        block = rng.normal(size=(bs, bs))
        stored = sub.block_index([i], [j])[0]
        values[stored] = block.T if sub.is_transposed([i], [j])[0] else block
        dense[bs * i:bs * i + bs, bs * j:bs * j + bs] = block
        dense[bs * j:bs * j + bs, bs * i:bs * i + bs] = block.T
    strength = np.abs(dense).sum(axis=1) + 1.0
    diagonal = sub.block_index(np.arange(len(nodes)), np.arange(len(nodes)))
    for i in range(len(nodes)):
        values[diagonal[i]] += np.diag(strength[bs * i:bs * i + bs])
    dense += np.diag(strength)
    rhs = rng.normal(size=bs * len(nodes))
    expected = scipy.linalg.solve(dense, rhs, assume_a="pos")
    np.testing.assert_allclose(sub.factor(values).solve(rhs), expected, rtol=0,
                               atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("ordering", ["amd", "metis"])
@pytest.mark.parametrize("parallel", [False, True])
def test_block_cholesky_solves_and_refuses_indefinite_matrices(monkeypatch, ordering, parallel):
    # parallel: subtrees on two threads whatever the size (the GIL-free kernels run at
    # the same time on different fronts of one buffer each)
    monkeypatch.setattr(cholesky, "PARALLEL_FLOPS", 0.0 if parallel else np.inf)
    rng = np.random.default_rng(0)
    n = 60
    edges = np.unique(np.sort(rng.integers(0, n, size=(150, 2)), axis=1), axis=0)
    edges = edges[edges[:, 0] != edges[:, 1]]
    sym = BlockCholesky(n, edges, block_size=6, ordering=ordering)
    assert sym.ordering == ordering
    if parallel:
        threads, top = sym._parallel_schedule(2)
        assert len(threads) == 2 and all(threads)
    dense = np.zeros((6 * n, 6 * n))
    values = np.empty((len(sym.lower_rows), 6, 6))
    for k, (i, j) in enumerate(zip(sym.lower_rows, sym.lower_cols)):
        block = rng.normal(size=(6, 6)) if i != j else np.zeros((6, 6))
        values[k] = block
        dense[6 * i:6 * i + 6, 6 * j:6 * j + 6] = block
        dense[6 * j:6 * j + 6, 6 * i:6 * i + 6] = block.T
    # diagonally dominant: positive definite
    strength = np.abs(dense).sum(axis=1) + 1.0
    diagonal = sym.block_index(np.arange(n), np.arange(n))
    for i in range(n):
        values[diagonal[i]] += np.diag(strength[6 * i:6 * i + 6])
    dense += np.diag(strength)
    rhs = rng.normal(size=(6 * n, 2))
    factor = sym.factor(values)
    x = factor.solve(rhs)
    np.testing.assert_allclose(dense @ x, rhs, rtol=0, atol=1e-10 * np.abs(rhs).max())
    expected = scipy.linalg.solve(dense, rhs, assume_a="pos")
    np.testing.assert_allclose(x, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    # one vector takes its own path (dtrsv)
    np.testing.assert_allclose(factor.solve(rhs[:, 1]), expected[:, 1], rtol=0,
                               atol=1e-12 * np.abs(expected).max())
    values[diagonal[0]] = -np.eye(6)
    with pytest.raises(np.linalg.LinAlgError):
        sym.factor(values)


def test_block_cholesky_orders_large_graphs_by_metis_when_it_is_installed(monkeypatch):
    # a 12 x 12 grid of blocks: 'auto' takes METIS from METIS_NODES nodes on, and AMD
    # without pymetis (Windows: no wheels); the two orderings differ on a grid
    edges = [(i, i + 1) for i in range(143) if (i + 1) % 12] + [(i, i + 12) for i in range(132)]
    orders = {}
    for nodes, metis, expected in ((144, True, "metis"), (145, True, "amd"), (144, False, "amd")):
        monkeypatch.setattr(cholesky, "METIS_NODES", nodes)
        if not metis:
            monkeypatch.setattr(ordering, "pymetis", None)
        sym = BlockCholesky(144, edges, block_size=1)
        assert sym.ordering == expected
        orders[expected] = sym.order
    assert not np.array_equal(orders["metis"], orders["amd"])
    with pytest.raises(ModuleNotFoundError, match="pymetis"):
        BlockCholesky(144, edges, block_size=1, ordering="metis")


def _dense_factor(factor, n_scalar):
    """The factor ``L`` of a :class:`BlockFactor` as a dense matrix (factor order)."""
    low = np.zeros((n_scalar, n_scalar))
    for (columns, rows), pivot, below in zip(factor.symbolic._solve_slices,
                                             factor._pivots, factor._below):
        if pivot is not None:  # else a batched leaf
            low[columns, columns] = np.tril(pivot)
        if below is not None:
            low[rows, columns] = below
    for group, (pivots, belows) in zip(factor.symbolic._leaf_groups, factor._leaves):
        for columns, rows, pivot, below in zip(group.columns, group.rows, pivots, belows):
            low[np.ix_(columns, columns)] = np.tril(pivot)
            low[np.ix_(rows, columns)] = below
    return low


def _random_spd_blocks(sym, rng, shift=1.0):
    """Random stored blocks of an SPD matrix on ``sym``'s pattern (diagonally dominant
    by ``shift`` times the largest absolute row sum), and the dense matrix."""
    n, bs = sym.n_nodes, sym.block_size
    values = rng.normal(size=(len(sym.lower_rows), bs, bs))
    dense = np.zeros((bs * n, bs * n))
    for k, (i, j) in enumerate(zip(sym.lower_rows, sym.lower_cols)):
        if i == j:
            values[k] = values[k] @ values[k].T
        dense[bs * i:bs * i + bs, bs * j:bs * j + bs] = values[k]
        dense[bs * j:bs * j + bs, bs * i:bs * i + bs] = values[k].T
    strength = shift * np.abs(dense).sum(axis=1).max()
    diagonal = sym.block_index(np.arange(n), np.arange(n))
    values[diagonal] += strength * np.eye(bs)
    dense += strength * np.eye(bs * n)
    return values, dense


@pytest.mark.parametrize("small_update, parallel, ordering",
                         [(0, False, "amd"), (10**9, False, "amd"), (0, True, "amd"),
                          (10**9, False, "metis"), (0, True, "metis")])
def test_block_cholesky_factor_equals_the_dense_cholesky(monkeypatch, small_update, parallel,
                                                         ordering):
    # the Cholesky factor of an SPD matrix is unique: every entry of the multifrontal
    # factor (assembly, extend-add of the children's updates, relaxed supernodes) must
    # equal LAPACK's dense factor of the same permuted matrix; small_update forces every
    # extend-add through the run-by-run path (0) or the flat-position path (huge);
    # parallel: subtrees on two threads whatever the size; both orderings
    monkeypatch.setattr(cholesky, "SMALL_UPDATE", small_update)
    monkeypatch.setattr(cholesky, "PARALLEL_FLOPS", 0.0 if parallel else np.inf)
    rng = np.random.default_rng(7)
    n, bs = 40, 3
    # a 2D grid graph with a few long-range edges: fronts with several children
    grid = [(i, i + 1) for i in range(n - 1) if (i + 1) % 8] + [(i, i + 8) for i in range(n - 8)]
    edges = np.array(grid + [(0, 37), (5, 30), (12, 39)])
    sym = BlockCholesky(n, edges, block_size=bs, ordering=ordering)
    assert any(len(children) > 1 for children in sym._children)
    if parallel:
        threads, top = sym._parallel_schedule(2)
        assert len(threads) == 2 and all(threads) and top
    values, dense = _random_spd_blocks(sym, rng)
    order = sym._scalar_order
    expected = scipy.linalg.cholesky(dense[np.ix_(order, order)], lower=True)
    factor = sym.factor(values)
    np.testing.assert_allclose(_dense_factor(factor, bs * n), expected, rtol=0,
                               atol=1e-12 * np.abs(expected).max())


def test_a_factorization_starts_threads_only_where_the_process_has_two_cores(
        monkeypatch, two_processes):
    # the same symbolic analysis factored on two cores, inside forking.on_one_core
    # (another process of the job on the other core: the caller's solver_threads
    # allows one), and on two again: the thread pool only on two, the factor the same
    monkeypatch.setattr(cholesky, "PARALLEL_FLOPS", 0.0)
    pools = []
    executor = cholesky.ThreadPoolExecutor
    monkeypatch.setattr(cholesky, "ThreadPoolExecutor",
                        lambda **kwargs: pools.append(kwargs) or executor(**kwargs))
    n, bs = 40, 3
    grid = [(i, i + 1) for i in range(n - 1) if (i + 1) % 8] + [(i, i + 8) for i in range(n - 8)]
    sym = BlockCholesky(n, np.array(grid), block_size=bs, ordering="amd")
    values, dense = _random_spd_blocks(sym, np.random.default_rng(5))
    factors = [_dense_factor(sym.factor(values), bs * n)]
    assert len(pools) == 1
    with forking.on_one_core(), solver_threads():
        factors.append(_dense_factor(sym.factor(values), bs * n))
    assert len(pools) == 1
    factors.append(_dense_factor(sym.factor(values), bs * n))
    assert len(pools) == 2
    np.testing.assert_array_equal(factors[0], factors[1])
    np.testing.assert_array_equal(factors[0], factors[2])


@pytest.mark.parametrize("parallel", [False, True])
def test_batched_leaves_factor_and_solve_as_the_dense_cholesky(monkeypatch, parallel):
    # leaves of one shape are factored and solved as one stack: on a 10 x 10 grid with
    # diagonals (AMD), every leaf batched, stacks of 1 to 3 leaves of 1, 2, 3 and 8
    # block columns; the factor, solves of one and of several right-hand sides against
    # scipy's dense results, and a leaf that is not positive definite must stop the
    # factorization
    monkeypatch.setattr(cholesky, "BATCH_LEAVES", 0)
    monkeypatch.setattr(cholesky, "PARALLEL_FLOPS", 0.0 if parallel else np.inf)
    n, bs = 100, 3
    grid = ([(i, i + 1) for i in range(n - 1) if (i + 1) % 10]
            + [(i, i + 10) for i in range(n - 10)]
            + [(i, i + 11) for i in range(n - 11) if (i + 1) % 10])
    sym = BlockCholesky(n, np.array(grid), block_size=bs, ordering="amd")
    shapes = [(group.k, len(group.supernodes)) for group in sym._leaf_groups]
    assert {k for k, _ in shapes} >= {3, 6, 9, 24} and max(g for _, g in shapes) >= 3
    assert sym._batched.sum() == sum(not children for children in sym._children)
    if parallel:  # the stacks first, then the other supernodes on two threads
        threads, top = sym._parallel_schedule(2)
        assert len(threads) == 2 and not any(sym._batched[s] for s in sum(threads, top))
    values, dense = _random_spd_blocks(sym, np.random.default_rng(3), shift=0.3)
    order = sym._scalar_order
    expected = scipy.linalg.cholesky(dense[np.ix_(order, order)], lower=True)
    factor = sym.factor(values)
    np.testing.assert_allclose(_dense_factor(factor, bs * n), expected, rtol=0,
                               atol=1e-12 * np.abs(expected).max())
    rhs = np.random.default_rng(4).normal(size=(bs * n, 3))
    solution = scipy.linalg.solve(dense, rhs, assume_a="pos")
    scale = np.abs(solution).max()
    np.testing.assert_allclose(factor.solve(rhs), solution, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(factor.solve(rhs[:, 2]), solution[:, 2], rtol=0,
                               atol=1e-12 * scale)
    leaf = sym.supernodes[sym._leaf_groups[-1].supernodes[-1]]
    node = sym.order[leaf.last]  # the leaf's last block column, in the caller's numbering
    values[sym.block_index(node, node)] = -np.eye(bs)
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        sym.factor(values)


@pytest.mark.parametrize("name", ["circle", "polygon:16", "square"])
@pytest.mark.parametrize("method", ["net", "plus"])
def test_interior_point_vertex_blocks_are_the_inverse(method, name):
    # D = (H + sum G^T W^-2 G)^-1 from the QR of the stacked rows, against the inverse
    # of the formed matrix, at scalings of random interior points
    components = COMPONENTS[method]
    rng = np.random.default_rng(5)
    cones = vertex_cones(components, FrictionCone.parse(name), 0.6)
    h = rng.uniform(0.5, 2.0, size=(200, len(components)))
    w_inverse = []
    stiffness = h[:, :, None] * np.eye(len(components))
    for vc in cones:
        s, z = (vc.cone.identity(200) * 2.0 + rng.uniform(-0.5, 0.5, (200, vc.cone.m))
                for _ in range(2))
        s, z = s * np.exp(rng.uniform(-3, 3, (200, 1))), z * np.exp(rng.uniform(-3, 3, (200, 1)))
        _, w = scaling_of(vc.cone, s, z)
        w_inverse.append(w)
        w2 = np.einsum("vk,vk->vk", w, w) if w.ndim == 2 else w @ w
        stiffness = stiffness + (np.einsum("ki,vk,kj->vij", vc.G, w2, vc.G) if w.ndim == 2
                                 else vc.G.T @ w2 @ vc.G)
    np.testing.assert_allclose(vertex_inverse(h, cones, w_inverse),
                               np.linalg.inv(stiffness), rtol=0, atol=1e-12)


@pytest.mark.slow
def test_newton_matrices_equal_the_sparse_products():
    """``A J A^T`` by interface (every vertex changed: the first matrix, a new one) and by
    vertex update (a third changed), against the dense product."""
    m = small("cyclic")
    system = assemble(m.blocks, m.interfaces, side_block=m.side_block,
                      side_rotation=m.side_rotation)
    assert len(np.unique(np.bincount(system.layout.vertex_interface))) > 1
    rng = np.random.default_rng(1)
    for method in ("net", "plus"):
        ns = NewtonSystem(system, method)
        first = rng.normal(size=(len(ns.coefficients), ns.width, ns.width))
        update = np.where(rng.random(len(first))[:, None, None] < 1 / 3,
                          rng.normal(size=first.shape), first)
        renewed = rng.normal(size=first.shape)
        for jacobian in (first, update, renewed):
            blocks = ns.newton_blocks(jacobian, 0.0)
            per_vertex = np.zeros((ns.A.shape[1],) * 2)
            for v, block in enumerate(jacobian):
                per_vertex[v * ns.width:(v + 1) * ns.width,
                           v * ns.width:(v + 1) * ns.width] = block
            full = ns.A.toarray() @ per_vertex @ ns.A.toarray().T
            sym = ns.symbolic
            for k, (i, j) in enumerate(zip(sym.lower_rows, sym.lower_cols)):
                np.testing.assert_allclose(blocks[k],
                                           full[6 * i:6 * i + 6, 6 * j:6 * j + 6],
                                           atol=1e-10 * np.abs(full).max())


def test_newton_columns_and_vertex_sums_are_the_equilibrium_matrix():
    """The Newton system's ``A`` and ``AT``, built from the vertex coefficients, are the
    columns of ``A_eq`` its model solves for, and ``times_A_eq`` sums ``A_eq x`` vertex by
    vertex; both against the sparse ``A_eq`` (cyclic: image sides routed onto the
    section's own blocks, two sides on one block included)."""
    rng = np.random.default_rng(2)
    for boundary in ("cyclic", "free"):
        m = small(boundary)
        system = assemble(m.blocks, m.interfaces, side_block=m.side_block,
                          side_rotation=m.side_rotation)
        dense = system.A_eq.toarray()
        for method in ("net", "plus"):
            ns = NewtonSystem(system, method)
            keep = (4 * np.arange(system.layout.n_vertices)[:, None]
                    + np.asarray(ns.components)).ravel()
            np.testing.assert_allclose(ns.A.toarray(), dense[:, keep], rtol=0,
                                       atol=1e-15)
            np.testing.assert_allclose(ns.AT.toarray(), dense[:, keep].T, rtol=0,
                                       atol=1e-15)
        x = rng.normal(size=system.layout.n_columns)
        np.testing.assert_allclose(system.times_A_eq(x), dense @ x, rtol=0,
                                   atol=1e-12 * np.abs(dense).sum(axis=1).max())


def _largest_difference(a, b) -> float:
    """The largest absolute entry of ``a - b``, two sparse matrices of one shape (kept
    sparse: the pyramid's friction rows of a small section are gigabytes dense)."""
    assert a.shape == b.shape
    difference = sp.csr_array(a - b)
    return float(abs(difference).max()) if difference.nnz else 0.0


@pytest.mark.parametrize("name", ["circle", "polygon:16", "square"])
def test_standard_form_is_the_equilibrium_system(name):
    m = small("free")
    system = assemble(m.blocks, m.interfaces, mu=0.45, cone=name)
    form = standard_form(system)
    for method in ("net", "plus"):
        rows = sp.csr_array(form.matrix(method, 0.45))
        n_eq, n_fr = form.n_eq, form.n_friction
        assert _largest_difference(rows[:n_eq], system.A_eq) == 0
        if system.cone.is_polyhedral:
            assert _largest_difference(rows[n_eq:n_eq + n_fr],
                                       system.A_fr[method]) <= 1e-15
        else:
            # -(mu (c - t), f1, f2) per vertex: the slack of the second-order cone
            x = np.random.default_rng(1).normal(size=system.layout.n_columns)
            c, t, f1, f2 = x.reshape(-1, 4).T
            load = c - t if method == "net" else c
            np.testing.assert_allclose(rows[n_eq:n_eq + n_fr] @ x,
                                       -np.column_stack([0.45 * load, f1, f2]).ravel(),
                                       rtol=0, atol=1e-14)
        tension = rows[n_eq + n_fr:]
        assert tension.sum() == system.layout.n_vertices
        np.testing.assert_array_equal(np.flatnonzero(tension.sum(axis=0)),
                                      system.layout.columns("t"))
    # one pattern for both models: solvers update values in place
    assert form.matrix("net", 0.3).nnz == form.matrix("plus", 0.7).nnz


# ---------------------------------------------------------------------- agreement
@functools.lru_cache(maxsize=None)
def solved(boundary, solver, accuracy="accurate", cone=None):
    return problem(small(boundary)).solve(solver=solver, accuracy=accuracy, lp_check=False,
                                          cone=cone)


@pytest.mark.parametrize("solver, cone", [
    ("clarabel-cvxpy", None), ("newton", None), ("interior", None),
    ("osqp", "polygon:16"), ("osqp-cvxpy", "polygon:16"), ("newton", "polygon:16"),
    ("interior", "polygon:16"), ("clarabel-cvxpy", "polygon:16")])
@pytest.mark.slow
def test_every_solver_finds_the_same_feasible_optimum(solver, cone):
    # H is positive definite: the minimiser is unique, every path must find the one of
    # Clarabel (an independent interior point implementation), with Coulomb's cone (the
    # default) or a pyramid (which OSQP takes)
    reference = solved("cyclic", "clarabel", cone=cone)
    result = solved("cyclic", solver, cone=cone)
    assert result.feasible and result.friction == "net"
    tolerance = 1e-4 if solver.startswith("osqp") else 1e-6
    np.testing.assert_allclose(result.x, reference.x, rtol=0,
                               atol=tolerance * scale(reference))
    assert result.objective == pytest.approx(reference.objective, rel=tolerance)


@pytest.mark.parametrize("solver", ["interior", "clarabel-cvxpy", None])
def test_solvers_agree_on_an_infeasible_section(solver):
    # Clarabel (accurate preset) is the reference for this project's interior point
    # method, the cvxpy path, and the balanced preset (Newton certificate, then the
    # interior point method on friction+, polished)
    reference = solved("free", "clarabel")
    result = solved("free", solver, "balanced")
    assert not result.feasible and result.friction == "plus"
    assert result.verdict == "infeasible"
    # the cvxpy path returns no multipliers, so it is not polished: an interior point
    # at gap 1e-8, whose vertex forces were measured 1.8e-5 of the largest from the optimum
    tolerance = 1e-4 if solver == "clarabel-cvxpy" else 1e-8
    assert result.moi_factor == pytest.approx(reference.moi_factor, rel=tolerance / 10)
    np.testing.assert_allclose(result.x, reference.x, rtol=0,
                               atol=tolerance * scale(reference))


@pytest.mark.parametrize("solver", [None, "interior"])
@pytest.mark.parametrize("mu", [0.05, 0.3, 1.5])
def test_the_fast_path_agrees_with_clarabel_on_infeasible_structures(mu, solver):
    # the balanced preset's friction+ (Newton from friction-net's last point where it
    # converges, else the interior point on the Newton system; then Newton polish) and
    # the interior point asked for by name, against Clarabel: MoI and every vertex
    # force, over the range of the interior point's starting scale (interior.START_SCALE)
    prepared = problem(small("free"))
    reference = prepared.solve(mu=mu, solver="clarabel", accuracy="accurate", lp_check=False)
    result = prepared.solve(mu=mu, accuracy="balanced", solver=solver)
    if solver == "interior":
        assert [a["solver"] for a in result.attempts][-2:] == ["interior", "newton-polish"]
    assert result.verdict == reference.verdict == "infeasible"
    assert result.moi_factor == pytest.approx(reference.moi_factor, rel=1e-8)
    np.testing.assert_allclose(result.x, reference.x, rtol=0, atol=1e-8 * scale(reference))


@pytest.mark.parametrize("mu", [0.05, 0.7])
def test_the_unpolished_interior_point_is_near_clarabels_optimum(mu):
    # the fast preset keeps the interior point's last point (tol 1e-6, no Newton
    # polish, no iterative refinement of its directions): still in equilibrium and
    # within 1e-4 of Clarabel's MoI
    prepared = problem(small("free"))
    reference = prepared.solve(mu=mu, solver="clarabel", accuracy="accurate", lp_check=False)
    result = prepared.solve(mu=mu, accuracy="fast", solver="interior")
    assert [a["solver"] for a in result.attempts][-1] == "interior"
    assert result.residual_eq <= 1e-6 and result.friction_violation <= 1e-6
    assert result.moi_factor == pytest.approx(reference.moi_factor, rel=1e-4)


def test_verdicts_and_run_json_fields():
    feasible = solved("cyclic", None, "balanced")
    assert feasible.verdict == "feasible" and feasible.to_dict()["verdict"] == "feasible"
    # friction-net alone on an infeasible section: Newton's certificate, no forces
    certified = problem(small("free")).solve(friction="net", solver="newton")
    assert certified.x is None and certified.verdict == "infeasible"
    # a tolerance no point meets: no answer, and no certificate either
    unsolved = problem(small("cyclic")).solve(friction="net", solver="newton",
                                              tol=Tolerances(residual=0.0))
    assert unsolved.x is None and unsolved.verdict == "not solved"


def test_direct_and_cvxpy_paths_agree_without_polish():
    # the fast preset does not polish: the raw interior-point points are compared
    direct = solved("cyclic", "clarabel", "fast")
    reference = solved("cyclic", "clarabel-cvxpy", "fast")
    assert [a["solver"] for a in direct.attempts] == ["clarabel"]
    np.testing.assert_allclose(direct.x, reference.x, rtol=0, atol=1e-4 * scale(reference))


def test_newton_certifies_infeasibility_and_the_lp_agrees():
    m = small("free")
    result = solve_rbe(m.blocks, m.interfaces, friction="net", solver="newton", lp_check=True)
    assert result.status == "infeasible" and result.x is None and not result.feasible
    assert result.lp_feasible is False


@pytest.mark.parametrize("accuracy", tuple(ACCURACY))
@pytest.mark.parametrize("boundary", ["free", "cyclic"])
def test_presets_meet_their_residuals(accuracy, boundary):
    result = solved(boundary, None, accuracy)
    limit = ACCURACY[accuracy].residual
    assert result.x is not None and result.accuracy == accuracy
    assert result.residual_eq <= limit and result.friction_violation <= limit
    assert result.feasible is (boundary == "cyclic")


@pytest.mark.parametrize("boundary", ["free", "cyclic"])
def test_the_accurate_preset_has_the_lp_confirm_infeasible_verdicts(boundary):
    result = problem(small(boundary)).solve(accuracy="accurate")
    if result.feasible:
        assert result.lp_feasible is None and result.lp_time_s == 0.0
    else:
        assert result.lp_feasible is False and result.lp_time_s > 0.0
    with pytest.raises(ValueError, match="lp_check"):
        problem(small(boundary)).solve(lp_check="always")


def test_polish_finds_the_exact_optimum():
    # Clarabel stops in the interior: tension residue on a feasible structure; the
    # Newton polish lands on the vertex solution with none
    raw = solved("cyclic", "clarabel", "fast")
    polished = solved("cyclic", "clarabel", "accurate")
    assert raw.moi > 0 and polished.moi == 0.0
    assert polished.attempts[-1]["solver"] == "newton-polish"
    assert polished.residual_eq < 1e-12


# ---------------------------------------------------------------------- load-path LP
@pytest.mark.parametrize("preset, boundary, mu, cone", [
    ("3", "free", 0.05, "circle"), ("3", "free", 0.3, "circle"), ("3", "free", 0.7, "circle"),
    ("3", "free", 1.5, "circle"), ("3", "cyclic", 0.05, "circle"),
    ("3", "cyclic", 0.7, "circle"), ("1", "free", 0.7, "circle"),
    ("3", "free", 0.7, "square"), ("3", "cyclic", 0.7, "square"),
    ("3", "cyclic", 0.05, "polygon:16")])
def test_the_load_path_lp_agrees_with_highs_and_clarabel(preset, boundary, mu, cone):
    m = small(boundary) if preset == "3" else model(preset, boundary=boundary)
    system = problem(m).system.with_material(mu=mu, density=2000.0, cone=cone)
    tol = NewtonOptions().infeasibility_tol
    outcome = decide(NewtonSystem(system, "net"), tol, Tolerances().residual)
    clarabel = BACKENDS["clarabel"].solve_rbe(system, "net", {}, {})
    feasible = clarabel.status == "optimal"
    assert clarabel.status in ("optimal", "infeasible")
    if system.cone.is_polyhedral:  # HiGHS, a third opinion
        assert lp_feasible(system, 60.0, feasible) == feasible
    # the verdict's evidence, recomputed from the layout's matrices
    b = -system.f_ext
    forces_columns = _selection(system.layout)
    A = system.A_eq @ forces_columns
    if feasible:
        # the LP stops where the load path reaches the dead load: forces within the
        # friction model that meet the equilibrium rows within the acceptance residual
        assert outcome.info["verdict"] == "feasible"
        forces = outcome.info["forces"]
        residual = np.abs(A @ forces.ravel() - b).max() / np.abs(b).max()
        assert system.cone.excess(*forces.T, mu).max() <= 1e-12 * np.abs(forces).max()
        assert residual == pytest.approx(outcome.info["residual"], rel=1e-6)
        assert residual <= Tolerances().residual
    else:
        assert outcome.info["verdict"] == "infeasible"
        gain = float(b @ outcome.y)
        assert gain > 0 and outcome.status == "infeasible"
        # every vertex force of unit compression within the model does at most the
        # certificate's slack of work on y
        assert _most_work(system, A.T @ outcome.y) <= tol * gain / np.abs(b).sum()


def _selection(layout):
    """(4 IV, 3 IV): the columns (c, f1, f2) of every vertex."""
    picked = np.stack([layout.columns(name) for name in ("c", "f1", "f2")], axis=1).ravel()
    return sp.csr_array((np.ones(len(picked)), (picked, np.arange(len(picked)))),
                        shape=(layout.n_columns, len(picked)))


def _most_work(system, work):
    """The largest work ``w . (c, f)`` of a vertex force inside the model per unit of its
    cone variables' trace (the sum of a pyramid's ray weights: ``c = 1``; the second-order
    cone's ``mu c = 1``), for the per-vertex works ``work`` ((3 IV,): on c, f1, f2)."""
    w = work.reshape(-1, 3)
    mu, cone = system.mu, system.cone
    if cone.is_polyhedral:
        return float((w @ cone.rays(mu)).max())
    return float((w[:, 0] / mu + np.hypot(w[:, 1], w[:, 2])).max())


@pytest.mark.slow
def test_the_load_path_lp_decides_past_an_early_load_factor_above_one(monkeypatch):
    # preset 1's cyclic section with p 20 at mu 0.45 (2,606 bricks): an early iterate of
    # the LP has lambda >= 1 while its point misses the dead load by 20 times its
    # largest entry, and the optimum is 0.97; the verdict is the certificate, recomputed
    # from the layout's matrices
    system = problem(model("1", p=20, boundary="cyclic")).system.with_material(
        mu=0.45, density=2000.0)
    tol = NewtonOptions().infeasibility_tol
    iterates, stop = [], net_feasibility._LoadPath.__call__

    def recorded(path, factor, g, y):
        if factor >= 1.0:  # the friction-net point of the module docstring
            iterates.append(path.point_residual(g / factor + (1 - 1 / factor) * path.start))
        return stop(path, factor, g, y)

    monkeypatch.setattr(net_feasibility._LoadPath, "__call__", recorded)
    outcome = decide(NewtonSystem(system, "net"), tol, Tolerances().residual)
    assert iterates and min(iterates) > 1.0 and outcome.info["load_factor"] < 0.99
    assert outcome.info["verdict"] == "infeasible" and outcome.info["forces"] is None
    A = system.A_eq @ _selection(system.layout)
    b = -system.f_ext
    gain = float(b @ outcome.y)
    assert gain > 0
    assert _most_work(system, A.T @ outcome.y) <= tol * gain / np.abs(b).sum()


def test_the_balanced_preset_certifies_by_the_load_path_lp():
    # Newton stalls on this section at mu 0.05: the LP certifies, not Clarabel; friction+
    # as before, against Clarabel
    prepared = problem(small("free"))
    reference = prepared.solve(mu=0.05, solver="clarabel", accuracy="accurate",
                               lp_check=False)
    result = prepared.solve(mu=0.05, accuracy="balanced")
    # the interior point method of the cone stops at its precision floor (user_limit)
    # or its tolerance; the polish ends at the optimum either way
    attempts = [(a["solver"], a["status"]) for a in result.attempts]
    assert attempts[:2] == [("newton", "user_limit"), (LOAD_PATH, "infeasible")]
    assert attempts[2][0] == "interior" and attempts[2][1] in ("optimal", "user_limit")
    assert attempts[3:] == [("newton-polish", "optimal")]
    assert result.verdict == reference.verdict == "infeasible"
    assert result.moi_factor == pytest.approx(reference.moi_factor, rel=1e-8)
    np.testing.assert_allclose(result.x, reference.x, rtol=0, atol=1e-8 * scale(reference))


def test_a_feasible_load_path_verdict_resumes_newton(monkeypatch, caplog):
    # Newton made to stall after one step without halving: the LP finds friction-net
    # feasible, Newton resumes and finds Clarabel's optimum; friction+, started on the
    # second core at the hand-over, is ended unused and the factorization gets its
    # threads back
    monkeypatch.setattr(solve_module, "LOAD_PATH_STALL", 1)
    monkeypatch.setattr(forking, "cores", lambda: 2)
    # separate problems: Clarabel's Newton polish would warm-start the balanced solve
    reference = problem(small("cyclic")).solve(mu=0.5, solver="clarabel",
                                               accuracy="accurate")
    prepared = problem(small("cyclic"))
    with caplog.at_level(logging.INFO, logger="masonry.rbe"):
        result = prepared.solve(mu=0.5, accuracy="balanced")
    if forking.can_fork():
        assert "friction+ starts on the second core" in caplog.text
    assert "friction+ was solved" not in caplog.text
    assert _factor_threads(prepared) is None
    assert [(a["solver"], a["status"]) for a in result.attempts] == [
        ("newton", "user_limit"), (LOAD_PATH, "user_limit"), ("newton", "optimal")]
    assert result.verdict == reference.verdict == "feasible"
    np.testing.assert_allclose(result.x, reference.x, rtol=0, atol=1e-6 * scale(reference))


@functools.lru_cache(maxsize=None)
def _arch_model(blocks):
    """A semicircular arch of 10 m span, 0.6 m thick, cut into ``blocks`` voussoirs."""
    return build_model(Params.of(scene="arch", arch_blocks=blocks, arch_thickness=0.6))[1]


def test_newton_stalled_twice_hands_friction_net_to_the_interior_point_method():
    # an arch of 1,024 voussoirs: Newton's steps crawl a hinge at a time, the LP finds
    # friction-net feasible, the resumed Newton stalls again and the interior point
    # method (polished) finds Clarabel's optimum: Clarabel is not on the path
    reference = problem(_arch_model(1024)).solve(mu=0.7, solver="clarabel",
                                                 accuracy="accurate")
    result = problem(_arch_model(1024)).solve(mu=0.7, accuracy="balanced")
    assert [(a["solver"], a["status"]) for a in result.attempts] == [
        ("newton", "user_limit"), (LOAD_PATH, "user_limit"), ("newton", "user_limit"),
        ("interior", "optimal"), ("newton-polish", "optimal")]
    assert result.verdict == reference.verdict == "feasible"
    np.testing.assert_allclose(result.x, reference.x, rtol=0, atol=1e-6 * scale(reference))


@pytest.mark.parametrize("clarabel_status", ["user_limit", "infeasible"])
def test_the_load_path_lp_point_answers_where_no_solver_reaches_the_optimum(
        clarabel_status, monkeypatch, caplog):
    # after the LP found the arch's friction-net feasible, the interior point method
    # made to fail (as it and Clarabel did at their precision floor on 16,384
    # voussoirs) and Clarabel to fail or to certify infeasibility: the verdict is the
    # LP's, not friction+'s tension, and its forces balance the dead load within the
    # friction model, recomputed here from the matrices
    def failing(status):
        return lambda system, method, options, workspace, **extra: Outcome(
            status=status, x=None, iterations=0)

    for module, status in ((interior_module, "user_limit"),
                           (clarabel_module, clarabel_status)):
        monkeypatch.setattr(module, "BACKEND", dataclasses.replace(
            module.BACKEND, rbe=failing(status)))
    prepared = problem(_arch_model(1024))
    with caplog.at_level(logging.WARNING, logger="masonry.rbe"):
        result = prepared.solve(mu=0.7, accuracy="balanced")
    assert "the LP's point is the answer" in caplog.text
    assert [(a["solver"], a["status"]) for a in result.attempts] == [
        ("newton", "user_limit"), (LOAD_PATH, "user_limit"), ("newton", "user_limit"),
        ("interior", "user_limit"), ("clarabel", clarabel_status)]
    assert result.verdict == "feasible" and result.solver == LOAD_PATH
    # RBE/00_objective.txt does not call these forces the QP's optimum
    summary = objective_text(result)
    assert "the load-path LP found forces" in summary and "to tolerance" not in summary
    system = prepared.system.with_material(mu=0.7, density=2000.0, cone="circle")
    x = system.to_scaled(result.x)
    residual = np.abs(system.A_eq @ x + system.f_ext).max() / np.abs(system.f_ext).max()
    assert residual <= Tolerances().residual
    c, t, f1, f2 = result.x.reshape(-1, 4).T
    largest = np.abs(result.x).max()
    assert c.min() >= 0 and (np.hypot(f1, f2) - 0.7 * (c - t)).max() <= 1e-9 * largest


@pytest.mark.slow
def test_newton_hands_a_damped_out_dome_to_the_load_path_lp(monkeypatch):
    # preset 2's dome with p = 3 at mu 0.05 under the square pyramid (the trajectory
    # this hand-over rule was measured on): Newton's steps sit at the damping ceiling
    # and it hands over before its stall, to the same verdict; the LP's certificate,
    # recomputed from the layout's matrices, proves that no vertex forces with a bounded
    # total balance the dead load
    m = model("2", scene="dome", p=3)
    prepared = problem(m)
    result = prepared.solve(mu=0.05, friction="net", accuracy="balanced", cone="square")
    monkeypatch.setattr(solve_module, "LOAD_PATH_DAMPED_OUT", 0)
    stalled = problem(m).solve(mu=0.05, friction="net", accuracy="balanced", cone="square")
    for run in (result, stalled):
        assert [(a["solver"], a["status"]) for a in run.attempts] == [
            ("newton", "user_limit"), (LOAD_PATH, "infeasible")]
        assert run.verdict == "infeasible" and run.x is None
    assert result.attempts[0]["iterations"] < stalled.attempts[0]["iterations"]
    system = prepared.system.with_material(mu=0.05, density=2000.0, cone="square")
    tol = NewtonOptions().infeasibility_tol
    certificate = decide(NewtonSystem(system, "net"), tol, Tolerances().residual).y
    A = system.A_eq @ _selection(system.layout)
    b = -system.f_ext
    gain = float(b @ certificate)
    assert gain > 0
    assert _most_work(system, A.T @ certificate) <= tol * gain / np.abs(b).sum()


@pytest.mark.slow
def test_a_feasible_dome_at_the_damping_ceiling_pays_no_load_path_lp():
    # preset 3's dome at mu 0.2 under the square pyramid (with Coulomb's cone it stands
    # at mu 0.2 by a margin of 0.2 %, and Newton wanders): Newton's damping reaches its
    # ceiling on single steps while the active set settles; it converges without the
    # LP, to a point in equilibrium within the pyramids
    result = problem(model("3", scene="dome")).solve(mu=0.2, friction="net",
                                                     accuracy="balanced", cone="square")
    assert [(a["solver"], a["status"]) for a in result.attempts] == [("newton", "optimal")]
    assert result.feasible and result.verdict == "feasible"
    assert result.residual_eq <= 1e-9 and result.friction_violation <= 1e-9


def _factor_threads(prepared):
    """The thread limit of the factorizations once a problem is solved (None: the
    default)."""
    return cholesky.thread_limit()


def _alongside(monkeypatch, on):
    """Let friction+ run on the second core (``on``: as on any two-core Linux machine)
    or never."""
    monkeypatch.setattr(forking, "cores", lambda: 2)
    if not on:
        monkeypatch.setattr(cores_module.Alongside, "wanted", staticmethod(lambda *a: False))


@pytest.mark.skipif(not forking.can_fork(), reason="friction+ alongside needs fork")
@pytest.mark.slow
def test_friction_plus_alongside_is_the_one_solved_after(monkeypatch, caplog):
    """preset 2's dome with p = 3 at mu 0.05: Newton hands friction-net over to the
    load-path LP, friction+ starts on the second core, and its result is the one this
    process gets by solving friction+ after friction-net: the same attempts, MoI and
    forces."""
    m = model("2", scene="dome", p=3)
    _alongside(monkeypatch, False)
    after = problem(m).solve(mu=0.05, accuracy="balanced")
    monkeypatch.undo()
    _alongside(monkeypatch, True)
    prepared = problem(m)
    with caplog.at_level(logging.INFO, logger="masonry.rbe"):
        alongside = prepared.solve(mu=0.05, accuracy="balanced")
    assert "friction+ was solved on the second core" in caplog.text
    assert _factor_threads(prepared) is None
    assert alongside.verdict == after.verdict == "infeasible"
    key = [(a["friction"], a["solver"], a["status"], a["iterations"]) for a in after.attempts]
    assert [(a["friction"], a["solver"], a["status"], a["iterations"])
            for a in alongside.attempts] == key
    assert abs(alongside.moi - after.moi) <= 1e-12 * after.weight_N
    np.testing.assert_allclose(alongside.x, after.x, rtol=0, atol=1e-12 * scale(after))


@pytest.mark.skipif(not forking.can_fork(), reason="friction+ alongside needs fork")
@pytest.mark.parametrize("where", ["in the forked process", "at the fork"])
@pytest.mark.slow
def test_friction_plus_alongside_failing_is_solved_here(monkeypatch, caplog, where):
    m = model("2", scene="dome", p=3)
    _alongside(monkeypatch, False)
    after = problem(m).solve(mu=0.05, accuracy="balanced")
    monkeypatch.undo()
    _alongside(monkeypatch, True)

    def broken(*args):
        raise MemoryError("out of memory")

    def no_fork(self):
        raise OSError(12, "Cannot allocate memory")

    if where == "at the fork":
        monkeypatch.setattr(forking.Forked, "start", no_fork)
    else:
        monkeypatch.setattr(cores_module.Alongside, "_solve", broken)
    prepared = problem(m)
    with caplog.at_level(logging.INFO, logger="masonry.rbe"):
        result = prepared.solve(mu=0.05, accuracy="balanced")
    assert ("cannot start on the second core" if where == "at the fork"
            else "friction+ on the second core failed (out of memory)") in caplog.text
    assert result.verdict == "infeasible" and result.friction == "plus"
    assert abs(result.moi - after.moi) <= 1e-12 * after.weight_N
    assert _factor_threads(prepared) is None


def test_a_feasible_structure_solves_friction_net_alone(monkeypatch):
    """A feasible section that Newton solves alone never starts friction+."""
    _alongside(monkeypatch, True)

    def start(self):
        raise AssertionError("friction+ started beside a feasible structure")

    monkeypatch.setattr(forking.Forked, "start", start)
    result = problem(small("cyclic")).solve(mu=0.7, accuracy="balanced")
    assert result.feasible and [a["solver"] for a in result.attempts] == ["newton"]


def test_a_solve_given_one_core_solves_friction_plus_here(monkeypatch):
    """The caller decides: on a machine where friction+ would start beside the load-path
    LP (preset 2's dome with p = 3 at mu 0.05), ``cores=1`` starts no process and
    factors on one thread."""
    _alongside(monkeypatch, True)

    def start(self):
        raise AssertionError("friction+ started on a second core")

    limits = []
    factor = BlockCholesky.factor
    monkeypatch.setattr(forking.Forked, "start", start)
    monkeypatch.setattr(BlockCholesky, "factor", lambda self, values: limits.append(
        cholesky.thread_limit()) or factor(self, values))
    result = problem(model("2", scene="dome", p=3)).solve(mu=0.05, accuracy="balanced",
                                                          cores=1)
    assert result.verdict == "infeasible" and result.friction == "plus"
    assert limits and set(limits) == {1}


# ---------------------------------------------------------------------- reuse
@pytest.mark.parametrize("solver, cone", [("newton", None), ("osqp", "square"),
                                          ("clarabel", None), ("clarabel", "square")])
@pytest.mark.slow
def test_reuse_between_friction_coefficients_changes_nothing(solver, cone):
    # and between friction models: the kept solver objects are rebuilt for another
    # model's rows
    m = small("free")
    prepared = problem(m)
    prepared.solve(mu=0.7, solver=solver, cone="polygon:8", lp_check=False)
    for mu in (1.5, 0.4, 5.0):
        again = prepared.solve(mu=mu, friction="plus" if solver != "newton" else "net",
                               solver=solver, lp_check=False, cone=cone)
        fresh = solve_rbe(m.blocks, m.interfaces, mu=mu, solver=solver, cone=cone,
                          friction="plus" if solver != "newton" else "net")
        assert again.feasible == fresh.feasible and again.status == fresh.status
        if fresh.x is not None:
            np.testing.assert_allclose(again.x, fresh.x, rtol=0, atol=1e-5 * scale(fresh))


def test_a_second_solve_starts_from_the_first():
    prepared = problem(small("cyclic"))
    first = prepared.solve()
    second = prepared.solve()
    assert first.iterations > 0 and second.iterations == 0
    np.testing.assert_allclose(first.x, second.x, rtol=0, atol=1e-12 * scale(first))


def test_density_only_scales_the_forces():
    prepared = problem(small("cyclic"))
    light = prepared.solve(density=20.0)
    heavy = prepared.solve(density=2.0e6)
    np.testing.assert_allclose(heavy.x, light.x * 1e5, rtol=0, atol=1e-9 * scale(heavy))
    assert heavy.weight_N == pytest.approx(light.weight_N * 1e5)


# ---------------------------------------------------------------------- bench
def test_bench_rows_tables_and_frontier(tmp_path):
    rows = bench(presets=("3",), scenes=("cyclic",), accuracies=("fast", "accurate"),
                 repeats=2, solvers=("clarabel-cvxpy",), overrides={"p": 5})
    assert [r["accuracy"] for r in rows] == ["accurate", "fast", "balanced"]
    for row in rows:
        assert set(COLUMNS) <= set(row)
        assert row["total_s"] >= row["solve_s"] >= row["lp_s"] >= 0
        assert row["residual_eq"] <= 1e-5 and row["feasible"]
    reference, fast, cvxpy = rows
    # a feasible verdict rests on its verified point: no LP
    assert reference["force_deviation"] == 0.0 and reference["lp_s"] == 0.0
    assert fast["force_deviation"] < 1e-6  # Newton's optimum, at the fast preset's 1e-6
    assert 0 < cvxpy["force_deviation"] < 1e-4  # an unpolished interior point
    markdown = table_markdown(rows)
    assert markdown.count("\n") == len(rows) + 2
    assert table_csv(rows).decode().splitlines()[0].split(",") == header(COLUMNS)
    assert frontier_png(rows)[:8] == b"\x89PNG\r\n\x1a\n"


def test_infeasible_against_feasible_ratios():
    rows = [{"preset": "1", "scene": scene, "accuracy": "balanced", "solver": "newton",
             "total_s": seconds}
            for scene, seconds in (("section", 0.6), ("cyclic", 0.4), ("dome", 4.0))]
    (pair,) = ratios(rows)  # no low-mu dome measured: one pair
    assert (pair["infeasible"], pair["feasible"]) == ("section", "cyclic")
    assert pair["ratio"] == pytest.approx(1.5)
    assert "| 1 | balanced | section | cyclic | 0.60 | 0.40 | 1.50 |" in ratios_markdown(rows)


def test_bench_command_writes_its_files(tmp_path, capsys):
    code = main(["bench", "--presets", "3", "--p", "5", "--scenes", "section",
                 "--accuracy", "balanced", "--repeats", "1", "--out", str(tmp_path), "-q"])
    assert code == 0
    for name in ("bench.csv", "bench.md", "frontier.png"):
        assert (tmp_path / "bench" / name).is_file()
    assert "| 3 | section |" in capsys.readouterr().out


def test_highs_prints_nothing_to_standard_output(capfd):
    """A run's stdout is its summary (pipes, -q): HiGHS's banner stays out of it."""
    highs = highs_lp(sp.csc_array(np.ones((1, 2))), np.ones(2), np.zeros(2),
                     np.full(2, 10.0), np.ones(1), np.ones(1), ())
    highs.run()
    assert highs.getInfo().objective_function_value == pytest.approx(1.0)
    assert capfd.readouterr().out == ""
