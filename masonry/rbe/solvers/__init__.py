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
threads. Adding a solver is adding a module and a line here (:data:`REGISTRY`). A
backend's module, and the libraries it solves with, load when it is first asked for: a
command that solves nothing never loads scipy's solvers, Clarabel, HiGHS or cvxpy.

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

from collections.abc import Mapping
from importlib import import_module

from masonry.rbe.solvers.base import COLLAPSE, PROBLEMS, RBE, Backend, Outcome

REGISTRY = {
    # name: (its module in this package, the problems it solves, pyramids only)
    "newton": ("newton", (RBE,), False),
    "interior": ("interior", (RBE, COLLAPSE), False),
    "clarabel": ("direct_clarabel", (RBE, COLLAPSE), False),
    "osqp": ("direct_osqp", (RBE,), True),
    "clarabel-cvxpy": ("via_cvxpy", (RBE,), False),
    "osqp-cvxpy": ("via_cvxpy", (RBE,), True),
    "highs-ipm": ("highs", (COLLAPSE,), True),
    "highs-crossover": ("highs", (COLLAPSE,), True),
    "highs-simplex": ("highs", (COLLAPSE,), True),
}
"""The one list of solver names: where each backend is declared and what it takes (the
tests check it against the backends themselves)."""


class _Backends(Mapping):
    """Solver name -> :class:`~masonry.rbe.solvers.base.Backend`, in :data:`REGISTRY`
    order; a backend's module is imported when it is first looked up."""

    def __getitem__(self, name) -> Backend:
        module = import_module(f"{__name__}.{REGISTRY[name][0]}")
        declared = getattr(module, "BACKENDS", None) or (module.BACKEND,)
        return next(backend for backend in declared if backend.name == name)

    def __iter__(self):
        return iter(REGISTRY)

    def __len__(self):
        return len(REGISTRY)


BACKENDS = _Backends()
"""Solver name -> :class:`~masonry.rbe.solvers.base.Backend`."""


def names(problem=None, cone=None) -> tuple:
    """The names of the backends that solve ``problem`` (:data:`PROBLEMS`; None: any)
    and can state the friction model ``cone`` (a
    :class:`~masonry.friction.FrictionCone`; None: any), in registry order."""
    return tuple(name for name, (_, problems, pyramids) in REGISTRY.items()
                 if (problem is None or problem in problems)
                 and (cone is None or cone.is_polyhedral or not pyramids))


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


__all__ = ["BACKENDS", "COLLAPSE", "REGISTRY", "RBE", "Backend", "Outcome", "backend",
           "names"]
