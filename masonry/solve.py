"""Solve rigid block equilibrium (RBE) as a quadratic program (SPEC 6.5-6.7, thesis 3.3.4).

The matrices come from :mod:`masonry.equilibrium`; this module only builds the cvxpy
problem, calls a solver, checks what the solver returned and packs the result. A
solver's status is never trusted alone: the equilibrium residual and the friction
violation are recomputed from the returned point, and an independent linear program
(scipy's HiGHS) checks friction-net feasibility.
"""

import logging
import time
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from .equilibrium import FRICTION_METHODS, EquilibriumSystem, VariableLayout, assemble
from .tolerances import Tolerances

log = logging.getLogger(__name__)

SOLVERS = {
    # OSQP (the thesis's solver): cvxpy's defaults (eps 1e-5, 10,000 iterations) leave
    # residuals near the acceptance tolerance; 1e-6 keeps a margin below
    # Tolerances.residual (1e-5), and polishing recovers an active-set accurate point on
    # small and medium scenes (it failed on 10,000 bricks, SPEC 6.6, at no harm).
    "osqp": (cp.OSQP, {"eps_abs": 1e-6, "eps_rel": 1e-6, "max_iter": 100_000,
                       "polishing": True}),
    # Clarabel, interior point: the accurate reference. Its default gap tolerances (1e-8)
    # leave interior-point residue of 2.6e-6 of the weight in the tension variables of
    # the straight wall; 1e-10 brings it to 2.4e-7 at the same time (16 vs 13 iterations,
    # 5.0 vs 4.8 s on preset 1).
    "clarabel": (cp.CLARABEL, {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10,
                               "tol_feas": 1e-10}),
}
"""Solver name -> (cvxpy solver name, solver options)."""

RESULT_KEYS = ("feasible", "friction", "mu", "objective", "moi", "moi_factor", "weight_N",
               "solver", "status", "iterations", "residual_eq", "friction_violation",
               "net_friction_violation", "time_s", "lp_feasible")
"""Scalar fields of :class:`RBEResult` written to run.json, in order."""

INTERFACE_FORCE_KEYS = ("compression", "tension", "normal", "t1", "t2", "friction")


@dataclass(frozen=True, eq=False)
class RBEResult:
    """Outcome of :func:`solve_rbe`. Forces in newtons.

    Parameters
    ----------
    feasible : bool
        ``x`` satisfies equilibrium and the friction-net pyramid, both within
        ``tol.residual`` (relative equilibrium residual, and friction violation relative
        to the reference weight): the structure stands without tension.
    friction : str
        ``'net'`` or ``'plus'``: the friction model whose solution ``x`` is.
    mu : float
    objective : float, N^2
        ``1/2 x^T H x`` (thesis eq. 3.27); only an optimality criterion. NaN without ``x``.
    moi : float, N
        Measure of infeasibility, the sum of all tension (thesis eq. 3.28).
    moi_factor : float
        ``moi / weight_N``.
    weight_N : float, N
        Total weight of the free blocks.
    solver, status : str
        Solver name and its status (cvxpy's words) for the problem that produced ``x``.
    iterations : int
        Solver iterations, -1 when not reported.
    residual_eq : float
        ``||A_eq x + f_ext||_inf / ||f_ext||_inf`` (scaled rows: forces per reference
        weight, moments per reference weight times reference length).
    friction_violation : float
        Largest violation of the friction rows of the problem solved and of the sign
        bounds ``c, t >= 0``, per reference weight.
    net_friction_violation : float
        The same on the friction-net rows, whatever problem was solved.
    time_s : float, s
        Wall time of :func:`solve_rbe` (assembly, every QP, the LP check).
    lp_feasible : bool or None
        Verdict of the independent friction-net LP (HiGHS); None when not run or
        inconclusive.
    x : (4 IV,) float or None, N
        Solution in the :class:`~masonry.equilibrium.VariableLayout` order.
    layout : VariableLayout
    """

    feasible: bool
    friction: str
    mu: float
    objective: float
    moi: float
    moi_factor: float
    weight_N: float
    solver: str
    status: str
    iterations: int
    residual_eq: float
    friction_violation: float
    net_friction_violation: float
    time_s: float
    lp_feasible: bool | None
    x: np.ndarray | None
    layout: VariableLayout

    def to_dict(self) -> dict:
        """The scalar fields (:data:`RESULT_KEYS`) as plain Python values, for run.json."""
        out = {}
        for key in RESULT_KEYS:
            value = getattr(self, key)
            out[key] = value.item() if isinstance(value, np.generic) else value
        return out

    def per_interface(self) -> dict:
        """Per-interface force sums; see :func:`interface_forces`."""
        if self.x is None:
            raise ValueError(f"no solution ({self.friction}: {self.status})")
        return interface_forces(self.layout, self.x)


def interface_forces(layout, x) -> dict:
    """Sum the vertex forces of every interface (SPEC 6.7, thesis eq. 3.29-3.34).

    Parameters
    ----------
    layout : VariableLayout
    x : (4 IV,) float, N

    Returns
    -------
    dict str -> (K,) float, N
        ``compression`` (sum c), ``tension`` (sum t), ``normal`` (sum of t - c, tension
        positive), ``t1`` (sum f1), ``t2`` (sum f2), ``friction``
        ``sqrt((sum f1)^2 + (sum f2)^2)`` (the thesis's eq. 3.34 is garbled; this is SPEC
        6.7's reading).
    """
    c, t, f1, f2 = (layout.interface_sum(layout.component(x, name))
                    for name in layout.COMPONENTS)
    return dict(zip(INTERFACE_FORCE_KEYS, (c, t, t - c, f1, f2, np.hypot(f1, f2))))


def solve_rbe(blocks, interfaces, mu=0.7, density=2000.0, friction="auto", solver="clarabel",
              tol=None, *, lp_check=True, lp_time_limit=60.0, side_block=None,
              side_rotation=None) -> RBEResult:
    """Rigid block equilibrium as a quadratic program (thesis 3.3.4).

    With ``x`` the vertex forces ``(c, t, f1, f2)`` of every interface vertex (thesis
    eq. 3.23)::

        minimize    1/2 x^T H x                  H = diag(1e-3 c, 1 t, 1e-3 f1, 1e-3 f2)
        subject to  A_eq x + f_ext = 0           force and moment balance of free blocks
                    A_fr x <= 0                  friction pyramid, net or plus
                    c >= 0, t >= 0

    friction-net: ``|f1|, |f2| <= mu (c - t)`` (eq. 3.26, infeasible when the structure
    cannot stand without tension); friction+: ``|f1|, |f2| <= mu c`` (eq. 3.25, always
    feasible; the sum of tension is the measure of infeasibility, eq. 3.28). The problem
    is solved scaled (:mod:`masonry.equilibrium`), results are in newtons.

    Parameters
    ----------
    blocks : masonry.blocks.Blocks
    interfaces : masonry.interfaces.Interfaces
    mu : float
        Friction coefficient.
    density : float, kg/m^3
    friction : {'auto', 'net', 'plus'}
        ``'auto'`` (thesis 3.3.3): friction-net first; when it has no accepted solution,
        friction+ and report that.
    solver : {'osqp', 'clarabel'}
        See :data:`SOLVERS`.
    tol : Tolerances, optional
        ``tol.residual`` bounds the relative equilibrium residual and the friction
        violation of an accepted solution. Default ``Tolerances()``.
    lp_check : bool
        Run the independent friction-net feasibility LP (HiGHS, zero objective). Its
        time grows faster than the QP's: 22 s for a 1,000-block wall (Clarabel: 2.4 s).
    lp_time_limit : float, s
        HiGHS's time limit; when reached, ``lp_feasible`` is None and a warning is logged.
    side_block, side_rotation : optional
        Force routing for boundary modes, see :func:`masonry.equilibrium.assemble`.

    Returns
    -------
    RBEResult
        ``feasible`` is decided from the returned point, not from a solver status: a
        solution is accepted when its residuals are below ``tol.residual``, and the
        structure is feasible when the accepted ``x`` meets equilibrium and the
        friction-net pyramid within that tolerance.

    Notes
    -----
    Statuses (cvxpy's words): ``optimal``, ``optimal_inaccurate`` and ``user_limit``
    return a point, which is kept only if it passes the residual check (OSQP has said
    "solved" on infeasible problems); ``infeasible``, ``infeasible_inaccurate`` and
    ``solver_error`` return none. Under ``'auto'`` any friction-net outcome without an
    accepted point moves on to friction+, so a spurious "infeasible" on a nearly
    feasible structure is caught when the friction+ point meets the friction-net
    pyramid (then ``feasible`` is True and a warning is logged), and the LP's verdict
    is reported beside the QP's (a disagreement is logged).
    """
    start = time.perf_counter()
    if tol is None:
        tol = Tolerances()
    if friction not in ("auto",) + FRICTION_METHODS:
        raise ValueError(f"friction must be 'auto', 'net' or 'plus', not {friction!r}")
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver {solver!r}; choose from {sorted(SOLVERS)}")
    if len(interfaces) == 0:
        raise ValueError("no interfaces: nothing can carry the blocks")

    system = assemble(blocks, interfaces, mu=mu, density=density, side_block=side_block,
                      side_rotation=side_rotation)
    for method in ("net", "plus") if friction == "auto" else (friction,):
        status, x_scaled, iterations = _solve_qp(system, method, solver)
        checks = _check(system, x_scaled, method)
        if method == "net":
            net_status = status
        accepted = checks is not None and max(checks[0], checks[1]) <= tol.residual
        if x_scaled is not None and not accepted:
            log.warning("%s rejected the %s solution with status %r: equilibrium residual "
                        "%.2e, friction violation %.2e (tolerance %.1e)", solver, method,
                        status, checks[0], checks[1], tol.residual)
        if accepted:
            break

    lp_feasible = _lp_feasible(system, lp_time_limit) if lp_check else None
    residual_eq, violation, net_violation = (np.nan,) * 3 if checks is None else checks
    # a rejected point is no solution: its residuals are reported, its forces are not
    x = system.to_newtons(x_scaled) if accepted else None
    feasible = bool(accepted and net_violation <= tol.residual)
    if feasible and friction == "auto" and method == "plus":
        log.warning("friction-net was not solved (%s), yet the friction+ solution meets "
                    "the friction-net pyramid: reported feasible", net_status)
    if lp_feasible is not None and lp_feasible != feasible:
        log.warning("the friction-net LP says %s, the %s QP says %s (status %r)",
                    "feasible" if lp_feasible else "infeasible", solver,
                    "feasible" if feasible else "infeasible", status)

    weight = system.total_weight
    if x is None:
        objective = moi = np.nan
    else:
        objective = float(0.5 * np.sum(system.h * x**2))
        moi = float(system.layout.component(x, "t").sum())
    return RBEResult(
        feasible=feasible, friction=method, mu=float(mu), objective=objective, moi=moi,
        moi_factor=moi / weight, weight_N=weight, solver=solver, status=status,
        iterations=iterations, residual_eq=float(residual_eq),
        friction_violation=float(violation), net_friction_violation=float(net_violation),
        time_s=time.perf_counter() - start, lp_feasible=lp_feasible, x=x,
        layout=system.layout)


def _solve_qp(system: EquilibriumSystem, method: str, solver: str):
    """Solve the scaled QP. Returns (cvxpy status, x in solver units or None, iterations)."""
    n = system.layout.n_columns
    x = cp.Variable(n)
    bounded = np.flatnonzero(np.isfinite(system.lower))
    # H is a constant positive diagonal: psd_wrap skips cvxpy's eigenvalue check
    objective = cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(sp.diags_array(system.h_solver))))
    constraints = [system.A_eq @ x == -system.f_ext,
                   system.A_fr[method] @ x <= 0,
                   x[bounded] >= system.lower[bounded]]
    problem = cp.Problem(objective, constraints)
    name, options = SOLVERS[solver]
    try:
        problem.solve(solver=name, **options)
    except cp.error.SolverError as error:
        # cvxpy raises when the solver ends without a usable status (numerical error)
        log.warning("%s failed on the %s problem: %s", solver, method, error)
        return cp.SOLVER_ERROR, None, -1
    stats = problem.solver_stats
    iterations = stats.num_iters
    if iterations is None:
        # cvxpy drops OSQP's count when there is no solution; OSQP's own info has it
        iterations = getattr(getattr(stats.extra_stats, "info", None), "iter", None)
    x_value = x.value if problem.status in cp.settings.SOLUTION_PRESENT else None
    return problem.status, x_value, -1 if iterations is None else int(iterations)


def _check(system: EquilibriumSystem, x_scaled, method: str):
    """Residuals of a returned point, recomputed from the matrices.

    Returns ``(residual_eq, violation, net_violation)`` or None without a point.
    ``residual_eq = ||A_eq x + f_ext||_inf / ||f_ext||_inf``; the violations are the
    largest positive ``A_fr x`` (of ``method`` and of friction-net) or bound excess, in
    units of the reference weight.
    """
    if x_scaled is None:
        return None
    residual_eq = (np.abs(system.A_eq @ x_scaled + system.f_ext).max()
                   / np.abs(system.f_ext).max())
    bound = max(0.0, float((system.lower - x_scaled).max()))

    def violation(name):
        return max(bound, float((system.A_fr[name] @ x_scaled).max(initial=0.0)))

    return float(residual_eq), violation(method), violation("net")


def _lp_feasible(system: EquilibriumSystem, time_limit: float):
    """Friction-net feasibility by linear programming (HiGHS, zero objective).

    The pyramid is written by its edges instead of its faces: a vertex force with
    ``t = 0`` and ``|f1|, |f2| <= mu c`` is a nonnegative combination of the four edge
    rays ``(c, f1, f2) = (1, +-mu, +-mu)``, so the LP is ``A_eq G lam = -f_ext,
    lam >= 0`` with 4 unknowns per vertex and no inequality rows. Fixing ``t = 0`` loses
    nothing: a friction-net point with ``0 < t <= c`` stays one with ``(c - t, 0)``.
    The edge form is also a second, independent way to state the constraints. HiGHS's
    interior point method decides it: on the section of preset 1 (9,000 vertices) it
    proved infeasibility in 6 s where the dual simplex had no verdict after 120 s; the
    time still grows faster than linearly, hence ``time_limit``.

    Returns True, False, or None when HiGHS ends without a verdict (time limit).
    """
    mu = system.mu
    edges = np.array([[1.0, 1.0, 1.0, 1.0],    # c
                      [0.0, 0.0, 0.0, 0.0],    # t
                      [mu, mu, -mu, -mu],      # f1
                      [mu, -mu, mu, -mu]])     # f2
    generators = sp.kron(sp.identity(system.layout.n_vertices), edges, format="csr")
    A = sp.csc_array(system.A_eq @ generators)
    result = linprog(np.zeros(A.shape[1]), A_eq=A, b_eq=-system.f_ext, bounds=(0, None),
                     method="highs-ipm", options={"time_limit": time_limit})
    if result.status in (0, 2):
        return result.status == 0
    log.warning("friction-net LP inconclusive: %s", result.message)
    return None
