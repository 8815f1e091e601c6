"""Primal-dual interior point method for the least adhesion, on the Newton method's matrix.

The program of :mod:`masonry.rbe.adhesion` in the shifted vertex forces ``x~_v = (n~,
f1, f2)``, ``n~ = n + a A_v / mu`` (scaled rows and columns of
:mod:`masonry.rbe.equilibrium`; ``A_v`` the vertex's strength per unit ``a``), so that the
cohesion moves the cone's apex and the friction model is the dry one::

    minimize a   subject to   A x~ + a l = b              6 rows per free block
                              G_1 x~_v + s_1v = 0          s_1v in the friction model
                              G_2 x~_v + q_v a + s_2v = 0  s_2v >= 0 (the cut-off)

``l = -A c`` the equilibrium rows' share of the shift (``c_v = (A_v / mu, 0, 0)``); the
friction model's rows ``G_1`` (:func:`~.interior.vertex_cones`: a pyramid's faces, or
Coulomb's cone on ``(mu n~, f1, f2)``); where the tension cut-off lies inside the cone
(``r < 1 / mu``) its row ``n~ - a A_v (1 / mu - r) >= 0``. Every vertex's unknowns meet
only their own cones and the equilibrium rows; ``a`` meets the equilibrium rows and the
cut-off rows.

Eliminating the slacks, their multipliers and ``x~`` from the Newton system of the
perturbed optimality conditions (Nesterov-Todd scalings ``W_b``, :mod:`.cones`) leaves ::

    A D A^T dy - w da = r_y,   w^T dy + sigma da = r_a,
    D_v = (sum_b G_b^T W_bv^-2 G_b)^-1,   w = A D v - l

``A D A^T`` is the Newton method's matrix (one 3 x 3 block ``D_v`` per vertex, six rows
per free block, the same :class:`~.cholesky.BlockCholesky` symbolic analysis, which a
stage sequence already holds); ``a``'s row borders it (a second solve with ``w`` on the
same factor), ``v_v = G_2^T W_2v^-2 q_v`` and ``sigma`` its Schur complement, both in
closed form (:func:`_reduced`). Mehrotra's predictor-corrector (:mod:`.predictor_corrector`,
the form of CVXOPT's ``coneqp``), with iterative refinement of the directions near the
optimum (:attr:`AdhesionOptions.refinements`), from a start that meets the equilibrium
and cone rows (:func:`_cold`).

Why it exists: Clarabel factors the whole KKT system (a row per vertex force and cone
row) at every one of its iterations; this factors the six rows per free block that the
stage's RBE solve factored (docs/bench.md, "The least adhesion of every brick stage").

It assumes a bounded optimum (a structure whose blocks all touch a joint has one,
:mod:`masonry.rbe.adhesion`) and has no infeasibility detection: a program it does not
solve (an infeasible one: no adhesion holds a block that needs tension with ``r = 0``)
ends with status ``user_limit`` and the caller asks Clarabel. Near the optimum the
scalings span 20 decades and the reduced matrix loses its small directions: the last
point within :attr:`AdhesionOptions.reduced` is then the answer (``optimal_inaccurate``,
checked as every other by the caller).
"""

import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.rbe.solvers import predictor_corrector
from masonry.rbe.solvers.base import SOLVER_ERROR
from masonry.rbe.solvers.cones import Orthant
from masonry.rbe.solvers.interior import VertexCone, vertex_cones, vertex_inverse
from masonry.rbe.solvers.newton import NewtonSystem

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class AdhesionOptions:
    """Settings of :func:`solve`.

    Parameters
    ----------
    tol, dual_tol, gap_tol : float
        Stop (status ``optimal``) when the equilibrium and cone rows' residuals relative
        to the largest load are at most ``tol``, the dual rows' at most ``dual_tol``
        (``x~``'s relative to the largest multiplier, ``a``'s to its objective
        coefficient 1) and the gap ``s^T z`` (an upper bound of ``a - a*`` while the
        dual rows hold) at most ``gap_tol`` times ``a`` (``gap_floor`` at least).
    reduced : tuple of float
        ``(tol, dual_tol, gap_tol, gap_floor)`` of a point accepted as
        ``optimal_inaccurate`` where the method cannot go on (a stalled step, a reduced
        matrix that does not factor): near the optimum the scalings span 20 decades and
        the reduced matrix loses its small directions (the point is then checked as
        every other); the gap at most ``gap_tol`` times ``a`` or ``gap_floor``.
    gap_floor : float
        The least ``a`` the gap is relative to (units of ``W_ref / A_ref``).
    max_iter : int
    step_fraction : float
        Fraction of the largest step to the boundary of the cones that is taken.
    regularization : float
        Shift of the reduced matrix relative to its mean diagonal.
    min_step : float
        Stop when a step falls below this.
    refinements, refine_gap : int, float
        Passes of iterative refinement of a direction (CVXOPT's) once the gap is below
        ``refine_gap`` times ``a`` (``gap_floor`` at least): near the optimum ``W^-2``
        amplifies the rounding of ``dx`` in ``dz`` by up to 1e20, and the dual rows are
        lost without them (before, a direction's error is corrected by the next one).
    """

    tol: float = 1e-8
    dual_tol: float = 1e-6
    gap_tol: float = 1e-7
    reduced: tuple = (1e-7, 1e-4, 1e-2, 1e-8)
    gap_floor: float = 1e-6
    max_iter: int = 60
    step_fraction: float = 0.99
    regularization: float = 1e-12
    min_step: float = 1e-6
    refinements: int = 1
    refine_gap: float = 1.0


@dataclass
class Point:
    """An iterate: ``x~`` (V, 3), ``a``, ``y`` (6 F,), per cone ``s`` and ``z`` (lists of
    (V, m) arrays: the friction model's, then the cut-off's where there is one)."""

    x: np.ndarray
    a: float
    y: np.ndarray
    s: list
    z: list


@dataclass(frozen=True)
class Solution:
    """The end of :func:`solve`: ``status`` (``optimal``, ``user_limit``,
    ``solver_error``), the last :class:`Point` (None without one), its physical vertex
    forces ``x`` ((V, 3) ``(n, f1, f2)``) and the iterations."""

    status: str
    point: Point | None
    x: np.ndarray | None
    iterations: int
    time_s: float


CUTOFF = VertexCone(Orthant(1), np.array([[-1.0, 0.0, 0.0]]))
"""The tension cut-off's row: ``-n~ + a A_v (1 / mu - r) + s = 0``, ``s >= 0``."""


class _Program:
    """The program (module docstring) on ``ns``: ``held`` ((V,) float) the strength of
    every vertex per unit ``a``, ``ratio`` the tension cut-off's ``r``."""

    def __init__(self, ns: NewtonSystem, held, ratio, options: AdhesionOptions):
        self.ns, self.held, self.ratio = ns, held, ratio
        self.diagonal_shift = options.regularization * ns.diagonal_scale
        self.gap_floor = options.gap_floor
        self.friction = vertex_cones(ns.components, ns.cone, ns.mu)[0]
        self.shift = held / ns.mu                      # n = n~ - a A_v / mu
        shift = np.zeros((len(held), 3))
        shift[:, 0] = self.shift
        self.load = -(ns.A @ shift.ravel())           # A x = A x~ + a load
        apex = 1.0 / ns.mu - ratio
        self.cutoff = apex * held if apex > 0 else None   # n~ >= a A_v (1 / mu - r)
        self.n = len(held)
        self.cones = [self.friction.cone] + ([CUTOFF.cone] if apex > 0 else [])
        self.degree = self.n * sum(cone.degree for cone in self.cones)

    def residuals(self, p: Point):
        """``(r_x, r_a, r_primal, r_cones)``: the dual rows of ``x~`` and ``a``, the
        equilibrium rows and the cone rows (friction, then cut-off)."""
        ns = self.ns
        r_x = -(ns.AT @ p.y).reshape(p.x.shape) + p.z[0] @ self.friction.G
        r_a = 1.0 - float(self.load @ p.y)
        r_cones = [sb - exact for sb, exact in zip(p.s, self.slacks(p.x, p.a))]
        if self.cutoff is not None:
            r_x = r_x + p.z[1] @ CUTOFF.G
            r_a += float(self.cutoff @ p.z[1][:, 0])
        r_primal = ns.A @ p.x.ravel() + self.load * p.a - ns.b
        return r_x, r_a, r_primal, r_cones

    def measures(self, p: Point, residuals) -> tuple:
        """``(primal, dual, gap)`` of ``p`` (:class:`AdhesionOptions`)."""
        r_x, r_a, r_primal, r_cones = residuals
        b_inf = float(np.abs(self.ns.b).max())
        primal = max(float(np.abs(r_primal).max()),
                     max(float(np.abs(rc).max()) for rc in r_cones)) / b_inf
        dual = max(float(np.abs(r_x).max()) / max(1.0, float(np.abs(p.y).max())), abs(r_a))
        return primal, dual, float(sum(np.sum(sb * zb) for sb, zb in zip(p.s, p.z)))

    @staticmethod
    def objective(p: Point) -> float:
        return p.a

    def iterate_at(self, s, z) -> "_Iterate":
        return _Iterate(self, s, z, self.diagonal_shift)

    def slacks(self, x, a) -> list:
        """The cone rows' slacks of ``(x~, a)``: ``-(G_b x~ + q_b a)``."""
        out = [-(x @ self.friction.G.T)]
        if self.cutoff is not None:
            out.append(-(x @ CUTOFF.G.T) - self.cutoff[:, None] * a)
        return out

    def physical(self, p: Point) -> np.ndarray:
        """(V, 3) the vertex forces ``(n, f1, f2)`` of ``p``'s ``x~``."""
        x = p.x.copy()
        x[:, 0] -= p.a * self.shift
        return x


class _Iterate(predictor_corrector.ConeIterate):
    """The reduced system at one point (module docstring): factored once, solved for the
    predictor and the corrector."""

    def __init__(self, program: _Program, s, z, shift):
        super().__init__(program.cones, s, z)
        self.program, w_inverse = program, self.w_inverse
        ns = program.ns
        self.D, self.Dv, self.sigma = _reduced(program, self.scalings, w_inverse,
                                               self.w2_inverse)
        # v = G_2^T W_2^-2 q: the cut-off's column of a (zero without one)
        self.v = (np.zeros((program.n, 3)) if program.cutoff is None else
                  (self.w2_inverse[1] * program.cutoff[:, None]) @ CUTOFF.G)
        self.factor = _factor(ns, self.D, shift)
        self.w = ns.A @ self.Dv.ravel() - program.load
        self.t = None

    def _bordered(self, rhs_y, rhs_a):
        """``(dy, da)`` with ``N dy - w da = rhs_y`` and ``w^T dy + sigma da = rhs_a``
        (``N`` the factored ``A D A^T``): ``dy = N^-1 rhs_y + da N^-1 w``."""
        if self.t is None:  # w's solve once per factor, with the first right-hand side
            both = self.factor.solve(np.column_stack([rhs_y, self.w]))
            u, self.t = both[:, 0], both[:, 1]
        else:
            u = self.factor.solve(rhs_y)
        da = (rhs_a - float(self.w @ u)) / (self.sigma + float(self.w @ self.t))
        return u + da * self.t, da

    def _left(self, d, target) -> tuple:
        """What ``d`` leaves of the rows it solves: the right-hand side of its
        correction."""
        program, ns = self.program, self.program.ns
        dx, da, dy, ds, dz = d
        r_x, r_a, r_primal, r_cones, q_c = target
        G = [program.friction.G] + ([CUTOFF.G] if program.cutoff is not None else [])
        e_x = -(ns.AT @ dy).reshape(dx.shape) + sum(zb @ g for zb, g in zip(dz, G)) + r_x
        e_a = -float(program.load @ dy) + r_a
        if program.cutoff is not None:
            e_a += float(program.cutoff @ dz[1][:, 0])
        e_primal = ns.A @ dx.ravel() + program.load * da + r_primal
        shifts = [0.0] + ([program.cutoff[:, None]] if program.cutoff is not None else [])
        e_cones = [dx @ g.T + qb * da + dsb + rc
                   for g, qb, dsb, rc in zip(G, shifts, ds, r_cones)]
        e_comp = [sc.times_w_inverse(dsb) + sc.times_w(dzb) - q
                  for sc, dsb, dzb, q in zip(self.scalings, ds, dz, q_c)]
        return e_x, e_a, e_primal, e_cones, [-e for e in e_comp]

    def _solve(self, r_x, r_a, r_primal, r_cones, q_c):
        """The direction for the rows' residuals and ``W^-1 ds + W dz = q_c``."""
        program, ns = self.program, self.program.ns
        cones, cut = program.cones, program.cutoff
        wq = [sc.times_w_inverse(q) for sc, q in zip(self.scalings, q_c)]
        pulled = [wq[b] + self.w2i(b, r_cones[b]) for b in range(len(cones))]
        qx = -r_x - pulled[0] @ program.friction.G
        qa = -r_a
        if cut is not None:
            qx = qx - pulled[1] @ CUTOFF.G
            qa -= float(cut @ pulled[1][:, 0])
        rhs_y = -r_primal - ns.A @ np.einsum("vij,vj->vi", self.D, qx).ravel()
        rhs_a = qa - float(np.sum(self.Dv * qx))
        dy, da = self._bordered(rhs_y, rhs_a)
        dx = np.einsum("vij,vj->vi", self.D,
                       qx - da * self.v + (ns.AT @ dy).reshape(qx.shape))
        dz = [wq[0] + self.w2i(0, r_cones[0] + dx @ program.friction.G.T)]
        if cut is not None:
            dz.append(wq[1] + self.w2i(1, r_cones[1] + dx @ CUTOFF.G.T
                                        + cut[:, None] * da))
        # ds from the cone rows, which keeps them exact (W^2 dz loses their digits)
        ds = [-r_cones[0] - dx @ program.friction.G.T]
        if cut is not None:
            ds.append(-r_cones[1] - dx @ CUTOFF.G.T - cut[:, None] * da)
        return dx, da, dy, ds, dz


def _factor(ns, D, shift):
    """The factor of ``A D A^T + shift I`` (``LinAlgError`` where it fails: near the
    optimum, where the last point within the reduced tolerances is the answer; a raised
    shift there bought no step that counted, at three factorizations)."""
    return ns.symbolic.factor(ns.newton_blocks(D, shift, incremental=False))


def _reduced(program, scalings, w_inverse, w2_inverse) -> tuple:
    """``(D, D v, sigma)``: per vertex ``D = (G_1^T W_1^-2 G_1 + d g g^T)^-1`` (the
    friction rows and the cut-off's ``g`` of weight ``d``), ``D v`` and ``a``'s Schur
    complement ``sigma = v^T ... = alpha - v^T D v``, from ``D_1`` (the friction rows'
    alone) and ``gamma = g^T D_1 g``: ``D = D_1 - d D_1 g g^T D_1 / (1 + d gamma)``,
    ``D g = D_1 g / (1 + d gamma)``, ``sigma = sum_v q_v^2 d / (1 + d gamma)`` (the
    difference of two large sums would cancel). Coulomb's cone has ``D_1 = G_1^-1 W_1^2
    G_1^-T`` (``G_1 = diag(-mu, -1, -1)``); where ``d gamma`` exceeds :data:`STIFF` (an
    active cut-off: the update would cancel) and for a pyramid's faces, ``D`` and ``D_1``
    by QR (:func:`~.interior.vertex_inverse`)."""
    friction = program.friction
    cut = program.cutoff is not None
    if friction.G.shape[0] == 3:       # Coulomb's cone: G_1 invertible
        g_inverse = np.linalg.inv(friction.G)
        D1 = g_inverse @ scalings[0].D @ g_inverse.T
    else:
        D1 = vertex_inverse(np.zeros((program.n, 3)), [friction], w_inverse[:1])
    if not cut:
        return D1, np.zeros((program.n, 3)), 0.0
    d, q = w2_inverse[1][:, 0], program.cutoff
    gamma = D1[:, 0, 0]                                   # g = (-1, 0, 0)
    share = d / (1.0 + d * gamma)
    column = D1[:, :, 0]                                  # -D_1 g
    D = D1 - share[:, None, None] * column[:, :, None] * column[:, None, :]
    stiff = np.flatnonzero((d * gamma > STIFF) | (friction.G.shape[0] != 3))
    if len(stiff):
        D[stiff] = vertex_inverse(np.zeros((len(stiff), 3)), [friction, CUTOFF],
                                  [w[stiff] for w in w_inverse[:2]])
    return D, -(q * share)[:, None] * column, float(np.sum(q * q * share))


STIFF = 1e4
"""``d gamma`` above which a vertex's ``D`` is found by QR rather than the rank-one
update (which loses about ``log10(d gamma)`` of its digits along the cut-off's row)."""


def _cold(program: _Program) -> Point:
    """A start that meets the equilibrium rows and nearly every cone row: the
    least-squares vertex forces of the unit scaling (``A x = b``), with the ``a`` of
    :func:`_least_inside` (a vertex it leaves outside is shifted inside); the
    least-squares multipliers of ``a``'s objective, shifted inside and balanced with the
    slacks (:func:`~.cones.centred_start`'s rule, the slacks kept)."""
    cones = program.cones
    units = [cone.identity(program.n) for cone in cones]
    first = program.iterate_at(units, units)
    zero = [np.zeros_like(u) for u in units]
    x, a, _, _, _ = first.direction(np.zeros((program.n, 3)), 0.0, -program.ns.b, zero, zero)
    _, _, y, _, z = first.direction(np.zeros((program.n, 3)), 1.0,
                                    np.zeros_like(program.ns.b), zero, zero)
    force = program.physical(Point(x, a, y, [], []))
    rms = float(np.sqrt(np.mean(np.sum(force * force, axis=1))))
    margin = predictor_corrector.START_MARGIN * rms
    a = _least_inside(program, force, margin)
    x = force.copy()
    x[:, 0] += a * program.shift                        # x~ of the physical forces
    s, z = predictor_corrector.inside_start(cones, program.slacks(x, a), z, margin)
    return Point(x, a, y, s, z)


START_QUANTILE = 0.9
"""The share of the vertices the starting ``a`` puts inside their cones; the few that
would need more (the least-squares forces' worst) are shifted inside instead, their cone
rows left off: a start at the largest ``a`` took one to three more iterations on preset
1's brick stages (docs/bench.md, "The least adhesion of every brick stage")."""


def _least_inside(program, force, margin) -> float:
    """The least ``a >= 0`` with which the :data:`START_QUANTILE` of the vertices some
    ``a`` helps have their slacks of ``force`` ``margin`` inside their cones."""
    friction, held = program.friction, program.held
    slack = -(force @ friction.G.T)                      # at a = 0
    rate = -friction.G[:, 0][None, :] * program.shift[:, None]   # d slack / d a
    helped = held > 0
    if isinstance(friction.cone, Orthant):
        need = np.max((margin - slack) / np.where(rate > 0, rate, np.inf), axis=1)
    else:  # the second-order cone's least eigenvalue grows by rate[:, 0]
        need = (margin - friction.cone.min_eigenvalue(slack)) / np.where(helped, held, np.inf)
    if program.cutoff is not None:  # n + r A_v a >= margin
        tension = (margin - force[:, 0]) / np.where(helped & (program.ratio > 0),
                                                     program.ratio * held, np.inf)
        need = np.maximum(need, tension)
    need = need[np.isfinite(need)]
    return max(0.0, float(np.quantile(need, START_QUANTILE))) if len(need) else 0.0


def solve(ns: NewtonSystem, held, ratio,
          options: AdhesionOptions = AdhesionOptions()) -> Solution:
    """The least adhesion's program (module docstring) on the friction-net system ``ns``
    (its friction model, ``mu`` and ``b``): ``held`` ((V,) float) every vertex's strength
    per unit ``a``, ``ratio`` ``t_c / c``."""
    begin = time.perf_counter()
    program = _Program(ns, np.asarray(held, dtype=float), ratio, options)
    try:
        p = _cold(program)
    except np.linalg.LinAlgError as error:
        log.warning("least adhesion: reduced matrix not positive definite: %s", error)
        return Solution(SOLVER_ERROR, None, None, 0, time.perf_counter() - begin)
    status, p, iterations = predictor_corrector.iterate(
        program, p, options, (options.tol, options.dual_tol, options.gap_tol,
                              options.gap_tol * options.gap_floor), "least adhesion")
    return Solution(status, p, program.physical(p), iterations, time.perf_counter() - begin)
