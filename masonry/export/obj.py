"""Wavefront OBJ of blocks: one named object per block (Rhino, trimesh, Blender)."""

import numpy as np

from masonry.blocks import Blocks
from masonry.export._text import format_floats


UP_AXIS = ("z up (Blender: import with Up Axis Z and Forward Axis Y; its default, Y up, "
           "lays the model on its side)")
"""The axes an OBJ file of masonry states in its first line: Rhino, trimesh, ParaView and
slicers take z up; Blender's importer assumes Y up unless told."""


SOLVED_GROUP = "solved_section"
COPIES_GROUP = "turned_copies"
"""The OBJ groups of a whole dome that a cyclic section stands for: the section the
analysis solved, and its copies turned about the axis (drawn, not solved)."""
NEIGHBOURS_GROUP = "rigid_neighbours"
"""The OBJ group of a rigid section's immovable neighbours (images of the next webs' end
bricks, supports of its analysis): analysed with them as supports, the file gives the
run's verdict."""


def blocks_obj(blocks: Blocks, vertices=None, groups=None) -> bytes:
    """OBJ text with ``o <block name>`` per block and its polygon faces.

    Parameters
    ----------
    blocks : Blocks
        Faces sorted by block (``face_block`` ascending).
    vertices : (V, 3) float, optional
        Vertex positions to write instead of ``blocks.vertices`` (e.g. CAD-offset ones).
    groups : (B,) str, optional
        A group per block: a ``g <group>`` line before the first block of each run of
        blocks of one group (readers that split by object, as ours does, ignore it).
    """
    vertices = blocks.vertices if vertices is None else vertices
    # block i's lines: its "o" line, its vertices, its faces; every line's row in the
    # file follows from the counts of the blocks before it
    first_face = blocks.block_face_offsets[:-1]
    block_row = np.arange(blocks.n_blocks) + blocks.vertex_offsets[:-1] + first_face
    vertex_block = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    vertex_row = np.arange(len(vertex_block)) + vertex_block + 1 + first_face[vertex_block]
    face_row = (np.arange(blocks.n_faces) + blocks.face_block + 1
                + blocks.vertex_offsets[blocks.face_block + 1])

    lines = np.empty(blocks.n_blocks + len(vertex_block) + blocks.n_faces, dtype=object)
    lines[block_row] = ["o " + name for name in blocks.block_name.tolist()]
    xyz = format_floats(vertices).ravel().tolist()
    lines[vertex_row] = ("v %s %s %s\n" * len(vertex_block) % tuple(xyz)).split("\n")[:-1]
    # faces by vertex count, each count's faces as one (faces, count) array
    counts = blocks.face_polygon_count
    for count in np.unique(counts):
        faces = np.flatnonzero(counts == count)
        ids = blocks.face_vertices[blocks.face_offsets[faces][:, None] + np.arange(count)]
        text = ("f" + " %d" * count + "\n") * len(faces) % tuple((ids + 1).ravel().tolist())
        lines[face_row[faces]] = text.split("\n")[:-1]
    lines = lines.tolist()
    if groups is not None:
        groups = np.asarray(groups, dtype=object)
        starts = np.flatnonzero(np.concatenate([[True], groups[1:] != groups[:-1]]))
        for start in starts[::-1]:  # from the end: the rows before stay where they are
            lines.insert(int(block_row[start]), f"g {groups[start]}")
    header = f"# masonry blocks: one object per block, metres, {UP_AXIS}"
    return "\n".join([header, *lines, ""]).encode()
