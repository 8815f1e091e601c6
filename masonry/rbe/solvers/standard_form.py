"""The scaled RBE QP as the sparse matrices a QP solver takes, without cvxpy.

Variables ``x`` in the :class:`~masonry.rbe.equilibrium.VariableLayout` order, solver units::

    minimize    1/2 x^T P x          P = diag(h_solver)
    subject to  A_eq x = b           b = -f_ext
                A_fr x <= 0          4 rows per vertex, friction-net or friction+
                t >= 0               1 row per vertex

``c >= 0`` needs no row: both pyramids imply it (``mu c >= |f1| >= 0``; friction-net
even ``c >= t``). The friction rows of friction-net and friction+ are stored with one
sparsity pattern (the tension coefficient is an explicit zero in friction+), and the
friction coefficient only changes values, so a solver set up once is updated in place
between the two models and between friction coefficients (OSQP and Clarabel keep
their symbolic factorization).
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

# rows +f1, -f1, +f2, -f2 of a vertex: the f column and its sign
_FRICTION_COLUMN = np.array([2, 2, 3, 3])
_FRICTION_SIGN = np.array([1.0, -1.0, 1.0, -1.0])


@dataclass(frozen=True, eq=False)
class StandardForm:
    """Constraint matrices in one stacked CSC pattern.

    Parameters
    ----------
    P : (n, n) scipy.sparse.csc_array
        Diagonal objective.
    rows : (m, n) scipy.sparse.csc_array
        ``[A_eq; A_fr; T]`` with ``T`` picking every ``t``; values for friction-net at
        ``mu``. :meth:`values` gives the data array for another model or ``mu``.
    n_eq, n_friction, n_tension : int
        Row counts of the three parts.
    b : (n_eq,) float
        Right-hand side of the equilibrium rows.
    """

    P: sp.csc_array
    rows: sp.csc_array
    n_eq: int
    n_friction: int
    n_tension: int
    b: np.ndarray
    _tension_slot: np.ndarray
    _mu_slot: np.ndarray

    def values(self, method: str, mu: float) -> np.ndarray:
        """The data array of :attr:`rows` for ``method`` (``'net'``/``'plus'``) and ``mu``."""
        data = self.rows.data.copy()
        data[self._mu_slot] = -mu
        data[self._tension_slot] = mu if method == "net" else 0.0
        return data

    def matrix(self, method: str, mu: float) -> sp.csc_array:
        out = self.rows.copy()
        out.data = self.values(method, mu)
        return out


def standard_form(system) -> StandardForm:
    """:class:`StandardForm` of an :class:`~masonry.rbe.equilibrium.EquilibriumSystem`."""
    layout = system.layout
    n, n_vertices = layout.n_columns, layout.n_vertices
    A_eq = sp.coo_array(system.A_eq)
    n_eq = A_eq.shape[0]
    base = layout.WIDTH * np.arange(n_vertices)
    friction_row = n_eq + 4 * np.arange(n_vertices)[:, None] + np.arange(4)  # (IV, 4)
    # per friction row: c (-mu), t (+mu net / 0 plus), f (+-1)
    fr_rows = np.repeat(friction_row[:, :, None], 3, axis=2)
    fr_cols = np.stack([np.broadcast_to(base[:, None], (n_vertices, 4)),
                        np.broadcast_to(base[:, None] + 1, (n_vertices, 4)),
                        base[:, None] + _FRICTION_COLUMN], axis=2)
    fr_kind = np.broadcast_to(np.arange(3), fr_rows.shape)  # 0: mu, 1: tension, 2: sign
    fr_vals = np.stack([np.full((n_vertices, 4), -1.0), np.ones((n_vertices, 4)),
                        np.broadcast_to(_FRICTION_SIGN, (n_vertices, 4))], axis=2)
    tension_rows = n_eq + 4 * n_vertices + np.arange(n_vertices)
    row = np.concatenate([A_eq.row, fr_rows.ravel(), tension_rows])
    col = np.concatenate([A_eq.col, fr_cols.ravel(), base + 1])
    val = np.concatenate([A_eq.data, fr_vals.ravel(), np.ones(n_vertices)])
    kind = np.concatenate([np.full(A_eq.nnz, 3), fr_kind.ravel(), np.full(n_vertices, 3)])
    m = n_eq + 5 * n_vertices
    # CSC by hand so explicit zeros stay and the slot of every entry is known
    order = np.lexsort((row, col))
    indptr = np.concatenate([[0], np.cumsum(np.bincount(col, minlength=n))])
    rows = sp.csc_array((val[order], row[order], indptr), shape=(m, n))
    kind = kind[order]
    return StandardForm(
        P=sp.csc_array(sp.diags_array(system.h_solver, format="csc")),
        rows=rows, n_eq=n_eq, n_friction=4 * n_vertices, n_tension=n_vertices,
        b=-system.f_ext, _tension_slot=np.flatnonzero(kind == 1),
        _mu_slot=np.flatnonzero(kind == 0))


def kept_form(system, workspace: dict) -> StandardForm:
    """The standard form of ``system`` kept in a solver's ``workspace`` (one per scene,
    built on first use: friction+ and other friction coefficients change only values)."""
    if "form" not in workspace:
        workspace["form"] = standard_form(system)
    return workspace["form"]
