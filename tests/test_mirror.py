"""Mirror symmetry (docs/model.md 6.11): a model solved on its half in a vertical plane
gives the whole model's answers. The whole is solved independently, on its own
matrices, and compared: the RBE's unique optimum (forces, objective, MoI, verdict) to
the Newton method's accuracy, and the collapse load factor to the LP's (1e-6 relative,
docs/collapse.md "Solver"), its mechanism checked on the whole's geometry."""

import json

import numpy as np
import pytest

from masonry.params import Params, from_preset, validate
from masonry.pipeline import Timer, build_model, collapse_of, solve
from masonry.rbe.collapse import collapse_load, collapse_on_half
from masonry.rbe.lateral_search import worst_lateral
from masonry.rbe.loads import CrownLoad, Lateral, crown_load, lateral
from masonry.rbe.mirror import MirrorError, half_model
from masonry.rbe.solve import RBEProblem
from masonry_cli.main import main
from test_collapse import LP_RESIDUAL, SMALL_DOME, check_mechanism

FACTOR_REL = 1e-6
"""The collapse LP's documented accuracy on the factor (docs/collapse.md "Solver")."""
FORCE_REL = 1e-6
"""The RBE's forces, relative to the largest: its optimum is unique and the accurate
preset's Newton method ends within 1e-9 of it."""


def small(**options):
    return validate(Params.of(**{**SMALL_DOME, **options}))


def whole_rbe(model, **options):
    return RBEProblem(model.blocks, model.interfaces, **model.assembly).solve(
        density=2000.0, accuracy="accurate", **options)


@pytest.fixture(scope="module")
def dome():
    return build_model(small(scene="dome"))[1]


@pytest.fixture(scope="module")
def section():
    return build_model(small(scene="section", boundary="cyclic"))[1]


@pytest.mark.parametrize("azimuth", [0.0, 30.0, 90.0, 240.0])
def test_a_lateral_load_along_a_mirror_plane_has_the_whole_domes_factor(dome, azimuth):
    """Along a web's mid-plane (0, 90 + 150 = 240 on the far side) or a corner plane (30,
    90), on the half of the dome: the whole's factor; the forces mapped back balance the
    whole's loads and the mechanism mapped back is one of the whole's (no joint
    penetrates, the virtual work balances)."""
    live = lateral(dome, azimuth)
    whole = collapse_load(dome, live)
    half = collapse_on_half(dome, Lateral(azimuth), azimuth)
    assert half.status == whole.status and half.dead_load_feasible
    assert half.load_factor == pytest.approx(whole.load_factor, rel=FACTOR_REL)
    assert half.residual <= 10 * LP_RESIDUAL
    assert half.forces["normal"].shape == whole.forces["normal"].shape
    check_mechanism(dome, live, half)
    # the mechanism is its own mirror image: the dome's two halves move alike
    assert half.main_hinge.sum() > 0


def test_the_halfs_blocks_and_joints(dome):
    """The half in a web's mid-plane: the blocks on one side, the cut ones halved (half
    the weight of the whole in all), each cut block keeping its motion in the plane
    (three rows dropped); about half the joints' vertices."""
    half = half_model(dome, 0.0)
    model = half.model
    free = ~model.blocks.block_is_support
    weight = [(m.blocks.block_volume * ~m.blocks.block_is_support).sum()
              for m in (model, dome)]
    assert weight[0] == pytest.approx(weight[1] / 2, rel=1e-12)
    cut = model.dropped_rows.any(axis=1)
    assert cut.any() and (model.dropped_rows[cut].sum(axis=1) == 3).all()
    assert not cut[~free].any()
    vertices = [len(m.interfaces.vertices) for m in (model, dome)]
    assert 0.45 * vertices[1] < vertices[0] < 0.6 * vertices[1]
    # a vertex in the plane carries half the whole's force
    on_plane = np.abs(model.interfaces.vertices[:, 1]) <= 1e-9
    assert set(np.unique(model.vertex_share)) == {0.5, 1.0}
    assert (model.vertex_share[~on_plane] == 1.0).all()


@pytest.mark.parametrize("scene", ["dome", "section"])
def test_self_weight_on_the_half_is_the_whole_equilibrium_mirrored(dome, section, scene):
    """The RBE's optimum is unique, so the half's, mirrored back, is the whole's: the same
    forces at every vertex, objective, MoI and verdict (the cyclic section: the half web,
    its other side bounded by the corner plane through the cyclic image)."""
    model = dome if scene == "dome" else section
    params = small(scene=scene, boundary="cyclic" if scene == "section" else "free",
                   accuracy="accurate")
    whole = whole_rbe(model)
    on_half = solve(model, params, Timer())
    assert on_half.verdict == whole.verdict == "feasible"
    assert on_half.layout.n_vertices == whole.layout.n_vertices
    scale = np.abs(whole.x).max()
    assert np.abs(on_half.x - whole.x).max() <= FORCE_REL * scale
    assert on_half.objective == pytest.approx(whole.objective, rel=FORCE_REL)
    assert on_half.weight_N == pytest.approx(whole.weight_N, rel=1e-12)
    assert on_half.residual_eq <= 1e-8


@pytest.mark.parametrize("plane", [0.0, 30.0])
def test_a_dome_that_cannot_stand_cannot_on_its_half(plane):
    """At mu 0.05 the dome needs tension: friction+ on the half gives the whole's MoI (its
    optimum is unique too) and the verdict 'infeasible'."""
    params = small(scene="dome", mu=0.05, accuracy="accurate")
    model = build_model(params)[1]
    whole = whole_rbe(model, mu=0.05)
    half = half_model(model, plane)
    on_half = RBEProblem(half.model.blocks, half.model.interfaces,
                         **half.model.assembly).solve(mu=0.05, density=2000.0,
                                                      accuracy="accurate")
    assert whole.verdict == on_half.verdict == "infeasible"
    assert on_half.moi * 2 == pytest.approx(whole.moi, rel=FORCE_REL)
    assert solve(model, params, Timer()).moi == pytest.approx(whole.moi, rel=FORCE_REL)


def test_a_crown_load_on_the_half_web_is_the_whole_domes(dome, section):
    """An upward crown load lifts the top course at a finite factor: the whole dome's, on
    the half of the dome and on the half web of the cyclic section."""
    whole = collapse_load(dome, crown_load(dome, -2000.0))
    for model, copies in ((dome, 1), (section, 6)):
        half = collapse_on_half(model, CrownLoad(-2000.0), 0.0, copies=copies)
        assert half.load_factor == pytest.approx(whole.load_factor, rel=FACTOR_REL)
        assert half.residual <= 10 * LP_RESIDUAL
    # a run's (downward) crown load, on the half web: carried at any factor, as on the
    # whole dome
    params = small(scene="section", boundary="cyclic", crown_load=2000.0)
    down = collapse_of(section, params)
    assert down.status == collapse_load(dome, crown_load(dome, 2000.0)).status == "unbounded"
    assert down.load_factor is None and down.dead_load_feasible


@pytest.mark.slow
def test_the_search_on_halves_finds_every_azimuths_factor(dome):
    """--lateral all with the mirror planes: every azimuth's factor as on the whole, with
    fewer solves (0, 15 and 30 degrees: 0 and 30 on halves)."""
    azimuths = np.arange(24) * 15.0
    plain = worst_lateral(dome, azimuths, refine=False)
    mirrored = worst_lateral(dome, azimuths, period_deg=60.0,
                             mirrors=tuple(np.arange(6) * 30.0), refine=False)
    np.testing.assert_allclose([f for _, f in mirrored.azimuths],
                               [f for _, f in plain.azimuths], rtol=FACTOR_REL)
    assert mirrored.azimuth_deg == plain.azimuth_deg == 30.0
    check_mechanism(dome, lateral(dome, 30.0), mirrored)


def test_a_plane_that_is_no_mirror_is_refused_naming_a_block(dome):
    with pytest.raises(MirrorError, match="plane at 15 degrees: block 'w0_b"):
        half_model(dome, 15.0)


def test_a_run_reports_the_half_on_the_whole_dome(tmp_path, dome):
    """``masonry run`` along a corner plane: the whole's factor, and every output on the
    whole dome (a row per block of the mechanism, per joint of the forces)."""
    code = main(["run", "--scene", "dome", "--stretch", "1", "--n", "6", "--r", "0",
                 "--p", "3", "--cut", "0.5", "--lateral", "30", "--out", str(tmp_path),
                 "--no-plots", "--no-printable", "-q"])
    assert code == 0
    folder = next(tmp_path.glob("*_lat30"))
    record = json.loads((folder / "run.json").read_text())
    whole = collapse_load(dome, lateral(dome, 30.0))
    assert record["collapse"]["load_factor"] == pytest.approx(whole.load_factor,
                                                              rel=FACTOR_REL)
    assert record["collapse"]["residual"] <= 10 * LP_RESIDUAL
    assert record["rbe"]["verdict"] == "feasible"
    assert record["rbe"]["weight_N"] == pytest.approx(whole_rbe(dome).weight_N, rel=1e-12)
    rows = (folder / "collapse" / "mechanism.csv").read_text().splitlines()
    assert len(rows) == 1 + dome.blocks.n_blocks
    for table in ("RBE", "collapse"):
        lines = (folder / table / "forces.csv").read_text().splitlines()
        assert len(lines) == 1 + len(dome.interfaces)


REVOLUTION = dict(scene="revolution", radius=12, p=2, spirals=6, cut=0.4)
"""A small dome of revolution: 198 bricks in 6 sectors, its mirror planes every 30
degrees (the middle and the edges of every sector)."""


@pytest.mark.parametrize("azimuth", [0.0, 30.0])
def test_the_dome_of_revolution_on_its_half_is_the_whole(azimuth):
    """Its rings are laid mirror-symmetric in the pattern's meridians (docs/model.md
    4.8): along a sector's middle (0) or its edge (30) the half dome has the whole's
    lateral factor and mechanism, and the whole's self-weight forces."""
    params = validate(Params.of(**REVOLUTION))
    model = build_model(params)[1]
    assert params.kind.symmetry(params.geometry).mirrors == tuple(np.arange(6) * 30.0)
    live = lateral(model, azimuth)
    whole = collapse_load(model, live)
    half = collapse_on_half(model, Lateral(azimuth), azimuth)
    assert half.load_factor == pytest.approx(whole.load_factor, rel=FACTOR_REL)
    check_mechanism(model, live, half)
    whole_weight = whole_rbe(model)
    half_model_ = half_model(model, azimuth)
    on_half = RBEProblem(half_model_.model.blocks, half_model_.model.interfaces,
                         **half_model_.model.assembly).solve(density=2000.0,
                                                             accuracy="accurate")
    forces = half_model_.whole_forces(on_half.x)
    assert on_half.verdict == whole_weight.verdict
    assert np.abs(forces - whole_weight.x).max() <= FORCE_REL * np.abs(whole_weight.x).max()


def test_a_sector_of_revolution_states_no_mirror_plane():
    """A brick across one edge of a sector is the sector's, the one across the other its
    neighbour's: the sector is not its own mirror image."""
    params = validate(Params.of(**{**REVOLUTION, "scene": "sector", "boundary": "cyclic"}))
    assert params.kind.symmetry(params.geometry).mirrors == ()
    with pytest.raises(MirrorError):
        half_model(build_model(params)[1], 0.0)


SMALL_ARGS = [f"--{key}={value}" for key, value in SMALL_DOME.items()]

CLOSED_CROWNS = {
    "8 webs closed at the crown": dict(preset="1", n=8, r=1, p=6, cut=0.0),
    "preset 3 at p 4": dict(preset="3", p=4),
    "preset 3 closed at the crown": dict(preset="3", cut=0.0),
}


@pytest.mark.parametrize("inputs", CLOSED_CROWNS.values(), ids=CLOSED_CROWNS.keys())
def test_a_cyclic_section_whose_top_courses_span_the_web_is_its_half(inputs):
    """Near a closed crown a course is one brick across the web, cut by the mid-plane and
    closed by its own cyclic images at both corners: the image's side lands on the other
    half of the brick and is sent across the plane. The run's equilibrium, solved on the
    half, is the whole section's (solved on its own matrices): the same verdict, the same
    unique optimum, and forces that balance every block of the whole."""
    inputs = dict(inputs)
    params = validate(from_preset(inputs.pop("preset"), boundary="cyclic",
                                  accuracy="accurate", **inputs))
    model = build_model(params)[1]
    on_half = solve(model, params, Timer())
    whole = whole_rbe(model, mu=params.analysis.mu)
    assert on_half.solved_on == "half" and whole.verdict == "feasible"
    assert on_half.verdict == whole.verdict
    assert on_half.residual_eq <= 1e-9 and on_half.net_friction_violation <= 1e-9
    scale = np.abs(whole.x).max()
    assert np.abs(on_half.x - whole.x).max() <= FORCE_REL * scale


def test_a_half_whose_forces_fail_on_the_whole_gives_way_to_the_whole(
        tmp_path, monkeypatch, capsys):
    """A map back that loses forces (simulated: the half's forces halved on the way) is
    caught by the residuals recomputed on the whole: the run solves the whole model, says
    so in one line and in run.json, and publishes forces that balance it."""
    from masonry.rbe.mirror import Half

    mapped = Half.whole_forces
    monkeypatch.setattr(Half, "whole_forces", lambda self, x: 0.5 * mapped(self, x))
    out = tmp_path / "out"
    assert main(["run", *SMALL_ARGS, "--boundary", "cyclic", "--no-plots", "--no-printable",
                 "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "the whole model was solved" in said
    record = json.loads(next(out.glob("*/run.json")).read_text())
    assert record["rbe"]["solved_on"] == "whole, the half rejected"
    assert record["rbe"]["verdict"] == "feasible" and record["rbe"]["residual_eq"] <= 1e-5
