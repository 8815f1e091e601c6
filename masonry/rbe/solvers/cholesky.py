"""Sparse Cholesky factorization of block-structured SPD matrices (multifrontal).

The Newton systems of the rigid block equilibrium (:mod:`masonry.rbe.solvers.newton`) are
``M = A J A^T + eps I`` over the six equilibrium rows of every free block: a symmetric
positive definite matrix of dense 6 x 6 blocks whose block pattern is the contact graph
(block ``i`` couples to block ``j`` when an interface joins them). The pattern is fixed
for a scene while the values change at every Newton step, so the ordering and the
symbolic analysis are done once and reused.

Why our own: scipy has no sparse Cholesky. Its SuperLU (``splu``, an LU that ignores
the symmetry) and ``qdldl`` (a simplicial LDL^T, already a dependency for its AMD
ordering) are several times slower on the Newton matrix of a full dome; CHOLMOD
(scikit-sparse, cvxopt) and MKL PARDISO (pypardiso) are faster but bring a GPL/LGPL
library or a 200 MB binary that would become the default install of every user. Dense
6 x 6 blocks and supernodes let LAPACK and BLAS do the arithmetic (``dpotrf``,
``dtrsm``, ``dsyrk``) from scipy alone. The measurements are in ``docs/bench.md``
("The sparse Cholesky against libraries").

Method (Liu, "The multifrontal method for sparse matrix solution", SIAM Review 1992):

1. Order the block graph by approximate minimum degree (AMD, from ``qdldl``'s
   factorization of the graph's diagonally dominant Laplacian-like matrix) or, for
   large graphs, by METIS nested dissection (``pymetis``), then by a postorder of its
   elimination tree.
2. Symbolic factorization on the block graph: the row structure of every column of L,
   fundamental supernodes, then relaxed amalgamation (merge a supernode into its parent
   when that adds few explicit zeros), which trades a little arithmetic for far fewer
   Python-level steps.
3. Numeric factorization, one dense frontal matrix per supernode: assemble the original
   blocks and the children's update matrices (extend-add: a small update by one add at
   precomputed flat positions, a large one by runs of consecutive columns), factor the
   pivot block, form the update for the parent. LAPACK and BLAS are called through
   ctypes, which frees the GIL while they run, so that independent subtrees of the
   elimination tree are factored on two threads at the same time.
4. Leaves of the supernodal tree in stacks: most supernodes of a dome's Newton matrix
   are leaves with small fronts (there the Python-level steps of a front, not its
   arithmetic, are the cost), and many share a shape (pivot columns, front size). A
   stack of them is factored at once, before the threads start: one fancy-index
   assembly of their pivot columns (a leaf has no children, so the rest of its front
   is zero), numpy's stacked Cholesky of the pivot blocks, the panels by forward
   substitution one pivot column at a time (a triangular solve, no inverse), and the
   updates by one stacked product. The triangular solves take a stack's forward
   substitution first and its backward substitution last, the rows below its leaves
   summed by ``np.subtract.at`` (leaves share rows, never columns).
"""

import contextlib
import contextvars
import ctypes
import functools
import logging
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.linalg import cython_blas, cython_lapack

from masonry.rbe.solvers.block_factor import BlockFactor, stacked_forward
from masonry.rbe.solvers.ordering import (amd_order, elimination_tree, has_metis, metis_order,
                                          postorder)
log = logging.getLogger(__name__)

RELAX_ZEROS = 0.2
"""Relaxed amalgamation: merge a supernode into its parent if at most this fraction of
the merged supernode's stored entries are explicit zeros ..."""

RELAX_COLUMNS = 8
"""... or if the merged supernode has at most this many block columns (fewer, larger
fronts: more flops, far fewer Python-level steps; measured in ``docs/bench.md``, "The
sparse Cholesky against libraries")."""


METIS_NODES = 2000
"""Block graphs of at least this many nodes are ordered by METIS nested dissection,
smaller ones by AMD: on the Newton matrices of the full domes (2,264 to 21,648 blocks)
nested dissection needs fewer flops than AMD and factors faster; on a section of 790
blocks it needs more flops and is slower (``docs/bench.md``,
"Ordering and two threads")."""


SMALL_UPDATE = 120
"""Update matrices up to this size are added to their parent's front by one add at
precomputed flat positions, larger ones by runs of consecutive columns (the fastest
of 60, 120, 240 and 480 on preset 1's full dome; ``docs/bench.md``, "The sparse
Cholesky against libraries")."""


BATCH_LEAVES = 2
"""Leaf supernodes (no children, an update of at most :data:`SMALL_UPDATE` rows) with
the same pivot columns and front size are factored and solved as one stack when at
least this many per pivot block column share the shape (a stack steps through its
pivot columns one by one; ``docs/bench.md``, "Batched leaves of the sparse Cholesky")."""


FACTOR_THREADS = 2
"""Most threads of a numeric factorization; its caller may allow fewer
(:func:`factor_threads`)."""

_THREADS = contextvars.ContextVar("factor_threads", default=None)
"""The thread count set by :func:`factor_threads`; None: :data:`FACTOR_THREADS`."""


@contextlib.contextmanager
def factor_threads(threads):
    """Within it, numeric factorizations use at most ``threads`` threads (and at most
    :data:`FACTOR_THREADS`; None: that many). The caller decides: the cores it may use,
    one while another process of the job works on the other core. A context of the
    calling thread, as :mod:`contextvars` keeps it (a forked process inherits it)."""
    token = _THREADS.set(None if threads is None else max(1, int(threads)))
    try:
        yield
    finally:
        _THREADS.reset(token)


def thread_limit():
    """The limit :func:`factor_threads` set here, None outside it."""
    return _THREADS.get()

PARALLEL_FLOPS = 1e9
"""Factorizations of fewer flops run on one thread: below it the Python-level steps of
small fronts, which hold the GIL, outweigh the gain (``docs/bench.md``, "Ordering and
two threads")."""


def _cython_function(module, name, *argtypes):
    """The routine ``name`` of scipy's Cython BLAS or LAPACK (``module``:
    ``scipy.linalg.cython_blas`` or ``cython_lapack``, the Fortran routines with every
    argument by pointer) as a ctypes function of ``argtypes``.

    ctypes releases the GIL during the call, so threads factoring different fronts run
    their dense kernels at the same time; scipy's f2py wrappers (``scipy.linalg.blas``,
    ``lapack``) hold the GIL, and threads calling them run one at a time.
    """
    capsule = module.__pyx_capi__[name]  # how Cython exports the functions to cimport
    ctypes.pythonapi.PyCapsule_GetName.restype = ctypes.c_char_p
    ctypes.pythonapi.PyCapsule_GetName.argtypes = [ctypes.py_object]
    ctypes.pythonapi.PyCapsule_GetPointer.restype = ctypes.c_void_p
    ctypes.pythonapi.PyCapsule_GetPointer.argtypes = [ctypes.py_object, ctypes.c_char_p]
    address = ctypes.pythonapi.PyCapsule_GetPointer(
        capsule, ctypes.pythonapi.PyCapsule_GetName(capsule))
    return ctypes.CFUNCTYPE(None, *argtypes)(address)


# argument types: a flag character, an integer, a double, an array (its address)
_CHAR, _INT = ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)
_DOUBLE, _ARRAY = ctypes.POINTER(ctypes.c_double), ctypes.c_void_p
_DPOTRF = _cython_function(cython_lapack, "dpotrf", _CHAR, _INT, _ARRAY, _INT, _INT)
_DTRSM = _cython_function(cython_blas, "dtrsm", _CHAR, _CHAR, _CHAR, _CHAR, _INT, _INT,
                          _DOUBLE, _ARRAY, _INT, _ARRAY, _INT)
_DSYRK = _cython_function(cython_blas, "dsyrk", _CHAR, _CHAR, _INT, _INT, _DOUBLE, _ARRAY,
                          _INT, _DOUBLE, _ARRAY, _INT)


def _runs(positions):
    """Split sorted ``positions`` into maximal runs of consecutive integers:
    (start in positions, start value, length) per run."""
    breaks = np.flatnonzero(np.diff(positions) != 1) + 1
    first = np.concatenate([[0], breaks])
    length = np.diff(np.concatenate([first, [len(positions)]]))
    return first, positions[first], length


@functools.cache
def _lower_triangle(n):
    """(columns, rows) of the entries ``i >= j`` of an ``n x n`` matrix, column by
    column (few sizes: multiples of the block size up to :data:`SMALL_UPDATE`)."""
    return np.triu_indices(n)


class _AddAt(NamedTuple):
    """A small update's extend-add: the flat positions of its lower triangle in its
    own front (``front``) and in the parent's (``parent``), column-major."""
    front: np.ndarray
    parent: np.ndarray


class _AddRuns(NamedTuple):
    """A large update's extend-add: the parent's rows of its rows (``rows``) and its
    runs of consecutive columns (start in the update, start in the parent, length)."""
    rows: np.ndarray
    runs: tuple


class _LeafGroup(NamedTuple):
    """``G`` leaf supernodes of one shape (``k`` pivot columns, fronts of ``size``),
    factored and solved as one stack. ``values``: where their stored entries are in
    the values :meth:`BlockCholesky.factor` reorders; ``positions``: where they go in
    the stack of the fronts' first ``k`` columns, flat ``(G, k, size)`` (each front
    column-major, as in :meth:`BlockCholesky._numeric_plan`); ``columns`` ``(G, k)`` and
    ``rows`` ``(G, size - k)``: their scalar columns and the rows below them, in the
    factor's order."""
    supernodes: np.ndarray
    k: int
    size: int
    values: np.ndarray
    positions: np.ndarray
    columns: np.ndarray
    rows: np.ndarray


@dataclass(frozen=True, eq=False)
class _Supernode:
    first: int          # first block column (in the factor's order)
    last: int           # last block column, inclusive
    rows: np.ndarray    # (R,) block rows below the supernode's columns, sorted
    parent: int         # parent supernode, -1 for a root
    position: np.ndarray  # where each of ``rows`` is in the parent's front (block units)


def block_graph(n_nodes: int, edges) -> sp.csr_array:
    """The symmetric 0/1 pattern of a block matrix: ``edges`` ((E, 2) int, either order,
    repeats allowed) and the diagonal."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    edges = edges[edges[:, 0] != edges[:, 1]]
    ring = np.arange(n_nodes)
    rows = np.concatenate([edges[:, 0], edges[:, 1], ring])
    cols = np.concatenate([edges[:, 1], edges[:, 0], ring])
    graph = sp.csr_array((np.ones(len(rows)), (rows, cols)), shape=(n_nodes, n_nodes))
    graph.sum_duplicates()
    graph.data[:] = 1.0
    return graph


def _automatic(n_nodes) -> str:
    return "metis" if n_nodes >= METIS_NODES and has_metis() else "amd"


def fill_reducing_order(graph: sp.csr_array, ordering: str = "auto") -> np.ndarray:
    """(n,) int: a fill-reducing order of the block graph ``graph`` (:func:`block_graph`):
    approximate minimum degree (``'amd'``), METIS nested dissection (``'metis'``, needs
    ``pymetis``), or ``'auto'``: METIS from :data:`METIS_NODES` nodes on when ``pymetis``
    is installed, else AMD."""
    n_nodes = graph.shape[0]
    if ordering == "auto":
        ordering = _automatic(n_nodes)
    orderings = {"amd": amd_order, "metis": metis_order}
    return orderings[ordering](graph) if n_nodes > 1 else np.arange(n_nodes)


class BlockCholesky:
    """Symbolic analysis of an SPD block matrix with a fixed block pattern.

    Parameters
    ----------
    n_nodes : int
        Number of block rows (and columns).
    edges : (E, 2) int
        Block pairs ``(i, j)``, ``i != j``, that may be nonzero (either order, repeats
        allowed). Diagonal blocks are always present.
    block_size : int
        Size of the dense blocks (6: the equilibrium rows of one rigid block).
    ordering : {'auto', 'amd', 'metis'} or (n_nodes,) int
        Fill-reducing ordering of the block graph (:func:`fill_reducing_order`), or a
        given order (a permutation of the nodes: a larger graph's order restricted to
        this one, whose fill it then does not exceed).

    Attributes
    ----------
    ordering : str
        The ordering used ('amd', 'metis' or 'given').
    lower_rows, lower_cols : (NB,) int
        The stored blocks ``(i, j)``, ``i >= j``, in the caller's numbering; values are
        passed to :meth:`factor` in this order (block ``(i, j)`` of the lower triangle).
    flops : float
        Floating point operations of one numeric factorization.
    nnz : int
        Entries stored in the factor (explicit zeros of relaxed supernodes included).
    """

    def __init__(self, n_nodes: int, edges, block_size: int = 6, ordering: str = "auto"):
        self.n_nodes = int(n_nodes)
        self.block_size = bs = int(block_size)
        graph = block_graph(self.n_nodes, edges)
        if isinstance(ordering, str):
            order = fill_reducing_order(graph, ordering)
            self.ordering = ordering if ordering != "auto" else _automatic(self.n_nodes)
        else:
            order = np.asarray(ordering, dtype=np.int64)
            if np.sort(order).tolist() != list(range(self.n_nodes)):
                raise ValueError("the given ordering is not a permutation of the nodes")
            self.ordering = "given"
        permuted = sp.csr_array(graph[order][:, order])
        parent = elimination_tree(permuted.indptr, permuted.indices)
        # a postorder is an equivalent order: same fill, the tree relabelled
        post = postorder(parent)
        label = np.empty_like(post)
        label[post] = np.arange(len(post))
        parent = np.where(parent[post] >= 0, label[np.maximum(parent[post], 0)], -1)
        order = order[post]
        permuted = sp.csr_array(graph[order][:, order])
        permuted.sort_indices()
        self.order = order                      # factor position -> caller's node
        self.position = np.empty_like(order)    # caller's node -> factor position
        self.position[order] = np.arange(self.n_nodes)

        structure, count = self._column_structures(permuted, parent)
        self.supernodes = self._supernodes(parent, structure, count)
        self._map_original_blocks(permuted)
        self._children = [[] for _ in self.supernodes]
        for s, sn in enumerate(self.supernodes):
            if sn.parent >= 0:
                self._children[sn.parent].append(s)
        # per supernode: its scalar columns and the scalar rows below them
        self._solve_slices = [(slice(bs * sn.first, bs * (sn.last + 1)),
                               (bs * sn.rows[:, None] + np.arange(bs)).ravel())
                              for sn in self.supernodes]
        self._scalar_order = (bs * order[:, None] + np.arange(bs)).ravel()
        self._front_buffers = []
        self._schedule = None
        self._steps = self._numeric_plan()
        self._leaf_groups = self._leaf_plan()
        self._batched = np.zeros(len(self.supernodes), dtype=bool)
        for group in self._leaf_groups:
            self._batched[group.supernodes] = True
        self._one_by_one = np.flatnonzero(~self._batched).tolist()  # postorder

        self.flops = 0.0
        self.nnz = 0
        for s in self.supernodes:
            k = bs * (s.last - s.first + 1)
            r = bs * len(s.rows)
            self.flops += k**3 / 3 + k * k * r + k * r * r
            self.nnz += k * (k + 1) // 2 + k * r
        log.debug("block Cholesky: %d blocks, %s ordering, %d supernodes, factor %.3g "
                  "entries, %.3g flops", self.n_nodes, self.ordering, len(self.supernodes),
                  self.nnz, self.flops)

    # ------------------------------------------------------------------ symbolic
    @staticmethod
    def _column_structures(permuted, parent):
        """Row structure of every column of L (block level), as sets."""
        n = len(parent)
        children = [[] for _ in range(n)]
        for j, p in enumerate(parent.tolist()):
            if p >= 0:
                children[p].append(j)
        indptr, indices = permuted.indptr, permuted.indices
        structure = [None] * n
        for j in range(n):
            row = indices[indptr[j]:indptr[j + 1]]
            s = set(row[row > j].tolist())
            for c in children[j]:
                s |= structure[c]
            s.discard(j)
            structure[j] = s
        count = np.array([len(s) for s in structure], dtype=np.int64)
        return structure, count

    def _supernodes(self, parent, structure, count):
        n = len(parent)
        n_children = np.bincount(parent[parent >= 0], minlength=n)
        # fundamental supernodes: column j - 1 continues j's supernode when j is its only
        # child's parent and their structures nest exactly
        starts = [0] + [j for j in range(1, n)
                        if not (parent[j - 1] == j and n_children[j] == 1
                                and count[j - 1] == count[j] + 1)]
        bounds = list(zip(starts, starts[1:] + [n]))
        merged = []  # (first, last, true entries)
        for first, stop in bounds:
            last = stop - 1
            entries = int(count[first:stop].sum()) + (stop - first)
            # relaxed amalgamation: absorb the preceding supernodes that are children
            # ending right before this one
            while merged:
                child_first, child_last, child_entries = merged[-1]
                if child_last + 1 != first or parent[child_last] != first:
                    break
                columns = last - child_first + 1
                dense = columns * (columns + 1) // 2 + columns * int(count[last])
                zeros = dense - (entries + child_entries)
                if zeros > RELAX_ZEROS * dense and columns > RELAX_COLUMNS:
                    break
                merged.pop()
                first, entries = child_first, entries + child_entries
            merged.append((first, last, entries))

        column_supernode = np.empty(n, dtype=np.int64)
        for s, (first, last, _) in enumerate(merged):
            column_supernode[first:last + 1] = s
        rows_of, index_of = [], []
        for first, last, _ in merged:
            below = set()
            for j in range(first, last + 1):
                below |= structure[j]
            rows = np.array(sorted(r for r in below if r > last), dtype=np.int64)
            rows_of.append(rows)
            index_of.append(np.concatenate([np.arange(first, last + 1), rows]))
        supernodes = []
        for s, (first, last, _) in enumerate(merged):
            rows = rows_of[s]
            if len(rows) == 0:
                supernodes.append(_Supernode(first, last, rows, -1, position=rows))
                continue
            p = int(column_supernode[rows[0]])
            position = np.searchsorted(index_of[p], rows)
            supernodes.append(_Supernode(first, last, rows, p, position))
        return supernodes

    def _map_original_blocks(self, permuted):
        """Where each stored block of the matrix goes in its supernode's front."""
        lower = sp.tril(permuted).tocsc()
        lower.sort_indices()
        n = self.n_nodes
        col = np.repeat(np.arange(n), np.diff(lower.indptr))
        row = lower.indices.astype(np.int64)
        # the caller's numbering of every stored block, i >= j in factor positions
        a, b = self.order[row], self.order[col]
        self.lower_rows, self.lower_cols = a, b
        self._lower_key = np.sort(a * n + b)
        self._lower_slot = np.argsort(a * n + b)
        column_supernode = np.empty(n, dtype=np.int64)
        for s, sn in enumerate(self.supernodes):
            column_supernode[sn.first:sn.last + 1] = s
        supernode = column_supernode[col]
        by_supernode = np.argsort(supernode, kind="stable")
        self._entry_split = np.searchsorted(supernode[by_supernode],
                                            np.arange(len(self.supernodes) + 1))
        self._entry_order = by_supernode
        local_row = np.empty(len(row), dtype=np.int64)
        for s, sn in enumerate(self.supernodes):
            sel = by_supernode[self._entry_split[s]:self._entry_split[s + 1]]
            index = np.concatenate([np.arange(sn.first, sn.last + 1), sn.rows])
            local_row[sel] = np.searchsorted(index, row[sel])
        self._local_row = local_row
        self._local_col = col - np.array([sn.first for sn in self.supernodes])[supernode]

    def _numeric_plan(self):
        """Everything :meth:`factor` needs per supernode, precomputed as one tuple:
        (front size, pivot columns, slice of its stored blocks in :attr:`_entry_order`,
        flat positions of their entries in the front, children, extend-add into the
        parent, the sizes as LAPACK's integers). A small update (:class:`_AddAt`) is
        taken out of the front as its lower triangle only and added to the parent's
        front by one add at flat positions; a large one (:class:`_AddRuns`) goes by its
        runs of consecutive columns in the parent, each added at the parent's rows
        (fewer bytes of indices to read)."""
        bs = self.block_size
        inner = np.arange(bs)
        steps = []
        for s, sn in enumerate(self.supernodes):
            size = bs * (sn.last - sn.first + 1 + len(sn.rows))
            entries = slice(self._entry_split[s], self._entry_split[s + 1])
            chosen = self._entry_order[entries]
            row = self._local_row[chosen][:, None, None] * bs + inner[:, None]
            col = self._local_col[chosen][:, None, None] * bs + inner[None, :]
            extend = None
            k = bs * (sn.last - sn.first + 1)
            if sn.parent >= 0:
                parent = self.supernodes[sn.parent]
                parent_size = bs * (parent.last - parent.first + 1 + len(parent.rows))
                rows = (bs * sn.position[:, None] + inner).ravel()
                if len(rows) <= SMALL_UPDATE:
                    # the update's lower triangle, column by column: where it is in this
                    # front, and where it goes in the parent's (its upper triangle is
                    # never read)
                    j, i = _lower_triangle(len(rows))
                    extend = _AddAt((k + j) * size + k + i, rows[j] * parent_size + rows[i])
                else:
                    start, value, length = _runs(sn.position)
                    extend = _AddRuns(rows, tuple(zip((bs * start).tolist(),
                                                      (bs * value).tolist(),
                                                      (bs * length).tolist())))
            # the front is column-major: entry (row, col) at col * size + row
            steps.append((size, k, entries, (col * size + row).ravel(), self._children[s],
                          extend, tuple(ctypes.c_int(n) for n in (k, size, size - k))))
        return steps

    def _leaf_plan(self):
        """The leaf supernodes batched by shape (:class:`_LeafGroup`, at least
        :data:`BATCH_LEAVES` of a shape per pivot block column). A leaf's front holds
        only its own stored blocks, all in its pivot columns (its lower right part is
        zero: no children)."""
        by_shape = {}
        for s, (size, k, _, _, children, extend, _) in enumerate(self._steps):
            if not children and isinstance(extend, _AddAt):
                by_shape.setdefault((k, size), []).append(s)
        entry = self.block_size ** 2
        groups = []
        for (k, size), members in sorted(by_shape.items()):
            if len(members) * self.block_size < BATCH_LEAVES * k:
                continue
            steps = [self._steps[s] for s in members]
            values = np.concatenate([np.arange(entry * step[2].start, entry * step[2].stop)
                                     for step in steps])
            # a leaf's stored entries are in its first k columns: flat positions in
            # the front (column-major) are positions in its panel of k columns
            positions = np.concatenate([g * k * size + step[3]
                                        for g, step in enumerate(steps)])
            columns = np.array([np.arange(self._solve_slices[s][0].start,
                                          self._solve_slices[s][0].stop) for s in members])
            rows = np.array([self._solve_slices[s][1] for s in members])
            groups.append(_LeafGroup(np.array(members), k, size, values, positions,
                                     columns, rows))
        return groups

    def block_index(self, i, j) -> np.ndarray:
        """Index into :attr:`lower_rows` of the stored block holding ``(i, j)``.

        ``i`` and ``j`` (caller's numbering, arrays) must be a stored pair in either
        order: the block ``(i, j)`` itself when its factor position is the lower one,
        else its transpose. Use :meth:`is_transposed` to know which."""
        i, j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
        lower = self.position[i] >= self.position[j]
        a, b = np.where(lower, i, j), np.where(lower, j, i)
        key = a * self.n_nodes + b
        where = np.searchsorted(self._lower_key, key)
        if np.any(where >= len(self._lower_key)) or np.any(self._lower_key[where] != key):
            raise ValueError("block pair outside the symbolic pattern")
        return self._lower_slot[where]

    def is_transposed(self, i, j) -> np.ndarray:
        """True where the stored block of ``(i, j)`` is ``(j, i)``."""
        return self.position[np.asarray(i)] < self.position[np.asarray(j)]

    # ------------------------------------------------------------------ numeric
    def factor(self, values) -> BlockFactor:
        """Numeric Cholesky factorization.

        The stacks of leaves (:data:`BATCH_LEAVES`) come first. Then independent
        subtrees of the supernodal elimination tree are factored on
        :data:`FACTOR_THREADS` threads (fewer within :func:`factor_threads`, as the
        caller decides) when the factorization is large enough
        (:data:`PARALLEL_FLOPS`): LAPACK and BLAS run without the GIL, and each thread
        works on its own fronts; the supernodes above the subtrees follow on one thread.

        Parameters
        ----------
        values : (NB, b, b) float
            The stored blocks in :attr:`lower_rows` order: block ``(i, j)`` of the
            matrix (rows of node ``i``, columns of node ``j``).

        Raises
        ------
        numpy.linalg.LinAlgError
            If the matrix is not (numerically) positive definite.
        """
        values = np.asarray(values, dtype=float)[self._entry_order].reshape(-1)
        n = len(self._steps)
        state = ([None] * n, [None] * n, [None] * n)  # updates, pivots, below
        limit = _THREADS.get()
        threads = FACTOR_THREADS if limit is None else min(limit, FACTOR_THREADS)
        if self._schedule is None or self._schedule[0] != threads:
            self._schedule = threads, self._parallel_schedule(threads)
        bins, top = self._schedule[1]
        leaves = [self._factor_leaves(group, values, state[0])
                  for group in self._leaf_groups]
        if len(bins) > 1:
            with ThreadPoolExecutor(max_workers=len(bins) - 1) as pool:
                others = [pool.submit(self._factor_steps, part, values, state, k + 1)
                          for k, part in enumerate(bins[1:])]
                self._factor_steps(bins[0], values, state, 0)
                for other in others:
                    other.result()
        else:
            top = self._one_by_one
        self._factor_steps(top, values, state, 0)
        return BlockFactor(self, state[1], state[2], leaves)

    def _parallel_schedule(self, threads):
        """Subtrees for ``threads`` threads: (one list of supernodes per thread, in
        postorder; the supernodes above them). Split the heaviest subtree at its root
        until it holds at most a thread's share of the flops, then deal the subtrees
        out, heaviest first, to the least loaded thread (longest processing time
        first)."""
        bs = self.block_size
        n = len(self.supernodes)
        work = np.empty(n)
        for s, sn in enumerate(self.supernodes):
            k, r = bs * (sn.last - sn.first + 1), bs * len(sn.rows)
            work[s] = k**3 / 3 + k * k * r + k * r * r
        subtree = work.copy()
        for s, sn in enumerate(self.supernodes):  # postorder: children first
            if sn.parent >= 0:
                subtree[sn.parent] += subtree[s]
        if threads < 2 or work.sum() < PARALLEL_FLOPS:
            return [], range(n)
        share = work.sum() / threads
        frontier = [s for s, sn in enumerate(self.supernodes) if sn.parent < 0]
        top = set()
        for _ in range(n):
            heaviest = max(frontier, key=lambda s: subtree[s])
            if subtree[heaviest] <= share or not self._children[heaviest]:
                break
            frontier.remove(heaviest)
            top.add(heaviest)
            frontier.extend(self._children[heaviest])
        load, bins = np.zeros(threads), [[] for _ in range(threads)]
        for s in sorted(frontier, key=lambda s: -subtree[s]):
            k = int(np.argmin(load))
            load[k] += subtree[s]
            bins[k].append(s)
        # the batched leaves are factored before the threads start
        members = [[s for s in self._subtree_members(roots) if not self._batched[s]]
                   for roots in bins]
        return members, sorted(top)

    def _factor_leaves(self, group, values, updates):
        """Factor the leaves of ``group`` as one stack; their updates into ``updates``
        (each the lower triangle, column by column, as :class:`_AddAt` adds it).

        Returns (L11, L21): the stacked pivot blocks ``(G, k, k)`` and the panels below
        them ``(G, size - k, k)``."""
        k, size = group.k, group.size
        panel = np.zeros(len(group.supernodes) * k * size)
        panel[group.positions] = values[group.values]
        panel = panel.reshape(-1, k, size)  # (G, k, size): the fronts' columns, transposed
        try:  # reads the lower triangles only
            l11 = np.linalg.cholesky(panel[:, :, :k].transpose(0, 2, 1))
        except np.linalg.LinAlgError:
            raise np.linalg.LinAlgError(
                f"matrix not positive definite (a leaf among supernodes "
                f"{group.supernodes.tolist()})") from None
        l21t = panel[:, :, k:]  # F21^T, then L21^T = L11^-1 F21^T
        stacked_forward(l11, l21t)
        # the update F22 - L21 L21^T (F22 is zero in a leaf), its lower triangle; numpy
        # multiplies stacks by BLAS when the first factor is contiguous
        l21 = np.ascontiguousarray(l21t.transpose(0, 2, 1))
        product = l21 @ l21t
        j, i = _lower_triangle(size - k)
        lower = np.take(product.reshape(len(product), -1), j * (size - k) + i, axis=1)
        np.negative(lower, out=lower)
        for s, update in zip(group.supernodes.tolist(), lower):
            updates[s] = update
        return l11, l21

    def _subtree_members(self, roots):
        """Every supernode under ``roots`` (themselves included), in postorder."""
        members, stack = [], list(roots)
        while stack:
            s = stack.pop()
            members.append(s)
            stack.extend(self._children[s])
        return sorted(members)

    def _factor_steps(self, supernodes, values, state, worker):
        """Factor ``supernodes`` (postorder; their children already done or among
        them) with front buffer ``worker``.

        A front is a column-major matrix in the buffer, valid in its lower triangle;
        LAPACK and BLAS work on it in place through ctypes (:func:`_cython_function`:
        the GIL is free while they run), and the pivot columns, the panel below them
        and the update for the parent are copied out of it."""
        updates, pivots, below = state
        steps = self._steps
        # one buffer per thread for every front: fresh fronts would fault their pages in
        # at every factorization
        while len(self._front_buffers) <= worker:
            self._front_buffers.append(np.empty(max(step[0] for step in steps) ** 2))
        buffer = self._front_buffers[worker]
        address, itemsize = buffer.ctypes.data, buffer.itemsize
        one, minus_one, info = ctypes.c_double(1.0), ctypes.c_double(-1.0), ctypes.c_int()
        entry = self.block_size ** 2
        for s in supernodes:
            size, k, entries, positions, children, extend, (k_, size_, rest_) = steps[s]
            flat = buffer[:size * size]
            flat.fill(0.0)
            flat[positions] = values[entry * entries.start:entry * entries.stop]
            front = flat.reshape(size, size, order="F")
            for child in children:
                update, added = updates[child], steps[child][5]
                updates[child] = None
                if isinstance(added, _AddAt):  # positions column-major, as the front
                    flat[added.parent] += update
                    continue
                # by runs of consecutive columns, in the lower triangle only (the update
                # is valid there: dsyrk): columns c:c + n go to the parent's p:p + n
                for c, p, n in added.runs:
                    front[added.rows[c:], p:p + n] += update[c:, c:c + n]
            _DPOTRF(b"L", k_, address, size_, info)  # L11 L11^T = F11
            if info.value != 0:
                raise np.linalg.LinAlgError(
                    f"matrix not positive definite (supernode {s}, pivot {info.value})")
            pivots[s] = front[:k, :k].copy(order="F")
            if size > k:
                panel = address + itemsize * k  # F21, then L21 = F21 L11^-T
                _DTRSM(b"R", b"L", b"T", b"N", rest_, k_, one, address, size_, panel, size_)
                below[s] = front[k:, :k].copy(order="F")
                # F22 - L21 L21^T, the update for the parent
                _DSYRK(b"L", b"N", rest_, k_, minus_one, panel, size_, one,
                       address + itemsize * (k * size + k), size_)
                updates[s] = (flat[extend.front] if isinstance(extend, _AddAt)
                              else front[k:, k:].copy(order="F"))

