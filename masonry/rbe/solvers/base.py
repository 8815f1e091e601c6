"""What every solver backend is and returns (:mod:`masonry.rbe.solvers`).

Two problems, in the scaled rows of :mod:`masonry.rbe.equilibrium`:

- :data:`RBE`: the rigid block equilibrium QP (thesis eq. 3.27, docs/model.md 6.5) for friction-net
  or friction+, ``solve(system, method, options, workspace) -> Outcome``;
- :data:`COLLAPSE`: the collapse load factor's cone program (docs/model.md 6.8,
  :class:`~masonry.rbe.solvers.program.ConeProgram`), held between load cases by a
  :class:`~masonry.rbe.solvers.program.HeldProgram`.

A :class:`Backend` says which of them it solves, which friction models it can state
(:attr:`Backend.polyhedral_only`), whose settings it takes and whose workspace it shares.
"""

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from masonry.rbe.solvers.residuals import Residuals, rbe_residuals

# statuses, in cvxpy's words (cvxpy.settings), so that every backend speaks alike
OPTIMAL = "optimal"
OPTIMAL_INACCURATE = "optimal_inaccurate"
INFEASIBLE = "infeasible"
INFEASIBLE_INACCURATE = "infeasible_inaccurate"
UNBOUNDED = "unbounded"
USER_LIMIT = "user_limit"
SOLVER_ERROR = "solver_error"

RBE = "rbe"
"""The rigid block equilibrium QP."""
COLLAPSE = "collapse"
"""The collapse load factor's cone program (an LP for the pyramids)."""
PROBLEMS = (RBE, COLLAPSE)


@dataclass(frozen=True, eq=False)
class Outcome:
    """One solve.

    Parameters
    ----------
    status : str
        One of the module's statuses (cvxpy's words). A cone program's is
        :data:`OPTIMAL`, :data:`INFEASIBLE` (the dead load cannot stand),
        :data:`UNBOUNDED` (the live load stands at any factor) or the solver's own words.
    x : (n,) float or None
        The point, in solver units and the :class:`~masonry.rbe.equilibrium.VariableLayout`
        order (a cone program: the vertex forces ``(c, 0, f1, f2)``); None without one.
    iterations : int
        Solver iterations (Newton steps, interior-point, ADMM or simplex iterations); -1
        when not reported.
    y : (6 F,) float or None
        Multipliers of the equilibrium rows, where the backend has them: for the QP in
        the Newton method's convention (warm starts, polish), for a cone program in the
        solver's sign (the collapse mechanism, oriented by the live load's work).
    setup_time, solve_time : float, s
        Building the solver's data (and any factorization it does up front), and the
        iterations.
    info : dict
        Backend-specific numbers (e.g. factorizations), for the benchmark; a cone
        program's ``load_factor``.
    residuals : Residuals or None
        Recomputed from the matrices by the interface (:meth:`Backend.solve_rbe`,
        :meth:`~masonry.rbe.solvers.program.HeldProgram.run`), not the solver's word;
        None without a point.
    """

    status: str
    x: np.ndarray | None
    iterations: int
    y: np.ndarray | None = None
    setup_time: float = 0.0
    solve_time: float = 0.0
    info: dict = field(default_factory=dict)
    residuals: Residuals | None = None


@dataclass(frozen=True)
class Backend:
    """One solver behind the common interface.

    Parameters
    ----------
    name : str
        Its name in the registry (:data:`masonry.rbe.solvers.BACKENDS`), in
        :attr:`masonry.rbe.result.RBEResult.solver` and
        :attr:`masonry.rbe.collapse.CollapseResult.solver`.
    settings : str
        Whose settings it takes from an accuracy preset's ``options``
        (:data:`masonry.rbe.accuracy.ACCURACY`): one key per implementation, so
        ``clarabel-cvxpy`` takes ``clarabel``'s.
    rbe : callable or None
        ``rbe(system, method, options, workspace, **extra) -> Outcome``: the RBE QP of an
        :class:`~masonry.rbe.equilibrium.EquilibriumSystem` for ``method`` (``'net'`` or
        ``'plus'``) with the solver's ``options``; it may keep what it can reuse
        (factorizations, solver objects, warm starts) in ``workspace``, a dict its
        caller keeps per scene.
    collapse : type or None
        ``collapse(program, workspace)``: a
        :class:`~masonry.rbe.solvers.program.HeldProgram` of a
        :class:`~masonry.rbe.solvers.program.ConeProgram`.
    polyhedral_only : bool
        It takes linear constraints only: the pyramids (``polygon:K``, ``square``), not
        Coulomb's cone.
    workspace : str
        The workspace it uses: its own name, or a backend's whose prepared systems it
        shares (the interior point method shares Newton's).
    truncated : tuple of str
        The friction models (:data:`masonry.friction.KINDS`) it states truncated by a
        tension cut-off before the cone's apex (a lower bound on the compression,
        :attr:`~masonry.rbe.equilibrium.EquilibriumSystem.compression_floor`); the
        others it refuses by name.
    """

    name: str
    settings: str
    rbe: object = None
    collapse: object = None
    polyhedral_only: bool = False
    workspace: str = ""
    truncated: tuple = ()

    def __post_init__(self):
        if not self.workspace:
            object.__setattr__(self, "workspace", self.name)

    @property
    def problems(self) -> tuple:
        """The problems it solves (:data:`PROBLEMS`)."""
        return tuple(p for p, solver in ((RBE, self.rbe), (COLLAPSE, self.collapse))
                     if solver is not None)

    def states(self, cone, truncated=False) -> bool:
        """Whether it can state the friction model ``cone``, ``truncated`` by a tension
        cut-off or not."""
        return ((cone.is_polyhedral or not self.polyhedral_only)
                and (not truncated or cone.kind in self.truncated))

    def refusal(self, system) -> str | None:
        """One line saying why it cannot state ``system``'s constraints, or None."""
        if not self.states(system.cone):
            return (f"{self.name} takes linear constraints only: the friction model "
                    f"{system.cone} needs another solver, or a polygon:K model")
        if not self.states(system.cone, system.compression_floor is not None):
            return (f"{self.name} does not state the {system.cone} model truncated by a "
                    f"tension cut-off (tensile strength below cohesion/mu)")
        return None

    def solve_rbe(self, system, method, options, workspace, **extra) -> Outcome:
        """The RBE QP (see :attr:`rbe`), its residuals recomputed from the matrices
        (:func:`~masonry.rbe.solvers.residuals.rbe_residuals`).

        Raises
        ------
        ValueError
            A friction model it cannot state (:attr:`polyhedral_only`).
        """
        refusal = self.refusal(system)
        if refusal is not None:
            raise ValueError(refusal)
        outcome = self.rbe(system, method, options, workspace, **extra)
        return dataclasses.replace(outcome,
                                   residuals=rbe_residuals(system, outcome.x, method))

    def hold(self, program, workspace):
        """A :class:`~masonry.rbe.solvers.program.HeldProgram` of ``program`` (a
        :class:`~masonry.rbe.solvers.program.ConeProgram`); ``workspace``, a dict the
        caller keeps per model, keeps what later programs reuse."""
        held = self.collapse(program, workspace)
        held.name = self.name
        return held
