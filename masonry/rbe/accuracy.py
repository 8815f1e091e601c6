"""The accuracy presets of the rigid block equilibrium (docs/model.md 6.6): which backends solve
friction-net and friction+ (:mod:`masonry.rbe.solvers`), with which settings, and when a
point is accepted. :mod:`masonry.rbe.solve` runs them."""

from dataclasses import dataclass, field

from masonry.friction import FrictionCone
from masonry.tolerances import ACCEPT_RESIDUAL, AZIMUTH_REFINE_REL


@dataclass(frozen=True)
class AccuracyPreset:
    """A documented choice of solvers and tolerances (docs/model.md 6.6).

    Parameters
    ----------
    name : str
    net_solver, plus_solver : str
        :data:`masonry.rbe.solvers.BACKENDS` names for friction-net and friction+. An
        explicit ``solver`` argument replaces both.
    residual : float
        Acceptance: a returned point counts when its relative equilibrium residual and
        friction violation are at most this (``Tolerances.residual``; the balanced
        preset's is :data:`~masonry.tolerances.ACCEPT_RESIDUAL`).
    lp_check : bool or 'infeasible'
        Run the independent friction-net LP (HiGHS): always, never, or only to confirm
        an infeasible verdict. A feasible verdict needs no second opinion: it rests on
        a point whose equilibrium and friction residuals were recomputed here.
    load_path : bool
        When Newton neither solves nor certifies friction-net, decide feasibility by
        the load-path LP on Newton's matrix (:mod:`masonry.rbe.solvers.net_feasibility`)
        before Clarabel: its certificate ends friction-net; a feasible verdict resumes
        Newton from where it stopped, then Clarabel.
    cone : str
        The friction model (:mod:`masonry.friction`) unless one is given.
    polish : bool
        Refine an accepted interior-point or ADMM point with Newton steps started from
        its multipliers (:mod:`masonry.rbe.solvers.newton`): one or two steps find the exact
        active set, which leaves residuals near rounding and no interior-point tension
        (Clarabel at 1e-10 left 1e-6 of the weight as tension on a feasible section).
        Kept only if it converges within :data:`masonry.rbe.solve.POLISH_STEPS`.
    azimuth_rel : float
        ``--lateral all`` refines its least sample until every bound between the solved
        azimuths beside it is within this (relative) of the least factor found
        (:mod:`masonry.rbe.azimuth_refine`; each refinement is a collapse program on the
        whole model).
    options : dict
        Solver settings by the key a backend takes them under
        (:attr:`~masonry.rbe.solvers.base.Backend.settings`: ``newton``, ``interior``,
        ``clarabel``, ``osqp``).
    """

    name: str
    net_solver: str
    plus_solver: str
    residual: float
    lp_check: bool | str
    cone: str = "circle"
    load_path: bool = False
    polish: bool = False
    azimuth_rel: float = AZIMUTH_REFINE_REL
    options: dict = field(default_factory=dict)


ACCURACY = {
    # Newton for friction-net, the interior point method on the Newton system for
    # friction+ (both factor the 6-rows-per-block matrix): Newton converges fast once the
    # active set of the friction cones is found, so a looser stop saves little; the savings are
    # the interior point's last iterations and the acceptance of OSQP's ADMM points.
    "fast": AccuracyPreset(
        "fast", "newton", "interior", residual=1e-4, lp_check=False, load_path=True,
        polish=False, azimuth_rel=1e-4,
        options={"newton": {"tol": 1e-6},
                 "interior": {"tol": 1e-6},
                 "clarabel": {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-6},
                 "osqp": {"eps_abs": 1e-4, "eps_rel": 1e-4, "max_iter": 100_000,
                          "polishing": False}}),
    # the default: friction-net by Newton (a few factorizations of the six-rows-per-block
    # system where Clarabel factors a KKT system twenty times larger more often);
    # friction+ by the interior point method on the same system, polished by Newton
    # (Newton alone on friction+ is slowed by the 1,000:1 tension weight). When Newton
    # neither solves nor certifies friction-net (low-friction domes), the load-path LP
    # on the same matrix decides, in fewer iterations than Clarabel on its KKT system;
    # where it finds a load path, Newton resumes and then the interior point method
    # solves friction-net; Clarabel takes over when these fail. Measured: docs/bench.md.
    "balanced": AccuracyPreset(
        "balanced", "newton", "interior", residual=ACCEPT_RESIDUAL, lp_check=False,
        load_path=True,
        polish=True,
        options={"newton": {"tol": 1e-9},
                 "interior": {"tol": 1e-10},
                 "clarabel": {"tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8, "tol_feas": 1e-8},
                 # cvxpy's defaults (eps 1e-5, 10,000 iterations) leave residuals near
                 # the acceptance tolerance; 1e-6 keeps a margin
                 "osqp": {"eps_abs": 1e-7, "eps_rel": 1e-7, "max_iter": 100_000,
                          "polishing": True}}),
    # the reference: Clarabel (an independent implementation) with tight gaps for both
    # models, polished, and the LP's second opinion on an infeasible verdict only (on
    # feasible ones it is slow and adds nothing: docs/bench.md, "Measurements behind
    # design choices"). Clarabel's default gaps
    # (1e-8) leave 2.6e-6 of the weight as interior-point tension on the straight wall;
    # 1e-10 leaves 2.4e-7.
    "accurate": AccuracyPreset(
        "accurate", "clarabel", "clarabel", residual=1e-6, lp_check="infeasible",
        polish=True,
        options={"newton": {"tol": 1e-12},
                 "interior": {"tol": 1e-10},
                 "clarabel": {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10,
                              "tol_feas": 1e-10},
                 "osqp": {"eps_abs": 1e-8, "eps_rel": 1e-8, "max_iter": 200_000,
                          "polishing": True}}),
}
"""Accuracy preset name -> :class:`AccuracyPreset`."""


def friction_model(accuracy="balanced", cone=None) -> FrictionCone:
    """The friction model of a solve: ``cone`` (a name or a :class:`FrictionCone`) if
    given, else the accuracy preset's."""
    return FrictionCone.parse(ACCURACY[accuracy].cone if cone is None else cone)
