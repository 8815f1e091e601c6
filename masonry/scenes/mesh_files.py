"""Mesh files read as triangle soups: the first step of an imported assembly (docs/model.md 4.6).

This module only reads: it turns one OBJ, STL, PLY or COMPAS JSON file into a
:class:`TriangleSoup`, the file's triangles with the block each belongs to, coordinates
exactly as written.
How a file's triangles make blocks:

- OBJ: one block per object (``o``); a file without objects, one block per group
  (``g``); a file with neither, one soup to split into its connected bodies. Polygons
  are cut into fans.
- STL (binary or ASCII) and PLY: one soup to split into its connected bodies.
- JSON: a COMPAS assembly, block model or list of meshes, one block per mesh, with the
  file's supports (:mod:`masonry.scenes.compas_json`).

Merging vertices, splitting a soup into bodies and checking that every block is a
closed convex solid come after (:mod:`masonry.scenes.imported`), once the tolerances
of all the files are known. A file that cannot be read raises :class:`AssemblyError`
naming it.

A library's reader is used where it takes at most 1.5 times the time of our own and
gives what the blocks need: trimesh's for STL and PLY. OBJ is read by our own, which
keeps objects and groups apart by name and in file order (:func:`_read_obj` says why
trimesh's and meshio's are not used; docs/bench.md, "Reading meshes", has the
measurements, and ``masonry bench --readers`` repeats them).
"""

import io
import warnings
from pathlib import Path

import numpy as np

from masonry.scenes.compas_json import read_compas_json
from masonry.scenes.soup import AssemblyError, TriangleSoup, fan
from masonry.tolerances import MAX_COORDINATE_M

MAX_INDEX = 2**62
"""An OBJ index beyond this (either sign) is read as this: out of range all the same,
and within numpy's integers."""

FORMATS = (".obj", ".stl", ".ply", ".json")
"""File suffixes :func:`read_mesh` reads (case-insensitive)."""


def read_mesh(path) -> TriangleSoup:
    """The triangles of one mesh file, with the block each belongs to.

    Parameters
    ----------
    path : str or Path
        An OBJ, STL, PLY or COMPAS JSON file (by its suffix, case-insensitive).

    Returns
    -------
    TriangleSoup
        At least one triangle; every vertex finite.

    Raises
    ------
    AssemblyError
        Naming ``path``: an unknown suffix, not a regular file, unreadable, empty, not
        parsable (the OBJ line at fault where there is one), no faces, or a vertex that is
        not a finite number or lies beyond :data:`~masonry.tolerances.MAX_COORDINATE_M`.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise AssemblyError(f"{path}: unknown format {path.suffix!r}; masonry reads "
                            f"{', '.join(FORMATS)}")
    if path.exists() and not path.is_file():  # a folder, FIFO or device never ends well
        raise AssemblyError(f"{path}: not a regular file")
    try:
        data = path.read_bytes()
    except OSError as error:
        raise AssemblyError(f"{path}: cannot be read: {error.strerror or error}") from None
    if not data or data.isspace():  # (strip() would copy the file)
        raise AssemblyError(f"{path}: the file is empty")
    reader = READERS[suffix]
    try:
        soup = reader(data)
    except AssemblyError as error:
        raise AssemblyError(f"{path}: {error}") from None
    except (ValueError, IndexError, KeyError, TypeError, UnicodeDecodeError) as error:
        raise AssemblyError(f"{path}: not a readable {suffix[1:].upper()} file "
                            f"({type(error).__name__}: {error})") from None
    if len(soup.triangles) == 0:
        raise AssemblyError(f"{path}: no faces, so no block")
    bad = ~np.isfinite(soup.vertices).all(axis=1)
    if bad.any():
        raise AssemblyError(f"{path}: {bad.sum()} vertices are not finite numbers (nan or "
                            f"inf), the first at {soup.vertices[bad][0].tolist()}")
    far = np.abs(soup.vertices).max(axis=1) > MAX_COORDINATE_M
    if far.any():
        raise AssemblyError(f"{path}: {far.sum()} vertices lie farther than "
                            f"{MAX_COORDINATE_M:g} m from the origin, the first at "
                            f"{soup.vertices[far][0].tolist()}; masonry reads metres: move "
                            f"the model near the origin or scale it to metres")
    return soup


# ---------------------------------------------------------------------- OBJ
def _read_obj(data: bytes) -> TriangleSoup:
    """Wavefront OBJ: ``v``, ``f`` (polygons, ``i``, ``i/t``, ``i/t/n``, ``i//n``,
    negative indices), ``o`` and ``g``; everything else is skipped.

    Our own parser, not a library's (docs/bench.md, "Reading meshes": ``OMP_NUM_THREADS=1
    masonry bench --readers bricks.obj`` on the 6,328 objects of preset 1's full dome).
    trimesh's ``load_obj`` takes longer than the rule allows, joins the objects that share
    a name, returns them last first, and resolves negative (relative) indices against all
    of the file's vertices instead of those before the face. meshio's ``meshio.read`` is as
    fast but keeps no object or group names, and refuses a file with fewer normals than
    vertices (Rhino's style: ``fixtures/assembly/arch_rhino.obj``).
    """
    vertices, corners = [], []
    faces = []  # per face: its line, the vertices before it, its size, object and group
    objects, groups = [], {}
    current_object = current_group = -1
    for number, line in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        tag = parts[0]
        if tag == "v":
            if len(parts) < 4:
                raise AssemblyError(f"line {number}: a vertex needs three coordinates")
            vertices.append(parts[1:4])
        elif tag == "f":
            if len(parts) < 4:
                raise AssemblyError(f"line {number}: a face needs three vertices")
            corners += parts[1:]
            faces.append((number, len(vertices), len(parts) - 1, current_object,
                          current_group))
        elif tag == "o":
            objects.append(" ".join(parts[1:]))
            current_object = len(objects) - 1
        elif tag == "g":
            name = " ".join(parts[1:])
            current_group = groups.setdefault(name, len(groups))
    vertices = np.array(vertices, dtype=float)
    if not faces:
        return TriangleSoup([], vertices)
    face_line, before, size, face_object, face_group = np.array(faces).T
    return _obj_blocks(vertices, _obj_indices(corners, face_line, before, size), size,
                       face_object, face_group, objects, list(groups))


def _obj_indices(corners, face_line, before, size):
    """(C,) int: the vertex of every face corner (``i``, ``i/t``, ``i/t/n``, ``i//n``;
    negative: relative to the ``before`` vertices the file defined before the face;
    ``size`` corners per face), 0-based. An index out of range raises naming its face's
    line (``face_line``)."""
    if any("/" in corner for corner in corners):
        corners = [corner.split("/", 1)[0] for corner in corners]
    ids = list(map(int, corners))  # ValueError: not an integer
    try:
        ids = np.array(ids, dtype=np.int64)
    except OverflowError:  # far beyond any file's vertices: out of range below
        ids = np.array([max(-MAX_INDEX, min(MAX_INDEX, i)) for i in ids], dtype=np.int64)
    count = np.repeat(before, size)
    ids = np.where(ids > 0, ids - 1, count + ids)
    bad = (ids < 0) | (ids >= count)
    if bad.any():
        face = np.repeat(np.arange(len(size)), size)[np.argmax(bad)]
        raise AssemblyError(f"line {face_line[face]}: the face refers to a vertex that is not "
                            f"defined before it (the file has {before[face]} by then)")
    return ids


def _obj_blocks(vertices, flat, counts, face_object, face_group, objects,
                groups) -> TriangleSoup:
    """The soup of an OBJ's polygons: one block per object, else per group, else one soup
    to split into bodies.

    Parameters
    ----------
    vertices : (V, 3) float
    flat, counts : (C,) int, (F,) int
        The polygons' vertex indices, polygon after polygon, and each polygon's count.
    face_object, face_group : (F,) int
        Index into ``objects`` and ``groups`` of every polygon, -1 before the first.
    objects, groups : list of str
        Names in order of appearance (objects may repeat, groups do not).
    """
    triangles, face = fan(flat, counts)
    if len(np.unique(face_object)) >= 2:
        names, key = objects, face_object
    elif len(np.unique(face_group)) >= 2:
        names, key = groups, face_group
    else:
        named = (objects[face_object[0]] if face_object[0] >= 0
                 else groups[face_group[0]] if face_group[0] >= 0 else "")
        return TriangleSoup([named], vertices, triangles, np.zeros(len(triangles)),
                            split_bodies=True)
    # faces before the first object or group form a block of their own
    if (key < 0).any():
        names = names + ["unnamed"]
        key = np.where(key < 0, len(names) - 1, key)
    used, key = np.unique(key, return_inverse=True)
    return TriangleSoup([names[i] for i in used], vertices, triangles, key[face])


# ---------------------------------------------------------------------- STL, PLY
def _read_stl(data: bytes) -> TriangleSoup:
    """Binary STL (exactly 84 + 50 n bytes) or ASCII STL (``solid`` ... ``endsolid``,
    every solid's ``vertex`` lines): one soup of all the triangles, in file order.

    Read by trimesh's ``load_stl_binary`` and ``load_stl_ascii``, after our own checks of
    the size, ``solid`` and ``endsolid`` (for their messages). On preset 1's full dome
    written as one STL they meet the rule above against the parser they replaced; meshio's is
    far slower on the binary file and could not read trimesh's ASCII STL
    (``OMP_NUM_THREADS=1 masonry bench --readers bricks.stl bricks_ascii.stl``;
    docs/bench.md, "Reading meshes").
    """
    from trimesh.exchange.stl import load_stl_ascii, load_stl_binary

    if len(data) >= 84 and len(data) == 84 + 50 * int.from_bytes(data[80:84], "little"):
        loaded = load_stl_binary(io.BytesIO(data))
        points = np.asarray(loaded.get("vertices", np.zeros((0, 3), np.float32)))
        with np.errstate(invalid="ignore"):  # NaNs are refused after reading
            return _one_soup(points.astype(float))
    text = data.decode("ascii", errors="replace")
    if not text.lstrip().startswith("solid"):
        raise AssemblyError(f"not an STL file: {len(data)} bytes is not 84 + 50 n (binary "
                            f"STL; truncated?) and the text does not start with 'solid'")
    if text.rfind("endsolid") < 0:
        raise AssemblyError("ASCII STL without 'endsolid': the file is truncated")
    with warnings.catch_warnings():
        # numpy's text parsing stops at the first word that is no number and only warns:
        # refuse the file instead of reading part of it
        warnings.simplefilter("error", DeprecationWarning)
        # the text as decoded above (trimesh would guess the encoding of bytes that are
        # not UTF-8); bytes, as a StringIO copies the text twice
        loaded = load_stl_ascii(io.BytesIO(text.encode()))
    solids = loaded["geometry"].values() if "geometry" in loaded else [loaded]
    return _one_soup(np.concatenate([np.zeros((0, 3))]
                                    + [s["vertices"][s["faces"]].reshape(-1, 3)
                                       for s in solids]))


def _read_ply(data: bytes) -> TriangleSoup:
    """PLY (ASCII or binary) by trimesh's reader: one soup of its faces.

    meshio's is far slower on the binary PLY of preset 1's full dome and no faster on the
    ASCII one (``OMP_NUM_THREADS=1 masonry bench --readers bricks.ply bricks_ascii.ply``;
    docs/bench.md, "Reading meshes").
    """
    import trimesh

    mesh = trimesh.load(io.BytesIO(data), file_type="ply", process=False)
    if not isinstance(mesh, trimesh.Trimesh):
        raise AssemblyError("no triangle mesh in the PLY file (a point cloud?)")
    return TriangleSoup([""], mesh.vertices, mesh.faces, np.zeros(len(mesh.faces)),
                        split_bodies=True)


def _one_soup(corners) -> TriangleSoup:
    """(3 T, 3) triangle corners, three by three -> a soup to split into bodies."""
    return TriangleSoup([""], corners, np.arange(len(corners)).reshape(-1, 3),
                        np.zeros(len(corners) // 3), split_bodies=True)


READERS = {".obj": _read_obj, ".stl": _read_stl, ".ply": _read_ply,
           ".json": read_compas_json}
"""Suffix -> reader of a file's bytes (one per entry of :data:`FORMATS`)."""
