"""Numerical stability at the extremes of every parameter (docs/model.md 3).

Every extreme either builds a valid model whose equilibrium is solved with residuals
below tolerance, or is refused before any work with one :class:`ParameterError` that
names the parameter and says why; never a traceback, never a silently wrong answer.
Domes are kept small (few pattern bricks, one rhombus) so the whole file runs in
seconds; the ranges are the valid ones of docs/model.md 3.
"""

import numpy as np
import pytest

from masonry.rbe.boundary import analysis_model
from masonry.tolerances import G
from masonry.interfaces import INTERFACE_KINDS
from masonry.params import ParameterError, Params, validate
from masonry.scenes import build
from masonry.rbe.solve import ACCURACY, RBEProblem
from masonry_cli.main import main

SUPPORT = INTERFACE_KINDS.index("support")
BASE = dict(stretch=1.0, n=8, r=1, p=5, cut=0.1, boundary="cyclic")


def analyse(accuracy="balanced", **changes):
    """Build and solve; returns (params, model, result) or raises ParameterError."""
    params = validate(Params.of(**{**BASE, **changes}))
    scene = build(params)
    model = analysis_model(scene, params.analysis.boundary)
    problem = RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                         side_rotation=model.side_rotation)
    result = problem.solve(mu=params.analysis.mu, density=params.analysis.density,
                           accuracy=accuracy)
    check_valid(params, scene, model, result)
    return params, model, result


def check_valid(params, scene, model, result):
    """A valid model and a valid result: every residual below the preset's tolerance."""
    blocks = scene.blocks
    free = ~blocks.block_is_support
    assert free.sum() > 0 and np.all(blocks.block_volume[free] > 0)
    assert result.weight_N == pytest.approx(
        params.analysis.density * G * blocks.block_volume[free].sum(), rel=1e-12)
    limit = ACCURACY[result.accuracy].residual
    assert result.x is not None, result.attempts
    assert np.all(np.isfinite(result.x))
    assert result.residual_eq <= limit and result.friction_violation <= limit
    assert result.feasible == (result.net_friction_violation <= limit)
    # the ground carries the weight: in cyclic symmetry the boundary forces on the two
    # ends have opposite vertical parts
    forces = result.per_interface()
    ground = model.interfaces.kind == SUPPORT
    vertical = ((forces["compression"] - forces["tension"])[ground]
                * model.interfaces.normal[ground, 2]
                + forces["t1"][ground] * model.interfaces.t1[ground, 2]
                + forces["t2"][ground] * model.interfaces.t2[ground, 2])
    assert vertical.sum() == pytest.approx(result.weight_N, rel=1e-5)


def refused(name, **changes):
    with pytest.raises(ParameterError) as error:
        analyse(**changes)
    assert error.value.name == name
    message = str(error.value)
    assert name in message and "expected" in message
    return message


def test_unit_scales_forces_by_its_cube():
    # 1e-3 m to 1e2 m bricks: the same structure at another scale. Weights grow with
    # unit^3, every force with them; feasibility and the MoI factor stay.
    results = {}
    for boundary in ("free", "cyclic"):
        for unit in (1e-3, 1e-1, 1e2):
            results[boundary, unit] = analyse(unit=unit, boundary=boundary)[2]
        reference = results[boundary, 1e-1]
        for unit in (1e-3, 1e2):
            result = results[boundary, unit]
            factor = (unit / 1e-1) ** 3
            assert result.feasible == reference.feasible == (boundary == "cyclic")
            assert result.moi_factor == pytest.approx(reference.moi_factor, rel=1e-6,
                                                      abs=1e-9)
            # per interface: the polygons' first vertices may differ with the scale
            for key, value in result.per_interface().items():
                expected = reference.per_interface()[key]
                np.testing.assert_allclose(value / factor, expected, rtol=0,
                                           atol=1e-6 * np.abs(expected).max())


@pytest.mark.parametrize("changes", [
    dict(stretch=0.5), dict(stretch=4.0), dict(stretch=0.3, n=32),
    dict(n=3, p=10), dict(n=32, p=3, r=0), dict(n=4, p=6),
    dict(p=2, r=4), dict(p=20, r=0),
    dict(r=0), dict(r=4, p=1, pattern="none"),
    dict(cut=0.0), dict(cut=0.9, p=20, r=2),
])
def test_geometric_extremes_build_and_solve(changes):
    analyse(**changes)


@pytest.mark.parametrize("changes, name", [
    (dict(stretch=0.3), "p"),   # courses meet in wedges too steep to close
    (dict(n=3, p=3, r=0), "p"),
    (dict(p=1, r=0), "p"),
    (dict(p=1, r=4), "p"),  # the lines from the corners end on the first course
    (dict(cut=0.9, p=3, r=0), "cut"),  # fewer than two courses
    (dict(stretch=0.0), "stretch"),
    (dict(n=2), "n"),
    (dict(p=0), "p"),
    (dict(r=-1), "r"),
    (dict(cut=1.0), "cut"),
    (dict(unit=0.0), "unit"),
    (dict(mu=0.0), "mu"),
    (dict(density=-1.0), "density"),
    (dict(unit=float("nan")), "unit"),
])
def test_inputs_that_cannot_be_built_are_refused_with_one_clear_error(changes, name):
    refused(name, **changes)


def test_the_command_line_reports_a_refused_input_in_one_line(capsys, tmp_path):
    code = main(["build", "--preset", "1", "--p", "1", "--r", "0", "--out", str(tmp_path),
                 "-q"])
    captured = capsys.readouterr()
    assert code == 2
    assert captured.err.count("\n") == 1 and "--p 1" in captured.err
    assert "Traceback" not in captured.err
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("mu", [0.01, 0.05, 0.3, 5.0, 10.0])  # the ends of mu's valid range
@pytest.mark.parametrize("boundary", ["free", "cyclic"])
def test_friction_coefficient_extremes(mu, boundary):
    _, _, result = analyse(mu=mu, boundary=boundary)
    if mu <= 0.05 or boundary == "free":
        # almost no friction: the inclined courses slide; a free web overhangs its base
        # whatever the friction
        assert not result.feasible and result.moi > 0
    else:
        # between its neighbours the web stands, with no tension at all
        assert result.feasible and result.moi_factor <= 1e-9


@pytest.mark.slow
def test_friction_lowers_the_measure_of_infeasibility_strictly():
    moi = [analyse(mu=mu, boundary="free")[2].moi_factor for mu in (0.05, 0.3, 1.0, 5.0)]
    assert all(a > b for a, b in zip(moi, moi[1:])), moi


def test_density_over_six_decades_only_scales_the_forces():
    # the ends of density's valid range
    results = {rho: analyse(density=rho, boundary=b)[2]
               for rho in (1.0, 2.0e3, 1.0e7) for b in ("free",)}
    reference = results[2.0e3]
    for rho in (1.0, 1.0e7):
        result = results[rho]
        assert result.feasible == reference.feasible
        assert result.moi_factor == pytest.approx(reference.moi_factor, rel=1e-9)
        np.testing.assert_allclose(result.x * (2.0e3 / rho), reference.x, rtol=0,
                                   atol=1e-9 * np.abs(reference.x).max())


@pytest.mark.parametrize("accuracy", list(ACCURACY))
def test_every_preset_is_valid_at_a_closed_crown(accuracy):
    # cut = 0: the courses close over the crown, the narrowest bricks of all
    analyse(accuracy=accuracy, cut=0.0, boundary="free")
