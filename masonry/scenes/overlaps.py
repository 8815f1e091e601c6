"""Blocks of an imported assembly that interpenetrate, and how deep (docs/assemblies.md).

Overlapping solids are not a structure, so :func:`masonry.scenes.imported.load_assembly`
refuses blocks that interpenetrate by more than a fraction of the smaller one's size
(:data:`~masonry.tolerances.INTERPENETRATION_REL` unless the user accepts more). Some
models overlap by design: a dome whose courses are rings of flat-faced blocks, staggered
by half a block, has bed faces that are chords of its conical bed joints, so each block's
corners cut into the chord faces of the blocks above and below it by the chord's sagitta
(compas_assembly's sample dome, about 1% of a block).
"""

import numpy as np

from masonry.blocks import Blocks
from masonry.tolerances import INTERPENETRATION_REL, PARALLEL_SIN


def overlapping_pairs(blocks: Blocks, rel: float | None = None):
    """Pairs of convex blocks that interpenetrate by more than ``rel`` of the smaller
    one's size (its bounding box diagonal), and how deep.

    Decided by the separating axis theorem: pairs whose bounding boxes overlap are
    projected on the face normals of both blocks, all at once (blocks in contact are
    separated by their common face's normal); the few left are projected on the cross
    products of their edges too, which makes the test exact. The least overlap over
    these axes is the penetration depth: the shortest translation that parts the two.

    Parameters
    ----------
    blocks : Blocks
        Convex blocks (metres).
    rel : float, optional
        Default :data:`~masonry.tolerances.INTERPENETRATION_REL`.

    Returns
    -------
    pairs : (P, 2) int
        Block index pairs, lower index first, sorted.
    depth : (P,) float, metres
        Each pair's penetration depth.
    """
    if rel is None:
        rel = INTERPENETRATION_REL
    lo, hi = blocks.block_bounds[:, 0], blocks.block_bounds[:, 1]
    size = np.linalg.norm(hi - lo, axis=1)
    a, b = _box_pairs(lo, hi)
    least = rel * np.minimum(size[a], size[b])
    boxes = (np.minimum(hi[a], hi[b]) - np.maximum(lo[a], lo[b])).min(axis=1) > least
    a, b, least = a[boxes], b[boxes], least[boxes]
    points, normals = _padded(blocks)
    on_faces = np.zeros(len(a))
    chunk = 4096  # pairs at a time: bounded memory
    for start in range(0, len(a), chunk):
        i, j = a[start:start + chunk], b[start:start + chunk]
        axes = np.concatenate([normals[i], normals[j]], axis=1)
        pa = np.einsum("pvk,pfk->pvf", points[i], axes)
        pb = np.einsum("pvk,pfk->pvf", points[j], axes)
        overlap = np.minimum(pa.max(axis=1) - pb.min(axis=1), pb.max(axis=1) - pa.min(axis=1))
        on_faces[start:start + chunk] = overlap.min(axis=1)
    deep = on_faces > least
    found = {}
    for i, j, d, f in zip(a[deep], b[deep], least[deep], on_faces[deep]):
        depth = min(float(f), _overlap_on_edge_axes(blocks, i, j))
        if depth > d:
            found[(min(i, j), max(i, j))] = depth
    pairs = sorted(found)
    return (np.array(pairs, int).reshape(-1, 2),
            np.array([found[p] for p in pairs], float))


def _box_pairs(lo, hi):
    """Index pairs ``(a, b)`` of boxes whose x ranges overlap (a sweep along x)."""
    n = len(lo)
    order = np.argsort(lo[:, 0], kind="stable")
    start = lo[order, 0]
    end = np.searchsorted(start, hi[order, 0], side="left")
    counts = np.maximum(end - np.arange(n) - 1, 0)
    first = np.repeat(np.arange(n), counts)
    offset = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return order[first], order[first + 1 + offset]


def _padded(blocks: Blocks):
    """``(B, V, 3)`` vertices and ``(B, F, 3)`` face normals per block, each padded with
    its block's first one (which changes no projection's range)."""
    vertex_counts = np.diff(blocks.vertex_offsets)
    rank = np.arange(len(blocks.vertices)) - np.repeat(blocks.vertex_offsets[:-1],
                                                       vertex_counts)
    points = np.repeat(blocks.vertices[blocks.vertex_offsets[:-1], None, :],
                       vertex_counts.max(), axis=1)
    points[np.repeat(np.arange(blocks.n_blocks), vertex_counts), rank] = blocks.vertices
    face_counts = np.bincount(blocks.face_block, minlength=blocks.n_blocks)
    first_face = np.concatenate([[0], np.cumsum(face_counts)[:-1]])
    rank = np.arange(blocks.n_faces) - first_face[blocks.face_block]
    normals = np.repeat(blocks.face_normal[first_face, None, :], face_counts.max(), axis=1)
    normals[blocks.face_block, rank] = blocks.face_normal
    return points, normals


def _overlap_on_edge_axes(blocks: Blocks, a: int, b: int) -> float:
    """Smallest overlap of two blocks along the cross products of their edges."""
    edges_a, edges_b = _block_edges(blocks, a), _block_edges(blocks, b)
    cross = np.cross(edges_a[:, None, :], edges_b[None, :, :]).reshape(-1, 3)
    length = np.linalg.norm(cross, axis=1)
    axes = cross[length > PARALLEL_SIN] / length[length > PARALLEL_SIN, None]
    if len(axes) == 0:
        return np.inf
    pa, pb = blocks.block_vertices(a) @ axes.T, blocks.block_vertices(b) @ axes.T
    return float(np.minimum(pa.max(axis=0) - pb.min(axis=0),
                            pb.max(axis=0) - pa.min(axis=0)).min())


def _block_edges(blocks: Blocks, block: int) -> np.ndarray:
    """(E, 3) unit edge directions of one block (each edge once per face using it)."""
    edges = []
    for face in blocks.block_faces(block):
        polygon = blocks.face_polygon(face)
        edges.append(np.roll(polygon, -1, axis=0) - polygon)
    edges = np.vstack(edges)
    length = np.linalg.norm(edges, axis=1)
    return edges[length > 0] / length[length > 0, None]
