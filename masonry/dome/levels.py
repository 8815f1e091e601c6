"""The level table: where each course meets the intrados (docs/model.md 4.1, 4.2; thesis 3.2.1).

The intrados of one web, in its mid-plane, is the quarter ellipse
``x = a cos(theta), z = c sin(theta)``. Course ``l`` starts at the contact point
``(x_{l-1}, z_{l-1})`` and ends where the circle of radius one unit around it meets the
ellipse higher up. The root is found in the ellipse's angle with a bracketed solver: the
distance from a point of the quadrant to the points above it grows monotonically, so the
bracket ``[theta_{l-1}, pi/2]`` holds exactly one root (the thesis's quartic has two real
roots and needs the right one picked; this form cannot pick the wrong one).
"""

from dataclasses import dataclass

import numpy as np

from masonry.tolerances import LEVEL_ANGLE_XTOL, LEVEL_TOP_REL


@dataclass(frozen=True)
class Dimensions:
    """Dome dimensions in metres (docs/model.md 4.1).

    ``width`` side of the polygon at ground level, ``radius`` its circumradius, ``a`` the
    apothem (intrados of the web at the ground), ``b`` half the side, ``c`` dome height,
    ``z_max`` the modeled height ``(1 - cut) c``.
    """

    width: float
    radius: float
    a: float
    b: float
    c: float
    z_max: float

    @classmethod
    def of(cls, params) -> "Dimensions":
        """The dimensions of a polygonal dome's geometry (its ``stretch``, ``n``, ``r``,
        ``p``, ``cut`` and ``unit``: :class:`masonry.scenes.polygonal.PolygonalDome`)."""
        width = 2 * (params.p + 1) * (params.r + 1) * params.unit
        radius = width / (2 * np.sin(np.pi / params.n))  # thesis eq. 3.3 prints sin(pi/2)
        a = width / 2 / np.tan(np.pi / params.n)
        c = radius * params.stretch
        return cls(width, radius, a, width / 2, c, (1 - params.cut) * c)


@dataclass(frozen=True)
class LevelTable:
    """One row per level ``l = 0..L`` (contact points), one per course ``k = 1..L``.

    Parameters
    ----------
    theta : (L + 1,) float
        Ellipse angle of each contact point.
    x, y, z : (L + 1,) float, metres
        Contact point ``(x_l, z_l)`` in the mid-plane and the web's half width
        ``y_l = x_l tan(pi/n)`` there.
    gamma_reg, gamma_pat : (L,) float, radians
        Inward inclination from vertical of a regular brick on course ``k`` (index
        ``k - 1``; the chord of one unit) and of a pattern brick started on course ``k``
        (the chord from ``(x_{k-1}, z_{k-1})`` to ``(x_{k+1}, z_{k+1})`` across the two
        courses it spans; NaN on the top course).
    pattern_height : (L,) float, metres
        Length of that two-course chord: the height of a pattern brick.

    Notes
    -----
    Thesis 3.2.1 takes ``gamma_pat`` from a circle of radius two units. A two-unit brick posed
    that way ends slightly above ``(x_{k+1}, z_{k+1})`` (two chords of one unit are shorter
    than one chord of two) and bites up to 3e-7 of its volume into the course above, and
    the intrados gets a step there. The two-course chord keeps the intrados continuous and
    the bricks disjoint; it is shorter than two units by less than 4e-4 of a unit on the
    thesis structures (``tests/test_model.py`` measures it; docs/model.md 4.2).
    """

    theta: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    gamma_reg: np.ndarray
    gamma_pat: np.ndarray
    pattern_height: np.ndarray

    @property
    def n_courses(self) -> int:
        return len(self.x) - 1

    @property
    def wedge_angles(self) -> np.ndarray:
        """Angles (radians) of the wedges between touching bricks of consecutive courses:
        course 1 on the ground, course k on course k - 1, and a pattern brick on the
        course below it and under the course above it (the gaps thesis 3.2.4 closes)."""
        reg, pat = self.gamma_reg, self.gamma_pat[:-1]
        below = np.concatenate([[0.0], reg[:-1]])  # what each course stands on
        above = reg[2:]  # what stands on a pattern brick started one course lower
        parts = [reg - below, pat - below[: len(pat)], above - pat[: len(above)]]
        return np.abs(np.concatenate(parts))

    @property
    def course_wedge_angles(self) -> np.ndarray:
        """Angles (radians) of the wedges of a dome without pattern bricks
        (docs/model.md 4.9): course 1 on the ground and course k on course k - 1, the
        first :attr:`n_courses` of :attr:`wedge_angles`."""
        return self.wedge_angles[: self.n_courses]


def ellipse_point(a, c, theta):
    """``(x, z)`` of the quarter ellipse at angle ``theta``."""
    return np.array([a * np.cos(theta), c * np.sin(theta)])


def _next_theta(a, c, theta0, radius):
    """Ellipse angle of the point at chord distance ``radius`` above ``theta0``, or None."""
    p0 = ellipse_point(a, c, theta0)

    def gap(theta):
        return np.hypot(*(ellipse_point(a, c, theta) - p0)) - radius

    if gap(np.pi / 2) < 0:
        return None
    from scipy.optimize import brentq  # scipy loads with the first model built

    return brentq(gap, theta0, np.pi / 2, xtol=LEVEL_ANGLE_XTOL, rtol=4 * np.finfo(float).eps)


def _inclination(p0, p1):
    return np.arctan2(p0[0] - p1[0], p1[1] - p0[1])


def contact_angles(a, c, z_max, unit, fits=None) -> np.ndarray:
    """Ellipse angles of the contact points ``(a cos theta, c sin theta)`` one chord of
    ``unit`` apart, from the ground up to ``z_max`` (docs/model.md 4.2).

    Parameters
    ----------
    a, c : float, metres
        The quarter ellipse's horizontal and vertical half axes.
    z_max : float, metres
        No contact point above it (``(1 + LEVEL_TOP_REL) z_max`` still counts).
    unit : float, metres
        The chord between consecutive contact points.
    fits : callable, optional
        ``fits(x) -> bool`` of a contact point's horizontal distance ``x``: the walk
        stops before the first point where it is False (a course too narrow for a
        brick).
    """
    thetas = [0.0]
    z_limit = z_max * (1 + LEVEL_TOP_REL)
    while True:
        theta1 = _next_theta(a, c, thetas[-1], unit)
        if theta1 is None:
            break
        x1, z1 = ellipse_point(a, c, theta1)
        if z1 > z_limit or (fits is not None and not fits(x1)):
            break
        thetas.append(theta1)
    return np.array(thetas)


def level_table(params, dims: Dimensions | None = None) -> LevelTable:
    """Contact points of every course up to ``z_max`` (docs/model.md 4.2).

    Levels stop where the next contact point would pass ``(1 - cut) c`` or the web gets
    narrower than ``min_fill`` across (no brick fits).
    """
    dims = Dimensions.of(params) if dims is None else dims
    a, c, h = dims.a, dims.c, params.unit
    tan = np.tan(np.pi / params.n)
    theta = contact_angles(a, c, dims.z_max, h,
                           fits=lambda x: 2 * x * tan >= params.min_fill * h)
    x, z = ellipse_point(a, c, theta)
    x[0], z[0] = a, 0.0  # exact ground point
    points = np.stack([x, z])
    gamma_reg = _inclination(points[:, :-1], points[:, 1:])
    gamma_pat = np.full(len(gamma_reg), np.nan)
    gamma_pat[:-1] = _inclination(points[:, :-2], points[:, 2:])
    pattern_height = np.full(len(gamma_reg), np.nan)
    pattern_height[:-1] = np.hypot(*(points[:, 2:] - points[:, :-2]))
    return LevelTable(theta=theta, x=x, y=x * tan, z=z, gamma_reg=gamma_reg,
                      gamma_pat=gamma_pat, pattern_height=pattern_height)
