"""The centering force: the least force temporary supports must give the blocks of a
structure (or of a construction stage) so that it stands (docs/model.md 6.10).

With the scaled matrices of :mod:`masonry.rbe.equilibrium` (``A_eq``, ``f_ext`` the self
weight) and a support force ``s_j`` on every free block ``j``, acting at its centroid::

    minimize    sum_j ||s_j||_2
    subject to  A_eq E g + B s = -f_ext          6 rows per free block
                g in K                          every vertex's friction model, t = 0

``x = E g`` are the vertex forces ``(c, 0, f1, f2)``: no tension, the friction within the
model at ``mu c`` (the columns of the collapse program,
:func:`masonry.rbe.collapse.friction_columns`: Coulomb's cone as a second-order cone in
``(mu c, f1, f2)``, a pyramid by its edge ray weights ``g >= 0``). ``B`` puts ``s_j``
(three components, global axes, the force the support gives the block) into the force
rows of block ``j`` and nothing into its moment rows: a force through the centroid has
no moment about it. The epigraph ``(tau_j, s_j)`` in a four-dimensional second-order
cone states ``||s_j|| <= tau_j``; the objective is ``sum tau_j``.

The support force acts at the centroid because that is the simplest sound model of a
prop or a hand holding a brick: it needs no choice of a contact point, its direction is
free (a prop that pushes, a hand that pulls or holds), and it can neither add a moment
nor lengthen a lever. A force at the best point of a face could hold a tipping brick with
less (a longer lever); at the centroid the answer does not depend on where a prop is put.

The Euclidean norm is the physical one (a support gives one force, whatever the axes);
``sum |s|_1`` would depend on how the model is turned. The program is a second-order cone
program whatever the friction model. The project's interior point method solves it on
the Newton method's matrix (:mod:`masonry.rbe.solvers.interior_centering`: six rows per
free block, the supports' cones adding a 3 x 3 block to each block's force rows), on the
symbolic factorization a stage sequence already holds; Clarabel solves it on the sparse
matrices (:func:`masonry.rbe.solvers.direct_clarabel.solve_cone_program`) where that
ends without a point that passes the check below, or alone when asked (``solver``). The
program is always feasible (every block held by its own weight, no joint loaded) and
bounded below by 0: it has an optimum, and a structure stands without support exactly
when it is 0.

Scaling: as the RBE's, forces in units of the reference weight ``W_ref``, moment rows
divided by ``L_ref``; the result is in newtons. The equilibrium residual and the friction
violation are recomputed from the returned point, as every outcome's.
"""

import logging
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from masonry.contact import ContactLaw
from masonry.errors import ParameterError
from masonry.friction import FrictionCone
from masonry.rbe.collapse import friction_columns
from masonry.rbe.equilibrium import EquilibriumSystem, assemble
from masonry.rbe.solvers import interior_centering
from masonry.rbe.solvers.base import OPTIMAL, OPTIMAL_INACCURATE
from masonry.rbe.solvers.direct_clarabel import CENTERING_SETTINGS, solve_cone_program
from masonry.rbe.solvers.newton import NewtonSystem
from masonry.rbe.solvers.program import SECOND_ORDER
from masonry.tolerances import ACCEPT_RESIDUAL, CENTERING_REPORTED_REL, G

log = logging.getLogger(__name__)

SOLVER = "clarabel"
INTERIOR = "interior"
SOLVERS = (INTERIOR, SOLVER)
"""The solvers of the program: the own interior point method (default; Clarabel where it
ends without a checked optimum), or Clarabel alone (module docstring)."""

RESULT_KEYS = ("total_N", "fraction", "weight_N", "held_count", "status", "solver",
               "iterations", "time_s", "residual_eq", "friction_violation", "mu",
               "friction_model", "point", "contact_law")
"""Scalar fields of :class:`CenteringResult` in run.json, in order (then ``held``)."""


@dataclass(frozen=True, eq=False)
class CenteringResult:
    """The least support force a structure needs (module docstring). Forces in newtons.

    Parameters
    ----------
    total_N : float or None
        ``sum_j ||s_j||``; None when the program was not solved (``status`` says why).
    weight_N : float
        The weight of the free blocks.
    block : (F,) int
        The free blocks of the model the program was stated on, in its rows' order.
    block_weight : (F,) float
        Their weights, N.
    force : (F, 3) float or None
        ``s_j``, the force the support gives each of them (global axes), N.
    status : str
        ``optimal`` or the solver's words.
    iterations : int
    time_s : float, s
        Assembly of the program and its solve.
    solver : str
        The solver whose point this is (:data:`SOLVERS`).
    residual_eq : float
        ``||A_eq x + f_ext + B s||_inf / ||f_ext||_inf``, recomputed (scaled rows).
    friction_violation : float
        The largest excess of a vertex force over its friction model at ``mu c`` (or of
        ``-c``), per reference weight, recomputed.
    mu : float
    cone : FrictionCone
    x : (4 IV,) float or None
        The vertex forces ``(c, 0, f1, f2)``, newtons, in the layout's order; with mortar
        ``c`` is the normal force (negative where the mortar holds in tension).
    law : ContactLaw
        The contact law (:mod:`masonry.contact`).
    """

    total_N: float | None
    weight_N: float
    block: np.ndarray
    block_weight: np.ndarray
    force: np.ndarray | None
    status: str
    iterations: int
    time_s: float
    residual_eq: float
    friction_violation: float
    mu: float
    cone: FrictionCone
    x: np.ndarray | None = None
    solver: str = INTERIOR
    point: str = "centroid"
    law: ContactLaw = ContactLaw()

    @property
    def contact_law(self) -> str:
        """The contact law in one line (:meth:`~masonry.contact.ContactLaw.describe`)."""
        return self.law.describe()

    @property
    def fraction(self) -> float | None:
        """``total_N`` over the weight of the free blocks."""
        return None if self.total_N is None else self.total_N / self.weight_N

    @property
    def friction_model(self) -> str:
        return self.cone.name

    @property
    def magnitude(self) -> np.ndarray:
        """(F,) float: ``||s_j||``, N (zeros without a solution)."""
        if self.force is None:
            return np.zeros(len(self.block))
        return np.linalg.norm(self.force, axis=1)

    @property
    def held(self) -> np.ndarray:
        """(k,) int: the rows (of :attr:`block`) of the blocks that need a support, whose
        force exceeds :data:`~masonry.tolerances.CENTERING_REPORTED_REL` of their own
        weight, largest first."""
        magnitude = self.magnitude
        rows = np.flatnonzero(magnitude > CENTERING_REPORTED_REL * self.block_weight)
        return rows[np.argsort(-magnitude[rows], kind="stable")]

    @property
    def held_count(self) -> int:
        return len(self.held)

    def held_forces(self, source=None) -> list:
        """The held blocks, largest first, as ``(block, force (3,) float, size)``:
        ``block`` a model block, or ``source[block]`` (e.g. a stage's
        :attr:`~masonry.rbe.boundary.Model.block_source`: the scene's block)."""
        rows = self.held
        blocks = self.block[rows] if source is None else np.asarray(source)[self.block[rows]]
        return [(int(b), self.force[r], float(m))
                for b, r, m in zip(blocks, rows, self.magnitude[rows])]

    def to_dict(self, names) -> dict:
        """Plain values for run.json: :data:`RESULT_KEYS` and ``held``, every block that
        needs a support, largest first (``names`` per model block), with its force vector
        and size, newtons."""
        out = {}
        for key in RESULT_KEYS:
            value = getattr(self, key)
            out[key] = value.item() if isinstance(value, np.generic) else value
        out["held"] = [{"block": block, "name": str(names[block]),
                        "force_N": [float(v) for v in force], "support_N": size}
                       for block, force, size in self.held_forces()]
        return out


def centering_force(model, *, mu=0.7, density=2000.0, cone="circle",
                    time_limit=600.0, cohesion=0.0, tensile=0.0,
                    solver=INTERIOR) -> CenteringResult:
    """The least total support force that lets ``model`` stand (module docstring).

    Parameters
    ----------
    model : masonry.rbe.boundary.Model
        A structure or a construction stage (:func:`masonry.rbe.boundary.restrict`);
        a cyclic section's forces are those of one web (every web needs the same,
        rotated).
    mu : float
    density : float, kg/m^3
    cone : FrictionCone or str
        The friction model (:mod:`masonry.friction`).
    time_limit : float, s
        Clarabel's limit.
    cohesion, tensile : float, Pa
        The mortar (:mod:`masonry.contact`); default dry joints.
    solver : str
        One of :data:`SOLVERS`.

    Returns
    -------
    CenteringResult
    """
    ContactLaw.of(cone, mu, cohesion, tensile)  # refuses a strength out of range
    if len(model.interfaces) == 0:
        return _held_by_weight(model.blocks, mu, density, cone)
    system = assemble(model.blocks, model.interfaces, mu=mu, density=density,
                      side_block=model.side_block, side_rotation=model.side_rotation,
                      cone=cone, cohesion=cohesion, tensile=tensile)
    return solve_centering(system, time_limit=time_limit, solver=solver)


def solve_centering(system: EquilibriumSystem, *, time_limit=600.0, solver=INTERIOR,
                    symbolic=None) -> CenteringResult:
    """:func:`centering_force` on assembled matrices (their friction model, ``mu``,
    density and mortar): by the own interior point method (on ``symbolic``, the
    :class:`~masonry.rbe.solvers.cholesky.BlockCholesky` analysis of the system's
    blocks, made here when None), and by Clarabel where that ends without a checked
    optimum; by Clarabel alone with ``solver`` ``clarabel``."""
    start = time.perf_counter()
    if solver not in SOLVERS:
        raise ParameterError("solver", solver, f"one of {', '.join(SOLVERS)}")
    if solver == INTERIOR:
        ns = NewtonSystem(system, "net", symbolic=symbolic)
        found = interior_centering.solve(ns)
        if found.status in (OPTIMAL, OPTIMAL_INACCURATE):
            result = _checked(system, ns.full_vector(found.x, system.layout),
                              found.support.ravel(), found.status, found.iterations, start,
                              INTERIOR)
            if result.total_N is not None:
                return result
        log.info("centering force: the interior point method ended %s; Clarabel",
                 found.status)
    return _by_clarabel(system, time_limit, start)


def _by_clarabel(system, time_limit, start) -> CenteringResult:
    """The program solved by Clarabel (module docstring)."""
    columns = friction_columns(system)
    free = len(system.free_block)
    A, b, rows, h, cones = _program(system, columns)
    n = A.shape[1]
    q = np.zeros(n)
    q[n - free:] = 1.0
    status, z, iterations = solve_cone_program(q, A, b, rows, h, cones, time_limit,
                                               CENTERING_SETTINGS)
    if z is None:
        log.warning("centering force: Clarabel ended %s", status)
        return CenteringResult(None, force=None, status=status, residual_eq=np.nan,
                               friction_violation=np.nan, time_s=time.perf_counter() - start,
                               solver=SOLVER, **_common(system, iterations))
    g, support = z[:columns.edges.shape[1]], z[columns.edges.shape[1]:n - free]
    return _checked(system, columns.edges @ g, support, status, iterations, start, SOLVER)


def _common(system, iterations) -> dict:
    return {"weight_N": system.total_weight, "block": system.free_block,
            "block_weight": system.block_weight[system.free_block],
            "iterations": iterations, "mu": system.mu, "cone": system.cone,
            "law": system.law}


def _checked(system, x, support, status, iterations, start, solver) -> CenteringResult:
    """The result of a solver's point: vertex forces ``x`` (the layout's, solver units)
    and support forces ``support`` ((3 F,), units of the reference weight), their
    equilibrium residual and friction violation recomputed; a point beyond
    :data:`~masonry.tolerances.ACCEPT_RESIDUAL` gives no value."""
    residual, violation = _residuals(system, x, support)
    accepted = max(residual, violation) <= ACCEPT_RESIDUAL
    if not accepted:
        # the interior point method's is not the last word: Clarabel follows
        log.log(logging.INFO if solver == INTERIOR else logging.WARNING,
                "centering force: the point of %s (%s) rejected: residual %.1e, "
                "friction violation %.1e", solver, status, residual, violation)
    elif status == "AlmostSolved":
        log.warning("centering force: almost solved, kept (residual %.1e)", residual)
    force = support.reshape(-1, 3) * system.weight_ref
    total = float(np.linalg.norm(force, axis=1).sum())
    if accepted:
        log.info("centering force: %.6g N (%.4g of the weight), %s, %d iterations", total,
                 total / system.total_weight, solver, iterations)
    return CenteringResult(
        total if accepted else None, force=force if accepted else None,
        status="optimal" if accepted else status, residual_eq=residual,
        friction_violation=violation,
        x=system.to_newtons(system.shifted(x, -1.0)) if accepted else None,
        time_s=time.perf_counter() - start, solver=solver,
        **_common(system, iterations))


def _held_by_weight(blocks, mu, density, cone) -> CenteringResult:
    """Blocks that touch nothing: each is held by a force equal to its weight, up."""
    free = np.flatnonzero(~blocks.block_is_support)
    weight = density * G * blocks.block_volume[free]
    force = np.zeros((len(free), 3))
    force[:, 2] = weight
    return CenteringResult(float(weight.sum()), float(weight.sum()), free, weight, force,
                           "optimal", iterations=0, time_s=0.0, residual_eq=0.0,
                           friction_violation=0.0, mu=float(mu),
                           cone=FrictionCone.parse(cone), solver="none")


def _program(system, columns):
    """``(A, b, G, h, cones)`` over ``z = [g, s, tau]``: the equilibrium rows ``A z = b``
    and the cone rows ``h - G z in cones`` (the friction model's, then one
    ``(tau_j, s_j)`` second-order cone of dimension 4 per free block)."""
    free = len(system.free_block)
    n_g = columns.edges.shape[1]
    block = np.arange(free)
    # B: s_j into the three force rows of block j
    support = sp.csc_array((np.ones(3 * free), ((6 * block[:, None] + np.arange(3)).ravel(),
                                                np.arange(3 * free))),
                           shape=(6 * free, 3 * free))
    A = sp.hstack([sp.csc_array(system.A_eq @ columns.edges), support,
                   sp.csc_array((6 * free, free))], format="csc")
    # -(tau_j, s_j) + slack = 0: rows 4 j (tau_j), 4 j + 1..3 (s_j)
    row = 4 * block[:, None] + np.arange(4)
    column = np.column_stack([n_g + 3 * free + block,
                              n_g + 3 * block[:, None] + np.arange(3)])
    epigraph = sp.csc_array((-np.ones(4 * free), (row.ravel(), column.ravel())),
                            shape=(4 * free, n_g + 4 * free))
    friction = sp.hstack([columns.G, sp.csc_array((columns.G.shape[0], 4 * free))])
    rows = sp.vstack([friction, epigraph], format="csc")
    h = np.concatenate([columns.h, np.zeros(4 * free)])
    cones = (*columns.cones, (SECOND_ORDER, 4, free))
    return A, -system.f_ext, rows, h, cones


def _residuals(system, x, support) -> tuple:
    """``(relative equilibrium residual, friction violation per reference weight)`` of
    vertex forces ``x`` and support forces ``support`` ((3 F,)), scaled."""
    total = system.times_A_eq(x) + system.f_ext
    total.reshape(-1, 6)[:, :3] += support.reshape(-1, 3)
    residual = float(np.abs(total).max() / np.abs(system.f_ext).max())
    c, _, f1, f2 = np.asarray(x).reshape(-1, 4).T
    excess = system.cone.excess(c, f1, f2, system.mu)
    # c >= 0, or a tension cut-off's floor (c is the shifted compression)
    below = system.lower[system.layout.columns("c")] - c
    violation = max(0.0, float(excess.max(initial=0.0)), float(below.max(initial=0.0)))
    return residual, violation
