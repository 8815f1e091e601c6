"""Primal-dual interior point method on the Newton method's reduced system.

The QP is the one of :mod:`masonry.rbe.solvers.newton` (scaled, thesis eq. 3.27)::

    minimize 1/2 x^T H x   subject to   A x = b,   G_b x + s_b = 0,   s_b in C_b

with ``G_b`` block-diagonal, the same small matrix per interface vertex for each cone
``C_b`` (:func:`vertex_cones`): the friction model (a pyramid's faces with nonnegative
slacks, or Coulomb's cone as the second-order cone of ``(mu c, f1, f2)``) and, for
friction+, ``t >= 0``. With the Nesterov-Todd scalings ``W_b`` of the slacks and their
multipliers (:mod:`.cones`), eliminating the slacks and the vertex forces from the Newton
system of the perturbed optimality conditions leaves, at every iteration, ::

    A D A^T dy = r,   D = (H + sum_b G_b^T W_b^-2 G_b)^-1   (one block per vertex)

which has the pattern of the semismooth Newton method's matrix ``A J A^T``: six rows
per free block, factored by the same :class:`~masonry.rbe.solvers.cholesky.BlockCholesky`
symbolic analysis. A general interior point solver (Clarabel) factors the whole KKT
system instead, one row per variable and constraint (26 times larger on the full dome).

Why it exists: friction+ weighs tension 1,000 times more than compression and friction
(thesis eq. 3.27). The semismooth Newton method's dual is piecewise quadratic with
curvatures 1,000 apart, and its active set settles slowly (``docs/bench.md``, "friction+
by the interior point method"); the interior point path crosses the pieces smoothly, in a
number of iterations that barely depends on the weights (Mehrotra's predictor-corrector,
S. Mehrotra, SIAM J. Optim. 2, 1992; the form is CVXOPT's ``coneqp``, L. Vandenberghe,
2010). Its last point is polished by Newton steps (:mod:`masonry.rbe.solve`), which find
the exact active set.

It assumes the problem is feasible (friction+ always is): there is no infeasibility
detection, an infeasible problem ends at ``max_iter`` with status ``user_limit``.

The backend ``interior`` (:data:`BACKEND`) is this method for the RBE QP and its
counterpart for the collapse program (:mod:`masonry.rbe.solvers.interior_lp`).
"""

import dataclasses
import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.rbe.solvers.base import OPTIMAL, SOLVER_ERROR, USER_LIMIT, Backend, Outcome
from masonry.rbe.solvers.cones import Lorentz, Orthant, centred_start
from masonry.rbe.solvers.interior_lp import InteriorProgram
from masonry.rbe.solvers.newton import NewtonSystem, prepared_system

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
        Fraction of the largest step to the boundary of the cones that is taken.
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
"""Bounds of the barrier weights ``z / s`` of the nonnegative slacks: the scaled forces
and multipliers are of order 1 to 1e5, so the weights of converged rows pass 1e14 only
when the iterate is at rounding level."""


@dataclass(frozen=True)
class VertexCone:
    """One cone of every vertex: ``G x_v + s = 0``, ``s`` in ``cone``."""

    cone: object
    G: np.ndarray  # (m, width)


def vertex_cones(components, friction_cone, mu) -> list:
    """The :class:`VertexCone` s of one vertex whose columns are ``components`` (indices
    into ``(c, t, f1, f2)``): the friction model's (a pyramid's faces ``f . normal_k - a
    c <= 0``; Coulomb's cone as ``s = (mu c, f1, f2)`` in the second-order cone) and
    ``-t <= 0`` when ``t`` is a column (friction+: the friction acts on ``c``)."""
    index = {component: k for k, component in enumerate(components)}
    width = len(components)
    picked = [index[0], index[2], index[3]]
    if friction_cone.is_polyhedral:
        faces = friction_cone.faces(mu)                  # (K, 3) over (c, f1, f2)
        G = np.zeros((len(faces), width))
        G[:, picked] = faces
        out = [VertexCone(Orthant(len(faces)), G)]
    else:
        G = np.zeros((3, width))
        G[[0, 1, 2], picked] = (-mu, -1.0, -1.0)
        out = [VertexCone(Lorentz(), G)]
    if 1 in index:
        G = np.zeros((1, width))
        G[0, index[1]] = -1.0
        out.append(VertexCone(Orthant(1), G))
    return out


def scaling_of(cone, s, z):
    """The cone's scaling of ``(s, z)`` and its ``W^-1`` per vertex ((V, m) for the
    orthant's diagonal, (V, m, m) for the second-order cone), the orthant's weights
    ``z / s`` bounded by :data:`WEIGHT_BOUNDS` (at the end, a pair 1e30 apart makes the
    vertex block singular)."""
    scaling = cone.scaling(s, z)
    if isinstance(cone, Orthant):
        return scaling, np.sqrt(np.clip(z / s, *WEIGHT_BOUNDS))
    return scaling, scaling.W_inverse


def vertex_inverse(h, cones, w_inverse) -> np.ndarray:
    """``D = (H + sum_b G_b^T W_b^-2 G_b)^-1`` per vertex.

    The matrix in parentheses is ``B^T B`` with ``B`` the rows ``W_b^-1 G_b`` of every
    cone stacked on ``diag(sqrt(h))``; ``B = Q R`` (Householder QR, numpy's stacked
    ``qr``) gives ``D = R^-1 R^-T`` without forming ``B^T B``, whose condition number is
    the square of ``B``'s: when the barrier weights of the active faces grow to 1e14, an
    inverse of the formed matrix keeps no digit of its small directions and the method
    stalls before its tolerance (tests/test_solvers.py compares both).

    Parameters
    ----------
    h : (V, width) float
        Diagonal of ``H``.
    cones : list of VertexCone
    w_inverse : list of (V, m) or (V, m, m) float
        ``W_b^-1`` of every cone: a diagonal as its entries, or the matrices.

    Returns
    -------
    (V, width, width) float
    """
    rows = [np.sqrt(h)[:, :, None] * np.eye(h.shape[1])]
    for vc, w in zip(cones, w_inverse):
        rows.append(w[:, :, None] * vc.G if w.ndim == 2 else w @ vc.G)
    r = np.linalg.qr(np.concatenate(rows, axis=1), mode="r")
    r_inverse = np.linalg.inv(r)
    return r_inverse @ r_inverse.transpose(0, 2, 1)


class _Iterate:
    """The reduced Newton system at one interior point: factor once, solve twice
    (predictor and corrector)."""

    def __init__(self, ns: NewtonSystem, cones, s, z, shift):
        self.ns, self.cones = ns, cones
        self.scalings, w_inverse = zip(*(scaling_of(vc.cone, sb, zb)
                                         for vc, sb, zb in zip(cones, s, z)))
        self.weights = [w * w if w.ndim == 2 else w @ w for w in w_inverse]
        self.D = vertex_inverse(ns.h, cones, w_inverse)
        self.factor = ns.symbolic.factor(ns.newton_blocks(self.D, shift, incremental=False))

    def _times_w2_inverse(self, b, v):
        w = self.weights[b]
        return w * v if w.ndim == 2 else np.einsum("vij,vj->vi", w, v)

    def direction(self, r_dual, r_primal, r_cone, r_comp):
        """Solve for (dx, dy, ds, dz) given the residuals ``H x - A^T y + G^T z``,
        ``A x - b``, ``G x + s`` (per cone) and the scaled complementarity ``lam o
        (W^-1 ds + W dz) = -r_comp`` (per cone). The reduced system is solved with its
        shifted factor, without refinement: the residuals are recomputed at every
        iteration, so the small error of a direction is corrected by the next one (the
        Newton polish then meets the equilibrium to rounding)."""
        ns = self.ns
        # q_c = -lam \ r_comp and W^-1 q_c, per cone
        q_c = [-vc.cone.divide(sc.lam, rc)
               for vc, sc, rc in zip(self.cones, self.scalings, r_comp)]
        wq = [sc.times_w_inverse(q) for sc, q in zip(self.scalings, q_c)]
        q = -r_dual
        for b, vc in enumerate(self.cones):
            q = q - (wq[b] + self._times_w2_inverse(b, r_cone[b])) @ vc.G
        dq = np.einsum("vij,vj->vi", self.D, q)
        dy = self.factor.solve(-r_primal - ns.A @ dq.ravel())
        dx = np.einsum("vij,vj->vi", self.D, (ns.AT @ dy).reshape(q.shape) + q)
        # dz from the cone rows, ds from the complementarity rows (W^-1 ds + W dz = q_c):
        # ds = W q_c - W^2 dz keeps the complementarity of the step exact, which the
        # last iterations need (CVXOPT's coneqp does the same)
        ds, dz = [], []
        for b, (vc, sc) in enumerate(zip(self.cones, self.scalings)):
            dz.append(wq[b] + self._times_w2_inverse(b, r_cone[b] + dx @ vc.G.T))
            ds.append(sc.times_w(q_c[b] - sc.times_w(dz[b])))
        return dx, dy, ds, dz


START_MU = 0.7
START_SCALE = (0.1, 1000.0)
"""The starting slacks and multipliers are scaled by ``(START_MU / mu)^2``, bounded by
these: a start of the wrong scale makes the first iterations take short steps. The
rule is fitted to the thesis's sections and domes, mu 0.05 to 1.5: a larger start at low
friction, a smaller one at high friction (the iterations per scale: ``docs/bench.md``,
"friction+ by the interior point method")."""


def start_scale(mu) -> float:
    """The factor of the starting slacks and multipliers at friction coefficient ``mu``
    (:data:`START_MU`)."""
    return float(np.clip((START_MU / mu) ** 2, *START_SCALE))


def largest_step(cones, s, z, ds, dz) -> float:
    """The largest step ``<= 1`` that keeps every slack and multiplier in its cone (one
    of ``cones`` each); NaN where a direction has one (Python's ``min`` would drop it
    unless it came first)."""
    return float(np.min([[cone.max_step(sb, dsb), cone.max_step(zb, dzb)]
                         for cone, sb, zb, dsb, dzb in zip(cones, s, z, ds, dz)]))


def _dot(a, b) -> float:
    return float(sum(x.ravel() @ y.ravel() for x, y in zip(a, b)))


def solve(ns: NewtonSystem, options: InteriorOptions) -> Outcome:
    """Solve the scaled QP of ``ns`` (its friction model and ``mu``).

    Returns
    -------
    Outcome
        ``x`` as (IV, width) forces in the columns of ``ns`` (the caller spreads them to
        the full layout), ``y`` the equilibrium multipliers in the Newton method's
        convention (``H x = A^T y - G^T z``); status ``optimal``, ``user_limit`` (the
        last point) or ``solver_error``.
    """
    start = time.perf_counter()
    cones = vertex_cones(ns.components, ns.cone, ns.mu)
    b, h = ns.b, ns.h
    b_inf = np.abs(b).max()
    n_vertices = len(h)
    degree = n_vertices * sum(vc.cone.degree for vc in cones)
    shift = options.regularization * ns.diagonal_scale

    # start (Mehrotra's rule): the least-squares point of
    #   min 1/2 x^T H x + 1/2 ||G x||^2,  A x = b,
    # its slacks s = -G x and multipliers z = G x shifted inside and balanced
    units = [vc.cone.identity(n_vertices) for vc in cones]
    first = _Iterate(ns, cones, units, units, shift)
    zero = [np.zeros_like(u) for u in units]
    x, y, s, z = first.direction(np.zeros_like(h), -b, zero, zero)
    scale = start_scale(ns.mu)
    s, z = centred_start([vc.cone for vc in cones], s, z)
    s, z = [scale * sb for sb in s], [scale * zb for zb in z]
    status, iterations = USER_LIMIT, 0
    for iterations in range(options.max_iter + 1):
        r_dual = h * x - (ns.AT @ y).reshape(x.shape) + sum(zb @ vc.G
                                                           for vc, zb in zip(cones, z))
        r_primal = ns.A @ x.ravel() - b
        r_cone = [x @ vc.G.T + sb for vc, sb in zip(cones, s)]
        gap = _dot(s, z) / degree
        objective = 0.5 * float(np.sum(h * x * x))
        # the dual residual is left out: it grows to 1e-7..1e-5 of the largest
        # multiplier in the last iterations (the weights spread over 20 decades, and
        # dz = W^-2 (G dx + r) loses digits); the points are judged on their recomputed
        # equilibrium and friction residuals, then polished by Newton from y
        if (np.abs(r_primal).max() <= options.tol * b_inf
                and gap * degree <= options.tol * (1.0 + abs(objective))):
            status = OPTIMAL
            break
        if iterations == options.max_iter:
            break
        try:
            point = _Iterate(ns, cones, s, z, shift)
        except np.linalg.LinAlgError as error:
            log.warning("interior point: reduced matrix not positive definite: %s", error)
            status = SOLVER_ERROR
            break
        # predictor (affine scaling), then Mehrotra's corrector with the same factor
        lam_square = [vc.cone.product(sc.lam, sc.lam)
                      for vc, sc in zip(cones, point.scalings)]
        dx, dy, ds, dz = point.direction(r_dual, r_primal, r_cone, lam_square)
        step = largest_step([vc.cone for vc in cones], s, z, ds, dz)
        predicted = _dot([sb + step * d for sb, d in zip(s, ds)],
                         [zb + step * d for zb, d in zip(z, dz)]) / degree
        sigma = (predicted / gap) ** 3
        r_comp = [square + vc.cone.product(sc.times_w_inverse(dsb), sc.times_w(dzb))
                  - sigma * gap * vc.cone.identity(n_vertices)
                  for vc, sc, square, dsb, dzb in zip(cones, point.scalings, lam_square,
                                                      ds, dz)]
        dx, dy, ds, dz = point.direction(r_dual, r_primal, r_cone, r_comp)
        step = options.step_fraction * largest_step([vc.cone for vc in cones], s, z, ds, dz)
        if step < options.min_step:
            log.info("interior point stalled at iteration %d (step %.1e)", iterations, step)
            break
        x, y = x + step * dx, y + step * dy
        s = [sb + step * d for sb, d in zip(s, ds)]
        z = [zb + step * d for zb, d in zip(z, dz)]
        log.debug("interior point %d: residual %.2e, dual %.2e, gap %.2e (objective "
                  "%.2e), step %.3f, sigma %.2e", iterations, np.abs(r_primal).max() / b_inf,
                  np.abs(r_dual).max() / max(1.0, np.abs(h * x).max()), gap, objective,
                  step, sigma)
    return Outcome(status=status, x=x, iterations=iterations, y=y,
                   solve_time=time.perf_counter() - start,
                   info={"factorizations": iterations + 1})


def backend(system, method, options, workspace) -> Outcome:
    """The :mod:`masonry.rbe.solvers` interface: ``options`` are :class:`InteriorOptions`
    fields; the workspace is shared with the Newton backend (its prepared systems and
    their symbolic factorization)."""
    start = time.perf_counter()
    ns = prepared_system(system, method, workspace)
    preparation = time.perf_counter() - start
    outcome = solve(ns, InteriorOptions(**options))
    return dataclasses.replace(outcome, x=ns.full_vector(outcome.x, system.layout),
                               setup_time=preparation)


BACKEND = Backend("interior", settings="interior", rbe=backend, collapse=InteriorProgram,
                  workspace="newton")
"""The interior point methods on the Newton method's matrix: the RBE QP and the collapse
program (every friction model); they share the Newton backend's prepared systems."""
