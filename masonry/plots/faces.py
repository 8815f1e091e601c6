"""The polygons a figure draws, as arrays: block faces and interfaces padded to one
vertex count (the last vertex repeated), so that matplotlib takes its fast path for
thousands of them; the faces hidden inside the structure (covered by the interfaces
between two drawn blocks) and those turned away from the viewer left out.

Blocks are convex and closed: a face whose outward normal points away from the viewer
lies behind its own block's other faces, and a face covered by a neighbour's touching
face is never seen. Leaving both out draws what the full set draws, in a fraction of
the time.
"""

import numpy as np

COVERED = 1.0 - 1e-6
"""A face is hidden when the interfaces on it cover at least this fraction of its
area."""

AWAY = -0.15
"""A face is turned away from a 3D view's camera when its unit normal's component along
the direction toward the camera is below this (the perspective's rays spread a few
degrees about that direction: faces near edge on are kept)."""


def padded(vertices, offsets, index) -> np.ndarray:
    """(n, m, 3) float: polygons ``index`` of a flat vertex list (polygon ``k`` is
    ``vertices[offsets[k]:offsets[k + 1]]``), each padded to the longest's ``m`` vertices
    by repeating its last."""
    index = np.asarray(index, dtype=int)
    if len(index) == 0:
        return np.zeros((0, 3, 3))
    start, count = offsets[index], offsets[index + 1] - offsets[index]
    corner = np.minimum(np.arange(int(count.max())), count[:, None] - 1)
    return vertices[start[:, None] + corner]


def face_array(blocks, faces) -> np.ndarray:
    """(n, m, 3) the polygons of ``blocks``' faces ``faces`` (:func:`padded`)."""
    return padded(blocks.vertices[blocks.face_vertices], blocks.face_offsets, faces)


def interface_array(interfaces, index) -> np.ndarray:
    """(n, m, 3) the polygons of the interfaces ``index`` (:func:`padded`)."""
    return padded(interfaces.vertices, interfaces.offsets, index)


def _face_on(blocks, block, normal, centre) -> np.ndarray:
    """(K,) int: the face of each ``block`` that lies in the plane through ``centre``
    with outward ``normal`` (the touching face of a convex block); -1 where none does."""
    order = np.argsort(blocks.face_block, kind="stable")
    first = np.searchsorted(blocks.face_block[order], np.arange(blocks.n_blocks + 1))
    count = np.diff(first)[block]
    slot = np.minimum(np.arange(int(count.max(initial=1))), np.maximum(count, 1)[:, None] - 1)
    candidate = order[np.minimum(first[block][:, None] + slot, len(order) - 1)]
    n = blocks.face_normal[candidate]
    along = np.einsum("kfi,ki->kf", n, normal)
    gap = np.abs(np.einsum("kfi,kfi->kf", n, centre[:, None] - blocks.face_centre[candidate]))
    size = np.sqrt(blocks.face_area[candidate])
    along[(count[:, None] == 0) | (gap > 1e-3 * size)] = -np.inf
    best = np.argmax(along, axis=1)
    found = along[np.arange(len(block)), best] > 0.999
    return np.where(found, candidate[np.arange(len(block)), best], -1)


def hidden_faces(blocks, interfaces, drawn=None, images=False) -> np.ndarray:
    """(F,) bool: the faces of ``blocks`` covered by interfaces between two drawn blocks.

    Parameters
    ----------
    blocks : Blocks
    interfaces : Interfaces or None
        Of a model whose first blocks are ``blocks`` (None: nothing is hidden).
    drawn : (B,) bool, optional
        The blocks drawn (default all): a face touching one not drawn is seen.
    images : bool
        An interface whose other block lies beyond ``blocks`` (a neighbour web's image)
        covers its face too: the section drawn with its neighbours (the whole dome).
    """
    covered = np.zeros(blocks.n_faces)
    if interfaces is None or len(interfaces) == 0:
        return covered > 0
    n = blocks.n_blocks
    drawn = np.append(np.ones(n, bool) if drawn is None else np.asarray(drawn, bool), images)
    pair = np.minimum(interfaces.pair, n)  # every image stands for the others
    both = drawn[pair].all(axis=1)
    for side, sign in ((0, 1.0), (1, -1.0)):
        on = both & (pair[:, side] < n)
        face = _face_on(blocks, pair[on, side], sign * interfaces.normal[on],
                        interfaces.centre[on])
        np.add.at(covered, face[face >= 0], interfaces.area[on][face >= 0])
    return covered >= COVERED * blocks.face_area


def facing(normals, toward, limit=0.0) -> np.ndarray:
    """(n,) bool: faces whose unit ``normals`` point toward the viewer (``toward``, a unit
    (3,)) by more than ``limit``."""
    return np.asarray(normals) @ toward > limit
