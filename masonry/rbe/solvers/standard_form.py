"""The scaled RBE QP as the sparse matrices a QP or conic solver takes, without cvxpy.

Variables ``x`` in the :class:`~masonry.rbe.equilibrium.VariableLayout` order, solver units::

    minimize    1/2 x^T P x          P = diag(h_solver)
    subject to  A_eq x = b           b = -f_ext
                F x + s = 0          s in the friction model's cone, per vertex
                -t + s = 0           s >= 0, one row per vertex

The friction rows ``F`` of a vertex (:class:`~masonry.friction.FrictionCone`): a
pyramid's ``K`` faces, ``f . normal_k - a (c - t) <= 0`` (``a`` its apothem at ``mu``,
the nonnegative cone); Coulomb's cone as ``s = (mu (c - t), f1, f2)`` in the
second-order cone, rows ``(-mu c + mu t, -f1, -f2)``. friction+ drops the tension
coefficient. ``c >= 0`` needs no row: every model implies it. The rows of friction-net
and friction+ are stored with one sparsity pattern (the tension coefficient is an
explicit zero in friction+), and the friction coefficient only changes values, so a
solver set up once is updated in place between the two models and between friction
coefficients (OSQP and Clarabel keep their symbolic factorization).
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

MU, TENSION, CONSTANT = 0, 1, 2
"""Kinds of a friction row's entries: ``-a`` on ``c``, ``+a`` (friction-net) or 0 on
``t``, a constant on ``f1, f2``."""


@dataclass(frozen=True, eq=False)
class StandardForm:
    """Constraint matrices in one stacked CSC pattern.

    Parameters
    ----------
    P : (n, n) scipy.sparse.csc_array
        Diagonal objective.
    rows : (m, n) scipy.sparse.csc_array
        ``[A_eq; F; T]`` with ``T`` picking every ``t``; values for friction-net at
        ``mu``. :meth:`values` gives the data array for another model or ``mu``.
    n_eq, n_friction, n_tension : int
        Row counts of the three parts.
    b : (n_eq,) float
        Right-hand side of the equilibrium rows.
    cone : masonry.friction.FrictionCone
        The friction model the rows state.
    """

    P: sp.csc_array
    rows: sp.csc_array
    n_eq: int
    n_friction: int
    n_tension: int
    b: np.ndarray
    cone: object
    _tension_slot: np.ndarray
    _mu_slot: np.ndarray

    def values(self, method: str, mu: float) -> np.ndarray:
        """The data array of :attr:`rows` for ``method`` (``'net'``/``'plus'``) and ``mu``."""
        slope = self.cone.apothem(mu) if self.cone.is_polyhedral else mu
        data = self.rows.data.copy()
        data[self._mu_slot] = -slope
        data[self._tension_slot] = slope if method == "net" else 0.0
        return data

    def matrix(self, method: str, mu: float) -> sp.csc_array:
        out = self.rows.copy()
        out.data = self.values(method, mu)
        return out


def _vertex_rows(cone) -> list:
    """One vertex's friction rows as ``(row, column, kind, constant)`` entries over its
    columns ``(c, t, f1, f2)`` = ``(0, 1, 2, 3)``."""
    if cone.is_polyhedral:
        entries = []
        for row, normal in enumerate(cone.face_normals()):
            entries += [(row, 0, MU, 0.0), (row, 1, TENSION, 0.0)]
            entries += [(row, 2 + axis, CONSTANT, value)
                        for axis, value in enumerate(normal) if value != 0.0]
        return entries
    return [(0, 0, MU, 0.0), (0, 1, TENSION, 0.0), (1, 2, CONSTANT, -1.0),
            (2, 3, CONSTANT, -1.0)]


def standard_form(system) -> StandardForm:
    """:class:`StandardForm` of an :class:`~masonry.rbe.equilibrium.EquilibriumSystem`."""
    layout = system.layout
    n, n_vertices = layout.n_columns, layout.n_vertices
    A_eq = sp.coo_array(system.A_eq)
    n_eq = A_eq.shape[0]
    template = np.array(_vertex_rows(system.cone))
    per_vertex = int(template[:, 0].max()) + 1
    base = layout.WIDTH * np.arange(n_vertices)[:, None]
    fr_rows = n_eq + per_vertex * np.arange(n_vertices)[:, None] + template[:, 0].astype(int)
    fr_cols = base + template[:, 1].astype(int)
    fr_kind = np.broadcast_to(template[:, 2].astype(int), fr_rows.shape)
    fr_vals = np.broadcast_to(np.where(template[:, 2] == CONSTANT, template[:, 3], 1.0),
                              fr_rows.shape)
    n_friction = per_vertex * n_vertices
    tension_rows = n_eq + n_friction + np.arange(n_vertices)
    row = np.concatenate([A_eq.row, fr_rows.ravel(), tension_rows])
    col = np.concatenate([A_eq.col, fr_cols.ravel(), base[:, 0] + 1])
    val = np.concatenate([A_eq.data, fr_vals.ravel(), np.ones(n_vertices)])
    kind = np.concatenate([np.full(A_eq.nnz, CONSTANT), fr_kind.ravel(),
                           np.full(n_vertices, CONSTANT)])
    m = n_eq + n_friction + n_vertices
    # CSC by hand so explicit zeros stay and the slot of every entry is known
    order = np.lexsort((row, col))
    indptr = np.concatenate([[0], np.cumsum(np.bincount(col, minlength=n))])
    rows = sp.csc_array((val[order], row[order], indptr), shape=(m, n))
    kind = kind[order]
    return StandardForm(
        P=sp.csc_array(sp.diags_array(system.h_solver, format="csc")),
        rows=rows, n_eq=n_eq, n_friction=n_friction, n_tension=n_vertices,
        b=-system.f_ext, cone=system.cone, _tension_slot=np.flatnonzero(kind == TENSION),
        _mu_slot=np.flatnonzero(kind == MU))


def kept_form(system, workspace: dict) -> StandardForm:
    """The standard form of ``system`` kept in a solver's ``workspace`` (one per scene and
    friction model, built on first use: friction+ and other friction coefficients change
    only values)."""
    form = workspace.get("form")
    if form is None or form.cone != system.cone:
        form = workspace["form"] = standard_form(system)
        workspace.pop("solver", None)  # a solver set up for another model's rows
    elif not np.array_equal(form.b, -system.f_ext):
        # a cohesion's shift (another cohesion or mu) moves the right-hand side
        form = workspace["form"] = dataclasses.replace(form, b=-system.f_ext)
        workspace.pop("solver", None)
    return form
