"""The independent check of a friction-net verdict by linear programming (HiGHS,
docs/model.md 6.5): Coulomb's cone bracketed by an inscribed and a circumscribed pyramid."""

import logging
import math

import scipy.sparse as sp

from masonry.friction import FrictionCone
from masonry.rbe.equilibrium import EquilibriumSystem, friction_edges
from masonry.rbe.solvers.highs import nonnegative_solution

log = logging.getLogger(__name__)

LP_CHECK_SIDES = 16
"""Coulomb's cone is checked by linear programming on a 16-sided pyramid: the inscribed
one (1.9 % short of the cone) for a feasible verdict, the circumscribed one (1.9 % over)
for an infeasible one."""


def lp_feasible(system: EquilibriumSystem, time_limit: float, verdict: bool):
    """Friction-net feasibility by linear programming (HiGHS, zero objective), to check
    the QP's ``verdict``.

    A pyramid is written by its edge rays instead of its faces: a vertex force with
    ``t = 0`` inside it is a nonnegative combination of its rays
    (:func:`~masonry.rbe.equilibrium.friction_edges`), so the LP is ``A_eq E lam =
    -f_ext, lam >= 0`` with ``K`` unknowns per vertex and no inequality rows. Fixing
    ``t = 0`` loses nothing: a friction-net point with ``0 < t <= c`` stays one with
    ``(c - t, 0)``. The edge form is also a second, independent way to state the
    constraints. Coulomb's cone is not a pyramid: it lies between the inscribed and the
    circumscribed :data:`LP_CHECK_SIDES`-sided ones, so a feasible verdict is checked
    on the inscribed one (feasible there proves it) and an infeasible one on the
    circumscribed one (infeasible there proves it); a structure within 2 % of its friction
    limit gets no second opinion (None). HiGHS's interior point method decides, without
    crossover (a vertex solution is not needed, only the verdict; crossover and the dual
    simplex were measured slower: docs/bench.md, "Measurements behind design choices").
    Proving feasibility takes far longer
    than proving infeasibility and grows faster than linearly, hence ``time_limit``.

    Returns True, False, or None when HiGHS ends without a verdict (time limit) or the
    pyramid cannot decide for the cone.
    """
    if system.compression_floor is not None:
        # the rays state the cone, not its truncation by a tension cut-off: they can
        # prove it infeasible (the truncated cone lies inside), never feasible
        if verdict:
            return None
        outer_mu = system.mu / (1.0 if system.cone.is_polyhedral
                                else math.cos(math.pi / LP_CHECK_SIDES))
        outer = system.cone if system.cone.is_polyhedral else pyramid_of(LP_CHECK_SIDES)
        return False if _edges_feasible(system, outer, outer_mu, time_limit) is False else None
    if system.cone.is_polyhedral:
        return _edges_feasible(system, system.cone, system.mu, time_limit)
    pyramid = pyramid_of(LP_CHECK_SIDES)
    if verdict:
        return True if _edges_feasible(system, pyramid, system.mu, time_limit) else None
    outer_mu = system.mu / math.cos(math.pi / LP_CHECK_SIDES)
    return False if _edges_feasible(system, pyramid, outer_mu, time_limit) is False else None


def pyramid_of(sides) -> FrictionCone:
    """The inscribed ``sides``-sided pyramid."""
    return FrictionCone.parse(f"polygon:{sides}")


def _edges_feasible(system, cone, mu, time_limit):
    """Whether the pyramid ``cone`` at ``mu`` carries the dead load (:func:`lp_feasible`):
    True, False or None (no verdict)."""
    generators = friction_edges(system.layout.n_vertices, cone, mu)
    A = sp.csc_array(system.A_eq @ generators)
    verdict, words = nonnegative_solution(A, -system.f_ext, time_limit)
    if verdict is None:
        log.warning("friction-net LP inconclusive: %s", words)
    return verdict
