"""Construction stages: does the structure stand at every stage of its laying (SPEC 4.7)?

Brunelleschi's dome was built without centering; the herringbone pattern bricks are
believed to hold each course while it is laid. A finished dome standing says nothing
about that, so this study solves the rigid block equilibrium of every stage.

A stage is the set of blocks laid so far. Its model (:func:`masonry.rbe.boundary.restrict`)
holds those blocks, the supports, the images of the laid bricks (cyclic and rigid
boundaries) and the interfaces of the whole structure whose two blocks are both present:
interfaces are detected once, never per stage. Each stage is solved as an ordinary run
(friction auto: friction-net, then friction+ where the stage cannot stand). The first
stage that cannot stand, and the bricks that carry tension there, are what a mason would
have to hold.

A :class:`StagePlan` says when each block is laid:

- :func:`course_plan`: stage ``k`` holds every brick that starts on courses ``1..k`` (a
  pattern brick belongs to the course it starts on), in every web.
- :func:`brick_plan`: courses ``1..K-1`` complete, then the bricks of course ``K`` one at
  a time, the same step in every web (``pattern-first`` or ``along``, see
  :data:`BRICK_ORDERS`).
- :func:`block_plan`: any assembly, one block at a time by name (``names``) or from the
  bottom up (``z``: blocks whose centroids lie at one height are laid together, so a
  symmetric arch rises from both springings at once).

A stage laid the same in every web is rotationally symmetric, so the cyclic section
(SPEC 6.4) models it exactly.
"""

import csv
import dataclasses
import io
import json
import logging
import re
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from masonry import plots
from masonry.blocks import BLOCK_CLASSES
from masonry.export.summaries import parameters_text
from masonry.params import ParameterError, structure_id
from masonry.pipeline import versions
from masonry.rbe.boundary import Model, restrict
from masonry.rbe.solve import ACCURACY, RBEProblem
from masonry.runfolder import RunFolder
from masonry.tolerances import Tolerances

log = logging.getLogger(__name__)

BRICK_ORDERS = {
    "pattern-first": "the pattern bricks that start on the course, from one corner to "
                     "the other; then the regular and fill-in bricks, nearest to a pattern "
                     "brick first (each next to one already laid), ties from one corner",
    "along": "every brick of the course by its position along the course, from the "
             "corner at -pi/n to the corner at +pi/n",
}
"""Laying orders of :func:`brick_plan` (SPEC 4.7)."""

BLOCK_ORDERS = {
    "names": "one block at a time, by name (digits compared as numbers)",
    "z": "from the bottom up by centroid height; blocks at one height together",
}
"""Laying orders of :func:`block_plan`."""

STAGE_COLUMNS = ("stage", "course", "bricks", "feasible", "moi", "moi_factor",
                 "load_factor", "solve_s")
"""Columns of ``stages.csv``, one row per stage."""

NOT_LAID = -1
"""``StagePlan.block_stage`` of a block the plan never lays."""

_PAT = BLOCK_CLASSES.index("pattern")


@dataclass(frozen=True)
class StagePlan:
    """When each block of a scene is laid.

    Parameters
    ----------
    block_stage : (S,) int
        Per scene block: 0 present from the start (supports; the courses below a brick
        plan's course), ``k >= 1`` laid at stage ``k``, :data:`NOT_LAID` never.
    stage_course : (N,) int
        The course each stage lays (0: the blocks have no course).
    by : str
        ``course``, ``brick`` or ``block``.
    order : str or None
        A :data:`BRICK_ORDERS` or :data:`BLOCK_ORDERS` name.
    course : int or None
        The course of a brick plan.
    """

    block_stage: np.ndarray
    stage_course: np.ndarray
    by: str
    order: str | None = None
    course: int | None = None

    @property
    def n_stages(self) -> int:
        return len(self.stage_course)

    @property
    def tag(self) -> str:
        """The plan's part of the run folder's name."""
        if self.by == "brick":
            return f"brick{self.course}_{self.order}"
        return self.by if self.by == "course" else self.order

    def is_present(self, stage: int) -> np.ndarray:
        """(S,) bool: the scene blocks present at ``stage`` (1..N)."""
        return (self.block_stage >= 0) & (self.block_stage <= stage)

    def record(self) -> dict:
        return {"by": self.by, "order": self.order, "course": self.course,
                "stages": self.n_stages}


def course_plan(blocks) -> StagePlan:
    """Stage ``k``: every brick starting on courses ``1..k`` (``block_course``).

    Raises
    ------
    ParameterError
        A free block has no course (an arch, an imported assembly): lay it by ``names``
        or ``z`` instead.
    """
    course = np.asarray(blocks.block_course)
    free = ~blocks.block_is_support
    if (course[free] < 1).any():
        raise ParameterError("by", "course", "a model built in courses (a dome or a wall); "
                                             "lay other blocks by --order names or z")
    stage = np.where(free, course, 0)
    return StagePlan(stage, np.arange(1, stage.max() + 1), by="course")


def brick_plan(scene, course: int, order: str = "pattern-first") -> StagePlan:
    """Courses ``1..course-1`` complete, then the bricks of ``course`` one at a time in
    ``order`` (:data:`BRICK_ORDERS`), the same step in every web of a ``dome`` scene.

    Raises
    ------
    ParameterError
        The scene has no course layout, ``course`` is not one of its courses, or
        ``order`` is unknown.
    """
    layout = scene.layout
    if layout is None:
        raise ParameterError("by", "brick", "a dome model (scene section or dome)")
    if order not in BRICK_ORDERS:
        raise ParameterError("order", order, f"one of {', '.join(BRICK_ORDERS)}")
    courses = int(layout.course.max())
    if not isinstance(course, (int, np.integer)) or not 1 <= course <= courses:
        raise ParameterError("course", course, f"a course of this model, 1..{courses}")
    rank = _laying_rank(layout, course, order)
    per_web = np.concatenate([[0], rank])  # the web's ground slab first (SPEC 4.4)
    webs, rest = divmod(scene.blocks.n_blocks, len(per_web))
    if rest:
        raise ValueError("the scene's blocks are not whole webs of its layout")
    stage = np.tile(per_web, webs)
    count = int(rank.max())
    return StagePlan(stage, np.full(count, course), by="brick", order=order, course=course)


def _laying_rank(layout, course, order) -> np.ndarray:
    """(L,) int per layout brick: 0 below ``course`` (and the pattern bricks that start
    on the course below and reach into it), 1.. its laying rank on it, NOT_LAID above."""
    on = layout.course == course
    rank = np.where(layout.course < course, 0, NOT_LAID)
    if order == "along":
        sequence = np.flatnonzero(on)[np.argsort(layout.s0[on], kind="stable")]
    else:
        # the course's occupants along the wall: its own bricks and the pattern bricks
        # of the course below, which already stand there
        below = (layout.klass == _PAT) & (layout.course == course - 1)
        occupant = np.flatnonzero(on | below)
        occupant = occupant[np.argsort(layout.s0[occupant], kind="stable")]
        anchor = np.flatnonzero(layout.klass[occupant] == _PAT)
        if len(anchor) == 0:  # no pattern brick on the course: work in from the corners
            anchor = np.array([0, len(occupant) - 1])
        position = np.arange(len(occupant))
        distance = np.abs(position[:, None] - anchor[None, :]).min(axis=1)
        new = on[occupant]
        occupant, distance = occupant[new], distance[new]
        sequence = occupant[np.lexsort((layout.s0[occupant], distance))]
    rank[sequence] = np.arange(1, len(sequence) + 1)
    return rank


def block_plan(blocks, order: str = "z", tol: Tolerances | None = None) -> StagePlan:
    """Any assembly laid block by block: by name, or from the bottom up (:data:`BLOCK_ORDERS`).

    Parameters
    ----------
    blocks : Blocks
    order : {'names', 'z'}
    tol : Tolerances, optional
        ``length`` decides which centroids lie at one height (``z``). Default
        ``Tolerances.for_points(blocks.vertices)``.
    """
    if order not in BLOCK_ORDERS:
        raise ParameterError("order", order, f"one of {', '.join(BLOCK_ORDERS)}")
    if tol is None:
        tol = Tolerances.for_points(blocks.vertices)
    free = np.flatnonzero(~blocks.block_is_support)
    stage = np.zeros(blocks.n_blocks, int)
    if order == "names":
        key = [_natural_key(str(blocks.block_name[i])) for i in free]
        free = free[sorted(range(len(free)), key=key.__getitem__)]
        stage[free] = np.arange(1, len(free) + 1)
    else:
        height = blocks.block_centroid[free, 2]
        free = free[np.argsort(height, kind="stable")]
        step = np.diff(blocks.block_centroid[free, 2]) > tol.length
        stage[free] = 1 + np.concatenate([[0], np.cumsum(step)])
    count = int(stage.max())
    stage_course = np.zeros(count, int)
    np.maximum.at(stage_course, stage[free] - 1, blocks.block_course[free])
    return StagePlan(stage, stage_course, by="block", order=order)


def _natural_key(name):
    return [(0, int(part), "") if part.isdigit() else (1, 0, part)
            for part in re.split(r"(\d+)", name) if part]


# ---------------------------------------------------------------------- one stage
def analyse_stage(model: Model, params, plan: StagePlan, stage: int) -> dict:
    """The rigid block equilibrium of one stage, as a row of ``stages.csv``.

    Parameters
    ----------
    model : Model
        The whole structure's analysis model (:func:`masonry.rbe.boundary.analysis_model`).
    params : masonry.params.Params
        ``mu``, ``density``, ``friction``, ``solver`` and the accuracy preset.
    plan : StagePlan
    stage : int
        1..``plan.n_stages``.

    Returns
    -------
    dict
        :data:`STAGE_COLUMNS` (``moi`` in newtons; ``solve_s`` the stage's wall time:
        model, assembly and solve; ``load_factor`` None: no live load), and ``tension``:
        scene block -> newtons of tension it carries (see :func:`tension_by_block`).
    """
    start = time.perf_counter()
    part = restrict(model, plan.is_present(stage))
    row = {"stage": stage, "course": int(plan.stage_course[stage - 1]) or None,
           "bricks": int((~part.blocks.block_is_support).sum()), "load_factor": None}
    if len(part.interfaces) == 0:
        log.warning("stage %d: no block touches another or a support", stage)
        row.update(feasible=False, moi=None, moi_factor=None, tension={})
    else:
        problem = RBEProblem(part.blocks, part.interfaces, side_block=part.side_block,
                             side_rotation=part.side_rotation)
        result = problem.solve(mu=params.mu, density=params.density,
                               friction=params.friction, solver=params.solver,
                               accuracy=params.solver_accuracy)
        floor = ACCURACY[params.solver_accuracy].residual * result.weight_N / row["bricks"]
        row.update(feasible=result.feasible, moi=_number(result.moi),
                   moi_factor=_number(result.moi_factor),
                   tension=tension_by_block(part, result, plan, floor))
    row["solve_s"] = round(time.perf_counter() - start, 4)
    return row


def tension_by_block(part: Model, result, plan: StagePlan, floor: float) -> dict:
    """Tension per brick: each interface's tension is charged to the later laid of its two
    blocks (both when laid at one stage), the brick a mason would have to hold.

    Parameters
    ----------
    part : Model
        A stage's model (:func:`masonry.rbe.boundary.restrict`).
    result : masonry.rbe.solve.RBEResult
    plan : StagePlan
    floor : float, newtons
        Interface tension at or below this is solver noise, not tension.

    Returns
    -------
    dict int -> float
        Scene block index -> newtons, largest first; empty without a solution.
    """
    if result.x is None:
        return {}
    tension = result.per_interface()["tension"]
    carried = np.flatnonzero(tension > floor)
    side = part.interfaces.pair if part.side_block is None else part.side_block
    block = part.block_source[side[carried]]                   # (k, 2) scene blocks
    when = np.where(part.blocks.block_is_support[side[carried]], -1,
                    plan.block_stage[block])
    held = when == when.max(axis=1, keepdims=True)
    total = np.zeros(len(plan.block_stage))
    np.add.at(total, block[held], np.broadcast_to(tension[carried, None], held.shape)[held])
    order = np.argsort(-total, kind="stable")
    return {int(b): float(total[b]) for b in order if total[b] > 0}


def _number(value):
    return None if value is None or not np.isfinite(value) else float(value)
