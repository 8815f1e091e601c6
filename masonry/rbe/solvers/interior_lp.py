"""Primal-dual interior point method for the collapse LP, on the Newton method's matrix.

The collapse LP of :mod:`masonry.rbe.collapse`, in the scaled rows of
:mod:`masonry.rbe.equilibrium`::

    maximize lambda   subject to   M g + lambda l = b,   g >= 0

``b = -f_dead``, ``l`` the live load, ``M = A E``: ``A`` the equilibrium matrix over the
vertex forces ``(c, f1, f2)`` (the friction-net columns of
:class:`~masonry.rbe.solvers.newton.NewtonSystem`) and ``E`` the four edge rays
``(1, +-mu, +-mu)`` of every vertex's friction pyramid. Its dual::

    minimize -b^T y   subject to   s = -M^T y >= 0,   l^T y = -1

``y`` is the collapse mechanism (a virtual motion of every block) and ``s`` the work of
every edge ray on it: ``s >= 0`` is the associated flow rule, no interface penetrates.

Mehrotra's predictor-corrector (S. Mehrotra, SIAM J. Optim. 2, 1992; S. Wright,
*Primal-Dual Interior-Point Methods*, SIAM 1997, ch. 10) with separate primal and dual
step lengths, and Gondzio's multiple centrality correctors (J. Gondzio, Comput. Optim.
Appl. 6, 1996): a few products ``g s`` far from the target stop the corrector's steps
short, and further solves with the same factor move them back. Every iteration solves
the normal equations ::

    M D M^T dy = r,   D = diag(g / s)

``M D M^T = A (E D E^T) A^T`` has one 3 x 3 block ``E D E^T`` per vertex, so it is the
Newton method's matrix ``A J A^T`` (six rows per free block) with ``J = E D E^T``: the
same :class:`~masonry.rbe.solvers.cholesky.BlockCholesky` symbolic analysis factors it.
The live load's column touches every loaded block; it stays out of the factor
(``lambda`` is eliminated by a second solve with ``l``, a bordered system). A general
interior point solver (Clarabel) factors the whole KKT system instead, one row per
variable and constraint.

It assumes the LP has an optimum: when the dead load cannot stand at any factor, or the
live load is carried at every factor, it ends without one (status ``user_limit``) and
:mod:`masonry.rbe.collapse` asks Clarabel, which detects both.
"""

import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.rbe.equilibrium import friction_pyramid_edges
from masonry.rbe.solvers.base import OPTIMAL, SOLVER_ERROR, USER_LIMIT, QPOutcome
from masonry.rbe.solvers.interior import centred_start, max_step
from masonry.rbe.solvers.newton import NewtonSystem, one_blas_thread

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class LoadFactorOptions:
    """Settings of :func:`load_factor`.

    Parameters
    ----------
    tol : float
        Stop when the residual of the dual rows (``M^T y + s = 0``, relative to the
        largest ``|M^T y|``), ``|l^T y + 1|`` and the duality gap ``g^T s`` relative to
        ``1 + |lambda|`` are at most ``tol`` ...
    primal_tol : float
        ... and the residual of the primal rows (``M g + lambda l = b``, relative to the
        largest load entry) at most ``primal_tol``. The dual rows stay exact, so
        ``-b^T y`` is an upper bound of the factor (:func:`load_factor` reports it),
        within the gap of the primal one while the primal rows hold. The residual is
        recomputed and reported with every collapse result.
    max_iter : int
    step_fraction : float
        Fraction of the largest step to the boundary of ``g, s >= 0`` that is taken.
    regularization : float
        Shift of the normal matrix relative to its mean diagonal. Near the optimum
        ``D`` spans 20 decades and the mean is set by its largest entries: a shift of
        1e-12 left the primal rows at 4e-7 (preset 1's full dome) to 4e-6 (its p = 5
        variant), and the factor up to 1e-6 off the dual bound; with 1e-16 they end at
        1e-9 (:data:`PASS_FLOOR`) and the factor within the gap of the bound.
    min_step : float
        Give up (status ``user_limit``) when a step falls below this.
    correctors : int
        Most centrality correctors per iteration (one solve each, on the iteration's
        factor).
    """

    tol: float = 1e-8
    primal_tol: float = 1e-5
    max_iter: int = 100
    step_fraction: float = 0.99
    regularization: float = 1e-16
    min_step: float = 1e-6
    correctors: int = 2


PRIMAL_PASSES = 2
"""Passes that solve for what the direction leaves of the primal rows, ..."""
PASS_RATIO = 1e-2
PASS_FLOOR = 1e-8
"""... while that is above this fraction of their residual and this fraction of the
largest load entry (without passes the primal residual rises to 3e-7 in the last
iterations; with them it falls to 1e-13, which the factor does not need)."""

ASPIRATION = 0.3
"""A centrality corrector aims at steps this much longer than the last direction's ..."""
ACCEPT = 0.1
"""... and is kept when its shorter step grows by at least this fraction of that."""
BOX = (0.1, 10.0)
"""The products ``g s`` a centrality corrector aims at, relative to the target."""

REGULARIZATION_RAISE = 1e3
REGULARIZATION_RAISES = 3
"""A normal matrix that fails to factor is shifted up to this many times more, by this
factor each time."""


def pyramid_rays(mu) -> np.ndarray:
    """``E_v`` ((3, 4) float): the edge rays of a vertex's friction pyramid as columns, in
    ``(c, f1, f2)`` and in the order of
    :func:`~masonry.rbe.equilibrium.friction_pyramid_edges`."""
    return friction_pyramid_edges(1, mu).toarray()[[0, 2, 3]]


def times_m(ns: NewtonSystem, rays, g) -> np.ndarray:
    """``M g`` ((6 F,)): the loads the edge ray weights ``g`` ((IV, 4)) balance."""
    return ns.A @ (g @ rays.T).ravel()


def times_mt(ns: NewtonSystem, rays, y) -> np.ndarray:
    """``M^T y`` ((IV, 4)): the work of every edge ray on the motion ``y`` ((6 F,))."""
    return (ns.AT @ y).reshape(-1, 3) @ rays


class _RayProducts:
    """Per interface, ``sum_v C_v E D_v E^T C_v^T`` (12 x 12, ``C_v`` the vertex's
    coefficients in both blocks' rows) for edge ray weights ``D``: one column ``C_v E_k``
    per vertex and ray, the columns of every interface side by side, and the interfaces
    with the same vertex count in one product (the Newton system's
    :attr:`~masonry.rbe.solvers.newton.NewtonSystem.groups`), into buffers kept from call
    to call (fresh ones fault their pages in every time; docs/bench.md)."""

    def __init__(self, ns: NewtonSystem, rays):
        self.rays = rays
        self.out = np.zeros((ns.n_interfaces, 12, 12))
        self.groups = []
        for faces, vertices, left in ns.groups:
            # (F, 12, n, 3) coefficients times the rays: (F, 12, 4 n), vertex by vertex
            columns = (left.reshape(len(faces), 12, -1, ns.width) @ rays).reshape(
                len(faces), 12, -1)
            rows = np.ascontiguousarray(columns.transpose(0, 2, 1))
            self.groups.append((faces, vertices, rows, columns, np.empty_like(columns),
                                np.empty((len(faces), 12, 12))))

    def sums(self, d) -> np.ndarray:
        """(K, 144) float: the interfaces' blocks for ``d`` ((IV, 4)), valid until the
        next call."""
        for faces, vertices, rows, columns, scaled, product in self.groups:
            weights = d[vertices].reshape(len(faces), 1, -1)
            np.matmul(np.multiply(columns, weights, out=scaled), rows, out=product)
            self.out[faces] = product
        return self.out.reshape(-1, 144)


class _Normal:
    """The normal equations at one interior point: ``K = M D M^T`` factored once, the
    live load's solve ``K^-1 l`` made with the first direction's and kept for the
    others of the iteration."""

    def __init__(self, ns: NewtonSystem, products: _RayProducts, d, regularization, load):
        self.ns, self.rays, self.d, self.load = ns, products.rays, d, load
        matrix = ns.scatter_sums(products.sums(d), 0.0)
        diagonal = matrix[ns.diagonal_blocks]
        scale = float(np.mean(np.trace(diagonal, axis1=1, axis2=2))) / 6.0
        # near the optimum D spans many decades and K is singular to working precision
        # where no edge ray of a block carries force: a shift relative to K's diagonal,
        # raised until the factorization succeeds (the primal passes of refine()
        # recover the digits it costs)
        for attempt in range(REGULARIZATION_RAISES + 1):
            shift = regularization * REGULARIZATION_RAISE**attempt * scale
            matrix[ns.diagonal_blocks] = diagonal + shift * np.eye(6)
            try:
                self.factor = ns.symbolic.factor(matrix)
                break
            except np.linalg.LinAlgError:
                if attempt == REGULARIZATION_RAISES:
                    raise
                log.debug("collapse LP: normal matrix shifted by %.1e of its diagonal",
                          regularization * REGULARIZATION_RAISE**(attempt + 1))
        self.v = self.lv = None

    def solve(self, rhs):
        """``K^-1 rhs``; the first call solves for the live load too (one pass over the
        factor for two columns costs less than two passes)."""
        if self.v is not None:
            return self.factor.solve(rhs)
        both = self.factor.solve(np.column_stack([rhs, self.load]))
        self.v, self.lv = both[:, 1], float(self.load @ both[:, 1])
        return both[:, 0]

    def times_m(self, g):
        return times_m(self.ns, self.rays, g)

    def times_mt(self, y):
        return times_mt(self.ns, self.rays, y)

    def direction(self, r_primal, r_dual, r_factor, r_comp, g, s):
        """Newton direction for the residuals ``M g + lambda l - b``, ``M^T y + s``,
        ``l^T y + 1`` and the complementarity target ``g s - r_comp`` (elementwise):
        ``(dg, dlambda, dy, ds)``."""
        rhs = -r_primal + self.times_m(r_comp / s - self.d * r_dual)
        dy, d_factor = self._bordered(rhs, float(r_factor))
        ds = -r_dual - self.times_mt(dy)
        return -r_comp / s - self.d * ds, d_factor, dy, ds

    def refine(self, direction, r_primal, floor):
        """``direction`` after up to :data:`PRIMAL_PASSES` passes that solve for what it
        leaves of the primal rows (``D`` amplifies the errors of ``dy`` in ``dg``), while
        that is above :data:`PASS_RATIO` of their residual and above ``floor``; the
        correction ``D M^T dy'`` keeps the other rows exact, as ``S D = G``."""
        dg, d_factor, dy, ds = direction
        bound = max(PASS_RATIO * np.abs(r_primal).max(), floor)
        for _ in range(PRIMAL_PASSES):
            left = self.times_m(dg) + d_factor * self.load + r_primal
            if np.abs(left).max() <= bound:
                break
            correction, d_extra = self._bordered(-left, 0.0)
            dy, d_factor = dy + correction, d_factor + d_extra
            correction = self.times_mt(correction)
            dg, ds = dg + self.d * correction, ds - correction
        return dg, d_factor, dy, ds

    def _bordered(self, rhs, r_factor):
        """``(dy, dlambda)`` with ``K dy + l dlambda = rhs`` and ``l^T dy = -r_factor``."""
        u = self.solve(rhs)
        d_factor = (float(self.load @ u) + r_factor) / self.lv
        return u - d_factor * self.v, d_factor


def _start(ns, products, load, regularization):
    """Mehrotra's starting point: the least-norm ``g`` with ``M g = b`` (``lambda = 0``),
    the least-norm dual slacks ``s = -M^T y`` with ``l^T y = -1``, both shifted inside
    the orthant and balanced (:func:`~masonry.rbe.solvers.interior.centred_start`)."""
    unit = _Normal(ns, products, np.ones((len(ns.h), 4)), regularization, load)
    g = unit.times_mt(unit.solve(ns.b))
    y = -unit.v / unit.lv
    g, s = centred_start(g, -unit.times_mt(y))
    return g, y, s


@one_blas_thread
def load_factor(ns: NewtonSystem, load, options: LoadFactorOptions, *, rhs=None,
                stop=None) -> QPOutcome:
    """The largest ``lambda`` of the collapse LP (module docstring) on the friction-net
    system ``ns``, for the live load ``load`` ((6 F,) float, scaled rows).

    Parameters
    ----------
    rhs : (6 F,) float, optional
        The right-hand side in place of ``b = ns.b`` (the dead load).
    stop : callable, optional
        ``stop(lambda, g, y) -> bool``, asked at every iterate before the convergence
        test: True ends the iterations there (status ``user_limit``,
        ``info["stopped"]`` True) with that iterate.

    Returns
    -------
    QPOutcome
        ``x`` the edge rays' weights ``g`` ((IV, 4), scaled), ``y`` the mechanism (the
        equilibrium rows' multipliers), ``info["load_factor"]`` and
        ``info["dual_bound"]`` (``-b^T y``: with exact dual rows, an upper bound of the factor);
        status ``optimal``, ``user_limit`` (no optimum found: see the module docstring)
        or ``solver_error``.
    """
    start = time.perf_counter()
    if rhs is not None:
        ns = ns.with_rhs(rhs)
    load = np.asarray(load, dtype=float)
    products = _RayProducts(ns, pyramid_rays(ns.mu))
    rays = products.rays
    scale = max(np.abs(ns.b).max(), np.abs(load).max())
    g, y, s = _start(ns, products, load, options.regularization)
    factor, status, iterations, stopped = 0.0, USER_LIMIT, 0, False
    for iterations in range(options.max_iter + 1):
        residuals = _residuals(ns, rays, load, g, y, s, factor)
        if stop is not None and stop(factor, g, y):
            stopped = True
            break
        if _converged(residuals, g, s, factor, scale, options):
            status = OPTIMAL
            break
        if iterations == options.max_iter:
            break
        try:
            normal = _Normal(ns, products, g / s, options.regularization, load)
        except np.linalg.LinAlgError as error:
            log.warning("collapse LP: normal equations not positive definite: %s", error)
            status = SOLVER_ERROR
            break
        (primal, dual), (dg, d_factor, dy, ds) = _mehrotra(normal, residuals[:3], g, s,
                                                           PASS_FLOOR * scale, options)
        if min(primal, dual) < options.min_step:
            log.info("collapse LP: stalled at iteration %d (steps %.1e, %.1e)",
                     iterations, primal, dual)
            break
        g, factor = g + primal * dg, factor + primal * d_factor
        y, s = y + dual * dy, s + dual * ds
        log.debug("collapse LP %d: lambda %.10g, residuals %.1e %.1e %.1e, gap %.2e, "
                  "steps %.3f %.3f", iterations, factor,
                  np.abs(residuals[0]).max() / scale,
                  np.abs(residuals[1]).max() / max(residuals[3], 1.0), abs(residuals[2]),
                  float(g.ravel() @ s.ravel()), primal, dual)
    return QPOutcome(status=status, x=g, iterations=iterations, y=y,
                     solve_time=time.perf_counter() - start,
                     info={"factorizations": iterations + 1, "load_factor": factor,
                           "dual_bound": -float(ns.b @ y), "stopped": stopped})


def _residuals(ns, rays, load, g, y, s, factor):
    """``(M g + lambda l - b, M^T y + s, l^T y + 1, |M^T y|_inf)``."""
    mty = times_mt(ns, rays, y)
    return (times_m(ns, rays, g) + factor * load - ns.b, mty + s, float(load @ y) + 1.0,
            float(np.abs(mty).max()))


def _converged(residuals, g, s, factor, scale, options) -> bool:
    r_primal, r_dual, r_factor, dual_scale = residuals
    tol = options.tol
    return (np.abs(r_primal).max() <= options.primal_tol * scale
            and np.abs(r_dual).max() <= tol * max(dual_scale, 1.0)
            and abs(r_factor) <= tol
            and float(g.ravel() @ s.ravel()) <= tol * (1.0 + abs(factor)))


def _mehrotra(normal, residuals, g, s, floor, options):
    """Predictor (affine scaling), Mehrotra's corrector and Gondzio's centrality
    correctors, all with the same factor: ``((primal step, dual step), (dg, dlambda,
    dy, ds))``."""
    gap = float(g.ravel() @ s.ravel()) / g.size
    dg, _, _, ds = normal.direction(*residuals, g * s, g, s)
    primal, dual = _steps(g, s, dg, ds)
    predicted = float((g + primal * dg).ravel() @ (s + dual * ds).ravel()) / g.size
    target = (predicted / gap) ** 3 * gap
    r_comp = g * s + dg * ds - target
    direction = normal.direction(*residuals, r_comp, g, s)
    steps = _steps(g, s, direction[0], direction[3])
    log.debug("  affine %.3f %.3f sigma %.2e, corrector %.3f %.3f", primal, dual,
              target / gap, *steps)
    direction = _centrality_correctors(normal, residuals, g, s, r_comp, target,
                                       direction, steps, options.correctors)
    direction = normal.refine(direction, residuals[0], floor)
    steps = _steps(g, s, direction[0], direction[3])
    return tuple(options.step_fraction * step for step in steps), direction


def _centrality_correctors(normal, residuals, g, s, r_comp, target, direction, steps,
                           count):
    """Gondzio's correctors of ``direction`` (complementarity residual ``r_comp``,
    ``steps``): each moves the products ``g s`` of the point that a longer step would
    reach into ``[BOX[0], BOX[1]] x target``, and is kept while it lengthens the
    shorter step by :data:`ACCEPT` x :data:`ASPIRATION` at least."""
    for _ in range(count):
        aspired = [min(1.0, step + ASPIRATION) for step in steps]
        products = (g + aspired[0] * direction[0]) * (s + aspired[1] * direction[3])
        push = np.clip(products, BOX[0] * target, BOX[1] * target) - products
        push = np.maximum(push, -BOX[1] * target)
        trial = normal.direction(*residuals, r_comp - push, g, s)
        trial_steps = _steps(g, s, trial[0], trial[3])
        log.debug("  centrality corrector %.3f %.3f", *trial_steps)
        if min(trial_steps) < min(steps) + ACCEPT * ASPIRATION:
            return trial if min(trial_steps) > min(steps) else direction
        direction, steps, r_comp = trial, trial_steps, r_comp - push
    return direction


def _steps(g, s, dg, ds):
    """The largest steps ``<= 1`` that keep ``g`` and ``s`` nonnegative."""
    return max_step(g.ravel(), dg.ravel()), max_step(s.ravel(), ds.ravel())
