"""CSV tables: brick vertex locations, interfaces and their forces (SPEC 5, 7)."""

import numpy as np

from masonry.blocks import BLOCK_CLASSES, Blocks
from masonry.export._text import format_floats


def _table(columns) -> bytes:
    """CSV bytes: a header line, then one line per row.

    Parameters
    ----------
    columns : sequence of (str, (n,) array)
        Every column's name and values: int, str or float (printed by
        :func:`~masonry.export._text.format_floats`).

    Notes
    -----
    Columns are printed whole and joined once, not row by row in Python (docs/bench.md).
    """
    names, texts = [], []
    for name, value in columns:
        value = np.asarray(value)
        names.append(name)
        texts.append(format_floats(value).tolist() if value.dtype.kind == "f"
                     else list(map(str, value.tolist())))
    return "\n".join([",".join(names), *map(",".join, zip(*texts)), ""]).encode()


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
    x, y, z = np.asarray(vertices, dtype=float).T
    return _table([("brick", owner), ("name", blocks.block_name[owner]), ("class", classes),
                   ("course", blocks.block_course[owner]), ("vertex", local), ("x", x),
                   ("y", y), ("z", z)])


def _interface_columns(blocks: Blocks, interfaces) -> list:
    from masonry.interfaces import INTERFACE_KINDS

    a, b = interfaces.pair[:, 0], interfaces.pair[:, 1]
    kind = np.array(INTERFACE_KINDS, dtype=object)[interfaces.kind]
    return [("id", np.arange(len(interfaces))), ("block_a", a), ("block_b", b),
            ("name_a", blocks.block_name[a]), ("name_b", blocks.block_name[b]),
            ("kind", kind), ("area_m2", interfaces.area),
            *((f"centre_{axis}", v) for axis, v in zip("xyz", interfaces.centre.T)),
            *((f"normal_{axis}", v) for axis, v in zip("xyz", interfaces.normal.T))]


def interfaces_csv(blocks: Blocks, interfaces) -> bytes:
    """``interfaces.csv``: one row per interface (SPEC 5): blocks (main first), kind,
    area, centre, normal (from the main block into the other), vertex count."""
    return _table(_interface_columns(blocks, interfaces)
                  + [("vertices", interfaces.vertex_count)])


def forces_csv(blocks: Blocks, interfaces, forces: dict) -> bytes:
    """``RBE/forces.csv``: one row per interface (SPEC 7): blocks, kind, area, centre,
    normal and the interface's resultants in newtons (compression, tension, normal force
    = tension - compression, t1, t2, friction)."""
    names = ("compression", "tension", "normal", "t1", "t2", "friction")
    return _table(_interface_columns(blocks, interfaces)
                  + [(f"{n}_N", np.asarray(forces[n], dtype=float)) for n in names])
