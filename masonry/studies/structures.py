"""The thesis's structures (table 4.1) and friction test (table 4.3), with every boundary
model side by side (docs/model.md 3, 6.4).

Structure ``k.1`` is preset ``k`` as a free-standing section, ``k.2`` in dome mode. The
thesis's dome mode added a hoop term it doubted itself (5.5); here ``k.2`` is the
``cyclic`` section (exact rotational symmetry), shown beside the ``rigid`` section
(immovable neighbours) and the full dome with every web explicit, which is the reference
the thesis could not compute (its future work, 5.6).
"""

import logging
import time

import numpy as np

from masonry.export._text import format_float
from masonry.export.csv import header
from masonry.rbe.lateral_search import worst_lateral
from masonry.rbe.equilibrium import VariableLayout
from masonry.params import from_preset
from masonry.pipeline import build_model
from masonry.tolerances import MECHANISM_MAIN

log = logging.getLogger(__name__)

# (structure, preset, scene, boundary, friction, mu): thesis table 4.1 and 4.3
ROWS = (
    ("1.1", "1", "section", "free", "auto", 0.7),
    ("1.2", "1", "section", "cyclic", "auto", 0.7),
    ("2.1", "2", "section", "free", "auto", 0.7),
    ("2.2", "2", "section", "cyclic", "auto", 0.7),
    ("3.1", "3", "section", "free", "auto", 0.7),
    ("3.2", "3", "section", "cyclic", "auto", 0.7),
    ("1.1 mu 0.3", "1", "section", "free", "auto", 0.3),
    ("1.1 mu 1.5", "1", "section", "free", "auto", 1.5),
    ("1.2 rigid", "1", "section", "rigid", "auto", 0.7),
    ("2.2 rigid", "2", "section", "rigid", "auto", 0.7),
    ("3.2 rigid", "3", "section", "rigid", "auto", 0.7),
    ("1 full dome", "1", "dome", "free", "auto", 0.7),
    ("2 full dome", "2", "dome", "free", "auto", 0.7),
    ("3 full dome", "3", "dome", "free", "auto", 0.7),
)

# what the thesis printed (tables 4.3 to 4.9; 3.1's and 3.2's tables are missing from
# its text, their verdicts are from 5.2 and docs/model.md 8): (feasible, MoI factor)
THESIS = {
    "1.1": ("no", 2.11), "1.1 mu 0.3": ("no", 7.86), "1.1 mu 1.5": ("no", 0.07),
    "2.1": ("yes?", 1.795), "3.1": ("no", None),
    "1.2": ("yes", 0.0), "2.2": ("yes", 0.0), "3.2": ("yes", None),
}

COLUMNS = ("structure", "preset", "scene", "boundary", "friction", "mu", "friction_model",
           "feasible",
           "objective", "moi", "weight_N", "moi_factor", "bricks", "interfaces",
           "unknowns", "residual_eq", "time_s", "thesis_feasible", "thesis_moi_factor")


LATERAL_COLUMNS = ("lateral_factor", "lateral_azimuth", "hinge_webs", "hinge_courses",
                   "sliding", "lateral_s")
"""Columns added to the full-dome rows by ``lateral=True``: the worst lateral load factor
(docs/model.md 6.8), its azimuth, the webs and courses of its hinges, the number of sliding
interfaces (those that carry the mechanism:
:data:`~masonry.tolerances.MECHANISM_MAIN`), and the search's seconds."""


def symmetric_azimuths(n_webs: int, count: int = 3):
    """Azimuths that cover every lateral direction of a dome with ``n_webs`` webs:
    ``count`` from the mid-plane of web 0 (0 degrees) to its corner (180/n). The dome is
    symmetric under rotation by 360/n and under the mirror in a web's mid-plane (the
    pattern is mirror-symmetric, docs/model.md 4.3), so every other direction repeats one of
    these."""
    return np.linspace(0.0, 180.0 / n_webs, count)


def lateral_record(model, params, count=3, cone="circle") -> dict:
    """The worst lateral load factor of a full dome and where its mechanism hinges, with
    the friction model ``cone``. (The thesis's square pyramid is not symmetric under
    the mirror in a web's mid-plane unless the joints' axes are: its search is a
    reproduction, not a bound.) With Coulomb's cone the azimuths in the dome's mirror
    planes are solved on its halves (docs/model.md 6.11). The least of the ``count``
    azimuths, not refined between them as ``--lateral all`` refines its samples: the
    tables of docs/structures.md were measured so."""
    start = time.perf_counter()
    n = params.geometry.n
    worst = worst_lateral(model, symmetric_azimuths(n, count), mu=params.analysis.mu,
                          density=params.analysis.density, cone=cone, n_webs=n,
                          mirrors=params.kind.symmetry(params.geometry).mirrors,
                          dead_load_feasible=True, refine=False)
    out = {"lateral_factor": worst.load_factor, "lateral_azimuth": worst.azimuth_deg,
           "hinge_webs": "", "hinge_courses": "", "sliding": worst.main_sliding,
           "lateral_s": round(time.perf_counter() - start, 1)}
    if worst.hinge is not None and worst.main_hinge.any():
        blocks = model.blocks
        pair = model.interfaces.pair[worst.main_hinge]
        webs = np.unique(blocks.block_web[pair])
        courses = blocks.block_course[pair[:, 1]]
        out["hinge_webs"] = " ".join(map(str, webs))
        out["hinge_courses"] = f"{courses.min()}-{courses.max()}"
    return out


def structures_table(rows=ROWS, full_dome=True, lp_check=False, lateral=False,
                     cone=None):
    """Solve every row; return a list of dicts with :data:`COLUMNS`.

    Parameters
    ----------
    rows : sequence of (str, str, str, str, str, float)
        ``(structure, preset, scene, boundary, friction, mu)``; default :data:`ROWS`
        (thesis tables 4.1 and 4.3, every boundary model).
    full_dome : bool
        False leaves the full-dome rows out (they are the slowest: every web explicit).
    lp_check : bool
        Confirm infeasible verdicts with the LP. Off by default: the table reports the
        QP's verdict with its recomputed residuals.
    lateral : bool
        Add :data:`LATERAL_COLUMNS` to the full-dome rows (the x.2 domes as a whole: a
        lateral load breaks the symmetry a cyclic section assumes), searched over
        :func:`symmetric_azimuths`.
    cone : str, optional
        The friction model (:mod:`masonry.friction`); default the balanced preset's
        (Coulomb's cone). ``'square'`` reproduces the thesis's pyramid.

    Returns
    -------
    list of dict
        One dict per solved row, keys :data:`COLUMNS` (and :data:`LATERAL_COLUMNS`): the verdict, ``objective``
        (N^2), ``moi`` and ``weight_N`` (N), ``moi_factor`` (dimensionless), counts,
        the relative equilibrium residual, ``time_s`` (wall clock, s) and what the
        thesis printed (:data:`THESIS`; None where it printed nothing).
    """
    from masonry.rbe.solve import friction_model, solve_rbe

    cone = friction_model("balanced", cone)
    out = []
    for structure, preset, scene_name, boundary, friction, mu in rows:
        params = from_preset(preset, scene=scene_name, boundary=boundary, mu=mu,
                             friction=friction)
        # the whole dome: the kind repeats by rotation and is not one part of it
        whole = params.kind.symmetry(params.geometry).period_deg is not None
        if whole and not full_dome:
            continue
        log.info("structure %s ...", structure)
        start = time.perf_counter()
        scene, model = build_model(params)
        result = solve_rbe(model.blocks, model.interfaces, mu=mu, friction=friction,
                           density=params.analysis.density, solver=params.analysis.solver,
                           cone=cone, lp_check=lp_check, side_block=model.side_block,
                           side_rotation=model.side_rotation)
        thesis = THESIS.get(structure, (None, None))
        d = result.to_dict()
        out.append({
            "structure": structure, "preset": preset, "scene": scene_name,
            "boundary": boundary if len(params.kind.boundaries) > 1 else "-",
            "friction": d["friction"], "mu": mu, "friction_model": cone.name,
            "feasible": d["feasible"],
            "objective": d["objective"], "moi": d["moi"], "weight_N": d["weight_N"],
            "moi_factor": d["moi_factor"], "bricks": int((~scene.blocks.block_is_support).sum()),
            "interfaces": len(model.interfaces),
            "unknowns": VariableLayout.from_interfaces(model.interfaces).n_columns,
            "residual_eq": d["residual_eq"], "time_s": round(time.perf_counter() - start, 2),
            "thesis_feasible": thesis[0], "thesis_moi_factor": thesis[1],
        })
        if lateral and whole and result.feasible:
            log.info("structure %s: worst lateral load factor ...", structure)
            out[-1].update(lateral_record(model, params, cone=cone))
    return out


def _cell(value):
    if isinstance(value, float):
        return f"{value:.4g}"
    return "" if value is None else str(value)


def table_csv(rows) -> bytes:
    """The rows of :func:`structures_table` as CSV (UTF-8 bytes): a header of
    :data:`COLUMNS` (and :data:`LATERAL_COLUMNS` when a row has them), floats as every
    CSV of the project prints them (the Markdown table rounds to 4 digits), None as an
    empty cell."""
    columns = COLUMNS + (LATERAL_COLUMNS if any("lateral_factor" in r for r in rows) else ())
    lines = [",".join(header(columns))]
    lines += [",".join(format_float(v) if isinstance(v, float) else _cell(v)
                       for v in (row.get(c) for c in columns)) for row in rows]
    return ("\n".join(lines) + "\n").encode()


def table_markdown(rows) -> str:
    """The rows of :func:`structures_table` as a Markdown table, followed by a table of
    each preset's boundary models side by side (verdict and MoI factor at ``mu = 0.7``)."""
    shown = ("structure", "scene", "boundary", "friction", "mu", "friction_model", "feasible",
             "objective",
             "moi", "weight_N", "moi_factor", "bricks", "unknowns", "time_s",
             "thesis_feasible", "thesis_moi_factor")
    lines = ["| " + " | ".join(shown) + " |", "|" + "---|" * len(shown)]
    lines += ["| " + " | ".join(_cell(row[c]) for c in shown) + " |" for row in rows]
    # the boundary models of each structure side by side
    side = ["", "| preset | free | rigid | cyclic | full dome |", "|---|---|---|---|---|"]
    for preset in sorted({row["preset"] for row in rows}):
        cells = []
        for scene_name, boundary in (("section", "free"), ("section", "rigid"),
                                     ("section", "cyclic"), ("dome", "-")):
            match = [r for r in rows if r["preset"] == preset and r["scene"] == scene_name
                     and r["boundary"] == boundary and r["mu"] == 0.7]
            cells.append("" if not match else (
                f"{'feasible' if match[0]['feasible'] else 'infeasible'}, "
                f"MoI factor {match[0]['moi_factor']:.3g}"))
        side.append(f"| {preset} | " + " | ".join(cells) + " |")
    domes = [r for r in rows if "lateral_factor" in r]
    if domes:
        side += ["", "| full dome | worst lateral load factor | azimuth [deg] | hinges in "
                 "webs | hinge courses | sliding interfaces |", "|---|---|---|---|---|---|"]
        side += [f"| {r['preset']} | {_cell(r['lateral_factor'])} | "
                 f"{_cell(r['lateral_azimuth'])} | {r['hinge_webs']} | {r['hinge_courses']} "
                 f"| {r['sliding']} |" for r in domes]
        side += ["", f"Hinges and sliding interfaces: those that open or slip by "
                     f"{MECHANISM_MAIN:.0%} of the largest or more."]
    return "\n".join(lines + side) + "\n"
