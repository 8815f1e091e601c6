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

A :class:`~masonry.stages.plans.StagePlan` says when each block is laid: by course, brick
by brick (one course, or every course: the whole construction) or block by block
(:mod:`masonry.stages.plans`).

A stage laid the same in every web is rotationally symmetric, so the cyclic section
(docs/model.md 6.4) models it exactly.

The stages are solved in order by one :class:`masonry.rbe.sequence.StageSequence`,
which carries the work consecutive stages share (matrices, ordering, dual points, a
local infeasibility certificate on the course being laid) from one to the next; each
stage alone (:func:`analyse_stage` without it) gives the same verdicts and measures
within the solver's accuracy.

With mortar (docs/model.md 6.13) a stage's joints have the strength of their age: a
:class:`~masonry.stages.laying.Laying` (a mortar's table and a laying rate) gives every joint,
made at the stage that laid the later of its two blocks, its age at the stage solved
(:func:`joint_strength`), and the stage's verdict, MoI and centering force are those of
that per-joint law.

This module analyses the stages and returns their rows (:data:`STAGE_COLUMNS`);
:mod:`masonry.stages.run` writes a stage study's run folder.
"""

import functools
import logging
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from masonry import forking
from masonry.rbe.adhesion import least_adhesion
from masonry.rbe.boundary import Model, kept_blocks, restrict
from masonry.rbe.centering import centering_force
from masonry.rbe.collapse import collapse_load
from masonry.rbe.sequence import StageSequence
from masonry.rbe.solve import RBEProblem
from masonry.stages.laying import Laying
from masonry.stages.plans import StagePlan

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
        row.update(_equilibrium(part, params, plan, stage, sequence, mortar, own))
    centering = None
    if sequence is not None and not row["feasible"] and not len(loose):
        centering = sequence.centering(plan.is_present(stage), plan.local(stage),
                                       **params.analysis.material_options(),
                                       accuracy=params.analysis.accuracy, **mortar)
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


def _equilibrium(part: Model, params, plan: StagePlan, stage: int, sequence, mortar,
                 own) -> dict:
    """A stage's ``feasible``, ``moi``, ``moi_factor`` and, where it stands, its
    ``load_factor``: solved on ``part`` with its joints' strengths ``own``, or by
    ``sequence`` with the whole model's ``mortar`` (:func:`analyse_stage`)."""
    options = params.analysis.rbe_options()
    if sequence is None:
        result = RBEProblem(part.blocks, part.interfaces, side_block=part.side_block,
                            side_rotation=part.side_rotation).solve(**options, **own)
    else:
        result = sequence.solve(plan.is_present(stage), plan.local(stage),
                                plan.is_present(plan.course_end(stage)), **options,
                                **mortar)
    row = {"feasible": result.feasible, "moi": _number(result.moi),
           "moi_factor": _number(result.moi_factor)}
    if result.feasible:
        row["load_factor"] = stage_load_factor(part, params, own)
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
        return params.analysis.mortar_on(model.interfaces), None
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
    options = params.analysis.adhesion_options()
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
        result = centering_force(part, **analysis.material_options(),
                                 **(mortar or analysis.mortar_on(part.interfaces)))
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
    result = collapse_load(part, live, **analysis.material_options(),
                           friction=analysis.friction_law, dead_load_feasible=True,
                           **(mortar or analysis.mortar_on(part.interfaces)))
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
