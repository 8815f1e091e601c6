"""The double-helix pattern in the flattened section (docs/model.md 4.3, thesis 3.2.2).

Coordinates: ``s`` is the position along the wall in units (``s = 0`` on the mid-plane),
courses are numbered ``k = 1..L``. A pattern brick started on course ``k`` at ``s``
covers ``[s, s + 1]`` on courses ``k`` and ``k + 1``. Since the ground half width
``Y_0 = (p + 1)(r + 1)`` is a whole number, every pattern brick sits on the integer
lattice, and the mirror image of ``[s, s + 1]`` is ``[-s - 1, -s]``.

Patternlines are zigzag paths that move one unit sideways per course. They leave the
ground nodes ``s = -Y_0 + 2 j (p + 1)``, ``j = 0..r+1`` (the two corners and the nodes
between them), in both directions, clamped inside the section at the corners. A line
bounces (reverses) where its next brick would leave the section (the rhombi close at
the boundary) or would run into another line (the rhombi meet in a node: two pattern
bricks side by side on one course). A line that can go neither on nor back (the section
has become too narrow) ends.

With one pattern brick per rhombus side (``p = 1``) no line from a corner node lays a
brick above the first course, whatever the dome: course 2 is narrower than the ground,
so a corner line starts one cell in, beside or one cell from the line coming toward it;
the two go on only into one cell or across each other, and back only out of the web or
onto a cell another line holds. The polygonal dome refuses it
(:meth:`masonry.scenes.polygonal.Section.check`).
"""

from dataclasses import dataclass

import numpy as np

from masonry.tolerances import PATTERN_END_REPORTED, UNIT_SLACK


@dataclass(frozen=True)
class Pattern:
    """Pattern bricks and what the rules did.

    Parameters
    ----------
    course : (P,) int
        Course each pattern brick starts on (it covers ``course`` and ``course + 1``).
    s : (P,) int
        Left edge of each brick along the wall, units.
    line : (P,) int
        Patternline of each brick.
    nodes : (N, 2) int
        ``(course, s)`` of every node: two bricks of two lines side by side on one course
        (``s`` is the shared edge).
    near_nodes : (M, 2) int
        ``(course, s)`` where two lines met one unit apart and bounced without forming a
        node (the narrowing section or the corner clamp shifted their parity); ``s`` is
        the middle of the one-unit gap. This is the rhombus deviation of docs/model.md 4.3,
        counted in run.json.
    boundary_bounces : (Q, 2) int
        ``(course, s)`` of the brick at which a line turned back at the boundary.
    ended : (E, 2) int
        ``(course, s)`` of the last brick of lines that ended below the top.
    """

    course: np.ndarray
    s: np.ndarray
    line: np.ndarray
    nodes: np.ndarray
    near_nodes: np.ndarray
    boundary_bounces: np.ndarray
    ended: np.ndarray

    def __len__(self) -> int:
        return len(self.course)

    @classmethod
    def none(cls) -> "Pattern":
        """No pattern bricks: a plain dome's or a wall's courses (docs/model.md 4.9)."""
        empty, pairs = np.zeros(0, int), np.zeros((0, 2), int)
        return cls(empty, empty, empty, pairs, pairs, pairs, pairs)

    @property
    def n_lines(self) -> int:
        """The number of pattern lines (every line lays a brick on course 1)."""
        return len(np.unique(self.line))

    def ended_far_below_top(self, n_courses: int) -> np.ndarray:
        """``(course, s)`` rows of :attr:`ended` for lines that end on a course below
        :data:`~masonry.tolerances.PATTERN_END_REPORTED` of the highest course a pattern
        brick starts on, ``n_courses - 1`` (lines that end near the top, where the web
        has narrowed, are not counted)."""
        return self.ended[self.ended[:, 0] < PATTERN_END_REPORTED * (n_courses - 1)]

    def cells(self, n_courses: int) -> list:
        """Per course ``k = 1..n_courses`` (list index ``k - 1``), the sorted left edges of
        the pattern cells it holds (bricks started on ``k`` and on ``k - 1``)."""
        out = [[] for _ in range(n_courses)]
        for k, s in zip(self.course, self.s):
            out[k - 1].append(int(s))
            if k < n_courses:
                out[k].append(int(s))
        return [sorted(c) for c in out]


def _fits(s, half_width):
    return (s >= -half_width - UNIT_SLACK) & (s + 1 <= half_width + UNIT_SLACK)


def _conflicts(old, new):
    """Lines whose new brick overlaps another line's new or old brick, or crosses a line."""
    bad = np.zeros(len(new), bool)
    for i in range(len(new)):
        others = np.arange(len(new)) != i
        same = new[others] == new[i]
        onto_old = old[others] == new[i]
        crossing = np.sign(old[i] - old[others]) * np.sign(new[i] - new[others]) < 0
        bad[i] = (same | onto_old | crossing).any()
    return bad


def _ground_lines(p: int, r: int, w: float):
    """``(pos, step)``, (n,) int each: first-course cell and direction (+-1) of every
    diagonal line, starting from the rhombus nodes on the ground, clamped inside the
    first two courses (half width ``w`` of course 2; the brick spans both)."""
    y0 = (p + 1) * (r + 1)
    pos, step = [], []
    for node in (-y0 + 2 * j * (p + 1) for j in range(r + 2)):
        if node > -y0:
            pos.append(node - 1)
            step.append(-1)
        if node < y0:
            pos.append(node)
            step.append(+1)
    pos = np.clip(np.array(pos), np.ceil(-w - UNIT_SLACK), np.floor(w + UNIT_SLACK) - 1)
    return pos.astype(int), np.array(step)


def _record_meetings(nodes, near, course, old, step, clash):
    """Append where two clashing lines of ``course`` met, as ``(course, s)``: adjacent
    bricks to ``nodes``, bricks one unit apart to ``near``."""
    order = np.argsort(old)
    for a, b in zip(order[:-1], order[1:]):
        if clash[a] and clash[b] and step[a] > 0 > step[b]:
            gap = old[b] - old[a] - 1
            if gap == 0:
                nodes.append((course, old[b]))
            elif gap == 1:
                near.append((course, old[a] + 1))


def build_pattern(half_width, p: int, r: int) -> Pattern:
    """Pattern bricks for a section whose course ``k`` spans ``[-W_k, W_k]``.

    Parameters
    ----------
    half_width : (L,) float
        ``W_k`` (index ``k - 1``): half width of course ``k`` at its top intrados edge,
        units (the narrowest part of the course). A brick started on course ``k`` must lie
        within ``[-W_{k+1}, W_{k+1}]``: it may not leave the web on either course it
        spans. (``shared/pattern-sketch-preset1.png`` checks the start course only; from
        course 34 of preset 1 on, its bounces come one course later, with bricks that stick
        out of the web by up to ``W_k - W_{k+1}``: 0.2 units there, 0.9 units on preset 3,
        into the neighbouring web.)
    p, r : int
        Pattern bricks per rhombus side, full rhombi across the section.
    """
    half_width = np.asarray(half_width, dtype=float)
    n_courses = len(half_width)
    if n_courses < 2:
        return Pattern.none()
    pos, step = _ground_lines(p, r, half_width[1])
    alive = np.ones(len(pos), bool)

    course, s, line = [], [], []
    nodes, near, bounces, ended = [], [], [], []

    def record(k, idx):
        course.extend([k] * len(idx))
        s.extend(pos[idx])
        line.extend(idx)

    record(1, np.flatnonzero(alive))
    for k in range(2, n_courses):  # a brick on course k needs course k + 1
        idx = np.flatnonzero(alive)
        if len(idx) == 0:
            break
        w = half_width[k]  # W_{k+1}: the brick must fit both courses it spans
        old = pos[idx]
        new = old + step[idx]
        turn = ~_fits(new, w)
        for i in np.flatnonzero(turn):
            bounces.append((k - 1, old[i]))
        clash = _conflicts(old, new) & ~turn
        _record_meetings(nodes, near, k - 1, old, step[idx], clash)
        turn |= clash
        new[turn] = old[turn] - step[idx][turn]
        step[idx[turn]] *= -1
        stuck = ~_fits(new, w) | _conflicts(old, new)
        for i in np.flatnonzero(stuck):
            ended.append((k - 1, old[i]))
        alive[idx[stuck]] = False
        pos[idx] = new
        record(k, idx[~stuck])
    as_pairs = [np.array(v, dtype=int).reshape(-1, 2) for v in (nodes, near, bounces, ended)]
    order = np.lexsort((s, course))
    return Pattern(np.array(course)[order], np.array(s)[order], np.array(line)[order],
                   *as_pairs)
