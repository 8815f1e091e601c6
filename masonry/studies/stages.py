"""Construction stages: does the structure stand at every stage of its laying (docs/model.md 4.7)?

Brunelleschi's dome was built without centering; the herringbone pattern bricks are
believed to hold each course while it is laid. A finished dome standing says nothing
about that, so this study solves the rigid block equilibrium of every stage.

A stage is the set of blocks laid so far. Its model (:func:`masonry.rbe.boundary.restrict`)
holds those blocks, the supports, the images of the laid bricks (cyclic and rigid
boundaries) and the interfaces of the whole structure whose two blocks are both present:
interfaces are detected once, never per stage. Each stage is solved as an ordinary run
(friction auto: friction-net, then friction+ where the stage cannot stand); a stage that
cannot stand gets its centering force (docs/model.md 6.10, :mod:`masonry.rbe.centering`): the least
total force that temporary supports must give its laid blocks, and the blocks that need
one, which is what a mason or a robot would have to hold.

A :class:`~masonry.studies.plans.StagePlan` says when each block is laid: by course, brick
by brick (one course, or every course: the whole construction) or block by block
(:mod:`masonry.studies.plans`).

A stage laid the same in every web is rotationally symmetric, so the cyclic section
(docs/model.md 6.4) models it exactly.

The stages are solved in order by one :class:`masonry.rbe.sequence.StageSequence`,
which carries the work consecutive stages share (matrices, ordering, dual points, a
local infeasibility certificate on the course being laid) from one to the next; each
stage alone (:func:`analyse_stage` without it) gives the same verdicts and measures
within the solver's accuracy.

With mortar (docs/model.md 6.13) a stage's joints have the strength of their age: a
:class:`~masonry.mortars.Laying` (a mortar's table and a laying rate) gives every joint,
made at the stage that laid the later of its two blocks, its age at the stage solved
(:func:`joint_strength`), and the stage's verdict, MoI and centering force are those of
that per-joint law.
"""

import csv
import dataclasses
import functools
import io
import logging
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from masonry import forking
from masonry.errors import ParameterError
from masonry.export._text import format_float
from masonry.export.csv import header, held_csv
from masonry.export.summaries import parameters_text
from masonry.mortars import Laying, stage_laying
from masonry.params import FILE_OUTPUTS, structure_id, validate
from masonry.pipeline import Timer, identity, run_model, versions, write_cache
from masonry.rbe.adhesion import least_adhesion
from masonry.rbe.boundary import Model, kept_blocks, restrict
from masonry.rbe.centering import centering_force
from masonry.rbe.collapse import collapse_load
from masonry.rbe.loads import Lateral
from masonry.rbe.sequence import StageSequence
from masonry.rbe.solve import RBEProblem
from masonry.runfolder import Publication, check_output_root
from masonry.scenes import check_size
from masonry.studies.plans import StagePlan, make_plan
from masonry.studies.stage_records import adhesion_peak, first_unsupported, stage_record
from masonry.tolerances import MAX_BRICKS

log = logging.getLogger(__name__)

STAGE_COLUMNS = ("stage", "course", "laid", "bricks", "feasible", "loose", "moi",
                 "moi_factor", "centering_N", "centering_fraction", "adhesion_kPa",
                 "load_factor", "time_h", "hold_h", "solve_s")
"""Columns of ``stages.csv``, one row per stage. ``laid``: the names of the blocks the
stage lays, in a brick or block plan (a course plan's stage is its course). ``loose``: the
laid blocks that touch nothing joining them to a support (:func:`loose_blocks`: the stage
has no equilibrium at all, and no MoI). ``centering_N``, ``centering_fraction``: the
centering force and its fraction of the stage's weight (:func:`stage_centering`; 0 for a
stage that stands). ``adhesion_kPa``: the least adhesion of the stage's model (docs/model.md
6.12, :func:`stage_adhesion`; 0 for a stage that stands dry, empty where it has none).
``load_factor``: the collapse load factor of the stage under the lateral load of
``params.lateral`` (:func:`stage_load_factor`); empty without one, or where the stage does
not stand under its own weight. ``time_h``: with a mortar that ages
(:func:`joint_strength`), the hours from the start of the first stage to the end of this
one, which set its joints' ages; empty without a laying rate. ``hold_h``: with a mortar
(``--mortar``), the age from which it holds the stage's least adhesion
(:meth:`~masonry.mortars.Mortar.hours_to_hold`): how long the brick just laid must be
held at most; 0 where fresh mortar holds it, empty where the mortar never does."""

# ---------------------------------------------------------------------- one stage
def analyse_stage(model: Model, params, plan: StagePlan, stage: int,
                  sequence: StageSequence | None = None, laying: Laying | None = None) -> dict:
    """The rigid block equilibrium of one stage, and its centering force, as a row of
    ``stages.csv``.

    Parameters
    ----------
    model : Model
        The whole structure's analysis model (:func:`masonry.rbe.boundary.analysis_model`).
    params : masonry.params.Params
        ``mu``, ``density``, ``friction``, the friction model, ``solver`` and the
        accuracy preset.
    plan : StagePlan
    stage : int
        1..``plan.n_stages``.
    sequence : StageSequence, optional
        Solve it from where the sequence's last stage ended (:func:`analyse_stages`);
        None: the stage alone, from scratch.
    laying : Laying, optional
        The joints' strength by age (:func:`joint_strength`); None: ``params``' contact
        law at every joint.

    Returns
    -------
    dict
        :data:`STAGE_COLUMNS` (``moi`` and ``centering_N`` in newtons; ``solve_s`` the
        stage's wall time: model, assembly and solves; ``load_factor`` None: no lateral
        load, or the stage does not stand), ``loose_blocks`` and ``held``: the scene
        blocks a support must hold, largest first (see :func:`stage_centering`);
        ``adhesion_reason``, ``adhesion_joint`` and ``adhesion_used`` (:func:`stage_adhesion`;
        the joints into ``model``'s interfaces).
    """
    start = time.perf_counter()
    part = restrict(model, plan.is_present(stage))
    loose = loose_blocks(part)
    laid = (None if plan.by == "course" else
            " ".join(map(str, model.blocks.block_name[:len(plan.block_stage)][
                plan.block_stage == stage])))
    mortar, time_h = joint_strength(model, params, plan, stage, laying)
    row = {"stage": stage, "course": int(plan.stage_course[stage - 1]) or None, "laid": laid,
           "bricks": int((~part.blocks.block_is_support).sum()), "loose": len(loose),
           "loose_blocks": loose.tolist(), "load_factor": None, "time_h": time_h}
    # the part's own slice of per-joint strengths (restrict keeps the model's order)
    chosen = kept_blocks(model, plan.is_present(stage))[model.interfaces.pair].all(axis=1)
    own = {name: value if np.ndim(value) == 0 else
           value[np.repeat(chosen, model.interfaces.vertex_count)]
           for name, value in mortar.items()}
    if len(loose) or len(part.interfaces) == 0:  # no equilibrium: nothing to solve
        row.update(feasible=False, moi=None, moi_factor=None)
    else:
        analysis = params.analysis
        options = dict(mu=analysis.mu, density=analysis.density, friction=analysis.friction,
                       solver=analysis.solver, accuracy=analysis.accuracy,
                       cone=analysis.friction_cone)
        if sequence is None:
            result = RBEProblem(part.blocks, part.interfaces, side_block=part.side_block,
                                side_rotation=part.side_rotation).solve(**options, **own)
        else:
            result = sequence.solve(plan.is_present(stage), plan.local(stage),
                                    plan.is_present(plan.course_end(stage)), **options,
                                    **mortar)
        row.update(feasible=result.feasible, moi=_number(result.moi),
                   moi_factor=_number(result.moi_factor))
        if result.feasible:
            row["load_factor"] = stage_load_factor(part, params, own)
    centering = None
    if sequence is not None and not row["feasible"] and not len(loose):
        analysis = params.analysis
        centering = sequence.centering(plan.is_present(stage), plan.local(stage),
                                       mu=analysis.mu, density=analysis.density,
                                       accuracy=analysis.accuracy, cone=analysis.friction_cone,
                                       **mortar)
    row.update(stage_centering(part, params, row["feasible"], centering, own))
    dry = not any(np.any(value) for value in mortar.values())
    row.update(stage_adhesion(part, params, plan, stage, row, sequence, dry))
    row["hold_h"] = None if laying is None else laying.mortar.hours_to_hold(
        row["adhesion_kPa"], params.analysis.adhesion_tension_ratio)
    if row["adhesion_used"] is not None:  # into the model's interfaces, as the figure's
        joints, used = row["adhesion_used"]
        row["adhesion_used"] = (np.flatnonzero(chosen)[joints], used)
    row["solve_s"] = round(time.perf_counter() - start, 4)
    return row


def joint_strength(model: Model, params, plan: StagePlan, stage: int,
                   laying: Laying | None = None) -> tuple:
    """The strength of every joint of ``model`` at the end of ``stage`` (docs/model.md
    6.13).

    A joint is made at the stage that lays the later of its two blocks (a support, and
    a block present from the start, at stage 0); at the end of stage ``k`` its age is
    the time the stages after it took (:meth:`Laying.stage_hours`, the bricks of the
    scene each stage lays), and its strength the mortar's at that age, times its joint
    kind's factor (:meth:`~masonry.rbe.settings.Analysis.joint_factor`).

    Returns
    -------
    tuple
        ``({'cohesion': c, 'tensile': t_c}, time_h)``: pascals, floats where every joint
        has the same strength, else (IV,)
        arrays over ``model``'s interface vertices (a joint not yet made takes the
        strength at age 0); ``time_h`` the hours to the end of ``stage``, None without
        a laying rate.
    """
    factor = params.analysis.joint_factor(model.interfaces)
    if laying is None:
        return _law_mortar(params, model), None
    if laying.rate_per_hour is None:
        cohesion, tensile = laying.mortar.strength_kPa(0.0)
        return {"cohesion": 1e3 * float(cohesion) * factor,
                "tensile": 1e3 * float(tensile) * factor}, None
    laid = plan.block_stage[plan.block_stage >= 1]
    hours = laying.stage_hours(np.bincount(laid, minlength=plan.n_stages + 1)[1:])
    source = (np.arange(model.blocks.n_blocks) if model.block_source is None
              else model.block_source)
    block_stage = np.maximum(plan.block_stage, 0)[source]  # images: their bricks'
    made = block_stage[model.interfaces.pair].max(axis=1)
    age = np.maximum(hours[stage] - hours[np.minimum(made, stage)], 0.0)
    cohesion, tensile = laying.mortar.strength_kPa(
        np.repeat(age, model.interfaces.vertex_count))
    return ({"cohesion": 1e3 * cohesion * factor, "tensile": 1e3 * tensile * factor},
            float(hours[stage]))


def stage_adhesion(part: Model, params, plan: StagePlan, stage: int, row,
                   sequence: StageSequence | None = None, dry: bool = True) -> dict:
    """The least adhesion of a stage (docs/model.md 6.12, :mod:`masonry.rbe.adhesion`):
    the least uniform strength of mortar (cohesion ``a``, tensile strength ``r a``) with
    which the stage's model stands.

    Parameters
    ----------
    part : Model
        The stage's model (:func:`masonry.rbe.boundary.restrict`).
    params : masonry.params.Params
        ``mu``, ``density``, the friction model and ``adhesion_tension_ratio``.
    plan : StagePlan
    stage : int
    row : dict
        The stage's ``feasible`` and ``loose`` (:func:`analyse_stage`).
    sequence : StageSequence, optional
        Solve the program on its matrices (:meth:`StageSequence.adhesion`); None: on
        ``part``'s own.
    dry : bool
        The stage was solved with dry joints: standing, it needs no adhesion (with
        mortar a stage that stands may not stand dry, so the program decides).

    Returns
    -------
    dict
        ``adhesion_kPa``: 0 for a stage that stands dry (no program), None where the
        stage has a block that no joint joins to a support or the program gives no
        checked value; ``adhesion_reason`` why not ('' with a value);
        ``adhesion_joint``: the two scene blocks of the joint that needs most, the later
        laid first (None without a positive value); ``adhesion_used``: the joints that
        need adhesion (:attr:`~masonry.rbe.adhesion.AdhesionResult.needing`, into the
        part's interfaces) and the kPa each uses, or None.
    """
    if row["feasible"] and dry:
        return {"adhesion_kPa": 0.0, "adhesion_reason": "", "adhesion_joint": None,
                "adhesion_used": None}
    if row["loose"] or len(part.interfaces) == 0:
        return {"adhesion_kPa": None, "adhesion_joint": None, "adhesion_used": None,
                "adhesion_reason": "a block touches nothing that joins it to a support: "
                                   "no adhesion holds it"}
    analysis = params.analysis
    options = dict(mu=analysis.mu, density=analysis.density, cone=analysis.cone,
                   ratio=analysis.adhesion_tension_ratio,
                   head_ratio=analysis.head_joint_ratio,
                   support_ratio=analysis.support_joint_ratio)
    if sequence is None:
        result, source = least_adhesion(part, **options), part.block_source
    else:
        result = sequence.adhesion(plan.is_present(stage), **options)
        source = sequence.model.block_source
    if result.a_kPa is None:
        log.warning("stage %d: no least adhesion (%s)", stage, result.reason)
    joint = None
    if result.a_kPa:
        pair = result.interface_pair[result.needing[0]]
        pair = pair if source is None else source[pair]
        joint = [int(b) for b in pair[np.argsort(-plan.block_stage[pair], kind="stable")]]
    used = None if not result.a_kPa else (result.needing,
                                          result.interface_kPa[result.needing])
    return {"adhesion_kPa": result.a_kPa, "adhesion_reason": result.reason,
            "adhesion_joint": joint, "adhesion_used": used}


def stage_centering(part: Model, params, stands: bool, result=None, mortar=None) -> dict:
    """The centering force of a stage (docs/model.md 6.10, :mod:`masonry.rbe.centering`): 0 for a
    stage that stands (its equilibrium needs none), else the least total force that
    supports at the laid blocks' centroids must give, loose blocks included (they must
    be held whole).

    Parameters
    ----------
    part : Model
        A stage's model (:func:`masonry.rbe.boundary.restrict`).
    params : masonry.params.Params
        ``mu``, ``density`` and the friction model.
    stands : bool
        The stage's verdict.
    result : CenteringResult, optional
        The stage's centering force found already
        (:meth:`masonry.rbe.sequence.StageSequence.centering`, its blocks the scene's).
    mortar : dict, optional
        ``cohesion`` and ``tensile`` (Pa, numbers or per vertex of ``part``); default
        ``params``' contact law.

    Returns
    -------
    dict
        ``centering_N`` (N) and ``centering_fraction`` (of the stage's weight), None when
        the program was not solved; ``held``: ``(scene block, force (3,) N, size N)`` of
        every block that needs a support, largest first.
    """
    if stands:
        return {"centering_N": 0.0, "centering_fraction": 0.0, "held": []}
    source = None  # a given result's blocks are the scene's
    if result is None:
        analysis = params.analysis
        result = centering_force(part, mu=analysis.mu, density=analysis.density,
                                 cone=analysis.cone, **(mortar or _law_mortar(params, part)))
        source = part.block_source
    return {"centering_N": result.total_N, "centering_fraction": result.fraction,
            "held": result.held_forces(source)}


def loose_blocks(part: Model) -> np.ndarray:
    """The scene blocks of a stage that no chain of interfaces joins to a support (a
    block laid before the ones under it): sorted, (k,) int.

    A section's images come after the scene's blocks (:func:`restrict` keeps the model's
    order): a rigid neighbour's image is a support of its own, a cyclic one acts on the
    brick it copies (``side_block``), so it joins nothing by itself."""
    source, support = part.block_source, part.blocks.block_is_support
    pair = part.interfaces.pair if part.side_block is None else part.side_block
    size = len(source)
    joined = sp.coo_array((np.ones(len(pair)), (pair[:, 0], pair[:, 1])), shape=(size, size))
    _, component = connected_components(joined, directed=False)
    body = np.zeros(size, bool)
    body[np.unique(source, return_index=True)[1]] = True  # not an image
    loose = body & ~support & ~np.isin(component, component[support])
    return np.unique(source[loose])


def _law_mortar(params, model: Model) -> dict:
    """``params``' contact law at ``model``'s joints as the solvers' keyword arguments
    (:meth:`~masonry.rbe.settings.Analysis.law_on`)."""
    law = params.analysis.law_on(model.interfaces)
    return {"cohesion": law.cohesion_Pa, "tensile": law.tensile_Pa}


def stage_load_factor(part: Model, params, mortar=None) -> float | None:
    """The collapse load factor of a stage (docs/model.md 6.8) under the lateral load at
    ``params.lateral`` degrees, built on the stage's own blocks; None without a lateral
    load or without a factor (unbounded: the stage carries any lateral load).

    Parameters
    ----------
    part : Model
        A stage's model (:func:`masonry.rbe.boundary.restrict`) that stands under its own
        weight.
    params : masonry.params.Params
        ``lateral`` (degrees, not ``'all'``), ``mu`` and ``density``.
    mortar : dict, optional
        As :func:`stage_centering` takes it.
    """
    if params.load is None:
        return None
    analysis = params.analysis
    live = params.load.on(part, analysis.density)
    result = collapse_load(part, live, mu=analysis.mu, density=analysis.density,
                           cone=analysis.cone, friction=analysis.friction_law,
                           dead_load_feasible=True, **(mortar or _law_mortar(params, part)))
    return result.load_factor


def _number(value):
    return None if value is None or not np.isfinite(value) else float(value)


# ---------------------------------------------------------------------- every stage
def analyse_stages(model: Model, params, plan: StagePlan, reuse: bool = True,
                   laying: Laying | None = None) -> list:
    """:func:`analyse_stage` of stages ``1..N`` (with ``laying``), in order, logging
    ``stage k of N``.

    With ``reuse``, in runs of consecutive stages, each run solved by one
    :class:`StageSequence` from its first stage to its last; on a large model two runs at
    once (:func:`masonry.forking.two_at_once`), every second run in a forked process.
    Without it, every stage alone, two at once on a large model."""
    blocks = int((~model.blocks.block_is_support).sum())
    stages = range(1, plan.n_stages + 1)
    if not reuse:
        return forking.two_at_once(functools.partial(_analysed, model, params, plan,
                                                     laying=laying), stages, blocks=blocks)
    sequence = StageSequence(model)  # made once, before any fork
    runs = _runs(plan, 2 * STAGE_RUNS if blocks >= forking.TWO_AT_ONCE_BLOCKS else 1)
    done = forking.two_at_once(functools.partial(_analysed_run, model, params, plan,
                                                 sequence, laying), runs, blocks=blocks)
    return [row for run in done for row in run]


STAGE_RUNS = 3
"""Runs of consecutive stages each process solves on a large model: a run starts
without a previous stage, so fewer runs reuse more, and more runs share the work between
the two processes more evenly (the last stages are the largest)."""


def _runs(plan: StagePlan, count: int) -> list:
    """The stages ``1..N`` in at most ``count`` runs of consecutive stages with about
    equal work (the blocks laid, summed over the run's stages)."""
    laid = np.bincount(np.maximum(plan.block_stage, 0), minlength=plan.n_stages + 1)
    work = np.cumsum(np.cumsum(laid)[1:])
    cut = np.searchsorted(work, work[-1] * np.arange(1, count) / count) + 1
    bounds = np.unique(np.concatenate([[1], cut, [plan.n_stages + 1]]))
    return [range(a, b) for a, b in zip(bounds[:-1], bounds[1:])]


def _analysed_run(model, params, plan, sequence, laying, stages) -> list:
    sequence.forget()  # another run's last stage is no start for this one's first
    return [_analysed(model, params, plan, stage, sequence, laying) for stage in stages]


def _analysed(model: Model, params, plan: StagePlan, stage: int, sequence=None,
              laying=None) -> dict:
    row = analyse_stage(model, params, plan, stage, sequence, laying)
    verdict = ("stands" if row["feasible"] else
               f"needs support ({row['loose']} blocks touch nothing that holds them)"
               if row["loose"] else "needs support")
    log.info("stage %d of %d: %d bricks, %s, MoI factor %s, %.2f s", stage, plan.n_stages,
             row["bricks"], verdict,
             "-" if row["moi_factor"] is None else f"{row['moi_factor']:.3g}", row["solve_s"])
    return row


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
def stages_folder_name(params, plan: StagePlan, laying: Laying | None = None) -> str:
    """The run folder of a stage study: the structure id, the plan and a mortar that
    ages (its name and rate, e.g. ``_lime60``), so it never replaces the folder of
    ``masonry run``, of another plan or of another mortar."""
    name = f"{structure_id(params)}_stages_{plan.tag}"
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
        The stage plan, see :func:`~masonry.studies.plans.make_plan`.
    force : bool
        Recompute when the folder holds this input's complete study.
    scene : Scene, optional
        An already built scene (imported blocks, :func:`masonry.scenes.imported.load_assembly`).
    source : dict, optional
        Where such a scene came from, recorded in run.json.
    max_bricks : int
        A model estimated larger (:func:`masonry.scenes.check_size`) is refused before
        anything is built.
    mortar, laying_rate, masons
        The joints' strength by age (:func:`~masonry.mortars.stage_laying`, docs/model.md
        6.13); default ``params``' contact law at every joint.

    Returns
    -------
    dict
        The record written as ``run.json``, its ``path``, and ``rows`` (one dict per
        stage, :data:`STAGE_COLUMNS`, ``loose_blocks`` and ``held``).
    """
    params = validate(params)
    check_live_load(params)
    laying = stage_laying(params, mortar, laying_rate, masons)
    check_output_root(out_root)
    if scene is None:
        check_size(params, max_bricks)
    timer = Timer()
    plan = None

    def check(built):  # bad plan options are refused before anything is written
        nonlocal plan
        plan = make_plan(built, by, order, course)

    scene, model, cached = run_model(params, out_root, timer, scene, check=check)
    out = params.outputs
    job = Publication(out_root, stages_folder_name(params, plan, laying),
                      {"params": identity(params), "plan": _plan_identity(plan),
                       "mortar": None if laying is None else laying.record()},
                      {"plots": out.plots, "quick": out.quick, "centering": True,
                       "adhesion": True, "figure_format": out.figure_format,
                       "dpi": out.dpi},
                      force=force,
                      identify=_identify)
    reused = job.reusable()
    if reused is not None:
        return reused
    grown = job.outputs()
    params = dataclasses.replace(params, outputs=dataclasses.replace(
        out, **{name: grown[name] for name in ("plots", "quick", "figure_format")}))
    with timer.stage("stages"):
        rows = analyse_stages(model, params, plan, laying=laying)
    record = stage_record(params, scene, model, plan, rows, cached, source, laying)
    record["stages"]["wall_s"] = timer.seconds["stages"]
    folder = job.publish(lambda folder: _write(folder, params, scene, model, plan, rows,
                                               record, timer))
    if cached == "computed":  # only a model whose study completed is cached
        write_cache(params, out_root, scene, model)
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


def _write(folder, params, scene, model, plan, rows, record, timer):
    """Every file of a stage study and, last, its ``run.json``."""
    folder.write("00_parameters.txt", parameters_text(params, structure_id(params)))
    folder.write("stages.csv", stages_csv(rows))
    first = first_unsupported(rows)
    if first is not None:
        folder.write("first_unsupported/held.csv", held_csv(scene.blocks, first["held"]))
    if params.outputs.plots:
        with timer.stage("plots"):
            figures = stage_pngs(params, scene, model, plan, rows)
            for name, data in figures.items():
                folder.write(name, data)
            record["figures"] = {"files": sorted(figures)}
    record["timings_s"] = timer.seconds
    record["versions"] = versions()
    record["complete"] = True
    folder.write_json("run.json", record)


def stage_pngs(params, scene, model: Model, plan: StagePlan, rows) -> dict:
    """``stages.png`` (the centering force of every stage as a fraction of its weight,
    which stages stand), ``adhesion.png`` (the least adhesion of every stage, kPa) and,
    when a stage needs support, ``first_unsupported/<view>.png``:
    that stage, its bricks coloured by the support force they need, and
    ``adhesion_peak/<view>.png`` (:func:`peak_adhesion_pngs`); each figure in the
    formats the outputs ask (``.png``, ``.svg``, ``.pdf``): path -> bytes."""
    from masonry import plots  # matplotlib, imported only by the runs that draw

    bricks = "every course" if plan.course is None else f"course {plan.course}"
    what = {"course": "course stages", "brick": f"{bricks} brick by brick ({plan.order})",
            "block": f"block by block ({plan.order})"}[plan.by]
    title = f"{structure_id(params)}: {what}, {sum(bool(r['feasible']) for r in rows)} of " \
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
        feasible, title=f"{structure_id(params)}: {what}, the least adhesion of every "
                        f"stage (mu {params.analysis.mu:g})", xlabel=xlabel,
        ratio=params.analysis.adhesion_tension_ratio, render=render)}
    out = {path: data for name, figure in out.items()
           for path, data in plots.as_files(name, figure).items()}
    out.update(peak_adhesion_pngs(params, model, plan, rows))
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
        subtitle=f"{scene.kind.describe(params.analysis.boundary)} | {structure_id(params)}",
        render=render)
    out.update({f"first_unsupported/{name}": png for name, png in views.items()})
    return out


def peak_adhesion_pngs(params, model: Model, plan: StagePlan, rows) -> dict:
    """``adhesion_peak/<view>.png``: the stage whose least adhesion peaks
    (:func:`~masonry.studies.stage_records.adhesion_peak`), its joints coloured by the
    adhesion they use there (the values its program gave, ``adhesion_used``: no other
    solve), its blocks outlined in the whole structure's frame; none when no stage needs
    adhesion or a stage has none."""
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
        f"peaks | {structure_id(params)}", plots.Render.of(params.outputs), drawn=present)
    return {f"adhesion_peak/{name}": data for name, data in views.items()}
