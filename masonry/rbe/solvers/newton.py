"""Semismooth Newton method on the dual of the RBE quadratic program.

The thesis's QP (eq. 3.27, docs/model.md 6.5), scaled as in :mod:`masonry.rbe.equilibrium`::

    minimize 1/2 x^T H x   subject to   A x = b,   x in K

where ``b = -f_ext`` and ``K`` is a product of one small cone per interface vertex:
the friction model on ``(c, f1, f2)`` (:class:`~masonry.friction.FrictionCone`:
Coulomb's cone ``||(f1, f2)|| <= mu c`` or a pyramid), times ``t >= 0`` for friction+.
friction-net (friction within the model at ``c - t``) has ``t = 0`` at its optimum: any
point with ``t > 0`` stays feasible with ``(c - t, 0)`` in place of ``(c, t)`` (same
force, same cone) and has a smaller objective, so it is solved without ``t``.

Its dual is unconstrained, concave and once differentiable::

    maximize g(y) = b^T y - 1/2 x(y)^T H x(y),   x(y) = projection of H^-1 A^T y onto K

(the projection in the metric of ``H``; vertex by vertex in closed form). ``y`` has one
entry per equilibrium row (six per free block: a virtual displacement and rotation), so
``grad g = b - A x(y)`` is the equilibrium residual of the forces ``x(y)``, and every
``x(y)`` meets the friction and sign constraints exactly. Newton steps use the
generalized Hessian ``-(A J A^T + eps I)``, ``J`` the Jacobian of the projection
(block-diagonal, one 3 x 3 or 4 x 4 block per vertex), factored by
:class:`masonry.rbe.solvers.cholesky.BlockCholesky` on the contact graph; a backtracking
(Armijo) line search on ``g`` globalizes them. A pyramid's projection is piecewise
linear: once the set of active faces is found the step is exact. The cone's projection
is strongly semismooth (its Jacobian varies smoothly on the cone's surface), so the
steps converge quadratically instead; both end with residuals near rounding.

Why: an interior point solver (Clarabel) factors the whole KKT system, one row per
unknown and constraint (790,000 rows on preset 1's full dome), at every iteration, and
ADMM (OSQP) needs many iterations for a loose friction tolerance; this method factors a
system of six rows per block (38,000 rows), once per step, and a feasible full dome
takes few steps (the measured times and steps: ``docs/bench.md``, the bench table and
"Newton against the general solvers").

When friction-net is infeasible the dual is unbounded: the iterates run off along a
Farkas direction ``d`` with ``b^T d > 0`` and ``A^T d`` in the polar cone of ``K``. The
method stops when the current step is such a certificate within tolerance, or when it
stalls or damps out (``NewtonOptions.damped_out``), and reports it;
:mod:`masonry.rbe.solve` then decides what to do.
"""

import copy
import dataclasses
import functools
import logging
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from masonry.rbe.equilibrium import VariableLayout, equilibrium_columns
from masonry.rbe.solvers.base import (INFEASIBLE, OPTIMAL, SOLVER_ERROR, USER_LIMIT, Backend,
                                      Outcome)
from masonry.rbe.solvers.cholesky import BlockCholesky

log = logging.getLogger(__name__)

MODEL_COMPONENTS = {"net": ("c", "f1", "f2"), "plus": ("c", "t", "f1", "f2")}
"""The vertex unknowns each friction model solves for (friction-net has ``t = 0`` at
its optimum, see above)."""

COMPONENTS = {method: tuple(VariableLayout.COMPONENTS.index(name) for name in names)
              for method, names in MODEL_COMPONENTS.items()}
"""Their columns in a vertex's :class:`~masonry.rbe.equilibrium.VariableLayout` block."""

TENSION = VariableLayout.COMPONENTS.index("t")

VERTEX_CHUNK = 32768
"""Vertices per stacked product when forming Newton matrices (bounds the buffers)."""

INCREMENTAL_SHARE = 0.5
"""A Newton matrix is updated vertex by vertex when at most this share of the vertices
changed their Jacobian, else formed anew interface by interface."""


@dataclass(frozen=True)
class NewtonOptions:
    """Settings of :func:`solve`.

    Parameters
    ----------
    tol : float
        Stop when ``||A x - b||_inf / ||b||_inf <= tol``.
    max_iter : int
        Newton steps (each one factorization) before giving up.
    stall : int
        Give up when the residual has not halved in this many steps; an interior-point
        method takes over. The residual wanders before the active set settles, the
        longer the larger the dome (``docs/bench.md``, "Newton's hand-over to the
        load-path LP").
    divergence : float
        Give up when the dual point has grown this many times larger than the first one:
        the iterates run off along a direction of infeasibility without certifying it
        (an interior-point method then decides).
    regularization : float
        ``eps`` of the Newton matrix, relative to the mean of its first diagonal: keeps
        it positive definite when a block has no active contact.
    infeasibility_tol : float
        A direction ``d`` certifies friction-net infeasibility when ``b^T d > 0`` and
        the largest per-vertex part of ``A^T d`` outside the polar cone is below
        ``infeasibility_tol * b^T d / ||b||_1``: then no forces with ``||x||_1`` up to
        ``||b||_1 / infeasibility_tol`` (in reference weights) can balance the loads.
    sufficient_increase : float
        Armijo constant of the backtracking line search on the dual.
    backtracks : int
        Step halvings before the line search counts as stalled.
    short_step : float
        Damping (Levenberg-Marquardt): a step shorter than this raises the shift of the
        Newton matrix by ``damping_raise``; a full step lowers it by ``damping_lower``.
    damping_raise, damping_lower : float
    damping_ceiling : float
        Largest shift, relative to the mean diagonal.
    """

    tol: float = 1e-9
    max_iter: int = 100
    stall: int = 25
    divergence: float = 1e6
    damped_out: int = 0
    regularization: float = 1e-10
    infeasibility_tol: float = 1e-4
    sufficient_increase: float = 1e-4
    backtracks: int = 50
    short_step: float = 0.25
    damping_raise: float = 100.0
    damping_lower: float = 10.0
    damping_ceiling: float = 1e-2


class NewtonSystem:
    """What the Newton method keeps for one :class:`~masonry.rbe.equilibrium.EquilibriumSystem`
    and friction model: the column subset of ``A_eq`` (``A``, and ``AT`` its transpose),
    the Cholesky symbolic analysis of the contact graph (shared between friction models
    and friction coefficients), and the maps that scatter per-interface 12 x 12 blocks
    into the Newton matrix."""

    def __init__(self, system, method, symbolic=None):
        self.method = method
        self.components = COMPONENTS[method]
        columns = np.asarray(self.components)
        layout = system.layout
        width = len(columns)
        self.width = width
        self.h = system.h_solver.reshape(-1, layout.WIDTH)[:, columns]
        # the columns of (c, f1, f2), which the friction model constrains
        self.friction = np.asarray([i for i, c in enumerate(columns) if c != TENSION])
        self.tension = [i for i, c in enumerate(columns) if c == TENSION]
        if np.ptp(self.h[:, self.friction], axis=1).any():
            raise ValueError("the cone's projection needs equal weights on a vertex's c, "
                             "f1, f2")
        self.b = -system.f_ext
        self.mu, self.cone = system.mu, system.cone
        self.floor = system.compression_floor
        # (IV, 12, width): rows of side 0's block, then side 1's
        self.coefficients = np.ascontiguousarray(
            system.vertex_coefficients[:, :, :, columns].reshape(layout.n_vertices, 12, width))
        # CSC, and its transpose CSR: no conversion, and products as fast as CSR's
        self.A = equilibrium_columns(self.coefficients, system.vertex_side_row, len(self.b))
        self.AT = self.A.T
        # contiguous transposes make the stacked matmuls faster
        self._coefficients_t = np.ascontiguousarray(self.coefficients.transpose(0, 2, 1))
        self.vertex_interface = np.asarray(layout.vertex_interface)
        """(IV,) int: the interface of every vertex."""
        self.n_interfaces = layout.n_interfaces
        # sums vertices into interfaces: a sparse product is faster than reduceat
        self._vertex_sum = sp.csc_array(
            (np.ones(layout.n_vertices), (self.vertex_interface, np.arange(layout.n_vertices))),
            shape=(self.n_interfaces, layout.n_vertices))
        # the last Jacobian and its per-interface sums: the Jacobian is piecewise constant,
        # so the next Newton matrix only adds the vertices whose Jacobian changed
        self._last = None
        n_free = len(system.free_block)
        rows = np.asarray(system.side_row, dtype=np.int64)
        if symbolic is None:
            both = (rows >= 0).all(axis=1)
            symbolic = BlockCholesky(n_free, rows[both], block_size=6)
        self.symbolic = symbolic
        self._scatter_maps(rows)

    def _scatter_maps(self, rows):
        """The sparse 0/1 matrix that sums the four 6 x 6 blocks ``(a, b)`` of every
        interface's 12 x 12 block (side ``a``'s rows, side ``b``'s columns) into the
        stored blocks of the Newton matrix: one product per Newton step, with one
        nonzero per interface block rather than per entry (36 times fewer nonzeros to build)."""
        sym = self.symbolic
        k = np.arange(len(rows))
        targets, sources = [], []
        for a, b in ((0, 0), (1, 1), (1, 0), (0, 1)):
            i, j = rows[:, a], rows[:, b]
            use = (i >= 0) & (j >= 0)
            if a != b:
                # one of the two mirrored off-diagonal blocks is stored; both land on the
                # diagonal when the two sides act on the same block
                use &= (i == j) | ~sym.is_transposed(np.maximum(i, 0), np.maximum(j, 0))
            targets.append(sym.block_index(i[use], j[use]))
            sources.append(4 * k[use] + 2 * a + b)
        target, source = np.concatenate(targets), np.concatenate(sources)
        self._scatter = sp.csr_array((np.ones(len(target)), (target, source)),
                                     shape=(len(sym.lower_rows), 4 * len(rows)))
        self.diagonal_blocks = sym.block_index(np.arange(sym.n_nodes), np.arange(sym.n_nodes))
        """Indices of the diagonal blocks among the stored blocks."""

    def with_rhs(self, b):
        """The same system with the right-hand side ``b`` ((6 F,) float) in place of the
        dead load: it shares the matrices and the symbolic factorization."""
        other = copy.copy(self)
        other.b = np.asarray(b, dtype=float)
        return other

    # ------------------------------------------------------------------ kernels
    def project(self, w, truncated=True):
        """``x(y)`` for ``w = A^T y`` ((IV, width)) and the projection's Jacobian; onto
        the cone truncated by the tension cut-off (:attr:`floor`) unless ``truncated`` is
        False (the cone itself, whose polar cone a Farkas certificate asks of)."""
        p = self.friction
        floor = self.floor if truncated else None
        x_p, j_p = self.cone.project(w[:, p] / self.h[:, p[:1]], self.mu, floor)
        j_p /= self.h[:, p[:1], None]
        if not self.tension:  # friction-net: the cone is every column
            return x_p, j_p
        x = np.zeros_like(w)
        jacobian = np.zeros((len(w), self.width, self.width))
        x[:, p] = x_p
        jacobian[:, p[:, None], p[None, :]] = j_p
        for t in self.tension:
            active = w[:, t] > 0
            x[:, t] = np.where(active, w[:, t], 0.0) / self.h[:, t]
            jacobian[:, t, t] = active / self.h[:, t]
        return x, jacobian

    def dual_value(self, y, x):
        return float(self.b @ y - 0.5 * np.sum(self.h * x * x))

    def newton_blocks(self, jacobian, shift, incremental=True):
        """Stored blocks of ``A J A^T + shift I``.

        A pyramid's Jacobian is piecewise constant: from one Newton step to the next only
        the vertices that moved to another face of their cone change it (preset 1's full
        dome: 18,000 of 75,000 vertices at the second step, 500 at the ninth), so the
        per-interface sums of the last call are updated with those vertices alone, unless
        ``incremental`` is False (the interior point method changes every vertex) or
        more than :data:`INCREMENTAL_SHARE` of them changed: then every interface's sum
        is formed anew (:meth:`interface_sums`)."""
        if self._last is None or not incremental:
            sums = self.interface_sums(jacobian)
        else:
            last_jacobian, sums = self._last
            vertices = np.flatnonzero((jacobian != last_jacobian).any(axis=(1, 2)))
            if len(vertices) > INCREMENTAL_SHARE * len(jacobian):
                sums = self.interface_sums(jacobian)
            else:
                sums = sums + self._vertex_sums(
                    vertices, jacobian[vertices] - last_jacobian[vertices])
        if incremental:
            self._last = (jacobian.copy(), sums)
        return self.scatter_sums(sums, shift)

    def _vertex_sums(self, vertices, delta):
        """(K, 144): the interfaces' sums of ``C_v delta_v C_v^T`` over ``vertices``,
        by stacked 12 x 12 products in chunks (bounded buffers on the largest models)."""
        sums = 0.0
        for start in range(0, len(vertices), VERTEX_CHUNK):
            part = slice(start, start + VERTEX_CHUNK)
            chosen = vertices[part]
            per_vertex = np.matmul(np.matmul(self.coefficients[chosen], delta[part]),
                                   self._coefficients_t[chosen])
            sums = sums + self._vertex_sum[:, chosen] @ per_vertex.reshape(-1, 144)
        return sums

    def interface_sums(self, jacobian) -> np.ndarray:
        """(K, 144): every interface's ``sum_v C_v J_v C_v^T`` (``C_v`` the vertex's
        coefficients in both blocks' rows), as the one product ``[C_1 .. C_n] [J_1 C_1^T;
        ..; J_n C_n^T]`` per interface of ``n`` vertices, stacked over the interfaces
        with as many vertices (:attr:`groups`): no per-vertex 12 x 12 products to sum.
        In chunks of :data:`VERTEX_CHUNK` vertices (bounded buffers on the largest
        models)."""
        sums = np.zeros((self.n_interfaces, 12, 12))
        for faces, vertices, left in self.groups:
            step = max(1, VERTEX_CHUNK // vertices.shape[1])
            for start in range(0, len(faces), step):
                part = slice(start, start + step)
                chosen = vertices[part]
                right = np.matmul(jacobian[chosen], self._coefficients_t[chosen])
                sums[faces[part]] = np.matmul(left[part],
                                              right.reshape(len(chosen), -1, 12))
        return sums.reshape(-1, 144)

    @functools.cached_property
    def groups(self):
        """Per vertex count ``n``: the interfaces with ``n`` vertices ((F,) int), their
        vertices ((F, n) int) and the vertices' coefficients side by side ((F, 12,
        n width) float)."""
        out = []
        for faces, vertices in _vertex_groups(self.vertex_interface):
            left = self.coefficients[vertices].transpose(0, 2, 1, 3)
            out.append((faces, vertices, np.ascontiguousarray(left).reshape(
                len(faces), 12, -1)))
        return out

    def scatter_sums(self, sums, shift):
        """Stored blocks of the Newton matrix with the interfaces' 12 x 12 blocks
        ``sums`` ((K, 144), side 0's rows then side 1's), plus ``shift I``."""
        # (K, a, r, b, c) -> (K, a, b, r, c): rows of 36 entries per interface block
        quarters = sums.reshape(-1, 2, 6, 2, 6).transpose(0, 1, 3, 2, 4).reshape(-1, 36)
        blocks = (self._scatter @ quarters).reshape(-1, 6, 6)
        blocks[self.diagonal_blocks] += shift * np.eye(6)
        return blocks

    @functools.cached_property
    def base_blocks(self) -> np.ndarray:
        """Stored blocks of ``A H^-1 A^T``, the Newton matrix without the cones (the
        same for every ``mu``)."""
        base = np.zeros((len(self.h), self.width, self.width))
        base[:, np.arange(self.width), np.arange(self.width)] = 1.0 / self.h
        return self.newton_blocks(base, 0.0, incremental=False)

    @functools.cached_property
    def diagonal_scale(self) -> float:
        """Mean diagonal entry of ``A H^-1 A^T``: the scale of the Newton matrix, which
        the regularization and the damping are relative to."""
        diagonal = self.base_blocks[self.diagonal_blocks]
        return float(np.mean(np.trace(diagonal, axis1=1, axis2=2)) / 6.0)

    def full_vector(self, x, layout):
        """(IV, width) forces in this system's columns -> the (4 IV,) vector of
        ``layout`` (zero in the columns not solved for); None stays None."""
        if x is None:
            return None
        full = np.zeros(layout.n_columns)
        full.reshape(-1, layout.WIDTH)[:, list(self.components)] = x
        return full

    def polar_excess(self, w):
        """Per vertex, the norm of the part of ``w`` that is not in the polar cone of K
        (the projection of ``H^-1 w`` onto K, in the metric of H). A tension cut-off's
        truncated cone lies in K, so a certificate on K is one on it."""
        x, _ = self.project(w, truncated=False)
        return np.sqrt(np.sum(self.h * x * x, axis=1))


def _vertex_groups(vertex_interface):
    """The interfaces grouped by vertex count ``n``: per count, the interfaces ((F,) int)
    and their vertices ((F, n) int), for one stacked product per count."""
    order = np.argsort(vertex_interface, kind="stable")
    counts = np.bincount(vertex_interface)
    groups = []
    for count in np.unique(counts[counts > 0]):
        faces = np.flatnonzero(counts == count)
        first = np.searchsorted(vertex_interface[order], faces)
        groups.append((faces, order[first[:, None] + np.arange(count)]))
    return groups


def solve(system, method, options=None, *, y0=None, newton_system=None) -> Outcome:
    """Solve the scaled RBE QP of ``system`` for ``method`` (``'net'`` or ``'plus'``).

    Parameters
    ----------
    system : masonry.rbe.equilibrium.EquilibriumSystem
    method : {'net', 'plus'}
    options : NewtonOptions, optional
    y0 : (6 F,) float, optional
        Starting dual point (a previous solution's ``y``: same structure, another
        ``mu``). Default: the dual of the QP without the cone constraints.
    newton_system : NewtonSystem, optional
        Reuse a prepared :class:`NewtonSystem` (and its symbolic factorization).

    Returns
    -------
    Outcome
        ``x`` in the layout of ``system`` (solver units; ``t = 0`` for friction-net),
        ``y`` the last dual point. Status ``optimal`` when the residual reached
        ``options.tol``, ``infeasible`` with a certificate (friction-net), else
        ``user_limit`` (iteration limit or a stalled line search) with the last point.
    """
    options = NewtonOptions() if options is None else options
    start = time.perf_counter()
    ns = NewtonSystem(system, method) if newton_system is None else newton_system
    setup = time.perf_counter() - start
    scale = ns.diagonal_scale
    if y0 is None:
        y = _unconstrained_dual(ns, options.regularization * scale)
    else:
        y = np.asarray(y0, dtype=float).copy()
    run = _Run(ns, y, options, scale)
    status = run.iterate(certify=method == "net")
    return Outcome(status=status,
                   x=None if status == INFEASIBLE else ns.full_vector(run.x, system.layout),
                   iterations=run.steps, y=run.y, setup_time=setup,
                   solve_time=time.perf_counter() - start - setup,
                   info={"factorizations": run.factorizations + (y0 is None)})


def _unconstrained_dual(ns, shift):
    """The dual point of the QP without cones: ``A H^-1 A^T y = b``."""
    blocks = ns.base_blocks.copy()
    blocks[ns.diagonal_blocks] += shift * np.eye(6)
    return ns.symbolic.factor(blocks).solve(ns.b)


class _Run:
    """The state of Newton's iterations on the dual ``g(y)``: the point, its forces and
    Jacobian, the damping shift, and the counts."""

    def __init__(self, ns, y, options, scale):
        self.ns, self.options, self.scale = ns, options, scale
        self.b_inf, self.b_one = np.abs(ns.b).max(), np.abs(ns.b).sum()
        self.floor = options.regularization * scale
        self.ceiling = options.damping_ceiling * scale
        self.shift = self.floor
        self.steps = self.factorizations = 0
        self.y_scale = max(float(np.abs(y).max()), np.finfo(float).tiny)
        self._move_to(y, (ns.AT @ y).reshape(len(ns.h), ns.width))

    def _move_to(self, y, w, projected=None):
        self.y, self.w = y, w
        self.x, self.jacobian = self.ns.project(w) if projected is None else projected
        self.value = self._value(y, self.x)

    def _value(self, y, x):
        return self.ns.dual_value(y, x)

    def gradient(self):
        """``b - A x(y)``, the equilibrium residual."""
        return self.ns.b - self.ns.A @ self.x.ravel()

    def iterate(self, certify) -> str:
        """Newton steps until converged (``optimal``), certified infeasible (``certify``
        and a step is a Farkas certificate: ``infeasible``), stalled, diverging, damped out
        or out of steps (``user_limit``), or a matrix that is not positive definite."""
        options = self.options
        best, best_at, previous = np.inf, 0, np.inf
        damped = 0  # steps in a row that ended at the damping ceiling
        for step in range(1, options.max_iter + 1):
            residual = self.gradient()
            size = np.abs(residual).max()
            if size <= options.tol * self.b_inf:
                return OPTIMAL
            if size < 0.5 * best:
                best, best_at = size, step
            elif step - best_at >= options.stall:
                log.info("Newton stalled: residual %.2e, no halving in %d steps",
                         size / self.b_inf, options.stall)
                return USER_LIMIT
            if np.abs(self.y).max() > options.divergence * self.y_scale:
                log.info("Newton diverging (the dual point grew %.0e times): likely "
                         "infeasible", options.divergence)
                return USER_LIMIT
            try:
                direction = self._direction(residual)
            except np.linalg.LinAlgError as error:
                log.warning("Newton matrix not positive definite: %s", error)
                return SOLVER_ERROR
            self.steps += 1
            w_step = (self.ns.AT @ direction).reshape(self.w.shape)
            # a Farkas direction shows up as a step that does not shrink: test only those
            if certify and (step == 1 or size >= previous) and certifies_infeasibility(
                    self.ns, direction, w_step, self.b_one, options.infeasibility_tol):
                return INFEASIBLE
            previous = size
            if not self._line_search(residual, direction, w_step):
                log.info("Newton line search stalled at step %d", step)
                return USER_LIMIT
            damped = damped + 1 if self.shift >= self.ceiling else 0
            if 0 < options.damped_out <= damped:
                log.info("Newton damped out: %d steps in a row at the damping ceiling "
                         "(residual %.2e)", damped, size / self.b_inf)
                return USER_LIMIT
        return USER_LIMIT

    def _direction(self, residual):
        """Solve the generalized Newton system ``(A J A^T + shift I) d = r``."""
        blocks = self.ns.newton_blocks(self.jacobian, self.shift)
        self.factorizations += 1
        return self.ns.symbolic.factor(blocks).solve(residual)

    def _line_search(self, residual, direction, w_step) -> bool:
        """Backtracking (Armijo) along ``direction``, then the damping update; False
        when no step length gives a sufficient increase.

        Near the optimum the increase of ``g`` that a step makes falls below the
        rounding of ``g`` itself (a residual of 1e-9 changes ``g`` by about 1e-18 of its
        value), so the Armijo test can refuse the very steps that converge: a full step
        that at least halves the residual is taken without it (the cone's projection,
        whose Newton steps converge quadratically instead of ending exactly, meets this
        on most polishes)."""
        options = self.options
        slope = float(residual @ direction)
        length = 1.0
        for _ in range(options.backtracks):
            projected = self.ns.project(self.w + length * w_step)
            y_new = self.y + length * direction
            if (self._value(y_new, projected[0])
                    >= self.value + options.sufficient_increase * length * slope):
                break
            if length == 1.0 and (np.abs(self.ns.b - self.ns.A @ projected[0].ravel()).max()
                                  <= 0.5 * np.abs(residual).max()):
                break
            length *= 0.5
        else:
            return False
        log.debug("Newton step %d: residual %.3e, step length %.3g, shift %.1e", self.steps,
                  np.abs(residual).max() / self.b_inf, length, self.shift / self.scale)
        # damping (Levenberg-Marquardt): a block whose contacts all opened has no
        # curvature but the shift, its step is huge and the line search cuts every
        # other block's step with it; short steps raise the shift, full steps lower it
        if length < options.short_step:
            self.shift = min(self.shift * options.damping_raise, self.ceiling)
        elif length == 1.0:
            self.shift = max(self.shift / options.damping_lower, self.floor)
        self._move_to(y_new, self.w + length * w_step, projected)
        return True


def certifies_infeasibility(ns, d, w_d, b_one, tol) -> bool:
    """Whether the direction ``d`` ((6 F,) float, ``w_d = A^T d`` per vertex) is a
    Farkas certificate within ``tol``: ``b^T d > 0`` and ``A^T d`` nearly in the polar
    cone of K (see :class:`NewtonOptions`)."""
    gain = float(ns.b @ d)
    if gain <= 0:
        return False
    return float(ns.polar_excess(w_d).max()) <= tol * gain / b_one


def prepared_system(system, method, workspace) -> NewtonSystem:
    """The :class:`NewtonSystem` of ``method`` kept in ``workspace`` (made on first use;
    the friction models share one symbolic factorization, the workspace's ``symbolic``
    when its caller made one), set to ``system.mu``."""
    prepared = workspace.setdefault("systems", {})
    if method not in prepared:
        symbolic = next((s.symbolic for s in prepared.values()), workspace.get("symbolic"))
        prepared[method] = NewtonSystem(system, method, symbolic=symbolic)
    ns = prepared[method]
    ns.mu, ns.cone, ns.floor = system.mu, system.cone, system.compression_floor
    ns.b = -system.f_ext  # a cohesion's shift (another mu, density) changes it
    return ns


def backend(system, method, options, workspace, y0=None) -> Outcome:
    """The :mod:`masonry.rbe.solvers` interface: ``options`` are :class:`NewtonOptions`
    fields. The workspace keeps the prepared systems (their symbolic factorization is
    shared by both friction models) and the last dual point per model, which starts the
    next solve of that model (another ``mu``) unless ``y0`` is given (a polish)."""
    start = time.perf_counter()
    ns = prepared_system(system, method, workspace)
    preparation = time.perf_counter() - start
    warm = workspace.setdefault("warm", {}).get(method)
    warm = warm if y0 is None else y0
    outcome = solve(system, method, NewtonOptions(**options), y0=warm, newton_system=ns)
    if outcome.status == "optimal":
        workspace["warm"][method] = outcome.y
    return dataclasses.replace(outcome, setup_time=outcome.setup_time + preparation)


BACKEND = Backend("newton", settings="newton", rbe=backend, truncated=("circle",))
"""The semismooth Newton method: the RBE QP (every friction model); the polish of the
other backends' points."""
