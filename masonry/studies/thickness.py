"""Minimum thickness of an arch by bisection on rigid block equilibrium (SPEC 8).

An arch of rigid, no-tension voussoirs stands above a minimum thickness and falls below
it (Heyman; Milankovitch's t/R = 0.1075 for a semicircle under self weight). Here the
feasibility of each thickness is decided by the same interface detector and friction-net
QP as every other scene; :mod:`masonry.studies.thrust_line` computes the same number
independently from the thrust line.
"""

import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.interfaces import detect
from masonry.params import Params, arch_radius, validate
from masonry.rbe.solve import solve_rbe
from masonry.scenes.arch import build_arch
from masonry.tolerances import THICKNESS_BRACKET, THICKNESS_LIMIT_FRACTION, THICKNESS_RTOL

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ThicknessResult:
    """Outcome of :func:`minimum_thickness`.

    Parameters
    ----------
    t_over_r : float
        The thinnest arch found feasible, over the centre-line radius: the minimum
        thickness lies in ``(lower, t_over_r]``.
    lower : float
        The thickest arch found infeasible, over the radius.
    thickness, radius : float, metres
        ``t_over_r * radius`` and the centre-line radius.
    steps : tuple of (float, bool)
        Every thickness tried (t/R) and its verdict, in order.
    time_s : float
    """

    t_over_r: float
    lower: float
    thickness: float
    radius: float
    steps: tuple
    time_s: float


def is_feasible(params: Params) -> bool:
    """Whether the arch of ``params`` stands: friction-net RBE, no LP check."""
    scene = build_arch(params)
    interfaces = detect(scene.blocks, up=scene.block_up)
    result = solve_rbe(scene.blocks, interfaces, mu=params.mu, density=params.density,
                       friction="net", solver=params.solver, lp_check=False)
    return bool(result.feasible)


def minimum_thickness(params: Params, rtol=THICKNESS_RTOL,
                      bracket=THICKNESS_BRACKET) -> ThicknessResult:
    """The minimum thickness of the arch of ``params`` (its ``arch_thickness`` is
    ignored), by bisection on :func:`is_feasible`.

    Bisection is geometric (on log t) and stops when the feasible and infeasible
    thicknesses differ by less than ``rtol`` of the feasible one; it assumes one
    threshold (thicker arches stand, thinner ones fall).

    Parameters
    ----------
    params : Params
        Scene ``arch`` (set here), shape, voussoirs, span, depth, ``mu``, ``density``,
        ``solver``.
    rtol : float
        Relative width of the final bracket.
    bracket : (float, float)
        Starting ``(infeasible, feasible)`` t/R; the upper end is cut to
        :data:`~masonry.tolerances.THICKNESS_LIMIT_FRACTION` (0.99) of the
        largest thickness the shape allows (the intrados vanishes there).

    Raises
    ------
    ValueError
        The upper end is infeasible (e.g. the arch slides at every thickness: raise
        ``mu``) or the lower end is feasible (lower it).
    """
    start = time.perf_counter()
    params = params.replace(scene="arch")
    radius, _ = arch_radius(params.arch_shape, params.arch_span, params.arch_rise)
    most = (params.arch_span if params.arch_shape == "pointed" else 2 * radius) / radius
    lo, hi = bracket[0], min(bracket[1], THICKNESS_LIMIT_FRACTION * most)
    steps = []

    def feasible(ratio):
        verdict = is_feasible(validate(params.replace(arch_thickness=ratio * radius)))
        steps.append((float(ratio), verdict))
        log.info("t/R = %.6f: %s", ratio, "stands" if verdict else "falls")
        return verdict

    if not feasible(hi):
        raise ValueError(f"the arch does not stand even at t/R = {hi:g} (with mu = "
                         f"{params.mu:g}: sliding?)")
    if feasible(lo):
        raise ValueError(f"the arch stands already at t/R = {lo:g}: lower the bracket")
    while hi / lo - 1 > rtol:
        mid = float(np.sqrt(lo * hi))
        if feasible(mid):
            hi = mid
        else:
            lo = mid
    return ThicknessResult(t_over_r=hi, lower=lo, thickness=hi * radius, radius=radius,
                           steps=tuple(steps), time_s=time.perf_counter() - start)
