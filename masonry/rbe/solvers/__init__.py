"""QP backends for the rigid block equilibrium (SPEC 6.5, 6.6).

Every backend is ``solve(system, method, options, workspace) -> QPOutcome``: it solves
the scaled QP of an :class:`~masonry.rbe.equilibrium.EquilibriumSystem` for the friction
model ``method`` (``'net'`` or ``'plus'``) with solver ``options``, and may keep
whatever it can reuse (factorizations, solver objects, warm starts) in ``workspace``, a
dict that :class:`masonry.rbe.solve.RBEProblem` keeps per scene and backend. Adding a solver
is adding a module and a line here.

- ``newton``: semismooth Newton on the dual (:mod:`.newton`); friction-net in the
  presets, and the polish of every other solver's point.
- ``interior``: a primal-dual interior point method on the same reduced system
  (:mod:`.interior`); friction+ in the presets.
- ``clarabel``, ``osqp``: the solvers called directly on sparse matrices
  (:mod:`.standard_form`).
- ``clarabel-cvxpy``, ``osqp-cvxpy``: the same through cvxpy, the readable reference.
"""

from masonry.rbe.solvers import direct_clarabel, direct_osqp, interior, newton, via_cvxpy
from masonry.rbe.solvers.base import QPOutcome

BACKENDS = {
    "newton": newton.backend,
    "interior": interior.backend,
    "clarabel": direct_clarabel.solve,
    "osqp": direct_osqp.solve,
    "clarabel-cvxpy": via_cvxpy.solver_for("CLARABEL"),
    "osqp-cvxpy": via_cvxpy.solver_for("OSQP"),
}
"""Solver name -> backend function."""

FAMILY = {"newton": "newton", "interior": "interior", "clarabel": "clarabel", "osqp": "osqp",
          "clarabel-cvxpy": "clarabel", "osqp-cvxpy": "osqp"}
"""Solver name -> whose options it takes (the accuracy presets set them per family)."""

__all__ = ["BACKENDS", "FAMILY", "QPOutcome"]
