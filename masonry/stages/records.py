"""What a stage study reports (:mod:`masonry.stages.run`): the extremes over its stages
(:func:`masonry.stages.analysis.analyse_stages`' rows), its ``run.json`` record, and the
columns a parameter study's summary takes from that record (docs/stages.md)."""

from masonry.export.columns import STAGE_COLUMNS, column_names, summary_row
from masonry.pipeline import model_record
from masonry.stages.orders import BLOCK_ORDERS, BRICK_ORDERS
from masonry.stages.plans import StagePlan
from masonry.tolerances import ADHESION_TIE_REL

STAGE_SUMMARY_COLUMNS = column_names(STAGE_COLUMNS)
"""A stage study's columns in a sweep's summary (:func:`stage_summary`;
:data:`masonry.export.columns.STAGE_COLUMNS`), after
:data:`masonry.studies.sweep.SUMMARY_COLUMNS` when the study asks for stages
(``Study.stages``)."""

STANDS_THROUGHOUT = ("first_unsupported_stage", "first_unsupported_course",
                     "first_unsupported_brick")
"""Stage columns left empty when every stage stands; as a measure they are then
infinite (:func:`masonry.studies.sweep.measure`): no stage needs support."""


def first_unsupported(rows) -> dict | None:
    """The row of the first stage that does not stand, None when every stage stands."""
    return next((row for row in rows if not row["feasible"]), None)


def stage_extremes(rows) -> dict:
    """The largest centering force over the stages, the smallest collapse load factor
    and the largest least adhesion.

    Returns
    -------
    dict
        ``centering_max_N`` (0 when every stage stands; None when no stage's centering
        force was solved), ``centering_max_fraction`` (that stage's
        ``centering_fraction``: of its own weight), ``centering_max_stage`` (None when
        every stage stands); ``load_factor_min`` and ``load_factor_min_stage`` over the
        stages with a load factor (None without a lateral load or where no stage stands);
        ``adhesion_max_kPa``, the largest least adhesion over the stages (0 when every
        stage stands dry, None when a stage has none: no adhesion builds it in this
        order), and the ``adhesion_max_stage`` and ``adhesion_max_course`` of
        :func:`adhesion_peak` (None where it is 0 or None).
    """
    solved = [row for row in rows if row["centering_N"] is not None]
    out = {"centering_max_N": None, "centering_max_fraction": None,
           "centering_max_stage": None, "load_factor_min": None,
           "load_factor_min_stage": None, "adhesion_max_kPa": None,
           "adhesion_max_stage": None, "adhesion_max_course": None}
    if solved:
        top = max(solved, key=lambda row: row["centering_N"])  # the first of equal ones
        out.update(centering_max_N=top["centering_N"],
                   centering_max_fraction=top["centering_fraction"],
                   centering_max_stage=top["stage"] if top["centering_N"] > 0 else None)
    factors = [row for row in rows if row["load_factor"] is not None]
    if factors:
        low = min(factors, key=lambda row: row["load_factor"])
        out.update(load_factor_min=low["load_factor"], load_factor_min_stage=low["stage"])
    top = adhesion_peak(rows)
    if top is not None:
        peak = top["adhesion_kPa"] > 0
        out.update(adhesion_max_kPa=max(row["adhesion_kPa"] for row in rows),
                   adhesion_max_stage=top["stage"] if peak else None,
                   adhesion_max_course=top["course"] if peak else None)
    return out


def adhesion_peak(rows) -> dict | None:
    """The row of the first stage whose least adhesion reaches the largest within
    :data:`~masonry.tolerances.ADHESION_TIE_REL`; None when a stage has none (no
    adhesion builds the structure in this order: there is no largest)."""
    if any(row["adhesion_kPa"] is None for row in rows):
        return None
    top = max(row["adhesion_kPa"] for row in rows)
    return next(row for row in rows if row["adhesion_kPa"] >= top * (1 - ADHESION_TIE_REL))


def stage_record(params, name: str, scene, model, plan: StagePlan, rows, cached, source,
                 laying=None) -> dict:
    """run.json of a stage study of structure id ``name``, before timings; ``mortar``: the
    :class:`~masonry.stages.laying.Laying` (its mortar's table and source, the rate, the
    masons) and ``law``, the contact law in one line; None without one (``params``'
    contact law at every joint, in ``params``)."""
    first = first_unsupported(rows)
    held = [] if first is None else [
        {"block": block, "name": str(scene.blocks.block_name[block]), "support_N": size,
         "force_N": [float(v) for v in force]} for block, force, size in first["held"]]
    record = {
        "structure_id": name,
        "scene": params.scene,
        "params": params.record(),
        "outputs": {"plots": params.outputs.plots, "quick": params.outputs.quick,
                    "figure_format": params.outputs.figure_format, "dpi": params.outputs.dpi,
                    "centering": True, "adhesion": True},
        "plan": {**plan.record(), "described": _described(plan)},
        **model_record(scene, params.analysis.density),
        "cache": {"geometry": cached},
        "friction_model": params.analysis.cone.record(),
        "mortar": None if laying is None else {**laying.record(), "law": law_line(
            params, laying), **hold_record(rows)},
        "stages": {
            "count": plan.n_stages,
            "standing": int(sum(bool(row["feasible"]) for row in rows)),
            "first_unsupported": None if first is None else {
                "stage": first["stage"], "course": first["course"],
                "bricks": first["bricks"], "moi_factor": first["moi_factor"],
                "brick": plan.brick_on_course(first["stage"]),
                "centering_N": first["centering_N"],
                "centering_fraction": first["centering_fraction"],
                "laid": [str(name) for name in scene.blocks.block_name[
                    plan.block_stage == first["stage"]]],
                "loose": [str(scene.blocks.block_name[b]) for b in first["loose_blocks"]],
                "held": held},
            **stage_extremes(rows),
            **_adhesion_record(scene, rows, params.analysis.adhesion_tension_ratio),
            # every stage's solve, summed: more than the wall time when two run at once
            "solve_s": round(sum(row["solve_s"] for row in rows), 4),
        },
    }
    record["counts"]["interfaces"] = model.interfaces.counts()
    if source is not None:
        record["source"] = source
    return record


def hold_record(rows) -> dict:
    """With a mortar: ``hold_max_h``, the longest a brick just laid must be held until
    the mortar holds its stage's least adhesion (stages.csv's ``hold_h``; 0 where fresh
    mortar holds every stage; None where no stage has a value), its stage
    ``hold_max_stage`` (None where it is 0), and ``hold_never_stage``, the first stage
    whose least adhesion the mortar never reaches (None where it reaches every one)."""
    never = [row["stage"] for row in rows
             if row["adhesion_kPa"] is not None and row["hold_h"] is None]
    top = max((row for row in rows if row["hold_h"] is not None),
              key=lambda row: row["hold_h"], default=None)
    return {"hold_max_h": None if top is None else top["hold_h"],
            "hold_max_stage": top["stage"] if top is not None and top["hold_h"] > 0 else None,
            "hold_never_stage": never[0] if never else None}


def law_line(params, laying) -> str:
    """The contact law of a stage study in one line: ``params``' where every joint has
    it, else the friction model and the mortar by age."""
    law = params.analysis.law
    if laying is None:
        return params.analysis.law_text()
    head = f"Coulomb {law.cone.name}, mu {law.mu:g}"
    kinds = params.analysis.kinds_text()
    if laying.rate_per_hour is None:
        return f"{head}, {laying.describe()}{kinds}"
    return (f"{head}, per joint by its age: {laying.describe()}; "
            f"{laying.mortar.describe()}{kinds}")


def _adhesion_record(scene, rows, ratio) -> dict:
    """The least adhesion's record beside :func:`stage_extremes`': the tension ratio;
    ``adhesion_max_joint``, the names of the two blocks of the joint that needs most at
    the stage where it peaks, the later laid first (None where it is 0 or None);
    ``adhesion_unsolved``: the stages without a value and the first one's reason (None
    when every stage has one)."""
    peak = adhesion_peak(rows)
    joint = None if peak is None or not peak["adhesion_kPa"] else peak["adhesion_joint"]
    missing = [row for row in rows if row["adhesion_kPa"] is None]
    return {"adhesion_tension_ratio": ratio,
            "adhesion_max_joint": None if joint is None else [
                str(name) for name in scene.blocks.block_name[joint]],
            "adhesion_unsolved": None if not missing else {
                "count": len(missing), "first_stage": missing[0]["stage"],
                "reason": missing[0]["adhesion_reason"]}}


def _described(plan: StagePlan) -> str:
    if plan.by == "course":
        return "stage k: every brick starting on courses 1..k"
    if plan.by == "brick" and plan.course is None:
        return "every course brick by brick, from the first: " + BRICK_ORDERS[plan.order]
    if plan.by == "brick":
        return f"courses 1..{plan.course - 1}, then course {plan.course}: " + \
            BRICK_ORDERS[plan.order]
    return BLOCK_ORDERS[plan.order]


def stage_summary(record) -> dict:
    """A stage study's :data:`STAGE_SUMMARY_COLUMNS` from its ``run.json`` record
    (:func:`stage_record`): the number of stages and of those that stand; the first that
    needs support (stage, course, and for a brick plan the brick's rank on its course),
    None when every stage stands; the largest centering force (N, and its fraction of
    that stage's weight), the smallest lateral load factor and the largest least
    adhesion (kPa, and the course where it peaks) over the stages
    (:func:`stage_extremes`)."""
    return summary_row(STAGE_COLUMNS, record)
