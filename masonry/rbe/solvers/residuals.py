"""Residuals of a returned point, recomputed from the matrices (never a solver's word).

Every backend's outcome carries them (:class:`~masonry.rbe.solvers.base.Outcome`): the
analyses accept a point by them (:data:`masonry.tolerances.ACCEPT_RESIDUAL`), whatever
the status says (OSQP has reported "solved" on infeasible points).
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Residuals:
    """How far a point is from the problem's constraints.

    Parameters
    ----------
    equilibrium : float
        ``||A_eq x + f||_inf / ||f||_inf``, ``f`` the loads the point balances (scaled
        rows: forces per reference weight, moments per reference weight times reference
        length).
    friction : float
        Largest violation of the friction rows of the problem solved and of the sign
        bounds, per reference weight; NaN where not measured (a cone program, whose
        forces are within their cones by construction).
    net_friction : float
        The same on the friction-net rows, whatever problem was solved; NaN where not
        measured.
    """

    equilibrium: float
    friction: float = np.nan
    net_friction: float = np.nan


def rbe_residuals(system, x_scaled, method: str) -> Residuals | None:
    """The residuals of an RBE point ``x_scaled`` ((4 IV,) float, solver units) of the
    friction model ``method`` (``'net'`` or ``'plus'``) on ``system`` (an
    :class:`~masonry.rbe.equilibrium.EquilibriumSystem`); None without a point.

    The violations are the largest excess of every vertex force over its friction model
    (:meth:`~masonry.friction.FrictionCone.excess`, at ``c - t`` for friction-net, at
    ``c`` for friction+) or over a bound (``system.lower``; for friction-net also the
    tension cut-off on ``c - t``, :attr:`~masonry.rbe.equilibrium.EquilibriumSystem.
    compression_floor`), in units of the reference weight. ``c`` is the solver's
    (shifted) compression.
    """
    if x_scaled is None:
        return None
    residual_eq = (np.abs(system.times_A_eq(x_scaled) + system.f_ext).max()
                   / np.abs(system.f_ext).max())
    bound = max(0.0, float((system.lower - x_scaled).max()))
    c, t, f1, f2 = np.asarray(x_scaled).reshape(-1, 4).T

    floor = system.compression_floor

    def violation(name):
        load = c - t if name == "net" else c
        excess = system.cone.excess(load, f1, f2, system.mu)
        if floor is not None and name == "net":  # the cut-off bounds the net force
            excess = np.maximum(excess, floor - load)
        return max(bound, float(excess.max(initial=0.0)))

    return Residuals(float(residual_eq), violation(method), violation("net"))


def program_residuals(system, x_scaled, factor: float, live) -> Residuals:
    """The residual of a collapse point: vertex forces ``x_scaled`` ((4 IV,) float, the
    layout's order) balancing the dead load of ``system`` and ``factor`` times the live
    load ``live`` ((6 F,) float, the rows' scaling):
    ``||A_eq x + f_dead + factor live||_inf / ||f_dead + factor live||_inf``."""
    total = system.f_ext + factor * live
    return Residuals(float(np.abs(system.A_eq @ x_scaled + total).max()
                           / np.abs(total).max()))
