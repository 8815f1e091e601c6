"""The thesis's structures (table 4.1) and friction test (table 4.3), with every boundary
model side by side (SPEC 3, 6.4).

Structure ``k.1`` is preset ``k`` as a free-standing section, ``k.2`` in dome mode. The
thesis's dome mode added a hoop term it doubted itself (5.5); here ``k.2`` is the
``cyclic`` section (exact rotational symmetry), shown beside the ``rigid`` section
(immovable neighbours) and the full dome with every web explicit, which is the reference
the thesis could not compute (its future work, 5.6).
"""

import logging
import time

from masonry.rbe.boundary import analysis_model
from masonry.rbe.equilibrium import VariableLayout
from masonry.params import from_preset
from masonry.scenes import build

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
# its text, their verdicts are from 5.2 and SPEC 8): (feasible, MoI factor)
THESIS = {
    "1.1": ("no", 2.11), "1.1 mu 0.3": ("no", 7.86), "1.1 mu 1.5": ("no", 0.07),
    "2.1": ("yes?", 1.795), "3.1": ("no", None),
    "1.2": ("yes", 0.0), "2.2": ("yes", 0.0), "3.2": ("yes", None),
}

COLUMNS = ("structure", "preset", "scene", "boundary", "friction", "mu", "feasible",
           "objective", "moi", "weight_N", "moi_factor", "bricks", "interfaces",
           "unknowns", "residual_eq", "time_s", "thesis_feasible", "thesis_moi_factor")


def structures_table(rows=ROWS, full_dome=True, lp_check=False):
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

    Returns
    -------
    list of dict
        One dict per solved row, keys :data:`COLUMNS`: the verdict, ``objective``
        (N^2), ``moi`` and ``weight_N`` (N), ``moi_factor`` (dimensionless), counts,
        the relative equilibrium residual, ``time_s`` (wall clock, s) and what the
        thesis printed (:data:`THESIS`; None where it printed nothing).
    """
    from masonry.rbe.solve import solve_rbe

    out = []
    for structure, preset, scene_name, boundary, friction, mu in rows:
        if scene_name == "dome" and not full_dome:
            continue
        log.info("structure %s ...", structure)
        start = time.perf_counter()
        params = from_preset(preset, scene=scene_name, boundary=boundary, mu=mu,
                             friction=friction)
        scene = build(params)
        model = analysis_model(scene)
        result = solve_rbe(model.blocks, model.interfaces, mu=mu, friction=friction,
                           density=params.density, solver=params.solver,
                           lp_check=lp_check, side_block=model.side_block,
                           side_rotation=model.side_rotation)
        thesis = THESIS.get(structure, (None, None))
        d = result.to_dict()
        out.append({
            "structure": structure, "preset": preset, "scene": scene_name,
            "boundary": boundary if scene_name == "section" else "-",
            "friction": d["friction"], "mu": mu, "feasible": d["feasible"],
            "objective": d["objective"], "moi": d["moi"], "weight_N": d["weight_N"],
            "moi_factor": d["moi_factor"], "bricks": int((~scene.blocks.block_is_support).sum()),
            "interfaces": len(model.interfaces),
            "unknowns": VariableLayout.from_interfaces(model.interfaces).n_columns,
            "residual_eq": d["residual_eq"], "time_s": round(time.perf_counter() - start, 2),
            "thesis_feasible": thesis[0], "thesis_moi_factor": thesis[1],
        })
    return out


def _cell(value):
    if isinstance(value, float):
        return f"{value:.4g}"
    return "" if value is None else str(value)


def table_csv(rows) -> bytes:
    """The rows of :func:`structures_table` as CSV (UTF-8 bytes): a header of
    :data:`COLUMNS`, floats to 4 significant digits, None as an empty cell."""
    lines = [",".join(COLUMNS)]
    lines += [",".join(_cell(row[c]) for c in COLUMNS) for row in rows]
    return ("\n".join(lines) + "\n").encode()


def table_markdown(rows) -> str:
    """The rows of :func:`structures_table` as a Markdown table, followed by a table of
    each preset's boundary models side by side (verdict and MoI factor at ``mu = 0.7``)."""
    shown = ("structure", "scene", "boundary", "friction", "mu", "feasible", "objective",
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
    return "\n".join(lines + side) + "\n"
