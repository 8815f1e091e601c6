"""The collapse load factor's cone program, as every backend receives it.

:mod:`masonry.rbe.collapse` states the program (its columns, cones and load columns);
a backend holds it (:class:`HeldProgram`) between load cases::

    maximize    cost . lambda
    subject to  M g + L lambda = b                 M = A_eq E, b = -f_dead
                tie . (lambda_1, lambda_2) = 0     a lateral direction (two loads)
                h - G g in cones                   every vertex's friction model

``x = E g`` are the vertex forces (:class:`Columns`), ``L`` the live loads' columns in the
rows' scaling, one per load.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from masonry.rbe.solvers.base import OPTIMAL
from masonry.rbe.solvers.residuals import program_residuals

NONNEGATIVE, SECOND_ORDER = "nonnegative", "second-order"
"""Kinds of a cone of :attr:`Columns.cones`."""


@dataclass(frozen=True, eq=False)
class Columns:
    """The program's columns ``g`` and their cone constraints.

    Parameters
    ----------
    edges : (4 IV, n) scipy.sparse.csr_array
        ``x = edges g``: the vertex forces in the
        :class:`~masonry.rbe.equilibrium.VariableLayout` order.
    G : (k, n) scipy.sparse.csc_array
    h : (k,) float
        The cone constraints ``h - G g in cones``.
    cones : tuple of (str, int, int)
        ``(kind, dimension, count)`` of those rows, in order: ``count`` cones of
        ``dimension`` rows each, ``kind`` :data:`NONNEGATIVE` or :data:`SECOND_ORDER`.
    is_rays : bool
        ``g >= 0`` is every constraint (a pyramid's edge rays): a linear program with
        column bounds.
    is_friction_model : bool
        The columns state the friction model at ``mu c`` (a pyramid's rays or the
        forces in Coulomb's cone), not a fixed capacity.
    """

    edges: sp.csr_array
    G: sp.csc_array
    h: np.ndarray
    cones: tuple
    is_rays: bool
    is_friction_model: bool = True


@dataclass(frozen=True, eq=False)
class ConeProgram:
    """One collapse program (module docstring).

    Parameters
    ----------
    system : masonry.rbe.equilibrium.EquilibriumSystem
        ``A_eq``, ``f_ext`` (the dead load ``f_dead``), the layout, the friction model
        and ``mu``.
    columns : Columns
    matrix : (6 F, n) scipy.sparse.csc_array
        ``M = A_eq E``.
    loads : (6 F, m) float
        The live loads' columns ``L``, scaled rows.
    cost : (m,) float
    tie : (2,) float or None
        The row tying two loads to one direction (``-sin a, cos a``).
    time_limit : float, s
        Per solve, for the solvers that take one (Clarabel, HiGHS).
    """

    system: object
    columns: Columns
    matrix: sp.csc_array
    loads: np.ndarray
    cost: np.ndarray
    tie: tuple | None
    time_limit: float

    @property
    def rhs(self) -> np.ndarray:
        """``b = -f_dead`` ((6 F,) float)."""
        return -self.system.f_ext


class HeldProgram:
    """A :class:`ConeProgram` held by a backend: it keeps its solver's work (symbolic
    factorization, basis) from one load case to the next.

    A backend implements :meth:`solve` (the raw outcome), :meth:`stands_unloaded` and
    :meth:`direct`; :meth:`run` adds the residuals recomputed from the matrices.
    ``name`` is the backend's (set by :meth:`~masonry.rbe.solvers.base.Backend.hold`).
    """

    name = ""

    def __init__(self, program: ConeProgram, workspace: dict):
        self.program, self.workspace = program, workspace

    def solve(self):
        """The program's :class:`~masonry.rbe.solvers.base.Outcome`: ``x`` the vertex
        forces (scaled, the layout's order), ``y`` the equilibrium rows' multipliers,
        ``info["load_factor"]`` the optimum of ``cost . lambda``."""
        raise NotImplementedError

    def stands_unloaded(self) -> bool | None:
        """Whether the dead load alone has an equilibrium (``lambda = 0``); None: no
        verdict."""
        raise NotImplementedError

    def direct(self, cos, sin):
        """Point the two loads of a lateral program along ``(cos, sin)``: the tie row
        ``(-sin, cos)`` and the costs ``(cos, sin)``."""
        raise NotImplementedError

    def run(self, live, per_unit=1.0):
        """:meth:`solve`, its factor times ``per_unit`` (the factor of ``live``, (6 F,)
        float, scaled rows: the load the program's columns state, up to that ratio) and
        its residual recomputed from the matrices
        (:func:`~masonry.rbe.solvers.residuals.program_residuals`)."""
        outcome = self.solve()
        if outcome.status != OPTIMAL:
            return outcome
        factor = outcome.info["load_factor"] * per_unit
        return dataclasses.replace(
            outcome, info={**outcome.info, "load_factor": factor},
            residuals=program_residuals(self.program.system, outcome.x, factor, live))
