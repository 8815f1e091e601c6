"""Round trips of the VTU and 3DM exporters (docs/model.md 7)."""

import functools
import sys

import meshio
import numpy as np
import pytest
from conftest import scene_of

from masonry.blocks import BLOCK_CLASSES
from masonry.export.rhino import SUPPORT_LAYER, block_user_text, blocks_3dm
from masonry.export.vtu import interfaces_vtu
from masonry.interfaces import INTERFACE_KINDS, Interfaces, detect
from masonry.rbe.boundary import Model

# binary VTU stores float64 as is
VTU_RTOL = 1e-12
# the per-interface resultants of RBE/forces.csv (docs/model.md 6.7)
FORCE_NAMES = ("compression", "tension", "normal", "t1", "t2", "friction")


@functools.cache
def interfaces_of(name):
    scene = scene_of(name)
    return detect(scene.blocks, up=scene.block_up)


def random_forces(count, seed=0):
    rng = np.random.default_rng(seed)
    return {key: rng.normal(scale=1e3, size=count) for key in FORCE_NAMES}


def polygon_interfaces():
    """Three interfaces by hand: a triangle, a pentagon and a quad, in that order, so
    that the file's cell blocks (by vertex count) reorder them."""
    polygons = [np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)]
    angle = 2 * np.pi * np.arange(5) / 5
    polygons.append(np.column_stack([np.cos(angle), np.sin(angle), np.ones(5)]))
    polygons.append(np.array([[0, 0, 2], [1, 0, 2], [1, 1, 2], [0, 1, 2]], float))
    count = len(polygons)
    z3 = np.tile([0.0, 0.0, 1.0], (count, 1))
    return Interfaces(
        pair=np.array([[0, 1], [1, 2], [2, 3]]), kind=np.array([0, 1, 2], np.int8),
        vertices=np.concatenate(polygons),
        offsets=np.concatenate([[0], np.cumsum([len(p) for p in polygons])]),
        area=np.array([0.5, 2.5 * np.sin(2 * np.pi / 5), 1.0]),
        centre=np.array([p.mean(axis=0) for p in polygons]), normal=z3,
        t1=np.tile([1.0, 0.0, 0.0], (count, 1)), t2=np.tile([0.0, 1.0, 0.0], (count, 1)))


def read_vtu(data, tmp_path):
    path = tmp_path / "interfaces.vtu"
    path.write_bytes(data)
    return meshio.read(path)


def check_vtu_round_trip(interfaces, forces, tmp_path):
    """The file holds one cell per interface with its polygon and all cell data."""
    mesh = read_vtu(interfaces_vtu(interfaces, forces), tmp_path)
    assert sum(len(block.data) for block in mesh.cells) == len(interfaces)
    data = {name: np.concatenate(arrays) for name, arrays in mesh.cell_data.items()}
    row = data["interface"]
    # cells in interface order: the rows of interfaces.csv and forces.csv
    np.testing.assert_array_equal(row, np.arange(len(interfaces)))
    expected = dict(forces, kind=interfaces.kind, area_m2=interfaces.area,
                    frame_normal=interfaces.normal, frame_t1=interfaces.t1,
                    frame_t2=interfaces.t2)
    assert set(data) == set(expected) | {"interface"}
    for name, value in expected.items():
        np.testing.assert_allclose(data[name], np.asarray(value)[row], rtol=VTU_RTOL,
                                   atol=0, err_msg=name)
    assert data["kind"].dtype.kind == "i"
    # every cell's polygon is its interface's polygon, vertex for vertex
    cell_rows = np.split(row, np.cumsum([len(block.data) for block in mesh.cells])[:-1])
    for block, rows in zip(mesh.cells, cell_rows):
        size = block.data.shape[1]
        assert block.type == {3: "triangle", 4: "quad"}.get(size, "polygon")
        np.testing.assert_array_equal(interfaces.vertex_count[rows], size)
        for cell, k in zip(block.data, rows):
            np.testing.assert_allclose(mesh.points[cell], interfaces.polygon(k),
                                       rtol=VTU_RTOL, atol=0)


def test_vtu_round_trips_triangle_quad_and_polygon_cells(tmp_path):
    interfaces = polygon_interfaces()
    check_vtu_round_trip(interfaces, random_forces(len(interfaces)), tmp_path)


def test_vtu_round_trips_the_interfaces_of_preset_1(tmp_path):
    interfaces = interfaces_of("1")
    assert set(np.unique(interfaces.vertex_count)) >= {4, 6}  # quads and hexagons
    check_vtu_round_trip(interfaces, random_forces(len(interfaces), seed=1), tmp_path)


def test_vtu_names_the_kinds_in_field_data_and_is_binary(tmp_path):
    data = interfaces_vtu(polygon_interfaces(), {})
    mesh = read_vtu(data, tmp_path)
    assert {name: int(value[0]) for name, value in mesh.field_data.items()} == {
        f"kind_{name}": code for code, name in enumerate(INTERFACE_KINDS)}
    # binary, not compressed (zlib was most of a run's export time)
    assert b'format="binary"' in data and b"compressor" not in data


def test_vtu_takes_vector_cell_data(tmp_path):
    interfaces = polygon_interfaces()
    shear = np.random.default_rng(2).normal(size=(len(interfaces), 3))
    mesh = read_vtu(interfaces_vtu(interfaces, {"shear": shear}), tmp_path)
    np.testing.assert_array_equal(np.concatenate(mesh.cell_data["shear"]), shear)


def test_vtu_rejects_bad_forces():
    interfaces = polygon_interfaces()
    with pytest.raises(ValueError, match="shape"):
        interfaces_vtu(interfaces, {"compression": np.zeros(len(interfaces) + 1)})
    with pytest.raises(ValueError, match="reserved"):
        interfaces_vtu(interfaces, {"kind": np.zeros(len(interfaces))})
    with pytest.raises(ValueError, match="no interfaces"):
        interfaces_vtu(Interfaces.empty(), {})


# ---------------------------------------------------------------------- 3dm
def test_3dm_has_one_named_closed_unwelded_mesh_per_brick_with_user_text():
    rhino3dm = pytest.importorskip("rhino3dm")
    blocks = scene_of("1").blocks
    model = rhino3dm.File3dm.FromByteArray(blocks_3dm(blocks,
                                                      user_text=block_user_text(blocks)))
    assert model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Meters
    layers = [layer.Name for layer in model.Layers]
    free = ~blocks.block_is_support
    assert layers == [BLOCK_CLASSES[c] for c in np.unique(blocks.block_class[free])] + [
        SUPPORT_LAYER]
    assert len(model.Objects) == blocks.n_blocks
    for i, item in enumerate(model.Objects):
        attributes = item.Attributes
        assert attributes.Name == blocks.block_name[i]
        layer = layers[attributes.LayerIndex]
        assert layer == (BLOCK_CLASSES[blocks.block_class[i]] if free[i] else SUPPORT_LAYER)
        assert attributes.GetUserString("course") == str(blocks.block_course[i])
        assert attributes.GetUserString("class") == BLOCK_CLASSES[blocks.block_class[i]]
        assert attributes.GetUserString("web") == "0"
        mesh = item.Geometry
        assert mesh.IsClosed and mesh.IsValid
        faces = blocks.block_faces(i)
        assert len(mesh.Faces) == len(faces)  # hexahedra: six quads
        # unwelded: every face has its own four vertices, and their normals are the
        # face's outward normal (flat shading)
        points = np.array([[p.X, p.Y, p.Z] for p in mesh.Vertices.ToPoint3dArray()])
        normals = np.array([[n.X, n.Y, n.Z] for n in mesh.Normals])
        assert len(points) == 4 * len(faces)
        for k, f in enumerate(faces):
            corners = blocks.face_vertices[blocks.face_offsets[f]:blocks.face_offsets[f + 1]]
            # double-precision vertices: exact
            np.testing.assert_array_equal(points[4 * k:4 * k + 4],
                                          blocks.vertices[corners])
            np.testing.assert_allclose(normals[4 * k:4 * k + 4],
                                       np.tile(blocks.face_normal[f], (4, 1)), atol=1e-6)


def test_3dm_of_a_cyclic_section_turns_it_to_the_whole_dome_as_block_instances():
    """The section's bricks as meshes; each other web an instance of one block definition
    of them, which Rhino's own transform puts where the whole dome's bricks are."""
    from masonry.export import EXPORTERS, RunOutputs
    from masonry.export.rhino import COPIES_DEFINITION, COPIES_LAYER
    from masonry.params import from_preset, validate
    from masonry.scenes import build

    rhino3dm = pytest.importorskip("rhino3dm")
    params = validate(from_preset("3", boundary="cyclic", p=4))
    made = RunOutputs(params, build(params), None)
    blocks, whole, webs = made.scene.blocks, made.shown, made.webs
    rhino = next(e for e in EXPORTERS if e.name == "rhino")
    file = rhino3dm.File3dm.FromByteArray(rhino.make(made).files["bricks.3dm"])

    normal = [o for o in file.Objects if o.Attributes.Mode == rhino3dm.ObjectMode.Normal]
    meshes = [o for o in normal if isinstance(o.Geometry, rhino3dm.Mesh)]
    assert [o.Attributes.Name for o in meshes] == blocks.block_name.tolist()
    assert {o.Attributes.GetUserString("solved") for o in meshes} == {"yes"}
    (definition,) = file.InstanceDefinitions
    assert definition.Name == COPIES_DEFINITION
    parts = [file.Objects.FindId(i) for i in definition.GetObjectIds()]
    # exploded, a copy's bricks are named and described as the section's
    assert [o.Attributes.Name for o in parts] == blocks.block_name.tolist()
    assert [o.Attributes.GetUserString("course") for o in parts] == [
        o.Attributes.GetUserString("course") for o in meshes]
    # but the two keys each copy states itself
    assert {o.Attributes.UserStringCount for o in parts} == {
        o.Attributes.UserStringCount - 2 for o in meshes}
    assert {o.Attributes.GetUserString(key) for o in parts for key in ("web", "solved")} == {
        ""}  # rhino3dm's answer for a key not set
    parts = [o.Geometry for o in parts]

    copies = [o for o in normal if isinstance(o.Geometry, rhino3dm.InstanceReference)]
    assert len(normal) == len(meshes) + len(copies) == blocks.n_blocks + webs - 1
    assert [o.Attributes.Name for o in copies] == [f"w{k}" for k in range(1, webs)]
    for k, copy in enumerate(copies, start=1):
        assert copy.Attributes.GetUserString("web") == str(k)
        assert copy.Attributes.GetUserString("solved") == "no (a turned copy)"
        assert file.Layers[copy.Attributes.LayerIndex].Name == COPIES_LAYER
        assert copy.Geometry.ParentIdefId == definition.Id
        for i, part in enumerate(parts):
            turned = part.Duplicate()
            assert turned.Transform(copy.Geometry.Xform)
            points = np.array([[p.X, p.Y, p.Z] for p in turned.Vertices.ToPoint3dArray()])
            faces = whole.block_faces(k * blocks.n_blocks + i)
            corners = np.concatenate([whole.face_vertices[whole.face_offsets[f]:
                                                          whole.face_offsets[f + 1]]
                                      for f in faces])
            np.testing.assert_allclose(points, whole.vertices[corners], atol=1e-12)


def test_3dm_user_text_carries_each_bricks_largest_forces():
    """Two interfaces of a three-block stack by hand: block 1 bears on both, so its
    largest compression is the larger of the two; the ground support on the first."""
    from test_rbe import stack

    rhino3dm = pytest.importorskip("rhino3dm")
    blocks, interfaces = stack(2)
    model = Model(blocks, interfaces)
    forces = {"compression": np.array([300.0, 120.0]), "tension": np.array([0.0, 2.5])}
    text = block_user_text(blocks, model, forces)
    assert text["max_compression_N"].tolist() == ["300", "300", "120"]
    assert text["max_tension_N"].tolist() == ["0", "2.5", "2.5"]
    assert text["support"].tolist() == ["yes", "no", "no"]
    file = rhino3dm.File3dm.FromByteArray(blocks_3dm(blocks, user_text=text))
    assert [o.Attributes.GetUserString("max_tension_N") for o in file.Objects] == [
        "0", "2.5", "2.5"]
    assert [file.Layers[o.Attributes.LayerIndex].Name for o in file.Objects] == [
        SUPPORT_LAYER, "block", "block"]


def test_3dm_without_rhino3dm_says_why(monkeypatch):
    monkeypatch.setitem(sys.modules, "rhino3dm", None)  # import now raises ImportError
    with pytest.raises(ImportError, match=r"rhino3dm, a dependency of masonry, is not "
                                          r"installed \(pip install rhino3dm"):
        blocks_3dm(scene_of("wall").blocks)
