"""Courses: regular and fill-in bricks between the pattern bricks (docs/model.md 4.4, thesis 3.2.3).

Works in the flattened section (``s`` along the wall in units, course ``k = 1..L``).
Each course's pattern cells split ``[-W_k, W_k]`` into sequences; each sequence gets
regular bricks (4 units) and fill-in bricks for the remainder. The layout is
mirror-symmetric about ``s = 0``: a sequence left of the centre is filled and mirrored,
the centre sequence gets a symmetric fill. A ring of the dome of revolution
(:func:`fill_ring`) is filled by the same rules, mirror-symmetric in its meridians.

Joints are staggered: among the fills a sequence admits (the fill-in at either end or in
between, or split into two fill-ins), the one whose joints keep farthest from the joints of
the course below is chosen. What could not be staggered is counted and reported.
"""

from dataclasses import dataclass

import numpy as np

from masonry.blocks import BLOCK_CLASSES
from masonry.dome.pattern import Pattern
from masonry.tolerances import UNIT_SLACK

REGULAR = 4.0  # regular brick length, units

REG, PAT, FILL = (BLOCK_CLASSES.index(c) for c in ("regular", "pattern", "fill_in"))


@dataclass(frozen=True)
class Layout:
    """Bricks of a section in the flattened coordinates, one row per brick.

    Parameters
    ----------
    course : (B,) int
        Course the brick starts on (pattern bricks also cover ``course + 1``).
    s0, s1 : (B,) float
        Extent along the wall, units (nominal: mitered ends reach the corner planes).
    klass : (B,) int8
        Code into ``BLOCK_CLASSES`` (regular, pattern, fill_in).
    miter_left, miter_right : (B,) bool
        End bricks, clipped by the corner plane at ``-pi/n`` / ``+pi/n``.
    repeated_joints : (L,) int
        Per course, joints within one unit of a joint of the course below (pattern
        bricks excepted), docs/model.md 4.4's measure of staggering.
    short_fill_ins : int
        Fill-ins shorter than ``min_fill`` that could not be avoided (an end gap beside a
        pattern brick that is not the course's end brick).
    """

    course: np.ndarray
    s0: np.ndarray
    s1: np.ndarray
    klass: np.ndarray
    miter_left: np.ndarray
    miter_right: np.ndarray
    repeated_joints: np.ndarray
    short_fill_ins: int

    def __len__(self) -> int:
        return len(self.course)


def _split(length, min_fill):
    """Regular count and remainder of a sequence, the remainder >= min_fill or zero."""
    m = int(np.floor(length / REGULAR + UNIT_SLACK))
    rem = length - REGULAR * m
    if rem < UNIT_SLACK * max(length, 1.0):
        return m, 0.0
    if rem < min_fill and m > 0:
        return m - 1, rem + REGULAR
    return m, rem


def _side_candidates(length, min_fill):
    """Piece lengths (left to right) that fill a sequence of ``length`` units."""
    m, rem = _split(length, min_fill)
    if rem == 0:
        out = [[REGULAR] * m]
        if m >= 1:  # split a regular brick into two fill-ins, one at each end
            out.append([REGULAR / 2] + [REGULAR] * (m - 1) + [REGULAR / 2])
        return out
    out = [[REGULAR] * i + [rem] + [REGULAR] * (m - i) for i in range(m + 1)]
    if m >= 1:  # two fill-ins at the ends, one regular brick fewer
        total = rem + REGULAR
        for left in {total / 2, REGULAR / 2, total - REGULAR / 2}:
            if min(left, total - left) >= min_fill - UNIT_SLACK:
                out.append([left] + [REGULAR] * (m - 1) + [total - left])
    return out


def _half_fill(half, min_fill):
    """Pieces from the centre outward that fill ``half`` units with one end fill-in."""
    m, rem = _split(half, min_fill)
    return [REGULAR] * m + ([rem] if rem else [])


def _centre_candidates(length, min_fill):
    """Symmetric piece lengths filling a sequence centred on ``s = 0``."""
    half = length / 2
    out = []
    # a joint on the centre line
    side = _half_fill(half, min_fill)
    if side and min(side) >= min_fill - UNIT_SLACK:
        out.append(side[::-1] + side)
    # a regular brick across the centre line
    if half >= REGULAR / 2 - UNIT_SLACK:
        side = _half_fill(half - REGULAR / 2, min_fill)
        if not side or min(side) >= min_fill - UNIT_SLACK:
            out.append(side[::-1] + [REGULAR] + side)
    # a fill-in across the centre line, regular bricks to both ends
    j = int(np.floor((length - min_fill) / (2 * REGULAR) + UNIT_SLACK))
    middle = length - 2 * REGULAR * max(j, 0)
    if j >= 0 and min_fill - UNIT_SLACK <= middle < REGULAR + min_fill:
        out.append([REGULAR] * j + [middle] + [REGULAR] * j)
    return out or [[length]]


def _mirrored_candidates(length, min_fill):
    """Symmetric piece lengths filling a sequence centred on a mirror meridian: those of
    :func:`_centre_candidates`, and a joint on the meridian or a regular brick across it
    with any fill of :func:`_side_candidates` on either side."""
    out = _centre_candidates(length, min_fill)
    for middle in (0.0, REGULAR):
        side = (length - middle) / 2
        if side <= UNIT_SLACK or side < min_fill - UNIT_SLACK:
            continue
        out += [pieces[::-1] + ([middle] if middle else []) + pieces
                for pieces in _side_candidates(side, min_fill)]
    return out


def _joints(start, pieces):
    return start + np.cumsum(pieces)[:-1]


def _score(joints, below):
    """(repeated joints, -closest distance) of ``joints`` against the joints ``below``:
    smaller is better."""
    if len(joints) == 0 or len(below) == 0:
        return 0, 0.0
    d = np.abs(joints[:, None] - below[None, :]).min(axis=1)
    return int((d < 1 - UNIT_SLACK).sum()), -float(d.min())


def _is_regular(length) -> bool:
    return abs(length - REGULAR) <= UNIT_SLACK


def _choose(candidates, start, below):
    """The candidate whose joints repeat fewest joints below, then with the fewest
    fill-ins, then whose joints keep farthest from those below."""
    def key(pieces):
        repeated, closest = _score(_joints(start, pieces), below)
        fill_ins = sum(not _is_regular(x) for x in pieces)
        return repeated, fill_ins, closest
    return min(candidates, key=key)


def _lay(rows, course, start, pieces, miter_first, miter_last) -> list:
    """Append the bricks of ``pieces`` (lengths from ``start``) to ``rows``; return the
    joints between them."""
    edges = start + np.concatenate([[0.0], np.cumsum(pieces)])
    for i, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
        klass = REG if _is_regular(b - a) else FILL
        rows.append((course, a, b, klass, miter_first and i == 0,
                     miter_last and i == len(pieces) - 1))
    return list(edges[1:-1])


def _lay_pattern(rows, pattern: Pattern, cells, half_width, min_fill, miter) -> set:
    """Append the pattern bricks to ``rows``; return the ``(course, 'left' | 'right')``
    ends that a pattern brick takes as the mitered end brick.

    The outermost pattern brick on both its courses, within ``min_fill`` of the boundary
    on its upper course, becomes the mitered end brick of both courses.
    """
    n_courses = len(half_width)
    lo = [c[0] if c else np.inf for c in cells]
    hi = [c[-1] if c else -np.inf for c in cells]
    ends = set()
    for k, s in zip(pattern.course, pattern.s):
        upper = min(k + 1, n_courses)
        w = half_width[upper - 1]
        left = miter and s == lo[k - 1] == lo[upper - 1] and s + w < min_fill - UNIT_SLACK
        right = (miter and s == hi[k - 1] == hi[upper - 1]
                 and w - (s + 1) < min_fill - UNIT_SLACK)
        rows.append((k, float(s), float(s + 1), PAT, left, right))
        for c in {k, upper}:
            if left:
                ends.add((c, "left"))
            if right:
                ends.add((c, "right"))
    return ends


def _sequences(course, w, cells, pattern_ends) -> list:
    """The gaps of one course between its boundaries ``-w, w`` and its pattern cells
    (left edges ``cells``), as ``(start, end, at_left_boundary, at_right_boundary)``;
    a boundary gap taken by a mitered pattern brick is left out."""
    edges = [(-w, True)]
    for c in sorted(cells):
        edges += [(float(c), False), (float(c + 1), False)]
    edges.append((w, True))
    out = []
    for (u, u_bound), (v, v_bound) in zip(edges[0::2], edges[1::2]):
        if ((u_bound and (course, "left") in pattern_ends)
                or (v_bound and (course, "right") in pattern_ends)):
            continue  # absorbed by the mitered pattern brick
        if v - u > UNIT_SLACK:
            out.append((u, v, u_bound, v_bound))
    return out


def _pieces(candidates, start, length, below, min_fill):
    """The pieces of a sequence of ``length`` units from ``start``: the best of
    ``candidates(length, min_fill)`` against the joints ``below``, or one piece shorter
    than ``min_fill`` (then True) when the sequence is that short."""
    if length < min_fill - UNIT_SLACK:
        return [length], True
    return _choose(candidates(length, min_fill), start, below), False


def fill_ring(cells, half, ring, below, min_fill):
    """The regular and fill-in bricks of one period of a ring that is its own mirror image
    in the meridians ``s = j half`` (``s`` units along the ring, ``ring`` its length, a
    multiple of ``2 half``): their extents ``(s0, s1)`` on ``[-half, half]`` and beyond
    (a brick across ``s = half`` is the period's; the one across ``-half`` is its
    rotation), mirror-symmetric about ``s = 0`` and ``s = half``, and how many are
    shorter than ``min_fill``.

    ``cells`` (m, 2) the extents of the ring's pattern bricks (mirror-symmetric likewise),
    ``below`` the joints of the course below (units, any turn). A gap between cells across
    a mirror meridian gets a symmetric fill (a joint on the meridian, a regular brick or a
    fill-in across it); one between two meridians is filled and mirrored; a ring without
    cells is filled from meridian to meridian (:func:`_between_mirrors`). Each fill is
    chosen against the joints below as in :func:`fill_courses`."""
    def near(a):  # the joints below from a, on the nearest turn
        return np.mod(np.asarray(below, float) - a + ring / 2, ring) - ring / 2

    cells = np.asarray(cells, float).reshape(-1, 2)
    if len(cells) == 0:
        right, pieces = _between_mirrors(half, near(0.0), min_fill)
        rows = _extents(right - half, pieces) + ([(half - right, half + right)] if right
                                                  else [])
        return rows, sum(p < min_fill - UNIT_SLACK for p in pieces)
    cells = cells[np.argsort(cells[:, 0])]
    rows, short = [], 0
    for a, b in zip(cells[:, 1], np.append(cells[1:, 0], cells[0, 0] + ring)):
        middle = np.mod((a + b) / 2 + half, ring) - half
        a, b = a + middle - (a + b) / 2, b + middle - (a + b) / 2
        if b - a <= UNIT_SLACK or not -UNIT_SLACK <= middle <= half + UNIT_SLACK:
            continue  # the mirror image or a rotation of a gap laid here
        if min(abs(middle), abs(middle - half)) <= UNIT_SLACK:  # across a meridian
            pieces, too_short = _pieces(_mirrored_candidates, 0.0, b - a, near(a),
                                        min_fill)
            rows += _extents(a, pieces)
            short += too_short
        else:
            pieces, too_short = _pieces(_side_candidates, 0.0, b - a, near(a), min_fill)
            rows += _extents(a, pieces) + _extents(-b, pieces[::-1])
            short += 2 * too_short
    return rows, short


def _extents(start, pieces) -> list:
    """``(s0, s1)`` of ``pieces`` (lengths) laid from ``start``."""
    edges = start + np.concatenate([[0.0], np.cumsum(pieces)])
    return list(zip(edges[:-1], edges[1:]))


def _between_mirrors(length, below, min_fill) -> tuple:
    """The fill of a ring between mirror meridians ``length`` units apart, at ``s = 0``
    and ``s = length``: ``(right, pieces)``, ``right`` half the regular brick across
    ``s = length`` (0: a joint on it), ``pieces`` the lengths from ``right - length`` to
    ``length - right``, symmetric about ``s = 0`` (:func:`_mirrored_candidates`). Of
    these, the one whose joints (on the meridians too) repeat fewest of ``below``, then with a joint on one meridian and a brick across
    the other (the next course can then do the opposite: running bond on a short ring),
    then with fewest fill-ins, then whose joints keep farthest from those below."""
    candidates = []
    for right in (0.0, REGULAR / 2):
        side = length - right
        if side >= min_fill - UNIT_SLACK:
            candidates += [(right, pieces)
                           for pieces in _mirrored_candidates(2 * side, min_fill)]

    def key(candidate):
        right, pieces = candidate
        edges = right - length + np.concatenate([[0.0], np.cumsum(pieces)])
        joints = edges[edges >= -UNIT_SLACK]
        across = not np.isclose(joints, 0.0, atol=UNIT_SLACK).any()
        repeated, closest = _score(joints, below)
        return (repeated, across == (right > 0), sum(not _is_regular(x) for x in pieces),
                closest)

    return min(candidates, key=key) if candidates else (0.0, [2 * length])


def _fill_course(rows, course, sequences, below, min_fill, miter):
    """Append the regular and fill-in bricks of one course's ``sequences`` to ``rows``,
    mirror-symmetric about ``s = 0``; return its sorted joints and the number of fill-ins
    shorter than ``min_fill`` it could not avoid."""
    joints, short = [], 0
    for u, v, u_bound, v_bound in sequences:
        if v <= UNIT_SLACK:  # left half: fill, then mirror
            pieces, too_short = _pieces(_side_candidates, u, v - u, below, min_fill)
            short += 2 * too_short
            joints += _lay(rows, course, u, pieces, miter and u_bound, miter and v_bound)
            if u < -UNIT_SLACK or v < -UNIT_SLACK:  # its mirror image on the right
                joints += _lay(rows, course, -v, pieces[::-1], miter and v_bound,
                               miter and u_bound)
        elif u < -UNIT_SLACK:  # the centre sequence
            pieces, too_short = _pieces(_centre_candidates, u, v - u, below, min_fill)
            short += too_short
            joints += _lay(rows, course, u, pieces, miter and u_bound, miter and v_bound)
    return np.sort(np.array(joints)), short


def fill_courses(half_width, pattern: Pattern, min_fill: float = 1.0,
                 miter: bool = True) -> Layout:
    """Lay every course: pattern bricks, then regular and fill-in bricks between them.

    Parameters
    ----------
    half_width : (L,) float
        ``W_k`` (index ``k - 1``), units.
    pattern : Pattern
    min_fill : float
        Shortest fill-in, units (docs/model.md 4.4).
    miter : bool
        End bricks are clipped by the corner planes (a dome web); False for a straight wall.

    Returns
    -------
    Layout
        Every brick, sorted by course and position.
    """
    half_width = np.asarray(half_width, dtype=float)
    n_courses = len(half_width)
    rows = []  # (course, s0, s1, class, miter_left, miter_right)
    cells = pattern.cells(n_courses)
    pattern_ends = _lay_pattern(rows, pattern, cells, half_width, min_fill, miter)
    repeated = np.zeros(n_courses, int)
    short = 0
    below = np.zeros(0)
    for k in range(1, n_courses + 1):
        sequences = _sequences(k, half_width[k - 1], cells[k - 1], pattern_ends)
        joints, course_short = _fill_course(rows, k, sequences, below, min_fill, miter)
        repeated[k - 1] = _score(joints, below)[0]
        short += course_short
        below = joints
    return _layout(rows, repeated, short)


def _layout(rows, repeated, short) -> Layout:
    """The :class:`Layout` of brick ``rows`` ``(course, s0, s1, class, miter_left,
    miter_right)``, sorted by course and position."""
    rows = sorted(rows, key=lambda row: (row[0], row[1]))
    arr = list(zip(*rows)) if rows else [[]] * 6
    return Layout(
        course=np.array(arr[0], dtype=int),
        s0=np.array(arr[1], dtype=float),
        s1=np.array(arr[2], dtype=float),
        klass=np.array(arr[3], dtype=np.int8),
        miter_left=np.array(arr[4], dtype=bool),
        miter_right=np.array(arr[5], dtype=bool),
        repeated_joints=repeated,
        short_fill_ins=short,
    )
