"""Solve rigid block equilibrium (RBE) as a quadratic program (docs/model.md 6.5 to 6.7).

The matrices come from :mod:`masonry.rbe.equilibrium`, the solvers from
:mod:`masonry.rbe.solvers`; this module chooses them by accuracy preset
(:mod:`masonry.rbe.accuracy`, docs/model.md 6.6), runs the thesis's friction flow (friction-net,
then friction+ when the structure is infeasible), checks what every solver returned and
packs the result. A solver's status is never
trusted alone: the equilibrium residual and the friction violation are recomputed from
the returned point (every backend's outcome carries them), and an independent linear
program (HiGHS) can check friction-net feasibility.

:class:`RBEProblem` keeps one scene's matrices, symbolic factorizations and solver
objects between solves, so a sweep over ``mu`` or ``density``, or friction+ after
friction-net, does not start from scratch; :func:`solve_rbe` is one solve.

The solvers neither fork nor set threads: this module decides (:mod:`masonry.rbe.cores`),
from the cores its caller allows (``cores``, default the process's:
:func:`masonry.forking.cores`). It solves inside
:func:`~masonry.rbe.cores.solver_threads` (BLAS on one thread, factorizations on up to
two), and with a second core, when Newton neither solves nor certifies friction-net, it
solves friction+ there while the load-path LP decides friction-net
(:class:`~masonry.rbe.cores.Alongside`).
"""

import dataclasses
import functools
import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry import forking
from masonry.contact import ContactLaw
from masonry.rbe.accuracy import ACCURACY, AccuracyPreset, friction_model
from masonry.rbe.cores import Alongside, solver_threads
from masonry.rbe.equilibrium import FRICTION_METHODS, assemble
from masonry.rbe.lp_check import lp_feasible as check_by_lp
from masonry.rbe.result import RBEResult
from masonry.rbe.solvers import BACKENDS, RBE, backend, names, net_feasibility
from masonry.rbe.solvers.base import INFEASIBLE, OPTIMAL
from masonry.rbe.solvers.newton import NewtonOptions, prepared_system
from masonry.rbe.solvers.residuals import Residuals, rbe_residuals
from masonry.tolerances import Tolerances

__all__ = ["ACCURACY", "AccuracyPreset", "RBEProblem", "RBEResult", "friction_model",
           "solve_rbe"]

log = logging.getLogger(__name__)


POLISH_STEPS = 20
"""Newton steps a polish may take. From a pyramid's interior point one or two steps
usually find the exact active set. Coulomb's cone has no active set to find: its interior
point stops at a gap of about 1e-7 of the objective (the cone's scaling spans more
decades than double precision holds), and Newton's first steps from there are damped
before it converges quadratically. The bound leaves room for both."""

POLISH_STALL = 8
"""... and it ends after this many steps without halving the residual: a polish that
converges halves it within a few damped steps, one that does not creeps at 1e-9 with
tiny steps and is not kept."""


LOAD_PATH = "load-path-lp"
"""The load-path LP's name among the candidates and in :attr:`RBEResult.attempts`."""

LOAD_PATH_STALL = 20
"""Newton's ``stall`` on friction-net when the load-path LP follows it (Newton's own,
25, otherwise): steps without halving the residual before the LP decides. Large
feasible domes wander nearly that long before converging (preset 1 with ``--p 19`` and
``--p 21``); a shorter stall makes them pay an LP and Newton's second run for nothing
(docs/bench.md, "Newton's hand-over to the load-path LP")."""

LOAD_PATH_DAMPED_OUT = 3
"""Newton's ``damped_out`` on friction-net when the load-path LP follows it (off
otherwise): steps in a row ending at the damping ceiling before the LP decides. On the
infeasible low-friction domes measured, Newton's steps ended there in long runs until
its stall; no feasible structure measured ended two steps in a row there (docs/bench.md,
"Newton's hand-over to the load-path LP"). A wrong
hand-over costs one LP, never a wrong verdict: a feasible verdict resumes Newton without
this rule."""

RESUME_STALL = 16
"""Newton's ``stall`` when it resumes after the load-path LP found friction-net
feasible; then the interior point method takes over. A dome near its limit resumes and
converges with long gaps between halvings of its residual (a shorter stall handed the
largest measured to the interior point method, which took longer); an arch of many
voussoirs crawls, a hinge at a time, where the interior point method's iterations do
not grow with the count (docs/bench.md, "Newton's steps and the size of the model")."""

WARM_NEWTON = "newton-warm"
"""Among the candidates: Newton from a given warm start (:meth:`RBEProblem.of_system`),
before the preset's solver of a model it does not lead; recorded as ``newton``."""

WARM_STEPS = 30
"""Newton steps from a warm start before the preset's solver takes over ..."""

WARM_STALL = 8
"""... or steps without halving the residual. From the last stage's friction+ point,
the next construction stage's friction+ took 7 to 14 steps on preset 1's upper courses
(docs/stages.md), where the interior point method and its polish take about 15
iterations and 2 steps; friction+ from a cold start is slowed by the 1,000:1 tension
weight, so a start that is not close hands over early."""

SOLVERS = names(RBE)
"""Every solver name :func:`solve_rbe` accepts (the registry's RBE backends)."""

class RBEProblem:
    """One scene's rigid block equilibrium, prepared for any number of solves.

    Assembles the scaled matrices once (:func:`masonry.rbe.equilibrium.assemble`); every
    :meth:`solve` reuses them with its own ``mu`` and ``density``, and every solver keeps
    its workspace (Newton's symbolic Cholesky factorization and last dual point, the
    OSQP and Clarabel solver objects, updated in place) between friction-net and
    friction+ and between solves.

    Parameters
    ----------
    blocks : masonry.blocks.Blocks
    interfaces : masonry.interfaces.Interfaces
    side_block, side_rotation, dropped_rows, vertex_share : optional
        Force routing for boundary modes and a half model's rows and shares, see
        :func:`masonry.rbe.equilibrium.assemble` (a model's :attr:`~masonry.rbe.boundary.
        Model.assembly`).
    """

    def __init__(self, blocks, interfaces, *, side_block=None, side_rotation=None,
                 dropped_rows=None, vertex_share=None):
        if len(interfaces) == 0:
            raise ValueError("no interfaces: nothing can carry the blocks")
        self.system = assemble(blocks, interfaces, side_block=side_block,
                               side_rotation=side_rotation, dropped_rows=dropped_rows,
                               vertex_share=vertex_share)
        self._workspaces = {}
        self.duals = {}
        """Friction model -> the equilibrium multipliers ((6 F,) float, solver units) of
        its last accepted point: the start of a similar problem's solve."""

    @classmethod
    def of_system(cls, system, *, symbolic=None, starts=None) -> "RBEProblem":
        """A problem on an assembled ``system`` (:class:`EquilibriumSystem`, e.g. a part
        of a larger one: :mod:`masonry.rbe.sequence`).

        Parameters
        ----------
        symbolic : BlockCholesky, optional
            The symbolic factorization of its Newton matrices (six rows per free block on
            the contact graph), made beforehand (from a given ordering).
        starts : dict str -> (6 F,) float, optional
            Per friction model (``'net'``, ``'plus'``), the dual point its Newton
            iterations start from (a similar problem's :attr:`duals`). friction+ is then
            tried by Newton from it first, for at most :data:`WARM_STEPS` steps, before
            the preset's solver.
        """
        problem = cls.__new__(cls)
        problem.system, problem._workspaces, problem.duals = system, {}, {}
        workspace = problem._workspace("newton")
        if symbolic is not None:
            workspace["symbolic"] = symbolic
        workspace["warm"] = dict(starts or {})
        return problem

    def solve(self, mu=0.7, density=2000.0, friction="auto", solver=None, tol=None, *,
              accuracy="balanced", cone=None, lp_check=None, lp_time_limit=60.0,
              cores=None, cohesion=0.0, tensile=0.0) -> RBEResult:
        """Solve at ``mu`` and ``density``; see :func:`solve_rbe` for the parameters."""
        start = time.perf_counter()
        preset, tol, lp_check = _settings(friction, solver, tol, accuracy, lp_check)
        cone = friction_model(preset.name, cone)
        ContactLaw.of(cone, mu, cohesion, tensile)  # refuses a strength out of range
        if solver is not None:
            backend(solver, RBE, cone)  # refuses a friction model it cannot state
        system = self.system.with_material(mu=mu, density=density, cone=cone,
                                           cohesion=cohesion, tensile=tensile)
        if solver is not None and BACKENDS[solver].refusal(system) is not None:
            raise ValueError(BACKENDS[solver].refusal(system))
        cores = forking.usable_cores(cores)
        with solver_threads(cores):
            solved, attempts = self._flow(system, friction, solver, preset, tol, cores)
            standing = self._standing(system, solved, friction, solver, preset, tol,
                                      attempts)
            result = self._result(system, solved, tol, lp_check, lp_time_limit, accuracy,
                                  attempts, friction, standing)
        log.info("%s: %s, MoI factor %.4g, residual %.1e, %.2f s", result.solver,
                 result.verdict, result.moi_factor, result.residual_eq,
                 time.perf_counter() - start)
        return dataclasses.replace(result, time_s=time.perf_counter() - start)

    def _flow(self, system, friction, solver, preset, tol, cores):
        """The thesis's friction flow (friction-net, then friction+ unless friction-net
        was solved; or the one model asked for), friction+ on a second core when
        :class:`~masonry.rbe.cores.Alongside` may: ``(the last model's _Solved, attempts)``."""
        attempts = []
        alongside = None
        if Alongside.wanted(friction, solver, preset, cores):
            alongside = Alongside(functools.partial(
                self._solve_model, system, "plus", _candidates("plus", solver, preset),
                preset, tol))
        try:
            for method in ("net", "plus") if friction == "auto" else (friction,):
                solved = None
                if method == "plus" and alongside is not None and alongside.started:
                    solved = alongside.solved(attempts)
                if solved is None:
                    log.info("solving friction-%s (mu %.3g, %d unknowns)", method,
                             system.mu, system.layout.n_columns)
                    solved = self._solve_model(
                        system, method, self._candidates(method, solver, preset), preset,
                        tol, attempts, before_lp=alongside.start if alongside else None)
                if solved.accepted:
                    break
                if method == "net" and friction == "auto":
                    log.info("friction-net has no solution (%s from %s): friction+ measures "
                             "the tension needed", solved.outcome.status, solved.name)
        finally:
            if alongside is not None:
                alongside.close()
        return solved, attempts

    def _standing(self, system, solved, friction, solver, preset, tol, attempts):
        """Whether the structure stands, where the one model asked for does not say:
        a friction+ point may carry tension where none is needed (its optimum trades
        compression for a little tension), so only friction-net decides. Returns
        friction-net's :class:`_Solved` (its solves join ``attempts``: an accepted point
        or a certificate decides), or None where ``solved`` decides already."""
        if friction != "plus" or not solved.accepted or (
                solved.checks.net_friction <= tol.residual):
            return None
        return self._solve_model(system, "net", self._candidates("net", solver, preset),
                                 preset, tol, attempts)

    def _candidates(self, method, solver, preset) -> list:
        """:func:`_candidates`, led by Newton where a warm start of ``method`` was given
        (:meth:`of_system`) and the preset's first solver is another."""
        candidates = _candidates(method, solver, preset)
        warm = self._workspace("newton").get("warm", {})
        if solver is None and method in warm and candidates[0] != "newton":
            return [WARM_NEWTON, *candidates]
        return candidates

    def _solve_model(self, system, method, candidates, preset, tol, attempts,
                     before_lp=None) -> "_Solved":
        """One friction model: the candidate solvers in turn until one returns an
        accepted point (polished if the preset says so) or certifies infeasibility.
        Every QP solved is appended to ``attempts``; ``before_lp`` (a callable) is
        called when Newton hands friction-net over to the load-path LP. Where the LP
        found an accepted friction-net point and no solver then reached the QP's
        optimum, or one certified infeasibility within its tolerance against that
        point, the LP's point is the answer (:meth:`_load_path_point`)."""
        outcome = found = None
        candidates = _stated(system, method, candidates, attempts)
        for index, name in enumerate(candidates):
            if name == LOAD_PATH:
                if before_lp is not None:
                    before_lp()
                name, outcome, found = self._load_path(system, preset, tol, outcome,
                                                       attempts)
            else:
                # Newton hands over sooner when the load-path LP follows it
                hand_over = ({"stall": LOAD_PATH_STALL, "damped_out": LOAD_PATH_DAMPED_OUT}
                             if LOAD_PATH in candidates[index:] else {})
                if name == WARM_NEWTON:
                    name, hand_over = "newton", {"max_iter": WARM_STEPS,
                                                 "stall": WARM_STALL}
                outcome = self._run(system, method, name, preset, **hand_over)
            checks = outcome.residuals
            accepted = _accepted(checks, tol)
            attempts.append(_record(method, name, outcome))
            if outcome.x is not None and not accepted:
                log.info("%s rejected the %s solution with status %r: equilibrium "
                         "residual %.2e, friction violation %.2e (tolerance %.1e)",
                         name, method, outcome.status, checks.equilibrium,
                         checks.friction, tol.residual)
            if (accepted and preset.polish and name != "newton" and outcome.y is not None
                    and BACKENDS["newton"].refusal(system) is None):
                polished = self._polish(system, method, outcome, tol, attempts)
                if polished is not None:
                    outcome, checks, name = polished, polished.residuals, f"{name}+newton"
            if accepted and outcome.y is not None:
                self.duals[method] = outcome.y
            if outcome.status == INFEASIBLE and found is not None:
                return self._load_path_point(method, found, certifier=name)
            if accepted or outcome.status == INFEASIBLE:
                if outcome.status == INFEASIBLE:
                    log.info("%s certified friction-%s infeasible", name, method)
                return _Solved(method, name, outcome, checks, accepted)
            if index + 1 < len(candidates):
                # no silent fallback: a fallback warns and stays in ``attempts``
                log.info("%s found no %s solution (%s); trying %s", name, method,
                         outcome.status, candidates[index + 1])
        if found is not None:
            return self._load_path_point(method, found)
        return _Solved(method, name, outcome, checks, False)

    def _load_path(self, system, preset, tol, stalled, attempts):
        """After Newton (``stalled``, its outcome) neither solved nor certified
        friction-net: the load-path LP's verdict (:mod:`~masonry.rbe.solvers.net_feasibility`).
        Its certificate, or its undecided outcome, is returned as is. When it finds
        friction-net feasible (a point within the accepted residual, not the QP's
        optimum), Newton resumes from its last dual point until its residual stops
        halving for :data:`RESUME_STALL` steps, and then the interior point method, which
        assumes a feasible program, solves friction-net; where that method cannot state
        the friction model (a cone truncated by a tension cut-off), Newton runs to its
        own stall and the next candidate follows. Returns ``(solver name, outcome, the
        LP's point)``: the last an outcome whose ``x`` is the LP's point with its
        residuals, None unless the LP found one that passes the acceptance check (which,
        unlike the LP, holds the tension cut-off); the records of the LP and of a resumed
        Newton that stalled join ``attempts``."""
        workspace = self._workspace("newton")
        options = preset.options.get("newton", {})
        ns = prepared_system(system, "net", workspace)
        decided = net_feasibility.decide(ns, NewtonOptions(**options).infeasibility_tol,
                                         tol.residual)
        if decided.info["verdict"] != net_feasibility.FEASIBLE:
            return LOAD_PATH, decided, None
        x = ns.full_vector(decided.info["forces"], system.layout)
        found = dataclasses.replace(decided, x=x, residuals=rbe_residuals(system, x, "net"))
        found = found if _accepted(found.residuals, tol) else None
        is_interior_next = BACKENDS["interior"].refusal(system) is None
        if stalled.y is None and not is_interior_next:
            return LOAD_PATH, decided, found
        attempts.append(_record("net", LOAD_PATH, decided))
        if stalled.y is not None:
            log.info("the load-path LP found friction-net feasible: Newton resumes")
            stall = {"stall": RESUME_STALL} if is_interior_next else {}
            resumed = BACKENDS["newton"].solve_rbe(system, "net", {**options, **stall},
                                                   workspace, y0=stalled.y)
            if resumed.status in (OPTIMAL, INFEASIBLE) or not is_interior_next:
                return "newton", resumed, found
            attempts.append(_record("net", "newton", resumed))
        log.info("the interior point method solves friction-net, which the load-path LP "
                 "found feasible")
        return "interior", self._run(system, "net", "interior", preset), found

    @staticmethod
    def _load_path_point(method, found, certifier=None) -> "_Solved":
        """Friction-net answered by the load-path LP's accepted point (``found``, its
        outcome): no solver reached the QP's optimum after the LP found it, or
        ``certifier`` (a solver's name) certified infeasibility within its tolerance
        against it (a point that balances the dead load within the friction model and
        the accepted residual, recomputed, is what feasible means). Without it friction+
        would run and report the little tension its optimum trades for compression.
        The forces are an equilibrium, not the QP's least-norm one (docs/model.md 6.6)."""
        if certifier is None:
            log.warning("no solver reached friction-net's optimum after the load-path LP "
                        "found it feasible: the LP's point is the answer (an equilibrium "
                        "within the friction model, not the QP's least-norm forces)")
        else:
            log.warning("%s certified friction-net infeasible within its tolerance, the "
                        "load-path LP found a point within the accepted residual: the "
                        "LP's point is the answer", certifier)
        return _Solved(method, LOAD_PATH, found, found.residuals, True)

    def _polish(self, system, method, outcome, tol, attempts):
        """Newton steps from ``outcome``'s multipliers: the polished outcome, or None when
        they do not converge within :data:`POLISH_STEPS` (its record joins ``attempts``
        either way)."""
        workspace = self._workspace("newton")
        options = {"tol": min(tol.residual, 1e-9), "max_iter": POLISH_STEPS,
                   "stall": POLISH_STALL}
        polished = BACKENDS["newton"].solve_rbe(system, method, options, workspace,
                                                y0=outcome.y)
        attempts.append(_record(method, "newton-polish", polished))
        if polished.status == OPTIMAL and _accepted(polished.residuals, tol):
            return polished
        log.info("Newton polish of the %s solution did not converge in %d steps (%s); "
                 "the unpolished point is kept", method, POLISH_STEPS, polished.status)
        return None

    def _result(self, system, solved, tol, lp_check, lp_time_limit, accuracy, attempts,
                friction, standing=None) -> RBEResult:
        """Pack the last model's outcome: residuals, forces in newtons, the verdict
        (with ``standing``, friction-net's outcome where it decides for a friction+
        point, :meth:`_standing`) and the LP's second opinion."""
        checks, accepted, outcome = solved.checks, solved.accepted, solved.outcome
        residual_eq, violation, net_violation = ((np.nan,) * 3 if checks is None else (
            checks.equilibrium, checks.friction, checks.net_friction))
        # a rejected point is no solution: its residuals are reported, its forces are not;
        # the forces are physical (a cohesion's shift taken off the compressions)
        x = system.to_newtons(system.shifted(outcome.x, -1.0)) if accepted else None
        feasible = bool(accepted and net_violation <= tol.residual
                        or standing is not None and standing.accepted)
        run_lp = ((lp_check == "infeasible" and not feasible) if isinstance(lp_check, str)
                  else bool(lp_check))
        lp_start = time.perf_counter()
        lp_feasible = check_by_lp(system, lp_time_limit, feasible) if run_lp else None
        lp_time = time.perf_counter() - lp_start if run_lp else 0.0
        if feasible and solved.method == "plus" and friction == "auto":
            log.warning("friction-net was not solved, yet the friction+ solution meets the "
                        "friction-net constraints: reported feasible")
        if lp_feasible is not None and lp_feasible != feasible:
            log.warning("the friction-net LP says %s, the %s QP says %s (status %r)",
                        "feasible" if lp_feasible else "infeasible", solved.name,
                        "feasible" if feasible else "infeasible", outcome.status)
        weight = system.total_weight
        objective = moi = np.nan
        if x is not None:
            solved_x = system.to_newtons(outcome.x)  # the program's own variables
            objective = float(0.5 * np.sum(system.h * solved_x**2))
            moi = float(system.layout.component(x, "t").sum())
        return RBEResult(
            feasible=feasible, friction=solved.method, mu=float(system.mu),
            objective=objective, moi=moi, moi_factor=moi / weight, weight_N=weight,
            solver=solved.name, status=outcome.status, iterations=outcome.iterations,
            residual_eq=float(residual_eq), friction_violation=float(violation),
            net_friction_violation=float(net_violation), time_s=0.0,
            lp_feasible=lp_feasible, x=x, layout=system.layout, accuracy=accuracy,
            lp_time_s=lp_time, attempts=tuple(attempts),
            verdict=_verdict(feasible, x, attempts, lp_feasible, standing),
            cone=system.cone, law=system.law)

    def _workspace(self, name):
        """The workspace of a backend; the Newton-system backends (semismooth Newton,
        interior point) share one: the symbolic factorization and prepared matrices
        (:attr:`~masonry.rbe.solvers.base.Backend.workspace`)."""
        return self._workspaces.setdefault(BACKENDS[name].workspace, {})

    def _run(self, system, method, name, preset, **overrides):
        chosen = BACKENDS[name]
        options = {**preset.options.get(chosen.settings, {}), **overrides}
        return chosen.solve_rbe(system, method, options, self._workspace(name))


@dataclass(frozen=True)
class _Solved:
    """The last outcome for one friction model: its solver's name (``+newton`` when
    polished), the outcome, its residuals, and whether the point was accepted."""

    method: str
    name: str
    outcome: object
    checks: Residuals | None
    accepted: bool


def _settings(friction, solver, tol, accuracy, lp_check):
    """Validate the arguments of :meth:`RBEProblem.solve`: (preset, tolerances, LP
    check)."""
    if friction not in ("auto",) + FRICTION_METHODS:
        raise ValueError(f"friction must be 'auto', 'net' or 'plus', not {friction!r}")
    if accuracy not in ACCURACY:
        raise ValueError(f"unknown accuracy {accuracy!r}; choose from {list(ACCURACY)}")
    if isinstance(lp_check, str) and lp_check != "infeasible":
        raise ValueError(f"lp_check must be a bool or 'infeasible', not {lp_check!r}")
    if solver is not None:
        backend(solver, RBE)  # an unknown name, or one that does not solve the QP
    preset = ACCURACY[accuracy]
    tol = Tolerances(residual=preset.residual) if tol is None else tol
    return preset, tol, preset.lp_check if lp_check is None else lp_check

def _candidates(method, solver, preset) -> list:
    """Solvers to try for ``method``, in order: the explicit ``solver`` alone, else the
    preset's, followed by Clarabel when the preset's is one of the fast methods on the
    Newton system (they neither converge nor certify on every structure), and by the
    load-path LP before Clarabel for Newton on friction-net if the preset says so."""
    if solver is not None:
        return [solver]
    chosen = preset.net_solver if method == "net" else preset.plus_solver
    if chosen not in ("newton", "interior"):
        return [chosen]
    if chosen == "newton" and method == "net" and preset.load_path:
        return [chosen, LOAD_PATH, "clarabel"]
    return [chosen, "clarabel"]


def _stated(system, method, candidates, attempts) -> list:
    """``candidates`` without the solvers that cannot state ``system``'s constraints (a
    tension cut-off some do not take, :meth:`~masonry.rbe.solvers.base.Backend.refusal`),
    each refusal logged (information: the flow is designed to pass it on) and kept in
    ``attempts``; the load-path LP goes with Newton,
    whose stalled point it needs."""
    kept = []
    for name in candidates:
        real = "newton" if name in (WARM_NEWTON, LOAD_PATH) else name
        refusal = BACKENDS[real].refusal(system)
        if refusal is None:
            kept.append(name)
        elif name != LOAD_PATH:
            log.info("%s; the next solver takes friction-%s", refusal, method)
            attempts.append({"friction": method, "solver": real, "status": "refused",
                             "iterations": -1, "setup_s": 0.0, "solve_s": 0.0,
                             "reason": refusal})
    return kept


def _accepted(checks, tol) -> bool:
    return checks is not None and max(checks.equilibrium, checks.friction) <= tol.residual


def _record(method, name, outcome) -> dict:
    """One QP solve, as kept in :attr:`RBEResult.attempts`."""
    return {"friction": method, "solver": name, "status": outcome.status,
            "iterations": outcome.iterations, "setup_s": round(outcome.setup_time, 4),
            "solve_s": round(outcome.solve_time, 4)}


def _verdict(feasible, x, attempts, lp_feasible, standing=None) -> str:
    """See :attr:`RBEResult.verdict`; ``standing`` as for :meth:`RBEProblem._result`."""
    if feasible:
        return "feasible"
    certified = lp_feasible is False or any(
        a["friction"] == "net" and a["status"] == INFEASIBLE for a in attempts)
    if certified:
        return "infeasible"
    if standing is not None:  # friction-net decided neither way for a friction+ point
        return "not solved"
    return "infeasible" if x is not None else "not solved"


def solve_rbe(blocks, interfaces, mu=0.7, density=2000.0, friction="auto", solver=None,
              tol=None, *, accuracy="balanced", cone=None, lp_check=None,
              lp_time_limit=60.0, side_block=None, side_rotation=None, cores=None,
              cohesion=0.0, tensile=0.0) -> RBEResult:
    """Rigid block equilibrium as a quadratic program (thesis 3.3.4).

    With ``x`` the vertex forces ``(c, t, f1, f2)`` of every interface vertex (thesis
    eq. 3.23)::

        minimize    1/2 x^T H x                  H = diag(1e-3 c, 1 t, 1e-3 f1, 1e-3 f2)
        subject to  A_eq x + f_ext = 0           force and moment balance of free blocks
                    (f1, f2) in the friction model at mu (c - t) (net) or mu c (plus)
                    c >= 0, t >= 0

    With mortar (``cohesion``, ``tensile``; :mod:`masonry.contact`) ``c`` is the shifted
    compression ``n + c A / mu``, ``f_ext`` takes the shift and a tension cut-off below
    the cone's apex bounds ``c - t`` (net) or ``c`` (plus) from below, so the tension
    ``t`` is what the law cannot carry.

    friction-net: the friction within the model at ``c - t`` (eq. 3.26, infeasible when
    the structure cannot stand without tension); friction+: within it at ``c`` (eq.
    3.25, always feasible; the sum of tension is the measure of infeasibility, eq.
    3.28). The friction model (``cone``) is Coulomb's isotropic cone ``||(f1, f2)|| <= mu
    c`` unless another is asked for (:mod:`masonry.friction`; the thesis's pyramid
    ``|f1|, |f2| <= mu c`` is ``square``). The problem is solved scaled
    (:mod:`masonry.rbe.equilibrium`), results are in newtons.

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
    solver : str, optional
        A backend of the RBE QP (:data:`SOLVERS`) for both friction models, with the
        preset's settings for it. Default: the preset's solvers.
    tol : Tolerances, optional
        ``tol.residual`` bounds the relative equilibrium residual and the friction
        violation of an accepted solution. Default: the preset's ``residual``.
    accuracy : {'fast', 'balanced', 'accurate'}
        The :data:`ACCURACY` preset.
    cone : FrictionCone or str, optional
        The friction model (``'circle'``, ``'polygon:K'``, ``'square'``); default the preset's.
    lp_check : bool or 'infeasible', optional
        Run the independent friction-net feasibility LP (HiGHS, zero objective): always,
        never, or only when the verdict is infeasible. Default: the preset's (``accurate``:
        when infeasible); proving feasibility takes it far longer (docs/bench.md,
        "Measurements behind design choices").
    lp_time_limit : float, s
        HiGHS's time limit; when reached, ``lp_feasible`` is None and a warning is logged.
    side_block, side_rotation : optional
        Force routing for boundary modes, see :func:`masonry.rbe.equilibrium.assemble`.
    cores : int, optional
        The cores it may use: friction+ forked onto a second, factorizations on two threads
        (:mod:`masonry.rbe.cores`). Default: the process's (:func:`masonry.forking.cores`).
    cohesion, tensile : float, Pa
        The mortar's cohesion and tensile strength (:class:`~masonry.contact.ContactLaw`);
        default dry joints.

    Returns
    -------
    RBEResult
        ``feasible`` is decided from the returned point, not from a solver status: a
        solution is accepted when its residuals are below ``tol.residual``, and the
        structure is feasible when the accepted ``x`` meets equilibrium and the
        friction-net constraints within that tolerance.

    Notes
    -----
    Statuses (cvxpy's words): ``optimal``, ``optimal_inaccurate`` and ``user_limit``
    return a point, which is kept only if it passes the residual check (OSQP has said
    "solved" on infeasible problems); ``infeasible``, ``infeasible_inaccurate`` and
    ``solver_error`` return none. Under ``'auto'`` any friction-net outcome without an
    accepted point moves on to friction+, so a spurious "infeasible" on a nearly
    feasible structure is caught when the friction+ point meets the friction-net
    constraints (then ``feasible`` is True, with a warning); the LP's verdict is reported
    beside the QP's. For several solves of one scene use :class:`RBEProblem`.
    """
    start = time.perf_counter()
    problem = RBEProblem(blocks, interfaces, side_block=side_block,
                         side_rotation=side_rotation)
    result = problem.solve(mu=mu, density=density, friction=friction, solver=solver,
                           tol=tol, accuracy=accuracy, cone=cone, lp_check=lp_check,
                           lp_time_limit=lp_time_limit, cores=cores, cohesion=cohesion,
                           tensile=tensile)
    return dataclasses.replace(result, time_s=time.perf_counter() - start)
