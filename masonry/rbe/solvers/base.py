"""What every QP backend returns (:mod:`masonry.rbe.solvers`)."""

from dataclasses import dataclass, field

import numpy as np

# statuses, in cvxpy's words (cvxpy.settings), so that every backend speaks alike
OPTIMAL = "optimal"
OPTIMAL_INACCURATE = "optimal_inaccurate"
INFEASIBLE = "infeasible"
INFEASIBLE_INACCURATE = "infeasible_inaccurate"
USER_LIMIT = "user_limit"
SOLVER_ERROR = "solver_error"


@dataclass(frozen=True, eq=False)
class QPOutcome:
    """One solve of the scaled RBE QP.

    Parameters
    ----------
    status : str
        One of the module's statuses (cvxpy's words).
    x : (n,) float or None
        The point, in solver units and the :class:`~masonry.rbe.equilibrium.VariableLayout`
        order; None without one.
    iterations : int
        Solver iterations (Newton steps, interior-point or ADMM iterations); -1 when
        not reported.
    y : (6 F,) float or None
        Multipliers of the equilibrium rows, where the backend has them (warm starts).
    setup_time, solve_time : float, s
        Building the solver's data (and any factorization it does up front), and the
        iterations.
    info : dict
        Backend-specific numbers (e.g. factorizations), for the benchmark.
    """

    status: str
    x: np.ndarray | None
    iterations: int
    y: np.ndarray | None = None
    setup_time: float = 0.0
    solve_time: float = 0.0
    info: dict = field(default_factory=dict)
