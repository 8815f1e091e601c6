"""The numeric factor of a :class:`~masonry.rbe.solvers.cholesky.BlockCholesky`
factorization and its triangular solves (step 4 of that module's method: the stacks of
leaves solved at once, the other supernodes one by one)."""

import functools

import numpy as np
from scipy.linalg import blas


class BlockFactor:
    """A numeric factorization ``P M P^T = L L^T`` (made by
    :meth:`~masonry.rbe.solvers.cholesky.BlockCholesky.factor`); :meth:`solve` applies
    ``M^-1``."""

    def __init__(self, symbolic, pivots, below, leaves):
        self.symbolic = symbolic
        self._pivots = pivots    # per supernode: L11 (Fortran order), None if batched
        self._below = below      # per supernode: L21, None if batched or a root
        self._leaves = leaves    # per leaf group: stacked (L11, L21)

    def solve(self, rhs) -> np.ndarray:
        """``M^-1 rhs`` for ``rhs`` of shape (n,) or (n, k), n = nodes x block size."""
        sym = self.symbolic
        order = sym._scalar_order
        x = np.asarray(rhs, dtype=float)[order]
        # a vector by dtrsv: fewer checks and copies per supernode than a one-column
        # dtrsm, and most solves are of one vector (docs/bench.md,
        # "Measurements behind design choices")
        if x.ndim == 1:
            forward = functools.partial(blas.dtrsv, lower=1)
            backward = functools.partial(blas.dtrsv, lower=1, trans=1)
        else:
            forward = functools.partial(blas.dtrsm, 1.0, lower=1)
            backward = functools.partial(blas.dtrsm, 1.0, lower=1, trans_a=1)
        # one tuple per supernode outside the stacks: (its columns, the rows below
        # them), L11, L21
        plan = [(sym._solve_slices[s], self._pivots[s], self._below[s])
                for s in sym._one_by_one]
        stacked = x.reshape(len(x), -1)  # a view: columns of the right-hand sides
        for group, (l11, l21) in zip(sym._leaf_groups, self._leaves):
            _forward_leaves(stacked, group, l11, l21)
        for (columns, rows), pivot, below in plan:
            xs = forward(pivot, x[columns])
            x[columns] = xs
            if below is not None:
                x[rows] -= below @ xs
        for (columns, rows), pivot, below in reversed(plan):
            v = x[columns]
            if below is not None:
                v = v - below.T @ x[rows]
            x[columns] = backward(pivot, v)
        for group, (l11, l21) in zip(sym._leaf_groups, self._leaves):
            _backward_leaves(stacked, group, l11, l21)
        out = np.empty_like(x)
        out[order] = x
        return out


def _forward_leaves(x, group, l11, l21):
    """Forward substitution of a group of leaves (a leaf group of the symbolic analysis)
    on ``x`` (n, m), in place: their columns by ``L11 xs = x``, then the rows below them
    less ``L21 xs`` (rows of different leaves overlap: summed by ``np.subtract.at``)."""
    xs = x[group.columns]  # (G, k, m)
    stacked_forward(l11, xs)
    x[group.columns] = xs
    np.subtract.at(x, group.rows, l21 @ xs)


def stacked_forward(l11, b):
    """``b <- L11^-1 b`` in place for stacks of lower triangles ``l11`` (G, k, k) and
    right-hand sides ``b`` (G, k, m): forward substitution, one row at a time."""
    for j in range(l11.shape[1]):
        if j:
            b[:, j] -= (l11[:, j, None, :j] @ b[:, :j])[:, 0]
        b[:, j] /= l11[:, j, j, None]


def _backward_leaves(x, group, l11, l21):
    """Backward substitution of a group of leaves on ``x`` (n, m), in place:
    ``L11^T xs = x - L21^T x_below`` on their columns (the rows below are final)."""
    xs = x[group.columns] - l21.transpose(0, 2, 1) @ x[group.rows]
    for j in reversed(range(group.k)):
        if j < group.k - 1:
            xs[:, j] -= (l11[:, None, j + 1:, j] @ xs[:, j + 1:])[:, 0]
        xs[:, j] /= l11[:, j, j, None]
    x[group.columns] = xs
