"""The printable body: all bricks united into one watertight solid (docs/model.md 7, thesis 3.4.1).

The thesis joins its bricks in a CAD tool after offsetting them inward by one unit, so
that consecutive courses overlap (3.4.1), and prints the joined body (3.4.2). Here the
union is computed with manifold3d. Three facts measured with manifold3d 3.5.4 shape the
method (docs/model.md 7):

1. Faces that touch exactly merge, but bricks that touch only up to floating-point
   rounding, or only along an edge, stay separate bodies. So every brick is first grown
   by a small deliberate ``overlap``: each of its face planes moves outward by that
   distance, and bricks in contact then overlap by twice that.
2. The union of overlapping dome bricks has edges as short as 1e-11 m where features of
   different bricks nearly coincide. A loader that rounds to float32 (binary STL) and
   merges vertices collapses them: the raw union of preset 1 read back from STL is not
   watertight and has 36 zero-area triangles. ``Manifold.simplify`` and
   ``set_tolerance`` keep these edges (manifold collapses edges only below its own
   epsilon, about 1e-15 of the model size, unless its cost checks allow it). So the
   union is cleaned here: edges shorter than ``tol.contact`` are collapsed, then
   ``simplify(tol.contact)`` swaps away degenerate triangles and drops redundant
   coplanar vertices (a quarter of the triangles), repeated until no short edge is left.
3. ``Manifold.decompose()`` is far too slow and memory-hungry for a body count
   (docs/bench.md, "Measurements behind design choices"); bodies are counted on the
   mesh's connectivity (trimesh's ``body_count``) instead.
4. One ``batch_boolean`` of all the bricks costs far more than the sum of its parts'
   (it unites the accumulated body again with every chunk of bricks): preset 1's whole
   dome (8 webs of 791 blocks) takes about 12 times one web's union. A dome of equal
   webs is therefore united as one web, cleaned, turned into every web's place and
   united once more (``copies``; docs/bench.md, "Outputs in the time of the solve").

The result is verified, not assumed: watertight, consistently wound, one body, no
zero-area triangle and no two vertices closer than ``tol.contact`` (so float32 rounding
merges none). A body that fails raises :class:`PrintableError`.
"""

import dataclasses
import itertools
import logging
import time

import numpy as np

from masonry.blocks import Blocks, rotation_z
from masonry.errors import MasonryError
from masonry.meshing import merge_vertices
from masonry.tolerances import MIN_CORNER_DET, OVERLAP_REL, Tolerances

log = logging.getLogger(__name__)

_CLEAN_ROUNDS = 4
"""Rounds of merging near vertices and dropping degenerate faces before the body must be
clean."""


class PrintableError(MasonryError, ValueError):
    """The united body is not printable: not watertight, not one body, degenerate, or
    manifold3d reported an error. ``report`` holds the measured checks."""

    def __init__(self, message, report=None):
        super().__init__(message)
        self.report = report


def grown_blocks(blocks: Blocks, overlap: float, tol: Tolerances | None = None):
    """Every convex block grown by moving each face plane outward by ``overlap``.

    For a convex block this is exact: the grown block is the intersection of the offset
    halfspaces. A vertex on exactly three faces moves to the point on its three offset
    planes, ``v + N^-1 (overlap, overlap, overlap)`` with ``N`` the (3, 3) matrix of the
    face normals, solved for all vertices in one batched call. A block is taken this way
    when all its vertices lie on three faces with independent normals and every moved
    vertex lies inside all the block's offset halfspaces (within ``tol.length``). Other
    blocks (a pyramid's apex, a triangulated block read from a mesh file, where a vertex
    lies on more faces) get the intersection of their offset halfspaces from qhull,
    one block at a time.

    Parameters
    ----------
    blocks : Blocks
        Convex blocks with planar faces, outward normals.
    overlap : float, metres
        Outward offset of every face plane, >= 0.
    tol : Tolerances, optional
        Default ``Tolerances.for_points(blocks.vertices)``; uses ``length``.

    Returns
    -------
    points : (P, 3) float, metres
        Corners of the grown blocks, block after block. A block taken by the
        three-plane path keeps its vertex layout (``P == V`` when all are).
    offsets : (B + 1,) int
        Block ``i`` owns ``points[offsets[i]:offsets[i + 1]]``.
    by_halfspaces : (B,) bool
        Blocks grown by qhull's halfspace intersection.

    Raises
    ------
    PrintableError
        When qhull finds no intersection of a block's offset halfspaces (a block that is
        not convex, or flat).
    """
    if tol is None:
        tol = Tolerances.for_points(blocks.vertices)
    points = _three_plane_corners(blocks, overlap)
    is_simple = _inside_offset_planes(blocks, points, overlap, tol)
    hulls = {i: _halfspace_corners(blocks, i, overlap) for i in np.flatnonzero(~is_simple)}

    vertex_count = np.diff(blocks.vertex_offsets)
    grown_count = vertex_count.copy()
    for i, corners in hulls.items():
        grown_count[i] = len(corners)
    offsets = np.concatenate([[0], np.cumsum(grown_count)])
    out = np.empty((offsets[-1], 3))
    keep = np.repeat(is_simple, vertex_count)
    shift = np.repeat(offsets[:-1] - blocks.vertex_offsets[:-1], vertex_count)
    out[(np.arange(len(blocks.vertices)) + shift)[keep]] = points[keep]
    for i, corners in hulls.items():
        out[offsets[i]:offsets[i + 1]] = corners
    return out, offsets, ~is_simple


def _three_plane_corners(blocks: Blocks, overlap: float) -> np.ndarray:
    """(V, 3) float, metres: every vertex on exactly three faces with independent
    normals moved onto its three offset planes, ``v + N^-1 (overlap, overlap,
    overlap)``; NaN for every other vertex."""
    n_vertices = len(blocks.vertices)
    # faces incident to every vertex, ragged: entries sorted by vertex
    entry_face = np.repeat(np.arange(blocks.n_faces), blocks.face_polygon_count)
    order = np.argsort(blocks.face_vertices, kind="stable")
    degree = np.bincount(blocks.face_vertices, minlength=n_vertices)
    first = np.cumsum(degree) - degree
    corner = np.flatnonzero(degree == 3)
    corner_faces = entry_face[order[first[corner][:, None] + np.arange(3)]]
    matrix = blocks.face_normal[corner_faces]  # (C, 3, 3): one face normal per row
    solvable = np.abs(np.linalg.det(matrix)) > MIN_CORNER_DET
    corner = corner[solvable]
    points = np.full((n_vertices, 3), np.nan)
    rhs = np.full((len(corner), 3, 1), float(overlap))
    points[corner] = blocks.vertices[corner] + np.linalg.solve(matrix[solvable], rhs)[..., 0]
    return points


def _inside_offset_planes(blocks: Blocks, points, overlap, tol: Tolerances) -> np.ndarray:
    """(B,) bool: blocks with faces whose moved vertices ``points`` ((V, 3), NaN where
    not moved) all lie inside every offset face plane of their block, within
    ``tol.length``."""
    # one (face, vertex) pair per face and vertex of the same block
    vertex_count = np.diff(blocks.vertex_offsets)
    per_face = vertex_count[blocks.face_block]
    pair_face = np.repeat(np.arange(blocks.n_faces), per_face)
    pair_vertex = (np.repeat(blocks.vertex_offsets[blocks.face_block] - np.cumsum(per_face)
                             + per_face, per_face) + np.arange(len(pair_face)))
    excess = (np.einsum("ij,ij->i", points[pair_vertex] - blocks.face_centre[pair_face],
                        blocks.face_normal[pair_face]) - overlap)
    bad = ~(excess <= tol.length)  # NaN (a vertex not moved) counts as bad
    face_count = np.bincount(blocks.face_block, minlength=blocks.n_blocks)
    return (face_count > 0) & (np.bincount(
        blocks.face_block[pair_face], bad, minlength=blocks.n_blocks) == 0)


def _halfspace_corners(blocks: Blocks, i: int, overlap: float) -> np.ndarray:
    """(n, 3) float, metres: corners of block ``i``'s offset halfspaces' intersection,
    from qhull."""
    from scipy.spatial import HalfspaceIntersection, QhullError

    faces = np.flatnonzero(blocks.face_block == i)
    normal = blocks.face_normal[faces]
    plane = np.column_stack([normal, -(np.einsum(
        "ij,ij->i", normal, blocks.face_centre[faces]) + overlap)])
    try:
        return HalfspaceIntersection(plane, blocks.block_vertex_mean[i]).intersections
    except QhullError as error:
        raise PrintableError(f"block {blocks.block_name[i]}: its grown halfspaces have "
                             "no intersection (is it convex and solid?)") from error


def printable_body(blocks: Blocks, vertices=None, overlap=None, tol=None, copies=1):
    """One watertight body from all blocks, for 3D printing (docs/model.md 7, thesis 3.4.1).

    Every block is grown by ``overlap`` (:func:`grown_blocks`), all are united in one
    ``Manifold.batch_boolean`` call, and the union is cleaned of edges shorter than
    ``tol.contact`` (see the module notes). Support blocks (the ground slab) are
    included: they are the printed dome's base. Pass ``blocks.subset(mask)`` to leave
    blocks out. With ``copies``, the blocks are one of that many equal parts about z (a
    web): their cleaned union is turned into every part's place and united again.

    Parameters
    ----------
    blocks : Blocks
        Convex blocks; all of them are united.
    vertices : (V, 3) float, metres, optional
        Positions to use instead of ``blocks.vertices``, in the same layout: the
        inward-offset CAD vertices (:meth:`masonry.scenes.base.Scene.cad_vertices`), whose
        consecutive courses overlap (thesis 3.4.1).
    overlap : float, metres, optional
        Outward growth of every face plane; default ``OVERLAP_REL * tol.scale``.
        Bricks that touch then overlap by ``2 * overlap``. 0 grows nothing, and bricks
        that only touch will not join (the body check then fails).
    tol : Tolerances, optional
        Default ``Tolerances.for_points`` of the whole body's vertices (every copy's).
        ``tol.contact`` is the cleaning distance: edges shorter than it are collapsed and
        surfaces move by less than about it; it must exceed float32 rounding at the
        model's coordinates.
    copies : int
        Turns of ``blocks`` by ``360 / copies`` degrees about z (1: the blocks alone).

    Returns
    -------
    mesh : trimesh.Trimesh
        The body, float64 vertices, built with ``process=False``.
    report : dict
        The body's checks and measures: manifold's status, watertight, wound, bodies,
        genus, volumes (cleaned, united, the blocks', the grown blocks'), triangles,
        vertices, the smallest edge, close vertex pairs, overlap, cleaning, ``copies``
        and the times (``union_time_s``, ``time_s``); the whole body's, every copy counted.

    Raises
    ------
    PrintableError
        When manifold3d reports an error or the body is not watertight, not
        consistently wound, not one body, has zero-area triangles or vertices closer
        than ``tol.contact``. The error's ``report`` holds the measurements.
    """
    import trimesh

    start = time.perf_counter()
    blocks, overlap, tol = _checked_inputs(blocks, vertices, overlap, tol, copies)
    parts, by_halfspaces = _grown_hulls(blocks, overlap, tol)
    union_start = time.perf_counter()
    union, collapsed = _united(parts, copies, tol.contact)
    union_volume = union.volume()  # evaluates the lazy boolean
    union_time = time.perf_counter() - union_start
    _require_ok(union, "union")

    body, more = _cleaned(union, tol.contact)
    mesh_data = body.to_mesh64()
    mesh = trimesh.Trimesh(np.array(mesh_data.vert_properties)[:, :3],
                           np.array(mesh_data.tri_verts), process=False)
    report = _body_report(body, mesh, tol) | {
        "union_volume_m3": float(union_volume),
        "blocks_volume_m3": copies * float(blocks.block_volume.sum()),
        "grown_volume_m3": copies * float(sum(part.volume() for part in parts)),
        "overlap_m": float(overlap),
        "halfspace_blocks": copies * int(by_halfspaces.sum()),
        "collapsed_edges": int(collapsed + more),
        "copies": int(copies),
        "union_time_s": round(union_time, 4),
        "time_s": round(time.perf_counter() - start, 4),
    }
    problems = _failed_checks(report, tol)
    if problems:
        raise PrintableError("printable body failed its checks: " + "; ".join(problems),
                             report)
    log.info("printable body: %d triangles, %.6g m^3, union %.2f s", report["triangles"],
             report["volume_m3"], union_time)
    return mesh, report


def _grown_hulls(blocks: Blocks, overlap, tol):
    """The grown blocks (:func:`grown_blocks`) as manifold3d hulls, and which blocks were
    grown by qhull; a block without volume is refused (:class:`PrintableError`)."""
    import manifold3d

    points, offsets, by_halfspaces = grown_blocks(blocks, overlap, tol)
    parts = [manifold3d.Manifold.hull_points(points[lo:hi])
             for lo, hi in itertools.pairwise(offsets)]
    flat = [i for i, part in enumerate(parts) if part.is_empty()]
    if flat:
        raise PrintableError(f"{len(flat)} blocks have no volume, first "
                             f"{blocks.block_name[flat[0]]}")
    return parts, by_halfspaces


def _united(parts, copies, distance):
    """The union of the manifolds ``parts`` turned ``copies`` times about z (see
    :func:`printable_body`), and how many short edges the part's cleaning collapsed."""
    import manifold3d

    union = manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add)
    if copies == 1:
        return union, 0
    _require_ok(union, "union")
    part, collapsed = _cleaned(union, distance)
    turns = [part.transform(np.column_stack([rotation_z(2 * np.pi * k / copies),
                                             np.zeros(3)])) for k in range(copies)]
    return manifold3d.Manifold.batch_boolean(turns, manifold3d.OpType.Add), collapsed


def _turned(points, copies) -> np.ndarray:
    """(copies * P, 3): ``points`` turned ``copies`` times by ``360 / copies`` degrees
    about z."""
    return np.concatenate([points @ rotation_z(2 * np.pi * k / copies).T
                           for k in range(copies)])


def _checked_inputs(blocks: Blocks, vertices, overlap, tol, copies=1):
    """``(blocks, overlap, tol)`` of :func:`printable_body`'s arguments: ``vertices`` put
    in ``blocks``, the defaults filled in; raises ValueError on a bad argument."""
    if vertices is not None:
        vertices = np.asarray(vertices, dtype=float)
        if vertices.shape != blocks.vertices.shape:
            raise ValueError(f"vertices has shape {vertices.shape}, the blocks' vertices "
                             f"{blocks.vertices.shape}")
        blocks = dataclasses.replace(blocks, vertices=vertices)
    if not (isinstance(copies, (int, np.integer)) and copies >= 1):
        raise ValueError(f"copies must be an integer >= 1, not {copies!r}")
    if tol is None:
        tol = Tolerances.for_points(_turned(blocks.vertices, copies))
    if overlap is None:
        overlap = OVERLAP_REL * tol.scale
    if not (np.isfinite(overlap) and overlap >= 0):
        raise ValueError(f"overlap must be a finite length >= 0 (metres), not {overlap!r}")
    if blocks.n_blocks == 0:
        raise ValueError("no blocks to unite")
    return blocks, overlap, tol


def _body_report(body, mesh, tol: Tolerances) -> dict:
    """The measured checks of the cleaned ``body`` (a ``Manifold``) and its ``mesh``
    (trimesh): see :func:`printable_body`'s ``report``."""
    from scipy.spatial import cKDTree

    edge_length = mesh.edges_unique_length
    return {
        "manifold_status": _status_name(body),
        "watertight": bool(mesh.is_watertight),
        "winding_consistent": bool(mesh.is_winding_consistent),
        "bodies": int(mesh.body_count),
        "genus": int(body.genus()),
        "volume_m3": float(body.volume()),
        "triangles": len(mesh.faces),
        "vertices": len(mesh.vertices),
        "zero_area_faces": int((mesh.area_faces <= 0).sum()),
        "close_vertex_pairs": len(cKDTree(mesh.vertices).query_pairs(
            tol.contact, output_type="ndarray")),
        "min_edge_m": float(edge_length.min()) if len(edge_length) else 0.0,
        "clean_distance_m": float(tol.contact),
    }


def _failed_checks(report: dict, tol: Tolerances) -> list:
    """One line for every check of a body ``report`` that fails (empty: printable)."""
    return [
        text for text, failed in (
            (f"manifold3d status {report['manifold_status']}",
             report["manifold_status"] != "NoError"),
            ("not watertight", not report["watertight"]),
            ("inconsistent winding", not report["winding_consistent"]),
            (f"{report['bodies']} bodies, expected 1", report["bodies"] != 1),
            (f"{report['zero_area_faces']} zero-area triangles", report["zero_area_faces"]),
            ((f"{report['close_vertex_pairs']} vertex pairs closer than "
              f"{tol.contact:.3g} m (float32 rounding may merge them)"),
             report["close_vertex_pairs"]),
            ("no volume", not report["volume_m3"] > 0),
        ) if failed]


def _cleaned(body, distance):
    """Collapse edges shorter than ``distance`` and simplify, until none is left.

    Returns the cleaned ``Manifold`` and the number of edges collapsed.
    """
    import manifold3d

    collapsed = 0
    for _ in range(_CLEAN_ROUNDS):
        data = body.to_mesh64()
        vertices, faces, count = _collapse_short_edges(
            np.array(data.vert_properties)[:, :3], np.array(data.tri_verts), distance)
        if count == 0:
            return body, collapsed
        collapsed += count
        # manifold3d rejects read-only arrays, hence the copies above
        body = manifold3d.Manifold(manifold3d.Mesh64(
            vert_properties=vertices, tri_verts=faces.astype(np.uint64)))
        _require_ok(body, "cleaned mesh")
        body = body.simplify(distance)
    raise PrintableError(f"edges shorter than {distance:.3g} m remain after "
                         f"{_CLEAN_ROUNDS} cleaning rounds")


def _collapse_short_edges(vertices, faces, distance):
    """Merge the endpoints of every edge shorter than ``distance``.

    Chains of short edges merge into their lowest-index vertex. Triangles that lose a
    vertex are dropped, as are unused vertices.

    Parameters
    ----------
    vertices : (V, 3) float
    faces : (T, 3) int

    Returns
    -------
    vertices : (V', 3) float, faces : (T', 3) int, collapsed : int
    """
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = edges[edges[:, 0] < edges[:, 1]]  # each interior edge once
    short = edges[np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]], axis=1)
                  < distance]
    if len(short) == 0:
        return vertices, faces, 0
    faces, _ = merge_vertices(faces, short, len(vertices))
    used = np.unique(faces)
    index = np.full(len(vertices), -1)
    index[used] = np.arange(len(used))
    return np.ascontiguousarray(vertices[used]), index[faces], len(short)


def _status_name(body) -> str:
    return str(body.status()).rsplit(".", 1)[-1]


def _require_ok(body, what):
    status = _status_name(body)
    if status != "NoError":
        raise PrintableError(f"manifold3d reported {status} for the {what}")


def printable_blocks(scene, boundary="free", cad_offset=1.0):
    """``(blocks, vertices, copies)`` of the printable body (:func:`printable_body`): the
    blocks, their vertices moved ``cad_offset`` units inward, and how many turns about z
    make the body of them. The whole dome when the scene is one part of it analysed with
    its neighbours (a section with a boundary; docs/model.md 7): the part, turned. A
    whole scene made of equal turned parts (:func:`repeated_part`) gives its first part,
    turned; any other scene itself, once."""
    cad = scene.cad_vertices(cad_offset)
    symmetry = scene.symmetry
    if symmetry.unit and boundary != "free":
        return scene.blocks, cad, symmetry.order
    if symmetry.period_deg is not None:
        first = repeated_part(scene.blocks, cad, symmetry.order)
        if first is not None:
            vertex = np.repeat(first, np.diff(scene.blocks.vertex_offsets))
            return scene.blocks.subset(first), cad[vertex], symmetry.order
    return scene.blocks, cad, 1


def repeated_part(blocks: Blocks, vertices, copies: int):
    """(B,) bool: the blocks of web 0 when ``blocks`` are ``copies`` webs (``block_web``),
    web after web, each web 0's blocks with the same vertex and face counts, its
    ``vertices`` ((V, 3), metres) those of web 0 turned by ``360 k / copies`` degrees
    about z within ``Tolerances.length``; None otherwise."""
    n = blocks.n_blocks
    if copies < 2 or n % copies:
        return None
    per = n // copies
    if not np.array_equal(blocks.block_web, np.repeat(np.arange(copies), per)):
        return None
    vertex_count = np.diff(blocks.vertex_offsets).reshape(copies, per)
    face_count = np.bincount(blocks.face_block, minlength=n).reshape(copies, per)
    if (vertex_count != vertex_count[0]).any() or (face_count != face_count[0]).any():
        return None
    own = np.asarray(vertices, dtype=float).reshape(copies, -1, 3)
    tol = Tolerances.for_points(vertices)
    if np.abs(_turned(own[0], copies) - own.reshape(-1, 3)).max() > tol.length:
        return None
    return blocks.block_web == 0
