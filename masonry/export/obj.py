"""Wavefront OBJ of blocks: one named object per block (Rhino, trimesh, Blender)."""

import io

import numpy as np

from ..blocks import Blocks


def blocks_obj(blocks: Blocks, vertices=None) -> bytes:
    """OBJ text with ``o <block name>`` per block and its polygon faces.

    Parameters
    ----------
    blocks : Blocks
    vertices : (V, 3) float, optional
        Vertex positions to write instead of ``blocks.vertices`` (e.g. CAD-offset ones).
    """
    vertices = blocks.vertices if vertices is None else vertices
    out = io.StringIO()
    out.write("# masonry blocks: one object per block, metres, z up\n")
    counts = blocks.face_polygon_count
    face_starts = blocks.face_offsets[:-1]
    faces_of = np.split(np.arange(blocks.n_faces), np.searchsorted(
        blocks.face_block, np.arange(1, blocks.n_blocks)))
    for i in range(blocks.n_blocks):
        lo, hi = blocks.vertex_offsets[i], blocks.vertex_offsets[i + 1]
        out.write(f"o {blocks.block_name[i]}\n")
        np.savetxt(out, vertices[lo:hi], fmt="v %.12g %.12g %.12g")
        for f in faces_of[i]:
            ids = blocks.face_vertices[face_starts[f]:face_starts[f] + counts[f]] + 1
            out.write("f " + " ".join(map(str, ids)) + "\n")
    return out.getvalue().encode()
