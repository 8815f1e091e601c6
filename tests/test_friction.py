"""Coulomb's isotropic friction (docs/model.md 6.3): analytic sliding, tipping and torsion of single
blocks under each friction model, results that do not depend on how the joints' axes are
chosen, and the own solvers of the cone against Clarabel's second-order cone program."""

import dataclasses

import numpy as np
import pytest
from test_rbe import box

from masonry.blocks import Blocks
from masonry.friction import FrictionCone
from masonry.interfaces import detect
from masonry.pipeline import build_model
from masonry.params import Params, from_preset, validate
from masonry.rbe.boundary import Model, analysis_model
from masonry.rbe.collapse import ANISOTROPIC_NOTE, CollapseLP, collapse_load
from masonry.rbe.loads import LiveLoad, lateral
from masonry.rbe.solve import RBEProblem
from masonry.scenes import build
from masonry.tolerances import G, Tolerances

DENSITY = 2000.0
TILT_MU = float(np.tan(np.radians(20.0)))  # 3DEC's tilting block: friction angle 20 deg
MODELS = ("circle", "polygon:16", "polygon:8", "square")
SMALL_DOME = dict(stretch=1.0, n=6, r=0, p=3, cut=0.5)  # 72 bricks in 6 webs, on 6 slabs


def turned_block(size, turn_deg):
    """A block ``size = (bx, by, h)`` on a ground slab, turned about z by ``turn_deg``
    about its own axis: its bed joint (found by the interface detector) has its axes
    along the block's sides, so they turn with it."""
    bx, by, h = size
    block = box((-bx / 2, -by / 2, 0.0), (bx / 2, by / 2, h))
    angle = np.radians(turn_deg)
    rotation = np.array([[np.cos(angle), -np.sin(angle), 0.0],
                         [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    slab = box((-4 * bx - 4 * by, -4 * bx - 4 * by, -0.1 * h), (4 * bx + 4 * by,
                                                                4 * bx + 4 * by, 0.0))
    blocks = Blocks.from_hexahedra([slab, block @ rotation.T], block_class=["ground", "block"],
                                   block_is_support=[True, False])
    return Model(blocks, detect(blocks))


def capacity_bounds(name):
    least, most = FrictionCone.parse(name).capacity_range
    return least, most


# ---------------------------------------------------------------------- sliding
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("turn, azimuth", [(0.0, 0.0), (0.0, 17.0), (0.0, 30.0),
                                           (0.0, 45.0), (30.0, 0.0), (45.0, 45.0)])
def test_the_tilting_block_slides_at_mu_in_every_direction(name, turn, azimuth):
    """A 10 x 10 x 5 m block with a 20 degree friction angle, turned on the slab by
    ``turn``, under a horizontal body force at ``azimuth`` (the tilting table): Coulomb's
    block slides at lambda = tan 20 in every direction. A polygon carries between mu
    cos(pi/K) and mu; the square mu / max(|cos|, |sin|) of the angle between the load
    and the joint's axes (those of the slab's face, the joint's main face), up to
    sqrt(2) mu at 45 degrees."""
    model = turned_block((10.0, 10.0, 5.0), turn)
    result = collapse_load(model, lateral(model, azimuth, DENSITY), mu=TILT_MU,
                           density=DENSITY, cone=name)
    least, most = capacity_bounds(name)
    assert least * TILT_MU * (1 - 1e-7) <= result.load_factor <= most * TILT_MU * (1 + 1e-7)
    assert result.slides.all() and not result.hinge.any()
    if name == "circle":
        assert result.load_factor == pytest.approx(TILT_MU, rel=1e-6)
    if name == "square":
        frame = model.interfaces.t1[0]
        angle = np.radians(azimuth) - np.arctan2(frame[1], frame[0])
        expected = TILT_MU / max(abs(np.cos(angle)), abs(np.sin(angle)))
        assert result.load_factor == pytest.approx(expected, rel=1e-6)
        assert result.note is not None and ANISOTROPIC_NOTE in result.note
    else:
        assert result.note is None or ANISOTROPIC_NOTE not in result.note


@pytest.mark.parametrize("name", ["circle", "polygon:16"])
def test_a_squat_block_on_a_slope_steeper_than_the_friction_angle_cannot_stand(name):
    """Self weight alone, the slab tilted about several horizontal axes: the block stands
    iff tan(slope) <= mu (within the model's bound), in every direction of tilt."""
    for direction in (0.0, 25.0, 45.0, 70.0):
        for offset, stands in ((-1.0, True), (1.0, False)):
            slope = np.arctan(0.5) + np.radians(offset)
            model = tilted_block(slope, direction)
            result = RBEProblem(model.blocks, model.interfaces).solve(
                mu=0.5, density=DENSITY, friction="net", cone=name)
            assert result.verdict == ("feasible" if stands else "infeasible"), direction


def tilted_block(slope, direction_deg, size=(1.0, 1.0, 0.2)):
    """A squat block on a slab tilted by ``slope`` radians, the slope falling towards
    the azimuth ``direction_deg``; the block's sides along x and y before the tilt."""
    angle = np.radians(direction_deg)
    axis = np.array([-np.sin(angle), np.cos(angle), 0.0])  # horizontal, across the fall
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + np.sin(slope) * k + (1 - np.cos(slope)) * k @ k
    bx, by, h = size
    block = box((-bx / 2, -by / 2, 0.0), (bx / 2, by / 2, h)) @ rotation.T
    slab = box((-3, -3, -0.1), (3, 3, 0.0)) @ rotation.T
    blocks = Blocks.from_hexahedra([slab, block], block_class=["ground", "block"],
                                   block_is_support=[True, False])
    return Model(blocks, detect(blocks))


# ---------------------------------------------------------------------- tipping
@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("azimuth, ratio", [(0.0, 1.0), (90.0, 1.0), (45.0, np.sqrt(2.0)),
                                            (225.0, np.sqrt(2.0))])
def test_a_tall_block_tips_at_b_over_h_or_over_its_corner(name, azimuth, ratio):
    """A square-based tall block (b/h = 0.25, mu = 0.8, never sliding first): it tips
    about a base edge at lambda = b/h, over a corner at sqrt(2) b/h, whatever the
    friction model (tipping asks nothing of friction)."""
    model = turned_block((0.25, 0.25, 1.0), 0.0)
    result = collapse_load(model, lateral(model, azimuth, DENSITY), mu=0.8, density=DENSITY,
                           cone=name)
    assert result.load_factor == pytest.approx(0.25 * ratio, rel=1e-6)
    assert result.hinge.all() and not result.main_slides.any()


# ---------------------------------------------------------------------- torsion
def torque(model, moment=1.0):
    """A pure couple ``moment`` N m about z on every free block."""
    wrench = np.zeros((model.blocks.n_blocks, 6))
    wrench[~model.blocks.block_is_support, 5] = moment
    return LiveLoad(wrench, {"kind": "torque", "moment_Nm": moment})


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("turn", [0.0, 30.0])
def test_torsion_of_a_square_dry_joint(name, turn):
    """A bar on a pedestal under a couple: the joint's four corner contacts each carry
    N/4 and slide perpendicular to their diagonal, at s / sqrt(2) from the centre of a
    square of side s: T = k mu N s with k = 1 / sqrt(2) = 0.707 under the cone (the vertex
    model; a continuous uniform pressure gives 0.383, docs/collapse.md). A polygon's
    corner carries between cos(pi/K) and 1 of that; the square's corners slide at 45
    degrees to its axes, where it carries sqrt(2) mu: k = 1."""
    side, mu = 0.4, 0.6
    model = turned_block((side, side, 1.0), turn)
    weight = DENSITY * G * side * side * 1.0
    result = collapse_load(model, torque(model), mu=mu, density=DENSITY, cone=name)
    k = result.load_factor / (mu * weight * side)
    if name == "square":
        phi = np.radians(45.0 + turn)
        assert k == pytest.approx((abs(np.cos(phi)) + abs(np.sin(phi))) / np.sqrt(2),
                                  rel=1e-6)
    else:
        least, _ = capacity_bounds(name)
        assert least / np.sqrt(2) * (1 - 1e-7) <= k <= 1 / np.sqrt(2) * (1 + 1e-7)
    if name == "circle":
        assert k == pytest.approx(1 / np.sqrt(2), rel=1e-6)
    assert result.slides.all()


# ---------------------------------------------------------------------- invariance
def turned_axes(model, seed):
    """The same model with every joint's in-plane axes (t1, t2) turned by a random angle:
    the frame the friction components are reported in, which the physics must not
    see."""
    interfaces = model.interfaces
    angle = np.random.default_rng(seed).uniform(0, 2 * np.pi, size=len(interfaces))
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    t1 = c * interfaces.t1 + s * interfaces.t2
    t2 = -s * interfaces.t1 + c * interfaces.t2
    return dataclasses.replace(model, interfaces=dataclasses.replace(interfaces, t1=t1,
                                                                     t2=t2))


def free_section():
    """Preset 3 with p = 5 as a free-standing section: 135 bricks, infeasible."""
    return build_model(from_preset("3", p=5, boundary="free"))[1]


@pytest.mark.parametrize("name", ["circle", "polygon:16"])
def test_the_equilibrium_does_not_depend_on_the_joints_axes(name):
    """Turning every joint's axes by a random angle leaves the verdict and the MoI
    factor of an infeasible section within the model's bound (the circle: to the
    solvers' accuracy), and the forces' magnitudes with them."""
    model = free_section()
    results = [RBEProblem(m.blocks, m.interfaces).solve(mu=0.7, density=DENSITY, cone=name)
               for m in (model, turned_axes(model, 1), turned_axes(model, 2))]
    bound = FrictionCone.parse(name).capacity_error
    for result in results:
        assert result.verdict == "infeasible"
        # the tension needed grows at most as the capacity falls (a crude but safe
        # bound for a polygon; the circle's results are the same point)
        assert result.moi_factor == pytest.approx(results[0].moi_factor,
                                                  rel=max(2 * bound, 1e-6))
    if name == "circle":
        friction = [np.hypot(*[r.layout.component(r.x, k) for k in ("f1", "f2")])
                    for r in results]
        scale = np.abs(results[0].x).max()
        for other in friction[1:]:
            np.testing.assert_allclose(other, friction[0], rtol=0, atol=1e-6 * scale)


def test_the_square_pyramid_depends_on_the_joints_axes():
    """The thesis's pyramid is not isotropic: the same section's MoI factor moves with
    the joints' axes by more than any isotropic model's bound, and its result says
    so."""
    model = free_section()
    base = RBEProblem(model.blocks, model.interfaces).solve(mu=0.7, cone="square")
    turned = turned_axes(model, 1)
    moved = RBEProblem(turned.blocks, turned.interfaces).solve(mu=0.7, cone="square")
    assert abs(moved.moi_factor / base.moi_factor - 1) > 0.02
    assert not base.cone.is_isotropic and base.friction_capacity_error == pytest.approx(
        np.sqrt(2) - 1)


@pytest.mark.parametrize("name", ["circle", "polygon:16"])
@pytest.mark.parametrize("azimuth", [0.0, 17.0, 45.0])
def test_the_collapse_factor_does_not_depend_on_the_joints_axes(name, azimuth):
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    live = lateral(dome, azimuth, DENSITY)
    factors = [collapse_load(m, live, mu=0.7, density=DENSITY, cone=name,
                             dead_load_feasible=True).load_factor
               for m in (dome, turned_axes(dome, 3))]
    bound = FrictionCone.parse(name).capacity_error
    assert factors[1] == pytest.approx(factors[0], rel=max(bound, 1e-6))


@pytest.mark.parametrize("turn", [17.0, 30.0, 45.0])
def test_a_dome_turned_about_z_with_its_load_gives_the_same_results(turn):
    """Turning the whole model about the vertical axis, and its lateral load with it,
    changes nothing: the verdict, the MoI factor of an infeasible section, the load
    factor and the mechanism's joints."""
    scene = build(validate(Params.of(scene="dome", **SMALL_DOME)))
    angle = np.radians(turn)
    motion = np.eye(4)
    motion[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
    turned = dataclasses.replace(scene, blocks=scene.blocks.transformed(motion),
                                 block_up=scene.block_up @ motion[:3, :3].T,
                                 block_inward=scene.block_inward @ motion[:3, :3].T)
    results = []
    for s, azimuth in ((scene, 10.0), (turned, 10.0 + turn)):
        model = analysis_model(s, "free")
        rbe = RBEProblem(model.blocks, model.interfaces).solve(mu=0.7, density=DENSITY)
        collapse = collapse_load(model, lateral(model, azimuth, DENSITY), mu=0.7,
                                 density=DENSITY, dead_load_feasible=rbe.feasible)
        results.append((rbe, collapse))
    (rbe_a, col_a), (rbe_b, col_b) = results
    assert rbe_a.verdict == rbe_b.verdict == "feasible"
    assert col_b.load_factor == pytest.approx(col_a.load_factor, rel=1e-6)
    np.testing.assert_array_equal(col_b.main_hinge, col_a.main_hinge)


# ---------------------------------------------------------------------- against Clarabel
@pytest.mark.parametrize("boundary", ["free", "cyclic"])
def test_the_own_solvers_of_the_cone_find_clarabels_optimum(boundary):
    """The RBE QP with Coulomb's cone: the presets' path (semismooth Newton on the
    cone's projection; the interior point method with Nesterov-Todd scaling and a Newton
    polish for friction+) against Clarabel's second-order cone program, stated by cvxpy:
    the same verdict, MoI factor and vertex forces."""
    model = build_model(from_preset("3", p=5, boundary=boundary))[1]

    def solve(**options):
        return RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                          side_rotation=model.side_rotation).solve(mu=0.7, **options)

    ours = solve()
    reference = solve(solver="clarabel-cvxpy", accuracy="accurate", lp_check=False)
    assert ours.verdict == reference.verdict
    assert ours.friction_model == reference.friction_model == "circle"
    scale = np.abs(reference.x).max()
    # (Clarabel stops in the interior: a feasible structure keeps a tension residue of
    # the order of its tolerance)
    assert ours.moi_factor == pytest.approx(reference.moi_factor, rel=1e-6,
                                            abs=Tolerances().residual)
    np.testing.assert_allclose(ours.x, reference.x, rtol=0, atol=1e-5 * scale)
    assert ours.residual_eq <= Tolerances().residual
    # the forces lie in the cone, vertex by vertex
    c, t, f1, f2 = ours.x.reshape(-1, 4).T
    load = c - t if ours.friction == "net" else c
    assert (np.hypot(f1, f2) - 0.7 * load).max() <= Tolerances().residual * scale


@pytest.mark.parametrize("azimuth", [0.0, 30.0])
@pytest.mark.slow
def test_the_collapse_lp_of_the_cone_finds_clarabels_optimum(azimuth):
    """The collapse load factor with Coulomb's cone: the own interior point method
    (Nesterov-Todd scaling on the Newton system) against Clarabel's second-order cone
    program on the 72-brick dome, between the inscribed and circumscribed 16-sided
    pyramids' factors (HiGHS's dual simplex)."""
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    live = lateral(dome, azimuth, DENSITY)
    ours = CollapseLP(dome, cone="circle").solve(live, dead_load_feasible=True)
    reference = CollapseLP(dome, cone="circle", method="clarabel").solve(
        live, dead_load_feasible=True)
    assert ours.solver == "interior" and reference.solver == "clarabel"
    assert ours.load_factor == pytest.approx(reference.load_factor, rel=1e-6)
    inner = CollapseLP(dome, cone="polygon:16", method="highs-simplex").solve(
        live, dead_load_feasible=True).load_factor
    outer = CollapseLP(dome, mu=0.7 / np.cos(np.pi / 16), cone="polygon:16",
                       method="highs-simplex").solve(live, dead_load_feasible=True).load_factor
    assert inner <= ours.load_factor <= outer
    # the square pyramid's factor is higher: it carries more friction diagonally
    square = CollapseLP(dome, cone="square").solve(live, dead_load_feasible=True)
    assert square.load_factor > 1.1 * ours.load_factor


# ---------------------------------------------------------------------- outputs
def test_every_output_of_a_run_states_the_friction_model(tmp_path, capsys):
    """run.json, RBE/00_objective.txt and collapse/00_collapse.txt name the model and its
    bound; the square's results say they depend on the joints' axes; the folder of a
    model other than the preset's carries its name."""
    from masonry_cli.main import main
    import json

    common = ["run", "--scene", "dome", "--stretch", "1", "--n", "6", "--r", "0", "--p", "3",
              "--cut", "0.5", "--lateral", "0", "--no-plots", "--no-printable", "--out",
              str(tmp_path)]
    assert main(common) == 0
    assert main(common + ["--friction-cone", "square"]) == 0
    out = capsys.readouterr().out
    assert "friction model circle" in out and "friction model square" in out
    assert out.count("note: the square friction model is the thesis's pyramid") == 1
    (default,) = [p for p in tmp_path.glob("fulldome_*") if "_cone" not in p.name]
    (square,) = tmp_path.glob("fulldome_*_conesquare_lat0")
    for folder, name, error in ((default, "circle", 0.0), (square, "square", np.sqrt(2) - 1)):
        record = json.loads((folder / "run.json").read_text())
        for key in ("rbe", "collapse"):
            assert record[key]["friction_model"] == name
            assert record[key]["friction_capacity_error"] == pytest.approx(error)
        objective = (folder / "RBE" / "00_objective.txt").read_text()
        collapse = (folder / "collapse" / "00_collapse.txt").read_text()
        for text in (objective, collapse):
            assert f"friction model:     {name}" in text
            assert ("41 %" in text) == (name == "square")
    square_record = json.loads((square / "run.json").read_text())["collapse"]
    assert "41 %" in square_record["note"]
    default_record = json.loads((default / "run.json").read_text())["collapse"]
    assert square_record["load_factor"] > default_record["load_factor"]
