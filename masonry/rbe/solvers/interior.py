"""Primal-dual interior point method on the Newton method's reduced system.

The QP is the one of :mod:`masonry.rbe.solvers.newton` (scaled, thesis eq. 3.27)::

    minimize 1/2 x^T H x   subject to   A x = b,   G x <= 0

with ``G`` block-diagonal, the same small matrix ``G_v`` for every interface vertex: the
four faces of the friction pyramid ``|f1|, |f2| <= mu c`` and, for friction+, ``t >= 0``.
Eliminating the slacks and the vertex forces from the Newton system of the
perturbed optimality conditions leaves, at every iteration, ::

    A D A^T dy = r,   D = (H + G^T (Z / S) G)^-1   (one width x width block per vertex)

which has the pattern of the semismooth Newton method's matrix ``A J A^T``: six rows
per free block, factored by the same :class:`~masonry.rbe.solvers.cholesky.BlockCholesky`
symbolic analysis. A general interior point solver (Clarabel) factors the whole KKT
system instead, one row per variable and constraint (26 times larger on the full dome).

Why it exists: friction+ weighs tension 1,000 times more than compression and friction
(thesis eq. 3.27). The semismooth Newton method's dual is piecewise quadratic with
curvatures 1,000 apart, and its active set settles slowly (more than 100 steps on
preset 1's free section); the interior point path crosses the pieces smoothly, in a
number of iterations that barely depends on the weights (Mehrotra's predictor-corrector,
S. Mehrotra, SIAM J. Optim. 2, 1992; the form is CVXOPT's ``coneqp`` for a nonnegative
cone, L. Vandenberghe, 2010). Its last point is polished by Newton steps
(:mod:`masonry.rbe.solve`), which find the exact active set.

It assumes the problem is feasible (friction+ always is): there is no infeasibility
detection, an infeasible problem ends at ``max_iter`` with status ``user_limit``.
"""

import dataclasses
import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.rbe.solvers.base import OPTIMAL, SOLVER_ERROR, USER_LIMIT, QPOutcome
from masonry.rbe.solvers.newton import NewtonSystem, one_blas_thread, prepared_system

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class InteriorOptions:
    """Settings of :func:`solve`.

    Parameters
    ----------
    tol : float
        Stop when the relative equilibrium residual ``||A x - b||_inf / ||b||_inf`` and
        the complementarity ``s^T z`` relative to ``1 + |objective|`` are at most
        ``tol``.
    max_iter : int
    step_fraction : float
        Fraction of the largest step to the boundary of ``s, z >= 0`` that is taken.
    regularization : float
        Shift of the reduced matrix relative to its mean diagonal (as in Newton's).
    min_step : float
        Give up (status ``user_limit``, the last point) when the step falls below this.
    """

    tol: float = 1e-8
    max_iter: int = 60
    step_fraction: float = 0.99
    regularization: float = 1e-10
    min_step: float = 1e-3


WEIGHT_BOUNDS = (1e-14, 1e14)
"""Bounds of the barrier weights ``z / s``: the scaled forces and multipliers are of
order 1 to 1e5, so the weights of converged rows pass 1e14 only when the iterate is at
rounding level."""


def vertex_constraints(components, mu) -> np.ndarray:
    """``G_v`` ((m, width) float): the rows ``G_v x_v <= 0`` of one vertex whose columns
    are ``components`` (indices into ``(c, t, f1, f2)``): the pyramid's faces
    ``+-f1 - mu c``, ``+-f2 - mu c`` and ``-t`` when ``t`` is a column."""
    index = {component: k for k, component in enumerate(components)}
    rows = []
    for friction in (2, 3):
        for sign in (1.0, -1.0):
            row = np.zeros(len(components))
            row[index[0]], row[index[friction]] = -mu, sign
            rows.append(row)
    if 1 in index:
        row = np.zeros(len(components))
        row[index[1]] = -1.0
        rows.append(row)
    return np.array(rows)


def vertex_inverse(h, w, mu, components) -> np.ndarray:
    """``D = (H + G^T W G)^-1`` per vertex, in closed form.

    With the rows of :func:`vertex_constraints` (``+f1, -f1, +f2, -f2`` faces, then
    ``-t``), the matrix is an arrow: ``c`` couples to ``f1`` and ``f2``, ``t`` to
    nothing. Its inverse follows from the Schur complement on ``c``, written without
    subtractions, ``s = h_c + mu^2 sum_i (h_f (w_i+ + w_i-) + 4 w_i+ w_i-) / d_i`` with
    ``d_i = h_f + w_i+ + w_i-``, so that it keeps its digits when the barrier weights
    ``w`` of the active faces grow large (a general inverse lost them).

    Parameters
    ----------
    h : (V, width) float
        Diagonal of ``H`` in the columns ``components`` (indices into ``(c, t, f1, f2)``).
    w : (V, m) float
        Barrier weights ``z / s`` of the vertex rows.
    mu : float
    components : tuple of int

    Returns
    -------
    (V, width, width) float
    """
    index = {component: k for k, component in enumerate(components)}
    c, f1, f2 = index[0], index[2], index[3]
    d = [h[:, f] + w[:, 2 * i] + w[:, 2 * i + 1] for i, f in enumerate((f1, f2))]
    b = [-mu * (w[:, 2 * i] - w[:, 2 * i + 1]) for i in range(2)]
    s = h[:, c] + mu * mu * sum(
        (h[:, f] * (w[:, 2 * i] + w[:, 2 * i + 1]) + 4.0 * w[:, 2 * i] * w[:, 2 * i + 1])
        / d[i] for i, f in enumerate((f1, f2)))
    D = np.zeros((len(h), len(components), len(components)))
    D[:, c, c] = 1.0 / s
    for i, f in enumerate((f1, f2)):
        D[:, c, f] = D[:, f, c] = -b[i] / (d[i] * s)
        for j, g in enumerate((f1, f2)):
            D[:, f, g] = b[i] * b[j] / (d[i] * d[j] * s) + (1.0 / d[i] if i == j else 0.0)
    if 1 in index:
        D[:, index[1], index[1]] = 1.0 / (h[:, index[1]] + w[:, 4])
    return D


def max_step(value, change) -> float:
    """Largest ``a <= 1`` with ``value + a change >= 0`` (``value > 0``)."""
    shrinking = change < 0
    if not shrinking.any():
        return 1.0
    return float(min(1.0, (-value[shrinking] / change[shrinking]).min()))


class _Iterate:
    """The reduced Newton system at one interior point: factor once, solve twice
    (predictor and corrector)."""

    def __init__(self, ns: NewtonSystem, G, x, s, z, shift):
        self.ns, self.G = ns, G
        # bounded: at the end, a pair (z/s, s/z) 1e30 apart makes the vertex block singular
        self.w = np.clip(z / s, WEIGHT_BOUNDS[0], WEIGHT_BOUNDS[1])
        self.D = vertex_inverse(ns.h, self.w, ns.mu, ns.components)
        self.factor = ns.symbolic.factor(ns.newton_blocks(self.D, shift, incremental=False))
        self.s, self.z = s, z

    def direction(self, r_dual, r_primal, r_cone_gap, r_comp):
        """Solve for (dx, dy, ds, dz) given the residuals ``H x - A^T y + G^T z``,
        ``A x - b``, ``G x + s`` and the complementarity target ``r_comp``. The reduced
        system is solved with its shifted factor, without refinement: the residuals are
        recomputed at every iteration, so the small error of a direction is corrected
        by the next one (the Newton polish then meets the equilibrium to rounding)."""
        ns, G, s = self.ns, self.G, self.s
        q = -r_dual - (self.w * r_cone_gap - r_comp / s) @ G
        dq = np.einsum("vij,vj->vi", self.D, q)
        dy = self.factor.solve(-r_primal - ns.A @ dq.ravel())
        dx = np.einsum("vij,vj->vi", self.D, (ns.AT @ dy).reshape(q.shape) + q)
        dz = self.w * (dx @ G.T + r_cone_gap) - r_comp / s
        ds = (-r_comp - s * dz) / self.z
        return dx, dy, ds, dz


START_MU = 0.7
START_SCALE = (0.1, 1000.0)
"""The starting slacks and multipliers are scaled by ``(START_MU / mu)^2``, bounded by
these: a start of the wrong scale makes the first iterations take short steps. The
rule is fitted to the thesis's sections and domes, mu 0.05 to 1.5 (``docs/bench.md``,
"friction+ by the interior point method (issue 15f)"): at mu 0.05 a scale of 100 to
1,000 took 25 or 26 iterations where 1 took 44 or 45; at mu 1.5 a scale of 0.3 saved
2 and 100 cost 5."""


def start_scale(mu) -> float:
    """The factor of the starting slacks and multipliers at friction coefficient ``mu``
    (:data:`START_MU`)."""
    return float(np.clip((START_MU / mu) ** 2, *START_SCALE))


def centred_start(s, z):
    """Mehrotra's starting slacks and multipliers from least-squares ones: shift both
    into the positive orthant, then by half of their mean complementarity."""
    s = s + max(0.0, -1.5 * float(s.min()))
    z = z + max(0.0, -1.5 * float(z.min()))
    product = float(s.ravel() @ z.ravel())
    # both are zero only if x = 0 solves the problem (b = 0)
    s = s + 0.5 * product / max(float(z.sum()), np.finfo(float).tiny) + np.finfo(float).eps
    z = z + 0.5 * product / max(float(s.sum()), np.finfo(float).tiny) + np.finfo(float).eps
    return s, z


@one_blas_thread
def solve(ns: NewtonSystem, options: InteriorOptions) -> QPOutcome:
    """Solve the scaled QP of ``ns`` (its friction model and ``mu``).

    Returns
    -------
    QPOutcome
        ``x`` as (IV, width) forces in the columns of ``ns`` (the caller spreads them to
        the full layout), ``y`` the equilibrium multipliers in the Newton method's
        convention (``H x = A^T y - G^T z``); status ``optimal``, ``user_limit`` (the
        last point) or ``solver_error``.
    """
    start = time.perf_counter()
    G = vertex_constraints(ns.components, ns.mu)
    b, h = ns.b, ns.h
    b_inf = np.abs(b).max()
    n_vertices = len(h)
    m = n_vertices * len(G)
    shift = options.regularization * ns.diagonal_scale

    # start (Mehrotra's rule): the least-squares point of
    #   min 1/2 x^T H x + 1/2 ||G x||^2,  A x = b,
    # its slacks s = -G x and multipliers z = G x shifted inside and balanced
    first = _Iterate(ns, G, np.zeros_like(h), np.ones((n_vertices, len(G))),
                     np.ones((n_vertices, len(G))), shift)
    zero = np.zeros((n_vertices, len(G)))
    x, y, s, z = first.direction(np.zeros_like(h), -b, zero, zero)
    s, z = centred_start(s, z)
    scale = start_scale(ns.mu)
    s, z = scale * s, scale * z
    status, iterations = USER_LIMIT, 0
    for iterations in range(options.max_iter + 1):
        r_dual = h * x - (ns.AT @ y).reshape(x.shape) + z @ G
        r_primal = ns.A @ x.ravel() - b
        r_cone = x @ G.T + s
        gap = float(s.ravel() @ z.ravel()) / m
        objective = 0.5 * float(np.sum(h * x * x))
        # the dual residual is left out: it grows to 1e-7..1e-5 of the largest
        # multiplier in the last iterations (z / s spreads over 20 decades, and
        # dz = W (G dx + r) loses digits); the points are judged on their recomputed
        # equilibrium and friction residuals, then polished by Newton from y
        if (np.abs(r_primal).max() <= options.tol * b_inf
                and gap * m <= options.tol * (1.0 + abs(objective))):
            status = OPTIMAL
            break
        if iterations == options.max_iter:
            break
        try:
            point = _Iterate(ns, G, x, s, z, shift)
        except np.linalg.LinAlgError as error:
            log.warning("interior point: reduced matrix not positive definite: %s", error)
            status = SOLVER_ERROR
            break
        # predictor (affine scaling), then Mehrotra's corrector with the same factor
        dx, dy, ds, dz = point.direction(r_dual, r_primal, r_cone, s * z)
        step = min(max_step(s.ravel(), ds.ravel()), max_step(z.ravel(), dz.ravel()))
        predicted = float((s + step * ds).ravel() @ (z + step * dz).ravel()) / m
        sigma = (predicted / gap) ** 3
        dx, dy, ds, dz = point.direction(r_dual, r_primal, r_cone,
                                         s * z + ds * dz - sigma * gap)
        step = options.step_fraction * min(max_step(s.ravel(), ds.ravel()),
                                           max_step(z.ravel(), dz.ravel()))
        if step < options.min_step:
            log.info("interior point stalled at iteration %d (step %.1e)", iterations, step)
            break
        x, y, s, z = x + step * dx, y + step * dy, s + step * ds, z + step * dz
        log.debug("interior point %d: residual %.2e, dual %.2e, gap %.2e (objective "
                  "%.2e), step %.3f, sigma %.2e", iterations, np.abs(r_primal).max() / b_inf,
                  np.abs(r_dual).max() / max(1.0, np.abs(h * x).max()), gap, objective,
                  step, sigma)
    return QPOutcome(status=status, x=x, iterations=iterations, y=y,
                     solve_time=time.perf_counter() - start,
                     info={"factorizations": iterations + 1})


def backend(system, method, options, workspace) -> QPOutcome:
    """The :mod:`masonry.rbe.solvers` interface: ``options`` are :class:`InteriorOptions`
    fields; the workspace is shared with the Newton backend (its prepared systems and
    their symbolic factorization)."""
    start = time.perf_counter()
    ns = prepared_system(system, method, workspace)
    preparation = time.perf_counter() - start
    outcome = solve(ns, InteriorOptions(**options))
    return dataclasses.replace(outcome, x=ns.full_vector(outcome.x, system.layout),
                               setup_time=preparation)
