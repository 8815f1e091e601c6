"""The least lateral load factor between sampled azimuths (``--lateral all``,
docs/model.md 6.8): Brent's method on every bracket between two samples where a smaller
factor may lie.

By the kinematic theorem the factor at the azimuth ``theta`` is the least, over the
mechanisms ``y`` (a cone that does not depend on ``theta``), of
``D(y) / (a(y) cos theta + b(y) sin theta)``: ``D`` the dead load's resisting work,
``a`` and ``b`` the work of the lateral loads at 0 and 90 degrees (the load at ``theta``
is their combination by ``cos`` and ``sin``). So ``h(theta) = 1 / lambda(theta)`` is the
support function of a convex set of the plane, the points ``(a, b) / D``, and two
samples bound it between them: the set lies in the half-planes ``p . u(theta_i) <= h_i``,
so between ``theta_1`` and ``theta_2`` (less than 180 degrees apart) ``h`` is at most
the corner of the two half-planes seen along ``u(theta)``; its inverse is a floor under
the factor there (:func:`floor_between`). Every bracket whose floor lies below the least
factor found, and that has an end at or near the least
(:data:`~masonry.tolerances.AZIMUTH_NEAR_LEAST_REL`), is searched by Brent's method
(:func:`scipy.optimize.minimize_scalar`, bounded), and then again on the brackets its
points leave, until every such floor is within
:data:`~masonry.tolerances.AZIMUTH_REFINE_REL` of the least. Brackets away from the least
are not searched: each point costs a collapse program on the whole model, and on a
large dome the loose floors of far brackets would ask for hundreds.

The azimuth tolerance follows from the factor's: the least of the branches
``D / (R cos(theta - phi))`` has its local minima where one branch has its own (two
branches cross at a peak, never at a dip), and there ``lambda = lambda_min /
cos(theta - phi)``: an azimuth within ``delta`` radians of it is within ``delta^2 / 2``
(relative) of its factor.
"""

import logging

import numpy as np
from scipy.optimize import minimize_scalar

from masonry.rbe.solvers.base import UNBOUNDED
from masonry.tolerances import AZIMUTH_NEAR_LEAST_REL, AZIMUTH_REFINE_REL

__all__ = ["floor_between", "refine_least", "search_factor"]

log = logging.getLogger(__name__)

XATOL_DEG = float(np.degrees(np.sqrt(2.0 * AZIMUTH_REFINE_REL)))
"""Brent's azimuth tolerance, degrees: within it of a local minimum the factor is within
:data:`~masonry.tolerances.AZIMUTH_REFINE_REL` of the minimum's (module docstring)."""

ROUNDS = 4
"""Searches of the brackets left after the one before, at most: the first finds the
local minimum in its bracket, the next the rare second one that bracket held."""

MAX_SOLVES = 8
"""Collapse programs a refinement solves at the most (each one on the whole model, off
the mirror planes): the 72-brick dome of the tests needs 7; on a large dome each costs
more than the sampled azimuths together, which the dome's symmetries solve on halves.
Past it the least factor found is kept, and the log says so."""


class _NoFactor(Exception):
    """A solve inside a bracket gave no factor (or an unbounded one): that bracket's
    search ends."""


def floor_between(azimuth_1, factor_1, azimuth_2, factor_2) -> float:
    """A lower bound of the lateral load factor between two azimuths (degrees,
    ``0 < azimuth_2 - azimuth_1 < 180``) of factors ``factor_1``, ``factor_2`` (> 0;
    ``inf``: no factor bounds the load there), by the support function's bound (module
    docstring). Returns ``inf`` where every load in between is carried at every factor."""
    width = np.radians(azimuth_2 - azimuth_1)
    h_1, h_2 = 1.0 / factor_1, 1.0 / factor_2
    # h(theta_1 + t) <= h_1 cos t + (h_2 - h_1 cos w) / sin w sin t = R cos(t - psi)
    along = (h_2 - h_1 * np.cos(width)) / np.sin(width)
    psi = np.arctan2(along, h_1)
    top = np.hypot(h_1, along) if 0.0 <= psi <= width else max(h_1, h_2)
    return np.inf if top <= 0.0 else 1.0 / top


def search_factor(result) -> float | None:
    """A collapse result's factor for :func:`refine_least`: ``inf`` when no factor bounds
    the load, None when the solve gave no verdict."""
    if result.load_factor is None and result.status == UNBOUNDED:
        return np.inf
    return result.load_factor


def refine_least(samples, factor_at, key=None) -> list:
    """Points that refine the least of ``samples`` ((azimuth in degrees, factor) pairs;
    factor None where the solve gave none, ``inf`` where no factor bounds the load) by
    calling ``factor_at(azimuth) -> float or None`` (the same meaning) inside the
    brackets between consecutive sampled azimuths, around the circle, where a smaller
    factor than the least found may lie (module docstring). ``key(azimuth)`` names the
    orbit of an azimuth under the structure's symmetries (equal keys, equal factors):
    of brackets that map onto each other only one is searched. Returns the new
    ``(azimuth, factor)`` pairs, in the order solved, azimuths in [0, 360)."""
    points = {float(a) % 360.0: f for a, f in samples}
    searched, new = set(), []
    for _ in range(ROUNDS):
        brackets = _open_brackets(points, key, searched)
        if not brackets:
            log.info("lateral search: %d azimuths refined", len(new))
            return new
        for low, high, name in brackets:
            if len(new) >= MAX_SOLVES:
                log.warning("lateral search: refinement stopped after %d solves; the least "
                            "factor found is kept", len(new))
                return new
            searched.add(name)
            new += _brent(low, high, points, factor_at, MAX_SOLVES - len(new))
    if _open_brackets(points, key, searched):
        log.warning("lateral search: brackets still open after %d rounds of Brent's "
                    "method; the least factor found is kept", ROUNDS)
    return new


def _open_brackets(points, key, searched) -> list:
    """``(low, high, name)`` of the brackets between consecutive azimuths of ``points``
    whose floor lies below the least factor by more than the tolerance, not yet
    ``searched`` (by ``name``: the key of its middle and its width); ``high`` may pass 360."""
    known = {a: f for a, f in points.items() if f is not None}
    finite = [f for f in known.values() if np.isfinite(f)]
    if len(known) < 2 or not finite or min(finite) <= 0.0:
        return []
    least = min(finite)
    angles = sorted(known)
    out = {}
    for low, high in zip(angles, angles[1:] + [angles[0] + 360.0]):
        if not 0.0 < high - low < 180.0:
            continue
        middle = 0.5 * (low + high) % 360.0
        name = (round(middle, 9) if key is None else key(middle), round(high - low, 9))
        ends = (known[low], known[high % 360.0])
        if min(ends) > least * (1.0 + AZIMUTH_NEAR_LEAST_REL):
            continue  # not beside the least: its floor is a bound, not searched
        floor = floor_between(low, ends[0], high, ends[1])
        if name not in searched and floor < least * (1.0 - AZIMUTH_REFINE_REL):
            out.setdefault(name, (low, high, name))
    return list(out.values())


def _brent(low, high, points, factor_at, budget) -> list:
    """Brent's method on the bracket ``[low, high]`` (degrees), ``budget`` solves at the
    most; every point it solves goes into ``points`` and the returned list."""
    new = []

    def factor(azimuth):
        if len(new) >= budget:
            raise _NoFactor
        value = factor_at(azimuth % 360.0)
        points[azimuth % 360.0] = value
        new.append((azimuth % 360.0, value))
        if value is None or not np.isfinite(value):
            raise _NoFactor
        return value

    try:
        minimize_scalar(factor, bounds=(low, high), method="bounded",
                        options={"xatol": XATOL_DEG})
    except _NoFactor:
        if len(new) < budget:
            log.warning("lateral search: no finite factor at %.6g deg; the bracket %.6g to "
                        "%.6g deg is not searched further", new[-1][0], low, high % 360.0)
    return new
