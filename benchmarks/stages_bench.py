"""Construction stages, measured (``masonry bench --stages``): every brick stage of a
dome's cyclic section, in both laying orders, solved in sequence
(:class:`masonry.rbe.sequence.StageSequence`: the work of one stage reused for the next)
and each stage alone, against one run of the dome (docs/bench.md, "Construction stages
brick by brick"); and (``masonry bench --adhesion-course K``) each brick stage's least
adhesion against its RBE solve.
"""

import statistics
import tempfile
import time

from masonry_benchmarks.markdown import markdown_table

from masonry.params import validate
from masonry.pipeline import build_model, run
from masonry.rbe.adhesion import INTERIOR, SOLVER
from masonry.rbe.sequence import StageSequence
from masonry.stages.analysis import analyse_stages
from masonry.stages.orders import BRICK_ORDERS
from masonry.stages.plans import make_plan

STAGES_COLUMNS = ("structure", "order", "stages", "standing", "same_verdicts",
                  "moi_factor_diff", "sequence_s", "alone_s", "speedup", "run_s",
                  "sequence_runs", "alone_runs")
"""Columns of a stages bench row (:data:`STAGES_NOTE` says what they hold)."""

STAGES_NOTE = """One row per structure and laying order (`masonry bench --stages`), every
brick stage of the cyclic section (`masonry stages --dome --by brick`), one pass each.
`sequence_s`: the stages solved in order, each from the last one's work (the whole
model's matrices and ordering, the last stage's dual points, the local infeasibility
certificate); `alone_s`: each stage alone from scratch (as before); both two at once on a
large model, as `masonry stages` does, the model built beforehand. `standing`: stages
that stand (in sequence); `same_verdicts`: every stage's verdict is the same both ways;
`moi_factor_diff`: the largest difference of a stage's MoI factor between the two;
`speedup`: alone over sequence; `run_s`: one `masonry run` of the dome (analysis and
exports, no plots, no printable body, no page; median over the repeats, the geometry from
the cache as a repeated run has it); `sequence_runs`, `alone_runs`: the stages' times
over the run's."""


def stages_bench(structures, orders=tuple(BRICK_ORDERS), repeats=3, alone=True,
                 progress=None) -> list:
    """Time every brick stage of each structure, in sequence and alone, against one run.

    Parameters
    ----------
    structures : dict str -> Params
        Named cyclic sections (their ``analysis`` is the stages' and the run's).
    orders : sequence of str
        :data:`~masonry.stages.orders.BRICK_ORDERS` names.
    repeats : int
        Runs of the dome timed (the stages are timed once).
    alone : bool
        Also each stage alone (slow: the reference).
    """
    rows = []
    for name, params in structures.items():
        run_s = _run_seconds(params, repeats)
        scene, model = build_model(params)
        for order in orders:
            plan = make_plan(scene, "brick", order)
            start = time.perf_counter()
            ours = analyse_stages(model, params, plan)
            sequence_s = time.perf_counter() - start
            row = dict(structure=name, order=order, stages=plan.n_stages,
                       standing=sum(bool(r["feasible"]) for r in ours),
                       sequence_s=sequence_s, run_s=run_s, sequence_runs=sequence_s / run_s)
            if alone:
                start = time.perf_counter()
                theirs = analyse_stages(model, params, plan, reuse=False)
                row["alone_s"] = time.perf_counter() - start
                row.update(_agreement(ours, theirs), speedup=row["alone_s"] / sequence_s,
                           alone_runs=row["alone_s"] / run_s)
            rows.append(row)
            if progress:
                progress(f"{name}, {order}: {plan.n_stages} stages in {sequence_s:.3g} s "
                         f"({sequence_s / run_s:.3g} runs)"
                         + (f", alone {row['alone_s']:.3g} s" if alone else ""))
    return rows


def _run_seconds(params, repeats) -> float:
    """Median seconds of one ``masonry run`` of the dome of ``params`` (no plots, no
    printable body, no page), after a first run that fills the geometry cache."""
    dome = validate(params.replace(plots=False, printable=False, html=False))
    times = []
    with tempfile.TemporaryDirectory() as out:
        for index in range(repeats + 1):
            start = time.perf_counter()
            run(dome, out, force=True)
            if index:
                times.append(time.perf_counter() - start)
    return statistics.median(times)


def _agreement(ours, theirs) -> dict:
    same = all(a["feasible"] == b["feasible"] for a, b in zip(ours, theirs))
    diff = max((abs(a["moi_factor"] - b["moi_factor"]) for a, b in zip(ours, theirs)
                if a["moi_factor"] is not None and b["moi_factor"] is not None), default=0.0)
    return {"same_verdicts": same, "moi_factor_diff": diff}


def stages_markdown(rows) -> str:
    """The rows as a markdown table, then :data:`STAGES_NOTE`."""
    return markdown_table(rows, STAGES_COLUMNS, STAGES_NOTE, formats={
        "moi_factor_diff": "{:.1e}", "sequence_s": "{:.1f}", "alone_s": "{:.1f}",
        "speedup": "{:.2f}", "run_s": "{:.2f}", "sequence_runs": "{:.1f}",
        "alone_runs": "{:.1f}"})


ADHESION_COLUMNS = ("structure", "course", "order", "stages", "needing", "rbe_s",
                    "adhesion_s", "ratio_median", "ratio_max", "by_interior", "clarabel_s",
                    "clarabel_ratio_median", "diff_max", "adhesion_max_kPa")
"""Columns of an adhesion bench row (:data:`ADHESION_NOTE`)."""

ADHESION_NOTE = """One row per structure and laying order (`masonry bench --adhesion-course
K`): course K of the cyclic section laid brick by brick on the courses under it, every
stage solved in one sequence (`StageSequence`) as `masonry stages` solves it: the RBE
(its friction flow, `auto`: friction-net, then friction+ where it cannot stand) and,
where a stage cannot stand dry, its least adhesion (the interior point method on the
stage's rows and columns of the whole model's matrices, Clarabel where it ends without a
checked optimum). `needing`: the stages that need adhesion; `rbe_s`, `adhesion_s`: their
seconds, summed over those stages; `ratio_median`, `ratio_max`: a stage's least adhesion
over its RBE solve, the median and the largest over those stages; `by_interior`: the
stages whose value the interior point method gave; `clarabel_s`,
`clarabel_ratio_median`: the same stages' program by Clarabel alone (the reference);
`diff_max`: the largest relative difference of the two values; `adhesion_max_kPa`: the
largest least adhesion."""


def adhesion_bench(structures, course, orders=tuple(BRICK_ORDERS), progress=None) -> list:
    """Time each brick stage of ``course`` of each structure: its RBE solve and, where it
    cannot stand dry, its least adhesion by the interior point method and by Clarabel, in
    one :class:`StageSequence` (one pass).

    Parameters
    ----------
    structures : dict str -> Params
        Named cyclic sections (their ``analysis`` is the stages').
    course : int
    orders : sequence of str
    """
    rows = []
    for name, params in structures.items():
        scene, model = build_model(params)
        for order in orders:
            plan = make_plan(scene, "brick", order, course)
            stages = _adhesion_stages(StageSequence(model), plan, params.analysis)
            ratios = [ours / rbe for rbe, ours, *_ in stages]
            rows.append(dict(
                structure=name, course=course, order=order, stages=plan.n_stages,
                needing=len(stages), rbe_s=sum(t[0] for t in stages),
                adhesion_s=sum(t[1] for t in stages),
                ratio_median=statistics.median(ratios) if ratios else None,
                ratio_max=max(ratios, default=None),
                by_interior=sum(t[5] == "interior" for t in stages),
                clarabel_s=sum(t[2] for t in stages),
                clarabel_ratio_median=statistics.median(t[2] / t[0] for t in stages)
                if stages else None,
                diff_max=max((abs(t[3] / t[4] - 1) for t in stages if t[3] and t[4]),
                             default=None),
                adhesion_max_kPa=max((t[3] or 0.0 for t in stages), default=0.0)))
            if progress:
                row = rows[-1]
                progress(f"{name}, course {course}, {order}: {row['needing']} of "
                         f"{plan.n_stages} stages need adhesion, {row['adhesion_s']:.3g} s "
                         f"against their RBE's {row['rbe_s']:.3g} s")
    return rows


def _adhesion_stages(sequence, plan, analysis) -> list:
    """Per stage that cannot stand dry, in order: ``(RBE s, least adhesion s, Clarabel s,
    a* kPa, Clarabel's a* kPa, solver)``."""
    out = []
    for stage in range(1, plan.n_stages + 1):
        start = time.perf_counter()
        result = sequence.solve(plan.is_present(stage), plan.local(stage),
                                plan.is_present(plan.course_end(stage)),
                                **analysis.rbe_options())
        solved = time.perf_counter()
        if result.feasible:
            continue
        found, ends = [], []
        for solver in (INTERIOR, SOLVER):
            found.append(sequence.adhesion(plan.is_present(stage), solver=solver,
                                           **analysis.adhesion_options()))
            ends.append(time.perf_counter())
        out.append((solved - start, ends[0] - solved, ends[1] - ends[0], found[0].a_kPa,
                    found[1].a_kPa, found[0].solver))
    return out


def adhesion_markdown(rows) -> str:
    """The rows as a markdown table, then :data:`ADHESION_NOTE`."""
    return markdown_table(rows, ADHESION_COLUMNS, ADHESION_NOTE, formats={
        "rbe_s": "{:.2f}", "adhesion_s": "{:.2f}", "ratio_median": "{:.2f}",
        "ratio_max": "{:.2f}", "clarabel_s": "{:.2f}", "clarabel_ratio_median": "{:.2f}",
        "diff_max": "{:.1e}", "adhesion_max_kPa": "{:.4g}"})
