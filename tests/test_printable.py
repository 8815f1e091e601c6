"""The printable body (docs/model.md 7, thesis 3.4.1): grown bricks, one watertight union, and the
STL as a slicer reads it back."""

import functools
import itertools

import numpy as np
import pytest
import trimesh
from conftest import scene_of

from masonry.blocks import Blocks
from masonry.export.stl import (STL_RECORD, obj_body_bytes, readback_check, stl_bytes,
                                stored_normal_errors)
from masonry.printable import (PrintableError, grown_blocks, printable_blocks, printable_body,
                               repeated_part)
from masonry.tolerances import OVERLAP_REL, Tolerances

SCENES = ("1", "2", "3", "wall")
# float32 STL: 24-bit mantissa at coordinates up to 7 m is 5e-7 m, so volumes read back
# agree to about 1e-7; 1e-5 leaves room
READBACK_RTOL = 1e-5
# union volume against the sum of brick volumes, measured: preset 1 -0.18 %, 2 -0.03 %,
# 3 -0.45 %, wall +0.04 %. The CAD offset makes consecutive courses overlap (the union
# of the ungrown bricks: -0.33, -0.19, -0.60, 0 %); the deliberate growth adds the
# exposed surface times the overlap (+0.15 to +0.16 % for the sections, +0.04 % wall)
BRICKS_RTOL = 0.01


@functools.cache
def body_of(name):
    """(mesh, report, stl bytes, read-back report) of a scene's CAD-offset bricks."""
    scene = scene_of(name)
    mesh, report = printable_body(scene.blocks, scene.cad_vertices())
    stl = stl_bytes(mesh)
    return mesh, report, stl, readback_check(stl, report["volume_m3"], rtol=READBACK_RTOL)


def box_corners(lo, hi):
    """(8, 3) corners of an axis-aligned box, corner index ``ix + 2 iy + 4 iz``."""
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1
    return np.asarray(lo, float) + bits * (np.asarray(hi, float) - np.asarray(lo, float))


def triangulated(blocks):
    """The same solids with every face split into triangles (vertices on up to 6
    faces), which sends them down the halfspace-intersection path."""
    tri = blocks.triangles
    return Blocks.from_arrays(blocks.vertices, blocks.vertex_offsets, tri.reshape(-1),
                              np.arange(len(tri) + 1) * 3,
                              blocks.face_block[blocks.triangle_face], blocks.block_class)


def grown_volumes(points, offsets):
    import manifold3d

    return np.array([manifold3d.Manifold.hull_points(points[lo:hi]).volume()
                     for lo, hi in itertools.pairwise(offsets)])


# ---------------------------------------------------------------------- growth
def test_grown_box_is_the_box_enlarged_on_every_side():
    blocks = Blocks.from_hexahedra(box_corners([0, 0, 0], [2.0, 3.0, 1.0])[None], "regular")
    points, offsets, by_halfspaces = grown_blocks(blocks, 0.01)
    np.testing.assert_array_equal(offsets, [0, 8])
    assert not by_halfspaces.any()
    np.testing.assert_allclose(points, box_corners([-0.01] * 3, [2.01, 3.01, 1.01]),
                               rtol=0, atol=1e-14)


def test_triangulated_box_takes_the_halfspace_path_and_grows_the_same():
    blocks = triangulated(Blocks.from_hexahedra(box_corners([0, 0, 0], [2.0, 3.0, 1.0])[None],
                                                "regular"))
    points, offsets, by_halfspaces = grown_blocks(blocks, 0.01)
    assert by_halfspaces.all()
    expected = box_corners([-0.01] * 3, [2.01, 3.01, 1.01])
    assert offsets[-1] == 8  # qhull's corners, in its own order
    np.testing.assert_allclose(np.sort(points.view("f8,f8,f8"), axis=0).view(float),
                               np.sort(expected.view("f8,f8,f8"), axis=0).view(float),
                               rtol=0, atol=1e-12)


def test_both_growth_paths_agree_on_mitered_dome_bricks():
    blocks = scene_of("1").blocks.subset(np.arange(40))
    overlap = 1e-3
    points, offsets, by_halfspaces = grown_blocks(blocks, overlap)
    assert not by_halfspaces.any()
    fast = grown_volumes(points, offsets)
    points, offsets, by_halfspaces = grown_blocks(triangulated(blocks), overlap)
    assert by_halfspaces.all()
    slow = grown_volumes(points, offsets)
    np.testing.assert_allclose(fast, slow, rtol=1e-12)


def test_growth_adds_surface_times_overlap():
    # V(d) = V + A d + O(d^2) for a convex polytope grown by d (faces moved outward)
    blocks = scene_of("1").blocks
    overlap = 1e-6
    grown = grown_volumes(*grown_blocks(blocks, overlap)[:2])
    surface = np.bincount(blocks.face_block, blocks.face_area)
    np.testing.assert_allclose((grown - blocks.block_volume) / overlap, surface, rtol=1e-3)


# ---------------------------------------------------------------------- union
@pytest.mark.parametrize("name", SCENES)
def test_union_is_one_watertight_body(name):
    mesh, report, _, _ = body_of(name)
    assert report["manifold_status"] == "NoError"
    assert report["watertight"] and report["winding_consistent"]
    assert report["bodies"] == mesh.body_count == 1
    assert report["genus"] == 0  # a section or wall on its slab has no handle
    assert report["zero_area_faces"] == report["close_vertex_pairs"] == 0
    assert report["halfspace_blocks"] == 0  # hexahedra: all grown by the batched solve
    assert report["overlap_m"] == pytest.approx(
        OVERLAP_REL * np.linalg.norm(np.ptp(scene_of(name).cad_vertices(), axis=0)))


@pytest.mark.parametrize("name", SCENES)
def test_stl_read_back_is_printable(name):
    _, report, stl, back = body_of(name)
    assert back["watertight"] and back["winding_consistent"]
    assert back["bodies"] == 1
    assert back["degenerate_faces"] == 0
    assert back["volume_m3"] == pytest.approx(report["volume_m3"], rel=READBACK_RTOL)
    assert back["triangles"] == report["triangles"]
    assert len(stl) == 84 + 50 * report["triangles"]  # binary STL layout
    # every stored normal is the unit normal of its float32 facet (what admesh checks)
    assert back["normal_errors"] == stored_normal_errors(stl) == 0


def facets(stl):
    return np.frombuffer(stl, dtype=STL_RECORD, offset=84)


def test_stl_normals_of_a_box_point_outward():
    box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    packed = facets(stl_bytes(box))
    # each facet's normal is the axis its centre lies out along
    centre = packed["vertices"].mean(axis=1)
    axis = np.argmax(np.abs(centre) / [0.5, 1.0, 1.5], axis=1)
    expected = np.zeros((len(packed), 3))
    expected[np.arange(len(packed)), axis] = np.sign(centre[np.arange(len(packed)), axis])
    np.testing.assert_array_equal(packed["normal"], expected)


def test_stl_normal_of_a_sliver_follows_its_float32_vertices():
    """A facet 3e-7 m thin at 5 m (float32 spacing there: 4.8e-7 m): rounding turns it;
    the stored normal turns with it, where trimesh stores the float64 normal."""
    vertices = np.array([[5.0, 5, 5], [5.001, 5 + 3e-7, 5], [5.002, 5, 5 + 2e-7]])
    sliver = trimesh.Trimesh(vertices, [[0, 1, 2]], process=False)
    data = stl_bytes(sliver)
    assert stored_normal_errors(data) == 0
    v = facets(data)["vertices"][0].astype(float)
    cross = np.cross(v[1] - v[0], v[2] - v[0])
    np.testing.assert_allclose(facets(data)["normal"][0], cross / np.linalg.norm(cross),
                               atol=1e-7)
    from trimesh.exchange.stl import export_stl
    assert stored_normal_errors(export_stl(sliver)) == 1


@pytest.mark.parametrize("name", SCENES)
def test_union_volume_is_close_to_the_bricks(name):
    _, report, _, _ = body_of(name)
    assert report["volume_m3"] == pytest.approx(report["blocks_volume_m3"], rel=BRICKS_RTOL)
    # a union never exceeds the sum of its parts
    assert report["volume_m3"] <= report["grown_volume_m3"] * (1 + 1e-12)


def test_wall_union_is_the_grown_box():
    # every wall brick moves by the same CAD offset, so slab and courses form one box
    # 0.2 x 3.2 x 1.1 m, grown by the overlap on all six sides
    _, report, _, _ = body_of("wall")
    d = report["overlap_m"]
    assert report["volume_m3"] == pytest.approx((0.2 + 2 * d) * (3.2 + 2 * d) * (1.1 + 2 * d),
                                                rel=1e-9)


def test_wall_volume_is_invariant_under_a_rigid_motion():
    rng = np.random.default_rng(7)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    matrix = np.eye(4)
    matrix[:3, :3] = q * np.sign(np.linalg.det(q))  # a rotation, not a reflection
    matrix[:3, 3] = rng.normal(size=3)
    blocks = scene_of("wall").blocks
    # the default overlap scales with the axis-aligned bounding box, which a rotation
    # changes: fix both
    tol = Tolerances.for_points(blocks.vertices)
    _, still = printable_body(blocks, overlap=5e-5, tol=tol)
    _, moved = printable_body(blocks.transformed(matrix), overlap=5e-5, tol=tol)
    assert moved["bodies"] == 1
    assert moved["volume_m3"] == pytest.approx(still["volume_m3"], rel=1e-9)


SMALL_DOME = dict(stretch=1.0, n=6, r=0, p=3, cut=0.5)


def test_turned_web_is_the_union_of_every_web():
    """The whole dome as one web's union turned into every web's place: the body of all
    its blocks united at once, within the cleaning's moves (contact times the surface)."""
    scene = scene_of("1", scene="dome", **SMALL_DOME)
    blocks, vertices, copies = printable_blocks(scene)
    assert copies == 6 and blocks.n_blocks * 6 == scene.blocks.n_blocks
    mesh, turned = printable_body(blocks, vertices, copies=copies)
    _, whole = printable_body(scene.blocks, scene.cad_vertices())
    assert turned["watertight"] and turned["bodies"] == mesh.body_count == 1
    assert turned["copies"] == 6 and whole["copies"] == 1
    assert turned["clean_distance_m"] == whole["clean_distance_m"]
    for key in ("blocks_volume_m3", "grown_volume_m3"):
        assert turned[key] == pytest.approx(whole[key], rel=1e-12)
    surface = mesh.area
    assert abs(turned["volume_m3"] - whole["volume_m3"]) < turned["clean_distance_m"] * surface
    # the section in dome mode: the same body
    section = scene_of("1", **SMALL_DOME)
    blocks, vertices, copies = printable_blocks(section, "cyclic")
    assert copies == 6 and blocks.n_blocks == section.blocks.n_blocks
    _, cyclic = printable_body(blocks, vertices, copies=copies)
    assert cyclic["volume_m3"] == pytest.approx(turned["volume_m3"], rel=1e-12)


def test_a_dome_whose_webs_differ_is_united_whole():
    scene = scene_of("1", scene="dome", **SMALL_DOME)
    cad = scene.cad_vertices()
    first = repeated_part(scene.blocks, cad, 6)
    assert first.sum() * 6 == scene.blocks.n_blocks
    moved = cad.copy()
    moved[-1, 2] += 1e-6  # one vertex of the last web
    assert repeated_part(scene.blocks, moved, 6) is None
    assert repeated_part(scene.blocks, cad, 4) is None  # not 4 equal webs


def test_separate_blocks_raise():
    corners = np.stack([box_corners([0, 0, 0], [1, 1, 1]), box_corners([2, 0, 0], [3, 1, 1])])
    with pytest.raises(PrintableError, match="2 bodies") as error:
        printable_body(Blocks.from_hexahedra(corners, "regular"))
    assert error.value.report["bodies"] == 2


def test_bad_overlap_and_vertices_raise():
    blocks = scene_of("wall").blocks
    with pytest.raises(ValueError, match="overlap"):
        printable_body(blocks, overlap=-1e-4)
    with pytest.raises(ValueError, match="shape"):
        printable_body(blocks, blocks.vertices[:-1])
    with pytest.raises(ValueError, match="copies"):
        printable_body(blocks, copies=0)


# ---------------------------------------------------------------------- files
def test_readback_check_rejects_an_open_mesh():
    box = trimesh.creation.box()
    open_box = trimesh.Trimesh(box.vertices, box.faces[:-1], process=False)
    with pytest.raises(PrintableError, match="not watertight"):
        readback_check(stl_bytes(open_box))
    with pytest.raises(PrintableError, match="volume"):
        readback_check(stl_bytes(box), volume_m3=2.0)


def test_obj_body_round_trips():
    mesh, report, _, _ = body_of("3")
    data = obj_body_bytes(mesh)
    assert b"\no dome\n" in data
    back = trimesh.load_mesh(trimesh.util.wrap_as_stream(data), file_type="obj")
    assert back.is_watertight and back.body_count == 1
    # 8 decimals in metres
    assert back.volume == pytest.approx(report["volume_m3"], rel=1e-7)


# ---------------------------------------------------------------------- 3MF
@pytest.mark.parametrize("name, size_mm", [("wall", 150.0), ("1", 180.0)])
def test_3mf_reads_back_in_millimetres_at_the_print_size(name, size_mm):
    from masonry.export.threemf import readback_3mf, threemf_bytes

    mesh, report, _, _ = body_of(name)
    back = readback_3mf(threemf_bytes(mesh, size_mm))
    assert back["unit"] == "millimeter" and back["objects"] == 1 and back["watertight"]
    assert max(back["extents_mm"]) == pytest.approx(size_mm, rel=1e-6)
    scale = size_mm / np.ptp(mesh.vertices, axis=0).max()  # mm per metre
    np.testing.assert_allclose(back["extents_mm"], np.ptp(mesh.vertices, axis=0) * scale,
                               rtol=1e-6)
    assert back["volume_mm3"] == pytest.approx(report["volume_m3"] * scale ** 3, rel=1e-5)
