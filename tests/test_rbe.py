"""Rigid block equilibrium: matrices by hand, analytic limit states, solver agreement.

Scenes are a few hexahedra with their interfaces built by hand (no detector), so each
test states its physics exactly.
"""

import numpy as np
import pytest

from masonry.blocks import Blocks, tangent_basis
from masonry.interfaces import INTERFACE_KINDS, Interfaces
from masonry.params import Params, validate
from masonry.rbe.equilibrium import VariableLayout, assemble
from masonry.rbe.result import RESULT_KEYS, interface_forces
from masonry.rbe.solve import RBEProblem, solve_rbe
from masonry.tolerances import G, Tolerances

MU = 0.7
DENSITY = 2000.0
SUPPORT, HORIZONTAL = INTERFACE_KINDS.index("support"), INTERFACE_KINDS.index("horizontal")


# ---------------------------------------------------------------------- scene helpers
def box(lo, hi):
    """(8, 3) corners of an axis-aligned box, corner index ix + 2 iy + 4 iz."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    bits = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)])
    return lo + bits * (hi - lo)


def rot_y(theta):
    """Rotation about y taking +z to (sin theta, 0, cos theta)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def make_interfaces(pair, polygons, normals, kind):
    """Interfaces from (main, other) pairs and planar polygons (counter-clockwise about
    the normal), with t1, t2 from :func:`tangent_basis` as the detector will use."""
    polygons = [np.asarray(p, float) for p in polygons]
    normal = np.asarray(normals, float).reshape(-1, 3)
    t1, t2 = tangent_basis(normal)
    area = np.array([0.5 * np.linalg.norm(np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0))
                     for p in polygons])
    return Interfaces(
        pair=np.asarray(pair, dtype=np.int64).reshape(-1, 2),
        kind=np.asarray(kind, dtype=np.int8).reshape(-1),
        vertices=np.concatenate(polygons),
        offsets=np.concatenate([[0], np.cumsum([len(p) for p in polygons])]),
        area=area,
        centre=np.array([p.mean(axis=0) for p in polygons]),  # rectangles only
        normal=normal, t1=t1, t2=t2)


def incline(theta, base, height, width=0.2):
    """A block (base along the slope, height) on a fixed slab tilted by ``theta``.

    The slope descends towards +x. ``tangent_basis`` makes t1 horizontal (along y) and
    t2 point up the slope, so the friction force lies along one pyramid axis and the
    pyramid is exact: the block slides iff tan(theta) > mu and tips over its downhill
    edge iff tan(theta) > base / height.
    """
    rotation = rot_y(theta)
    slab = box((-2, -2, -0.1), (2, 2, 0)) @ rotation.T
    block = box((0, 0, 0), (base, width, height)) @ rotation.T
    blocks = Blocks.from_hexahedra([slab, block], block_class=["ground", "block"],
                                   block_is_support=[True, False])
    interfaces = make_interfaces([(0, 1)], [block[[0, 1, 3, 2]]], [rotation[:, 2]], SUPPORT)
    return blocks, interfaces


def stack(count=3, size=(0.4, 0.2, 0.1)):
    """``count`` equal boxes stacked on a ground slab; bed joints have the lower block as
    main, so their normals point up."""
    sx, sy, sz = size
    corners = [box((-1, -1, -0.1), (1, 1, 0))]
    corners += [box((0, 0, i * sz), (sx, sy, (i + 1) * sz)) for i in range(count)]
    blocks = Blocks.from_hexahedra(corners, block_class=["ground"] + ["block"] * count)
    polygons = [box((0, 0, i * sz), (sx, sy, i * sz))[[0, 1, 3, 2]] for i in range(count)]
    kinds = [SUPPORT] + [HORIZONTAL] * (count - 1)
    return blocks, make_interfaces([(i, i + 1) for i in range(count)], polygons,
                                   [(0, 0, 1)] * count, kinds)


def cantilever(scale=1.0):
    """A 1.0 x 0.5 x 0.2 block whose support reaches only to x = 0.3: the centroid
    (x = 0.5) is outside the contact polygon, so it cannot stand without tension."""
    support = box((-1, -1, -0.2), (0.3, 1, 0)) * scale
    block = box((0, 0, 0), (1.0, 0.5, 0.2)) * scale
    blocks = Blocks.from_hexahedra([support, block], block_class=["ground", "block"])
    polygon = box((0, 0, 0), (0.3, 0.5, 0))[[0, 1, 3, 2]] * scale
    return blocks, make_interfaces([(0, 1)], [polygon], [(0, 0, 1)], SUPPORT)


def vertex_forces(interfaces, layout, x):
    """(IV, 3) force on the other block at every vertex, N."""
    c, t, f1, f2 = (layout.component(x, name)[:, None] for name in layout.COMPONENTS)
    k = layout.vertex_interface
    return (c - t) * interfaces.normal[k] + f1 * interfaces.t1[k] + f2 * interfaces.t2[k]


def block_weight(blocks, index):
    return DENSITY * G * blocks.block_volume[index]


# ---------------------------------------------------------------------- matrices alone
def two_cubes():
    """Unit cubes A (z 0..1) and B (z 1..2), both free, joint A -> B at z = 1, plus C:
    B turned by 90 degrees about z (for force routing)."""
    a, b = box((0, 0, 0), (1, 1, 1)), box((0, 0, 1), (1, 1, 2))
    c = b @ rot_z(np.pi / 2).T
    blocks = Blocks.from_hexahedra([a, b, c], block_class="block",
                                   block_is_support=[False, False, False])
    joint = make_interfaces([(0, 1)], [box((0, 0, 1), (1, 1, 1))[[0, 1, 3, 2]]],
                            [(0, 0, 1)], HORIZONTAL)
    return blocks, joint


def hand_x(layout):
    """Vertices (0,0,1), (1,0,1), (1,1,1), (0,1,1): c = 1000 N at the first, t = 300 N
    at the second, f1 = 200 N (along t1 = +x) at the third."""
    x = np.zeros(layout.n_columns)
    x[layout.columns("c")[0]] = 1000.0
    x[layout.columns("t")[1]] = 300.0
    x[layout.columns("f1")[2]] = 200.0
    return x


# Hand computed. On B: F = (200, 0, 1000 - 300); moments about B's centroid
# (0.5, 0.5, 1.5): (-0.5, -0.5, -0.5) x (0, 0, 1000) = (-500, 500, 0),
# (0.5, -0.5, -0.5) x (0, 0, -300) = (150, 150, 0), (0.5, 0.5, -0.5) x (200, 0, 0) =
# (0, -100, -100). A receives -F about (0.5, 0.5, 0.5): (500, -500, 0) + (-150, -150, 0)
# + (0, -100, 100).
WRENCH_B = np.array([200.0, 0.0, 700.0, -350.0, 550.0, -100.0])
WRENCH_A = np.array([-200.0, 0.0, -700.0, 350.0, -750.0, 100.0])


def test_layout_columns_and_sums():
    layout = VariableLayout(np.array([0, 4, 7]))
    assert layout.n_vertices == 7 and layout.n_columns == 28
    np.testing.assert_array_equal(layout.columns("t")[:3], [1, 5, 9])
    assert layout.vertex_columns(2) == slice(8, 12)
    x = np.arange(28.0)
    np.testing.assert_array_equal(layout.component(x, "f2"), 4 * np.arange(7) + 3)
    np.testing.assert_array_equal(layout.interface_sum(np.ones(7)), [4, 3])


def test_a_eq_matches_hand_computed_wrench():
    blocks, joint = two_cubes()
    system = assemble(blocks, joint, mu=MU, density=DENSITY)
    wrench = system.contact_wrench(hand_x(system.layout))
    np.testing.assert_allclose(wrench[0], WRENCH_A, atol=1e-9)
    np.testing.assert_allclose(wrench[1], WRENCH_B, atol=1e-9)
    np.testing.assert_allclose(wrench[2], 0.0, atol=1e-12)  # C has no interface
    weight = DENSITY * G * 1.0
    np.testing.assert_allclose(system.external_wrench(),
                               np.tile([0, 0, -weight, 0, 0, 0], (3, 1)), atol=1e-9)
    assert system.weight_ref == pytest.approx(weight)
    assert system.length_ref == pytest.approx(1.0)


def test_a_eq_routes_a_side_with_a_rotation():
    # the side of B routed onto C, turned by 90 degrees: what C receives is B's wrench
    # turned, since C's centroid is B's centroid turned (the cyclic-symmetry case)
    blocks, joint = two_cubes()
    rotation = np.stack([np.eye(3), rot_z(np.pi / 2)])[None]
    system = assemble(blocks, joint, side_block=[[0, 2]], side_rotation=rotation)
    wrench = system.contact_wrench(hand_x(system.layout))
    turn = rot_z(np.pi / 2)
    np.testing.assert_allclose(wrench[0], WRENCH_A, atol=1e-9)
    np.testing.assert_allclose(wrench[1], 0.0, atol=1e-12)
    np.testing.assert_allclose(wrench[2, :3], turn @ WRENCH_B[:3], atol=1e-9)
    np.testing.assert_allclose(wrench[2, 3:], turn @ WRENCH_B[3:], atol=1e-9)


def test_supports_have_no_rows_and_friction_rows():
    blocks, interfaces = stack(3)
    system = assemble(blocks, interfaces, mu=MU, cone="square")
    np.testing.assert_array_equal(system.free_block, [1, 2, 3])
    assert system.A_eq.shape == (18, 4 * 12)
    # vertex 0 with c = 1, t = 0.25, f1 = 0.5, f2 = -0.2 (solver units)
    x = np.zeros(system.layout.n_columns)
    x[:4] = [1.0, 0.25, 0.5, -0.2]
    net = system.A_fr["net"] @ x
    plus = system.A_fr["plus"] @ x
    # the square's faces, normals at 90, 180, 270 and 360 degrees: +f2, -f1, -f2, +f1
    np.testing.assert_allclose(net[:4], [-0.2 - 0.75 * MU, -0.5 - 0.75 * MU,
                                         0.2 - 0.75 * MU, 0.5 - 0.75 * MU])
    np.testing.assert_allclose(plus[:4], [-0.2 - MU, -0.5 - MU, 0.2 - MU, 0.5 - MU])
    np.testing.assert_allclose(net[4:], 0.0)


# ---------------------------------------------------------------------- analytic cases
@pytest.mark.parametrize("offset_deg, feasible", [(-2.0, True), (2.0, False)])
def test_squat_block_slides_past_the_friction_angle(offset_deg, feasible):
    theta = np.arctan(MU) + np.radians(offset_deg)
    blocks, interfaces = incline(theta, base=1.0, height=0.1)  # tips only past 84 deg
    result = solve_rbe(blocks, interfaces, mu=MU, friction="net", lp_check=True)
    assert result.feasible is feasible
    assert result.lp_feasible is feasible


@pytest.mark.parametrize("offset_deg, feasible", [(-2.0, True), (2.0, False)])
def test_tall_block_tips_past_base_over_height(offset_deg, feasible):
    base, height = 0.1, 0.4  # base / height = 0.25 < mu: tips before it slides
    theta = np.arctan(base / height) + np.radians(offset_deg)
    blocks, interfaces = incline(theta, base=base, height=height)
    result = solve_rbe(blocks, interfaces, mu=MU, friction="net", lp_check=True)
    assert result.feasible is feasible
    assert result.lp_feasible is feasible


def test_incline_reactions_carry_the_weight():
    theta = np.arctan(MU) - np.radians(2.0)
    blocks, interfaces = incline(theta, base=1.0, height=0.1)
    result = solve_rbe(blocks, interfaces, mu=MU)
    assert result.feasible and result.friction == "net" and result.status == "optimal"
    assert result.residual_eq < 1e-6 and result.friction_violation < 1e-6
    reaction = vertex_forces(interfaces, result.layout, result.x).sum(axis=0)
    weight = block_weight(blocks, 1)
    assert result.weight_N == pytest.approx(weight, rel=1e-12)
    np.testing.assert_allclose(reaction, [0.0, 0.0, weight], atol=1e-6 * weight)
    # no tension in a feasible structure; friction holds the block on the slope
    assert result.moi <= 1e-6 * weight
    assert result.per_interface()["t2"][0] == pytest.approx(weight * np.sin(theta), rel=1e-6)


def test_stack_bed_joints_carry_the_weight_above():
    blocks, interfaces = stack(3)
    result = solve_rbe(blocks, interfaces, mu=MU, lp_check=True)
    assert result.feasible and result.lp_feasible
    assert result.residual_eq < Tolerances().residual
    weight = block_weight(blocks, 1)
    forces = result.per_interface()
    np.testing.assert_allclose(forces["compression"], [3 * weight, 2 * weight, weight],
                               rtol=1e-4)
    np.testing.assert_allclose(forces["normal"], -forces["compression"], rtol=1e-4)
    assert np.abs(forces["tension"]).max() <= 1e-6 * weight
    assert np.abs(forces["friction"]).max() <= 1e-6 * weight
    # the ground's reactions (interface 0, on the bottom block) carry the total weight
    ground = vertex_forces(interfaces, result.layout, result.x)[:4].sum(axis=0)
    assert ground[2] == pytest.approx(result.weight_N, rel=1e-6)
    assert result.weight_N == pytest.approx(3 * weight, rel=1e-12)


@pytest.mark.parametrize("solver, cone", [("osqp", "polygon:16"), ("clarabel", "circle"),
                                          ("clarabel", "polygon:16")])
def test_cantilever_is_infeasible_and_friction_plus_measures_it(solver, cone):
    blocks, interfaces = cantilever()
    net = solve_rbe(blocks, interfaces, mu=MU, friction="net", solver=solver, cone=cone,
                    lp_check=True)
    assert not net.feasible and net.friction == "net"
    assert net.x is None and np.isnan(net.moi)  # no fake optimum
    assert net.lp_feasible is False

    auto = solve_rbe(blocks, interfaces, mu=MU, friction="auto", solver=solver, cone=cone,
                     lp_check=True)
    assert not auto.feasible and auto.friction == "plus" and auto.lp_feasible is False
    assert auto.residual_eq < 1e-5 and auto.friction_violation < 1e-5
    # moments about the support's edge x = 0.3: the weight's arm is 0.2, the tension's
    # (at x = 0) is 0.3, so the least total tension is 2/3 of the weight, and the QP puts
    # it there (any compression at x = 0 would need more tension)
    assert auto.moi_factor == pytest.approx(2.0 / 3.0, rel=1e-4)
    assert auto.net_friction_violation > 0.1


def test_verdict_follows_the_residuals_not_the_status(caplog):
    caplog.set_level("INFO", logger="masonry")  # fallbacks are logged at INFO
    # an impossible tolerance: the solver still says "optimal", the result must not
    blocks, interfaces = stack(2)
    result = solve_rbe(blocks, interfaces, mu=MU, solver="clarabel",
                       tol=Tolerances(residual=1e-30))
    assert result.status == "optimal" and not result.feasible and result.x is None
    assert np.isfinite(result.residual_eq) and result.residual_eq < 1e-8  # reported
    assert "rejected" in caplog.text


def test_moi_factor_and_feasibility_do_not_depend_on_the_unit():
    base = solve_rbe(*cantilever(), mu=MU)
    scaled = solve_rbe(*cantilever(scale=0.01), mu=MU)
    assert scaled.feasible == base.feasible
    assert scaled.moi_factor == pytest.approx(base.moi_factor, rel=1e-4)


def test_osqp_and_clarabel_agree_on_a_feasible_case():
    # H is positive definite, so the minimiser is unique and both must find it; every
    # vertex force within 1e-6 of the weight (measured: 3e-8); OSQP takes the pyramids
    theta = np.arctan(0.25) - np.radians(2.0)
    blocks, interfaces = incline(theta, base=0.1, height=0.4)
    osqp = solve_rbe(blocks, interfaces, mu=MU, solver="osqp", cone="polygon:16")
    clarabel = solve_rbe(blocks, interfaces, mu=MU, solver="clarabel", cone="polygon:16")
    assert osqp.feasible and clarabel.feasible
    np.testing.assert_allclose(osqp.x, clarabel.x, rtol=0, atol=1e-6 * osqp.weight_N)
    assert osqp.objective == pytest.approx(clarabel.objective, rel=1e-6)


def test_result_dict_and_interface_forces():
    blocks, interfaces = stack(2)
    result = solve_rbe(blocks, interfaces, mu=MU)
    record = result.to_dict()
    assert tuple(record) == RESULT_KEYS
    assert all(isinstance(v, (bool, int, float, str, type(None))) for v in record.values())
    forces = interface_forces(result.layout, result.x)
    assert set(forces) == {"compression", "tension", "normal", "t1", "t2", "friction"}
    assert all(v.shape == (2,) for v in forces.values())


def test_rejects_unknown_options():
    blocks, interfaces = stack(1)
    with pytest.raises(ValueError):
        solve_rbe(blocks, interfaces, friction="cone")
    with pytest.raises(ValueError):
        solve_rbe(blocks, interfaces, solver="gurobi")


@pytest.mark.parametrize("thickness, stands", [(0.4, True), (0.1, False)])
def test_friction_plus_alone_says_cannot_stand_only_where_the_structure_cannot(
        thickness, stands):
    """A semicircular arch of 8 voussoirs (R = 2 m) stands at t/R = 0.2 and not at 0.05,
    below Heyman's minimum of about 0.107. Asked for friction+ alone, the optimum carries
    some tension either way (it trades compression for a little tension), so its MoI is
    no verdict: friction-net decides, and the MoI stays the thesis's measure."""
    from masonry.pipeline import build_model

    params = validate(Params.of(scene="arch", arch_blocks=8, arch_span=4,
                                arch_thickness=thickness, arch_depth=0.5))
    model = build_model(params)[1]
    result = RBEProblem(model.blocks, model.interfaces, **model.assembly).solve(
        friction="plus")
    assert result.friction == "plus" and result.moi > 0
    assert result.verdict == ("feasible" if stands else "infeasible")
    assert result.feasible is stands
    assert any(a["friction"] == "net" for a in result.attempts)
