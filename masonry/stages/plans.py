"""Stage plans: when each block of a construction is laid (docs/model.md 4.7), for
:mod:`masonry.stages.analysis`.

- :func:`course_plan`: stage ``k`` holds every brick that starts on courses ``1..k`` (a
  pattern brick belongs to the course it starts on), in every web.
- :func:`brick_plan`: courses ``1..K-1`` complete, then the bricks of course ``K`` one at
  a time, the same step in every web (``pattern-first`` or ``along``, see
  :data:`~masonry.stages.orders.BRICK_ORDERS`); without ``K``, every course so, bottom
  to top: the whole construction.
- :func:`block_plan`: any assembly, one block at a time by name (``names``) or from the
  bottom up (``z``: blocks whose centroids lie at one height are laid together, so a
  symmetric arch rises from both springings at once).
"""

import re
from dataclasses import dataclass

import numpy as np

from masonry.blocks import BLOCK_CLASSES
from masonry.errors import ParameterError
from masonry.stages.orders import BLOCK_ORDERS, BRICK_ORDERS
from masonry.tolerances import Tolerances

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
        The course of a brick plan; None: every course (a brick plan of the whole
        construction).
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
            return f"brick{self.course or ''}_{self.order}"
        return self.by if self.by == "course" else self.order

    def is_present(self, stage: int) -> np.ndarray:
        """(S,) bool: the scene blocks present at ``stage`` (1..N)."""
        return (self.block_stage >= 0) & (self.block_stage <= stage)

    def local(self, stage: int) -> np.ndarray:
        """(S,) bool: the scene blocks laid so far on the course ``stage`` lays (every
        block laid at ``stage`` where it has no course): what a mason works on."""
        course = self.stage_course[stage - 1]
        laid = (self.block_stage >= 1) & (self.block_stage <= stage)
        if course == 0:
            return self.block_stage == stage
        return laid & (self.stage_course[np.maximum(self.block_stage, 1) - 1] == course)

    def course_end(self, stage: int) -> int:
        """The last stage of the course ``stage`` lays (``stage`` itself where it has no
        course)."""
        course = self.stage_course[stage - 1]
        if course == 0:
            return stage
        return stage + int(np.argmax(np.append(self.stage_course[stage:], -1) != course))

    def record(self) -> dict:
        return {"by": self.by, "order": self.order, "course": self.course,
                "stages": self.n_stages}

    def brick_on_course(self, stage: int) -> int | None:
        """A brick plan's stage ``stage`` (1..N) lays the ``k``-th brick of its course
        (1-based, in laying order); None for the other plans."""
        if self.by != "brick":
            return None
        return int((self.stage_course[:stage] == self.stage_course[stage - 1]).sum())


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


def brick_plan(scene, course: int | None, order: str = "pattern-first") -> StagePlan:
    """Courses ``1..course-1`` complete, then the bricks of ``course`` one at a time in
    ``order`` (:data:`BRICK_ORDERS`), the same step in every web of a ``dome`` scene;
    ``course`` None: every course so, from the first (the whole construction: the last
    stage of each course is its course stage).

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
    if course is not None and (not isinstance(course, (int, np.integer))
                               or not 1 <= course <= courses):
        raise ParameterError("course", course, f"a course of this model, 1..{courses}")
    if course is not None:
        rank = _laying_rank(layout, course, order)
        stage_course = np.full(int(rank.max()), course)
    else:  # every course's ranks after the courses below
        rank, stage_course = np.zeros(len(layout.course), int), []
        for each in range(1, courses + 1):
            on = layout.course == each
            rank[on] = _laying_rank(layout, each, order)[on] + len(stage_course)
            stage_course = np.concatenate([stage_course, np.full(on.sum(), each)])
        stage_course = stage_course.astype(int)
    per_web = np.concatenate([[0], rank])  # the web's ground slab first (docs/model.md 4.6)
    webs, rest = divmod(scene.blocks.n_blocks, len(per_web))
    if rest:
        raise ValueError("the scene's blocks are not whole webs of its layout")
    return StagePlan(np.tile(per_web, webs), stage_course, by="brick", order=order,
                     course=course)


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


def make_plan(scene, by: str = "course", order: str | None = None,
              course: int | None = None) -> StagePlan:
    """The stage plan of ``scene``: ``by`` course, brick (of ``course``, in ``order``,
    default ``pattern-first``) or block (in ``order``, default ``z``).

    Raises
    ------
    ParameterError
        An option that does not fit ``by`` or the scene (named ``by``, ``order`` or
        ``course``, as the front end's options).
    """
    if by == "course":
        if order is not None:
            raise ParameterError("order", order, "no laying order with --by course "
                                                   "(one for --by brick or --by block)")
        if course is not None:
            raise ParameterError("course", course, "no course with --by course "
                                                     "(--by brick --course K)")
        return course_plan(scene.blocks)
    if by == "brick":
        return brick_plan(scene, course, order or "pattern-first")
    if by == "block":
        if course is not None:
            raise ParameterError("course", course, "no course with --by block")
        return block_plan(scene.blocks, order or "z")
    raise ParameterError("by", by, "course, brick or block")
