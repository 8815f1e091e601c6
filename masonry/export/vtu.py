"""Interfaces with their forces as VTK XML unstructured grid (``RBE/interfaces.vtu``, for
ParaView; docs/model.md 7), written here; the collapse mechanism's blocks with meshio.

Interface polygons have 3 to 8 vertices, each a ``triangle``, ``quad`` or ``polygon``
cell: the file's cells are the interfaces in id order, the rows of ``interfaces.csv`` and
``RBE/forces.csv`` (the cell data ``interface`` repeats the id). meshio stores a cell
block as one (cells, vertices per cell) array, so it needs one block per run of
consecutive interfaces with the same vertex count (3,841 on preset 1's full dome), and
its per-block work took most of the file's time; VTU itself stores every cell in three
flat arrays, written here as meshio writes them (binary, base64, a UInt32 byte count
before each array, not compressed), and read back by meshio and ParaView alike. Array
names carry their unit as the CSV columns do (``compression_N``), since ParaView titles
a colour bar with the array's name.
The ``kind`` codes are named in the file's field data (``kind_horizontal = 0``, ...),
which ParaView lists in its Information panel.
"""

import base64
import os
import sys
import tempfile

import numpy as np

from masonry import __version__
from masonry.interfaces import INTERFACE_KINDS
from masonry.rbe.collapse_result import vertex_displacements

VTK_TRIANGLE, VTK_QUAD, VTK_POLYGON = 5, 9, 7
"""The VTK cell type codes of the interfaces' polygons."""

_VTU_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64",
              np.dtype(np.int8): "Int8"}
_RESERVED = ("interface", "kind", "area_m2", "frame_normal", "frame_t1", "frame_t2")


def _vtu_bytes(mesh, name) -> bytes:
    """meshio writes to paths only (and drops field data in VTU): write into a temporary
    folder and read back. Not compressed: zlib would take most of the export's time
    (docs/bench.md, "Measurements behind design choices")."""
    import meshio

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, name)
        meshio.write(path, mesh, file_format="vtu", binary=True, compression=None)
        with open(path, "rb") as f:
            return f.read()


def mechanism_vtu(blocks, mechanism) -> bytes:
    """VTU bytes of the blocks (triangulated faces) with the collapse mechanism as point
    data ``displacement`` ((V, 3), the virtual displacement of every block vertex,
    largest 1): ParaView's "Warp By Vector" draws the mechanism (docs/model.md 6.9). Cell data:
    ``block`` (int64) and ``displacement_norm`` of the block's centroid.

    Parameters
    ----------
    blocks : Blocks
    mechanism : (B, 6) float
        ``(ux, uy, uz, rx, ry, rz)`` per block about its centroid.
    """
    import meshio

    mechanism = np.asarray(mechanism, dtype=float)
    displacement = vertex_displacements(blocks, mechanism)
    block = blocks.face_block[blocks.triangle_face]
    mesh = meshio.Mesh(np.asarray(blocks.vertices, dtype=float),
                       [("triangle", blocks.triangles)],
                       point_data={"displacement": displacement},
                       cell_data={"block": [block.astype(np.int64)],
                                  "displacement_norm": [np.linalg.norm(
                                      mechanism[block, :3], axis=1)]})
    return _vtu_bytes(mesh, "mechanism.vtu")


def interfaces_vtu(interfaces, forces: dict, kind_names=INTERFACE_KINDS) -> bytes:
    """VTU bytes: one polygon cell per interface, with its forces as cell data.

    Parameters
    ----------
    interfaces : Interfaces
        ``K`` interfaces; their polygon vertices become the points (metres).
    forces : dict of str to (K,) or (K, 3) float
        Per-interface values, e.g. the sums ``compression``, ``tension``, ``normal``,
        ``t1``, ``t2``, ``friction`` in newtons (:func:`masonry.rbe.result.interface_forces`)
        and the resultants' ``shear`` (K, 3), ``eccentricity``
        (:func:`masonry.rbe.resultants.interface_resultants`).
    kind_names : sequence of str
        Names of the ``kind`` codes, written into the file's field data.

    Returns
    -------
    bytes
        Binary VTU (base64, not compressed), cells in interface order. Cell data: every
        entry of ``forces`` (float64), ``interface`` (int64, row in ``forces.csv``),
        ``kind`` (int8 code), ``area_m2``, ``frame_normal``, ``frame_t1``, ``frame_t2``
        ((K, 3) unit vectors: the directions of the normal, t1 and t2 forces). Field data:
        ``kind_<name>`` (the code of every kind name).

    Raises
    ------
    ValueError
        No interfaces (a grid without cells is not written), a force array of the
        wrong shape, or a force named like one of the fixed cell data.
    """
    count = len(interfaces)
    if count == 0:
        raise ValueError("no interfaces to write: a VTU needs at least one cell")
    values = {}
    for name, value in forces.items():
        if name in _RESERVED:
            raise ValueError(f"force name {name!r} is reserved for {_RESERVED}")
        value = np.asarray(value, dtype=float)
        if value.shape not in ((count,), (count, 3)):
            raise ValueError(f"forces[{name!r}] has shape {value.shape}, expected "
                             f"({count},) or ({count}, 3)")
        values[name] = value
    values.update(interface=np.arange(count, dtype=np.int64),
                  kind=np.asarray(interfaces.kind, dtype=np.int8),
                  **{name: np.asarray(value, dtype=float) for name, value in (
                      ("area_m2", interfaces.area), ("frame_normal", interfaces.normal),
                      ("frame_t1", interfaces.t1), ("frame_t2", interfaces.t2))})

    vertex_count = np.asarray(interfaces.vertex_count)
    types = np.select([vertex_count == 3, vertex_count == 4], [VTK_TRIANGLE, VTK_QUAD],
                      VTK_POLYGON).astype(np.int64)
    points = np.asarray(interfaces.vertices, dtype=float).reshape(-1, 3)
    offsets = np.asarray(interfaces.offsets, dtype=np.int64)
    cells = {"connectivity": np.arange(offsets[0], offsets[-1], dtype=np.int64),
             "offsets": offsets[1:] - offsets[0], "types": types}
    order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    text = "".join([
        '<?xml version="1.0"?>\n',
        f'<VTKFile type="UnstructuredGrid" version="0.1" byte_order="{order}">\n',
        f"<!--This file was created by masonry v{__version__}-->\n",
        "<UnstructuredGrid>\n",
        f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{count}">\n',
        "<Points>\n", _data_array("Points", points), "</Points>\n",
        "<Cells>\n", *(_data_array(name, v) for name, v in cells.items()), "</Cells>\n",
        "<CellData>\n", *(_data_array(name, v) for name, v in values.items()),
        "</CellData>\n", "</Piece>\n", "</UnstructuredGrid>\n", "</VTKFile>\n"])
    return _with_field_data(text.encode(), {f"kind_{name}": code
                                            for code, name in enumerate(kind_names)})


def _data_array(name, data) -> str:
    """One binary ``<DataArray>`` element as meshio writes it: base64 of the array's
    byte count (UInt32) followed by its bytes, in this machine's byte order."""
    data = np.ascontiguousarray(data)
    components = f' NumberOfComponents="{data.shape[1]}"' if data.ndim == 2 else ""
    payload = base64.b64encode(np.uint32(data.nbytes).tobytes() + data.tobytes())
    return (f'<DataArray type="{_VTU_TYPES[data.dtype]}" Name="{name}"{components} '
            f'format="binary">\n{payload.decode()}\n</DataArray>\n')


def _with_field_data(data: bytes, integers: dict) -> bytes:
    """VTU bytes with a ``<FieldData>`` of one-value Int32 arrays (name -> int) as the
    grid's first child, where VTK's XML reader looks for it."""
    arrays = "".join(f'<DataArray type="Int32" Name="{name}" NumberOfTuples="1" '
                     f'format="ascii">{int(value)}</DataArray>'
                     for name, value in integers.items())
    head, tag, tail = data.partition(b"<UnstructuredGrid>")
    if not tag:
        raise ValueError("meshio wrote no <UnstructuredGrid> element")
    return head + tag + f"\n<FieldData>{arrays}</FieldData>".encode() + tail
