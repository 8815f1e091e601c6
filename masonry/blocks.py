"""Blocks as arrays: convex polyhedra with planar faces (docs/model.md 4.5).

A :class:`Blocks` is a struct of arrays. Vertices and faces of all blocks are stored flat,
with offsets (as meshio stores cells), so a scene of 10,000 bricks is a handful of numpy
arrays, not 60,000 Python objects. Derived quantities (face normals, volumes, centroids)
are computed once on first use and cached.

Glossary
--------
- main face / complementary face: thesis 3.2.4; the interface detector's words.
- ``t1, t2``: in-plane basis of a face; ``(t1, t2, normal)`` is right-handed.
"""

import dataclasses
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from masonry.tolerances import COLLINEAR_SIN, HORIZONTAL_SIN, TIE_REL

BLOCK_CLASSES = ("ground", "regular", "pattern", "fill_in", "block")
"""Names of the ``block_class`` codes. ``block`` is an imported or scene block (arch)."""

CLASS_COLOURS = {
    "ground": "#9e9e9e",
    "regular": "#e8d5b0",
    "pattern": "#0072b2",
    "fill_in": "#e69f00",
    "block": "#c9b79c",
}
"""The colour of each block class in the figures and ``dome.html`` (Okabe and Ito's
colour-blind safe blue and orange for the pattern and fill-in bricks); no other concept of
a figure takes these (:mod:`masonry.plots.colours`, docs/outputs.md)."""

GROUND = BLOCK_CLASSES.index("ground")
"""``block_class`` code of a ground slab or support block."""

PATTERN = BLOCK_CLASSES.index("pattern")
"""``block_class`` code of a pattern (herringbone) brick, two courses high."""

BLOCK = BLOCK_CLASSES.index("block")
"""``block_class`` code of an imported or scene block (an arch's voussoir)."""

# Corner order of a hexahedral brick: index = ix + 2 * iy + 4 * iz, with local axes
# x = through the wall (0 inner, 1 outer), y = along the wall, z = up the course.
HEX_FACES = np.array(
    [
        [0, 4, 6, 2],  # inner (intrados)
        [1, 3, 7, 5],  # outer
        [0, 1, 5, 4],  # -y end
        [2, 6, 7, 3],  # +y end
        [0, 2, 3, 1],  # bottom
        [4, 5, 7, 6],  # top
    ]
)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def tangent_basis(normal, reference=None):
    """In-plane basis for unit normals.

    ``t1`` is horizontal (``z x n``) where the face is not horizontal; on a horizontal
    face it is ``reference`` projected into the plane (a direction of the face's own, so
    the basis turns with the model), or the x axis without one; ``t2 = n x t1``. The
    basis is the frame of the friction components in the results; the pyramids of
    :mod:`masonry.friction` are aligned with it: a global x axis on the ground slabs of a
    full dome would align the pyramids of some webs with their web and turn those of
    others by 2 pi/n, and the dome would lose its rotational symmetry (Coulomb's cone
    does not depend on the basis).

    Parameters
    ----------
    normal : (k, 3) float
    reference : (k, 3) float, optional
        In-plane direction for horizontal faces (e.g. the face's longest edge).

    Returns
    -------
    t1, t2 : (k, 3) float
    """
    normal = np.asarray(normal, dtype=float).reshape(-1, 3)
    t1 = np.cross(np.array([0.0, 0.0, 1.0]), normal)
    flat = np.linalg.norm(t1, axis=1) < HORIZONTAL_SIN
    ref = (np.broadcast_to([1.0, 0.0, 0.0], normal.shape) if reference is None
           else np.asarray(reference, dtype=float).reshape(-1, 3))[flat]
    t1[flat] = ref - normal[flat] * np.einsum("ij,ij->i", normal[flat], ref)[:, None]
    t1 = _unit(t1)
    t2 = np.cross(normal, t1)
    return t1, t2


@dataclass(frozen=True, eq=False)
class Blocks:
    """Convex blocks with planar polygonal faces.

    Parameters
    ----------
    vertices : (V, 3) float, metres
        Vertices of all blocks, block after block.
    vertex_offsets : (B + 1,) int
        Block ``i`` owns ``vertices[vertex_offsets[i]:vertex_offsets[i + 1]]``.
    face_vertices : (FV,) int
        Global vertex indices of every face polygon, counter-clockwise seen from outside.
    face_offsets : (F + 1,) int
        Face ``f`` is ``face_vertices[face_offsets[f]:face_offsets[f + 1]]``.
    face_block : (F,) int
        Owner block of every face.
    block_class : (B,) int8
        Code into :data:`BLOCK_CLASSES`.
    block_course : (B,) int
        Course index (1 = first course on the ground, 0 = ground or not in a course).
    block_is_support : (B,) bool
        Fixed supports (the ground): no equilibrium rows.
    block_name : (B,) str
        Unique names, e.g. ``b0042_regular_c12``.
    block_web : (B,) int
        Web index in a full dome (0 in a section).
    """

    vertices: np.ndarray
    vertex_offsets: np.ndarray
    face_vertices: np.ndarray
    face_offsets: np.ndarray
    face_block: np.ndarray
    block_class: np.ndarray
    block_course: np.ndarray
    block_is_support: np.ndarray
    block_name: np.ndarray
    block_web: np.ndarray

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_hexahedra(cls, corners, block_class, block_course=None, block_is_support=None,
                       block_name=None, block_web=None):
        """Blocks from hexahedra with corners in the :data:`HEX_FACES` order.

        Parameters
        ----------
        corners : (B, 8, 3) float, metres
            Corner ``ix + 2 iy + 4 iz`` of each block (see :data:`HEX_FACES`). Faces must
            be planar (boxes, and boxes clipped by planes through whole edges, are).
        block_class : (B,) int or str
        """
        corners = np.asarray(corners, dtype=float)
        count = len(corners)
        face_vertices = (HEX_FACES[None, :, :] + 8 * np.arange(count)[:, None, None])
        # orient every face outward, whatever the handedness of the corner frame
        vertices = corners.reshape(-1, 3)
        quads = vertices[face_vertices]  # (B, 6, 4, 3)
        normal = _newell(quads.reshape(-1, 4, 3)).reshape(count, 6, 3)
        outward = quads.mean(axis=2) - corners.mean(axis=1)[:, None, :]
        flip = np.einsum("bfk,bfk->bf", normal, outward) < 0
        face_vertices[flip] = face_vertices[flip][:, ::-1]
        return cls.from_arrays(
            vertices=vertices,
            vertex_offsets=np.arange(count + 1) * 8,
            face_vertices=face_vertices.reshape(-1),
            face_offsets=np.arange(count * 6 + 1) * 4,
            face_block=np.repeat(np.arange(count), 6),
            block_class=block_class,
            block_course=block_course,
            block_is_support=block_is_support,
            block_name=block_name,
            block_web=block_web,
        )

    @classmethod
    def from_arrays(cls, vertices, vertex_offsets, face_vertices, face_offsets, face_block,
                    block_class, block_course=None, block_is_support=None, block_name=None,
                    block_web=None):
        """Blocks from flat arrays, filling defaults for the optional per-block fields."""
        count = len(vertex_offsets) - 1
        block_class = np.broadcast_to(np.asarray(block_class), (count,))
        if block_class.dtype.kind in "US":
            block_class = np.array([BLOCK_CLASSES.index(c) for c in block_class])
        block_class = block_class.astype(np.int8)
        block_course = (np.zeros(count, int) if block_course is None
                        else np.asarray(block_course, dtype=int))
        block_is_support = (block_class == GROUND
                            if block_is_support is None
                            else np.asarray(block_is_support, dtype=bool))
        block_web = np.zeros(count, int) if block_web is None else np.asarray(block_web, int)
        if block_name is None:
            block_name = [
                f"b{i:04d}_{BLOCK_CLASSES[k]}_c{c}"
                for i, (k, c) in enumerate(zip(block_class, block_course))
            ]
        return cls(
            vertices=np.ascontiguousarray(vertices, dtype=float),
            vertex_offsets=np.asarray(vertex_offsets, dtype=np.int64),
            face_vertices=np.asarray(face_vertices, dtype=np.int64),
            face_offsets=np.asarray(face_offsets, dtype=np.int64),
            face_block=np.asarray(face_block, dtype=np.int64),
            block_class=block_class,
            block_course=block_course,
            block_is_support=block_is_support,
            block_name=np.asarray(block_name, dtype=object),
            block_web=block_web,
        )

    # ------------------------------------------------------------------ sizes
    @property
    def n_blocks(self) -> int:
        return len(self.vertex_offsets) - 1

    @property
    def n_faces(self) -> int:
        return len(self.face_offsets) - 1

    def __len__(self) -> int:
        return self.n_blocks

    # ------------------------------------------------------------------ derived, cached
    @cached_property
    def face_polygon_count(self) -> np.ndarray:
        """(F,) int: vertices per face."""
        return np.diff(self.face_offsets)

    @cached_property
    def triangles(self) -> np.ndarray:
        """(T, 3) int global vertex indices: every face fanned from its first vertex."""
        counts = self.face_polygon_count - 2
        face = np.repeat(np.arange(self.n_faces), counts)
        k = np.arange(len(face)) - np.repeat(np.cumsum(counts) - counts, counts)
        start = self.face_offsets[face]
        fv = self.face_vertices
        return np.stack([fv[start], fv[start + k + 1], fv[start + k + 2]], axis=1)

    @cached_property
    def triangle_face(self) -> np.ndarray:
        """(T,) int: face of every triangle in :attr:`triangles`."""
        return np.repeat(np.arange(self.n_faces), self.face_polygon_count - 2)

    @cached_property
    def _face_area_vectors(self) -> np.ndarray:
        tri = self.vertices[self.triangles]
        cross = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        return _sum_by(self.triangle_face, cross, self.n_faces)

    @cached_property
    def face_area(self) -> np.ndarray:
        """(F,) float, m^2."""
        return np.linalg.norm(self._face_area_vectors, axis=1)

    @cached_property
    def face_normal(self) -> np.ndarray:
        """(F, 3) float: outward unit normals."""
        return self._face_area_vectors / self.face_area[:, None]

    @cached_property
    def face_centre(self) -> np.ndarray:
        """(F, 3) float: area centroid of each face polygon, metres."""
        tri = self.vertices[self.triangles]
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                    axis=1)
        out = _sum_by(self.triangle_face, tri.mean(axis=1) * area[:, None], self.n_faces)
        weight = np.bincount(self.triangle_face, area, minlength=self.n_faces)
        return out / weight[:, None]

    @cached_property
    def face_longest_edge(self) -> np.ndarray:
        """(F, 3) float: the longest edge vector of every face polygon."""
        fv = self.face_vertices
        nxt = np.arange(len(fv)) + 1
        ends = self.face_offsets[1:] - 1
        nxt[ends] = self.face_offsets[:-1]  # close every polygon
        edge = self.vertices[fv[nxt]] - self.vertices[fv]
        length = np.linalg.norm(edge, axis=1)
        owner = np.repeat(np.arange(self.n_faces), self.face_polygon_count)
        # the first edge of maximal length (up to rounding) in each face
        longest = np.maximum.reduceat(length, self.face_offsets[:-1])
        is_longest = length >= longest[owner] * (1 - TIE_REL)
        first = np.full(self.n_faces, len(fv))
        np.minimum.at(first, owner[is_longest], np.flatnonzero(is_longest))
        return edge[first]

    @cached_property
    def face_basis(self) -> tuple:
        """``(t1, t2)``, each (F, 3) float: in-plane basis of every face (horizontal faces
        take ``t1`` along their longest edge, see :func:`tangent_basis`)."""
        return tangent_basis(self.face_normal, self.face_longest_edge)

    @cached_property
    def block_vertex_mean(self) -> np.ndarray:
        """(B, 3) float: mean of each block's vertices (a point inside a convex block)."""
        counts = np.diff(self.vertex_offsets)
        owner = np.repeat(np.arange(self.n_blocks), counts)
        return _sum_by(owner, self.vertices, self.n_blocks) / counts[:, None]

    @cached_property
    def _volume_moments(self) -> tuple:
        # divergence theorem on tetrahedra (reference point, triangle); the reference is
        # inside the block, which keeps the sum free of cancellation
        tri_block = self.face_block[self.triangle_face]
        ref = self.block_vertex_mean[tri_block]
        tri = self.vertices[self.triangles]
        a, b, c = tri[:, 0] - ref, tri[:, 1] - ref, tri[:, 2] - ref
        vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
        volume = np.bincount(tri_block, vol, minlength=self.n_blocks)
        moment = _sum_by(tri_block, vol[:, None] * (ref + (a + b + c) / 4.0), self.n_blocks)
        return volume, moment

    @cached_property
    def block_volume(self) -> np.ndarray:
        """(B,) float, m^3."""
        return self._volume_moments[0]

    @cached_property
    def block_centroid(self) -> np.ndarray:
        """(B, 3) float: centre of mass of each block (uniform density), metres."""
        volume, moment = self._volume_moments
        return moment / volume[:, None]

    @cached_property
    def block_bounds(self) -> np.ndarray:
        """(B, 2, 3) float: axis-aligned bounding box (min, max) of each block."""
        counts = np.diff(self.vertex_offsets)
        starts = self.vertex_offsets[:-1]
        lo = np.minimum.reduceat(self.vertices, starts, axis=0)
        hi = np.maximum.reduceat(self.vertices, starts, axis=0)
        lo[counts == 0] = np.nan
        return np.stack([lo, hi], axis=1)

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) float: bounding box of the whole scene."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def face_polygon(self, face: int) -> np.ndarray:
        """(k, 3) float: vertices of one face, counter-clockwise seen from outside."""
        start, stop = self.face_offsets[face], self.face_offsets[face + 1]
        return self.vertices[self.face_vertices[start:stop]]

    @cached_property
    def block_face_offsets(self) -> np.ndarray:
        """(B + 1,) int: block ``i`` owns faces ``block_face_offsets[i]`` to
        ``block_face_offsets[i + 1]`` (faces are stored block after block)."""
        return np.searchsorted(self.face_block, np.arange(self.n_blocks + 1))

    def block_faces(self, block: int) -> np.ndarray:
        """Face indices of one block (faces are stored block after block)."""
        return np.flatnonzero(self.face_block == block)

    def block_vertices(self, block: int) -> np.ndarray:
        return self.vertices[self.vertex_offsets[block]:self.vertex_offsets[block + 1]]

    # ------------------------------------------------------------------ trimesh
    def meshes(self):
        """One ``trimesh.Trimesh`` per block, built from the arrays (no hull, no processing)."""
        import trimesh

        tri_block = self.face_block[self.triangle_face]
        order = np.argsort(tri_block, kind="stable")
        tris = self.triangles[order]
        splits = np.searchsorted(tri_block[order], np.arange(1, self.n_blocks))
        out = []
        for i, faces in enumerate(np.split(tris, splits)):
            lo, hi = self.vertex_offsets[i], self.vertex_offsets[i + 1]
            out.append(trimesh.Trimesh(self.vertices[lo:hi], faces - lo, process=False))
        return out

    def subset(self, mask) -> "Blocks":
        """The blocks selected by a boolean mask or index array, in their order."""
        index = np.arange(self.n_blocks)[mask]
        vcount = np.diff(self.vertex_offsets)[index]
        vsel = np.concatenate([np.arange(self.vertex_offsets[i], self.vertex_offsets[i + 1])
                               for i in index]) if len(index) else np.zeros(0, int)
        remap = np.full(len(self.vertices), -1)
        remap[vsel] = np.arange(len(vsel))
        fsel = np.flatnonzero(np.isin(self.face_block, index))
        fcount = self.face_polygon_count[fsel]
        fv = np.concatenate([self.face_vertices[self.face_offsets[f]:self.face_offsets[f + 1]]
                             for f in fsel]) if len(fsel) else np.zeros(0, int)
        block_remap = np.full(self.n_blocks, -1)
        block_remap[index] = np.arange(len(index))
        return Blocks(
            vertices=self.vertices[vsel],
            vertex_offsets=np.concatenate([[0], np.cumsum(vcount)]),
            face_vertices=remap[fv],
            face_offsets=np.concatenate([[0], np.cumsum(fcount)]),
            face_block=block_remap[self.face_block[fsel]],
            block_class=self.block_class[index],
            block_course=self.block_course[index],
            block_is_support=self.block_is_support[index],
            block_name=self.block_name[index],
            block_web=self.block_web[index],
        )

    def transformed(self, matrix) -> "Blocks":
        """A copy moved by a 4x4 rigid transform (faces keep their orientation)."""
        matrix = np.asarray(matrix, dtype=float)
        vertices = self.vertices @ matrix[:3, :3].T + matrix[:3, 3]
        return dataclasses.replace(self, vertices=vertices)


MASK_BITS = 62
"""Most points whose subsets are kept as the bits of one int64 (a face's points in
:func:`hull_faces` and :func:`masonry.scenes.imported._own_faces`); more take a byte
string there, and qhull here."""


def hull_faces(points, hull, distance):
    """Planar faces of a convex hull: ``(face_of_entry, point_of_entry, normal)``.

    The points within ``distance`` of a hull triangle's plane form that triangle's face;
    triangles with the same point set are one face (qhull's own merged facets, and
    facets that rounding split). Returns, per (face, point) entry, the face index and the
    point index ((e,) int each, by face), and (F, 3) outward unit normals.
    """
    normal, offset = hull.equations[:, :3], hull.equations[:, 3]
    # only the hull's vertices: a point inside a face (a T-junction) is no corner
    corner = hull.vertices
    on = np.abs(normal @ points[corner].T + offset[:, None]) <= distance  # (T, n)
    if on.shape[1] <= MASK_BITS:
        key = on @ (np.int64(1) << np.arange(on.shape[1], dtype=np.int64))
    else:
        key = np.packbits(on, axis=1).view(f"V{(on.shape[1] + 7) // 8}").reshape(-1)
    _, first = np.unique(key, return_index=True)
    entry_face, entry_corner = np.nonzero(on[first])
    return entry_face, corner[entry_corner], normal[first]


def blocks_from_hulls(hull_points, faces, block_class, block_name, **fields) -> Blocks:
    """Convex :class:`Blocks` from per-block hull faces (:func:`hull_faces`): every
    face's points ordered counter-clockwise about its outward normal, collinear points
    dropped (vectorized over all faces of all blocks).

    Parameters
    ----------
    hull_points : list of (n, 3) float
        Each block's points.
    faces : list of tuple
        Each block's :func:`hull_faces`.
    block_class, block_name, **fields
        As :meth:`Blocks.from_arrays` takes them (``block_name`` is a list).

    Raises
    ------
    ValueError
        A face collapses to a line (a degenerate block), naming the block.
    """
    names = block_name
    hull_faces = faces
    count_blocks = len(hull_points)
    point_base = np.cumsum([0] + [len(p) for p in hull_points])
    face_base = np.cumsum([0] + [len(f[2]) for f in hull_faces])
    points = np.concatenate(hull_points)
    entry_face = np.concatenate([f[0] + face_base[b] for b, f in enumerate(hull_faces)])
    entry_point = np.concatenate([f[1] + point_base[b] for b, f in enumerate(hull_faces)])
    normal = np.concatenate([f[2] for f in hull_faces])
    face_block = np.repeat(np.arange(count_blocks), np.diff(face_base))

    # counter-clockwise about the outward normal: angle in the face's (t1, t2) basis
    t1, t2 = tangent_basis(normal)
    n_faces = len(normal)
    centre = np.zeros((n_faces, 3))
    np.add.at(centre, entry_face, points[entry_point])
    centre /= np.bincount(entry_face, minlength=n_faces)[:, None]
    arm = points[entry_point] - centre[entry_face]
    angle = np.arctan2(np.einsum("ij,ij->i", arm, t2[entry_face]),
                       np.einsum("ij,ij->i", arm, t1[entry_face]))
    order = np.lexsort((angle, entry_face))
    entry_face, entry_point = entry_face[order], entry_point[order]
    # drop points where the ring goes straight on (they lie inside an edge of the block
    # and are dropped from both faces of that edge alike) or turns back (a point inside
    # the face); repeat, as a point inside the face can hide a straight neighbour
    while True:
        count = np.bincount(entry_face, minlength=n_faces)
        start = np.cumsum(count) - count
        k = np.arange(len(entry_face)) - start[entry_face]
        prev = start[entry_face] + (k - 1) % count[entry_face]
        nxt = start[entry_face] + (k + 1) % count[entry_face]
        p = points[entry_point]
        a, b = p - p[prev], p[nxt] - p
        turn = np.einsum("ij,ij->i", np.cross(a, b), normal[entry_face])
        scale = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
        straight = turn <= COLLINEAR_SIN * scale
        if not straight.any():
            break
        entry_face, entry_point = entry_face[~straight], entry_point[~straight]
    count = np.bincount(entry_face, minlength=n_faces)
    if (count < 3).any():
        bad = int(face_block[np.flatnonzero(count < 3)[0]])
        raise ValueError(f"block {bad if names is None else names[bad]!r}: a face of its "
                         "convex hull collapses to "
                         "a line; the block is degenerate")
    # keep only points used by a face, block after block
    used, face_vertices = np.unique(entry_point, return_inverse=True)
    point_block = np.repeat(np.arange(count_blocks), np.diff(point_base))
    vertex_offsets = np.searchsorted(point_block[used], np.arange(count_blocks + 1))
    return Blocks.from_arrays(
        vertices=points[used], vertex_offsets=vertex_offsets,
        face_vertices=face_vertices.reshape(-1),
        face_offsets=np.concatenate([[0], np.cumsum(count)]), face_block=face_block,
        block_class=block_class, block_name=names, **fields)


def concatenate(parts) -> Blocks:
    """One :class:`Blocks` from several, in order."""
    parts = list(parts)
    vbase = np.cumsum([0] + [len(p.vertices) for p in parts])
    fvbase = np.cumsum([0] + [len(p.face_vertices) for p in parts])
    bbase = np.cumsum([0] + [p.n_blocks for p in parts])
    return Blocks(
        vertices=np.concatenate([p.vertices for p in parts]),
        vertex_offsets=np.concatenate(
            [[0]] + [p.vertex_offsets[1:] + vbase[i] for i, p in enumerate(parts)]),
        face_vertices=np.concatenate([p.face_vertices + vbase[i] for i, p in enumerate(parts)]),
        face_offsets=np.concatenate(
            [[0]] + [p.face_offsets[1:] + fvbase[i] for i, p in enumerate(parts)]),
        face_block=np.concatenate([p.face_block + bbase[i] for i, p in enumerate(parts)]),
        block_class=np.concatenate([p.block_class for p in parts]),
        block_course=np.concatenate([p.block_course for p in parts]),
        block_is_support=np.concatenate([p.block_is_support for p in parts]),
        block_name=np.concatenate([p.block_name for p in parts]),
        block_web=np.concatenate([p.block_web for p in parts]),
    )


def rotation_z(angle) -> np.ndarray:
    """(3, 3) rotation by ``angle`` radians about the dome axis (z)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def web_motion(web: int, n: int) -> np.ndarray:
    """(4, 4) motion that turns web 0 of ``n`` equal webs to web ``web``'s place: a
    rotation by ``2 pi web / n`` about z."""
    motion = np.eye(4)
    motion[:3, :3] = rotation_z(2 * np.pi * web / n)
    return motion


def web_name(web: int) -> str:
    """``w<web>``: what the names of web ``web``'s turned blocks start with
    (:func:`rotated_web`), and a 3DM file's name of that turned web."""
    return f"w{web}"


def rotated_web(blocks: Blocks, web: int, n: int, mask=None) -> Blocks:
    """Blocks (or those selected by ``mask``, (B,) bool) rotated by ``2 pi web / n`` about
    z (:func:`web_motion`), named ``w<web>_<name>`` and marked as web ``web % n``."""
    part = blocks if mask is None else blocks.subset(mask)
    part = part.transformed(web_motion(web, n))
    return dataclasses.replace(
        part,
        block_name=np.array([f"{web_name(web % n)}_{name}" for name in part.block_name],
                            dtype=object),
        block_web=np.full(part.n_blocks, web % n))


def whole_of_web(blocks: Blocks, n: int, rename_first=False) -> Blocks:
    """The whole dome that ``blocks`` (web 0 of ``n`` equal webs) stand for: them, then
    their ``n - 1`` rotations about z (:func:`rotated_web`, named ``w<web>_<name>``), so
    that every name is unique. Web 0 keeps its names (the names its analysis reports)
    unless ``rename_first``, which names it ``w0_<name>`` as the others."""
    first = rotated_web(blocks, 0, n) if rename_first else blocks
    return concatenate([first] + [rotated_web(blocks, web, n) for web in range(1, n)])


def _newell(polygons):
    """(k, m, 3) polygons -> (k, 3) Newell normals (area-weighted, not normalised)."""
    nxt = np.roll(polygons, -1, axis=1)
    return 0.5 * np.cross(polygons, nxt).sum(axis=1)


def _sum_by(index, values, n) -> np.ndarray:
    """(n, C) float: ``out[i]`` is the sum of the rows of ``values`` (N, C) whose ``index``
    is ``i``; ``np.add.at`` in the same order, one bincount per column (faster: docs/bench.md,
    "Measurements behind design choices")."""
    return np.stack([np.bincount(index, column, minlength=n) for column in values.T], axis=1)
