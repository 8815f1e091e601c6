"""CSV tables: brick vertex locations, interfaces and their forces, the blocks a temporary
support must hold, the adhesion every joint uses (docs/model.md 5, 6.10, 6.12, 7)."""

import numpy as np

from masonry.blocks import BLOCK_CLASSES, Blocks
from masonry.export._text import format_floats
from masonry.interfaces import INTERFACE_KINDS
from masonry.export.columns import COLUMNS, DTYPES
from masonry.params import input_dtypes
from masonry.tolerances import TENSION_REPORTED_REL

TENSION_TOP_COUNT = 20
"""Rows of ``RBE/tension_top.csv``: the interfaces with the largest tension."""


HEADERS = {c.name: c.header for c in COLUMNS.values() if c.header is not None}
"""Record keys whose CSV columns name their unit (``run.json`` keeps the keys):
:attr:`masonry.export.columns.Column.header`."""


def header(columns) -> list:
    """The CSV column names of record keys (:data:`HEADERS`)."""
    return [HEADERS.get(c, c) for c in columns]


def column_types(names) -> dict:
    """pandas dtypes of masonry's CSV columns ``names``: the declared columns by their
    kind (:data:`masonry.export.columns.COLUMNS`), the inputs of a sweep's rows by their
    declarations (:func:`masonry.params.input_dtypes`), every other column a float (its
    name says its unit). ``pd.read_csv(path, dtype=column_types(header))`` types a file
    with only its header as one with rows; :func:`masonry.read_table` does it."""
    inputs = input_dtypes()
    return {name: DTYPES[COLUMNS[name].kind] if name in COLUMNS
            else inputs.get(name, "float64") for name in names}


def missing_values(names) -> dict:
    """The cells of masonry's CSV columns ``names`` that read as missing (pandas
    ``na_values``): an empty cell in every column, and ``nan`` in a float column (what
    :func:`~masonry.export._text.format_floats` prints for NaN: a point of application
    that does not exist). A name's ``nan`` stays text."""
    return {name: ["", "nan"] if dtype == "float64" else [""]
            for name, dtype in column_types(names).items()}


def _table(columns) -> bytes:
    """CSV bytes: a header line, then one line per row.

    Parameters
    ----------
    columns : sequence of (str, (n,) array)
        Every column's name and values: int, str or float (printed by
        :func:`~masonry.export._text.format_floats`).

    Notes
    -----
    Columns are printed whole and joined once, not row by row in Python (docs/bench.md,
    "Measurements behind design choices").
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
    index, x_m, y_m, z_m).

    Parameters
    ----------
    vertices : (V, 3) float, optional
        Positions to write instead of ``blocks.vertices`` (the CAD-offset ones, docs/model.md 7).
    """
    vertices = blocks.vertices if vertices is None else vertices
    counts = np.diff(blocks.vertex_offsets)
    owner = np.repeat(np.arange(blocks.n_blocks), counts)
    local = np.arange(len(owner)) - np.repeat(blocks.vertex_offsets[:-1], counts)
    classes = np.array(BLOCK_CLASSES, dtype=object)[blocks.block_class][owner]
    x, y, z = np.asarray(vertices, dtype=float).T
    return _table([("brick", owner), ("name", blocks.block_name[owner]), ("class", classes),
                   ("course", blocks.block_course[owner]), ("vertex", local), ("x_m", x),
                   ("y_m", y), ("z_m", z)])


def _xyz(name, values, unit=""):
    """Three columns ``name_x``, ``name_y``, ``name_z`` (with ``_unit`` if given)."""
    suffix = f"_{unit}" if unit else ""
    return [(f"{name}_{axis}{suffix}", v) for axis, v in zip("xyz", np.asarray(values).T)]


def _interface_columns(blocks: Blocks, interfaces) -> list:
    a, b = interfaces.pair[:, 0], interfaces.pair[:, 1]
    kind = np.array(INTERFACE_KINDS, dtype=object)[interfaces.kind]
    return [("id", np.arange(len(interfaces))), ("block_a", a), ("block_b", b),
            ("name_a", blocks.block_name[a]), ("name_b", blocks.block_name[b]),
            ("course_a", blocks.block_course[a]), ("course_b", blocks.block_course[b]),
            ("kind", kind), ("area_m2", interfaces.area),
            *_xyz("centre", interfaces.centre, "m"), *_xyz("normal", interfaces.normal),
            *_xyz("t1", interfaces.t1), *_xyz("t2", interfaces.t2)]


def interfaces_csv(blocks: Blocks, interfaces) -> bytes:
    """``interfaces.csv``: one row per interface (docs/model.md 5.5), in id order: blocks (main
    first), their names and courses, kind, area, centre, the frame (unit normal from the
    main block into the other, t1, t2), vertex count. docs/outputs.md, "Columns", names
    each one."""
    return _table(_interface_columns(blocks, interfaces)
                  + [("vertices", interfaces.vertex_count)])


FORCE_SUMS = ("compression", "tension", "normal", "t1", "t2", "friction")
"""The per-interface sums of :func:`masonry.rbe.result.interface_forces`, in column order."""


def forces_columns(blocks: Blocks, interfaces, forces: dict, resultants: dict) -> list:
    """The columns of ``RBE/forces.csv`` (:func:`forces_csv`), ``(name, (K,) array)``."""
    return (_interface_columns(blocks, interfaces)
            + [(f"{n}_N", np.asarray(forces[n], dtype=float)) for n in FORCE_SUMS]
            + _xyz("shear", resultants["shear"], "N")
            + _xyz("point", resultants["point"], "m")
            + [("eccentricity", resultants["eccentricity"]),
               ("torsion_Nm", resultants["torsion"])])


def forces_csv(blocks: Blocks, interfaces, forces: dict, resultants: dict) -> bytes:
    """``RBE/forces.csv``: one row per interface (docs/model.md 6.7), in id order (the rows of
    ``interfaces.csv`` and the cells of ``RBE/interfaces.vtu``).

    Parameters
    ----------
    forces : dict str -> (K,) float, N
        The sums over each interface's vertices (:data:`FORCE_SUMS`).
    resultants : dict
        :func:`masonry.rbe.resultants.interface_resultants`: the shear vector (N), the
        point of application (m), its eccentricity (1) and the torsion about the normal
        there (N m).

    Notes
    -----
    Forces act on the other block ``block_b``; ``block_a`` receives their opposite.
    docs/outputs.md, "Columns", names each column with its unit and sign.
    """
    return _table(forces_columns(blocks, interfaces, forces, resultants))


def tension_top(forces: dict, weight_N: float, count=TENSION_TOP_COUNT) -> np.ndarray:
    """Interfaces with the largest tension, largest first: at most ``count``, each above
    :data:`~masonry.tolerances.TENSION_REPORTED_REL` of ``weight_N``.

    Returns
    -------
    (m,) int
        Interface ids, ``m <= count`` (none for a feasible structure).
    """
    tension = np.asarray(forces["tension"], dtype=float)
    order = np.argsort(-tension, kind="stable")[:count]
    return order[tension[order] > TENSION_REPORTED_REL * weight_N]


def tension_top_csv(blocks: Blocks, interfaces, forces: dict, resultants: dict,
                    top) -> bytes:
    """``RBE/tension_top.csv``: where the structure fails, one row per interface of
    ``top`` (:func:`tension_top`): rank, the interface's columns of ``forces.csv``
    (blocks, their names and courses, kind, centre), its tension, compression, normal
    force and eccentricity. Only the header when nothing is in tension."""
    top = np.asarray(top, dtype=np.int64)
    a, b = interfaces.pair[top, 0], interfaces.pair[top, 1]
    return _table([("rank", np.arange(1, len(top) + 1)), ("id", top),
                   ("name_a", blocks.block_name[a]), ("name_b", blocks.block_name[b]),
                   ("course_a", blocks.block_course[a]), ("course_b", blocks.block_course[b]),
                   ("kind", np.array(INTERFACE_KINDS, dtype=object)[interfaces.kind[top]]),
                   *((f"{n}_N", np.asarray(forces[n], dtype=float)[top])
                     for n in ("tension", "compression", "normal")),
                   ("eccentricity", resultants["eccentricity"][top]),
                   *_xyz("centre", interfaces.centre[top], "m")])


def mechanism_csv(blocks: Blocks, mechanism) -> bytes:
    """``collapse/mechanism.csv``: one row per block (docs/model.md 6.9): block, name,
    virtual translation of the centroid ``ux_rel, uy_rel, uz_rel`` and rotation
    ``rx_per_m, ry_per_m, rz_per_m`` (radians per metre), normalised so the largest
    displacement of a block's vertex is 1 (``_rel``: in units of it).

    Parameters
    ----------
    mechanism : (B, 6) float
    """
    mechanism = np.asarray(mechanism, dtype=float)
    names = ("ux_rel", "uy_rel", "uz_rel", "rx_per_m", "ry_per_m", "rz_per_m")
    return _table([("block", np.arange(blocks.n_blocks)), ("name", blocks.block_name)]
                  + [(name, mechanism[:, i]) for i, name in enumerate(names)])


def azimuths_csv(azimuths) -> bytes:
    """``collapse/azimuths.csv``: the lateral load factor of every azimuth searched, the
    samples then the refinement's (empty factor: none)."""
    lines = ["azimuth_deg,load_factor"]
    lines += [f"{a:.10g}," + ("" if f is None else f"{f:.10g}") for a, f in azimuths]
    return ("\n".join(lines) + "\n").encode()


def held_csv(blocks: Blocks, held) -> bytes:
    """The blocks a temporary support must hold and with what force (docs/model.md 6.10): a run's
    ``RBE/centering.csv``, a stage study's ``first_unsupported/held.csv``. One row per
    block, the largest force first: ``block``, ``name``, ``class``, ``course`` (empty for
    a block without one: an arch's voussoir, an imported block), ``support_N`` (the
    force's size) and ``force_x_N``, ``force_y_N``, ``force_z_N``, the force the support
    gives the block at its centroid (model axes).

    Parameters
    ----------
    blocks : Blocks
        The blocks ``held`` indexes (a scene's).
    held : list of (int, (3,) float, float)
        Block, force and its size in newtons
        (:meth:`~masonry.rbe.centering.CenteringResult.held_forces`).
    """
    block = np.array([b for b, _, _ in held], dtype=np.int64)
    force = np.array([f for _, f, _ in held], dtype=float).reshape(-1, 3)
    size = np.array([m for _, _, m in held], dtype=float)
    course = blocks.block_course[block]
    classes = np.array(BLOCK_CLASSES, dtype=object)[blocks.block_class[block]]
    return _table([("block", block), ("name", blocks.block_name[block]), ("class", classes),
                   ("course", np.where(course > 0, course.astype(str), "")),
                   ("support_N", size), *_xyz("force", force, "N")])


def adhesion_csv(blocks: Blocks, interfaces, used_kPa) -> bytes:
    """``RBE/adhesion.csv``: the adhesion every interface uses at the least adhesion's
    optimum (docs/model.md 6.12), one row per interface in id order: ``interface``,
    ``block_a``, ``block_b``, ``name_a``, ``name_b``, ``kind``, ``adhesion_kPa``.

    Parameters
    ----------
    blocks : Blocks
        The blocks the interfaces join (a model's).
    used_kPa : (K,) float
        :attr:`~masonry.rbe.adhesion.AdhesionResult.interface_kPa`.
    """
    a, b = interfaces.pair[:, 0], interfaces.pair[:, 1]
    kind = np.array(INTERFACE_KINDS, dtype=object)[interfaces.kind]
    return _table([("interface", np.arange(len(interfaces))), ("block_a", a), ("block_b", b),
                   ("name_a", blocks.block_name[a]), ("name_b", blocks.block_name[b]),
                   ("kind", kind), ("adhesion_kPa", np.asarray(used_kPa, dtype=float))])
