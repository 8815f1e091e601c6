"""Primal-dual interior point method for the centering force, on the Newton method's matrix.

The program of :mod:`masonry.rbe.centering` in the scaled rows and columns of
:mod:`masonry.rbe.equilibrium` (the friction-net columns ``x_v = (c, f1, f2)``; with a
mortar ``c`` is the shifted compression, so the friction model is the dry one)::

    minimize sum_j tau_j  subject to  A x + B u = b                6 rows per free block
                                      G_1 x_v + s_1v = 0           s_1v in the friction model
                                      -c_v + s_2v = -l_v           s_2v >= 0 (a cut-off's floor)
                                      -(tau_j, u_j) + s_3j = 0     s_3j in the 4-d Lorentz cone

``u_j`` the force the support gives free block ``j`` at its centroid, ``B`` puts it into
the block's three force rows. Every vertex's unknowns meet only their own cones and the
equilibrium rows, every block's ``(tau_j, u_j)`` only its cone and its own force rows.

Eliminating the slacks, their multipliers, ``x`` and ``(tau, u)`` from the Newton system
of the perturbed optimality conditions (Nesterov-Todd scalings ``W_b``, :mod:`.cones`)
leaves ::

    (A D A^T + B E B^T) dy = r,   D_v = (rho H_v + sum_b G_b^T W_bv^-2 G_b)^-1,   E_j = (W_3j^2)_uu

``A D A^T`` is the Newton method's matrix (one 3 x 3 block ``D_v`` per vertex, the same
:class:`~.cholesky.BlockCholesky` symbolic analysis, which a stage sequence holds);
``B E B^T`` adds a 3 x 3 block to the force rows of each free block's diagonal block, so
the pattern is the same. ``rho H`` (``H`` the friction-net QP's diagonal,
:attr:`CenteringOptions.proximal` ``rho``) is a primal regularization: the Hessian of
``rho / 2 ||x - x_k||_H^2`` about the iterate ``x_k``, whose gradient there is zero, so
the rows and the optimum are the program's and only the direction is damped; near the
optimum (``refine_gap``) iterative refinement on the unregularized rows takes the
damping out again where it converges.
Without it ``D_v`` of a vertex strictly inside its cone grows as its slack over its
multiplier, without bound, and near the optimum ``A D A^T`` spans more decades than a
factorization keeps. Mehrotra's predictor-corrector (:mod:`.predictor_corrector`,
shared with :mod:`.interior_adhesion`) from a start that meets the equilibrium rows
(:func:`_cold`). The multipliers of the supports' cones, and of Coulomb's cone (``G_1``
invertible) where a vertex's multiplier outweighs its slack (``W^2`` small), come from
their dual rows and their slacks from the complementarity; the others' slacks from the
cone rows and multipliers through ``W^-2``: ``W^-2 (W^2 v)`` of a cone near its apex
keeps no digit of ``v`` (the dual rows were lost in the last iterations), ``W^2 (W^-2
v)`` likewise the other way (the cone rows were).

Why it exists: Clarabel factors the whole KKT system (a row per vertex force, cone row
and support component) at every one of its iterations; this factors the six rows per
free block that the stage's RBE solve factored (docs/bench.md, "Construction stages
brick by brick").

The program always has an optimum (every block held by its own weight is a feasible
point, and the objective is at least 0), so there is no infeasibility detection. Near
the optimum the scalings span many decades and the reduced matrix may stop factoring:
the last point within :attr:`CenteringOptions.reduced` is then the answer
(``optimal_inaccurate``, checked by the caller as every other).
"""

import logging
import time
from dataclasses import dataclass

import numpy as np

from masonry.rbe.solvers import predictor_corrector
from masonry.rbe.solvers.base import SOLVER_ERROR
from masonry.rbe.solvers.cones import Lorentz, Orthant
from masonry.rbe.solvers.interior import VertexCone, vertex_cones, vertex_inverse
from masonry.rbe.solvers.newton import NewtonSystem

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class CenteringOptions:
    """Settings of :func:`solve`.

    Parameters
    ----------
    tol, dual_tol : float
        Stop (status ``optimal``) when the equilibrium and cone rows' residuals relative
        to the largest load are at most ``tol`` and the dual rows' relative to the
        largest multiplier (at least 1, the objective's coefficients) at most
        ``dual_tol``,
    gap_tol, gap_floor : float
        and the gap ``s^T z`` (an upper bound of the objective's excess over the
        optimum while the dual rows hold) at most ``gap_tol`` times the objective or
        ``gap_floor`` (units of the mean block weight), the larger.
    reduced : tuple of float
        ``(tol, dual_tol, gap_tol, gap_floor)`` of a point accepted as
        ``optimal_inaccurate`` where the method cannot go on (a stalled step, a reduced
        matrix that does not factor): its total is then within ``gap_tol`` of itself or
        ``gap_floor`` of the mean block weight of the optimum, its rows within the
        acceptance tolerance the caller checks them to.
    max_iter : int
        Iterations before the method gives up (Clarabel then answers): preset 1's
        cyclic section with ``p`` 27 meets the reduced tolerance at about the 75th.
    step_fraction : float
        Fraction of the largest step to the boundary of the cones that is taken (at
        0.99 the iterates of preset 1's upper brick stages lost their centring near the
        optimum and stalled, the pure centring step itself at 0.02).
    regularization, min_step : float
        The reduced matrix's shift relative to its mean diagonal; the step below which
        the method stops.
    proximal : float
        ``rho`` of the primal regularization (module docstring), relative to the
        friction-net QP's diagonal ``H``. Without it the method stalled near the optimum
        of preset 1's large cyclic sections as its dual rows' residual grew, at gaps of
        1e-3 to 2e-2 of the objective, and Clarabel ended almost solved at its iteration
        limit; with 1e-8 it ends within the reduced tolerance, within 2e-5 of Clarabel's
        points; 1e-4 damps too much (``docs/bench.md``, "How time and memory grow").
    refinements, refine_gap : int, float
        Passes of iterative refinement of a direction (CVXOPT's) once the gap is below
        ``refine_gap`` times the objective (or ``gap_floor``): near the optimum the
        scalings span many decades, and a direction that leaves a row unsolved by more
        than the row's tolerance stalls the method (one pass left preset 1's free web
        2e-5 of the reference weight from the optimum, three 2e-6). On preset 1's full
        dome at mu 0.1 three left the dual rows at 1e-5 to 1.4e-5 two iterations before
        the method stalls (a gap of 5e-5 of the objective), at the reduced tolerance, so
        that rounding decided between this method's point and Clarabel's seven times
        longer solve; six leave them at 8e-9 there.
    """

    tol: float = 1e-8
    dual_tol: float = 1e-6
    gap_tol: float = 1e-7
    gap_floor: float = 1e-6
    reduced: tuple = (1e-5, 1e-5, 1e-4, 1e-5)
    max_iter: int = 100
    step_fraction: float = 0.95
    regularization: float = 1e-10
    min_step: float = 1e-6
    proximal: float = 1e-8
    refinements: int = 6
    refine_gap: float = 1e-2


@dataclass
class Point:
    """An iterate: ``x`` (V, 3), ``w`` (F, 4) the ``(tau_j, u_j)``, ``y`` (6 F,), per cone
    ``s`` and ``z`` (lists: the friction model's (V, m), the cut-off's (V, 1) where there
    is one, the supports' (F, 4))."""

    x: np.ndarray
    w: np.ndarray
    y: np.ndarray
    s: list
    z: list


@dataclass(frozen=True)
class Solution:
    """The end of :func:`solve`: ``status`` (``optimal``, ``optimal_inaccurate``,
    ``user_limit``, ``solver_error``), the vertex forces ``x`` ((V, 3) in the columns of
    the Newton system), the supports' forces ``support`` ((F, 3), units of the mean block
    weight; None without a point) and the iterations."""

    status: str
    x: np.ndarray | None
    support: np.ndarray | None
    iterations: int
    time_s: float


CUTOFF = VertexCone(Orthant(1), np.array([[-1.0, 0.0, 0.0]]))
"""A tension cut-off's row: ``-c + s = -l``, ``s >= 0``."""

SUPPORT = Lorentz(4)
"""A free block's ``(tau_j, u_j)``: ``||u_j|| <= tau_j``."""


class _Program:
    """The program (module docstring) on ``ns``, as :func:`.predictor_corrector.iterate`
    takes it; ``diagonal_shift`` the reduced matrix's."""

    def __init__(self, ns: NewtonSystem, options: CenteringOptions):
        self.ns = ns
        self.diagonal_shift = options.regularization * ns.diagonal_scale
        self.proximal_h = options.proximal * ns.h  # rho H, the diagonal of the damping
        self.gap_floor = options.gap_floor
        self.friction = vertex_cones(ns.components, ns.cone, ns.mu)[0]
        self.vertex = [self.friction] + ([CUTOFF] if ns.floor is not None else [])
        self.cones = [vc.cone for vc in self.vertex] + [SUPPORT]
        # Coulomb's cone: G_1 invertible, the dual rows give its dz (_Iterate._solve)
        self.square = (np.linalg.inv(self.friction.G) if self.friction.G.shape[0] == 3
                       else None)
        self.n, self.blocks = len(ns.h), len(ns.b) // 6
        self.degree = self.n * sum(vc.cone.degree for vc in self.vertex) + self.blocks
        # the blocks no joint touches: their moment rows are empty, a unit keeps them
        # out of the factorization
        rows = np.bincount(ns.A.indices, minlength=len(ns.b)).reshape(-1, 6)
        self.untouched = np.flatnonzero((rows == 0).all(axis=1))
        self.cost = np.zeros((self.blocks, 4))
        self.cost[:, 0] = 1.0

    def residuals(self, p: Point):
        """``(r_x, r_w, r_primal, r_cones)``: the dual rows of ``x`` and ``w``, the
        equilibrium rows and the cone rows (friction, cut-off, supports)."""
        ns = self.ns
        r_x = -(ns.AT @ p.y).reshape(p.x.shape)
        for vc, zb in zip(self.vertex, p.z):
            r_x = r_x + zb @ vc.G
        r_w = self.cost - p.z[-1]
        r_w[:, 1:] -= p.y.reshape(-1, 6)[:, :3]
        r_primal = ns.A @ p.x.ravel() - ns.b
        r_primal.reshape(-1, 6)[:, :3] += p.w[:, 1:]
        r_cones = [sb - exact for sb, exact in zip(p.s, self.slacks(p.x, p.w))]
        return r_x, r_w, r_primal, r_cones

    def measures(self, p: Point, residuals) -> tuple:
        """``(primal, dual, gap)`` of ``p`` (:class:`CenteringOptions`)."""
        r_x, r_w, r_primal, r_cones = residuals
        b_inf = max(float(np.abs(self.ns.b).max()), 1.0)
        primal = max(float(np.abs(r_primal).max()),
                     max(float(np.abs(rc).max()) for rc in r_cones)) / b_inf
        dual = max(float(np.abs(r_x).max()), float(np.abs(r_w).max())) \
            / max(1.0, float(np.abs(p.y).max()))
        return primal, dual, float(sum(np.sum(sb * zb) for sb, zb in zip(p.s, p.z)))

    @staticmethod
    def objective(p: Point) -> float:
        return float(p.w[:, 0].sum())

    def iterate_at(self, s, z) -> "_Iterate":
        return _Iterate(self, s, z, self.diagonal_shift)

    def slacks(self, x, w) -> list:
        """The cone rows' slacks of ``(x, w)``: ``h - G (x, w)``."""
        out = [-(x @ self.friction.G.T)]
        if self.ns.floor is not None:
            out.append(x[:, :1] - self.ns.floor[:, None])
        return out + [w.copy()]


class _Iterate(predictor_corrector.ConeIterate):
    """``A D A^T + B E B^T`` at one point (module docstring), factored once for the
    predictor and the corrector."""

    def __init__(self, program: _Program, s, z, shift):
        super().__init__(program.cones, s, z)
        ns, w_inverse = program.ns, self.w_inverse
        self.program = program
        self.D = vertex_inverse(program.proximal_h, program.vertex, w_inverse[:-1])
        self.E = self.scalings[-1].D                       # W_3^2, (F, 4, 4)
        # the vertices whose friction slack outweighs its multiplier (W^2 large): their
        # dz from the cone rows, the others' from the dual rows (_solve)
        self.slack = np.linalg.norm(s[0], axis=1) > np.linalg.norm(z[0], axis=1)
        blocks = ns.newton_blocks(self.D, shift, incremental=False)
        diagonal = ns.diagonal_blocks
        blocks[diagonal, :3, :3] += self.E[:, 1:, 1:]
        blocks[diagonal[program.untouched], 3:, 3:] += np.eye(3)
        self.factor = ns.symbolic.factor(blocks)

    def _left(self, d, target) -> tuple:
        """What ``d`` leaves of the rows it solves: the right-hand side of its
        correction."""
        program, ns = self.program, self.program.ns
        dx, dw, dy, ds, dz = d
        r_x, r_w, r_primal, r_cones, q_c = target
        e_x = r_x - (ns.AT @ dy).reshape(dx.shape)
        for vc, dzb in zip(program.vertex, dz):
            e_x = e_x + dzb @ vc.G
        e_w = r_w - dz[-1]
        e_w[:, 1:] -= dy.reshape(-1, 6)[:, :3]
        e_primal = ns.A @ dx.ravel() + r_primal
        e_primal.reshape(-1, 6)[:, :3] += dw[:, 1:]
        e_cones = [dx @ vc.G.T + dsb + rc for vc, dsb, rc in zip(program.vertex, ds, r_cones)]
        e_cones.append(ds[-1] - dw + r_cones[-1])
        e_comp = [sc.times_w_inverse(dsb) + sc.times_w(dzb) - q
                  for sc, dsb, dzb, q in zip(self.scalings, ds, dz, q_c)]
        return e_x, e_w, e_primal, e_cones, [-e for e in e_comp]

    def _solve(self, r_x, r_w, r_primal, r_cones, q_c):
        """The direction for the rows' residuals and ``W^-1 ds + W dz = q_c``."""
        program, ns = self.program, self.program.ns
        wq = [sc.times_w_inverse(q) for sc, q in zip(self.scalings, q_c)]
        pulled = [wq[b] + self.w2i(b, r_cones[b]) for b in range(len(program.cones))]
        qx = -r_x
        for vc, pb in zip(program.vertex, pulled):
            qx = qx - pb @ vc.G
        qw = pulled[-1] - r_w                              # G_3 = -I
        rhs = -r_primal - ns.A @ np.einsum("vij,vj->vi", self.D, qx).ravel()
        rhs.reshape(-1, 6)[:, :3] -= np.einsum("fij,fj->fi", self.E[:, 1:], qw)
        dy = self.factor.solve(rhs)
        pushed = (ns.AT @ dy).reshape(qx.shape)
        dx = np.einsum("vij,vj->vi", self.D, qx + pushed)
        ds, dz = [], []
        for b, vc in enumerate(program.vertex):
            ds.append(-r_cones[b] - dx @ vc.G.T)     # from the cone rows: keeps them exact
            dz.append(wq[b] + self.w2i(b, r_cones[b] + dx @ vc.G.T))
        if program.square is not None:  # Coulomb's cone: its dz from the dual rows
            rest = pushed - r_x - program.proximal_h * dx
            for vc, dzb in zip(program.vertex[1:], dz[1:]):
                rest = rest - dzb @ vc.G
            scaling, keep = self.scalings[0], self.slack[:, None]
            dual = rest @ program.square
            dz[0] = np.where(keep, dz[0], dual)
            ds[0] = np.where(keep, ds[0], scaling.times_w(q_c[0]) - scaling.times_w2(dual))
        # the supports' from their dual rows and the complementarity: W^-2 (W^2 v) of
        # a support at the apex or on the boundary loses every digit of v
        dz_w = r_w.copy()
        dz_w[:, 1:] -= dy.reshape(-1, 6)[:, :3]
        scaling = self.scalings[-1]
        ds.append(scaling.times_w(q_c[-1]) - scaling.times_w2(dz_w))
        dz.append(dz_w)
        return dx, ds[-1] + r_cones[-1], dy, ds, dz


def _cold(program: _Program) -> Point:
    """A start that meets the equilibrium rows and nearly every cone row: the
    least-squares forces of the unit scaling (``A x + B u = b``), each support's
    ``tau_j`` :data:`START_MARGIN` above ``||u_j||``, a vertex outside its cones shifted
    inside; the least-squares multipliers of the objective, shifted inside and balanced
    with the slacks (:func:`~.cones.centred_start`'s rule, the slacks kept)."""
    cones, ns = program.cones, program.ns
    units = [cone.identity(program.n) for cone in cones[:-1]] + [
        SUPPORT.identity(program.blocks)]
    first = program.iterate_at(units, units)
    zero = [np.zeros_like(u) for u in units]
    x, w, _, _, _ = first.direction(np.zeros((program.n, 3)), np.zeros_like(program.cost),
                                    -ns.b, zero, zero)
    _, _, y, _, z = first.direction(np.zeros((program.n, 3)), program.cost,
                                    np.zeros_like(ns.b), zero, zero)
    rows = np.concatenate([x, w[:, 1:]])
    rms = float(np.sqrt(np.mean(np.sum(rows * rows, axis=1))))
    margin = predictor_corrector.START_MARGIN * max(rms, 1e-3)
    w[:, 0] = np.linalg.norm(w[:, 1:], axis=1) + margin
    s, z = predictor_corrector.inside_start(cones, program.slacks(x, w), z, margin)
    return Point(x, w, y, s, z)



def solve(ns: NewtonSystem, options: CenteringOptions = CenteringOptions()) -> Solution:
    """The centering force's program (module docstring) on the friction-net system
    ``ns`` (its friction model, ``mu``, cut-off floor and ``b``)."""
    begin = time.perf_counter()
    program = _Program(ns, options)
    try:
        p = _cold(program)
    except np.linalg.LinAlgError as error:
        log.warning("centering force: reduced matrix not positive definite: %s", error)
        return Solution(SOLVER_ERROR, None, None, 0, time.perf_counter() - begin)
    status, p, iterations = predictor_corrector.iterate(
        program, p, options,
        (options.tol, options.dual_tol, options.gap_tol, options.gap_floor), "centering force")
    return Solution(status, p.x, p.w[:, 1:], iterations, time.perf_counter() - begin)
