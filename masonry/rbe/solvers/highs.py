"""HiGHS (highspy): the collapse program of the pyramids, and the RBE's friction-net check.

:func:`highs_lp` makes a HiGHS linear program from scipy.sparse arrays;
:class:`HighsProgram` holds a collapse program (:mod:`masonry.rbe.solvers.program`) by
the settings of one of :data:`SETTINGS`; :func:`nonnegative_solution` decides the RBE's
independent friction-net LP (:func:`masonry.rbe.lp_check.lp_feasible`).
"""

import functools
import time

import highspy
import highspy.highs
import numpy as np
import scipy.sparse as sp

from masonry.rbe.solvers.base import INFEASIBLE, OPTIMAL, UNBOUNDED, Backend, Outcome
from masonry.rbe.solvers.program import HeldProgram

_HIGHS = getattr(highspy.highs, "_Highs", highspy.Highs)
"""The HiGHS class without highspy's Python layer: from highspy 1.16, ``highspy.Highs()``
prints HiGHS's banner to standard output as it sets up its callbacks, before
``output_flag`` can be switched off (github.com/ERGO-Code/HiGHS issues 1702, 2749); the
class under it prints nothing until run, and has every method used here (no callbacks are
used)."""


def highs_lp(A, cost, col_lower, col_upper, row_lower, row_upper, options,
             maximize=False) -> _HIGHS:
    """A HiGHS instance holding ``cost @ x`` (minimised, or maximised when ``maximize``)
    subject to ``row_lower <= A x <= row_upper`` and ``col_lower <= x <= col_upper``.

    Parameters
    ----------
    A : (m, n) scipy.sparse CSC array
    cost, col_lower, col_upper : (n,) float (``highspy.kHighsInf`` for no bound)
    row_lower, row_upper : (m,) float
    options : iterable of (name, value)
        HiGHS options; output is switched off first.

    Raises
    ------
    ValueError
        HiGHS refused an option (a misspelt name or a value out of its range).
    """
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = A.shape[1], A.shape[0]
    lp.col_cost_ = np.asarray(cost, dtype=float)
    lp.col_lower_, lp.col_upper_ = col_lower, col_upper
    lp.row_lower_, lp.row_upper_ = row_lower, row_upper
    if maximize:
        lp.sense_ = highspy.ObjSense.kMaximize
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
        A.indptr, A.indices, A.data)
    highs = _HIGHS()
    for name, value in (("output_flag", False), *options):
        if highs.setOptionValue(name, value) != highspy.HighsStatus.kOk:
            raise ValueError(f"HiGHS refused option {name}={value!r}")
    highs.passModel(lp)
    return highs


SETTINGS = {
    "highs-ipm": {"solver": "ipm", "run_crossover": "off"},
    "highs-crossover": {"solver": "ipm", "run_crossover": "on"},
    "highs-simplex": {"solver": "simplex"},
}
"""HiGHS's settings by backend name: its interior point method (IPX) without or with
crossover to a vertex, or its dual simplex (whose basis warm-starts the next load case).
They solve linear programs: the pyramids only."""

FEASIBILITY_TOL = 1e-7
"""HiGHS's primal and dual feasibility tolerance for the collapse program (scaled rows:
of order one)."""


def load_columns(loads):
    """Columns and link rows for ``loads`` ((6 F, m) float), one chain per load.

    A load column touches every loaded row, and one dense column makes an interior
    point method's normal equations dense. So each load gets one factor column per
    loaded block (its six rows), chained equal by link rows ``lambda_i - lambda_i+1
    = 0``: every column stays sparse. Returns the sparse columns ((6 F, c)), the link
    rows ((r, c)) and the first column of each chain, the one that stands for its
    ``lambda``.
    """
    columns, links, heads, start = [], [], [], 0
    for load in loads.T:
        per_block = load.reshape(-1, 6)
        blocks = np.flatnonzero(np.abs(per_block).max(axis=1) > 0)
        if len(blocks) == 0:
            raise ValueError("the live load is zero on every free block")
        rows = (6 * blocks[:, None] + np.arange(6)).ravel()
        chain = np.repeat(np.arange(len(blocks)), 6)
        columns.append(sp.csc_array((load[rows], (rows, chain)),
                                    shape=(len(load), len(blocks))))
        link = np.arange(len(blocks) - 1)
        links.append(sp.csc_array((np.r_[np.ones(len(link)), -np.ones(len(link))],
                                   (np.r_[link, link], np.r_[link, link + 1])),
                                  shape=(len(link), len(blocks))))
        heads.append(start)
        start += len(blocks)
    return sp.hstack(columns, format="csc"), sp.block_diag(links, format="csc"), heads


def _model(program, settings):
    """A HiGHS model of ``program``: columns ``g`` (>= 0), then the free load-factor
    chains of :func:`load_columns`; equilibrium rows, link rows, and a row tying two
    loads to one direction. Returns ``(highs, head columns, tie row)``."""
    matrix, n = program.matrix, program.matrix.shape[1]
    columns, links, heads = load_columns(program.loads)
    heads = np.asarray(heads, dtype=np.int32) + n
    A = sp.vstack([sp.hstack([matrix, columns]),
                   sp.hstack([sp.csc_array((links.shape[0], n)), links])], format="csc")
    lower = np.concatenate([program.rhs, np.zeros(links.shape[0])])
    tie_row = A.shape[0]
    if program.tie is not None:
        A = sp.vstack([A, sp.csc_array((np.asarray(program.tie), ([0, 0], heads)),
                                       shape=(1, A.shape[1]))], format="csc")
        lower = np.append(lower, 0.0)
    col_cost = np.zeros(A.shape[1])
    col_cost[heads] = program.cost
    free = np.full(A.shape[1] - n, highspy.kHighsInf)
    highs = highs_lp(A, col_cost, np.concatenate([np.zeros(n), -free]),
                     np.concatenate([np.full(n, highspy.kHighsInf), free]), lower, lower,
                     (*settings.items(), ("time_limit", float(program.time_limit)),
                      ("primal_feasibility_tolerance", FEASIBILITY_TOL),
                      ("dual_feasibility_tolerance", FEASIBILITY_TOL)), maximize=True)
    return highs, heads, tie_row


class HighsProgram(HeldProgram):
    """A collapse program held by HiGHS: :meth:`solve` from the last basis, the load
    factors fixed at 0 for the dead load check, a new lateral direction by two
    coefficients and two costs.

    Raises
    ------
    ValueError
        Columns that are not edge rays (Coulomb's cone, a fixed capacity): HiGHS solves
        linear programs.
    """

    def __init__(self, program, workspace, method):
        super().__init__(program, workspace)
        if not program.columns.is_rays:
            raise ValueError(f"HiGHS ({method}) solves linear programs: the friction model "
                             f"{program.system.cone} needs another solver, or a "
                             f"polygon:K model")
        start = time.perf_counter()
        self.highs, self.heads, self.tie_row = _model(program, SETTINGS[method])
        self.setup_time = time.perf_counter() - start

    def _status(self) -> str:
        # HiGHS's time limit counts from its creation: give every run its own
        self.highs.setOptionValue("time_limit",
                                  self.highs.getRunTime() + self.program.time_limit)
        self.highs.run()
        Status = highspy.HighsModelStatus
        status = self.highs.getModelStatus()
        if status == Status.kUnboundedOrInfeasible:
            # presolve's verdict does not say which; the solver without it does
            self.highs.setOptionValue("presolve", "off")
            self.highs.run()
            self.highs.setOptionValue("presolve", "choose")
            status = self.highs.getModelStatus()
        return {Status.kOptimal: OPTIMAL, Status.kInfeasible: INFEASIBLE,
                Status.kUnbounded: UNBOUNDED}.get(status,
                                                  self.highs.modelStatusToString(status))

    def solve(self) -> Outcome:
        start = time.perf_counter()
        status = self._status()
        info = self.highs.getInfo()
        iterations = int(info.simplex_iteration_count + info.ipm_iteration_count)
        times = dict(setup_time=self.setup_time, solve_time=time.perf_counter() - start)
        self.setup_time = 0.0
        if status != OPTIMAL:
            return Outcome(status, None, iterations, **times)
        solution = self.highs.getSolution()
        edges = self.program.columns.edges
        values = np.array(solution.col_value)[:edges.shape[1]]
        rows = self.program.matrix.shape[0]
        return Outcome(OPTIMAL, edges @ values, iterations,
                       y=np.array(solution.row_dual)[:rows],
                       info={"load_factor": float(info.objective_function_value)}, **times)

    def stands_unloaded(self) -> bool | None:
        zeros = np.zeros(len(self.heads))
        self.highs.changeColsBounds(len(self.heads), self.heads, zeros, zeros)
        status = self._status()
        self.highs.changeColsBounds(len(self.heads), self.heads, zeros - highspy.kHighsInf,
                                    zeros + highspy.kHighsInf)
        return {OPTIMAL: True, INFEASIBLE: False}.get(status)

    def direct(self, cos, sin):
        self.highs.changeCoeff(self.tie_row, self.heads[0], -sin)
        self.highs.changeCoeff(self.tie_row, self.heads[1], cos)
        self.highs.changeColsCost(2, self.heads, np.array([cos, sin]))


BACKENDS = tuple(Backend(name, settings="highs",
                         collapse=functools.partial(HighsProgram, method=name),
                         polyhedral_only=True) for name in SETTINGS)
"""The HiGHS backends: the collapse program only (the RBE's friction-net check,
:func:`nonnegative_solution`, is an LP of its own)."""


def nonnegative_solution(A, rhs, time_limit) -> tuple:
    """Whether ``A lam = rhs`` has a solution ``lam >= 0``, by HiGHS's interior point
    method without crossover (a zero objective: only the verdict is needed, not a vertex).

    Parameters
    ----------
    A : (m, n) scipy.sparse CSC array
    rhs : (m,) float
    time_limit : float, s

    Returns
    -------
    (bool or None, str)
        True, False, or None without a verdict (the time limit); HiGHS's status words.
    """
    solver = highs_lp(A, np.zeros(A.shape[1]), np.zeros(A.shape[1]),
                      np.full(A.shape[1], highspy.kHighsInf), rhs, rhs,
                      (*SETTINGS["highs-ipm"].items(), ("time_limit", float(time_limit))))
    solver.run()
    status = solver.getModelStatus()
    # with a zero objective nothing is unbounded: either verdict means infeasible
    verdict = {highspy.HighsModelStatus.kOptimal: True,
               highspy.HighsModelStatus.kInfeasible: False,
               highspy.HighsModelStatus.kUnboundedOrInfeasible: False}.get(status)
    return verdict, solver.modelStatusToString(status)
