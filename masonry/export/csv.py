"""CSV tables: brick vertex locations (SPEC 7)."""

import io

import numpy as np

from ..blocks import BLOCK_CLASSES, Blocks


def locations_csv(blocks: Blocks, vertices=None) -> bytes:
    """``locations.csv``: one row per block vertex (brick id, name, class, course, vertex
    index, x, y, z in metres).

    Parameters
    ----------
    vertices : (V, 3) float, optional
        Positions to write instead of ``blocks.vertices`` (the CAD-offset ones, SPEC 7).
    """
    vertices = blocks.vertices if vertices is None else vertices
    counts = np.diff(blocks.vertex_offsets)
    owner = np.repeat(np.arange(blocks.n_blocks), counts)
    local = np.arange(len(owner)) - np.repeat(blocks.vertex_offsets[:-1], counts)
    classes = np.array(BLOCK_CLASSES, dtype=object)[blocks.block_class][owner]
    out = io.StringIO()
    out.write("brick,name,class,course,vertex,x,y,z\n")
    for b, name, klass, course, v, (x, y, z) in zip(
            owner, blocks.block_name[owner], classes, blocks.block_course[owner], local,
            vertices):
        out.write(f"{b},{name},{klass},{course},{v},{x:.12g},{y:.12g},{z:.12g}\n")
    return out.getvalue().encode()
