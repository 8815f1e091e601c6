"""Solver backends of the rigid block equilibrium and the collapse load factor
(docs/model.md 6.5 to 6.8).

One registry, :data:`BACKENDS`: every backend is a module of this package that declares
a :class:`~masonry.rbe.solvers.base.Backend`: its name, the problems it solves (the RBE
QP, :data:`~masonry.rbe.solvers.base.RBE`; the collapse program,
:data:`~masonry.rbe.solvers.base.COLLAPSE`), whose settings it takes, and whether it
takes the pyramids only. Every outcome carries the residuals recomputed from the
matrices (:mod:`.residuals`). The analyses (:mod:`masonry.rbe.solve`,
:mod:`masonry.rbe.collapse`) call a backend by name; they decide the processes and
threads the solvers run on (:mod:`masonry.rbe.cores`), the solvers never fork nor set
threads. Adding a solver is adding a module and a line here.

- ``newton``: semismooth Newton on the QP's dual (:mod:`.newton`); friction-net in the
  presets, and the polish of every other solver's point.
- ``interior``: primal-dual interior point methods on the same reduced system: the QP
  (:mod:`.interior`, friction+ in the presets) and the collapse program
  (:mod:`.interior_lp`, the default there; also the load-path LP of
  :mod:`.net_feasibility`).
- ``clarabel``: Clarabel called directly on sparse matrices: the QP (:mod:`.standard_form`)
  and the collapse program (:mod:`.direct_clarabel`).
- ``osqp``: OSQP on the QP's standard form, pyramids only (:mod:`.direct_osqp`).
- ``clarabel-cvxpy``, ``osqp-cvxpy``: the QP through cvxpy, the readable reference
  (:mod:`.via_cvxpy`).
- ``highs-ipm``, ``highs-crossover``, ``highs-simplex``: HiGHS on the collapse program
  of the pyramids, by its interior point method without or with crossover, or its dual
  simplex (:mod:`.highs`).
"""

from masonry.rbe.solvers import direct_clarabel, direct_osqp, highs, interior, newton, via_cvxpy
from masonry.rbe.solvers.base import COLLAPSE, PROBLEMS, RBE, Backend, Outcome

BACKENDS = {backend.name: backend for backend in (
    newton.BACKEND, interior.BACKEND, direct_clarabel.BACKEND, direct_osqp.BACKEND,
    *via_cvxpy.BACKENDS, *highs.BACKENDS)}
"""Solver name -> :class:`~masonry.rbe.solvers.base.Backend`: the one list of solver
names."""


def names(problem=None, cone=None) -> tuple:
    """The names of the backends that solve ``problem`` (:data:`PROBLEMS`; None: any)
    and can state the friction model ``cone`` (a
    :class:`~masonry.friction.FrictionCone`; None: any), in registry order."""
    return tuple(name for name, backend in BACKENDS.items()
                 if (problem is None or problem in backend.problems)
                 and (cone is None or backend.states(cone)))


def backend(name, problem, cone=None) -> Backend:
    """The backend ``name`` for ``problem`` and the friction model ``cone``.

    Raises
    ------
    ValueError
        An unknown name, a backend that does not solve ``problem``, or one that cannot
        state ``cone``.
    """
    if problem not in PROBLEMS:
        raise ValueError(f"unknown problem {problem!r}; choose from {list(PROBLEMS)}")
    if name not in BACKENDS or problem not in BACKENDS[name].problems:
        what = {RBE: "solver", COLLAPSE: "collapse method"}[problem]
        raise ValueError(f"unknown {what} {name!r}; choose from {list(names(problem))}")
    chosen = BACKENDS[name]
    if cone is not None and not chosen.states(cone):
        raise ValueError(f"{name} takes linear constraints only: the friction model {cone} "
                         f"needs one of {', '.join(names(problem, cone))}, or a polygon:K "
                         f"model")
    return chosen


__all__ = ["BACKENDS", "COLLAPSE", "RBE", "Backend", "Outcome", "backend", "names"]
