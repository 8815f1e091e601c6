"""Any assembly of convex blocks, read from mesh files (docs/model.md 4.6, scene ``assembly``).

The interface detector and the rigid block equilibrium serve blocks that did not come
from our dome: an arch drawn in Rhino, a tower, a scan, a peer tool's model. This module
turns the triangle soups that :mod:`masonry.scenes.mesh_files` reads into checked
:class:`~masonry.blocks.Blocks`, and those into the scene:

- OBJ: one block per object or group, names kept (a name used twice gets ``_2``, ``_3``,
  ...). The ``bricks.obj`` of our own runs is such a file, and its names
  (``b0042_regular_c12``) give back each brick's class and course.
- A file that names no blocks (STL, PLY, an OBJ of neither objects nor groups): one
  block per connected body, named after the file (``wall_0007``), or after the file
  alone when it holds one body, so one file per block works too.
- COMPAS JSON (an assembly, a block model, a list of meshes): one block per mesh, with
  the supports the file flags (:mod:`masonry.scenes.compas_json`).

Every block must be a closed convex solid. A block that is open, non-manifold, inside
out, flat, or concave beyond :data:`~masonry.tolerances.CONVEXITY_REL` raises
:class:`AssemblyError` naming the block and its file; so does a file that cannot be
read. Each accepted block is replaced by its convex hull, whose coplanar triangles are
merged into whole planar polygons, so an interface is a whole face and not a triangle
of it. The scene then takes supports, an optional ground slab, and refuses blocks that
overlap.

Bodies in one STL or PLY that touch each other share vertices and edges: an edge where
two blocks touch belongs to four triangles. Connectivity therefore pairs the triangles
around such an edge by their angle about it (each solid wedge is bounded by the nearest
face on either side), instead of joining everything that shares an edge.
"""

import dataclasses
import hashlib
import logging
import numbers
import re
import time
from dataclasses import dataclass
from fnmatch import fnmatchcase
from pathlib import Path

import numpy as np

from masonry.blocks import (BLOCK, BLOCK_CLASSES, MASK_BITS, Blocks, blocks_from_hulls,
                            concatenate, hull_faces)
from masonry.meshing import merge_vertices
from masonry.parameters import declare
from masonry.scenes.base import Scene, SceneKind
from masonry.scenes.mesh_files import AssemblyError, TriangleSoup, read_mesh
from masonry.scenes.overlaps import overlapping_pairs
from masonry.errors import ParameterError
from masonry.tolerances import (COINCIDENT_ANGLE, CONVEXITY_REL, GROUND_MARGIN_REL,
                                INTERPENETRATION_REL, OVERLAP_TOLERANCE_RANGE, Tolerances)

log = logging.getLogger(__name__)

OUR_NAME = re.compile(r"^(?:w\d+_)?b\d+_(" + "|".join(BLOCK_CLASSES) + r")_c(\d+)$")
"""Block names written by :func:`masonry.export.obj.blocks_obj`: class and course (a web's
or sector's bricks of a whole dome carry ``w<web>_`` before them)."""


# ---------------------------------------------------------------------- public API
def read_blocks(paths, tol: Tolerances | None = None) -> Blocks:
    """Convex blocks from mesh files, in file order; the supports are those a COMPAS
    file flags (``is_support``), no block of another format.

    Parameters
    ----------
    paths : sequence of str or Path
        OBJ, STL, PLY or COMPAS JSON files (see the module docstring for how each splits
        into blocks).
    tol : Tolerances, optional
        ``length`` merges duplicate vertices, ``contact`` decides which hull triangles
        are coplanar (one face). Default ``Tolerances.for_points`` of all the vertices.

    Returns
    -------
    Blocks
        Class ``block`` (or the class in one of our own names), course 0 (or our name's),
        names unique, vertices in metres as read (no unit conversion).

    Raises
    ------
    AssemblyError
        A file cannot be read or holds no block, or a block is not a closed convex solid.
    """
    paths = [Path(p) for p in paths]
    if not paths:
        raise AssemblyError("no mesh file given")
    return _blocks_of(paths, [read_mesh(p) for p in paths], tol)[0]


def _blocks_of(paths, soups, tol: Tolerances | None) -> tuple:
    """:func:`read_blocks` of the files' soups, and the first block of every file ((n,)
    int)."""
    points = np.concatenate([s.vertices for s in soups])
    if tol is None:
        tol = Tolerances.for_points(points)
    parts = []
    for k, (path, soup) in enumerate(zip(paths, soups)):
        soup = _merged(soup, tol.length)
        if soup.split_bodies:
            soup = _bodies(soup, path.stem)
        soups[k] = soup
        parts.append(_convex_blocks(soup, path, tol))
    blocks = concatenate(parts)
    names = _unique_names(blocks.block_name)
    block_class, block_course = _classes_from_names(names)
    first = np.cumsum([0] + [part.n_blocks for part in parts[:-1]])
    return Blocks.from_arrays(
        blocks.vertices, blocks.vertex_offsets, blocks.face_vertices, blocks.face_offsets,
        blocks.face_block, block_class=block_class, block_course=block_course,
        block_is_support=np.concatenate([s.supports for s in soups]),
        block_name=names), first


def select_supports(blocks: Blocks, names=(), below=None, tol: Tolerances | None = None):
    """Which blocks are fixed supports.

    Parameters
    ----------
    blocks : Blocks
    names : sequence of str
        Block names or shell-style patterns (``fnmatch``: ``pier_*``, ``*_ground_*``),
        case-sensitive. Each must match at least one block.
    below : float, optional, metres
        Also every block whose lowest point is at or below ``z = below`` (within
        ``tol.contact``): the blocks touching (or under) that plane.
    tol : Tolerances, optional
        Default ``Tolerances.for_points(blocks.vertices)``.

    Returns
    -------
    (B,) bool
        ``blocks.block_is_support`` or'ed with the selection.

    Raises
    ------
    AssemblyError
        A name matches no block, or ``below`` lies under every block.
    """
    if tol is None:
        tol = Tolerances.for_points(blocks.vertices)
    is_support = np.array(blocks.block_is_support, dtype=bool)
    block_name = [str(n) for n in blocks.block_name]
    for pattern in names:
        hit = np.array([fnmatchcase(n, pattern) for n in block_name], dtype=bool)
        if not hit.any():
            raise AssemblyError(f"--support {pattern!r} matches no block (names are like "
                                f"{block_name[0]!r})")
        is_support |= hit
    if below is not None:
        hit = blocks.block_bounds[:, 0, 2] <= below + tol.contact
        if not hit.any():
            lowest = float(blocks.block_bounds[:, 0, 2].min())
            raise AssemblyError(f"--support-below {below:g}: no block reaches down to "
                                f"z = {below:g} (the lowest is at z = {lowest:.6g})")
        is_support |= hit
    return is_support


def with_ground(blocks: Blocks, tol: Tolerances | None = None) -> Blocks:
    """``blocks`` with a ground slab (class ``ground``, a support) added as block 0.

    The slab's top is the plane of the lowest vertex; it reaches under every block that
    comes within ``tol.contact`` of that plane, with a margin of
    :data:`~masonry.tolerances.GROUND_MARGIN_REL` (5%) of that footprint's larger side
    on every side, and is as thick as the margin. Only those lowest blocks
    touch it; what else rests on what is left to the interface detector.
    """
    if "ground" in set(blocks.block_name):
        raise AssemblyError("--ground: a block is already named 'ground'")
    if tol is None:
        tol = Tolerances.for_points(blocks.vertices)
    lo, hi = blocks.block_bounds[:, 0], blocks.block_bounds[:, 1]
    top = float(lo[:, 2].min())
    lowest = lo[:, 2] <= top + tol.contact
    foot_lo, foot_hi = lo[lowest, :2].min(axis=0), hi[lowest, :2].max(axis=0)
    margin = GROUND_MARGIN_REL * float((foot_hi - foot_lo).max())
    x0, y0 = foot_lo - margin
    x1, y1 = foot_hi + margin
    corners = np.array([[x, y, z] for z in (top - margin, top) for y in (y0, y1)
                        for x in (x0, x1)])
    ground = Blocks.from_hexahedra(corners[None], block_class="ground",
                                   block_is_support=[True], block_name=["ground"])
    return concatenate([ground, blocks])


def assembly_name(paths, blocks: Blocks) -> str:
    """``<stem of the first file>_<8 hex digits>``: the hash covers every vertex, face,
    name and support, so a changed file or support choice gets its own run folder."""
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "-", Path(next(iter(paths))).stem) or "assembly"
    digest = hashlib.sha1()
    for array in (blocks.vertices, blocks.face_vertices, blocks.face_offsets,
                  blocks.face_block, blocks.block_is_support, blocks.block_class):
        digest.update(np.ascontiguousarray(array).tobytes())
    digest.update("\0".join(map(str, blocks.block_name)).encode())
    return f"{stem}_{digest.hexdigest()[:8]}"


@dataclass(frozen=True)
class AssemblyGeometry:
    """The blocks read from mesh files, named after the files and their content
    (:func:`assembly_name`)."""

    assembly: str = declare("", "the imported model", kind="str",
                            check=lambda v: bool(v), names_geometry=True,
                            expected="the name of an imported model (masonry analyze "
                                     "sets it)")


class Assembly(SceneKind):
    """``assembly``: any set of convex blocks read from mesh files, with its supports
    (:func:`load_assembly`; not built from parameters alone)."""

    name = "assembly"
    summary = "blocks read from mesh files (masonry analyze)"
    geometry = AssemblyGeometry
    block_word = "blocks"
    has_courses = False
    moved_for_cad = False
    from_parameters = False

    @classmethod
    def id_prefix(cls, geometry, boundary) -> str:
        return f"assembly_{geometry.assembly}"


def load_assembly(paths, *, supports=(), support_below=None, ground=False,
                  overlap_tolerance=None):
    """The ``assembly`` scene of mesh files: blocks, supports, optional ground slab.

    Parameters
    ----------
    paths : sequence of str or Path
        Mesh files, see :func:`read_blocks`.
    supports, support_below : see :func:`select_supports`
        Either replaces the supports a COMPAS file flags; without them, those are kept.
    ground : bool
        Add a ground slab under the lowest blocks (:func:`with_ground`).
    overlap_tolerance : float, optional
        Blocks may interpenetrate by up to this fraction of the smaller one's size
        (:func:`~masonry.scenes.overlaps.overlapping_pairs`); default
        :data:`~masonry.tolerances.INTERPENETRATION_REL`.

    Returns
    -------
    scene : masonry.scenes.Scene
        Of kind :class:`Assembly`, its geometry named by :func:`assembly_name`; no course
        directions (bed and head joints are named with respect to z) and no CAD offset.
    source : dict
        Provenance for run.json: ``files``, ``support``, ``support_below``, ``ground``,
        the number of ``supports``, the ``overlap_tolerance`` and the overlaps it
        accepted (``overlaps``: count and deepest, in metres and as a fraction of the
        smaller block's size) and the reading time ``read_s`` (seconds).

    Raises
    ------
    AssemblyError
        A file or a block is bad (:func:`read_blocks`), a support pattern matches
        nothing, no block (or every block) is a support, or two blocks overlap by more
        than ``overlap_tolerance``.
    """
    start = time.perf_counter()
    overlap_tolerance = checked_overlap_tolerance(overlap_tolerance)
    if not paths:
        raise AssemblyError("no mesh file given")
    soups = [read_mesh(p) for p in paths]
    blocks, first = _blocks_of([Path(p) for p in paths], list(soups), None)
    problem = _problem_record(paths, soups, first)
    tol = Tolerances.for_points(blocks.vertices)
    if supports or support_below is not None:  # the user's choice, not the file's
        blocks = dataclasses.replace(blocks, block_is_support=np.zeros(blocks.n_blocks, bool))
    if ground:
        blocks = with_ground(blocks, tol)
    is_support = select_supports(blocks, supports, support_below, tol)
    if not is_support.any():
        raise AssemblyError("no support: name the fixed blocks (--support NAME), take every "
                            "block at the bottom (--support-below Z) or add a slab (--ground)")
    if is_support.all():
        raise AssemblyError(f"every one of the {len(is_support)} blocks is a support: "
                            "nothing is left to analyse")
    overlaps = _checked_overlaps(blocks, paths, overlap_tolerance)
    blocks = dataclasses.replace(blocks, block_is_support=is_support)
    geometry = AssemblyGeometry(assembly_name(paths, blocks))
    source = {"files": [str(p) for p in paths], "support": list(supports),
              "support_below": support_below, "ground": bool(ground),
              "supports": int(is_support.sum()), "overlap_tolerance": overlap_tolerance,
              "overlaps": overlaps, "read_s": round(time.perf_counter() - start, 4)}
    if problem is not None:
        source["problem"] = problem
    log.info("read %d blocks (%d supports) in %.3g s", blocks.n_blocks, source["supports"],
             source["read_s"])
    return Scene(Assembly, geometry, blocks), source


def _problem_record(paths, soups, first) -> dict | None:
    """The inputs of the one compas_dem Problem among the files (as run.json records
    them: ``file``, ``mu``, ``cohesion_Pa``, ``tensile_Pa``, ``density``, ``fixed`` and
    ``point_loads``, blocks as indices of the read blocks), or None."""
    stated = [(path, soup.problem, int(f)) for path, soup, f in zip(paths, soups, first)
              if soup.problem is not None]
    if len(stated) > 1:
        raise AssemblyError(f"{stated[1][0]}: a second compas_dem Problem (with "
                            f"{stated[0][0]}); masonry analyses one problem at a time")
    if not stated:
        return None
    path, problem, offset = stated[0]
    record = dataclasses.asdict(problem)
    record["fixed"] = [offset + b for b in problem.fixed]
    record["point_loads"] = [{**load, "block": offset + load["block"]}
                             for load in problem.point_loads]
    return {"file": str(path), **record}


def checked_overlap_tolerance(rel) -> float:
    """``rel`` (None: :data:`~masonry.tolerances.INTERPENETRATION_REL`) as a float.

    Raises
    ------
    masonry.errors.ParameterError
        ``rel`` is not a number within :data:`~masonry.tolerances.OVERLAP_TOLERANCE_RANGE`.
    """
    if rel is None:
        return INTERPENETRATION_REL
    low, high = OVERLAP_TOLERANCE_RANGE
    if isinstance(rel, bool) or not isinstance(rel, numbers.Real) or not low <= rel <= high:
        raise ParameterError("overlap_tolerance", rel, f"a fraction of the smaller block's "
                             f"size from {low:g} to {high:g} (default {INTERPENETRATION_REL:g})")
    return float(rel)


def _checked_overlaps(blocks: Blocks, paths, rel) -> dict:
    """The overlaps that ``rel`` accepts, for run.json: the number of ``pairs`` deeper
    than :data:`~masonry.tolerances.INTERPENETRATION_REL` (or ``rel`` if less), the
    deepest ``depth_m`` and the largest ``fraction`` of the smaller block's size.

    Raises
    ------
    AssemblyError
        Blocks overlap by more than ``rel``: naming the deepest pair, how many pairs, and
        the ``--overlap-tolerance`` that would accept them all.
    """
    pairs, depth = overlapping_pairs(blocks, min(rel, INTERPENETRATION_REL))
    if len(pairs) == 0:
        return {"pairs": 0, "depth_m": 0.0, "fraction": 0.0}
    fraction = depth / _smaller_size(blocks, pairs)
    k = int(np.argmax(fraction))
    if fraction[k] > rel:
        a, b = blocks.block_name[pairs[k, 0]], blocks.block_name[pairs[k, 1]]
        files = ", ".join(str(p) for p in paths)
        enough = _round_up(fraction[k])
        way_out = (f"if the model overlaps by design, accept it with --overlap-tolerance "
                   f"{enough:g}" if enough <= OVERLAP_TOLERANCE_RANGE[1] else
                   f"deeper than --overlap-tolerance accepts ({OVERLAP_TOLERANCE_RANGE[1]:g})")
        raise AssemblyError(
            f"{files}: blocks {a!r} and {b!r} overlap by {1000 * depth[k]:.3g} mm, "
            f"{fraction[k]:.3g} of the smaller one's size ({int((fraction > rel).sum())} "
            f"pairs overlap by more than --overlap-tolerance {rel:g}): interpenetrating "
            f"solids are not a structure (a block or file given twice?); {way_out}")
    return {"pairs": len(pairs), "depth_m": float(depth[k]), "fraction": float(fraction[k])}


def _smaller_size(blocks: Blocks, pairs) -> np.ndarray:
    """(P,) float, metres: the smaller bounding box diagonal of each pair's blocks."""
    size = np.linalg.norm(blocks.block_bounds[:, 1] - blocks.block_bounds[:, 0], axis=1)
    return np.minimum(size[pairs[:, 0]], size[pairs[:, 1]])


def _round_up(fraction: float) -> float:
    """``fraction`` rounded up to one significant digit (0.0137 -> 0.02)."""
    step = 10.0 ** np.floor(np.log10(fraction))
    return float(np.ceil(fraction / step) * step)


# ---------------------------------------------------------------------- triangle soups
def _merged(soup: TriangleSoup, distance) -> TriangleSoup:
    """Per-block vertices (a vertex shared by two blocks is copied; blocks own contiguous
    ranges) with coincident ones (within ``distance``, metres) merged, and the triangles
    that collapse dropped. A soup still to be split keeps one pool, so that touching
    bodies share their vertices until :func:`_bodies` pairs them."""
    block = soup.triangle_block
    if soup.split_bodies:
        block = np.zeros_like(block)
    key = block[:, None] * len(soup.vertices) + soup.triangles
    unique, inverse = np.unique(key, return_inverse=True)
    vertices = soup.vertices[unique % len(soup.vertices)]
    owner = unique // len(soup.vertices)
    triangles = inverse.reshape(-1, 3)
    from scipy.spatial import cKDTree  # scipy loads with the first file read

    # coincident vertices of one block: a k-d tree over all, pairs kept within a block
    pairs = cKDTree(vertices).query_pairs(distance, output_type="ndarray")
    pairs = pairs[owner[pairs[:, 0]] == owner[pairs[:, 1]]]
    # the smallest index of each cluster stands for it (same block: same range)
    triangles, keep = merge_vertices(triangles, pairs, len(vertices))
    used, triangles = np.unique(triangles, return_inverse=True)
    return TriangleSoup(soup.block_name, vertices[used], triangles.reshape(-1, 3),
                        soup.triangle_block[keep], soup.split_bodies, soup.block_is_support)


def _bodies(soup: TriangleSoup, stem) -> TriangleSoup:
    """One block per connected body (see :func:`_body_labels`) of a merged soup, named
    ``stem`` when there is one body, else ``stem_0000``, ... (or ``<name>_0000`` when the
    file named its only object)."""
    label = _body_labels(soup.vertices, soup.triangles)
    count = int(label.max()) + 1 if len(label) else 0
    # bodies in the order of their first triangle in the file
    first = np.full(count, len(label))
    np.minimum.at(first, label, np.arange(len(label)))
    rank = np.empty(count, int)
    rank[np.argsort(first)] = np.arange(count)
    base = soup.block_name[0] if soup.block_name and soup.block_name[0] else stem
    names = [base] if count == 1 else [f"{base}_{k:04d}" for k in range(count)]
    # merging again gives every body its own copy of the vertices it shares
    return _merged(TriangleSoup(names, soup.vertices, soup.triangles, rank[label]), 0.0)


def _body_labels(vertices, triangles):
    """(T,) int: connected body of every triangle.

    Two triangles are joined across an edge they share with opposite directions. An edge
    shared by more than two triangles (blocks in contact share it) joins each triangle
    that opens a solid wedge about the edge with the nearest triangle, turning the same
    way, that closes it; triangles lying on top of each other (within
    :data:`~masonry.tolerances.COINCIDENT_ANGLE`) bound two touching blocks and are never
    partners.
    """
    n_tri = len(triangles)
    if n_tri == 0:
        return np.zeros(0, int)
    start = triangles.reshape(-1)
    end = np.roll(triangles, -1, axis=1).reshape(-1)
    third = np.roll(triangles, -2, axis=1).reshape(-1)
    tri = np.repeat(np.arange(n_tri), 3)
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    _, edge, count = np.unique(lo * len(vertices) + hi, return_inverse=True,
                               return_counts=True)
    forward = start == lo  # the triangle runs along the edge from lo to hi
    order = np.argsort(edge, kind="stable")
    bounds = np.concatenate([[0], np.cumsum(count)])
    links = []

    two = np.flatnonzero(count == 2)
    first, second = order[bounds[two]], order[bounds[two] + 1]
    opposite = forward[first] != forward[second]
    links.append(np.stack([tri[first[opposite]], tri[second[opposite]]], axis=1))

    for e in np.flatnonzero(count > 2):
        half = order[bounds[e]:bounds[e + 1]]
        links.append(_pair_about_edge(vertices, lo[half[0]], hi[half[0]], third[half],
                                      forward[half], tri[half]))
    links = np.concatenate(links).reshape(-1, 2)
    from scipy.sparse import coo_array
    from scipy.sparse.csgraph import connected_components

    graph = coo_array((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(n_tri, n_tri))
    return connected_components(graph, directed=False)[1]


def _pair_about_edge(vertices, lo, hi, third, forward, tri):
    """Triangle pairs that bound one solid wedge about the edge ``lo -> hi``.

    Angles are measured about the axis ``hi - lo``. A triangle running ``lo -> hi`` has
    its outward normal towards increasing angle, so its solid lies at smaller angles
    (it closes a wedge); one running ``hi -> lo`` opens a wedge towards larger angles.
    Each opening triangle pairs with the closing one at the smallest positive angle
    beyond it. Returns (k, 2) int triangle pairs.
    """
    axis = vertices[hi] - vertices[lo]
    axis /= np.linalg.norm(axis)
    arm = vertices[third] - vertices[lo]
    arm -= np.outer(arm @ axis, axis)
    e1 = arm[0] / np.linalg.norm(arm[0])
    e2 = np.cross(axis, e1)
    angle = np.arctan2(arm @ e2, arm @ e1)
    opening, closing = np.flatnonzero(~forward), np.flatnonzero(forward)
    if len(opening) == 0 or len(closing) == 0:
        return np.zeros((0, 2), int)
    gap = np.mod(angle[closing][None, :] - angle[opening][:, None], 2 * np.pi)
    gap[(gap < COINCIDENT_ANGLE) | (gap > 2 * np.pi - COINCIDENT_ANGLE)] = np.inf
    partner = np.argmin(gap, axis=1)
    ok = np.isfinite(gap[np.arange(len(opening)), partner])
    return np.stack([tri[opening[ok]], tri[closing[partner[ok]]]], axis=1)


# ---------------------------------------------------------------------- checks, hulls
def _convex_blocks(soup: TriangleSoup, path: Path, tol: Tolerances) -> Blocks:
    """Check every block of a merged soup and rebuild it as its hull's planar faces.

    Raises
    ------
    AssemblyError
        Naming ``path`` and the first bad block: too few triangles, open, not manifold,
        inconsistently oriented, inside out, flat, several bodies, not convex, or faces
        that do not merge into planar polygons.
    """
    vstart = _vertex_ranges(soup)
    volume = _signed_volumes(soup, vstart)
    problem = _surface_problem(soup) or _volume_problem(volume, soup, vstart, tol)
    if problem is not None:
        raise AssemblyError(f"{path}: block {soup.block_name[problem[0]]!r} {problem[1]}")
    order = np.argsort(soup.triangle_block, kind="stable")
    tstart = np.searchsorted(soup.triangle_block[order], np.arange(len(soup.block_name) + 1))
    own = _own_faces(soup, vstart, volume, tol.contact)
    hulls = []
    for b in range(len(soup.block_name)):
        points = soup.vertices[vstart[b]:vstart[b + 1]]
        if own[b] is not None:
            hulls.append((points, own[b], volume[b]))
            continue
        triangles = soup.triangles[order[tstart[b]:tstart[b + 1]]] - vstart[b]
        hull, why = _convex_hull(points, volume[b], triangles)
        if why is not None:
            raise AssemblyError(f"{path}: block {soup.block_name[b]!r} {why}")
        hulls.append((points, hull_faces(points, hull, tol.contact), hull.volume))
    try:
        blocks = blocks_from_hulls([h[0] for h in hulls], [h[1] for h in hulls],
                                   block_class="block", block_name=list(soup.block_name))
    except ValueError as error:  # a degenerate face, named by its block
        raise AssemblyError(f"{path}: {error}") from None
    # the merged polygons must enclose the hull: faces that overlap or leave holes (a
    # surface too curved for tol.contact to tell its facets apart) change the volume
    mismatch = np.abs(blocks.block_volume / np.array([h[2] for h in hulls]) - 1.0)
    if (mismatch > CONVEXITY_REL).any():
        bad = int(np.argmax(mismatch > CONVEXITY_REL))
        raise AssemblyError(f"{path}: block {soup.block_name[bad]!r} has faces that cannot be "
                            "merged into planar polygons (nearly coplanar facets: a curved "
                            "surface?)")
    return blocks


def _own_faces(soup: TriangleSoup, vstart, volume, distance) -> list:
    """Per block, the planar faces of its hull in :func:`~masonry.blocks.hull_faces`'s
    form, where its own triangles bound it: every vertex within ``distance`` (metres) of
    the inside of every triangle's plane, and so little outside that the hull's volume
    exceeds the block's ``volume`` by at most :data:`~masonry.tolerances.CONVEXITY_REL`
    (qhull's test), no triangle thinner than ``distance``, at most
    :data:`~masonry.blocks.MASK_BITS` vertices. None for the other blocks, for qhull to
    decide. One pass over all blocks, where qhull takes one block at a time. A vertex
    inside a face or an edge (a T-junction) is kept in the faces' vertex sets, which
    qhull's corners leave out (:func:`~masonry.blocks.blocks_from_hulls` drops it from
    both), so such a block's faces can come in another order than qhull's."""
    count = np.diff(vstart)
    corners = soup.vertices[soup.triangles]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    twice_area = np.linalg.norm(cross, axis=1)
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    thin = twice_area <= distance * longest
    surface = np.bincount(soup.triangle_block, twice_area / 2, minlength=len(count))
    candidate = (count <= MASK_BITS) & (np.bincount(
        soup.triangle_block, thin, minlength=len(count)) == 0)
    tri = np.flatnonzero(candidate[soup.triangle_block])
    block = soup.triangle_block[tri]
    normal = cross[tri] / twice_area[tri, None]
    # every (triangle, vertex of its block) pair: the vertex's height over the plane
    size = count[block]
    first = np.cumsum(size) - size
    pair = np.repeat(np.arange(len(tri)), size)
    local = np.arange(len(pair)) - first[pair]
    height = np.einsum("ij,ij->i", normal[pair],
                       soup.vertices[vstart[block[pair]] + local] - corners[tri[pair], 0])
    outside = np.full(len(count), np.inf)
    outside[candidate] = -np.inf
    np.maximum.at(outside, block[pair], height)
    # the hull lies within ``outside`` of every face's plane: to first order it adds at
    # most surface x outside to the block
    convex = (outside <= distance) & (outside * surface <= CONVEXITY_REL * volume)
    # a face: the triangles on which the same vertices lie (a bit mask), once per block
    key = np.bitwise_or.reduceat(np.where(np.abs(height) <= distance,
                                          np.left_shift(1, local), 0), first)
    keep = convex[block]
    order = np.flatnonzero(keep)[np.lexsort((key[keep], block[keep]))]
    new = np.ones(len(order), bool)
    new[1:] = (key[order[1:]] != key[order[:-1]]) | (block[order[1:]] != block[order[:-1]])
    face = order[new]
    entry_face, entry_point = np.nonzero((key[face, None] >> np.arange(MASK_BITS)) & 1)
    fstart = np.searchsorted(block[face], np.arange(len(count) + 1))
    estart = np.searchsorted(entry_face, fstart)
    return [(entry_face[estart[b]:estart[b + 1]] - fstart[b],
             entry_point[estart[b]:estart[b + 1]], normal[face[fstart[b]:fstart[b + 1]]])
            if convex[b] else None for b in range(len(count))]


def _vertex_ranges(soup: TriangleSoup) -> np.ndarray:
    """(B + 1,) int: block ``b`` owns vertices ``vstart[b]:vstart[b + 1]`` (blocks own
    contiguous vertex ranges after :func:`_merged`)."""
    vertex_block = np.empty(len(soup.vertices), int)
    vertex_block[soup.triangles.reshape(-1)] = np.repeat(soup.triangle_block, 3)
    return np.searchsorted(vertex_block, np.arange(len(soup.block_name) + 1))


def _surface_problem(soup: TriangleSoup):
    """``(block, why)`` of the first block that is not a closed, manifold, consistently
    oriented surface of at least four triangles (every edge used by exactly two
    triangles, once in each direction), else None."""
    n_blocks = len(soup.block_name)
    tri_block = soup.triangle_block
    present = np.bincount(tri_block, minlength=n_blocks)
    for block in np.flatnonzero(present < 4)[:1]:
        return block, f"has {present[block]} triangles: too few for a solid"
    t = soup.triangles
    start, end = t.reshape(-1), np.roll(t, -1, axis=1).reshape(-1)
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    _, edge, count = np.unique(lo * len(soup.vertices) + hi, return_inverse=True,
                               return_counts=True)
    forward = np.bincount(edge, weights=(start == lo).astype(float))
    edge_block = np.empty(len(count), int)
    edge_block[edge] = np.repeat(tri_block, 3)
    problems = [
        (count == 1, "is not closed: {n} edges belong to one face only{last}"),
        (count > 2, "is not manifold: {n} edges are shared by more than two faces"),
        ((count == 2) & (forward != 1),
         "is not consistently oriented: {n} edges are run twice in the same direction"),
    ]
    bad_block = min([int(edge_block[bad].min()) for bad, _ in problems if bad.any()],
                    default=n_blocks)
    for bad, why in problems:
        n = int((bad & (edge_block == bad_block)).sum())
        if n:
            # a cut-off file leaves its last block open
            last = (" (the last block in the file: is the file truncated?)"
                    if bad_block == n_blocks - 1 else "")
            return bad_block, why.format(n=n, last=last)
    return None


def _signed_volumes(soup: TriangleSoup, vstart) -> np.ndarray:
    """(B,) float, m^3: signed volume of every block, by the divergence theorem about
    the block's first vertex (which keeps the sum free of cancellation far from the
    origin); negative for a block whose faces point inward."""
    tri_block = soup.triangle_block
    tri = soup.vertices[soup.triangles]
    ref = soup.vertices[vstart[tri_block]]
    six = np.einsum("ij,ij->i", tri[:, 0] - ref, np.cross(tri[:, 1] - ref, tri[:, 2] - ref))
    return np.bincount(tri_block, six, minlength=len(soup.block_name)) / 6.0


def _volume_problem(volume, soup: TriangleSoup, vstart, tol: Tolerances):
    """``(block, why)`` of the first block that is inside out, then of the first that is
    flat (no ``volume`` within ``tol.length`` times its size squared), else None."""
    size = np.linalg.norm(np.maximum.reduceat(soup.vertices, vstart[:-1])
                          - np.minimum.reduceat(soup.vertices, vstart[:-1]), axis=1)
    flat = np.abs(volume) <= tol.length * size**2
    for b in np.flatnonzero((volume < 0) & ~flat)[:1]:
        return b, f"is inside out: its faces point inward (volume {volume[b]:.4g} m^3)"
    for b in np.flatnonzero(flat)[:1]:
        return b, "is flat: it has no volume"
    return None


def _convex_hull(points, volume, triangles):
    """``(hull, None)``: the convex hull of a closed block's ``points`` ((n, 3) float),
    or ``(None, why)`` when the block is flat, or its ``volume`` (m^3) falls short of
    the hull's by more than :data:`~masonry.tolerances.CONVEXITY_REL`: it holds several
    bodies (its ``triangles``, (T, 3) int into ``points``, fall apart) or is not
    convex."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(points)
    except QhullError:
        return None, "is flat: it has no volume"
    deficit = 1.0 - volume / hull.volume
    if not deficit > CONVEXITY_REL:
        return hull, None
    bodies = int(_body_labels(points, triangles).max()) + 1
    if bodies > 1:
        return None, f"holds {bodies} separate bodies"
    return None, (f"is not convex: its volume is {100 * deficit:.3g}% below its convex "
                  f"hull's (tolerance {100 * CONVEXITY_REL:g}%)")


def _unique_names(names):
    """Names with repeats numbered ``_2``, ``_3``, ... and empty names replaced."""
    seen, out = {}, []
    for i, name in enumerate(names):
        name = str(name) or f"block{i:04d}"
        k = seen.get(name, 0) + 1
        seen[name] = k
        out.append(name if k == 1 else f"{name}_{k}")
    return out


def _classes_from_names(names):
    """(B,) class and course from our own names (``b0042_regular_c12``), else ``block``
    and 0."""
    block_class = np.full(len(names), BLOCK, dtype=np.int8)
    block_course = np.zeros(len(names), int)
    for i, name in enumerate(names):
        match = OUR_NAME.match(name)
        if match:
            block_class[i] = BLOCK_CLASSES.index(match.group(1))
            block_course[i] = int(match.group(2))
    return block_class, block_course
