"""Interfaces with their forces as VTK XML unstructured grid (SPEC 7: ``RBE/interfaces.vtu``,
for ParaView), written with meshio.

Interface polygons have 3 to 8 vertices. meshio stores a cell block as one
(cells, vertices per cell) array, so every run of consecutive interfaces with the same
vertex count becomes one block (``triangle``, ``quad`` or ``polygon``): the file's cells
are the interfaces in id order, the rows of ``interfaces.csv`` and ``RBE/forces.csv``
(the cell data ``interface`` repeats the id). Array names carry their unit as the CSV
columns do (``compression_N``), since ParaView titles a colour bar with the array's name.
The ``kind`` codes are named in the file's field data (``kind_horizontal = 0``, ...),
which ParaView lists in its Information panel.
"""

import os
import tempfile

import numpy as np

from masonry.interfaces import INTERFACE_KINDS

_CELL_TYPES = {3: "triangle", 4: "quad"}
_RESERVED = ("interface", "kind", "area_m2", "frame_normal", "frame_t1", "frame_t2")


def _vtu_bytes(mesh, name) -> bytes:
    """meshio writes to paths only (and drops field data in VTU): write into a temporary
    folder and read back. Not compressed: zlib would take most of the export's time
    (docs/bench.md)."""
    import meshio

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, name)
        meshio.write(path, mesh, file_format="vtu", binary=True, compression=None)
        with open(path, "rb") as f:
            return f.read()


def mechanism_vtu(blocks, mechanism) -> bytes:
    """VTU bytes of the blocks (triangulated faces) with the collapse mechanism as point
    data ``displacement`` ((V, 3), the virtual displacement of every block vertex,
    largest 1): ParaView's "Warp By Vector" draws the mechanism (SPEC 6.9). Cell data:
    ``block`` (int64) and ``displacement_norm`` of the block's centroid.

    Parameters
    ----------
    blocks : Blocks
    mechanism : (B, 6) float
        ``(ux, uy, uz, rx, ry, rz)`` per block about its centroid.
    """
    import meshio

    mechanism = np.asarray(mechanism, dtype=float)
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    arm = blocks.vertices - blocks.block_centroid[owner]
    displacement = mechanism[owner, :3] + np.cross(mechanism[owner, 3:], arm)
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
        ``t1``, ``t2``, ``friction`` in newtons (:func:`masonry.rbe.solve.interface_forces`)
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
        No interfaces (meshio cannot write a grid without cells), a force array of the
        wrong shape, or a force named like one of the fixed cell data.
    """
    import meshio

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
                  kind=np.asarray(interfaces.kind, dtype=np.int8), area_m2=interfaces.area,
                  frame_normal=interfaces.normal, frame_t1=interfaces.t1,
                  frame_t2=interfaces.t2)

    vertex_count = interfaces.vertex_count
    # runs of equal vertex count, in id order
    starts = np.flatnonzero(np.diff(vertex_count, prepend=-1))
    ends = np.append(starts[1:], count)
    cells, cell_data = [], {name: [] for name in values}
    for lo, hi in zip(starts.tolist(), ends.tolist()):
        size = int(vertex_count[lo])
        cells.append((_CELL_TYPES.get(size, "polygon"),
                      interfaces.offsets[lo:hi, None] + np.arange(size)))
        for name, value in values.items():
            cell_data[name].append(value[lo:hi])
    mesh = meshio.Mesh(np.asarray(interfaces.vertices, dtype=float).reshape(-1, 3), cells,
                       cell_data=cell_data)

    return _with_field_data(_vtu_bytes(mesh, "interfaces.vtu"),
                            {f"kind_{name}": code
                             for code, name in enumerate(kind_names)})


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
