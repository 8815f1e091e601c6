"""Contact interface detection (docs/model.md 5, thesis 3.2.4) on boxes built by hand."""

import dataclasses
import itertools

import numpy as np
import pytest
import shapely

from masonry.blocks import Blocks
from masonry.interfaces import (
    INTERFACE_KINDS,
    _area_centroid,
    _clean,
    _clip_convex,
    candidate_pairs,
    detect,
)
from masonry.params import from_preset
from masonry.scenes import build
from masonry.tolerances import Tolerances

KIND = {name: code for code, name in enumerate(INTERFACE_KINDS)}
REL = 1e-9  # relative tolerance on areas of exact geometry

# the running-bond wall below: courses of 4 full bricks alternate with courses of
# half + 3 full + half; every brick is 2 thick and 1 high, on a ground slab
WALL_COURSES = 5
WALL_FULL = 4


def bond_counts(courses, n_full):
    """Interfaces of a running-bond wall counted from its bond pattern: courses of
    ``n_full`` full bricks (the first, third, ...) alternate with courses of ``n_full - 1``
    full bricks and a half brick at each end. Every full brick overlaps two bricks of the
    next course by half its length (2 n_full bed joints per course transition); a course
    of m bricks has m - 1 head joints; the first course's bricks stand on the slab."""
    full, halved = (courses + 1) // 2, courses // 2
    return {"horizontal": 2 * n_full * (courses - 1),
            "vertical": full * (n_full - 1) + halved * n_full,
            "support": n_full, "boundary": 0}


# 4 bricks of course 1 stand on the slab; head joints: 3 per 4-brick course (x3) plus
# 4 per 5-brick course (x2); every one of the 4 course transitions has 8 bed joints
WALL_COUNTS = {"horizontal": 4 * 8, "vertical": 3 * 3 + 2 * 4, "support": 4, "boundary": 0}


# ---------------------------------------------------------------------- builders
def box_corners(lo, hi):
    """(8, 3) corners of an axis-aligned box, corner index ``ix + 2 iy + 4 iz``."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    index = np.arange(8)
    bits = np.stack([index & 1, (index >> 1) & 1, (index >> 2) & 1], axis=1)
    return lo + bits * (hi - lo)


def running_bond_wall(courses=WALL_COURSES, n_full=WALL_FULL):
    """A running-bond wall along y (thickness 2 along x, courses 1 high) on a ground slab.

    Returns the blocks (slab first) and their boxes, (B, 2, 3) float (min, max corner).
    """
    length = 4.0 * n_full
    boxes = [([0.0, 0.0, -1.0], [2.0, length, 0.0])]
    for course in range(courses):
        if course % 2 == 0:
            joints = np.arange(0.0, length + 1.0, 4.0)
        else:
            joints = np.concatenate([[0.0], np.arange(2.0, length, 4.0), [length]])
        boxes += [([0.0, y0, course], [2.0, y1, course + 1.0])
                  for y0, y1 in itertools.pairwise(joints)]
    boxes = np.array(boxes)
    corners = np.array([box_corners(lo, hi) for lo, hi in boxes])
    block_class = ["ground"] + ["regular"] * (len(boxes) - 1)
    return Blocks.from_hexahedra(corners, block_class), boxes


def wedge_pair(angle_deg, lift=0.0, upper_first=False):
    """A box with a second, narrower box on top, tilted open by a wedge angle.

    Lower box ``[0, 2] x [0, 4] x [0, 1]``; upper box ``[0, 1.5] x [1, 5] x [1, 2]``
    rotated by ``angle_deg`` about the line ``x = 0, z = 1`` (its bottom face keeps the
    edge ``x = 0`` on the lower top face and rises towards +x), then lifted by ``lift``.
    """
    lower = box_corners([0, 0, 0], [2, 4, 1])
    upper = box_corners([0, 1, 1], [1.5, 5, 2])
    a = np.radians(angle_deg)
    rotation = np.array([[np.cos(a), 0, -np.sin(a)], [0, 1, 0], [np.sin(a), 0, np.cos(a)]])
    hinge = np.array([0.0, 0.0, 1.0])
    upper = (upper - hinge) @ rotation.T + hinge + [0.0, 0.0, lift]
    corners = np.array([upper, lower] if upper_first else [lower, upper])
    return Blocks.from_hexahedra(corners, "regular")


def random_rotation(rng, keep_z=False):
    """A seeded proper rotation (3, 3); about z only when ``keep_z``."""
    if keep_z:
        a = rng.uniform(0, 2 * np.pi)
        return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def rigid(rotation, translation):
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, translation
    return matrix


def box_contact_area(box_i, box_j):
    """Area shared by two touching axis-aligned boxes: the two largest overlaps' product."""
    overlap = np.minimum(box_i[1], box_j[1]) - np.maximum(box_i[0], box_j[0])
    return np.sort(overlap)[1] * np.sort(overlap)[2], overlap


def area_by_pair(interfaces):
    """{(i, j) with i < j: area}; fails on a pair reported twice."""
    out = {}
    for (i, j), area in zip(interfaces.pair, interfaces.area):
        key = (min(i, j), max(i, j))
        assert key not in out
        out[key] = area
    return out


def polygon_area_vector(polygon):
    """Newell area vector of a closed 3D polygon, (3,) float."""
    return 0.5 * np.cross(polygon, np.roll(polygon, -1, axis=0)).sum(axis=0)


# ---------------------------------------------------------------------- running bond
def test_wall_counts_and_areas_match_box_overlaps():
    blocks, boxes = running_bond_wall()
    found = detect(blocks, Tolerances(scale=20.0))

    assert found.counts() == WALL_COUNTS
    # every pair of boxes sharing a face patch of positive area, and only those
    expected = {}
    for i, j in itertools.combinations(range(len(boxes)), 2):
        area, overlap = box_contact_area(boxes[i], boxes[j])
        if np.sum(overlap == 0.0) == 1 and np.all(overlap >= 0.0) and area > 0:
            expected[(i, j)] = area
    got = area_by_pair(found)
    assert got.keys() == expected.keys()
    for key, area in expected.items():
        assert got[key] == pytest.approx(area, rel=REL)


def test_wall_main_block_normal_and_kind():
    blocks, boxes = running_bond_wall()
    found = detect(blocks, Tolerances(scale=20.0))
    centre = boxes.mean(axis=1)
    for (main, other), kind, normal in zip(found.pair, found.kind, found.normal):
        step = centre[other] - centre[main]
        if kind == KIND["vertical"]:
            # a head joint: same course, parallel faces, the smaller index is main
            assert main < other
            np.testing.assert_allclose(normal, np.sign(step[1]) * np.array([0, 1, 0]))
        else:
            # bed joints and the ground: the lower block (the slab) is main, normal up
            assert step[2] == pytest.approx(1.0)
            assert (kind == KIND["support"]) == (main == 0)
            np.testing.assert_allclose(normal, [0, 0, 1])
    assert np.array_equal(found.pair, found.pair[np.lexsort(found.pair.T[::-1])])


def test_wall_polygons_are_consistent_frames():
    blocks, _ = running_bond_wall()
    found = detect(blocks, Tolerances(scale=20.0))
    # overlaps of rectangles with parallel edges are rectangles: shared edges and
    # corners left no duplicate or collinear vertices
    assert np.all(found.vertex_count == 4)
    frame = np.stack([found.t1, found.t2, found.normal], axis=1)
    np.testing.assert_allclose(frame @ frame.transpose(0, 2, 1),
                               np.broadcast_to(np.eye(3), frame.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(frame), 1.0)
    for k in range(len(found)):
        polygon = found.polygon(k)
        # counter-clockwise about the normal, with the reported area
        area_vector = polygon_area_vector(polygon)
        assert area_vector @ found.normal[k] == pytest.approx(found.area[k], rel=REL)
        # vertices in the plane through the centre; rectangles: centre = vertex mean
        np.testing.assert_allclose((polygon - found.centre[k]) @ found.normal[k], 0.0, atol=1e-12)
        np.testing.assert_allclose(found.centre[k], polygon.mean(axis=0), atol=1e-12)


def test_bond_counts_formula_matches_the_hand_count():
    assert bond_counts(WALL_COURSES, WALL_FULL) == WALL_COUNTS


@pytest.mark.parametrize("courses, n_full", [(2, 1), (3, 7), (6, 5)])
def test_wall_counts_follow_the_bond_pattern(courses, n_full):
    blocks, _ = running_bond_wall(courses, n_full)
    assert detect(blocks, Tolerances(scale=4.0 * n_full)).counts() == bond_counts(
        courses, n_full)


def test_wall_preset_counts_follow_its_bond_pattern():
    """The ``wall`` scene (courses of 4-unit bricks along ``wall_length`` units, half
    bricks at the ends of every second course) has the interfaces its bond implies."""
    params = from_preset("wall")
    scene = build(params)
    n_full = params.geometry.wall_length / 4.0
    assert n_full == int(n_full)
    assert (detect(scene.blocks, up=scene.block_up).counts()
            == bond_counts(params.geometry.wall_courses, int(n_full)))


@pytest.mark.parametrize("size", [1e-3, 1.0, 1e3])
def test_default_tolerances_follow_the_scene_size(size):
    """Without explicit tolerances, detection scales with the model: the wall built in
    millimetres or kilometres has the hand-counted interfaces and areas, and a gap of
    1e-8 of the wall's size between courses 2 and 3 is closed, one of 1e-4 is not."""
    blocks, boxes = running_bond_wall()
    scaled = dataclasses.replace(blocks, vertices=size * blocks.vertices)
    found = detect(scaled)
    assert found.counts() == WALL_COUNTS
    assert found.area.sum() == pytest.approx(size**2 * hand_area_sum(boxes), rel=REL)

    span = size * np.linalg.norm(np.ptp(blocks.vertices, axis=0))
    # every vertex of the bricks of courses 3 to 5 (boxes from z = 2 up)
    lifted = np.repeat(boxes[:, 0, 2] >= 2.0, np.diff(blocks.vertex_offsets))
    above = lifted[:, None] * np.array([0.0, 0.0, 1.0])
    closed = dataclasses.replace(blocks, vertices=size * blocks.vertices + 1e-8 * span * above)
    assert detect(closed).counts() == WALL_COUNTS
    opened = dataclasses.replace(blocks, vertices=size * blocks.vertices + 1e-4 * span * above)
    # the 8 bed joints between courses 2 and 3 open
    assert detect(opened).counts() == WALL_COUNTS | {"horizontal": WALL_COUNTS["horizontal"] - 8}


def hand_area_sum(boxes):
    """Sum of the contact areas of all touching pairs of axis-aligned ``boxes``."""
    total = 0.0
    for i, j in itertools.combinations(range(len(boxes)), 2):
        area, overlap = box_contact_area(boxes[i], boxes[j])
        if np.sum(overlap == 0.0) == 1 and np.all(overlap >= 0.0):
            total += area
    return total


# ---------------------------------------------------------------------- invariance
@pytest.mark.parametrize("seed", [0, 1])
def test_wall_invariant_under_rotation_about_z(seed):
    rng = np.random.default_rng(seed)
    blocks, _ = running_bond_wall()
    tol = Tolerances(scale=20.0)
    reference = detect(blocks, tol)
    moved = detect(blocks.transformed(rigid(random_rotation(rng, keep_z=True),
                                            rng.uniform(-50, 50, 3))), tol)
    assert moved.counts() == reference.counts()
    assert np.array_equal(moved.pair, reference.pair)
    np.testing.assert_allclose(moved.area, reference.area, rtol=REL)


@pytest.mark.parametrize("seed", [2, 3])
def test_wall_areas_invariant_under_any_rigid_motion(seed):
    # z decides kinds and main blocks, so compare unordered pairs and areas only
    rng = np.random.default_rng(seed)
    blocks, _ = running_bond_wall()
    tol = Tolerances(scale=20.0)
    reference = area_by_pair(detect(blocks, tol))
    moved = area_by_pair(detect(blocks.transformed(rigid(random_rotation(rng),
                                                         rng.uniform(-50, 50, 3))), tol))
    assert moved.keys() == reference.keys()
    for key, area in reference.items():
        assert moved[key] == pytest.approx(area, rel=REL)


# ---------------------------------------------------------------------- gap closing
# Rotating the upper box's bottom face back about the hinge x = 0 restores
# [0, 1.5] x [1, 5] in the plane z = 1; it overlaps the lower top face [0, 2] x [0, 4] in
# [0, 1.5] x [1, 4]. (Projecting instead would give 1.5 cos(angle) x 3.)
WEDGE_AREA = 1.5 * 3.0


@pytest.mark.parametrize("angle_deg", [0.0, 3.0, 9.0])
@pytest.mark.parametrize("upper_first", [False, True])
def test_wedge_is_closed_onto_the_lower_face(angle_deg, upper_first):
    blocks = wedge_pair(angle_deg, upper_first=upper_first)
    lower, upper = (1, 0) if upper_first else (0, 1)
    found = detect(blocks, Tolerances(scale=10.0))

    assert len(found) == 1
    assert found.pair.tolist() == [[lower, upper]]
    assert found.kind.tolist() == [KIND["horizontal"]]
    assert found.area[0] == pytest.approx(WEDGE_AREA, rel=REL)
    np.testing.assert_allclose(found.normal[0], [0, 0, 1], atol=1e-15)
    polygon = found.polygon(0)
    np.testing.assert_allclose(polygon[:, 2], 1.0, atol=1e-12)
    np.testing.assert_allclose(np.sort(polygon[:, 0]), [0, 0, 1.5, 1.5], atol=1e-12)
    np.testing.assert_allclose(np.sort(polygon[:, 1]), [1, 1, 4, 4], atol=1e-12)
    np.testing.assert_allclose(found.centre[0], [0.75, 2.5, 1.0], atol=1e-12)


def test_wedge_invariant_under_rigid_motion():
    rng = np.random.default_rng(4)
    tol = Tolerances(scale=10.0)
    for keep_z in (True, False):
        rotation = random_rotation(rng, keep_z=keep_z)
        found = detect(wedge_pair(4.0).transformed(rigid(rotation, rng.uniform(-5, 5, 3))),
                       tol)
        assert len(found) == 1
        assert found.area[0] == pytest.approx(WEDGE_AREA, rel=REL)
        if keep_z:  # the lower box stays main: its top face, moved
            np.testing.assert_allclose(found.normal[0], rotation[:, 2], atol=1e-12)


def test_wedge_within_contact_tolerance_is_found_beyond_it_is_not():
    tol = Tolerances(scale=10.0)  # contact = 1e-5
    assert len(detect(wedge_pair(3.0, lift=0.5 * tol.contact), tol)) == 1
    assert len(detect(wedge_pair(3.0, lift=10.0 * tol.contact), tol)) == 0
    assert len(detect(wedge_pair(0.0, lift=10.0 * tol.contact), tol)) == 0


def test_wedge_wider_than_max_gap_angle_is_open():
    tol = Tolerances(scale=10.0)
    assert np.degrees(tol.max_gap_angle) == pytest.approx(10.0)
    assert len(detect(wedge_pair(12.0), tol)) == 0


def test_planes_meeting_outside_the_faces_do_not_touch():
    # the upper box's hinge x = 2.5 lies beyond the lower top face (x <= 2); its bottom
    # face rises over the lower box, so the two faces never touch although rotating
    # about the hinge would make them overlap
    lower = box_corners([0, 0, 0], [2, 4, 1])
    upper = box_corners([1, 0, 1], [2.5, 4, 2])
    a = np.radians(3.0)
    rotation = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    hinge = np.array([2.5, 0.0, 1.0])
    upper = (upper - hinge) @ rotation.T + hinge
    blocks = Blocks.from_hexahedra(np.array([lower, upper]), "regular")
    assert len(detect(blocks, Tolerances(scale=10.0))) == 0


def test_faces_reaching_the_hinge_at_different_places_do_not_touch():
    # The upper box's bottom edge lies on the line x + y = 6 of the plane z = 1 between
    # (3, 3) and (6, 0); the lower top face [0, 2] x [0, 4] reaches that line only at its
    # corner (2, 4). Both faces have vertices on the planes' common line, and rotating
    # the upper face back would overlap the lower one, but they touch nowhere.
    along, inward = np.array([1.0, -1.0, 0.0]) / np.sqrt(2), -np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    hinge = np.array([3.0, 3.0, 1.0])
    index = np.arange(8)
    upper = (hinge + np.outer(3 * np.sqrt(2) * (index & 1), along)
             + np.outer(3.0 * ((index >> 1) & 1), inward)
             + np.outer((index >> 2) & 1, [0.0, 0.0, 1.0]))
    a = np.radians(3.0)  # about -along, so that the inward side rises
    k = -along
    v = upper - hinge
    upper = hinge + (v * np.cos(a) + np.cross(k, v) * np.sin(a)
                     + np.outer(v @ k, k) * (1 - np.cos(a)))
    assert upper[2, 2] > 1.0 + 0.1  # the inward bottom edge has risen
    blocks = Blocks.from_hexahedra(np.array([box_corners([0, 0, 0], [2, 4, 1]), upper]),
                                   "regular")
    assert len(detect(blocks, Tolerances(scale=10.0))) == 0


def test_square_on_square_turned_by_45_degrees_is_an_octagon():
    lower = box_corners([-1, -1, 0], [1, 1, 1])
    a = np.pi / 4
    turn = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    upper = box_corners([-1, -1, 1], [1, 1, 2]) @ turn.T
    found = detect(Blocks.from_hexahedra(np.array([lower, upper]), "regular"),
                   Tolerances(scale=10.0))
    assert found.vertex_count.tolist() == [8]
    # a regular octagon with inradius 1: 8 tan(22.5 deg) = 8 (sqrt 2 - 1)
    assert found.area[0] == pytest.approx(8 * (np.sqrt(2) - 1), rel=REL)
    assert polygon_area_vector(found.polygon(0))[2] == pytest.approx(found.area[0], rel=REL)
    np.testing.assert_allclose(found.centre[0], [0, 0, 1], atol=1e-12)


# ---------------------------------------------------------------------- supports, empty
def test_support_is_main_even_above_a_free_block():
    corners = np.array([box_corners([0, 0, 0], [2, 4, 1]), box_corners([-1, -1, 1], [3, 5, 2])])
    blocks = Blocks.from_hexahedra(corners, ["regular", "ground"])
    found = detect(blocks, Tolerances(scale=10.0))
    assert found.pair.tolist() == [[1, 0]]
    assert found.kind.tolist() == [KIND["support"]]
    np.testing.assert_allclose(found.normal[0], [0, 0, -1])
    assert found.area[0] == pytest.approx(8.0, rel=REL)


def test_two_supports_are_never_paired():
    corners = np.array([box_corners([0, 0, 0], [2, 4, 1]), box_corners([0, 4, 0], [2, 8, 1])])
    blocks = Blocks.from_hexahedra(corners, "ground")
    tol = Tolerances(scale=10.0)
    assert len(candidate_pairs(blocks, tol)) == 0
    assert len(detect(blocks, tol)) == 0


def test_blocks_far_apart_give_an_empty_result():
    corners = np.array([box_corners([0, 0, 0], [2, 4, 1]), box_corners([100, 0, 0], [102, 4, 1])])
    blocks = Blocks.from_hexahedra(corners, "regular")
    found = detect(blocks)
    assert len(found) == 0
    assert found.pair.shape == (0, 2)
    assert found.offsets.tolist() == [0]
    assert len(candidate_pairs(blocks)) == 0


# ---------------------------------------------------------------------- spatial index
def test_candidate_pairs_are_the_touching_boxes():
    blocks, boxes = running_bond_wall()
    tol = Tolerances(scale=20.0)
    expected = [[i, j] for i, j in itertools.combinations(range(len(boxes)), 2)
                if np.all(np.minimum(boxes[i, 1], boxes[j, 1])
                          - np.maximum(boxes[i, 0], boxes[j, 0]) >= -tol.contact)]
    assert candidate_pairs(blocks, tol).tolist() == expected


@pytest.mark.parametrize("n_full", [10, 100])
def test_candidate_pairs_grow_linearly(n_full):
    # each brick touches at most 2 bricks in its course and 2 above (or the slab): a
    # spatial index finds about 3 pairs per block, all pairs would be n (n - 1) / 2
    blocks, _ = running_bond_wall(courses=6, n_full=n_full)
    pairs = candidate_pairs(blocks, Tolerances.for_points(blocks.vertices))
    assert len(pairs) <= 3 * blocks.n_blocks
    found = detect(blocks)
    assert found.counts() == bond_counts(6, n_full)
    assert len(found) <= len(pairs)


# ---------------------------------------------------------------------- polygon clipping
def convex_polygon(rng, centre, count):
    """A random convex polygon: the hull of ``count`` points, (m, 2) counter-clockwise."""
    points = centre + rng.normal(size=(count, 2))
    return shapely.get_coordinates(shapely.convex_hull(shapely.multipoints(points)))[:-1][::-1]


def padded(polygons):
    """(2, W, S) float from a list of (m, 2) polygons, each padded with its last vertex."""
    width = max(len(p) for p in polygons)
    return np.stack([np.concatenate([p, np.repeat(p[-1:], width - len(p), axis=0)])
                     for p in polygons], axis=-1).transpose(1, 0, 2)


def clipping_cases():
    """Pairs of convex polygons: random ones, and the degenerate ones masonry is full of
    (identical faces, shared edges and corners, containment, touching corners, collinear
    vertices)."""
    rng = np.random.default_rng(11)
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    pairs = [(convex_polygon(rng, [0, 0], int(rng.integers(3, 8))),
              convex_polygon(rng, rng.uniform(-2, 2, 2), int(rng.integers(3, 8))))
             for _ in range(300)]
    pairs += [(square, square), (square, square + [1.0, 0.0]), (square, square + [2.0, 0.0]),
              (square, square + [2.0, 1.0]), (square, 0.5 * square + [0.5, 0.25]),
              (0.5 * square + [0.5, 0.25], square), (square, square[[1, 2, 3, 0]] + [0, 0.5]),
              (square, np.array([[1.0, 0.0], [3.0, 1.0], [1.0, 1.0]])),
              # a face with a vertex in the middle of an edge (an imported mesh's)
              (np.insert(square, 1, [1.0, 0.0], axis=0), 2 * square - 0.5)]
    return pairs


def test_convex_clipping_matches_shapely():
    pairs = clipping_cases()
    subject, clip = padded([p for p, _ in pairs]), padded([q for _, q in pairs])
    xy = _clip_convex(subject, clip, 1e-12)
    area, centroid = _area_centroid(xy)
    expected = shapely.intersection([shapely.Polygon(p) for p, _ in pairs],
                                    [shapely.Polygon(q) for _, q in pairs])
    np.testing.assert_allclose(area, shapely.area(expected), rtol=1e-9, atol=1e-12)
    overlap = area > 1e-9
    assert overlap.sum() > 100
    np.testing.assert_allclose(centroid[:, overlap].T,
                               shapely.get_coordinates(shapely.centroid(expected[overlap])),
                               atol=1e-9)
    # after cleaning: the vertices of the exact intersection, without repeats
    xy, count = _clean(xy[..., overlap], 1e-12)
    simplified = shapely.simplify(expected[overlap], 1e-12)
    assert count.tolist() == (shapely.get_num_coordinates(simplified) - 1).tolist()
    np.testing.assert_allclose(_area_centroid(xy)[0], shapely.area(expected[overlap]),
                               rtol=1e-9)
