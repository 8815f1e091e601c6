"""A stage study's run folder (docs/stages.md): the stages of a plan analysed
(:func:`masonry.stages.analysis.analyse_stages`) and published as a run is
(:class:`masonry.runfolder.Publication`): ``stages.csv``, ``run.json``
(:func:`masonry.stages.records.stage_record`), the blocks a first stage that needs
support must have held, and the figures.
"""

import csv
import io

import numpy as np

from masonry.errors import ParameterError
from masonry.export._text import format_float
from masonry.export.csv import header, held_csv
from masonry.export.summaries import parameters_text
from masonry.params import FILE_OUTPUTS, validate
from masonry.pipeline import Job, identity, run_model, versions
from masonry.rbe.boundary import Model, kept_blocks
from masonry.rbe.loads import Lateral
from masonry.stages.analysis import STAGE_COLUMNS, analyse_stages
from masonry.stages.laying import Laying, stage_laying
from masonry.stages.plans import StagePlan, make_plan
from masonry.stages.records import adhesion_peak, first_unsupported, stage_record
from masonry.tolerances import MAX_BRICKS


def stage_params(params, boundary_given: bool):
    """The inputs of a stage study of ``params``: a stage of the dome, not of a
    free-standing web, so a section whose scene takes a cyclic boundary is analysed
    cyclic unless the user gave a boundary (``boundary_given``)."""
    if "cyclic" in params.kind.boundaries and not boundary_given:
        return validate(params.replace(boundary="cyclic"))
    return params


def stages_csv(rows) -> bytes:
    """``stages.csv``: :data:`STAGE_COLUMNS`, one row per stage; empty cells for None,
    floats as every CSV of the project prints them."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header(STAGE_COLUMNS))
    for row in rows:
        writer.writerow(["" if row[c] is None else
                         format_float(row[c]) if isinstance(row[c], float)
                         else row[c] for c in STAGE_COLUMNS])
    return buf.getvalue().encode()


# ---------------------------------------------------------------------- the run
def stages_folder_name(name: str, plan: StagePlan, laying: Laying | None = None) -> str:
    """The run folder of a stage study: the structure id (``name``), the plan and a
    mortar that ages (its name and rate, e.g. ``_lime60``), so it never replaces the
    folder of ``masonry run``, of another plan or of another mortar."""
    name = f"{name}_stages_{plan.tag}"
    if laying is not None and laying.mortar.name != "constant":
        name += f"_{laying.mortar.name}{laying.rate_per_hour:g}"
        name += "" if laying.masons == 1 else f"x{laying.masons}"
    return name


def check_live_load(params) -> None:
    """Refuse the inputs a stage study does not take (:class:`ParameterError`): point
    and crown loads (they name blocks a stage may not hold yet) and ``--lateral all``
    (an azimuth search at every stage: one azimuth per study)."""
    load = params.load
    if load is None:
        return
    if not isinstance(load, Lateral):
        name, value = next(iter(load.options().items()))
        raise ParameterError(name, value, "none for stages (only --lateral AZIMUTH)")
    if load.azimuth_deg == "all":
        raise ParameterError("lateral", "all", "an azimuth in degrees for stages (a "
                                               "search over azimuths at every stage is "
                                               "not offered: run one azimuth per study)")


def run_stages(params, out_root="exports", *, by="course", order=None, course=None,
               force=False, scene=None, source=None, max_bricks=MAX_BRICKS, mortar=None,
               laying_rate=None, masons=None) -> dict:
    """Every construction stage of ``params`` (or of ``scene``) into its own run folder.

    The folder is published by the run-folder protocol
    (:class:`masonry.runfolder.Publication`), as a run's is: a folder holding this
    input's complete study with at least the plots asked for (``params.outputs``) and
    the centering forces is reused; one without plots gets them (the study is computed
    again; so is one written before the centering force), also with ``force``: a run
    folder only grows.

    Parameters
    ----------
    params : masonry.params.Params
        The structure and the analysis inputs, as for :func:`masonry.pipeline.run`.
    out_root : str or Path
        The run folder is ``out_root/<structure id>_stages_<plan>``.
    by, order, course
        The stage plan, see :func:`~masonry.stages.plans.make_plan`.
    force : bool
        Recompute when the folder holds this input's complete study.
    scene : Scene, optional
        An already built scene (imported blocks, :func:`masonry.assembly.read_assembly`).
    source : dict, optional
        Where such a scene came from, recorded in run.json.
    max_bricks : int
        A model estimated larger (:func:`masonry.scenes.check_size`) is refused before
        anything is built.
    mortar, laying_rate, masons
        The joints' strength by age (:func:`~masonry.stages.laying.stage_laying`, docs/model.md
        6.13); default ``params``' contact law at every joint.

    Returns
    -------
    dict
        The record written as ``run.json``, its ``path``, and ``rows`` (one dict per
        stage, :data:`STAGE_COLUMNS`, ``loose_blocks`` and ``held``).
    """
    job = Job.open(params, out_root, scene, max_bricks)
    check_live_load(job.params)
    laying = stage_laying(job.params, mortar, laying_rate, masons)
    plan = None

    def check(built):  # bad plan options are refused before anything is written
        nonlocal plan
        plan = make_plan(built, by, order, course)

    scene, model, cached = run_model(job.params, out_root, job.timer, scene, check=check)
    out = job.params.outputs
    reused = job.publication(
        stages_folder_name(job.structure_id, plan, laying),
        {"params": identity(job.params), "plan": _plan_identity(plan),
         "mortar": None if laying is None else laying.record()},
        {"plots": out.plots, "quick": out.quick, "centering": True, "adhesion": True,
         "figure_format": out.figure_format, "dpi": out.dpi},
        force=force, identify=_identify)
    if reused is not None:
        return reused
    params, name, timer = job.params, job.structure_id, job.timer
    with timer.stage("stages"):
        rows = analyse_stages(model, params, plan, laying=laying)
    record = stage_record(params, name, scene, model, plan, rows, cached, source, laying)
    record["stages"]["wall_s"] = timer.seconds["stages"]
    folder = job.publish(lambda folder: _write(folder, params, name, scene, model, plan,
                                               rows, record, timer), scene, model, cached)
    return {**record, "path": str(folder.target), "rows": rows}


def _plan_identity(plan) -> dict:
    return {"stages": plan.n_stages, **{k: plan.record()[k] for k in ("by", "order", "course")}}


def _identify(record) -> dict:
    plan, mortar = record["plan"], record.get("mortar")
    return {"params": {name: value for name, value in record["params"].items()
                       if name not in FILE_OUTPUTS},
            "plan": {"stages": plan.get("stages"),
                     **{k: plan.get(k) for k in ("by", "order", "course")}},
            "mortar": None if mortar is None else
            {k: v for k, v in mortar.items() if k != "law"}}


def _write(folder, params, name, scene, model, plan, rows, record, timer):
    """Every file of a stage study (of structure id ``name``) and, last, its
    ``run.json``."""
    folder.write("00_parameters.txt", parameters_text(params, name))
    folder.write("stages.csv", stages_csv(rows))
    first = first_unsupported(rows)
    if first is not None:
        folder.write("first_unsupported/held.csv", held_csv(scene.blocks, first["held"]))
    if params.outputs.plots:
        with timer.stage("plots"):
            figures = stage_pngs(params, name, scene, model, plan, rows)
            for name, data in figures.items():
                folder.write(name, data)
            record["figures"] = {"files": sorted(figures)}
    record["timings_s"] = timer.seconds
    record["versions"] = versions()
    record["complete"] = True
    folder.write_json("run.json", record)


def stage_pngs(params, name: str, scene, model: Model, plan: StagePlan, rows) -> dict:
    """``stages.png`` (the centering force of every stage as a fraction of its weight,
    which stages stand), ``adhesion.png`` (the least adhesion of every stage, kPa) and,
    when a stage needs support, ``first_unsupported/<view>.png``:
    that stage, its bricks coloured by the support force they need, and
    ``adhesion_peak/<view>.png`` (:func:`peak_adhesion_pngs`); each figure in the
    formats the outputs ask (``.png``, ``.svg``, ``.pdf``): path -> bytes. ``name``: the
    structure id, in the titles."""
    from masonry import plots  # matplotlib, imported only by the runs that draw

    bricks = "every course" if plan.course is None else f"course {plan.course}"
    what = {"course": "course stages", "brick": f"{bricks} brick by brick ({plan.order})",
            "block": f"block by block ({plan.order})"}[plan.by]
    title = f"{name}: {what}, {sum(bool(r['feasible']) for r in rows)} of " \
            f"{len(rows)} stages stand (mu {params.analysis.mu:g})"
    xlabel = {"course": "stage (courses laid)",
              "brick": f"stage (bricks of {bricks} laid, per web)"}.get(plan.by, "stage")
    stage, feasible = [r["stage"] for r in rows], [bool(r["feasible"]) for r in rows]
    render = plots.Render.of(params.outputs)
    out = {"stages.png": plots.stage_chart_png(
        stage, [np.nan if r["centering_fraction"] is None else r["centering_fraction"]
                for r in rows], feasible,
        [np.nan if r["load_factor"] is None else r["load_factor"] for r in rows],
        loose=[r["loose"] for r in rows], title=title, xlabel=xlabel, render=render),
        "adhesion.png": plots.stage_adhesion_png(
        stage, [np.nan if r["adhesion_kPa"] is None else r["adhesion_kPa"] for r in rows],
        feasible, title=f"{name}: {what}, the least adhesion of every "
                        f"stage (mu {params.analysis.mu:g})", xlabel=xlabel,
        ratio=params.analysis.adhesion_tension_ratio, render=render)}
    out = {path: data for name, figure in out.items()
           for path, data in plots.as_files(name, figure).items()}
    out.update(peak_adhesion_pngs(params, name, model, plan, rows))
    first = first_unsupported(rows)
    if first is None:
        return out
    support = np.zeros(scene.blocks.n_blocks)
    for block, _, size in first["held"]:
        support[block] = size
    per_web = " per web" if scene.symmetry.unit and params.analysis.boundary == "cyclic" \
        else ""
    total = ("not solved" if first["centering_N"] is None else
             f"{first['centering_N']:.3g} N{per_web} ({first['centering_fraction']:.3g} of "
             f"the weight)")
    views = plots.marked_structure_pngs(
        scene, plan.is_present(first["stage"]), support,
        f"stage {first['stage']} of {plan.n_stages}: {total} on {len(first['held'])} of "
        f"{first['bricks']} bricks",
        value_label="support force on the brick, at its centroid [N] (centering force)",
        is_outlined=plan.block_stage == first["stage"],
        outline_label=f"laid at stage {first['stage']}", fast=params.outputs.quick,
        subtitle=f"{scene.kind.describe(params.analysis.boundary)} | {name}",
        render=render)
    out.update({f"first_unsupported/{name}": png for name, png in views.items()})
    return out


def peak_adhesion_pngs(params, name: str, model: Model, plan: StagePlan, rows) -> dict:
    """``adhesion_peak/<view>.png``: the stage whose least adhesion peaks
    (:func:`~masonry.stages.records.adhesion_peak`), its joints coloured by the
    adhesion they use there (the values its program gave, ``adhesion_used``: no other
    solve), its blocks outlined in the whole structure's frame, titled with the structure
    id ``name``; none when no stage needs adhesion or a stage has none."""
    from masonry import plots

    peak = adhesion_peak(rows)
    if peak is None or peak["adhesion_used"] is None:
        return {}
    stage, (joints, kPa) = peak["stage"], peak["adhesion_used"]
    present = kept_blocks(model, plan.is_present(stage))
    chosen = present[model.interfaces.pair].all(axis=1)
    used = np.zeros(len(model.interfaces))
    used[joints] = kPa
    views = plots.adhesion_pngs(
        model.blocks, model.interfaces.subset(chosen), used[chosen], peak["adhesion_kPa"],
        params.outputs.quick, f"stage {stage} of {plan.n_stages}, where the least adhesion "
        f"peaks | {name}", plots.Render.of(params.outputs), drawn=present)
    return {f"adhesion_peak/{name}": data for name, data in views.items()}
