"""Contact interfaces between blocks (docs/model.md 5, thesis 3.2.4).

One generic detector for every scene; nothing here knows about domes.

An interface is a planar polygon through which two blocks push on each other. It lies in
the plane of the *main* face (the lower block's face for bed joints), with that face's
outward normal ``n`` (pointing from the main block ``pair[:, 0]`` into the other block
``pair[:, 1]``) and in-plane basis ``t1, t2``.

Why the polygons are clipped here and not by shapely (GEOS) (docs/model.md 5.4):
every pair is a pair of convex polygons, and in masonry they share edges and corners as
a rule. GEOS's overlay has no tolerance: it returned two points for two coincident
quadrilaterals 3e-17 m apart, and a polygon plus a 1e-12 m line elsewhere, so it needed
a snap-rounding retry wherever the result was not one polygon, and was slower
(docs/bench.md, "Measurements behind design choices"). Convex clipping of all pairs
at once (:func:`_clip_convex`, Sutherland-Hodgman with a point-on-line tolerance) has
no degenerate cases. Shapely stays its reference in the tests
(``test_convex_clipping_matches_shapely``).
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.spatial import cKDTree

from masonry.blocks import Blocks
from masonry.tolerances import BED_JOINT_ANGLE, Tolerances

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

    def is_kind(self, *names) -> np.ndarray:
        """(K,) bool: the interfaces of the kinds ``names`` (:data:`INTERFACE_KINDS`)."""
        return np.isin(self.kind, [INTERFACE_KINDS.index(name) for name in names])

    def subset(self, mask, block_remap=None) -> "Interfaces":
        """The interfaces selected by a boolean mask or index array, in their order.

        Parameters
        ----------
        mask : (K,) bool or (k,) int
        block_remap : (B,) int, optional
            New index of every block (``pair`` is mapped through it); default unchanged.
        """
        index = np.arange(len(self))[mask]
        count = self.vertex_count[index]
        start = np.repeat(self.offsets[index] - (np.cumsum(count) - count), count)
        vertex = start + np.arange(int(count.sum()))
        pair = self.pair[index] if block_remap is None else block_remap[self.pair[index]]
        return Interfaces(pair=pair, kind=self.kind[index], vertices=self.vertices[vertex],
                          offsets=np.concatenate([[0], np.cumsum(count)]),
                          area=self.area[index], centre=self.centre[index],
                          normal=self.normal[index], t1=self.t1[index], t2=self.t2[index])

    @classmethod
    def empty(cls) -> "Interfaces":
        z3 = np.zeros((0, 3))
        return cls(np.zeros((0, 2), int), np.zeros(0, np.int8), z3, np.zeros(1, int),
                   np.zeros(0), z3, z3, z3, z3)


# ---------------------------------------------------------------------- detection
def detect(blocks: Blocks, tol: Tolerances | None = None, up=None) -> Interfaces:
    """Contact interfaces between convex blocks (docs/model.md 5, thesis 3.2.4).

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
    4. Both polygons are intersected in the main face's ``(t1, t2)`` frame (convex
       clipping of all pairs at once, :func:`_clip_convex`). The intersection is kept
       when its area exceeds ``tol.min_area_rel`` times the smaller face's area and it
       touches the complementary face: the interval of distances of its vertices to the
       complementary face's plane comes within ``tol.contact`` of 0.
       (For a wedge this asks that the overlap reaches the line of contact, so two faces
       whose planes meet but whose polygons do not touch there give no interface.)

    Tolerances used (all from ``tol``):

    - ``contact``: bounding boxes within ``contact`` of each other are candidates; the
      vertices of each face must span a distance interval to the other face's plane that
      comes within ``contact`` of 0; the same test on the interface polygon.
    - ``max_gap_angle``: largest angle between ``n_a`` and ``-n_b`` (the wedge angle).
    - ``min_area_rel``: smallest kept area, relative to the smaller of the two faces.
    - ``length``: faces whose wedge moves the complementary face by at most ``length``
      count as parallel (projected, no rotation); in the clipping, a vertex within
      ``length`` of the other polygon's edge line lies on it; interface vertices closer
      than ``length`` to the line through their neighbours (collinear or duplicate) are
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
    if len(pairs) == 0:
        return Interfaces.empty()
    faces = _face_table(blocks)
    face_a, face_b = _touching_face_pairs(blocks, pairs, faces, tol)
    if len(face_a) == 0:
        return Interfaces.empty()
    up = np.broadcast_to([0.0, 0.0, 1.0], (blocks.n_blocks, 3)) if up is None else up
    up = np.asarray(up, dtype=float)
    main, comp = _order_main(blocks, face_a, face_b, up)
    return _intersect(blocks, main, comp, faces, tol, up)


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
    found = np.concatenate(found).reshape(-1, 2)
    i, j = np.minimum(found[:, 0], found[:, 1]), np.maximum(found[:, 0], found[:, 1])
    is_near = ~(blocks.block_is_support[i] & blocks.block_is_support[j])
    for lo_k, hi_k in zip(lo.T, hi.T):  # axis by axis: 1D gathers are the fast ones
        is_near &= (lo_k[i] <= hi_k[j] + tol.contact) & (lo_k[j] <= hi_k[i] + tol.contact)
    i, j = i[is_near], j[is_near]
    order = np.lexsort((j, i))
    return np.stack([i[order], j[order]], axis=1)


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


class _FaceTable(NamedTuple):
    """Every face's vertices in a padded table.

    xyz : (F, W, 3) float, metres
        Vertices in polygon order, the last one repeated up to W (the most vertices of
        any face). A repeated vertex is a zero-length edge: it changes no distance
        interval, area or centroid, and clips nothing.
    radius : (F,) float, metres
        Largest distance of a vertex from the face centre.
    warp : (F,) float, metres
        Largest distance of a vertex from the face plane (0 up to rounding for a planar
        face; an imported face may be planar only within a tolerance).
    """

    xyz: np.ndarray
    radius: np.ndarray
    warp: np.ndarray


def _face_table(blocks) -> _FaceTable:
    """The :class:`_FaceTable` of ``blocks``."""
    count = blocks.face_polygon_count
    k = np.minimum(np.arange(count.max()), count[:, None] - 1)
    xyz = blocks.vertices[blocks.face_vertices[blocks.face_offsets[:-1, None] + k]]
    # the radius and warp over each face's own vertices (the flat list, not the padding)
    x, y, z = (blocks.vertices[blocks.face_vertices]
               - np.repeat(blocks.face_centre, count, axis=0)).T
    n_x, n_y, n_z = np.repeat(blocks.face_normal, count, axis=0).T
    start = blocks.face_offsets[:-1]
    return _FaceTable(xyz, np.sqrt(np.maximum.reduceat(x * x + y * y + z * z, start)),
                      np.maximum.reduceat(np.abs(x * n_x + y * n_y + z * n_z), start))


def _touching_face_pairs(blocks, pairs, faces, tol):
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
    # of the block pairs of one width class are one batched product (a block of many
    # faces, a ground ring's, does not widen the others'); padding normals are NaN and
    # never pass
    face_count = np.bincount(blocks.face_block, minlength=blocks.n_blocks)
    order = np.argsort(blocks.face_block, kind="stable")
    owner = blocks.face_block[order]
    slot = np.arange(len(order)) - (np.cumsum(face_count) - face_count)[owner]
    block_face = np.full((blocks.n_blocks, face_count.max()), -1)
    block_face[owner, slot] = order
    block_normal = np.full(block_face.shape + (3,), np.nan)
    block_normal[owner, slot] = blocks.face_normal[order]

    face_a, face_b, cos = [], [], []
    for group in _width_classes(np.maximum(face_count[pairs[:, 0]], face_count[pairs[:, 1]])):
        a, b = pairs[group, 0], pairs[group, 1]
        width = max(face_count[a].max(), face_count[b].max())
        cos_ab = block_normal[a, :width] @ block_normal[b, :width].transpose(0, 2, 1)
        p, i, j = np.nonzero(cos_ab <= -np.cos(tol.max_gap_angle))
        face_a.append(block_face[a[p], i])
        face_b.append(block_face[b[p], j])
        cos.append(cos_ab[p, i, j])
    face_a, face_b, cos = np.concatenate(face_a), np.concatenate(face_b), np.concatenate(cos)

    # a cheap screen first: b's face centre near a's face plane. For b's vertices v,
    # n_a . (v - centre_b) = (n_a + n_b) . (v - centre_b) - n_b . (v - centre_b), at most
    # |n_a + n_b| radius_b + warp_b, and |n_a + n_b|^2 = 2 + 2 cos_ab
    normal, centre = blocks.face_normal, blocks.face_centre
    gap = np.einsum("ij,ij->i", normal[face_a], centre[face_b] - centre[face_a])
    excess = np.maximum(np.abs(gap) - tol.contact - faces.warp[face_b], 0.0)
    keep = excess**2 <= np.maximum(2.0 + 2.0 * cos, 0.0) * faces.radius[face_b]**2
    face_a, face_b = face_a[keep], face_b[keep]

    # the test itself, both ways
    for near, far in ((0, 1), (1, 0)):
        pair = (face_a, face_b)
        n = normal[pair[near]]
        # signed distances of the far face's vertices to the near face's plane
        d = (faces.xyz[pair[far]] @ n[:, :, None])[..., 0]
        d -= np.einsum("ij,ij->i", centre[pair[near]], n)[:, None]
        keep = (d.min(axis=1) <= tol.contact) & (d.max(axis=1) >= -tol.contact)
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
    is_bed = np.abs(rise) > np.cos(BED_JOINT_ANGLE)
    a_lower = np.where(is_bed, rise > 0, block_a < block_b)
    a_main = support_a | (~support_b & a_lower)
    return np.where(a_main, face_a, face_b), np.where(a_main, face_b, face_a)


def _intersect(blocks, main, comp, faces, tol, up):
    """Close the gap, intersect the polygons and assemble :class:`Interfaces`.

    Parameters
    ----------
    main, comp : (S,) int
        Main and complementary face of every surviving face pair.
    faces : _FaceTable
    """
    normal, centre = blocks.face_normal, blocks.face_centre
    t1, t2 = blocks.face_basis
    # face pairs in classes of polygon width, so that a few faces of many vertices (a
    # ground ring's) do not widen the padded arrays of all the others
    count = blocks.face_polygon_count
    parts = [_overlaps(blocks, main[group], comp[group], faces, tol)
             for group in _width_classes(np.maximum(count[main], count[comp]))]
    main, comp = (np.concatenate([part[i] for part in parts]) for i in (0, 1))
    count = np.concatenate([part[3] for part in parts])
    width = max(part[2].shape[1] for part in parts)
    xy = np.concatenate([_take(part[2], np.minimum(np.arange(width)[:, None],
                                                   part[2].shape[1] - 1))
                         for part in parts], axis=2)
    order = np.lexsort((comp, main, blocks.face_block[comp], blocks.face_block[main]))
    main, comp, xy, count = main[order], comp[order], xy[..., order], count[order]
    if len(main) == 0:
        return Interfaces.empty()

    vrow, k, vstart = _ragged(count)
    x, y = xy[:, k, vrow, None]
    vertices = centre[main][vrow] + x * t1[main][vrow] + y * t2[main][vrow]

    # contact test on the interface itself: the gap to the complementary face's plane
    # is affine over the polygon, so its extremes are at vertices
    gap = np.einsum("ij,ij->i", vertices - centre[comp][vrow], normal[comp][vrow])
    keep = ((np.minimum.reduceat(gap, vstart) <= tol.contact)
            & (np.maximum.reduceat(gap, vstart) >= -tol.contact))
    main, comp, xy = main[keep], comp[keep], xy[..., keep]
    block_m, block_c = blocks.face_block[main], blocks.face_block[comp]
    normal_k, t1_k, t2_k = normal[main], t1[main], t2[main]

    is_support = blocks.block_is_support[block_m] | blocks.block_is_support[block_c]
    is_horizontal = np.abs(np.einsum("ij,ij->i", normal_k, up[block_m])) > np.cos(BED_JOINT_ANGLE)
    kind = np.select([is_support, is_horizontal],
                     [INTERFACE_KINDS.index("support"), INTERFACE_KINDS.index("horizontal")],
                     INTERFACE_KINDS.index("vertical")).astype(np.int8)
    interface_area, (x, y) = _area_centroid(xy)
    return Interfaces(
        pair=np.stack([block_m, block_c], axis=1),
        kind=kind,
        vertices=vertices[keep[vrow]],
        offsets=np.concatenate([[0], np.cumsum(count[keep])]),
        area=interface_area,
        centre=centre[main] + x[:, None] * t1_k + y[:, None] * t2_k,
        normal=normal_k,
        t1=t1_k,
        t2=t2_k,
    )


def _overlaps(blocks, main, comp, faces, tol):
    """The overlaps of face pairs ``main``, ``comp`` ((S,) int) in the main faces'
    ``(t1, t2)`` frames: the pairs kept, their polygons (2, W, S') and vertex counts."""
    normal, centre, area = blocks.face_normal, blocks.face_centre, blocks.face_area
    t1, t2 = blocks.face_basis
    n_m, n_c = normal[main], normal[comp]
    width = int(max(blocks.face_polygon_count[main].max(initial=1),
                    blocks.face_polygon_count[comp].max(initial=1)))
    xyz_m, xyz_c = faces.xyz[main, :width], faces.xyz[comp, :width]

    # gap closing (docs/model.md 5.3); faces whose wedge rotation would move no vertex farther
    # than tol.length count as parallel and are only projected (below)
    sin = np.linalg.norm(np.cross(n_m, n_c), axis=1)
    is_wedge = sin * faces.radius[comp] > tol.length
    xyz = _close_wedge(xyz_c, is_wedge, n_m, centre[main], n_c, centre[comp])

    # both polygons in the main face's (t1, t2) frame; the complementary face turns the
    # other way round there (its normal is -n), so it is reversed
    frame = np.stack([t1[main], t2[main]], axis=2)  # (S, 3, 2)
    comp_xy = _planar(xyz[:, ::-1], centre[main], frame)
    xy = _clip_convex(comp_xy, _planar(xyz_m, centre[main], frame), tol.length)
    keep = _area_centroid(xy)[0] > tol.min_area_rel * np.minimum(area[main], area[comp])
    main, comp = main[keep], comp[keep]
    xy, count = _clean(xy[..., keep], tol.length)
    keep = count >= 3  # a sliver may collapse
    return main[keep], comp[keep], xy[..., keep], count[keep]


def _width_classes(width):
    """Index arrays of the entries of ``width`` ((n,) int) in classes 1-4, 5-8, 9-16, ..."""
    level = np.ceil(np.log2(np.maximum(width, 4))).astype(int)
    return [np.flatnonzero(level == k) for k in np.unique(level)]


def _close_wedge(xyz, is_wedge, n_m, point_m, n_c, point_c):
    """Rotate complementary faces onto their main planes about the planes' common line.

    The axis is ``u = n_m x n_c / |n_m x n_c|`` through the point ``p0`` on both planes
    nearest to ``point_c``; the angle is the wedge angle ``theta`` between ``n_c`` and
    ``-n_m`` (Rodrigues' formula), which turns ``n_c`` into ``-n_m``, so the face lands
    in the main plane and its points on the common line stay put (thesis 3.2.4, step 5).

    Parameters
    ----------
    xyz : (m, W, 3) float
        Complementary faces (padded table rows).
    is_wedge : (m,) bool
        Faces to rotate; the others are returned unchanged.
    n_m, point_m, n_c, point_c : (m, 3) float
        Main and complementary planes (unit normal, a point on the plane).

    Returns
    -------
    (m, W, 3) float
    """
    xyz = xyz.copy()
    n_m, point_m, n_c, point_c = n_m[is_wedge], point_m[is_wedge], n_c[is_wedge], point_c[is_wedge]
    axis = np.cross(n_m, n_c)
    sin = np.linalg.norm(axis, axis=1)
    cos = -np.einsum("ij,ij->i", n_m, n_c)
    u = axis / sin[:, None]
    # p0 = point_c + a (n_c x u): on the complementary plane for every a, and on the
    # main plane for a = n_m . (point_m - point_c) / sin, since n_m . (n_c x u) = sin
    height = np.einsum("ij,ij->i", n_m, point_m - point_c)
    p0 = (point_c + (height / sin)[:, None] * np.cross(n_c, u))[:, None]
    # R = cos I + sin [u]x + (1 - cos) u u^T, applied to row vectors as v R^T
    ux, uy, uz = u.T
    zero = np.zeros_like(ux)
    rotation = (cos[:, None, None] * np.eye(3)
                + sin[:, None, None] * np.stack([np.stack([zero, -uz, uy], axis=1),
                                                 np.stack([uz, zero, -ux], axis=1),
                                                 np.stack([-uy, ux, zero], axis=1)], axis=1)
                + (1.0 - cos)[:, None, None] * u[:, :, None] * u[:, None, :])
    xyz[is_wedge] = p0 + (xyz[is_wedge] - p0) @ rotation.transpose(0, 2, 1)
    return xyz


# Planar polygons, one per face pair, are (2, W, S) float arrays: coordinate, vertex,
# pair (each coordinate of each vertex slot is one contiguous array over the pairs).
def _planar(xyz, origin, frame):
    """(2, W, S) float: padded 3D polygons ``xyz`` (S, W, 3) in the frames ``origin``
    (S, 3), ``frame`` (S, 3, 2) (columns ``t1, t2``)."""
    return ((xyz - origin[:, None]) @ frame).transpose(2, 1, 0).copy()


def _cross2(a, b):
    """z component of the cross product of 2D vectors, ``(2, ...) -> (...)``."""
    return a[0] * b[1] - a[1] * b[0]


def _norm2(a):
    """Length of 2D vectors, ``(2, ...) -> (...)``."""
    return np.sqrt(a[0] * a[0] + a[1] * a[1])


def _clip_convex(subject, clip, length):
    """Intersections of convex polygons, one pair per column (Sutherland-Hodgman).

    Clipping by each edge of ``clip`` in turn keeps the vertices on its inner side and
    adds the points where ``subject``'s edges cross it. ``subject`` is convex, so the
    vertices kept are one cyclic run, entered and left through at most one crossing
    each: the clipped polygon is the entry crossing, the run and the exit crossing,
    padded to one vertex more than before. Vertices within ``length`` of an edge's line
    count as on it (shared edges and corners are the rule in masonry): they are kept,
    and no crossing is made next to them, which would only duplicate them.

    Parameters
    ----------
    subject, clip : (2, W, S) float
        Convex counter-clockwise polygons; vertices may repeat.
    length : float
        Point-to-line distance below which a point is on the line.

    Returns
    -------
    (2, W + Wc, S) float
        Counter-clockwise, with repeated vertices (``Wc``: the vertex slots of ``clip``);
        a pair that does not overlap comes out as one point (zero area).
    """
    for e in range(clip.shape[1]):
        width = subject.shape[1]
        start = clip[:, e, None]
        edge = clip[:, (e + 1) % clip.shape[1], None] - start
        d = _cross2(edge, subject - start)  # (W, S): |edge| times the distance inwards
        on = length * _norm2(edge[:, 0])
        is_kept = d >= -on
        run = is_kept.sum(axis=0)
        first = np.argmax(is_kept & ~np.roll(is_kept, 1, axis=0), axis=0)  # 0: all kept
        last = (first + np.maximum(run, 1) - 1) % width
        slot = np.arange(width + 1)[:, None]
        out = _take(subject, (first + np.clip(slot - 1, 0, np.maximum(run, 1) - 1)) % width)
        entry = _crossing(subject, d, (first - 1) % width, first, on)
        out[:, 0] = np.where(np.isnan(entry), out[:, 0], entry)
        exit_ = _crossing(subject, d, last, (last + 1) % width, on)
        subject = np.where((slot > run) & ~np.isnan(exit_[:, None]), exit_[:, None], out)
    return subject


def _take(xy, index):
    """``xy[:, index[v, s], s]``: vertices ``index`` (V, S) or (S,) int of polygons
    ``xy`` (2, W, S) float."""
    if index.ndim == 1:
        return np.take_along_axis(xy, index[None, None], axis=1)[:, 0]
    return np.take_along_axis(xy, index[None], axis=1)


def _crossing(xy, d, i, j, on):
    """(2, S) float: where the edges ``i -> j`` ((S,) int) of polygons ``xy`` (2, W, S)
    cross the line that ``d`` (W, S) measures the distance to (NaN where they do not
    cross it by more than ``on`` (S,) on either side)."""
    d_i = np.take_along_axis(d, i[None], axis=0)[0]
    d_j = np.take_along_axis(d, j[None], axis=0)[0]
    is_crossing = ((d_i > on) & (d_j < -on)) | ((d_i < -on) & (d_j > on))
    t = np.where(is_crossing, d_i / np.where(is_crossing, d_i - d_j, 1.0), np.nan)
    p = _take(xy, i)
    return p + t * (_take(xy, j) - p)


def _clean(xy, length):
    """Drop repeated vertices and those within ``length`` of the line through their
    neighbours (collinear), least significant first, one per polygon and round.

    Parameters
    ----------
    xy : (2, W, S) float
        Convex polygons; vertices may repeat.

    Returns
    -------
    xy : (2, W', S) float
        Padded by repeating the last vertex.
    count : (S,) int
        Vertices of each polygon.
    """
    is_kept = _norm2(xy - np.roll(xy, -1, axis=1)) > length  # the last of repeats
    count = is_kept.sum(axis=0)
    xy = _pad(_take(xy, np.argsort(~is_kept, axis=0, kind="stable")), count)
    while xy.shape[2]:
        k = np.arange(xy.shape[1])[:, None]
        # neighbours in the padded layout; the last vertex's next one is the first
        prev = np.roll(xy, 1, axis=1)
        nxt = np.where(k == count - 1, xy[:, :1], np.roll(xy, -1, axis=1))
        chord = nxt - prev
        chord_length = _norm2(chord)
        distance = np.abs(_cross2(chord, xy - prev)) / np.maximum(chord_length, length)
        distance[k >= count] = np.inf
        worst = distance.argmin(axis=0)
        is_dropped = distance.min(axis=0) <= length
        if not is_dropped.any():
            break
        count = count - is_dropped
        index = np.where(is_dropped & (k >= worst), k + 1, k)
        xy = _pad(_take(xy, np.minimum(index, xy.shape[1] - 1)), count)
    return xy, count


def _pad(xy, count):
    """Polygons ``xy`` (2, W, S) float cut to their ``count`` (S,) int vertices, the
    last one repeated up to the largest count."""
    slot = np.arange(max(count.max(initial=0), 1))[:, None]
    return _take(xy, np.minimum(slot, np.maximum(count, 1) - 1))


def _area_centroid(xy):
    """Area (S,) float and centroid (2, S) float of polygons ((2, W, S) float,
    counter-clockwise, vertices may repeat), from the fan of triangles at each first
    vertex."""
    a = xy[:, 1:-1] - xy[:, :1]
    b = xy[:, 2:] - xy[:, :1]
    twice = _cross2(a, b)  # twice the triangles' areas
    area = 0.5 * twice.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):  # empty polygons
        centroid = xy[:, 0] + (twice * (a + b)).sum(axis=1) / (6 * area)
    return area, centroid
