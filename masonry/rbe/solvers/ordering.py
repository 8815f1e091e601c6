"""Fill-reducing orderings and the elimination tree of a symmetric block graph, for the
symbolic analysis of :class:`masonry.rbe.solvers.cholesky.BlockCholesky`."""

import numpy as np
import scipy.sparse as sp

from masonry.optional import optional_import

# wheels for Linux and macOS only (pyproject.toml); elsewhere AMD orders every graph
pymetis = optional_import("pymetis")


def has_metis() -> bool:
    """Whether METIS (pymetis) is installed."""
    return pymetis is not None


def amd_order(graph: sp.csr_array) -> np.ndarray:
    """AMD ordering of a symmetric block graph, from qdldl (SuiteSparse AMD)."""
    import qdldl

    degree = np.diff(graph.indptr)
    # diagonally dominant, hence positive definite: the LDL^T exists in any order
    spd = sp.csc_array(graph + sp.diags_array(degree + 1.0))
    return np.asarray(qdldl.Solver(spd).factors()[2], dtype=np.int64)


def metis_order(graph: sp.csr_array) -> np.ndarray:
    """Nested dissection ordering of a symmetric block graph, from METIS (pymetis)."""
    if pymetis is None:
        raise ModuleNotFoundError("the METIS ordering needs pymetis (pip install pymetis)")
    graph = sp.csr_array(graph - sp.diags_array(graph.diagonal()))
    graph.eliminate_zeros()
    adjacency = pymetis.CSRAdjacency(graph.indptr, graph.indices)
    return np.asarray(pymetis.nested_dissection(adjacency)[0], dtype=np.int64)


def elimination_tree(indptr, indices) -> np.ndarray:
    """Elimination tree of a symmetric pattern (Liu's algorithm, path compression)."""
    n = len(indptr) - 1
    parent = np.full(n, -1, dtype=np.int64)
    ancestor = np.full(n, -1, dtype=np.int64)
    parent_l, ancestor_l = parent.tolist(), ancestor.tolist()
    indices_l = indices.tolist()
    for k in range(n):
        for i in indices_l[indptr[k]:indptr[k + 1]]:
            if i >= k:
                continue
            while ancestor_l[i] != -1 and ancestor_l[i] != k:
                following = ancestor_l[i]
                ancestor_l[i] = k
                i = following
            if ancestor_l[i] == -1:
                ancestor_l[i] = k
                parent_l[i] = k
    return np.array(parent_l, dtype=np.int64)


def postorder(parent) -> np.ndarray:
    """A postorder of the forest ``parent`` ((n,) int, -1 at roots): children before
    their parent, every subtree contiguous."""
    n = len(parent)
    children = [[] for _ in range(n)]
    roots = []
    for j, p in enumerate(parent.tolist()):
        (children[p] if p >= 0 else roots).append(j)
    order = []
    stack = [(r, False) for r in reversed(roots)]
    while stack:
        j, done = stack.pop()
        if done:
            order.append(j)
            continue
        stack.append((j, True))
        stack.extend((c, False) for c in reversed(children[j]))
    return np.array(order, dtype=np.int64)
