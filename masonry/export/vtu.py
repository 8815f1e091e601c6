"""Interfaces with their forces as VTK XML unstructured grid (SPEC 7: ``RBE/interfaces.vtu``,
for ParaView), written with meshio.

Interface polygons have 3 to 8 vertices. meshio stores a cell block as one
(cells, vertices per cell) array, so the interfaces go into one block per vertex count:
``triangle``, ``quad``, then ``polygon`` blocks of 5, 6, ... vertices (meshio 5.3 writes
and reads these back in order). The cell data ``interface`` gives every cell's row in
``RBE/forces.csv``.
"""

import os
import tempfile

import numpy as np

from masonry.interfaces import INTERFACE_KINDS

_CELL_TYPES = {3: "triangle", 4: "quad"}
_RESERVED = ("interface", "kind", "area", "frame_normal", "frame_t1", "frame_t2")


def interfaces_vtu(interfaces, forces: dict, kind_names=INTERFACE_KINDS) -> bytes:
    """VTU bytes: one polygon cell per interface, with its forces as cell data.

    Parameters
    ----------
    interfaces : Interfaces
        ``K`` interfaces; their polygon vertices become the points (metres).
    forces : dict of str to (K,) float
        Per-interface resultants in newtons, e.g. ``compression``, ``tension``,
        ``normal``, ``t1``, ``t2``, ``friction`` (:func:`masonry.rbe.solve.interface_forces`).
    kind_names : sequence of str
        Names of the ``kind`` codes, written into the file's header comment.

    Returns
    -------
    bytes
        Binary VTU (base64, not compressed). Cell data: every entry of ``forces``
        (float64), ``interface`` (int64, row in ``forces.csv``), ``kind`` (int8 code),
        ``area`` (m^2), ``frame_normal``, ``frame_t1``, ``frame_t2`` ((K, 3) unit
        vectors: the directions of the normal, t1 and t2 forces).

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
        if value.shape != (count,):
            raise ValueError(f"forces[{name!r}] has shape {value.shape}, expected ({count},)")
        values[name] = value
    values.update(interface=np.arange(count, dtype=np.int64),
                  kind=np.asarray(interfaces.kind, dtype=np.int8), area=interfaces.area,
                  frame_normal=interfaces.normal, frame_t1=interfaces.t1,
                  frame_t2=interfaces.t2)

    vertex_count = interfaces.vertex_count
    cells, cell_data = [], {name: [] for name in values}
    for size in np.unique(vertex_count):
        rows = np.flatnonzero(vertex_count == size)
        cells.append((_CELL_TYPES.get(size, "polygon"),
                      interfaces.offsets[rows][:, None] + np.arange(size)))
        for name, value in values.items():
            cell_data[name].append(value[rows])
    mesh = meshio.Mesh(np.asarray(interfaces.vertices, dtype=float).reshape(-1, 3), cells,
                       cell_data=cell_data)

    # meshio writes to paths only (and drops field data in VTU), so the file is
    # written to a temporary folder and the kind legend goes into a comment. Not
    # compressed: zlib would take most of the export's time (docs/bench.md)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "interfaces.vtu")
        meshio.write(path, mesh, file_format="vtu", binary=True, compression=None)
        with open(path, "rb") as f:
            data = f.read()
    legend = ", ".join(f"{code} {name}" for code, name in enumerate(kind_names))
    head, sep, tail = data.partition(b"?>\n")  # after the XML declaration
    return head + sep + f"<!--masonry interfaces, kind: {legend}-->\n".encode() + tail
