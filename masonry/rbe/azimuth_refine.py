"""The least lateral load factor between sampled azimuths (``--lateral all``,
docs/model.md 6.8): the tangents of the support function ``1 / lambda`` cut at their
corners.

By the kinematic theorem the factor at the azimuth ``theta`` is the least, over the
mechanisms ``y`` (a cone that does not depend on ``theta``), of
``D(y) / (a(y) cos theta + b(y) sin theta)``: ``D`` the dead load's resisting work,
``a`` and ``b`` the work of the lateral loads at 0 and 90 degrees (the load at ``theta``
is their combination by ``cos`` and ``sin``). So ``h(theta) = 1 / lambda(theta)`` is the
support function of a convex set ``S`` of the plane, the points ``(a, b) / D``, and the
least factor is ``1 / max |p|`` over ``S``. Each solved azimuth gives a tangent: ``S``
lies in the half-plane ``p . u(theta) <= h(theta)``, so between ``theta_1`` and
``theta_2`` (less than 180 degrees apart) ``h`` is at most the corner of the two tangents
seen along ``u(theta)``; its inverse is a floor under the factor there
(:func:`floor_between`).

Every bracket between two solved azimuths whose floor lies below the least factor found,
and that has an end at a sample near the least sampled
(:data:`~masonry.tolerances.AZIMUTH_NEAR_LEAST_REL`) or at a cut, is cut at its corner's
direction, the lowest floor first: the solve there either finds a smaller factor or
moves the tangent in and lifts the floor (the outer approximation of a sandwich
algorithm, G. Rote, Computing 48, 1992). Where the farthest point of ``S`` is a vertex,
as an LP's set has, finitely many cuts reach it: once the tangents on either side pass
through it, the floors there are its factor, exact; where ``S`` is smooth (a family of
mechanisms) a floor's gap falls with the square of its bracket's width. The cuts go on
until every such floor is within a tolerance of the least found (the accuracy preset's
``azimuth_rel``, :data:`~masonry.tolerances.AZIMUTH_REFINE_REL` unless fast). Brackets
away from the least are not searched: each cut costs a collapse program on the whole model,
and on a large dome the loose floors of far brackets would ask for hundreds.
"""

import logging

import numpy as np

from masonry.rbe.solvers.base import UNBOUNDED
from masonry.tolerances import AZIMUTH_NEAR_LEAST_REL, AZIMUTH_REFINE_REL

__all__ = ["floor_between", "refine_least", "search_factor"]

log = logging.getLogger(__name__)

MAX_SOLVES = 8
"""Collapse programs a refinement solves at the most (each one on the whole model, off
the mirror planes). Past it the least factor found is kept, and the log says so."""


def floor_between(azimuth_1, factor_1, azimuth_2, factor_2) -> float:
    """A lower bound of the lateral load factor between two azimuths (degrees,
    ``0 < azimuth_2 - azimuth_1 < 180``) of factors ``factor_1``, ``factor_2`` (> 0;
    ``inf``: no factor bounds the load there), by the support function's bound (module
    docstring). Returns ``inf`` where every load in between is carried at every factor."""
    return _corner(azimuth_1, factor_1, azimuth_2, factor_2)[0]


def _corner(azimuth_1, factor_1, azimuth_2, factor_2) -> tuple:
    """``(floor, azimuth)``: :func:`floor_between` and the azimuth (degrees) of the
    tangents' corner (where the floor is reached when it lies inside the bracket)."""
    width = np.radians(azimuth_2 - azimuth_1)
    h_1, h_2 = 1.0 / factor_1, 1.0 / factor_2
    # h(theta_1 + t) <= h_1 cos t + (h_2 - h_1 cos w) / sin w sin t = R cos(t - psi)
    along = (h_2 - h_1 * np.cos(width)) / np.sin(width)
    psi = np.arctan2(along, h_1)
    top = np.hypot(h_1, along) if 0.0 <= psi <= width else max(h_1, h_2)
    return (np.inf if top <= 0.0 else 1.0 / top), azimuth_1 + np.degrees(psi)


def search_factor(result) -> float | None:
    """A collapse result's factor for :func:`refine_least`: ``inf`` when no factor bounds
    the load, None when the solve gave no verdict."""
    if result.load_factor is None and result.status == UNBOUNDED:
        return np.inf
    return result.load_factor


def refine_least(samples, factor_at, key=None, azimuth_rel=AZIMUTH_REFINE_REL) -> list:
    """Points that refine the least of ``samples`` ((azimuth in degrees, factor) pairs;
    factor None where the solve gave none, ``inf`` where no factor bounds the load) by
    calling ``factor_at(azimuth) -> float or None`` (the same meaning) inside the
    brackets between consecutive solved azimuths, around the circle, where a smaller
    factor than the least found may lie (module docstring). ``key(azimuth)`` names the
    orbit of an azimuth under the structure's symmetries (equal keys, equal factors): of
    brackets that map onto each other only one is searched. The cuts end when every
    floor is within ``azimuth_rel`` (relative) of the least found. Returns the new
    ``(azimuth, factor)`` pairs, in the order solved, azimuths in [0, 360)."""
    known = {float(a) % 360.0: f for a, f in samples if f is not None}
    finite = [f for f in known.values() if np.isfinite(f)]
    if not finite or min(finite) <= 0.0:
        return []
    # the brackets beside the least are those with an end among the samples near the
    # least sampled or at a cut: a cut's two halves stay searched when it finds a
    # smaller factor elsewhere
    near = {a for a, f in known.items() if f <= min(finite) * (1.0 + AZIMUTH_NEAR_LEAST_REL)}
    searched, new = set(), []
    while brackets := _open_brackets(known, near, key, searched, azimuth_rel):
        _, low, high, name = brackets[0]
        searched.add(name)
        if len(new) == MAX_SOLVES:
            log.warning("lateral search: refinement stopped after %d solves; the least "
                        "factor found is kept", len(new))
            return new
        # an open bracket's corner lies inside it: its floor is below both ends' factors
        cut = _corner(low, known[low], high, known[high % 360.0])[1] % 360.0
        factor = factor_at(cut)
        new.append((cut, factor))
        if factor is None or not np.isfinite(factor):
            log.warning("lateral search: no finite factor at %.6g deg; the bracket %.6g to "
                        "%.6g deg is not searched further", cut, low, high % 360.0)
            continue
        known[cut] = factor
        near.add(cut)
    log.info("lateral search: %d azimuths refined", len(new))
    return new


def _open_brackets(known, near, key, searched, azimuth_rel) -> list:
    """``(floor, low, high, name)`` of the brackets between consecutive azimuths of
    ``known`` with an end in ``near`` whose floor lies below the least factor by more
    than ``azimuth_rel``, not yet ``searched`` (by ``name``: the key of its middle and
    its width), the lowest floor first; ``high`` may pass 360."""
    least = min(f for f in known.values() if np.isfinite(f))
    if least <= 0.0:
        return []
    angles = sorted(known)
    out = {}
    for low, high in zip(angles, angles[1:] + [angles[0] + 360.0]):
        if not 0.0 < high - low < 180.0 or not {low, high % 360.0} & near:
            continue  # not beside the least: its floor is a bound, not searched
        middle = 0.5 * (low + high) % 360.0
        name = (round(middle, 9) if key is None else key(middle), round(high - low, 9))
        floor = floor_between(low, known[low], high, known[high % 360.0])
        if name not in searched and floor < least * (1.0 - azimuth_rel):
            out.setdefault(name, (floor, low, high, name))
    return sorted(out.values(), key=lambda bracket: bracket[0])
