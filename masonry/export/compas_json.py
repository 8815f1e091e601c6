"""``assembly.json``: a run's blocks, interfaces and forces as a compas_assembly
``Assembly`` (compas 2 data model; docs/assemblies.md, "COMPAS").

``compas.json_load`` loads it into compas_assembly's classes, so the COMPAS viewers show
masonry's forces; ``masonry analyze assembly.json`` reads it back (its supports are the
file's ``is_support``). The layout is the one compas_assembly 0.7 writes:

- ``data.graph.data.node[i]``: block ``i`` as a ``compas_assembly.datastructures/Block``
  (a mesh: ``vertex`` coordinates in metres, ``face`` vertex lists, ``name`` masonry's
  block name), its centroid as ``x``, ``y``, ``z``, and ``is_support``;
- ``data.graph.data.edge[u][v].interfaces``: the interfaces between blocks ``u`` and
  ``v``, each a ``compas_assembly.datastructures/Interface`` with its polygon ``points``,
  ``frame`` (the centre, ``xaxis`` = t1, ``yaxis`` = t2: the normal x cross y points from
  ``u`` into ``v``), ``size`` (area, m^2), ``mesh`` (the polygon) and ``forces``: per
  point ``c_np`` compression, ``c_nn`` tension, ``c_u``, ``c_v`` friction along the
  frame's x and y axes, in newtons (the force on ``v`` is ``(c_np - c_nn) n + c_u x +
  c_v y``); null without a solution;
- ``data.attributes.masonry``: the verdict and the settings it holds for.
"""

import json
import uuid

import numpy as np

ASSEMBLY_DTYPE = "compas_assembly.datastructures/Assembly"
"""What ``compas.json_load`` makes of the file."""

VERDICT_KEYS = ("verdict", "feasible", "friction", "mu", "friction_model", "weight_N",
                "objective", "moi", "moi_factor", "solver", "status")
"""The RBE result's entries copied into ``data.attributes.masonry``."""


def assembly_json(blocks, interfaces, x, record: dict, name: str = "masonry") -> str:
    """The ``Assembly`` JSON of analysed blocks (strict JSON: no NaN).

    Parameters
    ----------
    blocks : masonry.blocks.Blocks
    interfaces : masonry.interfaces.Interfaces
    x : (4 IV,) float or None, N
        The vertex forces ``(c, t, f1, f2)`` per interface vertex
        (:class:`~masonry.rbe.equilibrium.VariableLayout`); None: no forces.
    record : dict
        The RBE result's ``to_dict()``; :data:`VERDICT_KEYS` are kept.
    name : str
        The assembly's name (the run's structure id).
    """
    nodes = {str(b): _node(blocks, b) for b in range(blocks.n_blocks)}
    edges = {str(b): {} for b in range(blocks.n_blocks)}
    forces = None if x is None else np.asarray(x, dtype=float).reshape(-1, 4)
    for k in range(len(interfaces)):
        u, v = (int(i) for i in interfaces.pair[k])
        flip = str(u) in edges[str(v)]  # the pair is stored the other way round already
        if flip:
            u, v = v, u
        edge = edges[str(u)].setdefault(str(v), {"interfaces": []})
        edge["interfaces"].append(_interface(interfaces, k, forces, flip))
    verdict = {key: _plain(record.get(key)) for key in VERDICT_KEYS}
    graph = {"attributes": {}, "default_node_attributes": {
                 "x": 0.0, "y": 0.0, "z": 0.0, "block": None, "is_support": False,
                 "section": None, "mesh_size": None, "displacement": [0.0] * 6},
             "default_edge_attributes": {"interfaces": None},
             "node": nodes, "edge": edges, "max_node": blocks.n_blocks - 1}
    data = {"attributes": {"name": name, "masonry": {**verdict, "units": "N, m"}},
            "graph": _object("compas.datastructures/Graph", graph)}
    return json.dumps(_object(ASSEMBLY_DTYPE, data), allow_nan=False)


def _object(dtype: str, data, name=None) -> dict:
    obj = {"dtype": dtype, "data": data, "guid": str(uuid.uuid4())}
    if name is not None:
        obj["name"] = name
    return obj


def _plain(value):
    """A JSON value: numpy scalars as Python's, NaN as null."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def _mesh_data(points, faces) -> dict:
    """A compas ``Mesh``'s data of ``points`` ((n, 3) float) and ``faces`` (lists of
    indices into them)."""
    return {"attributes": {}, "default_vertex_attributes": {"x": 0.0, "y": 0.0, "z": 0.0},
            "default_edge_attributes": {}, "default_face_attributes": {},
            "vertex": {str(i): dict(zip("xyz", map(float, p))) for i, p in enumerate(points)},
            "face": {str(f): [int(i) for i in face] for f, face in enumerate(faces)},
            "facedata": {str(f): {} for f in range(len(faces))}, "edgedata": {},
            "max_vertex": len(points) - 1, "max_face": len(faces) - 1}


def _node(blocks, b: int) -> dict:
    first = blocks.vertex_offsets[b]
    faces = [blocks.face_vertices[blocks.face_offsets[f]:blocks.face_offsets[f + 1]] - first
             for f in blocks.block_faces(b)]
    data = _mesh_data(blocks.block_vertices(b), faces)
    data["attributes"] = {"node": None}
    x, y, z = (float(c) for c in blocks.block_centroid[b])
    return {"block": _object("compas_assembly.datastructures/Block", data,
                             name=str(blocks.block_name[b])),
            "x": x, "y": y, "z": z, "is_support": bool(blocks.block_is_support[b])}


def _interface(interfaces, k: int, forces, flip: bool) -> dict:
    """Interface ``k``; ``flip``: seen from its other block (normal reversed: x = t2,
    y = t1, and the friction of the force on the first block, -f2 and -f1)."""
    polygon = interfaces.polygon(k)
    xaxis, yaxis = interfaces.t1[k], interfaces.t2[k]
    if flip:
        xaxis, yaxis, polygon = yaxis, xaxis, polygon[::-1]
    frame = {"point": interfaces.centre[k].tolist(), "xaxis": xaxis.tolist(),
             "yaxis": yaxis.tolist()}
    point_forces = None
    if forces is not None:
        rows = forces[interfaces.offsets[k]:interfaces.offsets[k + 1]]
        if flip:
            rows = np.stack([rows[:, 0], rows[:, 1], -rows[:, 3], -rows[:, 2]], axis=1)[::-1]
        point_forces = [dict(zip(("c_np", "c_nn", "c_u", "c_v"), map(float, row)))
                        for row in rows]
    data = {"points": [_object("compas.geometry/Point", p.tolist()) for p in polygon],
            "size": float(interfaces.area[k]),
            "frame": _object("compas.geometry/Frame", frame),
            "forces": point_forces,
            "mesh": _object("compas.datastructures/Mesh",
                            _mesh_data(polygon, [list(range(len(polygon)))]))}
    return _object("compas_assembly.datastructures/Interface", data)
