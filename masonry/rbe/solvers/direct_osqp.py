"""OSQP (ADMM, the thesis's solver) on the standard form, without cvxpy.

OSQP takes linear constraints: the pyramids (``polygon:K``, ``square``), not Coulomb's
cone. One OSQP object per scene: friction-net, friction+ and other friction coefficients only
change matrix values, so later solves update them in place (OSQP refactors numerically,
reusing its ordering) and warm start from the last solution of the same model.
"""

import time

import numpy as np
import scipy.sparse as sp

from masonry.rbe.solvers.base import (INFEASIBLE, INFEASIBLE_INACCURATE, OPTIMAL,
                                      OPTIMAL_INACCURATE, SOLVER_ERROR, USER_LIMIT, Backend,
                                      Outcome)
from masonry.rbe.solvers.standard_form import kept_form

STATUS = {
    "solved": OPTIMAL,
    "solved inaccurate": OPTIMAL_INACCURATE,
    "primal infeasible": INFEASIBLE,
    "primal infeasible inaccurate": INFEASIBLE_INACCURATE,
    "maximum iterations reached": USER_LIMIT,
    "run time limit reached": USER_LIMIT,
}
"""OSQP's status words -> ours; anything else is a solver error."""


def _csc32(matrix):
    """OSQP's extension takes scipy's csc_matrix with 32-bit indices."""
    return sp.csc_matrix((matrix.data, matrix.indices.astype(np.int32),
                          matrix.indptr.astype(np.int32)), shape=matrix.shape)


def solve(system, method, options, workspace) -> Outcome:
    """One OSQP solve; ``options`` are OSQP settings, ``workspace`` a dict kept per scene."""
    import osqp

    start = time.perf_counter()
    form = kept_form(system, workspace)
    values = form.values(method, system.mu)
    solver = workspace.get("solver")
    if solver is None or workspace.get("options") != options:
        matrix = form.rows.copy()
        matrix.data = values
        lower = np.concatenate([form.b, np.full(form.n_friction, -np.inf),
                                np.zeros(form.n_tension)])
        upper = np.concatenate([form.b, np.zeros(form.n_friction),
                                np.full(form.n_tension, np.inf)])
        solver = osqp.OSQP()
        solver.setup(_csc32(sp.triu(form.P, format="csc")), np.zeros(form.P.shape[0]),
                     _csc32(matrix), lower, upper, verbose=False, **options)
        workspace.update(solver=solver, options=options, values=values, warm={})
    elif not np.array_equal(workspace["values"], values):
        solver.update(Ax=values)
        workspace["values"] = values
    warm = workspace["warm"].get(method)
    if warm is not None:
        solver.warm_start(x=warm[0], y=warm[1])
    setup = time.perf_counter() - start
    result = solver.solve(raise_error=False)
    status = STATUS.get(result.info.status, SOLVER_ERROR)
    x = result.x if status in (OPTIMAL, OPTIMAL_INACCURATE, USER_LIMIT) else None
    if x is not None and np.all(np.isfinite(x)):
        workspace["warm"][method] = (x.copy(), result.y.copy())
    else:
        x = None
    # OSQP's multipliers of the equilibrium rows (stationarity P x + A^T y = 0) are the
    # Newton method's with the opposite sign
    return Outcome(status=status, x=x, iterations=int(result.info.iter),
                   y=None if x is None else -result.y[:form.n_eq],
                   setup_time=setup, solve_time=time.perf_counter() - start - setup,
                   info={"polish": int(result.info.status_polish)})


BACKEND = Backend("osqp", settings="osqp", rbe=solve, polyhedral_only=True)
"""OSQP: the RBE QP of the pyramids."""
