"""Rhino 3DM of blocks: one named, closed, unwelded mesh per block, on a layer per block
class and a ``supports`` layer, with user text (rhino3dm, a dependency); a cyclic
section's turned copies are instances of one block definition of the section, on a layer
of their own.

Names are the OBJ object names (``blocks.block_name``); layers are the
:data:`~masonry.blocks.BLOCK_CLASSES` of the free blocks and :data:`SUPPORT_LAYER` for the
fixed ones. Units are metres, in model coordinates (not moved by ``cad_offset``).

Each face has its own vertices (an unwelded mesh), so its vertex normals are the face's
normal and a brick shades flat; a welded mesh averages the normals at the corners and
shades as if rounded. rhino3dm 8 can make a Brep from a mesh, but its edges carry no
tolerance (``IsValid`` is False), which Rhino reports as a bad object.
"""

import os
import tempfile

import numpy as np

from masonry.blocks import BLOCK_CLASSES, Blocks
from masonry.optional import optional_import

# layer colours (RGBA), one per block class, in BLOCK_CLASSES order
_LAYER_COLOURS = ((128, 128, 128, 255), (200, 120, 80, 255), (200, 40, 40, 255),
                  (80, 120, 200, 255), (120, 180, 90, 255))
SUPPORT_LAYER = "supports"
_SUPPORT_COLOUR = (60, 60, 60, 255)
COPIES_LAYER = "turned copies (not solved)"
"""The layer of a whole dome's webs that copy the solved section by rotation (a cyclic
section's run) and of their block definition's meshes; the solved section's blocks are on
the class and support layers."""
COPIES_DEFINITION = "solved section"
"""The name of the block definition the turned copies are instances of."""
_COPIES_COLOUR = (190, 190, 190, 255)


MISSING = ("bricks.3dm not written: rhino3dm, a dependency of masonry, is not installed "
           "(pip install rhino3dm; it has wheels for Linux, macOS 12+ and Windows)")
"""The line a run logs when it cannot write the 3DM file."""


def available() -> bool:
    """Whether rhino3dm can be imported (an install without its dependencies, or a
    platform without its wheels, has none); an interrupt during its import is raised,
    not taken for its absence (:func:`masonry.optional.optional_import`)."""
    return optional_import("rhino3dm") is not None


def block_user_text(blocks: Blocks, model=None, forces=None) -> dict:
    """Per-block user text for :func:`blocks_3dm`: ``class``, ``course``, ``web``,
    ``support``, and with forces ``max_compression_N`` and ``max_tension_N``, the largest
    compression and tension sum of any interface the block bears on.

    Parameters
    ----------
    blocks : Blocks
        ``B`` blocks: the scene's.
    model : masonry.rbe.boundary.Model, optional
        Its blocks start with ``blocks``; interface sides routed elsewhere
        (``side_block``, cyclic symmetry) count for the block they act on.
    forces : dict str -> (K,) float, N, optional
        ``compression`` and ``tension`` per interface of ``model``.

    Returns
    -------
    dict str -> (B,) str
    """
    text = {"class": np.array(BLOCK_CLASSES, dtype=object)[blocks.block_class],
            "course": blocks.block_course.astype(str),
            "web": blocks.block_web.astype(str),
            "support": np.where(blocks.block_is_support, "yes", "no")}
    if model is None or forces is None:
        return text
    for name in ("compression", "tension"):
        largest = model.block_largest(forces[name])[:blocks.n_blocks]
        text[f"max_{name}_N"] = np.array([f"{v:.6g}" for v in largest])
    return text


def blocks_3dm(blocks: Blocks, vertices=None, user_text=None, copies=None) -> bytes:
    """3DM bytes (Rhino 8 file format) with one closed, unwelded mesh per block.

    Faces of 3 and 4 vertices become mesh triangles and quads; larger faces are fanned
    from their first vertex (Rhino meshes have no n-gon faces). Vertices are stored in
    double precision.

    Copies of the whole of ``blocks`` are block instances (Rhino: Insert, Explode): the
    meshes are stored once more as the geometry of the block definition
    :data:`COPIES_DEFINITION`, and each copy is a named instance of it with its motion,
    on :data:`COPIES_LAYER`; Rhino draws a copy as the blocks moved, and a file of a
    section and its seven turned copies holds two sets of meshes, not eight.

    Parameters
    ----------
    blocks : Blocks
    vertices : (V, 3) float, metres, optional
        Positions to write instead of ``blocks.vertices`` (e.g. the CAD-offset ones).
    user_text : dict str -> (B,) str, optional
        Per-block user text (Rhino: Properties > Attribute User Text), key -> values.
    copies : dict str -> ((4, 4) float, dict str -> str), optional
        Name -> (motion of the copy, its user text).

    Raises
    ------
    ImportError
        When rhino3dm is not installed (:data:`MISSING`).
    """
    rhino3dm = optional_import("rhino3dm")
    if rhino3dm is None:
        raise ImportError(MISSING)

    vertices = blocks.vertices if vertices is None else np.asarray(vertices, dtype=float)
    user_text = {} if user_text is None else user_text
    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
    free = ~blocks.block_is_support
    layer = {code: model.Layers.AddLayer(BLOCK_CLASSES[code], _LAYER_COLOURS[code])
             for code in np.unique(blocks.block_class[free])}
    if blocks.block_is_support.any():
        support_layer = model.Layers.AddLayer(SUPPORT_LAYER, _SUPPORT_COLOUR)

    face_start = blocks.block_face_offsets
    corner_start = blocks.face_offsets[face_start].tolist()
    corners = vertices[blocks.face_vertices].tolist()  # every face's corners, in order
    sizes = np.diff(blocks.face_offsets).tolist()
    layers = [layer[code] if is_free else support_layer
              for code, is_free in zip(blocks.block_class.tolist(), free.tolist())]
    texts = {key: list(map(str, np.asarray(values).tolist()))
             for key, values in user_text.items()}
    attributes = rhino3dm.ObjectAttributes()  # AddMesh copies it: one for every block
    definition = _Definition(rhino3dm, model, copies) if copies else None
    for i, name in enumerate(blocks.block_name.tolist()):
        mesh = _unwelded_mesh(rhino3dm, corners[corner_start[i]:corner_start[i + 1]],
                              sizes[face_start[i]:face_start[i + 1]])
        attributes.Name = str(name)
        attributes.LayerIndex = layers[i]
        for key, values in texts.items():
            attributes.SetUserString(key, values[i])
        model.Objects.AddMesh(mesh, attributes)
        if definition is not None:
            definition.add(mesh, str(name), {key: values[i] for key, values in texts.items()})
    if definition is not None:
        definition.place()

    # rhino3dm writes to paths only
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bricks.3dm")
        if not model.Write(path, 8):
            raise OSError("rhino3dm could not write the 3dm file")
        with open(path, "rb") as f:
            return f.read()


class _Definition:
    """The block definition :data:`COPIES_DEFINITION` of :func:`blocks_3dm`'s copies, on
    :data:`COPIES_LAYER`: its meshes carry their block's name and user text but the keys
    each copy states itself (``web``, ``solved``), so that an exploded copy's bricks
    are named and described as the section's."""

    def __init__(self, rhino3dm, model, copies):
        self.rhino3dm, self.model, self.copies = rhino3dm, model, copies
        self.layer = model.Layers.AddLayer(COPIES_LAYER, _COPIES_COLOUR)
        self.own = set().union(*(text for _, text in copies.values()))
        self.meshes, self.attributes = [], []

    def add(self, mesh, name, text):
        attributes = self.rhino3dm.ObjectAttributes()
        attributes.Name, attributes.LayerIndex = name, self.layer
        for key, value in text.items():
            if key not in self.own:
                attributes.SetUserString(key, value)
        self.meshes.append(mesh)
        self.attributes.append(attributes)

    def place(self):
        """The definition, and an instance of it per copy (name -> (4, 4) motion, user
        text)."""
        rhino3dm = self.rhino3dm
        index = self.model.InstanceDefinitions.Add(
            COPIES_DEFINITION, "the solved section's blocks, turned to the copies' places",
            "", "", rhino3dm.Point3d(0, 0, 0), tuple(self.meshes), tuple(self.attributes))
        definition_id = self.model.InstanceDefinitions[index].Id
        for name, (motion, text) in self.copies.items():
            xform = rhino3dm.Transform(1.0)
            for row, col in np.ndindex(4, 4):
                setattr(xform, f"M{row}{col}", float(motion[row][col]))
            attributes = rhino3dm.ObjectAttributes()
            attributes.Name, attributes.LayerIndex = name, self.layer
            for key, value in text.items():
                attributes.SetUserString(key, value)
            self.model.Objects.AddInstanceObject(
                rhino3dm.InstanceReference(definition_id, xform), attributes)


def _unwelded_mesh(rhino3dm, corners, sizes):
    """A rhino3dm Mesh whose faces have their own vertices: ``corners`` (list of (x, y, z),
    metres) holds the faces' corners face after face, ``sizes`` their counts."""
    mesh = rhino3dm.Mesh()
    add_point, add_face = mesh.Vertices.AddPoint3d, mesh.Faces.AddFace
    # rhino3dm 8: Vertices.Add stores float32; AddPoint3d stores doubles, which the file
    # keeps when the flag is set after the vertices exist (set on an empty list, it
    # stays False)
    for x, y, z in corners:
        add_point(x, y, z)
    start = 0
    for size in sizes:
        if size == 4:
            add_face(start, start + 1, start + 2, start + 3)
        else:
            for k in range(1, size - 1):
                add_face(start, start + k, start + k + 1)
        start += size
    mesh.Vertices.UseDoublePrecisionVertices = True
    mesh.Normals.ComputeNormals()
    return mesh
