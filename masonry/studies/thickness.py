"""Minimum thickness of an arch by bisection on rigid block equilibrium (docs/model.md 8).

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
from masonry.errors import MasonryError, ParameterError
from masonry.params import Params, validate
from masonry.rbe.solve import solve_rbe
from masonry.scenes.arch import arch_radius, build_arch
from masonry.tolerances import (MIN_SEARCH_RTOL, MIN_THICKNESS_BLOCKS, THICKNESS_BRACKET,
                                THICKNESS_LIMIT_FRACTION, THICKNESS_RTOL)

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
    scene = build_arch(params.geometry)
    interfaces = detect(scene.blocks, up=scene.block_up)
    result = solve_rbe(scene.blocks, interfaces,
                       **{**params.analysis.rbe_options(), "friction": "net"}, lp_check=False)
    return bool(result.feasible)


def minimum_thickness(params: Params, rtol=THICKNESS_RTOL,
                      bracket=THICKNESS_BRACKET) -> ThicknessResult:
    """The minimum thickness of the arch of ``params`` (its ``arch_thickness`` is
    ignored), by bisection on :func:`is_feasible`.

    Bisection is geometric (on log t) and stops when the feasible and infeasible
    thicknesses differ by less than ``rtol`` of the feasible one, or when the bracket
    no longer shrinks (floats next to each other); it assumes one threshold (thicker
    arches stand, thinner ones fall).

    Parameters
    ----------
    params : Params
        Of an ``arch`` scene: shape, voussoirs, span, depth, ``mu``, ``density``,
        ``solver``.
    rtol : float
        Relative width of the final bracket.
    bracket : (float, float)
        Starting ``(infeasible, feasible)`` t/R; the upper end is cut to
        :data:`~masonry.tolerances.THICKNESS_LIMIT_FRACTION` (0.99) of the
        largest thickness the shape allows (the intrados vanishes there).

    Raises
    ------
    ParameterError
        ``rtol`` is not in [:data:`~masonry.tolerances.MIN_SEARCH_RTOL`, 1); fewer than
        :data:`~masonry.tolerances.MIN_THICKNESS_BLOCKS` voussoirs (they stand at every
        thickness: named ``arch_blocks``); or the upper end is infeasible (the arch slides
        at every thickness: named ``mu``).
    MasonryError
        The lower end of ``bracket`` is feasible: the minimum lies below it.
    """
    if not (isinstance(rtol, float | int) and not isinstance(rtol, bool)
            and MIN_SEARCH_RTOL <= rtol < 1):
        raise ParameterError("rtol", rtol, f"a relative width from {MIN_SEARCH_RTOL:g} "
                             f"(machine precision) to 1 (exclusive)")
    if params.geometry.arch_blocks < MIN_THICKNESS_BLOCKS:
        raise ParameterError("arch_blocks", params.geometry.arch_blocks,
                             f"at least {MIN_THICKNESS_BLOCKS} voussoirs: an arch of fewer "
                             f"has too few joints for the four hinges of a mechanism and "
                             f"stands at every thickness")
    start = time.perf_counter()
    arch = params.geometry
    radius, _ = arch_radius(arch.arch_shape, arch.arch_span, arch.arch_rise)
    most = (arch.arch_span if arch.arch_shape == "pointed" else 2 * radius) / radius
    lo, hi = bracket[0], min(bracket[1], THICKNESS_LIMIT_FRACTION * most)
    steps = []

    def feasible(ratio):
        verdict = is_feasible(validate(params.replace(arch_thickness=ratio * radius)))
        steps.append((float(ratio), verdict))
        log.info("t/R = %.6f: %s", ratio, "stands" if verdict else "falls")
        return verdict

    if not feasible(hi):
        raise ParameterError("mu", params.analysis.mu,
                             f"a friction coefficient at which the arch stands: it falls "
                             f"even at t/R = {hi:g}, so its voussoirs slide")
    if feasible(lo):
        raise MasonryError(f"the arch stands already at t/R = {lo:g}, the thinnest the "
                           f"search tries: its minimum thickness is below that")
    while hi / lo - 1 > rtol:
        mid = float(lo * np.sqrt(hi / lo))  # not sqrt(lo * hi): that underflows first
        if not lo < mid < hi:  # the bracket is two neighbouring floats: it cannot shrink
            break
        if feasible(mid):
            hi = mid
        else:
            lo = mid
    return ThicknessResult(t_over_r=hi, lower=lo, thickness=hi * radius, radius=radius,
                           steps=tuple(steps), time_s=time.perf_counter() - start)


def folder_name(params: Params, rtol: float) -> str:
    """The run folder of a minimum-thickness search: every input but the thickness."""
    p, a = params.geometry, params.analysis
    name = (f"arch-thickness_{p.arch_shape}_N{p.arch_blocks}_s{p.arch_span:g}"
            f"_d{p.arch_depth:g}" + ("" if p.arch_rise is None else f"_h{p.arch_rise:g}")
            + f"_mu{a.mu:g}_rho{a.density:g}_rtol{rtol:g}")
    return name + ("" if a.solver is None else f"_{a.solver}")


def steps_csv(result: ThicknessResult) -> bytes:
    """One row per bisection step: t/R, thickness (metres), whether the arch stands."""
    lines = ["step,t_over_r,thickness_m,stands"]
    lines += [f"{i},{ratio:.9g},{ratio * result.radius:.9g},{bool(stands)}"
              for i, (ratio, stands) in enumerate(result.steps)]
    return ("\n".join(lines) + "\n").encode()
