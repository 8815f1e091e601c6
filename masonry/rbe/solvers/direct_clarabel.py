"""Clarabel (interior point, homogeneous embedding) on the standard form, without cvxpy.

Clarabel writes constraints as ``A x + s = b, s in K``: the equilibrium rows are a zero
cone, a pyramid's friction rows a nonnegative cone and Coulomb's cone a second-order
cone per vertex, the ``t >= 0`` rows a nonnegative cone (``t`` enters as ``-t + s =
0``). One solver per scene and friction model; friction+ and other friction
coefficients update the matrix values in place, which keeps Clarabel's KKT ordering
(data updates need presolve off; presolve only drops rows with infinite bounds, and this
problem has none).
"""

import time

import numpy as np

from masonry.rbe.solvers.base import (INFEASIBLE, INFEASIBLE_INACCURATE, OPTIMAL, OPTIMAL_INACCURATE,
                   SOLVER_ERROR, USER_LIMIT, QPOutcome)
from masonry.rbe.solvers.standard_form import kept_form

STATUS = {
    "Solved": OPTIMAL,
    "AlmostSolved": OPTIMAL_INACCURATE,
    "PrimalInfeasible": INFEASIBLE,
    "AlmostPrimalInfeasible": INFEASIBLE_INACCURATE,
    "MaxIterations": USER_LIMIT,
    "MaxTime": USER_LIMIT,
}
"""Clarabel's status names -> ours; anything else is a solver error."""

DEFAULTS = {
    "verbose": False,
    "presolve_enable": False,
    # qdldl: faster than the default (faer) on these KKT systems (docs/bench.md)
    "direct_solve_method": "qdldl",
}


def solve(system, method, options, workspace) -> QPOutcome:
    """One Clarabel solve; ``options`` are Clarabel settings (``DefaultSettings`` fields)."""
    import clarabel

    start = time.perf_counter()
    form = kept_form(system, workspace)
    values = form.values(method, system.mu)
    # Clarabel's rows are A x + s = b: the t rows enter negated
    values[_tension_rows(form)] *= -1.0
    solver = workspace.get("solver")
    if solver is None or workspace.get("options") != options:
        settings = clarabel.DefaultSettings()
        for name, value in {**DEFAULTS, **options}.items():
            setattr(settings, name, value)
        matrix = form.rows.copy()
        matrix.data = values
        b = np.concatenate([form.b, np.zeros(form.n_friction + form.n_tension)])
        if form.cone.is_polyhedral:
            cones = [clarabel.ZeroConeT(form.n_eq),
                     clarabel.NonnegativeConeT(form.n_friction + form.n_tension)]
        else:
            cones = [clarabel.ZeroConeT(form.n_eq),
                     *[clarabel.SecondOrderConeT(3)] * (form.n_friction // 3),
                     clarabel.NonnegativeConeT(form.n_tension)]
        solver = clarabel.DefaultSolver(form.P, np.zeros(form.P.shape[0]), matrix, b,
                                        cones, settings)
        workspace.update(solver=solver, options=options, values=values)
    elif not np.array_equal(workspace["values"], values):
        solver.update(A=values)
        workspace["values"] = values
    setup = time.perf_counter() - start
    result = solver.solve()
    status = STATUS.get(str(result.status), SOLVER_ERROR)
    x = np.array(result.x) if status in (OPTIMAL, OPTIMAL_INACCURATE, USER_LIMIT) else None
    # the equilibrium rows' multipliers in the Newton method's convention (L = 1/2 x^T P x
    # - y^T (A_eq x - b)); Clarabel's are those of A x + s = b, the opposite sign
    y = None if x is None else -np.array(result.z)[:form.n_eq]
    return QPOutcome(status=status, x=x, iterations=int(result.iterations), y=y,
                     setup_time=setup, solve_time=time.perf_counter() - start - setup)


def _tension_rows(form):
    """Slots of the ``t >= 0`` rows in the stacked matrix's data."""
    rows = form.rows
    row_of_slot = rows.indices
    return np.flatnonzero(row_of_slot >= form.n_eq + form.n_friction)
