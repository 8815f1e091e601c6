"""Friction-net feasibility decided by a load-path LP on the Newton method's matrix.

Friction-net is feasible when the dead load is carried by vertex forces within the
friction model alone: ``M g = b`` for some ``g`` in the cone ``K`` (``M = A T`` and ``b``
as in :mod:`masonry.rbe.solvers.interior_lp`). A reference load that is surely carried,
``r = M g0`` with ``g0 = e`` the cone's identity (every edge ray of a pyramid at unit
weight; a normal force and no friction at every vertex of Coulomb's cone), is moved
towards ``b``::

    maximize lambda   subject to   M g = r + lambda (b - r),   g in K

which is the collapse LP of :func:`~masonry.rbe.solvers.interior_lp.load_factor` with
right-hand side ``r`` and live load ``l = r - b``. ``lambda = 0`` is feasible (``g0``),
so the LP is never infeasible:

- ``lambda >= 1``: ``g' = g / lambda + (1 - 1 / lambda) g0`` (in ``K``) has ``M g' =
  b + d / lambda`` where the iterate's primal rows miss by ``d``. Its residual is
  recomputed here: within the QP's acceptance residual ``g'`` is a friction-net point
  and the verdict is ``feasible``. Further from the rows an iterate's ``lambda`` says
  nothing: an early iterate may pass 1 with ``g'`` far from the dead load where the
  optimum is below 1 (``docs/bench.md``, "Newton's hand-over to the load-path LP").
- an optimum below 1: the dual point has ``-M^T y`` in ``K`` and ``b^T y = r^T y + 1 >
  0`` (``l^T y = -1``, and ``-r^T y`` bounds ``lambda``), a Farkas certificate: no ``g``
  in ``K`` has ``M g = b``.

The interior point method stops at the first iterate that decides either way (it need
not converge; the LP is unbounded when ``b - r`` itself is carried, and the stop at a
``g'`` within the residual comes first). Where neither comes (an optimum at 1 to
within the residual, approached from below) it runs to its iteration limit and the
verdict is ``undecided``. The certificate is checked on ``M^T y`` and ``b^T y``
recomputed from the matrices, with the margins the QP's acceptance allows. Let
``delta`` be how far ``-M^T y`` lies outside ``K`` (its most negative eigenvalue: the
largest entry of ``M^T y`` for the orthant of a pyramid's rays); then for ``M g = b +
e``, ``g`` in ``K``, ``b^T y <= tr(g) delta + ||e||_inf ||y||_1`` (``tr(g) = e . g``:
the sum of the ray weights, or of ``mu c``). So when

    delta ||b||_1 / infeasibility_tol + residual ||b||_inf ||y||_1 < b^T y

no vertex forces with ``tr(g)`` (of the order of the sum of the normal forces, in
reference weights) up to ``||b||_1 / infeasibility_tol`` balance the loads within the
relative residual ``residual``: the Newton method's certificate
(:func:`~masonry.rbe.solvers.newton.certifies_infeasibility`), plus the residual margin
of an accepted point. Without either verdict the outcome is ``user_limit`` and the
caller asks another solver.

Why: when the dual of the friction-net QP is unbounded the Newton method may stall
instead of certifying (low friction), and Clarabel's certificate costs a factorization
of the whole KKT system per iteration; this LP factors the Newton method's six rows
per block.
"""

import logging
import time

import numpy as np

from masonry.rbe.solvers.base import INFEASIBLE, USER_LIMIT, Outcome
from masonry.rbe.solvers.interior_lp import ConeVariables, LoadFactorOptions, load_factor
from masonry.rbe.solvers.newton import NewtonSystem

log = logging.getLogger(__name__)

FEASIBLE, UNDECIDED = "feasible", "undecided"
"""``info["verdict"]`` of :func:`decide`, besides :data:`~masonry.rbe.solvers.base.INFEASIBLE`
(module docstring)."""


class _LoadPath:
    """The stop test of :func:`decide`: the verdict at an iterate of the LP."""

    def __init__(self, ns: NewtonSystem, infeasibility_tol, residual):
        self.ns, self.infeasibility_tol, self.residual = ns, infeasibility_tol, residual
        self.variables = ConeVariables(ns)
        cone = self.variables.cone
        self.start = cone.identity(len(ns.h))
        self.reference = self.variables.times_m(self.start)
        self.b_inf, self.b_one = np.abs(ns.b).max(), np.abs(ns.b).sum()
        self.verdict, self.quality = UNDECIDED, np.inf
        self.point, self.point_error = None, np.nan

    def __call__(self, factor, g, y) -> bool:
        if factor >= 1.0:
            point = g / factor + (1.0 - 1.0 / factor) * self.start
            error = self.point_residual(point)
            if error <= self.residual:
                self.point, self.point_error, self.verdict = point, error, FEASIBLE
                return True
        self.quality = self.certificate_quality(y)
        if self.quality < 1.0:
            self.verdict = INFEASIBLE
            return True
        return False

    def point_residual(self, g) -> float:
        """``||M g - b||_inf / ||b||_inf``."""
        return float(np.abs(self.variables.times_m(g) - self.ns.b).max() / self.b_inf)

    def certificate_quality(self, y) -> float:
        """The left side of the certificate's test (module docstring) over ``b^T y``:
        ``y`` certifies infeasibility when it is below 1 (inf when ``b^T y <= 0``)."""
        gain = float(self.ns.b @ y)
        if gain <= 0:
            return np.inf
        work = -self.variables.times_mt(y)
        excess = max(-float(self.variables.cone.min_eigenvalue(work).min()), 0.0)
        bound = (excess * self.b_one / self.infeasibility_tol
                 + self.residual * self.b_inf * float(np.abs(y).sum()))
        return bound / gain

    def forces(self) -> np.ndarray | None:
        """(IV, 3) float: the vertex forces ``(c, f1, f2)`` of the feasible point, scaled;
        None without one."""
        return None if self.point is None else self.point @ self.variables.T.T


OPTIONS = LoadFactorOptions(correctors=1)
"""The LP's settings: one centrality corrector, not the collapse LP's two, measured
when the LP stopped at its first ``lambda >= 1``, within a few iterations
(``docs/bench.md``, "friction+ by the interior point method", the load-path LP's
correctors); a verdict now takes 15 to 35 on preset 1's large sections."""


def decide(ns: NewtonSystem, infeasibility_tol, residual, options=OPTIONS) -> Outcome:
    """Decide friction-net feasibility of ``ns`` (the friction-net
    :class:`~masonry.rbe.solvers.newton.NewtonSystem`) by the load-path LP.

    Parameters
    ----------
    infeasibility_tol : float
        See the module docstring (the Newton method's ``infeasibility_tol``).
    residual : float
        Relative equilibrium residual of an accepted point (``Tolerances.residual``).
    options : LoadFactorOptions

    Returns
    -------
    Outcome
        ``x`` None (the LP's point is not the QP's optimum). Status ``infeasible`` with
        ``y`` the certificate, else ``user_limit``. ``info``: ``verdict`` (``feasible``,
        ``infeasible`` or ``undecided``), ``forces`` (the vertex forces ``(c, f1, f2)``
        ((IV, 3), scaled) of a feasible verdict, else None), ``residual`` (their
        ``||A x - b||_inf / ||b||_inf``, else NaN),
        ``certificate_quality`` (the last iterate's, see
        :meth:`_LoadPath.certificate_quality`), ``load_factor``.
    """
    start = time.perf_counter()
    path = _LoadPath(ns, infeasibility_tol, residual)
    outcome = load_factor(ns, path.reference - ns.b, options, rhs=path.reference,
                          stop=path)
    log.info("load-path LP: friction-net %s after %d iterations (lambda %.6g, "
             "certificate quality %.2e)", path.verdict, outcome.iterations,
             outcome.info["load_factor"], path.quality)
    return Outcome(
        status=INFEASIBLE if path.verdict == INFEASIBLE else USER_LIMIT, x=None,
        iterations=outcome.iterations,
        y=outcome.y if path.verdict == INFEASIBLE else None,
        solve_time=time.perf_counter() - start,
        info={"verdict": path.verdict, "forces": path.forces(),
              "residual": path.point_error,
              "certificate_quality": path.quality,
              "load_factor": outcome.info["load_factor"],
              "factorizations": outcome.info["factorizations"]})
