"""Collapse load factors and mechanisms (docs/model.md 6.8, 6.9) against analytic limit states and
an independent 2D linear program on the arch's voussoirs."""

import csv
import dataclasses
import functools
import itertools
import json
import shlex

import meshio
import numpy as np
import pytest
from scipy.optimize import linprog

import masonry
from masonry import forking
from masonry.blocks import Blocks
from masonry import pipeline
from masonry.pipeline import build_model
from masonry.params import ParameterError, Params, from_preset, validate
from masonry.rbe.azimuth_refine import MAX_SOLVES, floor_between, refine_least
from masonry.rbe.boundary import Model
from masonry.rbe.collapse import (UNBOUNDED_NOTE, CollapseLP, CollapseResult,
                                  collapse_load, fixed_capacity_factor)
from masonry.rbe.lateral_search import lateral_azimuths, symmetric_key, worst_lateral
from masonry.rbe.loads import PointLoads, crown_load, lateral, point_loads
from masonry.rbe.solvers.interior_lp import LoadFactorOptions
from masonry.scenes.arch import arch_profile
from masonry.studies.structures import lateral_record
from masonry.studies.thrust_line import thrust_line_minimum_thickness
from masonry.tolerances import FACTOR_TIE_REL, MECHANISM_MAIN, G
from masonry_cli.main import main
from test_rbe import HORIZONTAL, SUPPORT, box, make_interfaces

DENSITY = 2000.0
LP_RESIDUAL = LoadFactorOptions().primal_tol
"""The collapse LP's documented accuracy: its interior point method stops once the primal
rows hold to this fraction of the largest load entry (the factor itself is checked
against statics to 1e-6); below it the residual depends on the BLAS kernels' rounding
(OpenBLAS's Haswell kernels leave 4.6e-9 where others leave 1e-12)."""
SMALL_DOME = dict(stretch=1.0, n=6, r=0, p=3, cut=0.5)  # 72 bricks in 6 webs, on 6 slabs


def column(count, size):
    """``count`` boxes ``size = (bx, by, h)`` stacked on a ground slab, bed joints
    whole rectangles with the lower block as main (normals up)."""
    bx, by, h = size
    corners = [box((-1, -1, -0.1), (1, 1, 0))]
    corners += [box((0, 0, i * h), (bx, by, (i + 1) * h)) for i in range(count)]
    blocks = Blocks.from_hexahedra(corners, block_class=["ground"] + ["block"] * count,
                                   block_name=["ground"] + [f"b{i}" for i in range(count)])
    polygons = [box((0, 0, i * h), (bx, by, i * h))[[0, 1, 3, 2]] for i in range(count)]
    kinds = [SUPPORT] + [HORIZONTAL] * (count - 1)
    interfaces = make_interfaces([(i, i + 1) for i in range(count)], polygons,
                                 [(0, 0, 1)] * count, kinds)
    return Model(blocks, interfaces)


def check_mechanism(model, live, result):
    """Independently of the LP: the mechanism's virtual work balances (lambda W_live +
    W_dead = 0) and no interface vertex penetrates."""
    blocks, interfaces, motion = model.blocks, model.interfaces, result.mechanism
    weight = DENSITY * G * blocks.block_volume * ~blocks.block_is_support
    work_dead = -(weight * motion[:, 2]).sum()
    work_live = (live.wrench * motion).sum()
    assert abs(result.load_factor * work_live + work_dead) <= 1e-7 * abs(work_dead)
    vertex = interfaces.vertices
    k = np.repeat(np.arange(len(interfaces)), interfaces.vertex_count)
    main_block, other = interfaces.pair[k, 0], interfaces.pair[k, 1]

    def moved(block):
        arm = vertex - blocks.block_centroid[block]
        return motion[block, :3] + np.cross(motion[block, 3:], arm)

    relative = moved(other) - moved(main_block)
    opening = np.einsum("ij,ij->i", relative, interfaces.normal[k])
    assert opening.min() >= -1e-7
    # each joint's largest opening and slip, from the blocks' motions
    gap, slip = np.zeros(len(interfaces)), np.zeros(len(interfaces))
    np.maximum.at(gap, k, opening)
    np.maximum.at(slip, k, np.linalg.norm(
        relative - opening[:, None] * interfaces.normal[k], axis=1))
    assert np.abs(result.gap - gap).max() <= 1e-7
    assert np.abs(result.slip - slip).max() <= 1e-7
    # normalised: the largest vertex displacement of any block is 1
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    arm = blocks.vertices - blocks.block_centroid[owner]
    largest = np.linalg.norm(motion[owner, :3] + np.cross(motion[owner, 3:], arm), axis=1)
    assert largest.max() == pytest.approx(1.0, rel=1e-12)


# ---------------------------------------------------------------------- analytic blocks
@pytest.mark.parametrize("azimuth, expected, mode", [
    (0.0, 0.2 / 0.5, "tips"),       # b = 0.2 along x: tips at b/h = 0.4 < mu
    (180.0, 0.2 / 0.5, "tips"),
    (90.0, 0.7, "slides"),          # b = 0.4 along y: b/h = 0.8 > mu = 0.7, slides
    (270.0, 0.7, "slides"),
])
def test_single_block_tips_at_b_over_h_or_slides_at_mu(azimuth, expected, mode):
    model = column(1, (0.2, 0.4, 0.5))
    live = lateral(model, azimuth, DENSITY)
    result = collapse_load(model, live, mu=0.7, density=DENSITY)
    assert result.load_factor == pytest.approx(expected, rel=1e-6)
    assert result.dead_load_feasible and result.residual <= LP_RESIDUAL
    assert result.hinge.all() == (mode == "tips")
    assert result.slides.all() == (mode == "slides")
    assert (result.note is not None) == (mode == "slides")
    # normalised to a largest displacement of 1: tipping about a base edge opens the far
    # edge by b / sqrt(b^2 + h^2) (its top corner moves 1); sliding with the associated
    # dilation moves the block by (1, mu) / sqrt(1 + mu^2) along and off the joint
    if mode == "tips":
        assert result.gap[0] == pytest.approx(0.2 / np.hypot(0.2, 0.5), rel=1e-6)
        assert result.slip[0] == pytest.approx(0.0, abs=1e-6)
    else:
        assert result.gap[0] == pytest.approx(0.7 / np.hypot(1, 0.7), rel=1e-6)
        assert result.slip[0] == pytest.approx(1 / np.hypot(1, 0.7), rel=1e-6)
    check_mechanism(model, live, result)


@pytest.mark.parametrize("count", [2, 4])
def test_column_tips_at_b_over_its_whole_height(count):
    model = column(count, (0.1, 0.3, 0.15))
    live = lateral(model, 0.0, DENSITY)
    result = collapse_load(model, live, mu=0.9, density=DENSITY)
    assert result.load_factor == pytest.approx(0.1 / (0.15 * count), rel=1e-6)
    # the whole column rotates as one about its base: only the base joint opens
    assert result.opens.tolist() == [True] + [False] * (count - 1)
    check_mechanism(model, live, result)


@pytest.mark.parametrize("force", [1e-6, 100.0, 1e15])
def test_point_load_at_the_top_face_tips_a_block_at_the_lever_ratio(force):
    """A horizontal point force P at the top of a block of weight W tips it when
    P h = W b / 2, i.e. lambda = W b / (2 P h), whatever the size of P."""
    model = column(1, (0.2, 0.4, 0.5))
    live = point_loads(model.blocks, [f"b*:{force!r},0,0"])
    weight = DENSITY * G * 0.2 * 0.4 * 0.5
    result = collapse_load(model, live, mu=0.9, density=DENSITY)
    assert result.load_factor == pytest.approx(weight * 0.1 / (force * 0.5), rel=1e-6)
    assert result.residual <= LP_RESIDUAL
    check_mechanism(model, live, result)


def test_the_joints_that_carry_a_mechanism_move_by_a_share_of_the_largest():
    """Of the joints that move at all, those within MECHANISM_MAIN of the largest opening
    (hinges) or slip (sliding) carry the mechanism."""
    flags = np.array([True, True, True, False])
    gap = np.array([1.0, 0.9 * MECHANISM_MAIN, 1.1 * MECHANISM_MAIN, 2.0])
    result = CollapseResult(0.5, True, "optimal", solver="", iterations=0, time_s=0.0,
                            residual=0.0, work_balance=0.0, mu=0.7, live=None,
                            opens=flags, hinge=flags, gap=gap, slides=~flags,
                            slip=np.array([0.0, 0.0, 0.0, 0.01]))
    assert result.main_hinge.tolist() == [True, False, True, False]
    assert result.main_slides.tolist() == [False, False, False, True]
    assert (result.main_hinges, result.main_sliding) == (2, 1)


def test_a_point_load_spec_that_matches_no_block_or_cancels_is_refused():
    blocks = column(1, (0.2, 0.4, 0.5)).blocks
    with pytest.raises(ParameterError, match="point_loads"):
        point_loads(blocks, ["nothing*:1,0,0"])
    with pytest.raises(ParameterError, match="do not cancel"):
        point_loads(blocks, ["b0:100,0,0", "b*:-100,0,0"])


def test_a_point_load_on_no_block_is_refused_naming_the_option(tmp_path, capsys):
    code = main(["run", "--preset", "wall", "--point-load", "zzz:0,0,-1", "--out",
                 str(tmp_path), "--no-plots", "--no-printable"])
    error = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(error) == 1 and not any(tmp_path.iterdir())
    assert error[0].startswith("masonry: error: --point-load zzz:0,0,-1: expected a name")



def test_point_loads_name_their_folder_as_written_where_they_are_short_and_plain():
    """Names and numbers alone, up to 40 characters: the specs in the id, ``:`` as ``@``,
    joined by ``+``; a pattern, an exponent's ``+`` or a long list: a digest. Two lists
    never share a name (the tag's ``@`` and ``+`` are not in a plain spec)."""
    tag = lambda *specs: PointLoads.parse(list(specs)).tag
    assert tag("w0_b0123:0,0,-1000") == "_pl_w0_b0123@0,0,-1000"
    assert tag("a:1,2,3", "b:4,5,6") == "_pl_a@1,2,3+b@4,5,6"
    for digest in (tag("w*:0,0,-1"), tag("b0:1e+3,0,0"), tag(*[f"b{i}:0,0,-1" for i in range(9)])):
        assert len(digest) == 11 and digest.startswith("_pl") and "@" not in digest
    assert tag("a:1,2,3", "b:4,5,6") != tag("b:4,5,6", "a:1,2,3")

def test_free_wall_overturns_out_of_plane_at_t_over_h():
    params = from_preset("wall")
    model = build_model(params)[1]
    free = ~model.blocks.block_is_support
    bounds = model.blocks.block_bounds[free]
    thickness = bounds[:, 1, 0].max() - bounds[:, 0, 0].min()
    height = bounds[:, 1, 2].max() - bounds[:, 0, 2].min()
    length = bounds[:, 1, 1].max() - bounds[:, 0, 1].min()
    assert length > 10 * thickness  # the wall runs along y: x is out of plane
    live = lateral(model, 0.0, DENSITY)
    result = collapse_load(model, live, mu=0.7, density=DENSITY)
    assert result.load_factor == pytest.approx(thickness / height, rel=1e-7)
    check_mechanism(model, live, result)


# ---------------------------------------------------------------------- the arch
def arch_lp(profile, depth, mu, density=DENSITY):
    """The largest horizontal load factor of an arch by a 2D LP written here, apart from
    the RBE matrices: per joint, compressive forces at its intrados and extrados ends and
    one shear with |shear| <= mu (sum of the normal forces); per voussoir, force and
    moment balance in the xz-plane under its weight and lambda times its weight along
    +x. Joints 0 and N bear on the supports."""
    joints = len(profile.intrados)
    voussoirs = profile.voussoirs
    x, z = voussoirs[..., 0], voussoirs[..., 1]
    cross = x * np.roll(z, -1, axis=1) - np.roll(x, -1, axis=1) * z
    area = cross.sum(axis=1) / 2
    centroid = np.stack([((x + np.roll(x, -1, axis=1)) * cross).sum(axis=1),
                         ((z + np.roll(z, -1, axis=1)) * cross).sum(axis=1)], axis=1)
    centroid /= 6 * area[:, None]
    weight = density * G * np.abs(area) * depth
    # joint j: unit normal from voussoir j-1 into voussoir j (towards the left springing)
    along = profile.extrados - profile.intrados
    normal = np.stack([-along[:, 1], along[:, 0]], axis=1)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    # orient: joint 0's normal points into voussoir 0, every next one the same way round
    middle = (profile.intrados + profile.extrados) / 2
    for j in range(joints):
        inside = centroid[min(j, len(centroid) - 1)] - middle[j]
        sign = 1 if j < len(centroid) else -1
        if sign * (normal[j] @ inside) < 0:
            normal[j] *= -1
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
    # unknowns per joint: n_intrados, n_extrados, shear; then lambda
    count = 3 * joints + 1
    A, b = np.zeros((3 * len(voussoirs), count)), np.zeros(3 * len(voussoirs))
    for i in range(len(voussoirs)):
        for j, sign in ((i, 1.0), (i + 1, -1.0)):  # joint i pushes on i, joint i+1 back
            for col, (point, direction) in enumerate((
                    (profile.intrados[j], normal[j]), (profile.extrados[j], normal[j]),
                    (middle[j], tangent[j]))):
                arm = point - centroid[i]
                A[3 * i: 3 * i + 3, 3 * j + col] += sign * np.array(
                    [direction[0], direction[1], arm[0] * direction[1] - arm[1] * direction[0]])
        A[3 * i, -1] = weight[i]
        b[3 * i + 1] = weight[i]
    friction = np.zeros((2 * joints, count))
    for j in range(joints):
        friction[2 * j, [3 * j, 3 * j + 1, 3 * j + 2]] = (-mu, -mu, 1.0)
        friction[2 * j + 1, [3 * j, 3 * j + 1, 3 * j + 2]] = (-mu, -mu, -1.0)
    bounds = [(0, None), (0, None), (None, None)] * joints + [(None, None)]
    cost = np.zeros(count)
    cost[-1] = -1.0
    solution = linprog(cost, A_ub=friction, b_ub=np.zeros(2 * joints), A_eq=A, b_eq=b,
                       bounds=bounds, method="highs")
    assert solution.status == 0
    return solution.x[-1]


def arch_model(thickness, blocks=12):
    params = validate(Params.of(scene="arch", arch_blocks=blocks, arch_thickness=thickness))
    return params, build_model(params)[1]


@pytest.mark.parametrize("thickness, mu, method, cone", [
    (1.0, 0.9, "interior", "circle"), (1.6, 0.5, "interior", "circle"),
    (1.0, 0.9, "clarabel", "circle"), (1.0, 0.9, "interior", "polygon:16"),
    (1.0, 0.9, "highs-crossover", "polygon:16"), (1.0, 0.9, "interior", "square")])
def test_arch_under_horizontal_load_matches_an_independent_2d_lp(thickness, mu, method,
                                                                 cone):
    # the arch slides in its plane, along each joint's t2 axis: every model carries
    # mu c there (the polygons have an edge ray along it), the 2D LP's Coulomb law
    params, model = arch_model(thickness)
    live = lateral(model, 0.0, DENSITY)
    result = CollapseLP(model, mu=mu, density=DENSITY, method=method, cone=cone).solve(live)
    profile = arch_profile("semicircular", 12, params.geometry.arch_span, thickness)
    assert result.load_factor == pytest.approx(arch_lp(profile, params.geometry.arch_depth, mu),
                                               rel=1e-6)
    assert result.hinges >= 3  # a hinge mechanism: four hinges, or sliding with fewer
    check_mechanism(model, live, result)


def test_lateral_factor_vanishes_at_the_minimum_thickness_and_below_it_none():
    """lambda falls to 0 as the thickness approaches the minimum of the thrust line
    (:mod:`masonry.studies.thrust_line`, independent of the RBE); below it, no factor."""
    minimum = thrust_line_minimum_thickness("semicircular", 12, 10.0).thickness
    factors = []
    for ratio in (1.5, 1.2, 1.05, 1.01, 1.001):
        _, model = arch_model(ratio * minimum)
        result = collapse_load(model, lateral(model, 0.0, DENSITY), mu=10.0, density=DENSITY)
        factors.append(result.load_factor)
    assert all(a > b for a, b in zip(factors, factors[1:]))
    assert 0 < factors[-1] < 5e-3 * factors[0]  # about linear in t - t_min
    _, model = arch_model(0.99 * minimum)
    below = collapse_load(model, lateral(model, 0.0, DENSITY), mu=10.0, density=DENSITY)
    assert below.load_factor is None and below.dead_load_feasible is False
    assert below.status == "dead load infeasible"


# ---------------------------------------------------------------------- domes
def test_crown_load_on_the_cyclic_section_equals_the_full_dome():
    """On this dome cut at half its height, whose top ring is nearly flat, a downward crown
    load is carried at any factor by rigid blocks (the ring carries it in compression:
    'unbounded'); an upward one lifts the top course at a finite factor. Either way the
    cyclic section gives the full dome's answer."""
    section = build_model(validate(Params.of(scene="section", boundary="cyclic",
                                                   **SMALL_DOME)))[1]
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    down = [collapse_load(model, crown_load(model, 2000.0, copies=copies))
            for model, copies in ((section, 6), (dome, 1))]
    assert [r.status for r in down] == ["unbounded", "unbounded"]
    assert all(r.load_factor is None and r.dead_load_feasible for r in down)
    assert all(r.note == UNBOUNDED_NOTE for r in down)
    on_section = collapse_load(section, crown_load(section, -2000.0, copies=6))
    on_dome = collapse_load(dome, crown_load(dome, -2000.0))
    assert on_section.load_factor is not None and on_section.load_factor > 0
    assert on_dome.load_factor == pytest.approx(on_section.load_factor, rel=1e-6)
    total = crown_load(dome, 2000.0).total_force
    np.testing.assert_allclose(total, [0, 0, -2000.0], atol=1e-9 * 2000.0)


@pytest.mark.parametrize("method, cone", [("interior", "circle"), ("clarabel", "circle"),
                                          ("highs-simplex", "polygon:16")])
@pytest.mark.slow
def test_worst_lateral_searches_the_symmetry_directions_with_one_model(method, cone):
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    azimuths = lateral_azimuths(6)
    assert len(azimuths) >= 24 and {30.0, 90.0, 150.0} <= set(azimuths)
    worst = worst_lateral(dome, azimuths, n_webs=6, method=method, cone=cone, refine=False)
    factors = np.array([f for _, f in worst.azimuths])
    assert len(factors) == len(azimuths)
    # of the azimuths tied with the least (the LP's rounding apart), the first
    assert worst.load_factor == pytest.approx(factors.min(), rel=FACTOR_TIE_REL)
    tied = [a for a, f in worst.azimuths if f <= factors.min() * (1 + FACTOR_TIE_REL)]
    assert worst.azimuth_deg == tied[0]
    # six-fold symmetry: the factor repeats every 60 degrees
    by_angle = dict(worst.azimuths)
    for a in azimuths:
        assert by_angle[a] == pytest.approx(by_angle[(a + 60.0) % 360.0], rel=1e-6)
    # so the search may solve each azimuth modulo 60 degrees once
    reduced = worst_lateral(dome, azimuths, n_webs=6, period_deg=60.0, method=method,
                            cone=cone, refine=False)
    np.testing.assert_allclose([f for _, f in reduced.azimuths], factors, rtol=1e-6)
    assert reduced.azimuth_deg < 60.0 and reduced.load_factor == pytest.approx(
        worst.load_factor, rel=1e-6)
    # the same factor as an independent solve at that azimuth, by the own interior point
    # method: two solvers agree within their gaps (1e-8) and primal residuals
    alone = collapse_load(dome, lateral(dome, worst.azimuth_deg), cone=cone)
    assert alone.load_factor == pytest.approx(worst.load_factor, rel=1e-6)
    check_mechanism(dome, lateral(dome, worst.azimuth_deg), worst)


MIRRORS_6 = tuple(30.0 * np.arange(6))
"""The mirror planes of a dome of six webs: the webs' mid-planes and the corners."""


def test_the_azimuth_search_refines_its_least_sample_between_the_samples():
    """At mu 5 the small dome's least lateral factor lies near 29 and 31 degrees (mirror
    images in the plane at 30), between the samples: the least sample, 30 degrees (a
    peak where two mechanisms' factors cross), is 1.6e-4 above it. The search's factor is
    at most every factor of an independent 1-degree sweep of 0 to 30 degrees (the rotation
    by 60 and the mirrors every 30 map every azimuth there), and within 1e-6 of the least
    refined by hand: the vertex of the parabola through 28.5, 29 and 29.5 degrees (one
    mechanism's factor, D / (R cos(azimuth - phi)), is smooth there), solved."""
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    worst = worst_lateral(dome, lateral_azimuths(6), mu=5.0, n_webs=6, period_deg=60.0,
                          mirrors=MIRRORS_6)
    samples = dict(worst.azimuths)
    assert min(samples.values()) == samples[30.0]
    problem = CollapseLP(dome, mu=5.0)

    def factor(azimuth):
        return problem.solve_lateral(azimuth, dead_load_feasible=True).load_factor

    sweep = [factor(a) for a in np.arange(0.0, 30.5, 1.0)]
    assert worst.load_factor <= min(sweep) + 1e-6
    assert worst.load_factor < samples[30.0] - 1e-4
    near = np.array([28.5, 29.0, 29.5])
    a, b, _ = np.polyfit(near, [factor(x) for x in near], 2)
    by_hand = factor(-b / (2 * a))
    assert by_hand <= min(sweep) + 1e-9
    assert worst.load_factor == pytest.approx(by_hand, abs=1e-6)
    assert symmetric_key(worst.azimuth_deg, 60.0, MIRRORS_6) == pytest.approx(-b / (2 * a),
                                                                              abs=0.05)
    assert worst.refined and (worst.azimuth_deg, worst.load_factor) in worst.refined
    # the reported mechanism is the refined azimuth's, checked on the whole
    check_mechanism(dome, lateral(dome, worst.azimuth_deg), worst)


def test_the_floor_between_two_azimuths_bounds_every_mechanism_between_them():
    """The floor of :func:`floor_between` is the least factor a mechanism can have between
    two azimuths where its factors are known: for one mechanism, D / (R cos(theta -
    phi)) with its best azimuth phi between them, the floor is exactly its least, D / R;
    with phi outside, the smaller end."""
    def branch(theta, phi, least):
        return least / np.cos(np.radians(theta - phi))

    for phi in (3.0, 7.5, 14.0):
        ends = branch(0.0, phi, 2.0), branch(15.0, phi, 2.0)
        assert floor_between(0.0, ends[0], 15.0, ends[1]) == pytest.approx(2.0, rel=1e-12)
    ends = branch(20.0, 10.0, 2.0), branch(35.0, 10.0, 2.0)
    assert floor_between(20.0, ends[0], 35.0, ends[1]) == pytest.approx(ends[0], rel=1e-12)
    # an end where no factor bounds the load leaves the other's branch
    assert floor_between(0.0, 2.0, 15.0, np.inf) == pytest.approx(2.0, rel=1e-12)


def _support(azimuth, points=None, centre=None, radius=None):
    """``1 / h(azimuth)`` of a convex set of the plane: the polygon of ``points``, or the
    disc of ``radius`` about ``centre``."""
    u = np.array([np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))])
    h = float(np.max(points @ u)) if points is not None else radius + float(centre @ u)
    return 1.0 / h


@pytest.mark.parametrize("corner_deg", [7.0, 19.0, 22.5, 37.3])
def test_the_refinement_cuts_a_polygon_at_its_farthest_vertex(corner_deg):
    """The set of a program's mechanisms is a polygon: the least factor is ``1 / |v|``
    at the farthest vertex ``v``'s azimuth. Sampled every 15 degrees, the corners find it
    to 1e-9 in at most two solves wherever the vertex lies (on a sample: none)."""
    angles = np.radians([corner_deg - 40.0, corner_deg, corner_deg + 50.0, 200.0])
    radii = np.array([2.0, 2.5, 2.1, 1.0])
    points = radii[:, None] * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    samples = [(a, _support(a, points)) for a in np.arange(0.0, 360.0, 15.0)]
    new = refine_least(samples, lambda a: _support(a, points))
    least = min(f for _, f in samples + new)
    assert least == pytest.approx(1.0 / 2.5, rel=1e-9)
    assert len(new) <= 2 and (corner_deg % 15.0 != 0.0 or not new)


def test_the_refinement_certifies_a_smooth_least_on_a_mirror_plane(caplog):
    """A disc about an off-centre point: a smooth family of mechanisms, the least factor
    ``1 / (r + |c|)`` at ``c``'s azimuth, here a sample in the set's mirror plane (as on
    preset 1's dome, where Brent's method spent every solve converging on the sample and
    stopped uncertified). The search closes every bracket's floor to its tolerance
    (1e-7) within its solves, the mirror image's bracket left to the symmetry."""
    centre = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    samples = [(a, _support(a, centre=centre, radius=2.0)) for a in np.arange(0.0, 360.0,
                                                                                 15.0)]
    orbit = functools.partial(symmetric_key, mirrors=(30.0,))
    with caplog.at_level("WARNING"):
        new = refine_least(samples, lambda a: _support(a, centre=centre, radius=2.0),
                           key=orbit)
    assert 0 < len(new) < MAX_SOLVES and "stopped" not in caplog.text
    assert all(f >= 1.0 / 3.0 * (1.0 - 1e-12) for _, f in new)
    assert all(15.0 < a < 30.0 for a, _ in new)  # one side of the mirror
    # every floor between the solved azimuths there within 1e-7 of the least, 1 / 3
    solved = sorted([(15.0, samples[1][1]), (30.0, samples[2][1]), *new])
    floors = [floor_between(a, f, b, g) for (a, f), (b, g) in itertools.pairwise(solved)]
    assert min(floors) >= (1.0 - 1e-7) / 3.0


@pytest.mark.parametrize("tol, most", [(1e-7, None), (1e-4, 4), (1e-3, 1)])
def test_the_refinement_stops_within_its_tolerance(tol, most):
    """A looser tolerance (the fast preset's ``azimuth_rel``) takes fewer solves and
    ends within it of the least, ``1 / (r + |c|)`` for a disc about ``c`` (between the
    samples, at 20 degrees)."""
    centre = 1.8 * np.array([np.cos(np.radians(20.0)), np.sin(np.radians(20.0))])
    samples = [(a, _support(a, centre=centre, radius=2.0)) for a in np.arange(0.0, 360.0,
                                                                                 15.0)]
    new = refine_least(samples, lambda a: _support(a, centre=centre, radius=2.0),
                       azimuth_rel=tol)
    # the samples alone are off by more than every tolerance: the cuts bring it within
    assert min(f for _, f in samples) > (1.0 + 1e-3) / 3.8
    assert min(f for _, f in new) <= (1.0 + tol) / 3.8
    assert most is None or len(new) <= most


def test_the_refinement_searches_beside_every_sample_near_the_least():
    """Two samples within 0.1 % of the least sampled, on opposite sides: at 240 and 255
    degrees (a vertex at 247.5 between them, radius 2) and at 75 (a farther vertex at
    67.9, radius 2.01: the least factor, 1 / 2.01). The first cut, between 240 and 255,
    finds 1 / 2 and leaves the sample at 75 more than 0.1 % above it; the brackets beside
    that sample are searched all the same."""
    polar = [(247.5, 2.0), (240.0, 1.995), (255.0, 1.995), (67.9, 2.01), (160.0, 1.5),
             (340.0, 1.5)]
    points = np.array([[r * np.cos(np.radians(a)), r * np.sin(np.radians(a))]
                       for a, r in polar])
    samples = [(a, _support(a, points)) for a in np.arange(0.0, 360.0, 15.0)]
    new = refine_least(samples, lambda a: _support(a, points))
    assert new[0][1] == pytest.approx(0.5, rel=1e-12)  # the cut between 240 and 255
    assert min(f for _, f in new) == pytest.approx(1.0 / 2.01, rel=1e-9)


@pytest.mark.parametrize("accuracy", ["fast", "balanced"])
def test_a_run_refines_its_azimuth_search_to_its_presets_tolerance(monkeypatch, accuracy):
    """``--lateral all`` refines to the accuracy preset's ``azimuth_rel``: 1e-4 when
    fast, 1e-7 otherwise (docs/model.md 6.6)."""
    asked = {}

    class Asked(Exception):
        pass

    def search(model, **options):
        asked.update(options)
        raise Asked

    params = validate(Params.of(scene="dome", **SMALL_DOME, lateral="all", accuracy=accuracy))
    monkeypatch.setattr(pipeline, "worst_lateral", search)
    with pytest.raises(Asked):
        pipeline.collapse_of(build_model(params)[1], params)
    assert asked["azimuth_rel"] == {"fast": 1e-4, "balanced": 1e-7}[accuracy]


def test_run_reports_the_refined_least_of_an_azimuth_search(tmp_path, capsys):
    out = tmp_path / "run"
    args = [f"--{key}={value}" for key, value in SMALL_DOME.items()]
    assert main(["run", "--scene", "dome", *args, "--mu", "5", "--lateral", "all",
                 "--no-printable", "--out", str(out)]) == 0
    (record,) = out.glob("*/run.json")
    folder = record.parent
    collapse = json.loads(record.read_text())["collapse"]
    azimuth, factor = collapse["azimuth_deg"], collapse["load_factor"]
    sampled = {row["azimuth_deg"]: row["load_factor"] for row in collapse["azimuths"]}
    assert factor < sampled[30.0] - 1e-4
    assert {"azimuth_deg": azimuth, "load_factor": factor} in collapse["refined"]
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    alone = collapse_load(dome, lateral(dome, azimuth), mu=5.0)
    assert factor == pytest.approx(alone.load_factor, rel=1e-6)
    table = masonry.read_table(folder / "collapse" / "azimuths.csv")
    assert len(table) == len(sampled) + len(collapse["refined"])
    assert table["load_factor"].min() == pytest.approx(factor, rel=1e-9)
    assert (folder / "collapse" / "azimuths.png").exists()
    printed = capsys.readouterr().out
    assert f"lateral at {azimuth:.6g} deg (the least of {len(sampled)} azimuths and " \
           f"{len(collapse['refined'])} more solved between them" in printed


@pytest.mark.skipif(not forking.can_fork(), reason="the azimuths share the cores by fork")
@pytest.mark.parametrize("known", [None, True])
def test_an_azimuth_search_on_two_cores_gives_every_azimuth_its_factor(two_processes, known):
    """Two azimuths at once, every second one in a forked process: the block of
    test_single_block_tips_at_b_over_h_or_slides_at_mu tips at b/h = 0.4 along x and
    slides at mu = 0.7 along y, whichever process solved the azimuth (after the first,
    here, when the dead load is not known to stand)."""
    model = column(1, (0.2, 0.4, 0.5))
    azimuths = [0.0, 90.0, 180.0, 270.0, 45.0]
    worst = worst_lateral(model, azimuths, mu=0.7, density=DENSITY,
                          dead_load_feasible=known)
    assert len(two_processes) == 1
    factors = dict(worst.azimuths)
    assert list(factors) == azimuths
    for azimuth, expected in ((0.0, 0.4), (90.0, 0.7), (180.0, 0.4), (270.0, 0.7)):
        assert factors[azimuth] == pytest.approx(expected, rel=1e-6)
    # along the diagonal its x part tips it about the far edge along y: lambda cos 45
    # times h / 2 against b / 2
    assert factors[45.0] == pytest.approx(0.1 / (0.25 * np.cos(np.pi / 4)), rel=1e-6)
    assert worst.azimuth_deg == 0.0 and worst.load_factor == pytest.approx(0.4, rel=1e-6)
    check_mechanism(model, lateral(model, 0.0, DENSITY), worst)


@pytest.mark.skipif(not forking.can_fork(), reason="the azimuths share the cores by fork")
def test_an_azimuth_search_given_one_core_forks_nothing(two_processes):
    """The caller decides: ``cores=1`` solves every azimuth here, to the factors the
    two processes find."""
    model = column(1, (0.2, 0.4, 0.5))
    azimuths = [0.0, 90.0, 180.0, 270.0, 45.0]
    alone = worst_lateral(model, azimuths, mu=0.7, density=DENSITY, dead_load_feasible=True,
                          cores=1)
    assert two_processes == []
    shared = worst_lateral(model, azimuths, mu=0.7, density=DENSITY,
                           dead_load_feasible=True)
    assert len(two_processes) == 1
    np.testing.assert_allclose([f for _, f in alone.azimuths],
                               [f for _, f in shared.azimuths], rtol=1e-9)


def test_highs_refuses_coulombs_cone():
    """HiGHS solves linear programs: the registry says so before any matrix is built."""
    with pytest.raises(ValueError, match="linear constraints only.*interior, clarabel"):
        CollapseLP(column(1, (0.2, 0.4, 0.5)), method="highs-simplex", cone="circle")
    with pytest.raises(ValueError, match="unknown collapse method 'simplex'"):
        CollapseLP(column(1, (0.2, 0.4, 0.5)), method="simplex", cone="square")


@pytest.mark.parametrize("azimuth", [0.0, 45.0])
@pytest.mark.parametrize("cone", ["polygon:16", "square"])
@pytest.mark.slow
def test_interior_point_lp_finds_the_simplex_optimum_on_a_dome(azimuth, cone):
    """The own interior point method against HiGHS's dual simplex (an exact vertex
    solution) on the 72-brick dome, without falling back to Clarabel."""
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    live = lateral(dome, azimuth, DENSITY)
    ours = CollapseLP(dome, method="interior", cone=cone).solve(live, dead_load_feasible=True)
    simplex = CollapseLP(dome, method="highs-simplex", cone=cone).solve(live,
                                                                 dead_load_feasible=True)
    assert ours.solver == "interior"
    assert ours.load_factor == pytest.approx(simplex.load_factor, rel=1e-7)
    assert ours.residual <= LP_RESIDUAL
    check_mechanism(dome, live, ours)


# ---------------------------------------------------------------------- inputs, CLI
@pytest.mark.parametrize("argv, option", [
    (["--lateral", "north"], "--lateral"),
    (["--point-load", "b1:1,2"], "--point-load"),
    (["--crown-load", "-5"], "--crown-load"),
    (["--dome", "--lateral", "30"], "--scene dome"),
    (["--lateral", "30", "--crown-load", "5"], "one live load"),
])
def test_bad_live_loads_are_refused_in_one_line(argv, option, tmp_path, capsys):
    code = main(["run", "--preset", "1", "--out", str(tmp_path), "--no-plots",
                 "--no-printable", *argv])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and option in err
    assert not any(tmp_path.iterdir())


def test_run_writes_the_collapse_record_and_files(tmp_path, capsys):
    code = main(["run", "--preset", "wall", "--lateral", "0", "--out", str(tmp_path),
                 "--no-plots", "--no-printable"])
    assert code == 0
    line = [ln for ln in capsys.readouterr().out.splitlines() if "lambda" in ln]
    assert len(line) == 1 and "lambda = 0.2" in line[0]
    folder = next(tmp_path.glob("wall_*_lat0"))
    record = json.loads((folder / "run.json").read_text())["collapse"]
    assert record["load_factor"] == pytest.approx(0.2, rel=1e-7)
    assert record["dead_load_feasible"] is True and record["azimuth_deg"] == 0.0
    assert record["live_load"]["kind"] == "lateral" and record["residual"] < 1e-7
    for name in ("forces.csv", "interfaces.vtu", "mechanism.csv", "mechanism.vtu"):
        assert (folder / "collapse" / name).stat().st_size > 0
    rows = (folder / "collapse" / "mechanism.csv").read_text().splitlines()
    assert rows[0] == "block,name,ux_rel,uy_rel,uz_rel,rx_per_m,ry_per_m,rz_per_m"
    assert len(rows) == 1 + 86
    # the forces at collapse in RBE's table: same columns; the supports carry the lateral
    # load, lambda times the weight, against it (forces act on block_b, the brick)
    with open(folder / "collapse" / "forces.csv") as f:
        table = list(csv.DictReader(f))
    with open(folder / "RBE" / "forces.csv") as f:
        assert list(table[0]) == next(csv.reader(f))
    weight = json.loads((folder / "run.json").read_text())["rbe"]["weight_N"]
    support = sum(float(r["shear_x_N"]) for r in table if r["kind"] == "support")
    assert support == pytest.approx(-0.2 * weight, rel=1e-6)
    mesh = meshio.read(folder / "collapse" / "interfaces.vtu")
    assert {"compression_N", "shear_N", "hinge", "slides", "opens", "gap_rel",
            "slip_rel"} <= set(mesh.cell_data)


def test_sweep_records_the_load_factor(tmp_path):
    """An arch thickness study with a lateral load: lambda per variant, each equal to the
    independent 2D LP's."""
    study = tmp_path / "arch.toml"
    study.write_text('[base]\nscene = "arch"\nblocks = 12\nlateral = 0\nmu = 0.9\n'
                     '[grid]\nthickness = [0.8, 1.2]\n')
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path), "-q"]) == 0
    rows = (tmp_path / "sweep_arch" / "summary.csv").read_text().splitlines()
    header = rows[0].split(",")
    for line in rows[1:]:
        row = dict(zip(header, line.split(",")))
        thickness = float(row["arch_thickness"])
        expected = arch_lp(arch_profile("semicircular", 12, 10.0, thickness), 1.0, 0.9)
        assert float(row["load_factor"]) == pytest.approx(expected, rel=1e-5)
        assert float(row["load_azimuth_deg"]) == 0.0


def test_non_associative_friction_lowers_a_sliding_collapse_and_keeps_a_tipping_one():
    """Fixed friction capacities (no dilatancy): a block that slides by translation or
    tips needs no dilatancy and keeps its factor; the small dome's mixed mechanism loses
    part of it."""
    for azimuth, expected in ((0.0, 0.4), (90.0, 0.7)):
        model = column(1, (0.2, 0.4, 0.5))
        result = collapse_load(model, lateral(model, azimuth), friction="non-associative")
        assert result.load_factor == pytest.approx(expected, rel=1e-6)
        assert result.friction_law == "non-associative" and result.note is None
    dome = build_model(validate(Params.of(scene="dome", **SMALL_DOME)))[1]
    live = lateral(dome, 0.0)
    associated = collapse_load(dome, live)
    estimate = collapse_load(dome, live, friction="non-associative")
    assert associated.note is not None  # sliding takes part: the outputs say so
    assert estimate.associated_factor == pytest.approx(associated.load_factor, rel=1e-6)
    assert 0 < estimate.load_factor < 0.95 * associated.load_factor
    forces = estimate.x.reshape(-1, 4)
    assert forces[:, 1].max() == 0  # no tension
    assert estimate.residual <= LP_RESIDUAL
    # settled: Coulomb's law holds at the estimate's forces (the fixed capacities of the
    # last round are those of its own compression: a disc, not a box) to within a
    # fraction of a percent
    excess = np.hypot(forces[:, 2], forces[:, 3]) - 0.7 * forces[:, 0]
    assert excess.max() <= 5e-3 * forces[:, 0].max()


def test_run_reports_the_non_associative_estimate_beside_the_associated_factor(tmp_path,
                                                                              capsys):
    common = ["run", "--scene", "dome", "--stretch", "1", "--n", "6", "--r", "0", "--p",
              "3", "--cut", "0.5", "--lateral", "0", "--out", str(tmp_path), "--no-plots",
              "--no-printable", "-q"]
    assert main(common + ["--friction-law", "non-associative"]) == 0
    assert main(common) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if "lambda" in ln]
    associated_factor = float(lines[1].split("lambda = ")[1].split()[0])
    assert f"non-associative friction (associated: {associated_factor:.4g})" in lines[0]
    records = {path.name: json.loads((path / "run.json").read_text())["collapse"]
               for path in tmp_path.glob("fulldome_*")}
    estimate = records[next(n for n in records if n.endswith("_nonassoc"))]
    associated = records[next(n for n in records if n.endswith("_lat0"))]
    assert estimate["friction_law"] == "non-associative"
    assert estimate["associated_factor"] == pytest.approx(associated["load_factor"])
    assert estimate["load_factor"] < 0.95 * associated["load_factor"]
    assert main(["run", "--preset", "wall", "--friction-law", "non-associative", "--out",
                 str(tmp_path / "x")]) == 2
    assert "--friction-law non-associative: expected associated without a live load" in \
        capsys.readouterr().err


@pytest.mark.slow
def test_the_dome_symmetry_leaves_azimuths_from_a_web_to_its_corner():
    """The worst lateral factor over 0..180/n (structures' search) is the worst over the
    whole circle: rotation by 360/n and the mirror in a web's mid-plane map every
    direction into that sector."""
    params = validate(Params.of(scene="dome", **SMALL_DOME))
    dome = build_model(params)[1]
    sector = lateral_record(dome, params, count=3)  # 0, 15, 30 degrees
    circle = worst_lateral(dome, lateral_azimuths(6), refine=False)  # every 15 degrees
    assert sector["lateral_factor"] == pytest.approx(circle.load_factor, rel=1e-6)
    assert sector["hinge_webs"] and sector["hinge_courses"]


def test_a_non_associative_round_without_equilibrium_gives_no_factor(monkeypatch):
    """Capacities fixed from a collapse may admit no equilibrium at all (preset 3's dome
    at p = 6, round 2): then there is no estimate, and no mechanism of unsettled
    capacities; the associated factor stays."""
    model = column(1, (0.2, 0.4, 0.5))
    live = lateral(model, 90.0)
    problem = CollapseLP(model, mu=0.7, density=DENSITY)
    fixed = problem.with_friction_capacity

    def one_good_round(capacity):
        out = fixed(capacity)
        rounds.append(out)
        if len(rounds) > 1:  # the second re-solve: no equilibrium with these capacities
            out.solve = lambda *args, **kwargs: dataclasses.replace(
                problem.solve(live), load_factor=None, status="dead load infeasible")
        return out

    rounds = []
    monkeypatch.setattr(problem, "with_friction_capacity", one_good_round)
    result = fixed_capacity_factor(problem, live)
    assert result.load_factor is None and result.mechanism is None and result.hinges == -1
    assert result.status == ("non-associative estimate: round 2 has no equilibrium (dead "
                             "load infeasible)")
    assert result.associated_factor == pytest.approx(0.7, rel=1e-6)
    with pytest.raises(ValueError, match="at least 2"):
        fixed_capacity_factor(problem, live, rounds=1)


# ---------------------------------------------------------------------- defects found
def test_analyze_takes_the_non_associative_friction_law(fixtures_dir, tmp_path):
    """`masonry analyze --friction-law non-associative` runs the estimate: run.json says
    so and the folder's name has the suffix."""
    path = fixtures_dir / "assembly" / "arch_rhino.obj"
    assert main(["analyze", str(path), "--support", "pier_*", "--lateral", "0",
                 "--friction-law", "non-associative", "--no-plots", "--no-printable",
                 "--out", str(tmp_path), "-q"]) == 0
    (folder,) = tmp_path.glob("assembly_arch_rhino_*")
    assert folder.name.endswith("_lat0_nonassoc")
    collapse = json.loads((folder / "run.json").read_text())["collapse"]
    assert collapse["friction_law"] == "non-associative"
    assert collapse["associated_factor"] is not None


def _no_constants(name):
    raise AssertionError(f"{name} is not JSON")


@pytest.mark.slow
def test_run_json_is_strict_json_with_null_where_a_value_is_missing(tmp_path):
    """A collapse without a factor (the live load is carried at any factor) and a
    friction-net solve without a point: run.json has null, never NaN or Infinity, which
    JavaScript and `jq` refuse."""
    common = ["run", "--scene", "dome", "--stretch", "1", "--n", "6", "--r", "0", "--p",
              "3", "--cut", "0.5", "--no-plots", "--no-printable", "-q"]
    assert main(common + ["--crown-load", "2000", "--out", str(tmp_path / "a")]) == 0
    assert main(["run", "--preset", "1", "--boundary", "free", "--friction", "net",
                 "--no-plots", "--no-printable", "-q", "--out", str(tmp_path / "b")]) == 0
    for path in tmp_path.glob("*/*/run.json"):
        record = json.loads(path.read_text(), parse_constant=_no_constants)
        if "collapse" in record:
            assert record["collapse"]["load_factor"] is None
            assert record["collapse"]["status"] == "unbounded"
            assert record["collapse"]["residual"] is None
        else:
            assert record["rbe"]["verdict"] == "infeasible"
            assert record["rbe"]["moi"] is None and record["rbe"]["objective"] is None


@pytest.mark.parametrize("argv", [["--point-load", "b*:1e-320,0,0"],
                                  ["--crown-load", "5e-324"]])
def test_a_live_load_too_small_for_a_finite_factor_is_refused(tmp_path, capsys, argv):
    scene = ["--scene", "dome"] if "--crown-load" in argv else ["--preset", "wall"]
    code = main(["run", *scene, *argv, "--out", str(tmp_path), "--no-plots",
                 "--no-printable"])
    error = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(error) == 1 and not any(tmp_path.iterdir())
    assert error[0].startswith(f"masonry: error: {argv[0]} {shlex.quote(argv[1])}: expected ")
    assert "finite load factor" in error[0]


def test_a_crown_load_on_a_thesis_dome_has_a_bounded_factor():
    """docs/collapse.md: the thesis's domes carry a finite multiple of a lantern (preset 3's
    cyclic section: lambda = 4.548 for 20 kN), unlike the dome cut at half its height."""
    section = build_model(from_preset("3", boundary="cyclic"))[1]
    result = collapse_load(section, crown_load(section, 20000.0, copies=4),
                           dead_load_feasible=True)
    assert result.status == "optimal"
    assert result.load_factor == pytest.approx(4.548, rel=1e-3)  # the documented digits
    assert result.work_balance < 1e-6
