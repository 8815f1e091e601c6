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


CHUNK = 2000
"""Blocks (the graph's nodes, or the edges that start at them) made into JSON text at a
time: the document is never whole as Python objects, which at 100,000 blocks would take
gigabytes and fresh memory for each (docs/bench.md, "How time and memory grow")."""


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
        nodes = _members(_nodes(blocks, guid, first) for first in range(0, blocks.n_blocks,
                                                                         CHUNK))
        edges = _members(_Edges(interfaces, x, blocks.n_blocks).chunks(guid))
    verdict = {key: _plain(record.get(key)) for key in VERDICT_KEYS}
    defaults = {"x": 0.0, "y": 0.0, "z": 0.0, "block": None, "is_support": False,
                "section": None, "mesh_size": None, "displacement": [0.0] * 6}
    attributes = {"name": name, "masonry": {**verdict, "units": "N, m"}}
    graph_guid, assembly_guid = guid(), guid()
    # the text in pieces, joined once: the document may be hundreds of megabytes
    head = (f'{{"dtype": "{ASSEMBLY_DTYPE}", "data": {{"attributes": {_dumps(attributes)}, '
            f'"graph": {{"dtype": "compas.datastructures/Graph", "data": {{"attributes": {{}}, '
            f'"default_node_attributes": {_dumps(defaults)}, '
            f'"default_edge_attributes": {{"interfaces": null}}, "node": ')
    tail = (f', "max_node": {blocks.n_blocks - 1}}}, "guid": "{graph_guid}"}}}}, '
            f'"guid": "{assembly_guid}"}}')
    return "".join([head, *nodes, ', "edge": ', *edges, tail])


def _dumps(value) -> str:
    """Strict JSON of a tree built here (no cycle to look for)."""
    return json.dumps(value, allow_nan=False, check_circular=False)


def _members(chunks) -> list:
    """One JSON object of the members of ``chunks`` (dicts, in order), as pieces of
    text."""
    texts = [_dumps(chunk)[1:-1] for chunk in chunks if chunk]
    pieces = [", "] * (2 * len(texts) - 1) if texts else []
    pieces[::2] = texts
    return ["{", *pieces, "}"]


@contextmanager
def _no_collection():
    """Python's cyclic garbage collector paused: each chunk of the document is a tree of
    thousands of small dicts and lists, none in a cycle, for the collector to pass over
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


def _nodes(blocks, guid, first) -> dict:
    """The graph's nodes of :data:`CHUNK` blocks from block ``first``: each a
    compas_assembly ``Block``."""
    stop = min(first + CHUNK, blocks.n_blocks)
    corners, face_of = blocks.vertex_offsets, blocks.block_face_offsets
    faces = slice(face_of[first], face_of[stop])
    counts = np.diff(blocks.face_offsets[faces.start:faces.stop + 1])
    corner = blocks.face_vertices[blocks.face_offsets[faces.start]:
                                  blocks.face_offsets[faces.stop]]
    # every face's corners numbered within its block
    local = (corner - np.repeat(corners[blocks.face_block[faces]], counts)).tolist()
    face_lists = [local[a:b] for a, b in pairwise(np.concatenate([[0], np.cumsum(counts)])
                                                  .tolist())]
    block_faces = (face_of[first:stop + 1] - face_of[first]).tolist()
    vertices = blocks.vertices[corners[first]:corners[stop]].tolist()
    vertex_first = (corners[first:stop + 1] - corners[first]).tolist()
    centroids = blocks.block_centroid[first:stop].tolist()
    nodes = {}
    for i, (name, is_support) in enumerate(zip(blocks.block_name[first:stop].tolist(),
                                                blocks.block_is_support[first:stop].tolist())):
        data = _mesh_data(vertices[vertex_first[i]:vertex_first[i + 1]],
                          face_lists[block_faces[i]:block_faces[i + 1]])
        data["attributes"] = {"node": None}
        x, y, z = centroids[i]
        nodes[str(first + i)] = {"block": _object("compas_assembly.datastructures/Block",
                                                  data, guid(), name=str(name)),
                                 "x": x, "y": y, "z": z, "is_support": bool(is_support)}
    return nodes


class _Edges:
    """The graph's edges: every interface seen from the block that first meets the pair
    (``u``), under ``edge[u][v].interfaces`` in the order of the interfaces. An interface
    stored the other way round is flipped (normal reversed: x = t2, y = t1, its polygon
    reversed, and the friction of the force on the first block, -f2 and -f1)."""

    def __init__(self, interfaces, x, n_blocks):
        self.interfaces, self.n_blocks = interfaces, n_blocks
        pair = interfaces.pair
        key = pair.min(axis=1) * (pair.max(initial=0) + 1) + pair.max(axis=1)
        _, first, which = np.unique(key, return_index=True, return_inverse=True)
        self.flip = pair[first[which.reshape(-1)], 0] != pair[:, 0]
        self.ends = np.where(self.flip[:, None], pair[:, ::-1], pair)
        self.order = np.argsort(self.ends[:, 0], kind="stable")  # by u, then as stored
        self.forces = None
        if x is not None:
            self.forces = np.asarray(x, dtype=float).reshape(-1, 4).copy()
            turned = self.flip[interfaces.vertex_interface]
            self.forces[turned, 2:] = -self.forces[turned][:, [3, 2]]

    def chunks(self, guid):
        """``{u: {v: {"interfaces": [...]}}}`` of :data:`CHUNK` blocks ``u`` at a time,
        every block ``u`` in order (an empty dict where no interface starts)."""
        starts = self.ends[self.order, 0]
        for low in range(0, self.n_blocks, CHUNK):
            high = min(low + CHUNK, self.n_blocks)
            ks = self.order[np.searchsorted(starts, low):np.searchsorted(starts, high)]
            edges = {str(b): {} for b in range(low, high)}
            for (u, v), interface in zip(self.ends[ks].tolist(), self._interfaces(ks, guid)):
                edges[str(u)].setdefault(str(v), {"interfaces": []})["interfaces"].append(
                    interface)
            yield edges

    def _interfaces(self, ks, guid):
        """The compas_assembly ``Interface`` of every interface ``ks``, in turn."""
        interfaces, flip = self.interfaces, self.flip[ks].tolist()
        offsets = interfaces.offsets
        counts = offsets[ks + 1] - offsets[ks]
        bounds = np.concatenate([[0], np.cumsum(counts)])
        rows = np.repeat(offsets[ks] - bounds[:-1], counts) + np.arange(bounds[-1])
        bounds = bounds.tolist()
        points = interfaces.vertices[rows].tolist()
        point_forces = [None] * len(rows)
        if self.forces is not None:
            point_forces = [{"c_np": a, "c_nn": b, "c_u": c, "c_v": d}
                            for a, b, c, d in self.forces[rows].tolist()]
        axes = np.where(self.flip[ks, None, None],
                        np.stack([interfaces.t2[ks], interfaces.t1[ks]], axis=1),
                        np.stack([interfaces.t1[ks], interfaces.t2[ks]], axis=1)).tolist()
        centres, areas = interfaces.centre[ks].tolist(), interfaces.area[ks].tolist()
        for i, (a, b) in enumerate(pairwise(bounds)):
            polygon, vertex_forces = points[a:b], point_forces[a:b]
            if flip[i]:
                polygon, vertex_forces = polygon[::-1], vertex_forces[::-1]
            frame = {"point": centres[i], "xaxis": axes[i][0], "yaxis": axes[i][1]}
            data = {"points": [_object("compas.geometry/Point", p, guid()) for p in polygon],
                    "size": areas[i],
                    "frame": _object("compas.geometry/Frame", frame, guid()),
                    "forces": None if self.forces is None else vertex_forces,
                    "mesh": _object("compas.datastructures/Mesh",
                                    _mesh_data(polygon, [list(range(len(polygon)))]), guid())}
            yield _object("compas_assembly.datastructures/Interface", data, guid())
