"""Rhino 3DM of blocks: one named mesh object per block, on a layer per block class
(optional extra ``rhino``: rhino3dm).

Names are the OBJ object names (``blocks.block_name``); layers are the
:data:`~masonry.blocks.BLOCK_CLASSES` present in the scene. Units are metres.
"""

import os
import tempfile

import numpy as np

from masonry.blocks import BLOCK_CLASSES, Blocks

# layer colours (RGBA), one per block class, in BLOCK_CLASSES order
_LAYER_COLOURS = ((128, 128, 128, 255), (200, 120, 80, 255), (200, 40, 40, 255),
                  (80, 120, 200, 255), (120, 180, 90, 255))


def available() -> bool:
    """Whether the optional rhino3dm package is installed."""
    try:
        import rhino3dm  # noqa: F401
    except ImportError:
        return False
    return True


def blocks_3dm(blocks: Blocks, vertices=None) -> bytes:
    """3DM bytes (Rhino 8 file format) with one closed mesh per block.

    Faces of 3 and 4 vertices become mesh triangles and quads; larger faces are fanned
    from their first vertex (Rhino meshes have no n-gon faces). Vertices are stored in
    double precision.

    Parameters
    ----------
    blocks : Blocks
    vertices : (V, 3) float, metres, optional
        Positions to write instead of ``blocks.vertices`` (e.g. the CAD-offset ones).

    Raises
    ------
    ImportError
        When rhino3dm is not installed (the optional extra ``masonry[rhino]``).
    """
    try:
        import rhino3dm
    except ImportError as error:
        raise ImportError("blocks_3dm needs rhino3dm: pip install 'masonry[rhino]' "
                          "(or pip install rhino3dm)") from error

    vertices = blocks.vertices if vertices is None else np.asarray(vertices, dtype=float)
    model = rhino3dm.File3dm()
    model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
    layer = {code: model.Layers.AddLayer(BLOCK_CLASSES[code], _LAYER_COLOURS[code])
             for code in np.unique(blocks.block_class)}

    face_start = np.searchsorted(blocks.face_block, np.arange(blocks.n_blocks + 1))
    for i in range(blocks.n_blocks):
        lo, hi = blocks.vertex_offsets[i], blocks.vertex_offsets[i + 1]
        mesh = rhino3dm.Mesh()
        # rhino3dm 8: Vertices.Add stores float32; AddPoint3d stores doubles, which the
        # file keeps when the flag is set after the vertices exist (set on an empty
        # list, it stays False)
        for x, y, z in vertices[lo:hi].tolist():
            mesh.Vertices.AddPoint3d(x, y, z)
        mesh.Vertices.UseDoublePrecisionVertices = True
        for f in range(face_start[i], face_start[i + 1]):
            ids = (blocks.face_vertices[blocks.face_offsets[f]:blocks.face_offsets[f + 1]]
                   - lo).tolist()
            if len(ids) == 4:
                mesh.Faces.AddFace(*ids)
            else:
                for k in range(1, len(ids) - 1):
                    mesh.Faces.AddFace(ids[0], ids[k], ids[k + 1])
        mesh.Normals.ComputeNormals()
        attributes = rhino3dm.ObjectAttributes()
        attributes.Name = str(blocks.block_name[i])
        attributes.LayerIndex = layer[blocks.block_class[i]]
        model.Objects.AddMesh(mesh, attributes)

    # rhino3dm writes to paths only
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bricks.3dm")
        if not model.Write(path, 8):
            raise OSError("rhino3dm could not write the 3dm file")
        with open(path, "rb") as f:
            return f.read()
