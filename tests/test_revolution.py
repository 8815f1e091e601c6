"""The dome of revolution (docs/model.md 4.8): its loxodromes against the continuous
curve, its rings, its bricks as solids, the lone brick on a conical bed, sector = whole
dome, the plain dome beside it, and the printable body."""

import dataclasses

import numpy as np
import pytest

from masonry.interfaces import INTERFACE_KINDS, detect
from masonry.params import Params, validate
from masonry.pipeline import build_model
from masonry.printable import printable_body
from masonry.rbe.solve import RBEProblem, solve_rbe
from masonry.scenes import build
from masonry.scenes.revolution import (PAT, RevolutionDome, _zigzag, default_spirals,
                                       profile_of, ring_pattern,
                                       rings_of)
from masonry_cli.main import main

SMALL = dict(radius=20, p=3, cut=0.3)  # 12 sectors of 63 bricks, 756 bricks in all
BED = INTERFACE_KINDS.index("horizontal")


def small(scene="sector", **changes):
    return validate(Params.of(scene=scene, **{**SMALL, **changes}))


# ------------------------------------------------------------------------ loxodromes
@pytest.mark.parametrize("elevation, longitude", [(30.0, 31.5), (60.0, 75.5)])
def test_the_lines_follow_the_loxodrome_as_the_unit_shrinks(elevation, longitude):
    """On a sphere a line at beta to the meridian gains tan(beta) ln(tan(phi0/2) /
    tan(phi1/2)) of longitude between polar angles phi0 and phi1; from the springing at
    45 degrees: 31.5 degrees to elevation 30, 75.5 to 60 (docs/model.md 4.8). The
    discrete line (two start nodes: no node on the way) converges at first order in
    unit / radius."""
    polar = np.radians(90 - elevation)
    assert np.degrees(np.log(1 / np.tan(polar / 2))) == pytest.approx(longitude, abs=0.05)
    errors = []
    for radius in (50, 100, 200, 400):
        g = RevolutionDome(radius=radius, spirals=2, p=200, cut=0.05)
        prof = profile_of(g)
        line = _zigzag(g, prof, 2)[0]
        course = np.array([brick[0] for brick in line])
        middle = np.array([(brick[1] + brick[2]) / 2 for brick in line])
        elev = np.degrees(np.arctan2(prof.z, prof.x))
        k = int(np.argmin(np.abs(elev - elevation)))
        assert not any(brick[3] for brick in line if brick[0] <= k)  # no node below
        polar = np.radians(90 - elev[k])
        exact = np.log(1 / np.tan(polar / 2))  # tan(45) ln(tan(pi/4) / tan(polar/2))
        errors.append(abs(middle[course == k][0] - exact))
        assert errors[-1] <= 0.8 / radius  # radians: about half a brick at the ring
    assert all(b <= 0.6 * a for a, b in zip(errors, errors[1:]))  # first order


def passing_line(g):
    """The longitude (radians) of the middle of one line's brick on every course, the line
    traced through its crossings: :func:`_zigzag` turns back at a node (it stands beside
    its partner there); the line that passes on is its mirror image about the node's
    meridian from the next course on. Returns ``(course, longitude, nodes)``."""
    prof = profile_of(g)
    line = _zigzag(g, prof, g.spirals or default_spirals(g))[0]
    offset, sign, direction, out = 0.0, 1.0, 1, []
    for k, lo, hi, node, *_ in line:
        out.append((k, offset + sign * 0.5 * (lo + hi)))
        if node:  # what follows, mirrored about the node's meridian
            meridian = hi if direction > 0 else lo
            offset, sign, direction = offset + 2 * sign * meridian, -sign, -direction
    course, longitude = np.array(out).T
    return course.astype(int), longitude, sum(brick[3] for brick in line)


@pytest.mark.parametrize("angle, elevation, band", [
    (45.0, 30.0, (0.05, 0.12)), (45.0, 60.0, (0.07, 0.12)),
    (75.0, 30.0, (0.19, 0.26)), (75.0, 60.0, (0.22, 0.27))])
def test_a_line_through_its_crossings_runs_ahead_of_the_loxodrome(angle, elevation, band):
    """Across a node a line gains about a brick width (it stands beside its partner, then
    the passing line steps on from the far side): traced through its crossings, the
    default dome's line runs ahead of the loxodrome by a share of its longitude that does
    not shrink with a finer unit (docs/model.md 4.8 states these numbers): 10.5 % at
    beta 45 and 21 to 23 % at beta 75, elevations 30 and 60, at unit 0.1 (50 units in
    radius); 6 to 8 % and 24 % at unit 0.05 (the same dome, 100 units in radius): the
    share moves with where the last node falls, not with the unit."""
    for unit in (0.1, 0.05):
        g = RevolutionDome(helix_angle=angle, unit=unit, radius=5.0 / unit)
        prof = profile_of(g)
        course, longitude, nodes = passing_line(g)
        elev = np.degrees(np.arctan2(prof.z, prof.x))
        k = int(np.argmin(np.abs(elev - elevation)))
        polar = np.radians(90 - elev[k])
        exact = np.tan(np.radians(angle)) * np.log(1 / np.tan(polar / 2))
        ahead = longitude[course == k][0] / exact - 1
        assert nodes >= 4 and band[0] <= ahead <= band[1], (unit, ahead)


@pytest.mark.parametrize("angle, helix", [(45.0, "loxodrome"), (60.0, "loxodrome"),
                                          (50.0, "clelia")])
def test_every_pattern_brick_steps_tan_beta_units(angle, helix):
    """A line's brick steps tan(beta) units sideways at the level between it and the
    one before (a loxodrome), or the springing's longitude step (a Clelia curve); the
    brick that closes a node steps further, up to twice, to stand beside its partner."""
    g = RevolutionDome(helix_angle=angle, helix=helix)
    prof = profile_of(g)
    line = _zigzag(g, prof, default_spirals(g))[0]
    tan, x = max(np.tan(np.radians(angle)), 1.0), prof.x
    steps = 0
    for (k0, lo0, hi0, node0, *_), (k1, lo1, hi1, node1, *_) in zip(line, line[1:]):
        assert k1 == k0 + 1
        if node0 or node1:  # a node turns the line back: not a step of one hand
            continue
        moved = lo1 - lo0 if lo1 > lo0 else hi0 - hi1  # the trailing edge
        reference = x[k0] if helix == "loxodrome" else x[0]
        assert moved * reference / g.unit == pytest.approx(tan, rel=1e-9)
        steps += 1
    assert steps > 20


def test_nodes_and_line_ends_keep_the_spacing():
    """Nodes of a course stand 2 (p + 1) units apart or more; where they would come
    closer, the lines of every other node end there and the symmetry halves."""
    g = RevolutionDome()
    prof, pattern = profile_of(g), ring_pattern(g)
    for course in np.unique(pattern.nodes[:, 0]).astype(int):
        at = np.sort(pattern.nodes[pattern.nodes[:, 0] == course, 1])
        spacing = np.diff(np.concatenate([at, at[:1] + 2 * np.pi])) * prof.x[course] / g.unit
        ended = pattern.ended[pattern.ended[:, 0] == course]
        if len(ended) == 0:
            assert spacing.min() >= 2 * (g.p + 1) - 1e-9
        else:  # the survivors of this course are twice as far apart
            assert 2 * spacing.min() >= 2 * (g.p + 1) - 1e-9
            assert len(ended) == len(at) // 2
    assert pattern.order[1] == 12 and pattern.symmetry == 6
    assert (np.diff(pattern.order[1:]) <= 0).all()


# ----------------------------------------------------------------------------- rings
def test_every_course_is_a_closed_horizontal_ring():
    """Every course covers the whole ring exactly once (its bricks and the pattern
    bricks of the course below), so every meridian crosses every course; every brick's
    bed lies at its course's contact level."""
    g = RevolutionDome(**SMALL)
    rings, prof = rings_of(g), profile_of(g)
    for k in range(1, prof.n_courses + 1):
        here = (rings.course == k) | ((rings.course == k - 1) & (rings.klass == PAT))
        start = np.mod(rings.phi0[here], 2 * np.pi)
        order = np.argsort(start)
        a, b = start[order], (start + rings.phi1[here] - rings.phi0[here])[order]
        assert (b - a).sum() == pytest.approx(2 * np.pi, rel=1e-12)  # covered ...
        assert np.all(b[:-1] <= a[1:] + 1e-12) and b[-1] <= a[0] + 2 * np.pi + 1e-12  # once
    blocks = build(small("revolution")).blocks
    free = ~blocks.block_is_support
    lowest = np.minimum.reduceat(blocks.vertices[:, 2], blocks.vertex_offsets[:-1])
    np.testing.assert_allclose(lowest[free], prof.z[blocks.block_course[free] - 1],
                               atol=1e-12)


def test_bricks_are_convex_and_share_whole_planar_faces():
    """Every brick is convex (its volume is its hull's), the bricks fill the courses
    without overlap (their volume is the rings' between the bed cones), and the
    interface detector finds every bed and head joint as a face shared by two
    bricks."""
    scene, model = build_model(small(boundary="cyclic"))
    blocks = scene.blocks
    from scipy.spatial import ConvexHull
    for b in range(1, blocks.n_blocks, 7):
        assert blocks.block_volume[b] == pytest.approx(
            ConvexHull(blocks.block_vertices(b)).volume, rel=1e-9)
    interfaces = model.interfaces
    # a brick of course k >= 2 bears on the course below over its whole bed (in the
    # sector or on a neighbour's image, which stands for the brick it copies: a boundary
    # interface)
    bottom = np.zeros(blocks.n_blocks)
    lower = model.blocks.block_centroid[:, 2][interfaces.pair]
    on_top = np.where(lower[:, 0] > lower[:, 1], interfaces.pair[:, 0], interfaces.pair[:, 1])
    bed_like = np.abs(interfaces.normal[:, 2]) > 0.3
    np.add.at(bottom, model.block_source[on_top[bed_like]], interfaces.area[bed_like])
    regular = (blocks.block_course >= 2) & (blocks.block_class != PAT)
    # its faces against its course direction, but the horizontal sliver its intrados
    # leaves under the chord of its bed's facets (inside the dome, touching nothing)
    along = np.einsum("ij,ij->i", blocks.face_normal, scene.block_up[blocks.face_block])
    down = (along < -0.9) & (blocks.face_normal[:, 2] > -1 + 1e-9)
    faces_down = [blocks.face_area[(blocks.face_block == b) & down].sum()
                  for b in np.flatnonzero(regular)]
    assert bottom[regular] == pytest.approx(np.array(faces_down), rel=1e-6)


# ---------------------------------------------------------------------- a lone brick
def test_a_lone_brick_on_a_conical_bed_stands_iff_tan_alpha_is_within_mu():
    """A brick alone on the courses below it stands iff the friction coefficient
    reaches the slope of the bed it rests on (docs/model.md 4.8): tan(alpha) <= mu.
    Its bed is one of the cone's chord facets, a little steeper than the cone (a brick
    on two facets rests in a valley, which slopes as the cone)."""
    scene = build(small())
    blocks = scene.blocks
    k = 11
    course, pattern = blocks.block_course, blocks.block_class == PAT
    below = ((course <= k - 1) & ~pattern) | (pattern & (course <= k - 2))

    def bed_of(brick):  # its faces down the cone, not the intrados sliver
        faces = np.flatnonzero(blocks.face_block == brick)
        down = blocks.face_normal[faces, 2]
        return faces[(down < -0.5) & (down > -np.cos(np.radians(1)))]

    brick = next(int(b) for b in np.flatnonzero((course == k) & ~pattern)
                 if len(bed_of(b)) == 1)
    keep = np.flatnonzero(below | (np.arange(blocks.n_blocks) == brick))
    part = dataclasses.replace(blocks.subset(keep), block_is_support=keep != brick)
    interfaces = detect(part, up=scene.block_up[keep])
    slope = np.arccos(-blocks.face_normal[bed_of(brick), 2])
    prof = profile_of(RevolutionDome(**SMALL))
    cone = np.arctan2(prof.nz[k - 1], prof.nx[k - 1])
    assert slope.min() >= cone - 1e-9 and slope.max() <= cone + np.radians(0.5)
    for mu, stands in ((0.999 * np.tan(slope.min()), False),
                       (1.001 * np.tan(slope.max()), True)):
        assert solve_rbe(part, interfaces, mu=mu, friction="net").feasible is stands


# ------------------------------------------------------------------- sector = whole
def test_the_cyclic_sector_is_the_whole_dome():
    """n sectors make the dome: n times the bricks and bed joints, the same verdict and
    n times the QP's objective (docs/model.md 6.4: the unique optimum is symmetric)."""
    sector_params, whole_params = small(boundary="cyclic"), small("revolution")
    n = ring_pattern(RevolutionDome(**SMALL)).symmetry
    sector, whole = build_model(sector_params), build_model(whole_params)
    free = [int((~s.blocks.block_is_support).sum()) for s, _ in (sector, whole)]
    assert free[1] == n * free[0] == len(rings_of(RevolutionDome(**SMALL)).course)
    beds = [int((m.interfaces.kind == BED).sum()) for _, m in (sector, whole)]
    assert beds[1] == n * beds[0]
    results = []
    for _, model in (sector, whole):
        problem = RBEProblem(model.blocks, model.interfaces, side_block=model.side_block,
                             side_rotation=model.side_rotation)
        results.append(problem.solve(mu=0.7, density=2000.0, accuracy="accurate"))
    assert results[0].verdict == results[1].verdict == "feasible"
    assert results[1].objective == pytest.approx(n * results[0].objective, rel=1e-5)


def test_the_plain_dome_has_the_courses_and_beds_without_the_pattern():
    plain, helix = (build(small("revolution", pattern=p)) for p in ("none", "herringbone"))
    assert not (plain.blocks.block_class == PAT).any()
    assert (helix.blocks.block_class == PAT).any()
    assert plain.blocks.block_course.max() == helix.blocks.block_course.max()
    np.testing.assert_array_equal(plain.levels.z, helix.levels.z)
    # every bed joint lies on a level of the same table: the same bed cones
    for scene in (plain, helix):
        free = ~scene.blocks.block_is_support
        z = np.minimum.reduceat(scene.blocks.vertices[:, 2],
                                scene.blocks.vertex_offsets[:-1])[free]
        assert np.isin(np.round(z, 12), np.round(helix.levels.z, 12)).all()


def test_the_printable_body_is_one_watertight_body():
    scene = build(small("revolution", radius=12, p=2, spirals=6, cut=0.4))
    mesh, report = printable_body(scene.blocks, scene.cad_vertices())
    assert report["watertight"] and report["bodies"] == 1
    assert mesh.is_watertight


# ---------------------------------------------------------------------- commands
@pytest.mark.slow
def test_run_writes_the_dome_of_revolution(tmp_path):
    args = ["run", "--scene", "sector", "--boundary", "cyclic", "--radius", "20", "--p", "3",
            "--cut", "0.3", "--fast", "--no-printable", "--out", str(tmp_path), "-q"]
    assert main(args) == 0
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.name.startswith(".")]
    assert folder.name.startswith("sector1_fast1_fricauto_R20_")
    assert (folder / "00_pattern.png").is_file() and (folder / "RBE" / "forces.csv").is_file()
    assert (folder / "05_dome" / "3_structure.png").is_file()


@pytest.mark.parametrize("args, named", [
    (["--scene", "revolution", "--cut", "0"], "--cut"),
    (["--scene", "revolution", "--helix-angle", "30"], "--helix-angle"),
    (["--scene", "sector", "--spirals", "60"], "--spirals"),
    (["--scene", "revolution", "--helix", "spiral"], "--helix"),
    (["--scene", "dome", "--radius", "20"], "--radius"),
])
def test_bad_inputs_are_refused_by_name(tmp_path, capsys, args, named):
    try:
        code = main(["run", *args, "--out", str(tmp_path / "x"), "-q"])
    except SystemExit as refused:  # argparse's choices
        code = refused.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0]
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("p", [1, 2, 10])
def test_the_default_start_nodes_are_at_least_three_bricks_apart(p):
    """Two pattern bricks and a regular brick (6 units) fit between any two start nodes
    of the default count, a multiple of four, whatever p asks: radius 20 units at p 1
    asks 2 (p + 1) = 4 units, less than 6."""
    g = validate(Params.of(scene="revolution", radius=20, p=p)).geometry
    count = default_spirals(g)
    assert count % 4 == 0 and 2 * np.pi * 20 / count >= 6
    assert build(validate(Params.of(scene="revolution", radius=20, p=p))).blocks.n_blocks
