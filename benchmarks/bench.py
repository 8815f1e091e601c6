"""Speed against accuracy, measured (docs/model.md 6.6): the table users choose a preset from.

For every structure (a thesis preset as a free-standing section, a cyclic section and the
full dome) and every accuracy preset, :func:`bench` runs the whole process from
parameters to exported forces several times and reports the median time of each stage
(model, interfaces, assembly, solve, exports) and of the whole, with the solve's
iterations, objective, MoI, relative equilibrium residual and largest friction
violation, and how far its MoI and forces are from the most accurate solution (the
``accurate`` preset's). The library returns rows; :func:`table_markdown`,
:func:`table_csv` and :func:`frontier_png` format them, the ``masonry bench`` command
prints and writes them.

Every repeat builds everything again (a fresh :class:`~masonry.rbe.solve.RBEProblem`), so no
solver reuses a factorization or a warm start from an earlier run: the times are what a
user's first run costs.
"""

import csv
import io
import logging
import statistics
import time

import numpy as np
from masonry_benchmarks.markdown import markdown_table

from masonry.dome.levels import Dimensions
from masonry.export import force_tables
from masonry.export.csv import header, interfaces_csv, locations_csv
from masonry.export.obj import blocks_obj
from masonry.params import Params, from_preset, validate
from masonry.pipeline import build_model
from masonry.rbe.boundary import analysis_model
from masonry.rbe.collapse import CollapseLP, collapse_on_half
from masonry.rbe.lateral_search import lateral_azimuths, worst_lateral
from masonry.rbe.loads import Lateral, lateral
from masonry.rbe.mirror import half_model
from masonry.rbe.solve import ACCURACY, RBEProblem
from masonry.scenes import build

log = logging.getLogger(__name__)


def revolution_inputs(preset) -> dict:
    """The dome of revolution of a preset's profile: its circumradius as the radius (in
    units), its stretch, cut, pattern spacing p and unit."""
    polygonal = from_preset(preset).geometry
    dims = Dimensions.of(polygonal)
    return dict(radius=round(float(dims.radius / polygonal.unit), 6), stretch=polygonal.stretch,
                cut=polygonal.cut, p=polygonal.p, unit=polygonal.unit)


SCENES = {
    "section": dict(scene="section", boundary="free"),
    "cyclic": dict(scene="section", boundary="cyclic"),
    "dome": dict(scene="dome"),
    "dome-mu0.05": dict(scene="dome", mu=0.05),
    "revolution": dict(scene="revolution", of_preset=revolution_inputs),
    "sector": dict(scene="sector", boundary="cyclic", of_preset=revolution_inputs),
}
"""Bench scene name -> :class:`~masonry.params.Params` fields (over the bench's ``mu``
and ``density``). ``section`` (free-standing, the thesis's x.1) and ``dome-mu0.05`` are
infeasible; ``cyclic`` and ``dome`` are their feasible counterparts of the same size.
``revolution`` and ``sector`` are the dome of revolution of the preset's profile (its
circumradius, stretch, cut, p and unit: :func:`revolution_inputs`) and its cyclic
sector. ``of_preset``: the scene's inputs from a preset's, where its geometry is not a
preset's."""

PAIRS = (("section", "cyclic"), ("dome-mu0.05", "dome"))
"""(infeasible, feasible) scenes of the same size, compared by :func:`ratios`."""

STAGES = ("model", "interfaces", "assembly", "solve", "exports")

COLUMNS = ("preset", "scene", "accuracy", "solver", "bricks", "unknowns", "feasible",
           "friction", "model_s", "interfaces_s", "assembly_s", "solve_s", "lp_s",
           "exports_s", "total_s", "iterations", "objective", "moi", "moi_factor",
           "residual_eq", "friction_violation", "moi_deviation", "force_deviation",
           "lp_feasible")
"""Columns of a bench row. Times are medians over the repeats, in seconds; ``lp_s`` is
the part of ``solve_s`` spent in the LP check. ``solver`` and ``iterations`` list every
QP solved, joined by ``+`` (e.g. Newton's certificate of infeasibility, Clarabel on
friction+, Newton's polish). ``moi_deviation``: ``|MoI - MoI_ref| / weight``;
``force_deviation``: the largest difference of a vertex force from the reference, over
the reference's largest vertex force; the reference is the ``accurate`` preset's
solution of the same structure."""


def bench(presets=("1", "2", "3"), scenes=tuple(SCENES), accuracies=tuple(ACCURACY),
          repeats=3, solvers=(), mu=0.7, density=2000.0, overrides=None,
          progress=None) -> list:
    """Measure every (preset, scene, accuracy) and return one row per combination.

    Parameters
    ----------
    presets : sequence of str
        Thesis presets (``'1'``, ``'2'``, ``'3'``).
    scenes : sequence of str
        Keys of :data:`SCENES`.
    accuracies : sequence of str
        Accuracy presets. ``accurate`` is always solved once per structure (it is the
        reference for the deviations), and timed only if listed.
    repeats : int
        Runs per combination; stage times are their medians.
    solvers : sequence of str
        Extra rows: the ``balanced`` preset with this solver in place of its own (e.g.
        ``'osqp'``, the thesis's solver, or ``'clarabel-cvxpy'``).
    mu, density : float
    overrides : dict, optional
        Further :class:`~masonry.params.Params` fields for every structure (e.g.
        ``{'p': 3}`` for small domes).
    progress : callable, optional
        Called with a short message before every combination.

    Returns
    -------
    list of dict
        Rows with the :data:`COLUMNS` keys.
    """
    rows = []
    runs = [(accuracy, None) for accuracy in accuracies]
    runs += [("balanced", solver) for solver in solvers]
    for preset in presets:
        for scene_name in scenes:
            params = preset_params(preset, scene_name, mu=mu, density=density,
                                   **(overrides or {}))
            reference = None
            if "accurate" not in accuracies:
                reference = _run(params, "accurate", None, exports=False)[1]
            measured = {}
            for accuracy, solver in sorted(runs, key=lambda r: r[0] != "accurate"):
                if progress is not None:
                    progress(f"preset {preset} {scene_name}: {accuracy}"
                             + (f" ({solver})" if solver else ""))
                times, result, counts = [], None, None
                for _ in range(max(1, int(repeats))):
                    stage_times, result, counts = _run(params, accuracy, solver)
                    times.append(stage_times)
                if accuracy == "accurate" and solver is None:
                    reference = result
                measured[(accuracy, solver)] = (times, result, counts)
            for (accuracy, solver), (times, result, counts) in measured.items():
                rows.append(_row(preset, scene_name, accuracy, solver, times, result,
                                 counts, reference))
    return rows


def preset_params(preset, scene_name, **inputs):
    """The inputs of a bench structure: a preset in one of the :data:`SCENES`."""
    scene = dict(SCENES[scene_name])
    of_preset = scene.pop("of_preset", None)
    if of_preset is not None:
        return validate(Params.of(**{**of_preset(preset), **scene, **inputs}))
    return from_preset(preset, **{**scene, **inputs})


def _run(params, accuracy, solver, exports=True):
    """One whole process; returns ({stage: seconds}, RBEResult, counts)."""
    seconds = {}
    start = time.perf_counter()
    scene = build(params)
    seconds["model"] = time.perf_counter() - start
    start = time.perf_counter()
    model = analysis_model(scene, params.analysis.boundary)
    seconds["interfaces"] = time.perf_counter() - start
    start = time.perf_counter()
    problem = RBEProblem(model.blocks, model.interfaces, **model.assembly)
    seconds["assembly"] = time.perf_counter() - start
    start = time.perf_counter()
    result = problem.solve(**{**params.analysis.rbe_options(), "solver": solver,
                              "accuracy": accuracy})
    seconds["solve"] = time.perf_counter() - start
    seconds["lp"] = result.lp_time_s
    start = time.perf_counter()
    if exports:
        # what a run writes about the model and its forces (not the plots and the
        # printable body, which are the same for every accuracy)
        locations_csv(scene.blocks)
        blocks_obj(scene.blocks)
        interfaces_csv(model.blocks, model.interfaces)
        if result.x is not None:
            force_tables(model.blocks, model.interfaces, result, result.per_interface())
    seconds["exports"] = time.perf_counter() - start
    counts = {"bricks": int((~scene.blocks.block_is_support).sum()),
              "unknowns": problem.system.layout.n_columns}
    return seconds, result, counts


def _row(preset, scene, accuracy, solver, times, result, counts, reference) -> dict:
    median = {stage: statistics.median(t[stage] for t in times) for stage in STAGES}
    total = statistics.median(sum(t[stage] for stage in STAGES) for t in times)
    lp = statistics.median(t["lp"] for t in times)
    moi_dev = force_dev = np.nan
    if reference is not None and result.x is not None and reference.x is not None:
        moi_dev = abs(result.moi - reference.moi) / reference.weight_N
        force_dev = (np.abs(result.x - reference.x).max()
                     / max(np.abs(reference.x).max(), np.finfo(float).tiny))
    return {
        "preset": preset, "scene": scene, "accuracy": accuracy,
        "solver": "+".join(a["solver"] for a in result.attempts),
        "bricks": counts["bricks"], "unknowns": counts["unknowns"],
        "feasible": result.feasible, "friction": result.friction,
        **{f"{stage}_s": median[stage] for stage in STAGES}, "lp_s": lp, "total_s": total,
        "iterations": "+".join(str(a["iterations"]) for a in result.attempts),
        "objective": result.objective, "moi": result.moi, "moi_factor": result.moi_factor,
        "residual_eq": result.residual_eq, "friction_violation": result.friction_violation,
        "moi_deviation": moi_dev, "force_deviation": force_dev,
        "lp_feasible": result.lp_feasible,
    }


def ratios(rows) -> list:
    """Infeasible against feasible: for every preset, accuracy (and extra solver) and
    :data:`PAIRS` pair measured, ``total_s`` of the infeasible scene over that of the
    feasible one (the same web or dome, the same number of bricks).

    Returns
    -------
    list of dict
        ``preset``, ``accuracy``, ``solver``, ``infeasible``, ``feasible`` (scene names),
        ``infeasible_s``, ``feasible_s``, ``ratio``.
    """
    by_key = {(r["preset"], r["scene"], r["accuracy"], r["solver"]): r for r in rows}
    out = []
    for (preset, scene, accuracy, solver), row in by_key.items():
        for infeasible, feasible in PAIRS:
            other = next((r for (p, sc, a, _), r in by_key.items()
                          if (p, sc, a) == (preset, feasible, accuracy)), None)
            if scene != infeasible or other is None:
                continue
            out.append({"preset": preset, "accuracy": accuracy, "solver": solver,
                        "infeasible": infeasible, "feasible": feasible,
                        "infeasible_s": row["total_s"], "feasible_s": other["total_s"],
                        "ratio": row["total_s"] / other["total_s"]})
    return out


# ---------------------------------------------------------------------- formatting
def _cell(key, value) -> str:
    if isinstance(value, float):
        if np.isnan(value):
            return "-"
        if key.endswith("_s"):
            return f"{value:.2f}"
        return f"{value:.3g}" if key in ("moi_factor",) else f"{value:.2e}"
    if value is None:
        return "-"
    return str(value)


MARKDOWN_COLUMNS = ("preset", "scene", "bricks", "accuracy", "solver", "feasible",
                    "model_s", "interfaces_s", "assembly_s", "solve_s", "lp_s",
                    "exports_s", "total_s", "iterations", "objective", "moi_factor",
                    "residual_eq", "friction_violation", "moi_deviation",
                    "force_deviation")


def table_markdown(rows, columns=MARKDOWN_COLUMNS) -> str:
    """A Markdown table of bench rows (times in seconds, medians)."""
    lines = ["| " + " | ".join(columns) + " |",
             "|" + "|".join("---" for _ in columns) + "|"]
    for row in rows:
        lines.append("| " + " | ".join(_cell(c, row[c]) for c in columns) + " |")
    return "\n".join(lines) + "\n"


def ratios_markdown(rows) -> str:
    """A Markdown table of :func:`ratios` (empty when no pair was measured)."""
    pairs = ratios(rows)
    if not pairs:
        return ""
    lines = ["| preset | accuracy | infeasible | feasible | infeasible_s | feasible_s | ratio |",
             "|---|---|---|---|---|---|---|"]
    for r in pairs:
        lines.append(f"| {r['preset']} | {r['accuracy']} | {r['infeasible']} | "
                     f"{r['feasible']} | {r['infeasible_s']:.2f} | {r['feasible_s']:.2f} | "
                     f"{r['ratio']:.2f} |")
    return "\n".join(lines) + "\n"


def table_csv(rows, columns=COLUMNS) -> bytes:
    """Bench rows as CSV (full precision)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header(columns))
    for row in rows:
        writer.writerow(["" if row[c] is None else row[c] for c in columns])
    return buffer.getvalue().encode()


def frontier_png(rows) -> bytes:
    """The speed/accuracy frontier: solve time against the forces' deviation from the
    accurate solution, one line per structure from its fast to its balanced preset; the
    accurate runs (the reference, no deviation of their own) on a strip below, at their
    solve time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, strip) = plt.subplots(2, 1, figsize=(7.5, 5.6), dpi=120, sharex=True,
                                    gridspec_kw={"height_ratios": [5, 1]})
    structures = dict.fromkeys((r["preset"], r["scene"]) for r in rows)
    markers = {"fast": "o", "balanced": "s", "accurate": "^"}
    order = {name: k for k, name in enumerate(markers)}
    for (preset, scene), colour in zip(structures, plt.cm.tab10.colors * 3):
        own = sorted((r for r in rows if (r["preset"], r["scene"]) == (preset, scene)),
                     key=lambda r: order.get(r["accuracy"], len(order)))
        compared = [r for r in own if r["accuracy"] != "accurate"
                    and np.isfinite(r["force_deviation"])]
        # a deviation of zero (a preset that gave the reference's forces) at the floor
        y = [max(r["force_deviation"], 1e-16) for r in compared]
        ax.plot([r["solve_s"] for r in compared], y, "-", color=colour, alpha=0.5,
                label=f"preset {preset}, {scene}")
        for r, yi in zip(compared, y):
            ax.plot(r["solve_s"], yi, markers.get(r["accuracy"], "x"), color=colour)
        for r in own:
            if r["accuracy"] == "accurate":
                strip.plot(r["solve_s"], 0, markers["accurate"], color=colour)
    structures_legend = ax.legend(fontsize=7, loc="upper right", title="structure",
                                  title_fontsize=7)
    ax.add_artist(structures_legend)
    ran = [name for name in markers if any(r["accuracy"] == name for r in rows)]
    handles = [ax.plot([], [], markers[name], color="black", label=name)[0] for name in ran]
    ax.legend(handles=handles, fontsize=7, loc="center left", title="accuracy",
              title_fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylabel("force deviation from the\naccurate solution (relative)")
    ax.set_title("speed / accuracy frontier (lower left is better)")
    ax.grid(True, which="major", axis="y", alpha=0.3)
    ax.grid(True, which="both", axis="x", alpha=0.3)
    strip.set_yticks([0], ["accurate\n(reference)"], fontsize=8)
    strip.grid(True, which="both", axis="x", alpha=0.3)
    strip.set_xlabel("solve time, s (median)")
    # ticks at 1, 2 and 5 of every decade, as plain numbers: data from 0.2 to 3 s would
    # otherwise get one labelled tick; the other minor ticks unlabelled
    strip.xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    strip.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    strip.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    buffer = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    return buffer.getvalue()


COLLAPSE_COLUMNS = ("structure", "model", "bricks", "unknowns", "azimuths", "rbe_s",
                    "collapse_s", "ratio", "load_factor", "azimuth_deg", "solver")
"""Columns of a collapse bench row (:data:`COLLAPSE_NOTE` says what they hold)."""

COLLAPSE_NOTE = """Seconds are medians over the repeats, each with its assembly. One azimuth
(`azimuths` 1): `rbe_s` is the balanced RBE solve of the whole structure, `collapse_s`
the collapse LP at that azimuth on the `model` named: the whole, or its half in the
mirror plane along the load (docs/model.md 6.11: building the half, its LP, and its
result mapped back onto the whole), `ratio` their quotient (the target: at most 4). The
azimuth search (`azimuths` > 1, `--lateral all`): `rbe_s` holds the sum of independent
one-azimuth LPs on the whole instead, `collapse_s` the search as `masonry run` makes it
(one LP per model reused, azimuths reduced by the rotations and mirrors, those in a
mirror plane on halves), `ratio` their quotient."""


def collapse_bench(structures, azimuth=0.0, repeats=3, search=False, method=None,
                   progress=None) -> list:
    """Time the lateral collapse load factor (docs/model.md 6.8) against the balanced
    RBE solve of the whole structure.

    Parameters
    ----------
    structures : dict str -> Params
        Named structures (e.g. ``{"preset 1 full dome": from_preset("1", scene="dome")}``).
    azimuth : float
        Of the one-azimuth rows on the whole. A structure with mirror planes (its scene
        kind's :meth:`~masonry.scenes.base.SceneKind.symmetry`) also gets a row on the
        half for a load along a web's mid-plane (0 degrees) and one along the plane
        ``180 / n`` degrees on (a corner plane of the polygonal dome).
    search : bool
        Also a row for ``--lateral all`` (:func:`~masonry.rbe.lateral_search.worst_lateral`,
        as ``masonry run`` makes it) against independent one-azimuth LPs on the whole at
        the same azimuths.
    """
    rows = []
    for name, params in structures.items():
        _, model = build_model(params)
        symmetry = params.kind.symmetry(params.geometry)
        analysis = params.analysis
        options = dict(**analysis.material_options(), method=method)
        bricks = int((~model.blocks.block_is_support).sum())
        rbe = []
        for _ in range(repeats):
            start = time.perf_counter()
            RBEProblem(model.blocks, model.interfaces, **model.assembly).solve(
                **{**analysis.rbe_options(), "accuracy": "balanced"})
            rbe.append(time.perf_counter() - start)
            if progress:
                progress(f"{name}: RBE {rbe[-1]:.3g} s")
        common = dict(structure=name, bricks=bricks, rbe_s=statistics.median(rbe))
        rows.append(_whole_row(model, azimuth, repeats, options, progress, **common))
        planes = symmetry.mirrors[:2] if symmetry.mirrors else ()
        rows += [_half_row(model, plane, repeats, options, progress, **common)
                 for plane in planes]
        if search:
            rows.append(_search_row(model, symmetry, options, **common))
    return rows


def _whole_row(model, azimuth, repeats, options, progress, **common) -> dict:
    """A collapse bench row: the LP at ``azimuth`` on the whole ``model``."""
    one = []
    for _ in range(repeats):
        start = time.perf_counter()
        problem = CollapseLP(model, **options)
        result = problem.solve(lateral(model, azimuth, options["density"]),
                               dead_load_feasible=True)
        one.append(time.perf_counter() - start)
        if progress:
            progress(f"{common['structure']}: collapse LP at {azimuth:g} deg, whole "
                     f"{one[-1]:.3g} s")
    return dict(common, model="whole", unknowns=problem.matrix.shape[1], azimuths=1,
                collapse_s=statistics.median(one),
                ratio=statistics.median(one) / common["rbe_s"],
                load_factor=result.load_factor, azimuth_deg=azimuth, solver=result.solver)


def _half_row(model, plane, repeats, options, progress, **common) -> dict:
    """A collapse bench row: a lateral load along the mirror plane at ``plane`` degrees,
    on the half of ``model`` in it (:func:`~masonry.rbe.collapse.collapse_on_half`)."""
    one = []
    for _ in range(repeats):
        result = collapse_on_half(model, Lateral(plane), plane, dead_load_feasible=True,
                                  **options)
        one.append(result.time_s)
        if progress:
            progress(f"{common['structure']}: collapse LP at {plane:g} deg, half "
                     f"{one[-1]:.3g} s")
    half = half_model(model, plane).model
    unknowns = CollapseLP(half, **options).matrix.shape[1]
    return dict(common, model=f"half in {plane:g} deg", unknowns=unknowns, azimuths=1,
                collapse_s=statistics.median(one),
                ratio=statistics.median(one) / common["rbe_s"],
                load_factor=result.load_factor, azimuth_deg=plane, solver=result.solver)


def _search_row(model, symmetry, options, **common) -> dict:
    """A collapse bench row: the samples of ``--lateral all`` as ``masonry run`` solves
    them (not its refinement between them) against independent one-azimuth LPs on the
    whole at the same azimuths."""
    angles = lateral_azimuths(symmetry.webs)
    start = time.perf_counter()
    worst = worst_lateral(model, angles, period_deg=symmetry.period_deg,
                          mirrors=symmetry.mirrors, dead_load_feasible=True, refine=False,
                          **options)
    together = time.perf_counter() - start
    start = time.perf_counter()
    for angle in angles:
        problem = CollapseLP(model, **options)
        problem.solve(lateral(model, angle, options["density"]), dead_load_feasible=True)
    apart = time.perf_counter() - start
    return dict(common, model="search", unknowns=problem.matrix.shape[1],
                azimuths=len(angles), rbe_s=apart, collapse_s=together,
                ratio=together / apart, load_factor=worst.load_factor,
                azimuth_deg=worst.azimuth_deg, solver=worst.solver)


def collapse_markdown(rows) -> str:
    """A Markdown table of collapse bench rows, and what its columns hold."""
    return markdown_table(rows, COLLAPSE_COLUMNS, COLLAPSE_NOTE)


FRICTION_MODELS = ("circle", "polygon:16", "square")
"""The friction models :func:`friction_bench` compares by default: the exact cone (the
default), the inscribed 16-sided pyramid, and the thesis's square pyramid (the model
before Coulomb's)."""

FRICTION_COLUMNS = ("structure", "model", "capacity_error", "rbe_s", "rbe_steps",
                    "rbe_vs_square", "collapse_s", "collapse_iterations",
                    "collapse_vs_square", "load_factor", "vs_circle", "solver")
"""Columns of a friction-model bench row (:data:`FRICTION_NOTE` says what they hold)."""

FRICTION_NOTE = """One row per structure and friction model (`masonry bench
--friction-models`). `rbe_s`: the balanced RBE solve (its Newton steps in `rbe_steps`),
`collapse_s`: the collapse LP of a lateral load at the azimuth, each a median over the
repeats with its assembly; `*_vs_square`: the time over the square pyramid's (the model
the project used before Coulomb's cone; the target for the default model: at most 1.5).
`load_factor` and `vs_circle`, its relative difference from the exact cone's:
a polygon's is below it by at most its `capacity_error`, the square's above it."""


def friction_bench(structures, models=FRICTION_MODELS, azimuth=0.0, repeats=1,
                   progress=None) -> list:
    """Time and factor of every friction model (:mod:`masonry.friction`) on each
    structure: the balanced RBE solve and the collapse LP of the lateral load at
    ``azimuth``, side by side.

    Parameters
    ----------
    structures : dict str -> Params
    models : sequence of str
        Friction model names; ``circle`` and ``square`` are measured in any case (the
        references of ``vs_circle`` and ``*_vs_square``).
    azimuth : float, degrees
    repeats : int
        Runs per row; times are medians.

    Returns
    -------
    list of dict
        Keys :data:`FRICTION_COLUMNS`.
    """
    names = list(dict.fromkeys(["circle", *models, "square"]))
    rows = []
    for structure, params in structures.items():
        _, model = build_model(params)
        live = lateral(model, azimuth, params.analysis.density)
        measured = {}
        for name in names:
            rbe, collapse = [], []
            for _ in range(repeats):
                start = time.perf_counter()
                result = RBEProblem(model.blocks, model.interfaces, **model.assembly).solve(
                    **{**params.analysis.rbe_options(), "cone": name})
                rbe.append(time.perf_counter() - start)
                start = time.perf_counter()
                lp = CollapseLP(model, **{**params.analysis.material_options(), "cone": name})
                factor = lp.solve(live, dead_load_feasible=result.feasible or None)
                collapse.append(time.perf_counter() - start)
            if progress:
                progress(f"{structure}, {name}: RBE {rbe[-1]:.3g} s, collapse LP "
                         f"{collapse[-1]:.3g} s, lambda {factor.load_factor}")
            measured[name] = dict(rbe_s=statistics.median(rbe), rbe_steps=result.iterations,
                                  collapse_s=statistics.median(collapse),
                                  collapse_iterations=factor.iterations,
                                  load_factor=factor.load_factor, solver=factor.solver,
                                  capacity_error=lp.cone.capacity_error)
        exact, square = measured["circle"]["load_factor"], measured["square"]
        for name in names:
            row = dict(structure=structure, model=name, **measured[name])
            row["rbe_vs_square"] = row["rbe_s"] / square["rbe_s"]
            row["collapse_vs_square"] = row["collapse_s"] / square["collapse_s"]
            row["vs_circle"] = (None if exact is None or row["load_factor"] is None
                                else row["load_factor"] / exact - 1.0)
            rows.append(row)
    return rows


def friction_markdown(rows) -> str:
    """A Markdown table of friction-model bench rows, and what its columns hold."""
    return markdown_table(rows, FRICTION_COLUMNS, FRICTION_NOTE)
