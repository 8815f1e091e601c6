"""The collapse load factor and mechanism: one linear program (docs/model.md 6.8, 6.9).

With the scaled matrices of :mod:`masonry.rbe.equilibrium` (``A_eq``, the dead load
``f_dead`` = the RBE's ``f_ext``) and a live load ``l`` (:mod:`masonry.rbe.loads`, in the
same row scaling)::

    maximize    lambda
    subject to  A_eq E g + lambda l = -f_dead        6 rows per free block
                g in K                                 every vertex's friction model

``x = E g`` are the vertex forces ``(c, 0, f1, f2)`` with no tension and the friction
within the model (:class:`~masonry.friction.FrictionCone`, docs/model.md 6.3 with ``t = 0``):
for Coulomb's cone ``g = (c, f1, f2)`` with ``||(f1, f2)|| <= mu c`` (a second-order cone
program), for a pyramid ``g >= 0`` the weights of its edge rays
(:func:`~masonry.rbe.equilibrium.friction_edges`; a linear program). This module states
the program (its columns, cones and load columns,
:class:`~masonry.rbe.solvers.program.ConeProgram`) and reads the mechanism from its
dual; a backend of :mod:`masonry.rbe.solvers` solves it, named by ``method``: the own
interior point method (``interior``, :mod:`masonry.rbe.solvers.interior_lp`, the
default) and Clarabel both models, HiGHS the pyramids (``highs-simplex``: the dual
simplex, whose basis warm-starts the next load case). One held program serves every
load case (:class:`CollapseLP`: a lateral load at another azimuth changes two
coefficients and two costs; docs/model.md 6.8: every azimuth on one LP).

The dual of the equilibrium rows is the collapse mechanism (docs/model.md 6.9): per free block a
virtual translation ``u`` and rotation ``theta`` about the centroid. The dual constraints
``E^T A_eq^T y in K*`` say that the relative motion at every vertex lies in the normal
cone of its friction model: it opens the joint at least ``mu`` times its slip, with the
slip along the friction force (associated flow), so no interface penetrates; and at the
optimum ``lambda l^T y = -f_dead^T y``: the live load's virtual work balances the dead
load's (the kinematic theorem).

Glossary: ``lambda`` -> ``load_factor``; ``y`` -> the dual of the equilibrium rows, in
scaled units (force rows: a translation; moment rows: a rotation times ``length_ref``).
"""

import dataclasses
import logging
import time

import numpy as np
import scipy.sparse as sp

from masonry.contact import ContactLaw
from masonry.friction import FrictionCone
from masonry.rbe.collapse_result import (ANISOTROPIC_NOTE, ASSOCIATED_NOTE, RESULT_KEYS,
                                         UNBOUNDED_NOTE, CollapseResult)
from masonry.rbe.equilibrium import assemble, friction_edges
from masonry.rbe.loads import LiveLoad, lateral
from masonry.rbe.mirror import half_model, states_exactly
from masonry.rbe.cores import solver_threads
from masonry.rbe.result import interface_forces
from masonry.rbe.solvers import BACKENDS, COLLAPSE, backend
from masonry.rbe.solvers.base import INFEASIBLE, OPTIMAL, UNBOUNDED
from masonry.rbe.solvers.program import NONNEGATIVE, SECOND_ORDER, Columns, ConeProgram
from masonry.tolerances import MOTION_TOL

__all__ = ["ANISOTROPIC_NOTE", "ASSOCIATED_NOTE", "RESULT_KEYS", "UNBOUNDED_NOTE",
           "CollapseLP", "CollapseResult", "collapse_load", "collapse_on_half",
           "fixed_capacity_factor", "on_the_whole"]

log = logging.getLogger(__name__)

METHOD = "interior"
"""The default backend of the collapse program (:func:`masonry.rbe.solvers.names` with
:data:`~masonry.rbe.solvers.base.COLLAPSE` lists them all): the project's interior point
method on the Newton method's matrix (:mod:`masonry.rbe.solvers.interior_lp`). Clarabel's
interior point (direct LDL factorization of the whole KKT system) stopped 0.3 % short of
the optimum on preset 1's cyclic section; HiGHS (the pyramids only) decides the small
scenes of the tests at once, and its dual simplex warm-starts across azimuths, but gave
no verdict on preset 1's sections and dome in the time it was given (docs/collapse.md,
"The cone program")."""

FALLBACK = {"interior": "clarabel"}
"""Backends that assume the program has an optimum -> the backend that decides when
they find none (a dead load that cannot stand, a live load carried at every factor)."""

STATUS = {OPTIMAL: "optimal", INFEASIBLE: "dead load infeasible", UNBOUNDED: "unbounded"}
"""A backend's verdict -> :attr:`CollapseResult.status`; other statuses keep the
solver's words."""


def _selection(layout) -> sp.csr_array:
    """(4 IV, 3 IV): the columns ``(c, f1, f2)`` of every vertex, in that order."""
    picked = np.stack([layout.columns(name) for name in ("c", "f1", "f2")], axis=1)
    count = picked.size
    return sp.csr_array((np.ones(count), (picked.ravel(), np.arange(count))),
                        shape=(layout.n_columns, count))


def friction_columns(system) -> Columns:
    """The friction model's columns: a pyramid's edge ray weights ``g >= 0``, or the
    forces ``(c, f1, f2)`` with ``(mu c, f1, f2)`` in the second-order cone; and rows
    ``c >= floor`` where a tension cut-off truncates the cone (masonry.contact)."""
    n_vertices, cone, mu = system.layout.n_vertices, system.cone, system.mu
    if cone.is_polyhedral:
        edges = friction_edges(n_vertices, cone, mu)
        n = edges.shape[1]
        columns = Columns(edges, sp.csc_array(-sp.identity(n)), np.zeros(n),
                          ((NONNEGATIVE, n, 1),), is_rays=True)
    else:
        scale = sp.kron(sp.identity(n_vertices), sp.diags_array([mu, 1.0, 1.0]))
        columns = Columns(_selection(system.layout), sp.csc_array(-scale),
                          np.zeros(3 * n_vertices), ((SECOND_ORDER, 3, n_vertices),),
                          is_rays=False)
    floor = system.compression_floor
    if floor is None:
        return columns
    compression = sp.csc_array(columns.edges[system.layout.columns("c")])  # c of each vertex
    return Columns(columns.edges, sp.csc_array(sp.vstack([columns.G, -compression])),
                   np.concatenate([columns.h, -floor]),
                   (*columns.cones, (NONNEGATIVE, n_vertices, 1)), is_rays=False)


def _capacity_columns(system, capacity) -> Columns:
    """The forces ``(c, f1, f2)`` with ``c >= 0`` and the friction within the model at a
    fixed capacity ``capacity`` ((IV,) float) instead of ``mu c``: a disc of that radius
    (the circle), the pyramid's polygon at that radius (its faces ``f . normal_k <=
    capacity rho cos(pi / K)``)."""
    n_vertices, cone = system.layout.n_vertices, system.cone
    capacity = np.asarray(capacity, dtype=float)
    vertex = np.arange(n_vertices)
    # c >= 0 (or a tension cut-off's floor): -(-c) in the nonnegative cone
    rows = [sp.csc_array((-np.ones(n_vertices), (vertex, 3 * vertex)),
                         shape=(n_vertices, 3 * n_vertices))]
    floor = system.compression_floor
    h = [np.zeros(n_vertices) if floor is None else -floor]
    if cone.is_polyhedral:
        normals = cone.face_normals()                       # (K, 2)
        sides = len(normals)
        row = np.arange(n_vertices * sides)
        owner = np.repeat(vertex, sides)
        data = np.tile(normals, (n_vertices, 1))
        rows.append(sp.csc_array(
            (data.ravel(), (np.repeat(row, 2), (3 * owner[:, None] + [1, 2]).ravel())),
            shape=(len(row), 3 * n_vertices)))
        h.append(np.repeat(capacity * cone.apothem(1.0), sides))
        cones = ((NONNEGATIVE, n_vertices + len(row), 1),)
    else:
        # (capacity, f1, f2) in the second-order cone
        row = 3 * vertex[:, None] + [1, 2]
        rows.append(sp.csc_array((-np.ones(2 * n_vertices),
                                  (row.ravel(), (3 * vertex[:, None] + [1, 2]).ravel())),
                                 shape=(3 * n_vertices, 3 * n_vertices)))
        cone_h = np.zeros((n_vertices, 3))
        cone_h[:, 0] = capacity
        h.append(cone_h.ravel())
        cones = ((NONNEGATIVE, n_vertices, 1), (SECOND_ORDER, 3, n_vertices))
    return Columns(_selection(system.layout), sp.csc_array(sp.vstack(rows)),
                   np.concatenate(h), cones, is_rays=False, is_friction_model=False)


class CollapseLP:
    """One model's collapse LP, kept by its solver between load cases.

    The matrix ``A_eq E`` is built once. :meth:`solve` takes any live load;
    :meth:`solve_lateral` keeps a second program whose two load columns are the lateral
    loads along x and y, tied by one row ``-sin a lambda_x + cos a lambda_y = 0`` and
    maximising ``cos a lambda_x + sin a lambda_y``: another azimuth changes two
    coefficients and two costs (HiGHS's dual simplex restarts from the last basis, the
    interior point methods keep their symbolic factorization).

    Parameters
    ----------
    model : masonry.rbe.boundary.Model
    mu : float
    density : float, kg/m^3
    cone : FrictionCone or str
        The friction model (:mod:`masonry.friction`; default Coulomb's cone); with
        ``cohesion``, ``tensile`` (Pa; default dry), the contact law (:mod:`masonry.contact`).
    time_limit : float, s
        HiGHS's and Clarabel's limit per solve.
    method : str, optional
        The backend (:mod:`masonry.rbe.solvers`, one that solves
        :data:`~masonry.rbe.solvers.base.COLLAPSE`); default :data:`METHOD`.
    cores : int, optional
        The cores a solve may use: its factorizations on up to two threads
        (:func:`~masonry.rbe.solvers.cholesky.factor_threads`), BLAS on one. Default: the
        process's (:func:`masonry.forking.cores`).

    Raises
    ------
    ValueError
        An unknown method, or one that cannot state the friction model (HiGHS solves
        linear programs only: the pyramids).
    """

    def __init__(self, model, *, mu=0.7, density=2000.0, cone="circle", time_limit=600.0,
                 method=None, cores=None, cohesion=0.0, tensile=0.0):
        self.model = model
        ContactLaw.of(cone, mu, cohesion, tensile)  # refuses a strength out of range
        self.system = assemble(model.blocks, model.interfaces, mu=mu, density=density,
                               cone=cone, cohesion=cohesion, tensile=tensile,
                               **model.assembly)
        self.method = METHOD if method is None else method
        # the default hands a tension cut-off it cannot state to clarabel (logged)
        refusal = backend(self.method, COLLAPSE, self.system.cone).refusal(self.system)
        if refusal is not None and method is not None:
            raise ValueError(refusal)
        if refusal is not None:
            log.warning("%s; clarabel solves the collapse program", refusal)
            self.method = "clarabel"
        self.columns = friction_columns(self.system)
        self.matrix = sp.csc_array(self.system.A_eq @ self.columns.edges)
        self.mu, self.density, self.time_limit = float(mu), float(density), time_limit
        self.cores = cores
        self._lateral = None
        self._workspace = {}  # what the backends keep between programs of the model

    @property
    def cone(self) -> FrictionCone:
        return self.system.cone

    def with_friction_capacity(self, capacity) -> "CollapseLP":
        """The same LP with a fixed friction capacity: at every vertex ``c >= 0`` and the
        friction within the model at radius ``capacity`` ((IV,) float, scaled units; see
        :func:`_capacity_columns`), the variables ``(c, f1, f2)`` themselves. A capacity
        that does not grow with ``c`` has a purely tangential flow rule: joints slide
        without dilating (non-associative friction, see :func:`fixed_capacity_factor`).
        Clarabel solves it."""
        columns = _capacity_columns(self.system, capacity)
        out = CollapseLP.__new__(CollapseLP)
        out.__dict__.update(self.__dict__, columns=columns, _lateral=None,
                            method="clarabel",
                            matrix=sp.csc_array(self.system.A_eq @ columns.edges))
        return out

    def scaled(self, live: LiveLoad) -> np.ndarray:
        """(6 F,) float: a live load in the rows' scaling (:func:`scaled_load`)."""
        return scaled_load(self.system, live)

    def solve(self, live: LiveLoad, *, dead_load_feasible=None) -> CollapseResult:
        """The largest factor of ``live``; ``dead_load_feasible`` (e.g. the RBE's verdict)
        saves the check of ``lambda = 0`` when the optimum is positive."""
        with solver_threads(self.cores):
            start = time.perf_counter()
            load = self.scaled(live)
            # the LP takes the load at the dead load's size (the same optimum, times the
            # ratio): a point load of 1e12 N would leave the factor at the rows' rounding
            if not np.any(load):
                raise ValueError("the live load is zero on every free block")
            ratio = float(np.abs(load).max() / np.abs(self.system.f_ext).max())
            held = self._hold(load[:, None] / ratio, np.ones(1))
            return self._result(held, live, None, start, dead_load_feasible,
                                per_unit=1 / ratio)

    def solve_lateral(self, azimuth_deg: float, *, dead_load_feasible=None) -> CollapseResult:
        """The factor of :func:`masonry.rbe.loads.lateral` at ``azimuth_deg``, reusing the
        previous azimuth's program (HiGHS: its basis; Clarabel and the interior point
        method: their symbolic factorization)."""
        with solver_threads(self.cores):
            start = time.perf_counter()
            angle = np.radians(azimuth_deg)
            cos, sin = np.cos(angle), np.sin(angle)
            if self._lateral is None:
                loads = np.stack([self.scaled(lateral(self.model, 0.0, self.density)),
                                  self.scaled(lateral(self.model, 90.0, self.density))],
                                 axis=1)
                self._lateral = self._hold(loads, np.array([cos, sin]), tie=(-sin, cos))
            else:
                self._lateral.direct(cos, sin)
            live = lateral(self.model, azimuth_deg, self.density)
            return self._result(self._lateral, live, float(azimuth_deg) % 360.0, start,
                                dead_load_feasible)

    def _hold(self, loads, cost, tie=None) -> "_Held":
        """The program of ``loads`` ((6 F, m) float, scaled rows) combined by ``cost``
        (and ``tie``), held by the backend :attr:`method`."""
        program = ConeProgram(self.system, self.columns, self.matrix, loads, cost, tie,
                              self.time_limit)
        return _Held(self.method, program, self._workspace)

    def _result(self, held, live, azimuth, start, dead_load_feasible,
                per_unit=1.0) -> CollapseResult:
        """The result of ``held`` run, whose factor times ``per_unit`` is ``live``'s."""
        load = self.scaled(live)
        outcome = held.run(load, per_unit)
        status = STATUS.get(outcome.status, outcome.status)
        common = dict(solver=held.name, mu=self.mu, live=live, azimuth_deg=azimuth,
                      iterations=outcome.iterations, cone=self.cone, law=self.system.law)
        if status != "optimal":
            feasible = False if status == "dead load infeasible" else dead_load_feasible
            if status == "unbounded" and feasible is None:
                feasible = held.stands_unloaded()
            if status not in ("dead load infeasible", "unbounded"):
                log.warning("collapse LP without a verdict: %s", status)
            return CollapseResult(None, feasible, status, time_s=time.perf_counter() - start,
                                  residual=np.nan, work_balance=np.nan, **common)
        factor = outcome.info["load_factor"]
        if factor < 0:
            # the largest factor is negative: lambda = 0 is past it
            dead_load_feasible = False
        elif dead_load_feasible is None:
            dead_load_feasible = held.stands_unloaded()
        motion = mechanism_of(self.system, self.model.blocks,
                              outcome.y[: self.system.A_eq.shape[0]], load, factor)
        x = self.system.to_newtons(self.system.shifted(outcome.x, -1.0))
        log.debug("collapse LP: lambda %.6g, %d iterations", factor, outcome.iterations)
        return CollapseResult(
            factor if dead_load_feasible else None, dead_load_feasible,
            "optimal" if dead_load_feasible else "dead load infeasible",
            time_s=time.perf_counter() - start, residual=outcome.residuals.equilibrium, x=x,
            forces=interface_forces(self.system.layout, x), **motion, **common)


def scaled_load(system, live: LiveLoad) -> np.ndarray:
    """(6 F,) float: a live load in the rows' scaling of ``system``
    (:class:`~masonry.rbe.equilibrium.EquilibriumSystem`): free blocks only, zero on the
    rows the model drops."""
    wrench = live.wrench[system.free_block].ravel() / system.row_scale
    return wrench if system.row_kept is None else wrench * system.row_kept


def mechanism_of(system, blocks, dual, load, factor) -> dict:
    """Mechanism, per-interface flags and the work balance from the equilibrium rows'
    dual ``y`` ((6 F,) float, scaled) of ``system`` on ``blocks``, the scaled live load
    and the factor (docs/model.md 6.9)."""
    if dual @ load < 0:  # HiGHS's sign convention: make the live load do positive work
        dual = -dual
    per_block = dual.reshape(-1, 6).copy()
    per_block[:, 3:] /= system.length_ref  # moment rows: rotation times length_ref
    mechanism = np.zeros((blocks.n_blocks, 6))
    mechanism[system.free_block] = per_block
    # the largest displacement of any vertex: u + theta x (p - c)
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    arm = blocks.vertices - blocks.block_centroid[owner]
    motion = mechanism[owner, :3] + np.cross(mechanism[owner, 3:], arm)
    largest = float(np.linalg.norm(motion, axis=1).max())
    if largest == 0:
        return dict(work_balance=np.nan)
    mechanism /= largest
    # relative motion at every vertex, per column (c: opening along n; f1, f2: slip
    # along t1, t2); A_eq^T y routes the cyclic images like the forces
    relative = (system.A_eq.T @ dual).reshape(-1, 4) / largest
    layout = system.layout
    opening, slip = relative[:, 0], np.hypot(relative[:, 2], relative[:, 3])
    gap, most_slip = np.zeros(layout.n_interfaces), np.zeros(layout.n_interfaces)
    np.maximum.at(gap, layout.vertex_interface, opening)
    np.maximum.at(most_slip, layout.vertex_interface, slip)
    opens, slides = gap > MOTION_TOL, most_slip > MOTION_TOL
    closed = np.bincount(layout.vertex_interface, opening <= MOTION_TOL,
                         minlength=layout.n_interfaces) > 0
    # kinematic theorem on the normalised mechanism, in physical units
    free = system.free_block
    work_live = float(np.sum(load.reshape(-1, 6) * system.row_scale.reshape(-1, 6)
                             * mechanism[free]))
    dead = (system.f_ext * system.row_scale).reshape(-1, 6)
    work_dead = float(np.sum(dead * mechanism[free]))
    balance = abs(factor * work_live + work_dead) / max(abs(work_dead), abs(work_live))
    return dict(mechanism=mechanism, opens=opens, slides=slides, hinge=opens & closed,
                gap=gap, slip=most_slip, work_balance=balance)


class _Held:
    """A program held by the backend ``name`` and, when that one assumes an optimum
    (:data:`FALLBACK`), by the backend that decides without one, made when first needed
    (on preset 1's dome Clarabel's KKT matrix is a large part of a solve). Both follow
    every new lateral direction; :attr:`name` says who gave the last outcome."""

    def __init__(self, name, program, workspace):
        self.program, self.workspace = program, workspace
        self.primary = BACKENDS[name].hold(program, workspace)
        self.fallback_name = FALLBACK.get(name)
        self.name, self._fallback, self._direction = name, None, None

    def fallback(self):
        """The deciding backend's program, set to the current direction."""
        if self._fallback is None:
            self._fallback = BACKENDS[self.fallback_name].hold(self.program, self.workspace)
        if self._direction is not None:
            self._fallback.direct(*self._direction)
        return self._fallback

    def run(self, live, per_unit):
        """The outcome of the primary backend, or of the deciding one when the primary
        found no optimum (logged; :attr:`name` says ``primary+fallback``)."""
        outcome = self.primary.run(live, per_unit)
        self.name = self.primary.name
        if outcome.status == OPTIMAL or self.fallback_name is None:
            return outcome
        log.info("collapse LP: %s found no optimum (%s); %s decides", self.primary.name,
                 outcome.status, self.fallback_name)
        self.name = f"{self.primary.name}+{self.fallback_name}"
        return self.fallback().run(live, per_unit)

    def stands_unloaded(self) -> bool | None:
        verdict = self.primary.stands_unloaded()
        if verdict is None and self.fallback_name is not None:
            verdict = self.fallback().stands_unloaded()
        return verdict

    def direct(self, cos, sin):
        self._direction = (cos, sin)
        self.primary.direct(cos, sin)


def collapse_load(model, live: LiveLoad, *, mu=0.7, density=2000.0, cone="circle",
                  friction=None, dead_load_feasible=None, time_limit=600.0,
                  cores=None, cohesion=0.0, tensile=0.0) -> CollapseResult:
    """The collapse load factor of ``live`` on ``model`` and its mechanism (docs/model.md 6.8, 6.9).

    Parameters
    ----------
    model : masonry.rbe.boundary.Model
    live : LiveLoad
        Built on ``model.blocks`` (:mod:`masonry.rbe.loads`).
    mu : float
    density : float, kg/m^3
        Of the dead load (and of a lateral load built with the same density).
    cone : FrictionCone or str
        The friction model (:mod:`masonry.friction`).
    friction : None, 'associated' or 'non-associative'
        ``Params.friction_law``'s values. ``associated`` (or None): the LP above.
        ``non-associative``: the estimate of :func:`fixed_capacity_factor` (friction
        capacities fixed from the last collapse, re-solved: joints slide without
        dilating).
    dead_load_feasible : bool, optional
        Known verdict on the dead load alone (e.g. the RBE's); otherwise the LP decides it
        with ``lambda`` fixed at 0.
    time_limit : float, s
    cores : int, optional
        See :class:`CollapseLP`.

    Returns
    -------
    CollapseResult
    """
    if live.wrench.shape != (model.blocks.n_blocks, 6):
        raise ValueError(f"live load of shape {live.wrench.shape} for "
                         f"{model.blocks.n_blocks} blocks")
    problem = CollapseLP(model, mu=mu, density=density, cone=cone, time_limit=time_limit,
                         cores=cores, cohesion=cohesion, tensile=tensile)
    if friction in (None, "associated"):
        return problem.solve(live, dead_load_feasible=dead_load_feasible)
    if friction == "non-associative":
        return fixed_capacity_factor(problem, live, dead_load_feasible=dead_load_feasible)
    raise ValueError(f"friction must be 'associated' (or None) or 'non-associative', not "
                     f"{friction!r}")


NON_ASSOCIATIVE_ROUNDS = 30
"""Most re-solves of :func:`fixed_capacity_factor`."""
NON_ASSOCIATIVE_RELAXATION = 0.5
"""How far each round of :func:`fixed_capacity_factor` moves the capacities toward the
last collapse's compression: halfway settles the small dome of the tests within 1e-3 in
about a dozen rounds, where the whole step oscillates between 0.47 and 0.69."""


def fixed_capacity_factor(problem: CollapseLP, live: LiveLoad, *, dead_load_feasible=None,
                          rounds=NON_ASSOCIATIVE_ROUNDS, rtol=1e-3) -> CollapseResult:
    """A non-associative estimate of the load factor (docs/model.md 6.8, the friction law).

    Start from the associated LP; then fix every vertex's friction capacity at ``mu``
    times its compression at the last collapse (:meth:`CollapseLP.with_friction_capacity`:
    a capacity that does not grow with the compression lets joints slide without
    dilating) and solve again, until the factor changes by less than ``rtol`` in two
    rounds running. This is the iterative scheme of Gilbert, Casapulla and Ahmed (2006,
    Comput. Struct. 84) for non-associative frictional joints: an estimate, not a bound,
    that removes the dilatancy by which the associated factor overestimates a sliding
    collapse. Each round's capacities move halfway (:data:`NON_ASSOCIATIVE_RELAXATION`)
    from the last round's toward the last collapse's: the plain iteration oscillates
    between mechanisms where the LP's optimum is degenerate, and which optimum a solver
    returns decides where it goes. Between rounds a joint's friction may exceed ``mu``
    times its compression,
    so only a settled factor is reported: after ``rounds`` (at least 2) re-solves
    without one, or a round whose capacities admit no equilibrium, the factor and the
    mechanism are None (the status says which). The LP's optimum is degenerate, so the
    factor wanders as it settles (docs/collapse.md, "The friction law"). ``friction_law``
    of the result says ``non-associative``; ``associated_factor`` keeps the starting factor.
    """
    if rounds < 2:
        raise ValueError(f"rounds must be at least 2 (a factor settles over two), not "
                         f"{rounds}")
    start = time.perf_counter()
    associated = problem.solve(live, dead_load_feasible=dead_load_feasible)
    result, known = associated, associated.dead_load_feasible
    if associated.load_factor is None:  # nothing to iterate from
        return dataclasses.replace(result, friction_law="non-associative",
                                   time_s=time.perf_counter() - start)
    settled, capacity = 0, None
    for done in range(1, rounds + 1):
        # the capacity mu c~ = mu n + c A of the shifted compression (masonry.contact),
        # relaxed: the plain iteration oscillates where the LP's optimum is degenerate
        shifted = problem.system.shifted(problem.system.to_scaled(result.x))
        aimed = problem.mu * shifted.reshape(-1, 4)[:, 0]
        capacity = aimed if capacity is None else (
            (1 - NON_ASSOCIATIVE_RELAXATION) * capacity + NON_ASSOCIATIVE_RELAXATION * aimed)
        following = problem.with_friction_capacity(capacity).solve(
            live, dead_load_feasible=known)
        if following.load_factor is None:
            break
        previous, result = result.load_factor, following
        close = abs(result.load_factor - previous) <= rtol * abs(previous)
        settled = settled + 1 if close else 0
        if settled == 2:
            break
    if settled < 2:
        why = (f"round {done} has no equilibrium ({following.status})"
               if following.load_factor is None else f"not settled after {done} rounds")
        log.warning("non-associative estimate: %s; no factor", why)
        # no mechanism either: the last round's is of capacities that were not settled
        result = dataclasses.replace(
            result, load_factor=None, status=f"non-associative estimate: {why}",
            **dict.fromkeys(("mechanism", "opens", "slides", "hinge", "gap", "slip")))
    return dataclasses.replace(result, friction_law="non-associative",
                               associated_factor=associated.load_factor,
                               time_s=time.perf_counter() - start)


def collapse_on_half(model, case, plane, *, copies=1, mu=0.7, density=2000.0, cone="circle",
                     dead_load_feasible=None, time_limit=600.0, method=None,
                     cores=None) -> CollapseResult:
    """The collapse load factor of the load ``case`` (a case of :mod:`masonry.rbe.loads`
    that is its own mirror image in the vertical plane at ``plane`` degrees,
    :func:`~masonry.rbe.mirror.symmetric_plane`) on ``model``, one of ``copies`` equal
    parts of the structure: solved on the half of ``model`` in that plane
    (:func:`~masonry.rbe.mirror.half_model`) and reported on the whole
    (:func:`on_the_whole`), ``time_s`` all of it. Associated friction with Coulomb's
    cone only (:func:`~masonry.rbe.mirror.states_exactly`); the other parameters as for
    :class:`CollapseLP` and :meth:`CollapseLP.solve`.

    Raises
    ------
    masonry.rbe.mirror.MirrorError
        ``model`` is not its own mirror image in that plane.
    """
    if not states_exactly(cone):
        raise ValueError(f"a half states Coulomb's cone only, not {cone}")
    start = time.perf_counter()
    half = half_model(model, plane)
    problem = CollapseLP(half.model, mu=mu, density=density, cone=cone,
                         time_limit=time_limit, method=method, cores=cores)
    result = problem.solve(half.live(case, density, copies),
                           dead_load_feasible=dead_load_feasible)
    whole = on_the_whole(half, result, case.on(model, density, copies=copies), mu=mu,
                         density=density, cone=cone)
    return dataclasses.replace(whole, time_s=time.perf_counter() - start)


def on_the_whole(half, result: CollapseResult, live: LiveLoad, *, mu=0.7, density=2000.0,
                 cone="circle") -> CollapseResult:
    """A result of ``half.model`` (:class:`~masonry.rbe.mirror.Half`) as its whole's:
    ``live`` the load on the whole, the forces and the mechanism mirrored back, the flags,
    the work balance and the equilibrium residual computed again on the whole's matrices
    (the residual checks the map). Without a factor the result keeps none of the half's
    forces or mechanism."""
    if result.load_factor is None or result.x is None or result.mechanism is None:
        return dataclasses.replace(result, live=live, x=None, forces=None, **dict.fromkeys(
            ("mechanism", "opens", "slides", "hinge", "gap", "slip")))
    whole = half.whole
    system = assemble(whole.blocks, whole.interfaces, mu=mu, density=density, cone=cone,
                      **whole.assembly)
    x = half.whole_forces(result.x)
    motion = half.whole_motion(result.mechanism)[system.free_block]
    motion[:, 3:] *= system.length_ref
    load, factor = scaled_load(system, live), result.load_factor
    flags = mechanism_of(system, whole.blocks, motion.ravel(), load, factor)
    rhs = system.f_ext + factor * load
    residual = np.abs(system.A_eq @ system.to_scaled(x) + rhs).max() / np.abs(rhs).max()
    return dataclasses.replace(result, live=live, x=x,
                               forces=interface_forces(system.layout, x),
                               residual=float(residual), solved_on="half", **flags)
