"""Primal-dual interior point method for the collapse LP, on the Newton method's matrix.

The collapse LP of :mod:`masonry.rbe.collapse`, in the scaled rows of
:mod:`masonry.rbe.equilibrium`::

    maximize lambda   subject to   M g + lambda l = b,   g in K

``b = -f_dead``, ``l`` the live load, ``M = A T``: ``A`` the equilibrium matrix over the
vertex forces ``(c, f1, f2)`` (the friction-net columns of
:class:`~masonry.rbe.solvers.newton.NewtonSystem`) and ``T`` the map from every vertex's
cone variables ``g`` to its force (:class:`ConeVariables`): for a pyramid, its ``K`` edge
rays (``g >= 0`` their weights), for Coulomb's cone ``diag(1 / mu, 1, 1)`` (``g = (mu c,
f1, f2)`` in the second-order cone). Its dual::

    minimize -b^T y   subject to   s = -M^T y in K,   l^T y = -1

``y`` is the collapse mechanism (a virtual motion of every block) and ``s`` the work of
the vertex forces on it: ``s`` in the (self-dual) cone is the associated flow rule, the
relative motion at every vertex lies in the normal cone of the friction model, so no
interface penetrates.

Mehrotra's predictor-corrector (S. Mehrotra, SIAM J. Optim. 2, 1992; S. Wright,
*Primal-Dual Interior-Point Methods*, SIAM 1997, ch. 10) with separate primal and dual
step lengths and Nesterov-Todd scaling (:mod:`.cones`), and for the pyramids Gondzio's
multiple centrality correctors (J. Gondzio, Comput. Optim. Appl. 6, 1996): a few products
``g s`` far from the target stop the corrector's steps short, and further solves with
the same factor move them back. Every iteration solves the normal equations ::

    M D M^T dy = r,   D = W^2 (diag(g / s) for the rays)

``M D M^T = A (T D T^T) A^T`` has one 3 x 3 block ``T D T^T`` per vertex, so it is the
Newton method's matrix ``A J A^T`` (six rows per free block) with ``J = T D T^T``: the
same :class:`~masonry.rbe.solvers.cholesky.BlockCholesky` symbolic analysis factors it.
The live load's column touches every loaded block; it stays out of the factor
(``lambda`` is eliminated by a second solve with ``l``, a bordered system). A general
interior point solver (Clarabel) factors the whole KKT system instead, one row per
variable and constraint.

It assumes the LP has an optimum: when the dead load cannot stand at any factor, or the
live load is carried at every factor, it ends without one (status ``user_limit``) and
:mod:`masonry.rbe.collapse` asks Clarabel, which detects both.

:class:`InteriorProgram` holds a collapse program (:mod:`masonry.rbe.solvers.program`)
for it: the friction-net Newton system is prepared once per model (its symbolic
factorization serves every load case).
"""

import dataclasses
import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.rbe.solvers.base import OPTIMAL, SOLVER_ERROR, USER_LIMIT, Outcome
from masonry.rbe.solvers.cones import Lorentz, Orthant, centred_start
from masonry.rbe.solvers.newton import NewtonSystem, prepared_system
from masonry.rbe.solvers.program import HeldProgram
from masonry.tolerances import ACCEPT_RESIDUAL

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
        largest load entry) at most ``primal_tol`` (the acceptance tolerance,
        :data:`~masonry.tolerances.ACCEPT_RESIDUAL`). The dual rows stay exact, so
        ``-b^T y`` is an upper bound of the factor (:func:`load_factor` reports it),
        within the gap of the primal one while the primal rows hold. The residual is
        recomputed and reported with every collapse result.
    max_iter : int
        Iterations before the method gives up (Clarabel then decides). The pyramids'
        many edge rays make the LP degenerate and the iterations many (``docs/bench.md``,
        "Friction models").
    step_fraction : float
        Fraction of the largest step to the boundary of the cone that is taken.
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
    primal_tol: float = ACCEPT_RESIDUAL
    max_iter: int = 200
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


class ConeVariables:
    """The LP's unknowns at every vertex and the forces they make: ``x_v = T g_v`` with
    ``g_v`` in :attr:`cone` (module docstring), from the friction model and ``mu`` of the
    friction-net :class:`~masonry.rbe.solvers.newton.NewtonSystem` ``ns``."""

    def __init__(self, ns: NewtonSystem):
        self.ns = ns
        if ns.cone.is_polyhedral:
            self.T = ns.cone.rays(ns.mu)                     # (3, K) edge rays
            self.cone = Orthant(self.T.shape[1])
            self._rays = _RayProducts(ns, self.T)
        else:
            self.T = np.diag([1.0 / ns.mu, 1.0, 1.0])        # g = (mu c, f1, f2)
            self.cone = Lorentz()
            self._rays = None

    @property
    def shape(self) -> tuple:
        """``(IV, m)``: the shape of ``g`` and ``s``."""
        return len(self.ns.h), self.cone.m

    def times_m(self, g) -> np.ndarray:
        """``M g`` ((6 F,)): the loads the cone variables ``g`` ((IV, m)) balance."""
        return self.ns.A @ (g @ self.T.T).ravel()

    def times_mt(self, y) -> np.ndarray:
        """``M^T y`` ((IV, m)): the work of every vertex's unknowns on the motion ``y``."""
        return (self.ns.AT @ y).reshape(-1, 3) @ self.T

    def normal_sums(self, scaling) -> np.ndarray:
        """(K, 144): the interfaces' blocks of ``M W^2 M^T`` (the Newton system's
        :meth:`~masonry.rbe.solvers.newton.NewtonSystem.interface_sums` with ``J_v = T
        W_v^2 T^T``; for the rays, by :class:`_RayProducts`)."""
        if self._rays is not None:
            return self._rays.sums(scaling.d)
        return self.ns.interface_sums(self.T @ scaling.D @ self.T.T)


class _RayProducts:
    """Per interface, ``sum_v C_v E D_v E^T C_v^T`` (12 x 12, ``C_v`` the vertex's
    coefficients in both blocks' rows) for edge ray weights ``D``: one column ``C_v E_k``
    per vertex and ray, the columns of every interface side by side, and the interfaces
    with the same vertex count in one product (the Newton system's
    :attr:`~masonry.rbe.solvers.newton.NewtonSystem.groups`), into buffers kept from call
    to call (fresh ones fault their pages in every time; docs/bench.md, "Measurements
    behind design choices")."""

    def __init__(self, ns: NewtonSystem, rays):
        self.out = np.zeros((ns.n_interfaces, 12, 12))
        self.groups = []
        for faces, vertices, left in ns.groups:
            # (F, 12, n, 3) coefficients times the rays: (F, 12, K n), vertex by vertex
            columns = (left.reshape(len(faces), 12, -1, ns.width) @ rays).reshape(
                len(faces), 12, -1)
            rows = np.ascontiguousarray(columns.transpose(0, 2, 1))
            self.groups.append((faces, vertices, rows, columns, np.empty_like(columns),
                                np.empty((len(faces), 12, 12))))

    def sums(self, d) -> np.ndarray:
        """(K, 144) float: the interfaces' blocks for ``d`` ((IV, K)), valid until the
        next call."""
        for faces, vertices, rows, columns, scaled, product in self.groups:
            weights = d[vertices].reshape(len(faces), 1, -1)
            np.matmul(np.multiply(columns, weights, out=scaled), rows, out=product)
            self.out[faces] = product
        return self.out.reshape(-1, 144)


class _Unit:
    """The scaling ``W = I`` of the starting point (least-norm ``g`` and ``s``)."""

    def __init__(self, shape, cone):
        self.d = np.ones(shape)
        self.D = np.broadcast_to(np.eye(3), (shape[0], 3, 3))
        self.lam = cone.identity(shape[0])

    @staticmethod
    def times_w(v):
        return v

    times_w_inverse = times_w2 = times_w


class _Normal:
    """The normal equations at one interior point: ``K = M W^2 M^T`` factored once, the
    live load's solve ``K^-1 l`` made with the first direction's and kept for the
    others of the iteration."""

    def __init__(self, variables: ConeVariables, scaling, regularization, load):
        ns = variables.ns
        self.variables, self.scaling, self.load = variables, scaling, load
        matrix = ns.scatter_sums(variables.normal_sums(scaling), 0.0)
        diagonal = matrix[ns.diagonal_blocks]
        scale = float(np.mean(np.trace(diagonal, axis1=1, axis2=2))) / 6.0
        # near the optimum W^2 spans many decades and K is singular to working precision
        # where no vertex of a block carries force: a shift relative to K's diagonal,
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

    def direction(self, r_primal, r_dual, r_factor, r_comp):
        """Newton direction for the residuals ``M g + lambda l - b``, ``M^T y + s``,
        ``l^T y + 1`` and the scaled complementarity ``lam o (W^-1 dg + W ds) = -r_comp``:
        ``(dg, dlambda, dy, ds)``."""
        scaling, variables = self.scaling, self.variables
        wq = scaling.times_w(-variables.cone.divide(scaling.lam, r_comp))
        rhs = -r_primal - variables.times_m(wq + scaling.times_w2(r_dual))
        dy, d_factor = self._bordered(rhs, float(r_factor))
        ds = -r_dual - variables.times_mt(dy)
        return wq - scaling.times_w2(ds), d_factor, dy, ds

    def refine(self, direction, r_primal, floor):
        """``direction`` after up to :data:`PRIMAL_PASSES` passes that solve for what it
        leaves of the primal rows (``W^2`` amplifies the errors of ``dy`` in ``dg``), while
        that is above :data:`PASS_RATIO` of their residual and above ``floor``; the
        correction ``W^2 M^T dy'`` keeps the other rows exact."""
        dg, d_factor, dy, ds = direction
        variables = self.variables
        bound = max(PASS_RATIO * np.abs(r_primal).max(), floor)
        for _ in range(PRIMAL_PASSES):
            left = variables.times_m(dg) + d_factor * self.load + r_primal
            if np.abs(left).max() <= bound:
                break
            correction, d_extra = self._bordered(-left, 0.0)
            dy, d_factor = dy + correction, d_factor + d_extra
            correction = variables.times_mt(correction)
            dg, ds = dg + self.scaling.times_w2(correction), ds - correction
        return dg, d_factor, dy, ds

    def _bordered(self, rhs, r_factor):
        """``(dy, dlambda)`` with ``K dy + l dlambda = rhs`` and ``l^T dy = -r_factor``."""
        u = self.solve(rhs)
        d_factor = (float(self.load @ u) + r_factor) / self.lv
        return u - d_factor * self.v, d_factor


def _start(variables, load, regularization):
    """Mehrotra's starting point: the least-norm ``g`` with ``M g = b`` (``lambda = 0``),
    the least-norm dual slacks ``s = -M^T y`` with ``l^T y = -1``, both shifted inside
    the cone and balanced (:func:`centred_start`)."""
    unit = _Normal(variables, _Unit(variables.shape, variables.cone), regularization, load)
    g = variables.times_mt(unit.solve(variables.ns.b))
    y = -unit.v / unit.lv
    (g,), (s,) = centred_start([variables.cone], [g], [-variables.times_mt(y)])
    return g, y, s


def load_factor(ns: NewtonSystem, load, options: LoadFactorOptions, *, rhs=None,
                stop=None) -> Outcome:
    """The largest ``lambda`` of the collapse LP (module docstring) on the friction-net
    system ``ns`` (its friction model and ``mu``), for the live load ``load`` ((6 F,)
    float, scaled rows).

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
    Outcome
        ``x`` the vertex forces ``T g`` ((IV, 3): ``c, f1, f2``, scaled), ``y`` the
        mechanism (the equilibrium rows' multipliers), ``info["load_factor"]`` and
        ``info["dual_bound"]`` (``-b^T y``: with exact dual rows, an upper bound of the
        factor); status ``optimal``, ``user_limit`` (no optimum found: see the module
        docstring) or ``solver_error``.
    """
    start = time.perf_counter()
    if rhs is not None:
        ns = ns.with_rhs(rhs)
    load = np.asarray(load, dtype=float)
    variables = ConeVariables(ns)
    scale = max(np.abs(ns.b).max(), np.abs(load).max())
    g, y, s = _start(variables, load, options.regularization)
    factor, status, iterations, stopped = 0.0, USER_LIMIT, 0, False
    for iterations in range(options.max_iter + 1):
        residuals = _residuals(variables, load, g, y, s, factor)
        if stop is not None and stop(factor, g, y):
            stopped = True
            break
        if _converged(residuals, g, s, factor, scale, options):
            status = OPTIMAL
            break
        if iterations == options.max_iter:
            break
        try:
            normal = _Normal(variables, variables.cone.scaling(g, s),
                             options.regularization, load)
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
    return Outcome(status=status, x=g @ variables.T.T, iterations=iterations, y=y,
                   solve_time=time.perf_counter() - start,
                   info={"factorizations": iterations + 1, "load_factor": factor,
                         "dual_bound": -float(ns.b @ y), "stopped": stopped,
                         "cone_variables": g})


def _residuals(variables, load, g, y, s, factor):
    """``(M g + lambda l - b, M^T y + s, l^T y + 1, |M^T y|_inf)``."""
    mty = variables.times_mt(y)
    return (variables.times_m(g) + factor * load - variables.ns.b, mty + s,
            float(load @ y) + 1.0, float(np.abs(mty).max()))


def _converged(residuals, g, s, factor, scale, options) -> bool:
    r_primal, r_dual, r_factor, dual_scale = residuals
    tol = options.tol
    return (np.abs(r_primal).max() <= options.primal_tol * scale
            and np.abs(r_dual).max() <= tol * max(dual_scale, 1.0)
            and abs(r_factor) <= tol
            and float(g.ravel() @ s.ravel()) <= tol * (1.0 + abs(factor)))


def _mehrotra(normal, residuals, g, s, floor, options):
    """Predictor (affine scaling), Mehrotra's corrector and, on the orthant, Gondzio's
    centrality correctors, all with the same factor: ``((primal step, dual step), (dg,
    dlambda, dy, ds))``."""
    cone, scaling = normal.variables.cone, normal.scaling
    count = len(g) * cone.degree
    gap = float(g.ravel() @ s.ravel()) / count
    lam_square = cone.product(scaling.lam, scaling.lam)
    dg, _, _, ds = normal.direction(*residuals, lam_square)
    primal, dual = _steps(cone, g, s, dg, ds)
    predicted = float((g + primal * dg).ravel() @ (s + dual * ds).ravel()) / count
    target = (predicted / gap) ** 3 * gap
    r_comp = (lam_square + cone.product(scaling.times_w_inverse(dg), scaling.times_w(ds))
              - target * cone.identity(len(g)))
    direction = normal.direction(*residuals, r_comp)
    steps = _steps(cone, g, s, direction[0], direction[3])
    log.debug("  affine %.3f %.3f sigma %.2e, corrector %.3f %.3f", primal, dual,
              target / gap, *steps)
    if isinstance(cone, Orthant):
        direction = _centrality_correctors(normal, residuals, g, s, r_comp, target,
                                           direction, steps, options.correctors)
    direction = normal.refine(direction, residuals[0], floor)
    steps = _steps(cone, g, s, direction[0], direction[3])
    return tuple(options.step_fraction * step for step in steps), direction


def _centrality_correctors(normal, residuals, g, s, r_comp, target, direction, steps,
                           count):
    """Gondzio's correctors of ``direction`` (complementarity residual ``r_comp``,
    ``steps``): each moves the products ``g s`` of the point that a longer step would
    reach into ``[BOX[0], BOX[1]] x target``, and is kept while it lengthens the
    shorter step by :data:`ACCEPT` x :data:`ASPIRATION` at least."""
    cone = normal.variables.cone
    for _ in range(count):
        aspired = [min(1.0, step + ASPIRATION) for step in steps]
        products = (g + aspired[0] * direction[0]) * (s + aspired[1] * direction[3])
        push = np.clip(products, BOX[0] * target, BOX[1] * target) - products
        push = np.maximum(push, -BOX[1] * target)
        trial = normal.direction(*residuals, r_comp - push)
        trial_steps = _steps(cone, g, s, trial[0], trial[3])
        log.debug("  centrality corrector %.3f %.3f", *trial_steps)
        if min(trial_steps) < min(steps) + ACCEPT * ASPIRATION:
            return trial if min(trial_steps) > min(steps) else direction
        direction, steps, r_comp = trial, trial_steps, r_comp - push
    return direction


def _steps(cone, g, s, dg, ds):
    """The largest steps ``<= 1`` that keep ``g`` and ``s`` in the cone."""
    return cone.max_step(g, dg), cone.max_step(s, ds)


class InteriorProgram(HeldProgram):
    """A collapse program solved by :func:`load_factor`: the load columns combined by the
    costs (a lateral direction: ``cos, sin``) into one live load, on the friction-net
    Newton system of the program's model (prepared once in the workspace). It assumes an
    optimum: without one the outcome's status is not ``optimal`` and
    :meth:`stands_unloaded` says None; the caller then asks a backend that tells which
    (:mod:`masonry.rbe.collapse`).

    Raises
    ------
    ValueError
        Columns at a fixed friction capacity: it states the friction model at ``mu c``.
    """

    def __init__(self, program, workspace):
        super().__init__(program, workspace)
        if not program.columns.is_friction_model:
            raise ValueError("the interior point method states the friction model at mu c "
                             "only: a fixed friction capacity needs clarabel")
        self.ns = prepared_system(program.system, "net", workspace)
        self.cost = np.asarray(program.cost, dtype=float)

    def solve(self) -> Outcome:
        outcome = load_factor(self.ns, self.program.loads @ self.cost, LoadFactorOptions())
        return dataclasses.replace(
            outcome, x=self.ns.full_vector(outcome.x, self.program.system.layout))

    def stands_unloaded(self) -> bool | None:
        """The feasible factors are an interval: ``lambda = 0`` lies in it when the
        largest factor of the reversed load is also at least 0."""
        reversed_load = load_factor(self.ns, -(self.program.loads @ self.cost),
                                    LoadFactorOptions())
        if reversed_load.status == OPTIMAL:
            return reversed_load.info["load_factor"] >= 0
        return None

    def direct(self, cos, sin):
        self.cost = np.array([cos, sin])
