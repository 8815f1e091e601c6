"""COMPAS JSON files read as triangle soups (docs/assemblies.md, "COMPAS").

The COMPAS 2 data model writes every object as ``{"dtype": "<package>/<Class>", "data":
{...}, "guid": ...}``. Three layouts hold blocks as meshes (a mesh's ``data.vertex`` maps
a key to ``x``, ``y``, ``z``; its ``data.face`` maps a key to a list of vertex keys):

- compas_assembly's ``Assembly`` and compas_cra's ``CRA_Assembly``: the graph's nodes
  (``data.graph.data.node``), each with its ``block`` and ``is_support``;
- compas_dem's ``BlockModel``: its ``elements`` (keyed by guid), each with its mesh
  ``geometry`` and ``is_support``, in the order of the model graph's nodes, which name
  them by guid;
- a plain list of meshes (``compas.datastructures/Mesh`` or compas_assembly ``Block``);
- compas_dem's ``Problem`` saved with its ``BlockModel``: the model's blocks, and the
  analysis inputs the problem states (:mod:`masonry.scenes.compas_problem`).

compas 1 files (``value`` in place of ``data``) are read too. Parsed with the standard
``json`` module: the COMPAS packages are not needed to read.
Interfaces the file holds are not used: masonry detects its own from the blocks (their
forces and pieces belong to another model). A block's name is its mesh's (or
element's) own when no other block of the file has it, else ``node_<key>`` (a graph's
node key), ``element_<i>`` or ``mesh_<i>`` (its position).

Every problem raises :class:`AssemblyError` with one line naming the object at fault
(:func:`masonry.scenes.mesh_files.read_mesh` adds the file).
"""

import json
import math
from collections import Counter
from numbers import Real

import numpy as np

from masonry.scenes.compas_problem import PROBLEM_DTYPE, problem_inputs, problem_model
from masonry.scenes.soup import AssemblyError, TriangleSoup, fan

ASSEMBLY_DTYPES = ("compas_assembly.datastructures/Assembly",
                   "compas_cra.datastructures/CRA_Assembly")
"""Graphs of blocks: node ``block`` and ``is_support``."""

BLOCK_MODEL_DTYPE = "compas_dem.models/BlockModel"
"""compas_dem's model: ``elements`` by guid, ordered by its graph's nodes."""

MESH_DTYPES = ("compas.datastructures/Mesh", "compas_assembly.datastructures/Block")
"""Meshes a block may be."""

GENERIC_NAMES = ("", "Mesh", "Block", "Box")
"""Class names COMPAS gives every unnamed mesh or element: never a block's name."""


def read_compas_json(data: bytes) -> TriangleSoup:
    """The blocks of a COMPAS JSON file (see the module docstring), with its supports.

    Raises
    ------
    AssemblyError
        Not JSON, an unknown ``dtype``, a block with no faces, a face of fewer than three
        vertices or naming a vertex the mesh lacks, a coordinate that is not a finite
        number, an ``is_support`` that is not true or false, a guid or key that points
        to nothing; the message names the object.
    """
    try:
        document = json.loads(data)
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise AssemblyError(f"not a JSON file ({error})") from None
    problem = None
    if isinstance(document, list):
        entries = [(f"mesh {i}", f"mesh_{i}", mesh, False) for i, mesh in enumerate(document)]
    elif isinstance(document, dict) and document.get("dtype") in ASSEMBLY_DTYPES:
        entries = _assembly_entries(_data(document, "the file"))
    elif isinstance(document, dict) and document.get("dtype") == BLOCK_MODEL_DTYPE:
        entries = _model_entries(_data(document, "the file"))
    elif isinstance(document, dict) and document.get("dtype") == PROBLEM_DTYPE:
        model = _data(problem_model(document, _data), "the problem's model")
        entries = _model_entries(model)
        problem = problem_inputs(document, _data, [e[4] for e in entries],
                                 [_material(model, e[5]) for e in entries])
        fixed = set(problem.fixed)
        entries = [(*e[:3], e[3] or i in fixed) for i, e in enumerate(entries)]
    else:
        dtype = document.get("dtype") if isinstance(document, dict) else type(document)
        raise AssemblyError(
            f"dtype {dtype!r}: masonry reads a COMPAS {' or '.join(ASSEMBLY_DTYPES)}, "
            f"{BLOCK_MODEL_DTYPE}, {PROBLEM_DTYPE} or a list of meshes")
    if not entries:
        raise AssemblyError("no block in the file")
    meshes = [_mesh(where, mesh) for where, _, mesh, *_ in entries]
    names = _names([e[1] for e in entries], [m[2] for m in meshes])
    counts = np.array([len(m[0]) for m in meshes])
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    faces = [np.asarray(face) + s for (_, block_faces, _), s in zip(meshes, start)
             for face in block_faces]
    face_block = np.repeat(np.arange(len(meshes)), [len(m[1]) for m in meshes])
    sizes = np.array([len(f) for f in faces])
    triangles, face = fan(np.concatenate(faces), sizes)
    return TriangleSoup(names, np.concatenate([m[0] for m in meshes]), triangles,
                        face_block[face], block_is_support=[e[3] for e in entries],
                        problem=problem)


def _data(obj, where: str) -> dict:
    """The ``data`` dict of a COMPAS object."""
    data = obj.get("data", obj.get("value")) if isinstance(obj, dict) else None
    if not isinstance(data, dict):
        raise AssemblyError(f"{where}: no 'data' object (a COMPAS object is "
                            "{'dtype': ..., 'data': {...}})")
    return data


def _dict(obj, key: str, where: str) -> dict:
    value = obj.get(key)
    if not isinstance(value, dict):
        raise AssemblyError(f"{where}: {key!r} is {_shown(value)}, expected an object")
    return value


def _shown(value) -> str:
    text = json.dumps(value) if not isinstance(value, float) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _support(flag, where: str) -> bool:
    if not isinstance(flag, bool):
        raise AssemblyError(f"{where}: is_support is {_shown(flag)}, expected true or false")
    return flag


def _assembly_entries(data: dict) -> list:
    """``(where, fallback name, mesh, is_support)`` of every node of an assembly."""
    graph = _data(_dict(data, "graph", "the assembly"), "the assembly's graph")
    nodes = _dict(graph, "node", "the assembly's graph")
    defaults = graph.get("default_node_attributes") or {}
    default_support = defaults.get("is_support", False)
    edges = graph.get("edge") or {}
    for u, neighbours in edges.items():
        for v in (neighbours or {}):
            for key in (u, v):
                if key not in nodes:
                    raise AssemblyError(f"edge ({u}, {v}): node {key!r} does not exist "
                                        f"(the graph has {len(nodes)} nodes)")
    entries = []
    for key, node in nodes.items():
        where = f"node {key!r}"
        if not isinstance(node, dict) or node.get("block") is None:
            raise AssemblyError(f"{where}: no 'block' (a mesh)")
        support = _support(node.get("is_support", default_support), where)
        entries.append((where, f"node_{key}", node["block"], support))
    return entries


def _model_entries(data: dict) -> list:
    """``(where, fallback name, mesh, is_support, node key, material guid)`` of every
    element of a BlockModel, in the order of its graph's nodes; its tree's and materials'
    guids checked too."""
    elements = _dict(data, "elements", "the block model")
    materials = data.get("materials") or {}
    graph = data.get("graph") or {}
    nodes = graph.get("node") if isinstance(graph, dict) else None
    order = (list(enumerate(elements)) if not nodes
             else [(key, _guid(node, "element", elements, f"graph node {key!r}"))
                   for key, node in nodes.items()])
    tree = (data.get("tree") or {}).get("root") or {}
    for child in tree.get("children") or []:
        _guid(child, "element", elements, "tree node")
    entries = []
    for i, (key, guid) in enumerate(order):
        where = f"element {guid!r}"
        element = _data(elements[guid], where)
        material = element.get("material")
        if material is not None and material not in materials:
            raise AssemblyError(f"{where}: material {_shown(material)} points to no "
                                f"material of the model (it has {len(materials)})")
        mesh = element.get("geometry")
        support = _support(element.get("is_support", False), where)
        name = element.get("name")
        named = mesh if name in GENERIC_NAMES or not isinstance(mesh, dict) \
            else {**mesh, "name": name}
        entries.append((where, f"element_{i}", named, support, str(key), material))
    return entries


def _material(model: dict, guid) -> dict | None:
    """The data of the material ``guid`` of a BlockModel (checked to exist), or None."""
    return None if guid is None else _data(model["materials"][guid], f"material {guid!r}")


def _guid(node, key: str, targets: dict, where: str) -> str:
    guid = node.get(key) if isinstance(node, dict) else None
    if guid not in targets:
        raise AssemblyError(f"{where}: {key} {_shown(guid)} points to no element of the "
                            f"model (it has {len(targets)})")
    return guid


def _mesh(where: str, mesh):
    """``(vertices (n, 3) float, faces list of (m,) int into them, name)`` of one block
    mesh, checked."""
    if not isinstance(mesh, dict) or mesh.get("dtype") not in MESH_DTYPES:
        dtype = mesh.get("dtype") if isinstance(mesh, dict) else _shown(mesh)
        raise AssemblyError(f"{where}: dtype {dtype!r}, expected a mesh "
                            f"({' or '.join(MESH_DTYPES)})")
    data = _data(mesh, where)
    vertex = _dict(data, "vertex", where)
    face = _dict(data, "face", where)
    if not face:
        raise AssemblyError(f"{where}: the block has no faces")
    defaults = data.get("default_vertex_attributes") or data.get("dva") or {}
    index, points = {}, []
    for key, attributes in vertex.items():
        point = [attributes.get(axis, defaults.get(axis)) if isinstance(attributes, dict)
                 else None for axis in "xyz"]
        if not all(isinstance(c, Real) and not isinstance(c, bool) and math.isfinite(c)
                   for c in point):
            raise AssemblyError(f"{where}: vertex {key!r} has coordinates {_shown(point)}, "
                                "expected three finite numbers")
        index[key] = len(points)
        points.append(point)
    faces = []
    for key, corners in face.items():
        if not isinstance(corners, list) or len(corners) < 3:
            raise AssemblyError(f"{where}: face {key!r} is {_shown(corners)}, expected a "
                                "list of three or more vertex keys")
        missing = [c for c in corners if str(c) not in index or isinstance(c, bool)]
        if missing:
            raise AssemblyError(f"{where}: face {key!r} names vertex {_shown(missing[0])}, "
                                "which the mesh does not have")
        faces.append([index[str(c)] for c in corners])
    name = (data.get("attributes") or {}).get("name") or mesh.get("name") or ""
    return np.array(points, dtype=float), faces, str(name)


def _names(fallbacks, own) -> list:
    """Each block's own name where no other block of the file has it, else its
    fallback."""
    counts = Counter(own)
    return [name if name not in GENERIC_NAMES and counts[name] == 1 else fallback
            for name, fallback in zip(own, fallbacks)]
