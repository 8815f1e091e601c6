"""A sparse Cholesky factorization of a larger block graph serving its subgraphs
(:class:`Embedded`): the construction stages of a structure
(:mod:`masonry.rbe.sequence`) factor on the symbolic analysis of the course being laid,
complete, instead of analysing every stage's graph again."""

from typing import NamedTuple

import numpy as np

from masonry.rbe.solvers.block_factor import BlockFactor
from masonry.rbe.solvers.cholesky import BlockCholesky


class Embedded:
    """A :class:`BlockCholesky` of a larger block graph serving a subgraph of it: the
    symbolic analysis is made once for the larger graph, and every subgraph within it
    factors on it, the larger graph's other nodes decoupled (an identity diagonal
    block, a zero right-hand side). It has the interface :class:`BlockCholesky` offers
    the Newton systems (:mod:`masonry.rbe.solvers.newton`).

    Parameters
    ----------
    symbolic : BlockCholesky
        Of the larger graph.
    nodes : (n,) int
        The larger graph's node of each node of the subgraph; every edge of the subgraph
        must be one of the larger graph's.
    """

    def __init__(self, symbolic: BlockCholesky, nodes):
        self.symbolic = symbolic
        self.nodes = np.asarray(nodes, dtype=np.int64)
        self.n_nodes = len(self.nodes)
        self.block_size = bs = symbolic.block_size
        self.lower_rows = symbolic.lower_rows
        idle = np.ones(symbolic.n_nodes, bool)
        idle[self.nodes] = False
        idle = np.flatnonzero(idle)
        self._idle = symbolic.block_index(idle, idle)
        self._scalar = (bs * self.nodes[:, None] + np.arange(bs)).ravel()

    def block_index(self, i, j) -> np.ndarray:
        """:meth:`BlockCholesky.block_index` in the subgraph's numbering."""
        return self.symbolic.block_index(self.nodes[np.asarray(i)], self.nodes[np.asarray(j)])

    def is_transposed(self, i, j) -> np.ndarray:
        return self.symbolic.is_transposed(self.nodes[np.asarray(i)],
                                           self.nodes[np.asarray(j)])

    def factor(self, values) -> "_EmbeddedFactor":
        """:meth:`BlockCholesky.factor` of the stored blocks ``values`` (the larger
        graph's; the blocks of nodes outside the subgraph are ignored)."""
        values = np.array(values, dtype=float)
        values[self._idle] = np.eye(self.block_size)
        return _EmbeddedFactor(self.symbolic.factor(values), self._scalar,
                               self.symbolic.n_nodes * self.block_size)


class _EmbeddedFactor(NamedTuple):
    factor: BlockFactor
    scalar: np.ndarray
    size: int

    def solve(self, rhs) -> np.ndarray:
        """``M^-1 rhs`` on the subgraph's rows (see :meth:`BlockFactor.solve`)."""
        rhs = np.asarray(rhs, dtype=float)
        full = np.zeros((self.size,) + rhs.shape[1:])
        full[self.scalar] = rhs
        return self.factor.solve(full)[self.scalar]
