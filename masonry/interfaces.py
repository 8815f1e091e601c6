"""Contact interfaces between blocks (SPEC 5, thesis 3.2.4).

One generic detector for every scene; nothing here knows about domes.

An interface is a planar polygon through which two blocks push on each other. It lies in
the plane of the *main* face (the lower block's face for bed joints), with that face's
outward normal ``n`` (pointing from the main block ``pair[:, 0]`` into the other block
``pair[:, 1]``) and in-plane basis ``t1, t2``.
"""

from dataclasses import dataclass

import numpy as np
import shapely
from scipy.spatial import cKDTree

from masonry.blocks import Blocks
from masonry.tolerances import Tolerances

INTERFACE_KINDS = ("horizontal", "vertical", "support", "boundary")
"""Names of the ``kind`` codes. ``support``: one block is a fixed support (the ground);
``boundary``: contact with a neighbouring web (dome boundary modes)."""


@dataclass(frozen=True, eq=False)
class Interfaces:
    """Interfaces as a struct of arrays.

    Parameters
    ----------
    pair : (K, 2) int
        ``(main block, other block)``; the normal points from the main block into the other.
    kind : (K,) int8
        Code into :data:`INTERFACE_KINDS`.
    vertices : (IV, 3) float, metres
        Polygon vertices of all interfaces, flat, counter-clockwise about ``normal``.
    offsets : (K + 1,) int
        Interface ``k`` is ``vertices[offsets[k]:offsets[k + 1]]`` (3 to 8 vertices).
    area : (K,) float, m^2
    centre : (K, 3) float, metres (area centroid)
    normal, t1, t2 : (K, 3) float
        Right-handed orthonormal frame ``(t1, t2, normal)``.
    """

    pair: np.ndarray
    kind: np.ndarray
    vertices: np.ndarray
    offsets: np.ndarray
    area: np.ndarray
    centre: np.ndarray
    normal: np.ndarray
    t1: np.ndarray
    t2: np.ndarray

    def __len__(self) -> int:
        return len(self.pair)

    @property
    def vertex_count(self) -> np.ndarray:
        """(K,) int: vertices per interface."""
        return np.diff(self.offsets)

    @property
    def vertex_interface(self) -> np.ndarray:
        """(IV,) int: the interface each vertex belongs to."""
        return np.repeat(np.arange(len(self)), self.vertex_count)

    def polygon(self, k: int) -> np.ndarray:
        return self.vertices[self.offsets[k]:self.offsets[k + 1]]

    def counts(self) -> dict:
        """Number of interfaces per kind name."""
        return {name: int((self.kind == i).sum()) for i, name in enumerate(INTERFACE_KINDS)}

    @classmethod
    def empty(cls) -> "Interfaces":
        z3 = np.zeros((0, 3))
        return cls(np.zeros((0, 2), int), np.zeros(0, np.int8), z3, np.zeros(1, int),
                   np.zeros(0), z3, z3, z3, z3)


# ---------------------------------------------------------------------- detection
def detect(blocks: Blocks, tol: Tolerances | None = None, up=None) -> Interfaces:
    """Contact interfaces between convex blocks (SPEC 5, thesis 3.2.4).

    1. Candidate block pairs from a spatial index (:func:`candidate_pairs`).
    2. Face pairs of a candidate pair whose outward normals are anti-parallel within
       ``tol.max_gap_angle`` and whose polygons come within ``tol.contact`` of each
       other's planes.
    3. The *main* face is the support's face when one block is a support, else the lower
       block's face (thesis 3.2.4): the face that looks up along its block's ``up``
       direction; for head joints, the smaller block index's face. Gap
       closing: if the faces form a wedge, the complementary face is rotated about the
       line where the two face planes meet onto the main plane; parallel faces are
       projected onto it.
    4. Both polygons are intersected in the main face's ``(t1, t2)`` frame (shapely). The
       intersection is kept when its area exceeds ``tol.min_area_rel`` times the smaller
       face's area and it touches the complementary face: the interval of distances of
       its vertices to the complementary face's plane comes within ``tol.contact`` of 0.
       (For a wedge this asks that the overlap reaches the line of contact, so two faces
       whose planes meet but whose polygons do not touch there give no interface.)

    Tolerances used (all from ``tol``):

    - ``contact``: bounding boxes within ``contact`` of each other are candidates; the
      vertices of each face must span a distance interval to the other face's plane that
      comes within ``contact`` of 0; the same test on the interface polygon.
    - ``max_gap_angle``: largest angle between ``n_a`` and ``-n_b`` (the wedge angle).
    - ``min_area_rel``: smallest kept area, relative to the smaller of the two faces.
    - ``grid``: precision grid of the shapely intersection (robust on coincident faces).
    - ``length``: faces whose wedge moves the complementary face by at most ``length``
      count as parallel (projected, no rotation); interface vertices closer than
      ``length`` to the line through their neighbours (collinear or duplicate) are
      dropped.

    Parameters
    ----------
    blocks : Blocks
    tol : Tolerances, optional
        Default ``Tolerances.for_points(blocks.vertices)``.
    up : (B, 3) float, optional
        Each block's own up direction (the direction its course is stacked in), used only
        to name bed joints and head joints. Default: the z axis for every block. A scene
        whose courses lean (the top of a dome leans up to 80 degrees) passes its bricks'
        course directions, so a bed joint stays a bed joint however it leans.

    Returns
    -------
    Interfaces
        Sorted by ``(main block, other block)``. Kinds: ``support`` when one block is a
        support, else ``horizontal`` (a bed joint) when the main normal is within 45 deg
        of the main block's ``up`` direction (or its opposite),
        else ``vertical``; this detector never reports ``boundary``. The vertex count is
        3 to 8 for faces of at most 4 vertices (two convex polygons of ``m`` and ``n``
        vertices intersect in at most ``m + n``).
    """
    if tol is None:
        tol = Tolerances.for_points(blocks.vertices)
    pairs = candidate_pairs(blocks, tol)
    face_a, face_b = _touching_face_pairs(blocks, pairs, tol)
    if len(face_a) == 0:
        return Interfaces.empty()
    up = np.broadcast_to([0.0, 0.0, 1.0], (blocks.n_blocks, 3)) if up is None else up
    up = np.asarray(up, dtype=float)
    main, comp = _order_main(blocks, face_a, face_b, up)
    return _intersect(blocks, main, comp, tol, up)


def candidate_pairs(blocks: Blocks, tol: Tolerances | None = None) -> np.ndarray:
    """Block pairs whose bounding boxes are within ``tol.contact`` of each other.

    Boxes are indexed by a k-d tree over their centres, one tree per size class (box
    half-diagonals within a factor 2), so that one large block (a ground slab) does not
    widen the query radius of all the small ones. Pairs whose centres are farther apart
    than the sum of the classes' largest half-diagonals cannot touch and are never
    generated; the survivors are then tested box against box. Pairs of two supports are
    skipped.

    Parameters
    ----------
    blocks : Blocks
    tol : Tolerances, optional
        Default ``Tolerances.for_points(blocks.vertices)``; uses ``contact`` and ``length``.

    Returns
    -------
    (P, 2) int
        ``(i, j)`` with ``i < j``, sorted lexicographically.
    """
    if tol is None:
        tol = Tolerances.for_points(blocks.vertices)
    if blocks.n_blocks < 2:
        return np.zeros((0, 2), dtype=np.int64)
    lo, hi = blocks.block_bounds[:, 0], blocks.block_bounds[:, 1]
    centre = 0.5 * (lo + hi)
    radius = 0.5 * np.linalg.norm(hi - lo, axis=1)
    r_min = max(float(radius.min()), tol.length)
    size_class = np.floor(np.log2(np.maximum(radius, r_min) / r_min)).astype(int)
    members = [np.flatnonzero(size_class == k) for k in np.unique(size_class)]
    trees = [cKDTree(centre[m]) for m in members]
    reach = [radius[m].max() for m in members]
    # boxes grown by contact / 2 on every side have half-diagonals longer by
    # sqrt(3) / 2 * contact; 2 * contact covers both boxes
    slack = 2.0 * tol.contact
    found = []
    for k, (mk, tk) in enumerate(zip(members, trees)):
        ij = tk.query_pairs(2 * reach[k] + slack, output_type="ndarray")
        found.append(mk[ij])
        for ml, tl, rl in zip(members[k + 1:], trees[k + 1:], reach[k + 1:]):
            hits = tk.sparse_distance_matrix(tl, reach[k] + rl + slack, output_type="ndarray")
            found.append(np.stack([mk[hits["i"]], ml[hits["j"]]], axis=1))
    pairs = np.sort(np.concatenate(found).reshape(-1, 2), axis=1)
    i, j = pairs[:, 0], pairs[:, 1]
    overlap = np.all((lo[i] <= hi[j] + tol.contact) & (lo[j] <= hi[i] + tol.contact), axis=1)
    both_support = blocks.block_is_support[i] & blocks.block_is_support[j]
    pairs = pairs[overlap & ~both_support]
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


# ---------------------------------------------------------------------- kernels
def _ragged(counts):
    """Flat indexing of ragged rows.

    Parameters
    ----------
    counts : (n,) int, every count >= 0

    Returns
    -------
    row : (sum(counts),) int
        Row of every flat entry.
    k : (sum(counts),) int
        Position of every flat entry in its row.
    start : (n,) int
        First flat entry of every row.
    """
    start = np.cumsum(counts) - counts
    row = np.repeat(np.arange(len(counts)), counts)
    return row, np.arange(len(row)) - start[row], start


def _face_vertex_rows(blocks, face):
    """Vertices of many faces, flat: ``(row, xyz, start, count)``.

    ``row`` (n,) int gives the entry of ``face`` each vertex belongs to, ``xyz`` (n, 3)
    float the vertices in polygon order, ``start`` and ``count`` (len(face),) int the
    ragged layout.
    """
    count = blocks.face_polygon_count[face]
    row, k, start = _ragged(count)
    xyz = blocks.vertices[blocks.face_vertices[blocks.face_offsets[face][row] + k]]
    return row, xyz, start, count


def _plane_distance_interval(blocks, face, point, normal):
    """(min, max) signed distance of each face's vertices to the plane (point, normal).

    ``face`` (n,) int; ``point``, ``normal`` (n, 3) float, one plane per face. Returns two
    (n,) float arrays, metres.
    """
    row, xyz, start, _ = _face_vertex_rows(blocks, face)
    d = np.einsum("ij,ij->i", xyz - point[row], normal[row])
    return np.minimum.reduceat(d, start), np.maximum.reduceat(d, start)


def _touching_face_pairs(blocks, pairs, tol):
    """Face pairs of the candidate block pairs that may be in contact (vectorized screen).

    Every face of block ``i`` is paired with every face of block ``j``; a face pair
    survives when the normals are anti-parallel within ``tol.max_gap_angle`` and each
    face's vertices span a distance interval to the other face's plane that comes within
    ``tol.contact`` of 0 (a necessary condition for the polygons to be that close).

    Returns
    -------
    face_a, face_b : (S,) int
        Faces of ``pairs[:, 0]`` and ``pairs[:, 1]``.
    """
    if len(pairs) == 0:
        return np.zeros(0, int), np.zeros(0, int)
    # faces per block in a padded (B, width) table, so that the normals of all face pairs
    # of all block pairs are one batched product; padding normals are NaN and never pass
    face_count = np.bincount(blocks.face_block, minlength=blocks.n_blocks)
    order = np.argsort(blocks.face_block, kind="stable")
    owner = blocks.face_block[order]
    slot = np.arange(len(order)) - (np.cumsum(face_count) - face_count)[owner]
    block_face = np.full((blocks.n_blocks, face_count.max()), -1)
    block_face[owner, slot] = order
    block_normal = np.full(block_face.shape + (3,), np.nan)
    block_normal[owner, slot] = blocks.face_normal[order]

    a, b = pairs[:, 0], pairs[:, 1]
    cos_ab = np.einsum("pik,pjk->pij", block_normal[a], block_normal[b])
    p, i, j = np.nonzero(cos_ab <= -np.cos(tol.max_gap_angle))
    face_a, face_b = block_face[a[p], i], block_face[b[p], j]

    normal, centre = blocks.face_normal, blocks.face_centre
    for side in range(2):
        near, far = (face_a, face_b) if side == 0 else (face_b, face_a)
        if len(near) == 0:
            break
        lo, hi = _plane_distance_interval(blocks, far, centre[near], normal[near])
        keep = (lo <= tol.contact) & (hi >= -tol.contact)
        face_a, face_b = face_a[keep], face_b[keep]
    return face_a, face_b


def _order_main(blocks, face_a, face_b, up):
    """Split face pairs into (main, complementary) faces.

    The support's face is main; else the lower block's: the one whose face looks up
    along its course (``n_a . up_a > 0``). Centroid heights would not do: near the top
    of a dome a deep pattern brick's centroid stands higher than the brick resting on it.
    Head joints (normal across ``up``) go to the smaller block index.
    """
    block_a, block_b = blocks.face_block[face_a], blocks.face_block[face_b]
    support_a = blocks.block_is_support[block_a]
    support_b = blocks.block_is_support[block_b]
    rise = np.einsum("ij,ij->i", blocks.face_normal[face_a], up[block_a])
    is_bed = np.abs(rise) > np.cos(np.pi / 4)
    a_lower = np.where(is_bed, rise > 0, block_a < block_b)
    a_main = support_a | (~support_b & a_lower)
    return np.where(a_main, face_a, face_b), np.where(a_main, face_b, face_a)


def _intersect(blocks, main, comp, tol, up):
    """Close the gap, intersect the polygons and assemble :class:`Interfaces`.

    Parameters
    ----------
    main, comp : (S,) int
        Main and complementary face of every surviving face pair.
    """
    normal, centre, area = blocks.face_normal, blocks.face_centre, blocks.face_area
    t1, t2 = blocks.face_basis
    n_m, n_c = normal[main], normal[comp]
    origin = centre[main]

    # gap closing (SPEC 5.3); faces whose wedge rotation would move no vertex farther
    # than tol.length count as parallel and are only projected (below)
    row, xyz, start, count = _face_vertex_rows(blocks, comp)
    sin = np.linalg.norm(np.cross(n_m, n_c), axis=1)
    face_radius = np.maximum.reduceat(np.linalg.norm(xyz - centre[comp][row], axis=1), start)
    is_wedge = sin * face_radius > tol.length
    xyz = _close_wedge(xyz, row, is_wedge, n_m, origin, n_c, centre[comp])

    comp_poly = _polygons_2d(xyz, row, count, origin, t1[main], t2[main])
    row_m, xyz_m, _, count_m = _face_vertex_rows(blocks, main)
    main_poly = _polygons_2d(xyz_m, row_m, count_m, origin, t1[main], t2[main])

    overlap = shapely.intersection(main_poly, comp_poly)
    # GEOS's plain overlay can fail on coincident polygons (points instead of the
    # polygon); snap rounding on a fine grid is robust but twice as slow, so only the
    # pairs that did not come back as one polygon are redone with it
    retry = shapely.get_type_id(overlap) != shapely.GeometryType.POLYGON
    overlap[retry] = shapely.intersection(main_poly[retry], comp_poly[retry],
                                          grid_size=tol.grid)
    overlap = _polygon_part(overlap)
    keep = (shapely.get_type_id(overlap) == shapely.GeometryType.POLYGON) & (
        shapely.area(overlap) > tol.min_area_rel * np.minimum(area[main], area[comp]))
    # drop collinear and duplicate vertices, then make every ring counter-clockwise
    # about the main normal ((t1, t2, n) is right-handed)
    main, comp = main[keep], comp[keep]
    overlap = shapely.orient_polygons(shapely.simplify(overlap[keep], tol.length))
    keep = ~shapely.is_empty(overlap)  # simplify may collapse a sliver
    main, comp, overlap = main[keep], comp[keep], overlap[keep]
    order = np.lexsort((comp, main, blocks.face_block[comp], blocks.face_block[main]))
    main, comp, overlap = main[order], comp[order], overlap[order]
    if len(main) == 0:
        return Interfaces.empty()

    # one ring per polygon (convex, no holes); drop each ring's closing vertex
    _, coords, (ring_offsets, _) = shapely.to_ragged_array(overlap)
    vertex_count = np.diff(ring_offsets) - 1
    vrow, k, vstart = _ragged(vertex_count)
    xy = coords[ring_offsets[:-1][vrow] + k]
    vertices = (centre[main][vrow] + xy[:, :1] * t1[main][vrow]
                + xy[:, 1:] * t2[main][vrow])

    # contact test on the interface itself: the gap to the complementary face's plane
    # is affine over the polygon, so its extremes are at vertices
    gap = np.einsum("ij,ij->i", vertices - centre[comp][vrow], normal[comp][vrow])
    keep = ((np.minimum.reduceat(gap, vstart) <= tol.contact)
            & (np.maximum.reduceat(gap, vstart) >= -tol.contact))
    main, comp, overlap = main[keep], comp[keep], overlap[keep]
    block_m, block_c = blocks.face_block[main], blocks.face_block[comp]
    normal_k, t1_k, t2_k = normal[main], t1[main], t2[main]

    is_support = blocks.block_is_support[block_m] | blocks.block_is_support[block_c]
    is_horizontal = np.abs(np.einsum("ij,ij->i", normal_k, up[block_m])) > np.cos(np.pi / 4)
    kind = np.select([is_support, is_horizontal],
                     [INTERFACE_KINDS.index("support"), INTERFACE_KINDS.index("horizontal")],
                     INTERFACE_KINDS.index("vertical")).astype(np.int8)
    centroid = shapely.get_coordinates(shapely.centroid(overlap))
    return Interfaces(
        pair=np.stack([block_m, block_c], axis=1),
        kind=kind,
        vertices=vertices[keep[vrow]],
        offsets=np.concatenate([[0], np.cumsum(vertex_count[keep])]),
        area=shapely.area(overlap),
        centre=centre[main] + centroid[:, :1] * t1_k + centroid[:, 1:] * t2_k,
        normal=normal_k,
        t1=t1_k,
        t2=t2_k,
    )


def _polygon_part(overlap):
    """The polygon of each overlay result. Two convex polygons meet in one convex
    polygon, but GEOS may return it in a collection with a sliver line or point of 1e-12 m
    (whether depends on where the face polygons start); those would drop the interface."""
    collection = np.flatnonzero(shapely.get_type_id(overlap) > shapely.GeometryType.POLYGON)
    if len(collection):
        parts, owner = shapely.get_parts(overlap[collection], return_index=True)
        polygon = shapely.get_type_id(parts) == shapely.GeometryType.POLYGON
        parts, owner = parts[polygon], owner[polygon]
        overlap = overlap.copy()
        overlap[collection] = shapely.from_wkt("POLYGON EMPTY")  # points, lines only
        if len(parts):
            largest = np.lexsort((shapely.area(parts), owner))  # by owner, then area
            last = np.r_[owner[largest][1:] != owner[largest][:-1], True]
            overlap[collection[owner[largest][last]]] = parts[largest][last]
    return overlap


def _close_wedge(xyz, row, is_wedge, n_m, point_m, n_c, point_c):
    """Rotate complementary faces onto their main planes about the planes' common line.

    The axis is ``u = n_m x n_c / |n_m x n_c|`` through the point ``p0`` on both planes
    nearest to ``point_c``; the angle is the wedge angle ``theta`` between ``n_c`` and
    ``-n_m`` (Rodrigues' formula), which turns ``n_c`` into ``-n_m``, so the face lands
    in the main plane and its points on the common line stay put (thesis 3.2.4, step 5).

    Parameters
    ----------
    xyz : (n, 3) float
        Complementary face vertices, flat; ``row`` (n,) int gives their face pair.
    is_wedge : (m,) bool
        Face pairs to rotate; the others are returned unchanged.
    n_m, point_m, n_c, point_c : (m, 3) float
        Main and complementary planes (unit normal, a point on the plane).

    Returns
    -------
    (n, 3) float
    """
    xyz = xyz.copy()
    pick = np.flatnonzero(is_wedge)
    if len(pick) == 0:
        return xyz
    n_m, point_m, n_c, point_c = n_m[pick], point_m[pick], n_c[pick], point_c[pick]
    axis = np.cross(n_m, n_c)
    sin = np.linalg.norm(axis, axis=1)
    cos = -np.einsum("ij,ij->i", n_m, n_c)
    u = axis / sin[:, None]
    # p0 = point_c + a (n_c x u): on the complementary plane for every a, and on the
    # main plane for a = n_m . (point_m - point_c) / sin, since n_m . (n_c x u) = sin
    height = np.einsum("ij,ij->i", n_m, point_m - point_c)
    p0 = point_c + (height / sin)[:, None] * np.cross(n_c, u)

    rotated = is_wedge[row]
    r = (np.cumsum(is_wedge) - 1)[row[rotated]]  # row in the picked arrays
    v = xyz[rotated] - p0[r]
    c, s, u = cos[r, None], sin[r, None], u[r]
    xyz[rotated] = (p0[r] + v * c + np.cross(u, v) * s
                    + u * np.einsum("ij,ij->i", u, v)[:, None] * (1.0 - c))
    return xyz


def _polygons_2d(xyz, row, count, origin, t1, t2):
    """Shapely polygons of flat 3D vertices in per-row frames ``(origin, t1, t2)``.

    ``xyz`` (n, 3) float with ``row`` (n,) int into ``count``, ``origin``, ``t1``, ``t2``
    (m,) / (m, 3); returns (m,) shapely polygons (rings closed here).
    """
    rel = xyz - origin[row]
    xy = np.stack([np.einsum("ij,ij->i", rel, t1[row]),
                   np.einsum("ij,ij->i", rel, t2[row])], axis=1)
    closed_row, k, _ = _ragged(count + 1)
    src_start = np.cumsum(count) - count
    closed = xy[src_start[closed_row] + k % count[closed_row]]
    ring_offsets = np.concatenate([[0], np.cumsum(count + 1)])
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, closed,
                                     (ring_offsets, np.arange(len(count) + 1)))
