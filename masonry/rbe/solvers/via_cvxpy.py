"""The RBE QP through cvxpy: the readable reference path (thesis 3.3.4).

The problem is written as the model states it (every sign bound, the friction model as
cvxpy constraints: a pyramid's faces as rows, Coulomb's cone as second-order cones) and
cvxpy canonicalizes it for OSQP (pyramids only) or Clarabel. The direct paths
(:mod:`.direct_osqp`, :mod:`.direct_clarabel`) must agree with it (tests/test_solvers.py).
"""

import logging
import time

import numpy as np
import scipy.sparse as sp

from masonry.friction import KINDS
from masonry.rbe.solvers.base import SOLVER_ERROR, Backend, Outcome

log = logging.getLogger(__name__)


def solver_for(name):
    """A backend function for cvxpy's solver ``name`` (``'OSQP'`` or ``'CLARABEL'``)."""

    def solve(system, method, options, workspace) -> Outcome:
        return _solve(system, method, name, options)

    return solve


def _solve(system, method, name, options) -> Outcome:
    import cvxpy as cp

    start = time.perf_counter()
    x = cp.Variable(system.layout.n_columns)
    bounded = np.flatnonzero(np.isfinite(system.lower))
    # H is a constant positive diagonal: psd_wrap skips cvxpy's eigenvalue check
    objective = cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(sp.diags_array(system.h_solver))))
    constraints = [system.A_eq @ x == -system.f_ext, x[bounded] >= system.lower[bounded]]
    floor = system.compression_floor
    if floor is not None and method == "net":  # the tension cut-off on the net force
        constraints.append(x[system.layout.columns("c")] - x[system.layout.columns("t")]
                           >= floor)
    if system.cone.is_polyhedral:
        constraints.append(system.A_fr[method] @ x <= 0)
    else:
        vertex = cp.reshape(x, (system.layout.n_vertices, 4), order="C")
        load = vertex[:, 0] - vertex[:, 1] if method == "net" else vertex[:, 0]
        constraints.append(cp.SOC(system.mu * load, vertex[:, 2:], axis=1))
    problem = cp.Problem(objective, constraints)
    try:
        problem.solve(solver=name, **options)
    except cp.error.SolverError as error:
        # cvxpy raises when the solver ends without a usable status (numerical error)
        log.warning("%s (via cvxpy) failed on the %s problem: %s", name, method, error)
        return Outcome(status=SOLVER_ERROR, x=None, iterations=-1,
                       solve_time=time.perf_counter() - start)
    stats = problem.solver_stats
    iterations = stats.num_iters
    if iterations is None:
        # cvxpy drops OSQP's count when there is no solution; OSQP's own info has it
        iterations = getattr(getattr(stats.extra_stats, "info", None), "iter", None)
    x_value = x.value if problem.status in cp.settings.SOLUTION_PRESENT else None
    total = time.perf_counter() - start
    solver_time = stats.solve_time if stats.solve_time is not None else total
    return Outcome(status=problem.status, x=x_value,
                   iterations=-1 if iterations is None else int(iterations),
                   setup_time=max(total - solver_time, 0.0), solve_time=solver_time)


BACKENDS = (Backend("clarabel-cvxpy", settings="clarabel", rbe=solver_for("CLARABEL"),
                    truncated=KINDS),
            Backend("osqp-cvxpy", settings="osqp", rbe=solver_for("OSQP"),
                    polyhedral_only=True, truncated=KINDS))
"""Clarabel and OSQP through cvxpy: the RBE QP, with the direct paths' settings (a
tension cut-off is a bound on ``c``, ``system.lower``, and on ``c - t`` for
friction-net)."""
