"""The dome of revolution: the ``revolution`` scene (the whole dome) and the ``sector``
scene (one of its equal sectors), courses as closed horizontal rings and the double
helix as discrete loxodromes (docs/model.md 4.8).

Profile: the thesis's quarter ellipse (docs/model.md 4.2) with the apothem replaced by
the radius ``R``; contact points one unit apart along it. Every bed joint is the cone
normal to the intrados at its contact point (a plane at the springing; apex at the
centre for a sphere), so the bricks of consecutive courses share their beds exactly.
Head joints lie in meridian planes.

Longitude ``phi`` runs from +x toward +y. A brick of course ``k`` spans ``[phi0, phi1]``
and the levels ``k - 1`` to ``k`` (a pattern brick two courses, to ``k + 1``).

Pattern (docs/model.md 4.8): ``N`` start nodes on the springing ring, each starting a
right- and a left-handed line. A line's brick is one unit wide at its middle level and
each brick steps ``tan(beta)`` units sideways at the level between it and the one before
(``loxodrome``; ``clelia`` keeps the springing's longitude step). Lines of the two hands
meet side by side (a node) midway between their start nodes and go on past each other.
On the discrete lattice passing and bouncing lay the same bricks, so the pattern is one
line's zigzag between two mirror meridians, repeated about the dome: its rotations by
``2 pi / N`` and its mirror images. Where the nodes of a course come closer than
``2 (p + 1)`` units, the lines of every other node end there (``N`` halves; all end when
``N`` is odd): the dome's symmetry order is the last ``N``.

Courses: the gaps between pattern bricks, and the plain rings, are filled by the rules
of docs/model.md 4.4 (regular bricks of 4 units, fill-ins, joints staggered against the
course below), measured at the ring's top inner edge; rings are periodic with the dome's
symmetry and mirror-symmetric in the meridians every ``pi / N``, as the pattern is (it is
turned so that longitude 0 is one of them), no mitres.

Bricks as solids (convex, faces planar, shared exactly): a bed cone is replaced by its
chord facets between the head joints of the bricks below it, so a brick's top is one
facet and the brick above rests on the same facets (its bottom may span several: the
region above a bed cone is convex). Each brick is the convex hull of its corners.
"""

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np

from masonry.blocks import (GROUND, blocks_from_hulls, hull_faces, rotation_z,
                            whole_of_web)
from masonry.dome.courses import FILL, PAT, REG, Layout, fill_ring
from masonry.dome.levels import LevelTable, contact_angles, ellipse_point
from masonry.dome.pattern import Pattern
from masonry.errors import ParameterError
from masonry.parameters import declare
from masonry.scenes.base import Scene, SceneKind, Symmetry, ThrustSection
from masonry.tolerances import (BRICKS_PER_COURSE_AND_NODE, PATTERN_CHECKED_BRICKS,
                                REVOLUTION_UNITS_PER_BRICK, UNIT_SLACK, Tolerances)

DEPTH = {REG: 2.0, FILL: 2.0, PAT: 4.0}
"""Brick depth through the wall, units (a pattern brick stands proud: docs/model.md 4.5)."""

HELICES = ("loxodrome", "clelia")
PATTERNS = ("herringbone", "none")


@dataclass(frozen=True)
class RevolutionDome:
    """A dome of revolution with the double helix as loxodromes (docs/model.md 4.8);
    lengths in units of ``unit`` metres unless stated."""

    radius: float = declare(50.0, "units, radius of the intrados at the springing",
                            low=8.0, high=1e5, tag="R", head=True, names_geometry=True)
    stretch: float = declare(1.0, "dome height / radius", low=0.05, high=20.0, tag="s",
                             head=True, names_geometry=True)
    cut: float = declare(0.1, "fraction of the height cut off: the oculus",
                         check=lambda v: 0 < v < 1, tag="c", head=True, names_geometry=True,
                         expected="0 < cut < 1 (the loxodromes wind into the pole: a dome "
                                  "of revolution keeps an oculus)")
    p: int = declare(10, "pattern bricks per rhombus side: nodes 2(p + 1) units apart",
                     kind="int", check=lambda v: v >= 1, expected="an integer >= 1",
                     tag="p", head=True, names_geometry=True)
    unit: float = declare(0.1, "m, the brick unit", low=1e-3, high=1e2, tag="u", head=True,
                          names_geometry=True,
                          expected="0.001 to 100 (metres: bricks of 1 mm to 100 m; forces "
                                   "scale with unit^3)")
    spirals: int | None = declare(None, "start nodes on the springing ring (none: a "
                                  "multiple of 4, at least 2(p + 1) units apart)",
                                  kind="int", optional=True,
                                  check=lambda v: v >= 2, expected="an integer >= 2",
                                  tag="N", names_geometry=True)
    helix_angle: float = declare(45.0, "degrees between a pattern line and the meridian",
                                 low=45.0, high=80.0, tag="beta", names_geometry=True,
                                 expected="45 to 80 degrees (a pattern brick is one unit "
                                          "wide: a smaller step would overlap the one "
                                          "before)")
    helix: str = declare("loxodrome", "loxodrome (constant angle to the meridian) | clelia "
                         "(constant longitude step)", kind="str", choices=HELICES, tag="",
                         names_geometry=True)
    pattern: str = declare("herringbone", "herringbone | none (plain running bond)",
                           kind="str", choices=PATTERNS, tag="pat", names_geometry=True)
    min_fill: float = declare(1.0, "units, shortest fill-in brick",
                              check=lambda v: 0 < v <= 4,
                              expected="0 < min_fill <= 4 (units)", tag="mf",
                              names_geometry=True)


@dataclass(frozen=True)
class Profile:
    """The meridian: contact points ``(x, z)`` (metres) of levels ``0..L`` and the unit
    normals ``(nx, nz)`` of the intrados there (the bed cones' generators)."""

    x: np.ndarray
    z: np.ndarray
    nx: np.ndarray
    nz: np.ndarray

    @property
    def n_courses(self) -> int:
        return len(self.x) - 1


def profile_of(g: RevolutionDome) -> Profile:
    """The contact points of every course up to the oculus (docs/model.md 4.2, 4.8)."""
    a = g.radius * g.unit
    c = a * g.stretch
    theta = contact_angles(a, c, (1 - g.cut) * c, g.unit)
    x, z = ellipse_point(a, c, theta)
    x[0], z[0] = a, 0.0
    nx, nz = x / a**2, z / c**2
    length = np.hypot(nx, nz)
    return Profile(x, z, nx / length, nz / length)


# --------------------------------------------------------------------------- pattern
NODE_SPACING_MIN = 6
"""Fewest units between start nodes on the springing ring: two pattern bricks and a
regular brick."""


def default_spirals(g: RevolutionDome) -> int:
    """Start nodes at least ``2 (p + 1)`` units apart around the springing ring, and at
    least :data:`NODE_SPACING_MIN` (the least :func:`check_revolution` takes), a multiple
    of four (at least four), so that the lines can end twice at every other node and
    keep the dome's symmetry."""
    spacing = max(2 * (g.p + 1), NODE_SPACING_MIN)
    return max(4, 4 * int(2 * np.pi * g.radius / (4 * spacing)))


@dataclass(frozen=True)
class RingPattern:
    """The pattern bricks of the whole dome and what the rules did.

    ``course``, ``phi0``, ``phi1`` (P,) the pattern bricks (started on ``course``,
    spanning it and the next), ``node_step`` (P,) bool whether the brick closed a node
    (its step is longer than ``tan(beta)`` units, to stand beside its partner), ``line``
    (P,) its line (the start node's right-handed lines, then the left-handed ones);
    ``nodes`` and ``ended`` (M, 2) ``(course, phi)`` of every node and of the nodes where
    lines ended; ``order`` (L + 1,) the rotational symmetry of the bricks started on
    each course (index ``k``).
    """

    course: np.ndarray
    phi0: np.ndarray
    phi1: np.ndarray
    node_step: np.ndarray
    line: np.ndarray
    nodes: np.ndarray
    ended: np.ndarray
    order: np.ndarray

    @property
    def symmetry(self) -> int:
        """The whole dome's rotational symmetry: the order of its top courses."""
        return int(self.order[-1])


def _node_ring(course, meridian, count):
    """``(course, phi)`` of the ``count`` nodes of a course, one at ``meridian``."""
    return [(course, meridian + 2 * np.pi * j / count) for j in range(count)]


def _zigzag(g: RevolutionDome, prof: Profile, spirals: int):
    """One line's bricks ``(course, lo, hi, node, count, mirror)``, the nodes, the nodes
    where lines ended, and the symmetry order per course.

    The line leaves the start node at longitude 0 toward +phi and meets its mirror image
    about ``target`` side by side (a node); then it heads back, and its mirror images
    about its last node and its rotations by ``2 pi / count`` are the other lines."""
    x, u, L = prof.x, g.unit, prof.n_courses
    tan = max(np.tan(np.radians(g.helix_angle)), 1.0)  # 45 degrees: exactly one unit

    def step(level):  # the sideways step at a level, radians
        return tan * u / (x[level] if g.helix == "loxodrome" else x[0])

    order = np.zeros(L + 1, int)
    count, home, target, direction = spirals, 0.0, np.pi / spirals, 1
    lo, hi = 0.0, u / x[1]
    line, nodes, ended = [(1, lo, hi, False, count, home)], [], []
    for k in range(2, L):  # a brick started on course k spans k and k + 1 <= L
        width = u / x[k]
        anchor = (lo if direction > 0 else hi) + direction * step(k - 1)
        lo, hi = (anchor, anchor + width) if direction > 0 else (anchor - width, anchor)
        gap = 2 * (target - hi if direction > 0 else lo - target)
        closing = 2 * step(k) + 2 * (u / x[k + 1] - width)  # the next brick's approach
        if gap >= closing - UNIT_SLACK * width:
            line.append((k, lo, hi, False, count, home))
            continue
        # the next brick would pass its mirror image: stand beside it now, a node
        lo, hi = (target - width, target) if direction > 0 else (target, target + width)
        line.append((k, lo, hi, True, count, home))
        nodes += _node_ring(k, target, count)
        if 2 * np.pi / count * x[k] / u < 2 * (g.p + 1) - UNIT_SLACK:
            if count % 2:  # an odd ring cannot keep its symmetry: every line ends
                ended += _node_ring(k, target, count)
                break
            ended += _node_ring(k, target + 2 * np.pi / count, count // 2)
            count //= 2
        home, direction = target, -direction
        target = home + direction * np.pi / count
    for k, *_, n, _ in line:
        order[k] = n
    order[0], order[line[-1][0] + 1:] = spirals, count
    return line, nodes, ended, order


@functools.lru_cache(maxsize=16)
def ring_pattern(g: RevolutionDome) -> RingPattern:
    """The pattern bricks of the whole dome (none for ``pattern = 'none'``)."""
    prof = profile_of(g)
    spirals = g.spirals or default_spirals(g)
    nothing = np.zeros((0, 2))
    if g.pattern == "none" or prof.n_courses < 3:
        order = np.full(prof.n_courses + 1, spirals)
        return RingPattern(np.zeros(0, int), np.zeros(0), np.zeros(0), np.zeros(0, bool),
                           np.zeros(0, int), nothing, nothing, order)
    line, nodes, ended, order = _zigzag(g, prof, spirals)
    # turned so that the last lines' mirror meridian, a mirror of the whole pattern
    # (those of the lines below are a finer lattice through it), is longitude 0
    turn = line[-1][5]
    course, phi0, width, node_step, which = [], [], [], [], []
    for k, lo, hi, node, n, mirror in line:  # the line's brick's orbit on its course
        turns = 2 * np.pi * np.arange(n) / n - turn
        starts = np.concatenate([lo + turns, 2 * mirror - hi + turns])
        course.append(np.full(2 * n, k))
        phi0.append(starts)
        width.append(np.full(2 * n, hi - lo))
        node_step.append(np.full(2 * n, node))
        which.append(np.arange(2 * n))  # its rotations, then their mirror images
    course, phi0 = np.concatenate(course), np.mod(np.concatenate(phi0), 2 * np.pi)
    order_ = np.lexsort((phi0, course))
    phi0 = phi0[order_]
    nodes, ended = (np.array(at, float).reshape(-1, 2) - [0.0, turn] for at in (nodes, ended))
    return RingPattern(course[order_], phi0, phi0 + np.concatenate(width)[order_],
                       np.concatenate(node_step)[order_], np.concatenate(which)[order_],
                       nodes, ended, order)


# --------------------------------------------------------------------------- courses
@dataclass(frozen=True)
class Rings:
    """Every brick of the whole dome, one row each, sorted by course and longitude.

    ``course`` (B,) int the course it starts on; ``phi0``, ``phi1`` (B,) its longitudes
    (radians); ``klass`` (B,) int8 (regular, pattern, fill-in); ``repeated_joints``
    (L,) per course, joints within one unit of a joint below; ``short_fill_ins`` the
    fill-ins shorter than ``min_fill`` that could not be avoided; ``period`` the angle
    under which the rings repeat (``2 pi`` over the dome's symmetry)."""

    course: np.ndarray
    phi0: np.ndarray
    phi1: np.ndarray
    klass: np.ndarray
    repeated_joints: np.ndarray
    short_fill_ins: int
    period: float

    @property
    def top(self) -> np.ndarray:
        """(B,) the level of each brick's top: its course, a pattern brick's next one."""
        return self.course + (self.klass == PAT)


def _around(rows, period, count):
    """``rows`` ``(phi0, phi1, class)`` repeated ``count`` times by ``period``."""
    rows = np.array(rows, float).reshape(-1, 3)
    turns = np.repeat(np.arange(count) * period, len(rows))
    tiled = np.tile(rows, (count, 1))
    tiled[:, :2] += turns[:, None]
    return tiled


@functools.lru_cache(maxsize=16)
def rings_of(g: RevolutionDome) -> Rings:
    """Lay every ring of the whole dome: the pattern bricks, then regular and fill-in
    bricks in the gaps (docs/model.md 4.4, :func:`~masonry.dome.courses.fill_ring`),
    periodic with the dome's symmetry ``N`` and mirror-symmetric in the meridians
    ``j pi / N``, as the pattern is."""
    prof, pattern = profile_of(g), ring_pattern(g)
    count = pattern.symmetry
    period, start = 2 * np.pi / count, -np.pi / count
    pat = np.column_stack([pattern.phi0, pattern.phi1])
    rows = [np.column_stack([pat, np.full(len(pat), PAT)])]
    courses = [pattern.course]
    repeated, short = np.zeros(prof.n_courses, int), 0
    below = np.zeros(0)
    for k in range(1, prof.n_courses + 1):
        scale = prof.x[k] / g.unit
        here = (pattern.course == k) | (pattern.course == k - 1)
        cells = _cyclic_cells(pat[here], start)
        extents, too_short = fill_ring(cells * scale, period / 2 * scale, 2 * np.pi * scale,
                                       below * scale, g.min_fill)
        extents = np.array(extents, float).reshape(-1, 2) / scale
        regular = np.abs(np.diff(extents, axis=1)[:, 0] * scale - 4.0) <= UNIT_SLACK
        fills = np.column_stack([extents, np.where(regular, REG, FILL)])
        ring = _around(fills, period, count)
        rows.append(ring)
        courses.append(np.full(len(ring), k))
        joints = np.unique(np.mod(np.concatenate([ring[:, 0], pat[here, 0], pat[here, 1]]),
                                  2 * np.pi))
        repeated[k - 1] = _repeated(joints, below, scale)
        short += too_short * count
        below = joints
    rows, course = np.concatenate(rows), np.concatenate(courses)
    # from just below the first sector's start: a brick that starts on a sector's edge
    # (to rounding) belongs to the sector it starts
    slack = UNIT_SLACK * period
    phi0 = np.mod(rows[:, 0] - start + slack, 2 * np.pi) + start - slack
    order = np.lexsort((phi0, course))
    return Rings(course[order], phi0[order], (phi0 + rows[:, 1] - rows[:, 0])[order],
                 rows[order, 2].astype(np.int8), repeated, short, period)


def _cyclic_cells(cells, start):
    """``cells`` ``(phi0, phi1)`` with their starts in ``[start, start + 2 pi)``, sorted."""
    cells = np.array(cells, float).reshape(-1, 2)
    shift = np.mod(cells[:, 0] - start, 2 * np.pi) + start - cells[:, 0]
    cells = cells + shift[:, None]
    return cells[np.argsort(cells[:, 0])]


def _repeated(joints, below, scale) -> int:
    """Joints within one unit of a joint of the course below (docs/model.md 4.4)."""
    if len(joints) == 0 or len(below) == 0:
        return 0
    d = np.abs(np.mod(joints[:, None] - below[None, :] + np.pi, 2 * np.pi) - np.pi)
    return int((d.min(axis=1) * scale < 1 - UNIT_SLACK).sum())


# --------------------------------------------------------------------------- solids
def _level_grids(rings: Rings, levels: int, start: float) -> list:
    """Per level ``0..levels``, the sorted longitudes (in ``[start, start + 2 pi)``) of the
    head joints of the bricks whose top lies on it: where its bed's facets break."""
    top, slack = rings.top, UNIT_SLACK * rings.period
    grids = []
    for level in range(levels + 1):
        on = top == level
        edges = np.sort(np.mod(np.concatenate([rings.phi0[on], rings.phi1[on]]) - start,
                               2 * np.pi) + start)
        # one meridian where two bricks' edges meet to rounding
        grids.append(edges[np.concatenate([[True], np.diff(edges) > slack])[:len(edges)]])
    return grids


def _facet_factor(grid, phi, start):
    """(m,) the radial factor of the points at longitudes ``phi`` on a bed faceted at
    ``grid``: ``cos(h) / cos(phi - mid)`` on the chord facet ``mid +- h`` that holds
    them, 1 on the grid's meridians (and on an unfaceted bed)."""
    phi = np.asarray(phi, float)
    if len(grid) < 2:
        return np.ones(len(phi))
    ring = np.concatenate([grid[-1:] - 2 * np.pi, grid, grid[:1] + 2 * np.pi])
    wrapped = np.mod(phi - start, 2 * np.pi) + start
    i = np.clip(np.searchsorted(ring, wrapped), 1, len(ring) - 1)
    lo, hi = ring[i - 1], ring[i]
    half, mid = (hi - lo) / 2, (hi + lo) / 2
    factor = np.cos(half) / np.cos(wrapped - mid)
    on_grid = np.minimum(wrapped - lo, hi - wrapped) <= UNIT_SLACK * (hi - lo)
    return np.where(on_grid, 1.0, factor)


def _bed_points(prof: Profile, level, phi, factor, depth):
    """(m, 2, 3) the inner and outer points (metres) at longitudes ``phi`` on the bed cone
    of ``level``, its facets' radial ``factor``, ``depth`` metres deep."""
    out = np.empty((len(phi), 2, 3))
    for j, t in enumerate((0.0, depth)):
        rho = (prof.x[level] + t * prof.nx[level]) * factor
        out[:, j, 0], out[:, j, 1] = rho * np.cos(phi), rho * np.sin(phi)
        out[:, j, 2] = prof.z[level] + t * prof.nz[level]
    return out


def _brick_points(prof, grids, start, level0, level1, phi0, phi1, depth):
    """The corners (n, 3) of one brick: its bottom on the facets of ``level0`` between
    ``phi0`` and ``phi1`` (and at the facets' breaks between them), its top the one facet
    ``phi0``-``phi1`` of ``level1``."""
    grid = grids[level0]
    wrapped = np.mod(grid - phi0, 2 * np.pi) + phi0
    inner = np.sort(wrapped[(wrapped > phi0) & (wrapped < phi1)])
    keep = (inner - phi0 > UNIT_SLACK * (phi1 - phi0)) & (phi1 - inner > UNIT_SLACK
                                                           * (phi1 - phi0))
    phi = np.concatenate([[phi0], inner[keep], [phi1]])
    factor = _facet_factor(grid, phi, start) if level0 > 0 else np.ones(len(phi))
    bottom = _bed_points(prof, level0, phi, factor, depth)
    top = _bed_points(prof, level1, np.array([phi0, phi1]), np.ones(2), depth)
    return np.concatenate([bottom.reshape(-1, 3), top.reshape(-1, 3)])


def _ground_points(prof: Profile, start, period, unit):
    """The corners of the ground slab under one sector: its top the bed of level 0, one
    unit deep, from a chord inside the springing to a polygon outside the pattern
    bricks' feet."""
    inner, outer = prof.x[0] - unit, prof.x[0] + 5 * unit
    pieces = max(2, int(np.ceil(period / 0.05)))
    angle = start + period * np.arange(pieces + 1) / pieces
    rim = outer / np.cos(period / pieces / 2)
    ring = np.concatenate([np.column_stack([rim * np.cos(angle), rim * np.sin(angle)]),
                           inner * np.array([[np.cos(start), np.sin(start)],
                                             [np.cos(start + period),
                                              np.sin(start + period)]])])
    return np.concatenate([np.column_stack([ring, np.full(len(ring), z)])
                           for z in (0.0, -unit)])


def _course_directions(prof: Profile, level0, level1, middle):
    """(B, 3) the course direction (up the meridian, along the intrados chord) of bricks
    between ``level0`` and ``level1`` at longitudes ``middle``."""
    up = np.stack([prof.x[level1] - prof.x[level0], prof.z[level1] - prof.z[level0]], 1)
    up /= np.linalg.norm(up, axis=1)[:, None]
    c, s = np.cos(middle), np.sin(middle)
    return np.column_stack([up[:, 0] * c, up[:, 0] * s, up[:, 1]])


def build_sector(g: RevolutionDome, kind=None) -> Scene:
    """One sector of the dome (docs/model.md 4.8): its ground slab (block 0), then the
    bricks whose start lies in it (``[-pi / N, pi / N)`` for the dome's symmetry ``N``),
    by course and longitude; the whole dome is its ``N`` rotations."""
    check_revolution(g, pattern=True)
    prof, rings = profile_of(g), rings_of(g)
    start, period = -rings.period / 2, rings.period
    mine = rings.phi0 < start + period - UNIT_SLACK * period
    course, phi0, phi1 = rings.course[mine], rings.phi0[mine], rings.phi1[mine]
    klass, top = rings.klass[mine], rings.top[mine]
    grids = _level_grids(rings, prof.n_courses, start)
    depth = np.array([DEPTH[int(c)] for c in klass]) * g.unit
    points = [_ground_points(prof, start, period, g.unit)]
    points += [_brick_points(prof, grids, start, k - 1, t, a, b, d)
               for k, t, a, b, d in zip(course, top, phi0, phi1, depth)]
    tol = Tolerances.for_points(np.concatenate(points))
    from scipy.spatial import ConvexHull  # scipy loads with the first model built

    faces = [hull_faces(p, ConvexHull(p), tol.contact) for p in points]
    blocks = blocks_from_hulls(points, faces, np.concatenate([[GROUND], klass]),
                               None, block_course=np.concatenate([[0], course]))
    up = np.concatenate([[[0.0, 0.0, 1.0]], _course_directions(prof, course - 1, top,
                                                                 (phi0 + phi1) / 2)])
    return Scene(kind or Sector, g, blocks, _level_table(prof, period / 2, g.unit),
                 _pattern_record(g, prof), _layout(rings, mine, prof, g.unit), None, up)


def _level_table(prof: Profile, half_angle, unit) -> LevelTable:
    """The profile as a :class:`~masonry.dome.levels.LevelTable`: ``y`` the half width
    of the unrolled ring (metres at each level over ``half_angle``), for the pattern
    figure."""
    x, z = prof.x, prof.z
    incline = np.arctan2(x[:-1] - x[1:], z[1:] - z[:-1])
    two = np.full(len(incline), np.nan)
    two[:-1] = np.arctan2(x[:-2] - x[2:], z[2:] - z[:-2])
    height = np.full(len(incline), np.nan)
    height[:-1] = np.hypot(x[2:] - x[:-2], z[2:] - z[:-2])
    return LevelTable(theta=np.arctan2(z, x), x=x, y=x * half_angle, z=z,
                      gamma_reg=incline, gamma_pat=two, pattern_height=height)


def _layout(rings: Rings, mine, prof: Profile, unit) -> Layout:
    """The sector's bricks unrolled: ``s`` the arc length (units) on the top inner edge
    of the course a brick starts on, from the sector's middle meridian."""
    scale = prof.x[rings.course[mine]] / unit
    none = np.zeros(int(mine.sum()), bool)
    return Layout(course=rings.course[mine], s0=rings.phi0[mine] * scale,
                  s1=rings.phi1[mine] * scale, klass=rings.klass[mine], miter_left=none,
                  miter_right=none, repeated_joints=rings.repeated_joints,
                  short_fill_ins=rings.short_fill_ins)


def _pattern_record(g: RevolutionDome, prof: Profile) -> Pattern:
    """The whole dome's pattern report (docs/model.md 4.8): its pattern bricks, nodes and
    line ends, ``s`` in units on their course's ring from longitude 0; two lines end at
    every node where lines ended (one row each)."""
    pattern = ring_pattern(g)

    def at(course, phi):
        course = np.asarray(course, int)
        return np.column_stack([course, np.asarray(phi) * prof.x[course] / g.unit])

    ended = np.repeat(pattern.ended, 2, axis=0)
    return Pattern(course=pattern.course, s=at(pattern.course, pattern.phi0)[:, 1],
                   line=pattern.line,
                   nodes=at(pattern.nodes[:, 0], pattern.nodes[:, 1]),
                   near_nodes=np.zeros((0, 2)), boundary_bounces=np.zeros((0, 2)),
                   ended=at(ended[:, 0], ended[:, 1]))


def whole_dome(section: Scene, kind) -> Scene:
    """The whole dome: ``section`` (a sector of the dome's symmetry order ``N``) and its
    ``N - 1`` rotations, sector after sector, each brick named after its sector
    (``w<sector>_<name>``: :func:`~masonry.blocks.whole_of_web`)."""
    n = kind.symmetry(section.geometry).order
    blocks = whole_of_web(section.blocks, n, rename_first=True)
    up = np.concatenate([section.block_up @ rotation_z(2 * np.pi * j / n).T
                         for j in range(n)])
    return dataclasses.replace(section, kind=kind, blocks=blocks, block_up=up)


# --------------------------------------------------------------------------- kinds
def intrados_bricks(g: RevolutionDome) -> float:
    """The whole dome's bricks from its intrados (the zone of the ellipsoid up to the
    oculus, in square units) and its meridian's length ``L`` (units, about its courses):
    the area over :data:`~masonry.tolerances.REVOLUTION_UNITS_PER_BRICK` and
    :data:`~masonry.tolerances.BRICKS_PER_COURSE_AND_NODE` per course and start node
    (pattern bricks and the fill-ins beside them; a plain dome's fill-ins, one per
    course and period)."""
    with np.errstate(all="ignore"):
        a = g.radius
        c = a * g.stretch
        theta = np.linspace(0.0, np.arcsin(1 - g.cut), 257)
        arc = np.hypot(a * np.sin(theta), c * np.cos(theta))
        f = 2 * np.pi * a * np.cos(theta) * arc
        area = float(np.sum((f[1:] + f[:-1]) / 2 * np.diff(theta)))
        length = float(np.sum((arc[1:] + arc[:-1]) / 2 * np.diff(theta)))
    nodes = g.spirals or default_spirals(g)
    per_node = BRICKS_PER_COURSE_AND_NODE if g.pattern == "herringbone" else 1.0
    return area / REVOLUTION_UNITS_PER_BRICK + per_node * length * nodes


def estimated_symmetry(g: RevolutionDome) -> int:
    """The dome's symmetry order (:attr:`RingPattern.symmetry`) from the continuous
    helix instead of the lattice of bricks, in time independent of the dome's size: a
    line travels ``pi / N`` of longitude from node to node (``tan(beta) / x`` per unit
    of meridian for a loxodrome, ``tan(beta) / R`` for a clelia), and at a node where the
    ``N`` nodes of the ring come closer than ``2 (p + 1)`` units ``N`` halves (an odd
    ``N`` ends every line), as :func:`ring_pattern` lays them."""
    count = g.spirals or default_spirals(g)
    if g.pattern == "none":
        return count
    with np.errstate(all="ignore"):
        a = g.radius
        theta = np.linspace(0.0, np.arcsin(1 - g.cut), 4097)
        x = a * np.cos(theta)
        ds = np.hypot(a * np.sin(theta), a * g.stretch * np.cos(theta)) * np.diff(theta)[0]
        tan = max(np.tan(np.radians(g.helix_angle)), 1.0)
        rate = tan / (x if g.helix == "loxodrome" else np.full(len(x), a))
        phi = np.concatenate([[0.0], np.cumsum((rate[1:] + rate[:-1]) / 2 * ds[1:])])
    travelled = np.pi / count
    while (k := int(np.searchsorted(phi, travelled))) < len(phi):
        if 2 * np.pi / count * x[k] < 2 * (g.p + 1):
            if count % 2:
                break
            count //= 2
        travelled += np.pi / count
    return count


def check_revolution(g: RevolutionDome, pattern=None) -> None:
    """Refuse a dome of fewer than three courses, more start nodes than its springing
    ring holds (two pattern bricks and a regular brick between nodes), or sectors too
    narrow at the oculus for a regular brick.

    The last check lays the whole dome's pattern (:func:`ring_pattern`), which takes
    time and memory in proportion to the dome's bricks: by default (``pattern`` None) it
    runs only on a dome estimated at most :data:`~masonry.tolerances.PATTERN_CHECKED_BRICKS`
    bricks, so that a dome too large to build is refused by its size
    (:func:`masonry.scenes.check_size`) at once; building runs it always (True)."""
    if g.radius * np.arcsin(1 - g.cut) < 3:
        raise ParameterError("cut", g.cut, "a dome at least three courses high; lower cut",
                             related=("radius", "stretch"))
    spirals = g.spirals or default_spirals(g)
    if 2 * np.pi * g.radius / spirals < NODE_SPACING_MIN and g.pattern == "herringbone":
        raise ParameterError("spirals", spirals, f"at most "
                             f"{int(2 * np.pi * g.radius / NODE_SPACING_MIN)} "
                             f"start nodes on a springing ring of radius {g.radius:g} units "
                             "(two pattern bricks and a regular brick between nodes)",
                             related=("radius", "p"))
    if pattern is None:
        pattern = intrados_bricks(g) <= PATTERN_CHECKED_BRICKS
    if not pattern:
        return
    prof = profile_of(g)
    top, sectors = prof.x[-1] / g.unit, ring_pattern(g).symmetry
    if 2 * np.pi * top / sectors < 4:
        raise ParameterError("spirals", spirals, f"fewer sectors at the oculus: its ring "
                             f"(radius {top:.3g} units) holds {2 * np.pi * top / 4:.3g} "
                             f"regular bricks and the dome repeats {sectors} times; raise "
                             "cut or lower spirals", related=("cut", "radius", "p"))


class Sector(SceneKind):
    """``sector``: one of the dome of revolution's equal sectors, free-standing or with
    its neighbours as a boundary (docs/model.md 4.8, 6.4)."""

    name = "sector"
    geometry = RevolutionDome
    boundaries = ("free", "rigid", "cyclic")
    unit_word = "sector"
    crown = True
    moved_for_cad = False  # the bricks share their beds: the printed body needs no offset
    pattern_axis = ("arc length s along the ring (its top inner edge) from the sector's "
                    "middle [units]")
    pattern_ends = "their nodes came closer than 2(p + 1) units"
    summary = "one sector of the dome of revolution (see --boundary)"

    @classmethod
    def build(cls, geometry) -> Scene:
        return build_sector(geometry, cls)

    @classmethod
    def check(cls, geometry):
        check_revolution(geometry)

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        return intrados_bricks(geometry) / estimated_symmetry(geometry)

    @classmethod
    def id_prefix(cls, geometry, boundary) -> str:
        return f"sector{int(boundary != 'free')}"

    @classmethod
    def symmetry(cls, geometry) -> Symmetry:
        """Rotations by the sector's angle; no mirror plane (docs/model.md 6.11): the
        dome is its own mirror image in its middle meridian, but a brick across one of
        the sector's edges is the sector's and the one across the other its
        neighbour's."""
        return Symmetry(order=ring_pattern(geometry).symmetry, unit=True)

    @classmethod
    def thrust_section(cls, scene) -> ThrustSection:
        return ThrustSection(0.0, 2, (0.0, float(scene.blocks.bounds[0, 2])), True,
                             "y = 0 m")

    @classmethod
    def describe(cls, boundary) -> str:
        return f"sector, boundary {boundary}"

    @classmethod
    def pattern_caption(cls, geometry) -> str:
        return f"one sector of {ring_pattern(geometry).symmetry}, unrolled"

    @classmethod
    def edge_blocks(cls, scene) -> tuple:
        """The blocks within one brick of the sector's edges (the ground slab at both)."""
        rings = rings_of(scene.geometry)
        start, period = -rings.period / 2, rings.period
        mine = rings.phi0 < start + period - UNIT_SLACK * period
        phi0, phi1 = rings.phi0[mine], rings.phi1[mine]
        reach = float(np.max(rings.phi1 - rings.phi0)) * 1.5
        ground = np.ones(1, bool)
        return (np.concatenate([ground, phi0 < start + reach]),
                np.concatenate([ground, phi1 > start + period - reach]))


class Revolution(Sector):
    """``revolution``: the whole dome of revolution, its sectors explicitly."""

    name = "revolution"
    boundaries = ("free",)
    id_prefix_name = "revolution"
    summary = "the whole dome of revolution (courses as rings, the helix as loxodromes)"

    @classmethod
    def build(cls, geometry) -> Scene:
        return whole_dome(build_sector(geometry, cls), cls)

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        return intrados_bricks(geometry)

    @classmethod
    def id_prefix(cls, geometry, boundary) -> str:
        return cls.id_prefix_name

    @classmethod
    def symmetry(cls, geometry) -> Symmetry:
        """Rotations by ``2 pi / N``; the meridian planes every ``pi / N``: the middle and
        the edges of every sector (the rings are laid mirror-symmetric in them, as the
        pattern is)."""
        n = ring_pattern(geometry).symmetry
        return Symmetry(order=n, unit=False, mirrors=tuple(180.0 * k / n for k in range(n)))

    @classmethod
    def describe(cls, boundary) -> str:
        return "dome of revolution"

    @classmethod
    def pattern_caption(cls, geometry) -> str:
        return f"sector 0 of {ring_pattern(geometry).symmetry}, unrolled"
