"""The outcome of a rigid block equilibrium (docs/model.md 6.5): the verdict, the forces,
their residuals and the record run.json keeps (:mod:`masonry.rbe.solve` computes it)."""

import math
from dataclasses import dataclass

import numpy as np

from masonry.contact import ContactLaw
from masonry.friction import FrictionCone
from masonry.rbe.accuracy import ACCURACY
from masonry.rbe.equilibrium import VariableLayout

RESULT_KEYS = ("verdict", "feasible", "friction", "mu", "friction_model",
               "friction_capacity_error", "objective", "moi", "moi_factor", "weight_N",
               "solver", "status", "iterations", "residual_eq", "friction_violation",
               "net_friction_violation", "time_s", "lp_feasible", "accuracy", "lp_time_s",
               "solved_on", "contact_law")
"""Scalar fields of :class:`RBEResult` written to run.json, in order."""

INTERFACE_FORCE_KEYS = ("compression", "tension", "normal", "t1", "t2", "friction")


@dataclass(frozen=True, eq=False)
class RBEResult:
    """Outcome of :func:`solve_rbe`. Forces in newtons.

    Parameters
    ----------
    feasible : bool
        ``x`` satisfies equilibrium and the friction-net constraints, both within
        ``tol.residual`` (relative equilibrium residual, and friction violation relative
        to the reference weight): the structure stands without tension.
    friction : str
        ``'net'`` or ``'plus'``: the problem (friction-net or friction+) whose solution
        ``x`` is.
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
        Solver name and its status (cvxpy's words) for the problem that produced ``x``
        (the last attempt; ``load-path-lp`` with ``user_limit`` where the load-path
        LP's friction-net point answers, an equilibrium but not the QP's optimum:
        docs/model.md 6.6).
    iterations : int
        That solver's iterations, -1 when not reported.
    residual_eq : float
        ``||A_eq x + f_ext||_inf / ||f_ext||_inf`` (scaled rows: forces per reference
        weight, moments per reference weight times reference length).
    friction_violation : float
        Largest violation of the friction rows of the problem solved and of the sign
        bounds ``c, t >= 0``, per reference weight.
    net_friction_violation : float
        The same on the friction-net rows, whatever problem was solved.
    time_s : float, s
        Wall time of the solve (every QP and the LP check; assembly too for
        :func:`solve_rbe`).
    lp_feasible : bool or None
        Verdict of the independent friction-net LP (HiGHS); None when not run or
        inconclusive.
    x : (4 IV,) float or None, N
        Solution in the :class:`~masonry.rbe.equilibrium.VariableLayout` order, physical
        forces: with mortar (:mod:`masonry.contact`) ``c`` is the normal force the
        law carries, negative where the mortar holds in tension, and ``t`` the tension
        beyond the law (the MoI's).
    layout : VariableLayout
    accuracy : str
        The accuracy preset.
    lp_time_s : float, s
        Time of the LP check (0 when not run).
    attempts : tuple of dict
        Every QP solved (and the load-path LP, :data:`LOAD_PATH`), in order: friction
        model, solver, status, iterations, setup and solve seconds (a fallback shows as
        a second attempt of the same model).
    cone : FrictionCone
        The friction model (:mod:`masonry.friction`).
    law : ContactLaw
        The contact law (the friction model, ``mu`` and the mortar's strengths).
    solved_on : {'whole', 'half', 'whole, the half rejected'}
        The model whose program gave the forces: the whole; its half in a mirror plane,
        mapped back and checked on the whole (docs/model.md 6.11); or the whole, solved
        because the half's forces failed that check.
    verdict : {'feasible', 'infeasible', 'not solved'}
        ``'feasible'``: ``feasible`` is True. ``'infeasible'``: friction-net has no
        accepted point, and either a solver certified that (a Farkas certificate, an
        infeasibility status, the LP) or an accepted friction+ point carries the
        tension it needs. ``'not solved'``: no solver returned an accepted point and
        none certified infeasibility; the residuals say how far the last point was.
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
    accuracy: str = "balanced"
    lp_time_s: float = 0.0
    attempts: tuple = ()
    verdict: str = "not solved"
    cone: FrictionCone = FrictionCone("circle")
    solved_on: str = "whole"
    law: ContactLaw = ContactLaw()

    @property
    def contact_law(self) -> str:
        """The contact law in one line (:meth:`~masonry.contact.ContactLaw.describe`)."""
        return self.law.describe()

    @property
    def friction_model(self) -> str:
        return self.cone.name

    @property
    def friction_capacity_error(self) -> float:
        """The model's bound on the error of the friction capacity (see
        :attr:`~masonry.friction.FrictionCone.capacity_error`)."""
        return self.cone.capacity_error

    def checked(self) -> bool:
        """Whether the residuals, recomputed on the model this result describes, meet its
        accuracy preset's acceptance tolerance (docs/model.md 6.5): equilibrium and the
        friction model solved and, for a feasible verdict, friction-net. A result without
        forces has nothing to check."""
        if self.x is None:
            return True
        tol = ACCURACY[self.accuracy].residual
        checks = [self.residual_eq, self.friction_violation]
        if self.feasible:
            checks.append(self.net_friction_violation)
        return all(math.isfinite(value) and value <= tol for value in checks)

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
    """Sum the vertex forces of every interface (docs/model.md 6.7, thesis eq. 3.29-3.34).

    Parameters
    ----------
    layout : VariableLayout
    x : (4 IV,) float, N

    Returns
    -------
    dict str -> (K,) float, N
        ``compression`` (sum c), ``tension`` (sum t), ``normal`` (sum of t - c, tension
        positive), ``t1`` (sum f1), ``t2`` (sum f2), ``friction``
        ``sqrt((sum f1)^2 + (sum f2)^2)`` (the thesis's eq. 3.34 is garbled; this is the
        reading of docs/model.md 6.7).
    """
    c, t, f1, f2 = (layout.interface_sum(layout.component(x, name))
                    for name in layout.COMPONENTS)
    return dict(zip(INTERFACE_FORCE_KEYS, (c, t, t - c, f1, f2, np.hypot(f1, f2))))
