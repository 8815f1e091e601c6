"""Clarabel (interior point, homogeneous embedding): the RBE QP and the collapse program.

The RBE QP on the standard form, without cvxpy. Clarabel writes constraints as ``A x +
s = b, s in K``: the equilibrium rows are a zero cone, a pyramid's friction rows a
nonnegative cone and Coulomb's cone a second-order cone per vertex, the ``t >= 0`` rows
a nonnegative cone (``t`` enters as ``-t + s = 0``). One solver per scene and friction
model; friction+ and other friction coefficients update the matrix values in place,
which keeps Clarabel's KKT ordering (data updates need presolve off; presolve only drops
rows with infinite bounds, and this problem has none).

The collapse program (:class:`ClarabelProgram`): the equilibrium (and tie) rows in the
zero cone, the columns' cones after them (:mod:`masonry.rbe.solvers.program`). Clarabel
tells a dead load that cannot stand from a live load carried at any factor, which the
own interior point method does not (:mod:`masonry.rbe.collapse` asks it then).
"""

import logging
import time

import clarabel
import numpy as np
import scipy.sparse as sp

from masonry.friction import KINDS
from masonry.rbe.solvers.base import (INFEASIBLE, INFEASIBLE_INACCURATE, OPTIMAL,
                                      OPTIMAL_INACCURATE, SOLVER_ERROR, UNBOUNDED, USER_LIMIT,
                                      Backend, Outcome)
from masonry.rbe.solvers.program import NONNEGATIVE, HeldProgram
from masonry.rbe.solvers.standard_form import kept_form
from masonry.tolerances import ACCEPT_RESIDUAL

log = logging.getLogger(__name__)

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
    # qdldl: faster than the default (faer) on these KKT systems (docs/bench.md,
    # "Measurements behind design choices")
    "direct_solve_method": "qdldl",
}


def solve(system, method, options, workspace) -> Outcome:
    """One Clarabel solve; ``options`` are Clarabel settings (``DefaultSettings`` fields)."""
    start = time.perf_counter()
    form = kept_form(system, workspace)
    values = form.values(method, system.mu)
    # Clarabel's rows are A x + s = b: the t rows enter negated
    values[_tension_rows(form)] *= -1.0
    solver = workspace.get("solver")
    floor = system.compression_floor
    if solver is None or workspace.get("options") != options or floor is not None:
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
        if floor is not None:
            matrix, b = _with_floor(system, method, matrix, b, floor)
            cones.append(clarabel.NonnegativeConeT(len(floor)))
        solver = clarabel.DefaultSolver(form.P, np.zeros(form.P.shape[0]), matrix, b,
                                        cones, settings)
        # a truncated cone's solver is not kept: its rows are not the form's
        workspace.update(solver=None if floor is not None else solver, options=options,
                         values=values)
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
    return Outcome(status=status, x=x, iterations=int(result.iterations), y=y,
                   setup_time=setup, solve_time=time.perf_counter() - start - setup)


def _with_floor(system, method, matrix, b, floor):
    """``matrix`` and ``b`` with one row per vertex for the tension cut-off: ``c - t >=
    floor`` (friction-net) or ``c >= floor`` (friction+), as ``-(c - t) + s = -floor``
    with ``s`` nonnegative."""
    layout = system.layout
    vertex = np.arange(layout.n_vertices)
    rows = [vertex, vertex] if method == "net" else [vertex]
    cols = [layout.columns("c"), layout.columns("t")] if method == "net" else [
        layout.columns("c")]
    vals = [-np.ones(len(vertex)), np.ones(len(vertex))][:len(rows)]
    extra = sp.csc_array((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(len(vertex), matrix.shape[1]))
    return (sp.csc_array(sp.vstack([matrix, extra], format="csc")),
            np.concatenate([b, -np.asarray(floor, dtype=float)]))


def _tension_rows(form):
    """Slots of the ``t >= 0`` rows in the stacked matrix's data."""
    rows = form.rows
    row_of_slot = rows.indices
    return np.flatnonzero(row_of_slot >= form.n_eq + form.n_friction)


PROGRAM_SETTINGS = {"tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8, "tol_feas": 1e-8}
"""Clarabel's tolerances for the collapse program (its defaults; scaled rows of order
one); tighter gaps end "almost solved" on the full domes (docs/collapse.md)."""

CENTERING_SETTINGS = {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10}
"""Clarabel's tolerances for the centering force (:mod:`masonry.rbe.centering`), solved
once: at the collapse program's 1e-8 its total stopped 1e-3 of the mean block weight
above the optimum on preset 1's free web (an independent SOCP, docs/model.md 6.10), at
1e-10 within 1e-6, for four or five more iterations."""

PROGRAM_STATUS = {"Solved": OPTIMAL, "AlmostSolved": OPTIMAL,
                  "PrimalInfeasible": INFEASIBLE, "DualInfeasible": UNBOUNDED}
"""Clarabel's verdicts on a collapse program; other statuses keep Clarabel's words. An
"almost solved" point is kept when its equilibrium rows meet
:data:`~masonry.tolerances.ACCEPT_RESIDUAL` (with a warning)."""


class ClarabelProgram(HeldProgram):
    """A collapse program held by Clarabel (interior point, direct LDL): ``minimize -cost
    . lambda`` over ``[g, lambda]`` with the equilibrium (and tie) rows in the zero cone
    and the columns' cone constraints after them. A new lateral direction updates two
    entries of ``A`` and the costs in place, which keeps the symbolic factorization."""

    def __init__(self, program, workspace):
        super().__init__(program, workspace)
        matrix, loads, columns, tie = program.matrix, program.loads, program.columns, program.tie
        n, m = matrix.shape[1], loads.shape[1]
        rows = [sp.hstack([matrix, sp.csc_array(loads)])]
        if tie is not None:
            rows.append(sp.csc_array((np.asarray(tie, dtype=float), ([0, 0], [n, n + 1])),
                                     shape=(1, n + m)))
        self.n_eq = sum(r.shape[0] for r in rows)
        rows.append(sp.hstack([columns.G, sp.csc_array((columns.G.shape[0], m))]))
        self.cones = [clarabel.ZeroConeT(self.n_eq), *clarabel_cones(columns.cones)]
        self.A = sp.csc_matrix(sp.vstack(rows, format="csc"))
        self.A.sort_indices()
        rhs = program.rhs
        self.b = np.concatenate([rhs, np.zeros(self.n_eq - len(rhs)), columns.h])
        self.q = np.concatenate([np.zeros(n), -np.asarray(program.cost, dtype=float)])
        self.n, self.m = n, m
        if tie is not None:  # where the tie row's two entries sit in A.data
            self.tie_at = [self.A.indptr[c] + np.flatnonzero(
                self.A.indices[self.A.indptr[c]:self.A.indptr[c + 1]] == self.n_eq - 1)[0]
                for c in (n, n + 1)]
        self.solver = None

    def _settings(self):
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.presolve_enable = False  # keep the rows: data updates need them
        settings.time_limit = float(self.program.time_limit)
        for name, value in PROGRAM_SETTINGS.items():
            setattr(settings, name, value)
        return settings

    def solve(self) -> Outcome:
        start = time.perf_counter()
        if self.solver is None:
            size = self.n + self.m
            self.solver = clarabel.DefaultSolver(sp.csc_matrix((size, size)), self.q,
                                                 self.A, self.b, self.cones, self._settings())
        setup = time.perf_counter() - start
        solution = self.solver.solve()
        status = str(solution.status)
        words = PROGRAM_STATUS.get(status, status)
        iterations = int(solution.iterations)
        if status == "AlmostSolved":
            x = np.array(solution.x)
            residual = np.abs(self.A[: self.n_eq] @ x - self.b[: self.n_eq]).max()
            if residual > ACCEPT_RESIDUAL * np.abs(self.b[: self.n_eq]).max():
                words = status
            else:
                log.warning("Clarabel: almost solved, kept (relative residual %.1e)",
                            residual / np.abs(self.b[: self.n_eq]).max())
        times = dict(setup_time=setup, solve_time=time.perf_counter() - start - setup)
        if words != OPTIMAL:
            return Outcome(words, None, iterations, **times)
        x = np.array(solution.x)
        rows = self.program.matrix.shape[0]
        return Outcome(OPTIMAL, self.program.columns.edges @ x[:self.n], iterations,
                       y=np.array(solution.z)[:rows],
                       info={"load_factor": float(-self.q[self.n:] @ x[self.n:])}, **times)

    def stands_unloaded(self) -> bool | None:
        """The dead load alone: the load columns dropped, a zero objective."""
        A = sp.csc_matrix(self.A[:, : self.n])
        solver = clarabel.DefaultSolver(sp.csc_matrix((self.n, self.n)), np.zeros(self.n),
                                        A, self.b, self.cones, self._settings())
        status = str(solver.solve().status)
        return {"Solved": True, "PrimalInfeasible": False}.get(status)

    def direct(self, cos, sin):
        self.A.data[self.tie_at[0]], self.A.data[self.tie_at[1]] = -sin, cos
        self.q[self.n:] = (-cos, -sin)
        if self.solver is not None:
            self.solver.update(q=self.q, A=self.A)


def solve_cone_program(q, A, b, G, h, cones, time_limit, tolerances=None) -> tuple:
    """``minimize q . z`` subject to ``A z = b`` and ``h - G z`` in ``cones`` (the
    ``(kind, dimension, count)`` of :attr:`~masonry.rbe.solvers.program.Columns.cones`),
    with Clarabel's ``tolerances`` (default the collapse program's,
    :data:`PROGRAM_SETTINGS`): a program stated once and solved once (the centering
    force, :mod:`masonry.rbe.centering`, with :data:`CENTERING_SETTINGS`).

    Returns
    -------
    status : str
        Clarabel's words (``Solved``, ``AlmostSolved``, ...).
    z : (n,) float or None
        Clarabel's point, unless it has none (neither solved nor almost).
    iterations : int
    """
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.time_limit = float(time_limit)
    for name, value in (PROGRAM_SETTINGS if tolerances is None else tolerances).items():
        setattr(settings, name, value)
    n = len(q)
    solver = clarabel.DefaultSolver(
        sp.csc_matrix((n, n)), np.asarray(q, dtype=float),
        sp.csc_matrix(sp.vstack([A, G], format="csc")), np.concatenate([b, h]),
        [clarabel.ZeroConeT(A.shape[0]), *clarabel_cones(cones)], settings)
    solution = solver.solve()
    status = str(solution.status)
    z = np.array(solution.x) if status in ("Solved", "AlmostSolved") else None
    return status, z, int(solution.iterations)


def clarabel_cones(cones) -> list:
    """Clarabel's cones of :attr:`~masonry.rbe.solvers.program.Columns.cones`."""
    out = []
    for kind, dimension, count in cones:
        cone = (clarabel.NonnegativeConeT(dimension) if kind == NONNEGATIVE
                else clarabel.SecondOrderConeT(dimension))
        out += [cone] * count
    return out


BACKEND = Backend("clarabel", settings="clarabel", rbe=solve, collapse=ClarabelProgram,
                  truncated=KINDS)
"""Clarabel: the RBE QP (every friction model) and the collapse program."""
