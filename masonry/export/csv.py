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


def _table(header, columns) -> bytes:
    out = io.StringIO()
    out.write(",".join(header) + "\n")
    for row in zip(*columns):
        out.write(",".join(v if isinstance(v, str) else f"{v:.12g}" for v in row) + "\n")
    return out.getvalue().encode()


def _interface_columns(blocks: Blocks, interfaces):
    from ..interfaces import INTERFACE_KINDS

    kind = np.array(INTERFACE_KINDS, dtype=object)[interfaces.kind]
    header = ["id", "block_a", "block_b", "name_a", "name_b", "kind", "area_m2",
              "centre_x", "centre_y", "centre_z", "normal_x", "normal_y", "normal_z"]
    a, b = interfaces.pair[:, 0], interfaces.pair[:, 1]
    columns = [[str(i) for i in range(len(interfaces))], [str(i) for i in a],
               [str(i) for i in b], list(blocks.block_name[a]), list(blocks.block_name[b]),
               list(kind), interfaces.area, *interfaces.centre.T, *interfaces.normal.T]
    return header, columns


def interfaces_csv(blocks: Blocks, interfaces) -> bytes:
    """``interfaces.csv``: one row per interface (SPEC 5): blocks (main first), kind,
    area, centre, normal (from the main block into the other), vertex count."""
    header, columns = _interface_columns(blocks, interfaces)
    return _table(header + ["vertices"],
                  columns + [[str(c) for c in interfaces.vertex_count]])


def forces_csv(blocks: Blocks, interfaces, forces: dict) -> bytes:
    """``RBE/forces.csv``: one row per interface (SPEC 7): blocks, kind, area, centre,
    normal and the interface's resultants in newtons (compression, tension, normal force
    = tension - compression, t1, t2, friction)."""
    header, columns = _interface_columns(blocks, interfaces)
    names = ("compression", "tension", "normal", "t1", "t2", "friction")
    return _table(header + [f"{n}_N" for n in names], columns + [forces[n] for n in names])
