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

import gc
import json
import os
from contextlib import contextmanager
from itertools import pairwise

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
    n_objects = 2 + blocks.n_blocks + 3 * len(interfaces) + len(interfaces.vertices)
    guid = iter(_guids(n_objects)).__next__
    with _no_collection():
        nodes = _nodes(blocks, guid)
        edges = {str(b): {} for b in range(blocks.n_blocks)}
        for u, v, interface in _interfaces(interfaces, x, guid):
            edges[str(u)].setdefault(str(v), {"interfaces": []})["interfaces"].append(
                interface)
    verdict = {key: _plain(record.get(key)) for key in VERDICT_KEYS}
    graph = {"attributes": {}, "default_node_attributes": {
                 "x": 0.0, "y": 0.0, "z": 0.0, "block": None, "is_support": False,
                 "section": None, "mesh_size": None, "displacement": [0.0] * 6},
             "default_edge_attributes": {"interfaces": None},
             "node": nodes, "edge": edges, "max_node": blocks.n_blocks - 1}
    data = {"attributes": {"name": name, "masonry": {**verdict, "units": "N, m"}},
            "graph": _object("compas.datastructures/Graph", graph, guid())}
    return json.dumps(_object(ASSEMBLY_DTYPE, data, guid()), allow_nan=False,
                      check_circular=False)  # a tree built here: no cycle to look for


@contextmanager
def _no_collection():
    """Python's cyclic garbage collector paused: the document is a tree of a few hundred
    thousand small dicts and lists, none in a cycle, for the collector to pass over
    again and again while it grows (docs/bench.md, "A 5,025-block wall")."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _guids(n: int) -> list:
    """``n`` random (version 4) UUIDs as compas writes them, made in one draw rather than
    one ``uuid.uuid4()`` per object (docs/bench.md, "A 5,025-block wall")."""
    raw = np.frombuffer(os.urandom(16 * n), np.uint8).reshape(n, 16).copy()
    raw[:, 6] = raw[:, 6] & 0x0F | 0x40  # version 4
    raw[:, 8] = raw[:, 8] & 0x3F | 0x80  # RFC 4122 variant
    h = raw.tobytes().hex()
    return [f"{h[i:i + 8]}-{h[i + 8:i + 12]}-{h[i + 12:i + 16]}-{h[i + 16:i + 20]}-"
            f"{h[i + 20:i + 32]}" for i in range(0, 32 * n, 32)]


def _object(dtype: str, data, guid: str, name=None) -> dict:
    obj = {"dtype": dtype, "data": data, "guid": guid}
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


def _mesh_data(points: list, faces: list) -> dict:
    """A compas ``Mesh``'s data of ``points`` ([x, y, z] lists) and ``faces`` (lists of
    indices into them)."""
    return {"attributes": {}, "default_vertex_attributes": {"x": 0.0, "y": 0.0, "z": 0.0},
            "default_edge_attributes": {}, "default_face_attributes": {},
            "vertex": {str(i): {"x": x, "y": y, "z": z} for i, (x, y, z) in enumerate(points)},
            "face": {str(f): face for f, face in enumerate(faces)},
            "facedata": {str(f): {} for f in range(len(faces))}, "edgedata": {},
            "max_vertex": len(points) - 1, "max_face": len(faces) - 1}


def _nodes(blocks, guid) -> dict:
    """The graph's nodes: every block as a compas_assembly ``Block``."""
    vertices = blocks.vertices.tolist()
    first = blocks.vertex_offsets
    local = blocks.face_vertices - np.repeat(first[blocks.face_block],
                                             np.diff(blocks.face_offsets))
    face_lists = [local[a:b].tolist() for a, b in pairwise(blocks.face_offsets.tolist())]
    face_first = blocks.block_face_offsets.tolist()
    centroids = blocks.block_centroid.tolist()
    nodes = {}
    for b, (name, is_support) in enumerate(zip(blocks.block_name.tolist(),
                                                blocks.block_is_support.tolist())):
        data = _mesh_data(vertices[first[b]:first[b + 1]],
                          face_lists[face_first[b]:face_first[b + 1]])
        data["attributes"] = {"node": None}
        x, y, z = centroids[b]
        nodes[str(b)] = {"block": _object("compas_assembly.datastructures/Block", data,
                                          guid(), name=str(name)),
                         "x": x, "y": y, "z": z, "is_support": bool(is_support)}
    return nodes


def _interfaces(interfaces, x, guid):
    """``(u, v, interface)`` of every interface, seen from the block that first meets
    the pair: an interface stored the other way round is flipped (normal reversed:
    x = t2, y = t1, its polygon reversed, and the friction of the force on the first
    block, -f2 and -f1)."""
    pair = interfaces.pair
    _, first, which = np.unique(pair.min(axis=1) * (pair.max(initial=0) + 1) + pair.max(axis=1),
                                return_index=True, return_inverse=True)
    flip = pair[first[which.reshape(-1)], 0] != pair[:, 0]
    axes = np.where(flip[:, None, None], np.stack([interfaces.t2, interfaces.t1], axis=1),
                    np.stack([interfaces.t1, interfaces.t2], axis=1)).tolist()
    points = interfaces.vertices.tolist()
    rows = [None] * len(points)
    if x is not None:
        forces = np.asarray(x, dtype=float).reshape(-1, 4).copy()
        turned = flip[interfaces.vertex_interface]
        forces[turned, 2:] = -forces[turned][:, [3, 2]]
        rows = [{"c_np": a, "c_nn": b, "c_u": c, "c_v": d} for a, b, c, d in forces.tolist()]
    for k, (a, b) in enumerate(pairwise(interfaces.offsets.tolist())):
        polygon, point_forces = points[a:b], rows[a:b]
        if flip[k]:
            polygon, point_forces = polygon[::-1], point_forces[::-1]
        frame = {"point": interfaces.centre[k].tolist(), "xaxis": axes[k][0],
                 "yaxis": axes[k][1]}
        data = {"points": [_object("compas.geometry/Point", p, guid()) for p in polygon],
                "size": float(interfaces.area[k]),
                "frame": _object("compas.geometry/Frame", frame, guid()),
                "forces": None if x is None else point_forces,
                "mesh": _object("compas.datastructures/Mesh",
                                _mesh_data(polygon, [list(range(len(polygon)))]), guid())}
        u, v = pair[k, ::-1] if flip[k] else pair[k]
        yield int(u), int(v), _object("compas_assembly.datastructures/Interface", data, guid())
