"""The collapse load factor and mechanism: one linear program (SPEC 6.8, 6.9).

With the scaled matrices of :mod:`masonry.rbe.equilibrium` (``A_eq``, the dead load
``f_dead`` = the RBE's ``f_ext``) and a live load ``l`` (:mod:`masonry.rbe.loads`, in the
same row scaling)::

    maximize    lambda
    subject to  A_eq E g + lambda l = -f_dead        6 rows per free block
                g in K                                 every vertex's friction model

``x = E g`` are the vertex forces ``(c, 0, f1, f2)`` with no tension and the friction
within the model (:class:`~masonry.friction.FrictionCone`, SPEC 6.3 with ``t = 0``):
for Coulomb's cone ``g = (c, f1, f2)`` with ``||(f1, f2)|| <= mu c`` (a second-order cone
program), for a pyramid ``g >= 0`` the weights of its edge rays
(:func:`~masonry.rbe.equilibrium.friction_edges`; a linear program). The own interior
point method (:mod:`masonry.rbe.solvers.interior_lp`) solves both; Clarabel both;
HiGHS the pyramids, by the dual simplex, whose basis warm-starts the next load case
(:class:`CollapseLP`: a lateral load at another azimuth changes two coefficients and two
costs, SPEC 6.8's "reuse work").

The dual of the equilibrium rows is the collapse mechanism (SPEC 6.9): per free block a
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
import functools
import logging
import time
from dataclasses import dataclass, field

import clarabel
import highspy
import numpy as np
import scipy.sparse as sp

from masonry import forking
from masonry.rbe.equilibrium import assemble, friction_edges
from masonry.friction import FrictionCone
from masonry.rbe.loads import LiveLoad, lateral
from masonry.rbe.cores import solver_threads
from masonry.rbe.solve import interface_forces
from masonry.rbe.solvers.base import OPTIMAL
from masonry.rbe.solvers.highs import highs_lp
from masonry.rbe.solvers.interior_lp import LoadFactorOptions, load_factor
from masonry.rbe.solvers.newton import NewtonSystem
from masonry.tolerances import ACCEPT_RESIDUAL, FACTOR_TIE_REL, MECHANISM_MAIN, MOTION_TOL

log = logging.getLogger(__name__)

FEASIBILITY_TOL = 1e-7
"""HiGHS's primal and dual feasibility tolerance (scaled rows: of order one)."""

METHODS = ("interior", "clarabel", "ipm", "ipm-crossover", "simplex")
"""Solvers of the collapse LP: the project's interior point method on the Newton method's
matrix (:mod:`masonry.rbe.solvers.interior_lp`; Clarabel decides when it finds no
optimum: a dead load that cannot stand, a live load carried at every factor), Clarabel's
interior point (direct LDL factorization of the whole KKT system), or HiGHS
(``HIGHS_METHODS``, for the pyramids only: HiGHS solves linear programs). HiGHS decides
the small scenes of the tests at once, and its dual simplex warm-starts across azimuths,
but gave no verdict on preset 1's sections and dome within minutes; Clarabel stopped 0.3 %
short of the optimum on preset 1's cyclic section (docs/collapse.md). ``interior`` is the
default."""

CLARABEL_SETTINGS = {"tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8, "tol_feas": 1e-8}
"""Clarabel's tolerances for the collapse LP (its defaults; scaled rows of order one);
tighter gaps end "almost solved" on the full domes (docs/collapse.md)."""

HIGHS_METHODS = {
    "ipm": {"solver": "ipm", "run_crossover": "off"},
    "ipm-crossover": {"solver": "ipm", "run_crossover": "on"},
    "simplex": {"solver": "simplex"},
}
"""HiGHS settings by name."""

METHOD = "interior"
"""The default of :data:`METHODS`."""

ASSOCIATED_NOTE = (
    "sliding interfaces take part in this mechanism: the load factor assumes associated "
    "friction (the friction cone's normal as flow rule, joints that dilate as they slide) "
    "and can overestimate the collapse load of real, non-dilatant joints (SPEC 6.8)")

ANISOTROPIC_NOTE = (
    "the friction model is the thesis's square pyramid: it carries up to 41 % more "
    "friction than Coulomb's cone where joints slide diagonally to their axes, so this "
    "factor depends on how the model is turned and may be too high")

UNBOUNDED_NOTE = (
    "the live load stands at any factor: rigid blocks pass it to the supports in "
    "compression without a joint reaching its limit (a downward load on a dome's top "
    "ring; a lateral load on a section whose rigid boundary holds it)")

RESULT_KEYS = ("load_factor", "dead_load_feasible", "status", "solver", "iterations",
               "time_s", "residual", "work_balance", "mu", "friction_model",
               "friction_capacity_error", "azimuth_deg", "opening", "sliding", "hinges",
               "main_hinges", "main_sliding", "friction_law", "associated_factor", "note")
"""Scalar fields of :class:`CollapseResult` in run.json, in order (plus ``live_load``)."""


@dataclass(frozen=True, eq=False)
class CollapseResult:
    """Outcome of a collapse load factor LP. Forces in newtons, lengths in metres.

    Parameters
    ----------
    load_factor : float or None
        The largest ``lambda``; None when the dead load alone cannot stand, when the live
        load is carried at any factor (``status`` says which) or without a verdict.
    dead_load_feasible : bool or None
        Whether ``lambda = 0`` has an equilibrium (None: unknown, e.g. time limit).
    status : str
        ``optimal``, ``dead load infeasible``, ``unbounded`` or HiGHS's words.
    solver : str
    iterations : int
        Simplex iterations of this solve.
    time_s : float, s
    residual : float
        ``||A_eq x + f_dead + lambda l||_inf / ||f_dead + lambda l||_inf``, recomputed.
    work_balance : float
        ``|lambda W_live + W_dead| / |W_dead|`` on the normalised mechanism (the
        kinematic theorem; 0 up to rounding).
    mu : float
    live : LiveLoad
    azimuth_deg : float or None
        Of a lateral load.
    x : (4 IV,) float or None
        Vertex forces at collapse in the :class:`~masonry.rbe.equilibrium.VariableLayout`
        order, newtons.
    forces : dict str -> (K,) float or None
        Per-interface sums (:func:`masonry.rbe.solve.interface_forces`).
    mechanism : (B, 6) float or None
        ``(ux, uy, uz, rx, ry, rz)`` per block: translation of the centroid and rotation
        (radians per unit), normalised so the largest displacement of any block vertex is
        1; zero on supports.
    opens, slides, hinge : (K,) bool or None
        Per interface: some vertex separates (relative normal motion > :data:`~masonry.tolerances.MOTION_TOL`);
        some vertex slips; opens with some vertex still closed (a hinge, not a separation).
    gap, slip : (K,) float or None
        Per interface: the largest opening (relative motion along the normal) and slip
        (along the plane) of its vertices, per largest block displacement (1). An interior
        point's mechanism moves many joints by little (see ``MOTION_TOL``): these say
        which joints carry it.
    azimuths : tuple of (float, float or None)
        After :func:`worst_lateral`: every azimuth searched and its factor.
    friction_law : str
        ``associated`` (the LP of SPEC 6.8) or ``non-associative`` (see
        :func:`fixed_capacity_factor`).
    associated_factor : float or None
        With ``non-associative``: the associated factor it started from.
    cone : FrictionCone
        The friction model.
    """

    load_factor: float | None
    dead_load_feasible: bool | None
    status: str
    solver: str
    iterations: int
    time_s: float
    residual: float
    work_balance: float
    mu: float
    live: LiveLoad
    azimuth_deg: float | None = None
    x: np.ndarray | None = None
    forces: dict | None = None
    mechanism: np.ndarray | None = None
    opens: np.ndarray | None = None
    slides: np.ndarray | None = None
    hinge: np.ndarray | None = None
    gap: np.ndarray | None = None
    slip: np.ndarray | None = None
    azimuths: tuple = field(default=())
    friction_law: str = "associated"
    associated_factor: float | None = None
    cone: FrictionCone = FrictionCone("circle")

    @property
    def friction_model(self) -> str:
        return self.cone.name

    @property
    def friction_capacity_error(self) -> float:
        """The model's bound on the error of the friction capacity (see
        :attr:`~masonry.friction.FrictionCone.capacity_error`)."""
        return self.cone.capacity_error

    @property
    def opening(self) -> int:
        return _count(self.opens)

    @property
    def sliding(self) -> int:
        return _count(self.slides)

    @property
    def hinges(self) -> int:
        return _count(self.hinge)

    @property
    def main_hinge(self) -> np.ndarray | None:
        """(K,) bool: the hinges that carry the mechanism (:data:`MECHANISM_MAIN`)."""
        return None if self.hinge is None else _main(self.hinge, self.gap)

    @property
    def main_slides(self) -> np.ndarray | None:
        """(K,) bool: the sliding joints that carry the mechanism."""
        return None if self.slides is None else _main(self.slides, self.slip)

    @property
    def main_hinges(self) -> int:
        return _count(self.main_hinge)

    @property
    def main_sliding(self) -> int:
        return _count(self.main_slides)

    @property
    def note(self) -> str | None:
        """:data:`UNBOUNDED_NOTE` when no factor bounds the live load, else
        :data:`ASSOCIATED_NOTE` when sliding takes part in an associated mechanism, and
        :data:`ANISOTROPIC_NOTE` for a model that is not isotropic."""
        notes = []
        if self.status == "unbounded":
            notes.append(UNBOUNDED_NOTE)
        elif self.sliding > 0 and self.friction_law == "associated":
            notes.append(ASSOCIATED_NOTE)
        if not self.cone.is_isotropic:
            notes.append(ANISOTROPIC_NOTE)
        return "; ".join(notes) if notes else None

    def to_dict(self) -> dict:
        """Plain values for run.json: :data:`RESULT_KEYS`, ``live_load`` and, after a
        search, every azimuth's factor."""
        out = {}
        for key in RESULT_KEYS:
            value = getattr(self, key)
            out[key] = value.item() if isinstance(value, np.generic) else value
        out["live_load"] = self.live.description
        if self.azimuths:
            out["azimuths"] = [{"azimuth_deg": a, "load_factor": f} for a, f in self.azimuths]
        return out


def _count(flags) -> int:
    """How many interfaces ``flags`` marks; -1 without a mechanism (None)."""
    return -1 if flags is None else int(flags.sum())


def _main(flags, motion) -> np.ndarray:
    """Of the interfaces flagged, those whose motion is at least :data:`MECHANISM_MAIN`
    of the largest among them."""
    if not flags.any():
        return flags
    return flags & (motion >= MECHANISM_MAIN * motion[flags].max())


@dataclass(frozen=True, eq=False)
class _Columns:
    """The LP's columns ``g`` and their constraints, for the general solvers.

    Parameters
    ----------
    edges : (4 IV, n) scipy.sparse.csr_array
        ``x = edges g``: the vertex forces in the
        :class:`~masonry.rbe.equilibrium.VariableLayout` order.
    G : (k, n) scipy.sparse.csc_array
    h : (k,) float
        The cone constraints ``h - G g in cones`` (Clarabel's form).
    cones : list
        Clarabel's cones of those rows, in order.
    is_rays : bool
        ``g >= 0`` is every constraint (a pyramid's edge rays): HiGHS takes it as
        column bounds.
    """

    edges: sp.csr_array
    G: sp.csc_array
    h: np.ndarray
    cones: list
    is_rays: bool


def _selection(layout) -> sp.csr_array:
    """(4 IV, 3 IV): the columns ``(c, f1, f2)`` of every vertex, in that order."""
    picked = np.stack([layout.columns(name) for name in ("c", "f1", "f2")], axis=1)
    count = picked.size
    return sp.csr_array((np.ones(count), (picked.ravel(), np.arange(count))),
                        shape=(layout.n_columns, count))


def _cone_columns(system) -> _Columns:
    """The friction model's columns: a pyramid's edge ray weights ``g >= 0``, or the
    forces ``(c, f1, f2)`` with ``(mu c, f1, f2)`` in the second-order cone."""
    n_vertices, cone, mu = system.layout.n_vertices, system.cone, system.mu
    if cone.is_polyhedral:
        edges = friction_edges(n_vertices, cone, mu)
        n = edges.shape[1]
        return _Columns(edges, sp.csc_array(-sp.identity(n)), np.zeros(n),
                        [clarabel.NonnegativeConeT(n)], is_rays=True)
    scale = sp.kron(sp.identity(n_vertices), sp.diags_array([mu, 1.0, 1.0]))
    return _Columns(_selection(system.layout), sp.csc_array(-scale),
                    np.zeros(3 * n_vertices),
                    [clarabel.SecondOrderConeT(3)] * n_vertices, is_rays=False)


def _capacity_columns(system, capacity) -> _Columns:
    """The forces ``(c, f1, f2)`` with ``c >= 0`` and the friction within the model at a
    fixed capacity ``capacity`` ((IV,) float) instead of ``mu c``: a disc of that radius
    (the circle), the pyramid's polygon at that radius (its faces ``f . normal_k <=
    capacity rho cos(pi / K)``)."""
    n_vertices, cone = system.layout.n_vertices, system.cone
    capacity = np.asarray(capacity, dtype=float)
    vertex = np.arange(n_vertices)
    # c >= 0: -(-c) in the nonnegative cone
    rows = [sp.csc_array((-np.ones(n_vertices), (vertex, 3 * vertex)),
                         shape=(n_vertices, 3 * n_vertices))]
    h = [np.zeros(n_vertices)]
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
        cones = [clarabel.NonnegativeConeT(n_vertices + len(row))]
    else:
        # (capacity, f1, f2) in the second-order cone
        row = 3 * vertex[:, None] + [1, 2]
        rows.append(sp.csc_array((-np.ones(2 * n_vertices),
                                  (row.ravel(), (3 * vertex[:, None] + [1, 2]).ravel())),
                                 shape=(3 * n_vertices, 3 * n_vertices)))
        cone_h = np.zeros((n_vertices, 3))
        cone_h[:, 0] = capacity
        h.append(cone_h.ravel())
        cones = ([clarabel.NonnegativeConeT(n_vertices)]
                 + [clarabel.SecondOrderConeT(3)] * n_vertices)
    return _Columns(_selection(system.layout), sp.csc_array(sp.vstack(rows)),
                    np.concatenate(h), cones, is_rays=False)


class CollapseLP:
    """One model's collapse LP, kept by its solver between load cases.

    The matrix ``A_eq E`` is built once. :meth:`solve` takes any live load;
    :meth:`solve_lateral` keeps a second model whose two load columns are the lateral
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
        The friction model (:mod:`masonry.friction`; default Coulomb's cone).
    time_limit : float, s
        HiGHS's and Clarabel's limit per solve.
    method : str, optional
        One of :data:`METHODS`; default :data:`METHOD`.
    cores : int, optional
        The cores a solve may use: its factorizations on up to two threads
        (:func:`~masonry.rbe.solvers.cholesky.factor_threads`), BLAS on one. Default: the
        process's (:func:`masonry.forking.cores`).

    Raises
    ------
    ValueError
        A HiGHS method for the circle (HiGHS solves linear programs only).
    """

    def __init__(self, model, *, mu=0.7, density=2000.0, cone="circle", time_limit=600.0,
                 method=None, cores=None):
        self.model = model
        self.system = assemble(model.blocks, model.interfaces, mu=mu, density=density,
                               side_block=model.side_block,
                               side_rotation=model.side_rotation, cone=cone)
        self.method = METHOD if method is None else method
        if self.method not in METHODS:
            raise ValueError(f"unknown collapse method {self.method!r}; choose from "
                             f"{list(METHODS)}")
        if self.method in HIGHS_METHODS and not self.system.cone.is_polyhedral:
            raise ValueError(f"HiGHS ({self.method}) solves linear programs: the friction "
                             f"model {self.system.cone} needs interior or clarabel, or a "
                             f"polygon:K model")
        self.columns = _cone_columns(self.system)
        self.matrix = sp.csc_array(self.system.A_eq @ self.columns.edges)
        self.mu, self.density, self.time_limit = float(mu), float(density), time_limit
        self.cores = cores
        self._lateral = None
        self._newton_system = None  # the interior point method's, made on first use

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
        """(6 F,) float: a live load in the rows' scaling (free blocks only)."""
        wrench = live.wrench[self.system.free_block].ravel()
        return wrench / self.system.row_scale

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
            lp = self._backend(load[:, None] / ratio, np.ones(1))
            return self._result(lp, live, None, start, dead_load_feasible,
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
                self._lateral = self._backend(loads, np.array([cos, sin]), tie=(-sin, cos))
            else:
                self._lateral.direct(cos, sin)
            live = lateral(self.model, azimuth_deg, self.density)
            return self._result(self._lateral, live, float(azimuth_deg) % 360.0, start,
                                dead_load_feasible)

    def _backend(self, loads, cost, tie=None):
        def clarabel_lp():
            return _ClarabelLP(self.matrix, loads, -self.system.f_ext, cost, tie,
                               self.time_limit, self.columns)

        if self.method == "clarabel":
            return clarabel_lp()
        if self.method == "interior":
            if self._newton_system is None:
                self._newton_system = NewtonSystem(self.system, "net")
            return _InteriorLP(self._newton_system, self.system.layout, loads, cost,
                               clarabel_lp)
        return _HighsLP(*self._highs(loads, cost, tie), self)

    def _load_columns(self, loads):
        """Columns and link rows for ``loads`` ((6 F, m) float), one chain per load.

        A load column touches every loaded row, and one dense column makes an interior
        point method's normal equations dense. So each load gets one factor column per
        loaded block (its six rows), chained equal by link rows ``lambda_i - lambda_i+1
        = 0``: every column stays sparse. Returns the sparse columns ((6 F, c)), the link
        rows ((r, c)) and the first column of each chain, the one that stands for its
        ``lambda``."""
        columns, links, heads, start = [], [], [], 0
        for load in loads.T:
            per_block = load.reshape(-1, 6)
            blocks = np.flatnonzero(np.abs(per_block).max(axis=1) > 0)
            if len(blocks) == 0:
                raise ValueError("the live load is zero on every free block")
            rows = (6 * blocks[:, None] + np.arange(6)).ravel()
            chain = np.repeat(np.arange(len(blocks)), 6)
            columns.append(sp.csc_array((load[rows], (rows, chain)),
                                        shape=(len(load), len(blocks))))
            link = np.arange(len(blocks) - 1)
            links.append(sp.csc_array((np.r_[np.ones(len(link)), -np.ones(len(link))],
                                       (np.r_[link, link], np.r_[link, link + 1])),
                                      shape=(len(link), len(blocks))))
            heads.append(start)
            start += len(blocks)
        return sp.hstack(columns, format="csc"), sp.block_diag(links, format="csc"), heads

    def _highs(self, loads, cost, tie=None):
        """A HiGHS model: columns ``g`` (>= 0), then the free load-factor chains of
        :meth:`_load_columns`; equilibrium rows, link rows, and a row tying two loads to
        one direction. Returns ``(highs, head columns, tie row)``."""
        system, n = self.system, self.matrix.shape[1]
        columns, links, heads = self._load_columns(loads)
        heads = np.asarray(heads, dtype=np.int32) + n
        A = sp.vstack([sp.hstack([self.matrix, columns]),
                       sp.hstack([sp.csc_array((links.shape[0], n)), links])], format="csc")
        lower = np.concatenate([-system.f_ext, np.zeros(links.shape[0])])
        tie_row = A.shape[0]
        if tie is not None:
            A = sp.vstack([A, sp.csc_array((np.asarray(tie), ([0, 0], heads)),
                                           shape=(1, A.shape[1]))], format="csc")
            lower = np.append(lower, 0.0)
        col_cost = np.zeros(A.shape[1])
        col_cost[heads] = cost
        free = np.full(A.shape[1] - n, highspy.kHighsInf)
        highs = highs_lp(A, col_cost, np.concatenate([np.zeros(n), -free]),
                         np.concatenate([np.full(n, highspy.kHighsInf), free]),
                         lower, lower,
                         (*HIGHS_METHODS[self.method].items(),
                          ("time_limit", float(self.time_limit)),
                          ("primal_feasibility_tolerance", FEASIBILITY_TOL),
                          ("dual_feasibility_tolerance", FEASIBILITY_TOL)), maximize=True)
        return highs, heads, tie_row

    def _result(self, lp, live, azimuth, start, dead_load_feasible,
                per_unit=1.0) -> CollapseResult:
        """The result of ``lp`` run, whose factor times ``per_unit`` is ``live``'s."""
        status, factor, x_scaled, dual, iterations = lp.run()
        common = dict(solver=lp.name, mu=self.mu, live=live, azimuth_deg=azimuth,
                      iterations=iterations, cone=self.cone)
        if status != "optimal":
            feasible = False if status == "dead load infeasible" else dead_load_feasible
            if status == "unbounded" and feasible is None:
                feasible = lp.stands_unloaded()
            if status not in ("dead load infeasible", "unbounded"):
                log.warning("collapse LP without a verdict: %s", status)
            return CollapseResult(None, feasible, status, time_s=time.perf_counter() - start,
                                  residual=np.nan, work_balance=np.nan, **common)
        factor *= per_unit
        load = self.scaled(live)
        total = self.system.f_ext + factor * load
        residual = float(np.abs(self.system.A_eq @ x_scaled + total).max()
                         / np.abs(total).max())
        if factor < 0:
            # the largest factor is negative: lambda = 0 is past it
            dead_load_feasible = False
        elif dead_load_feasible is None:
            dead_load_feasible = lp.stands_unloaded()
        motion = self._mechanism(dual[: self.system.A_eq.shape[0]], load, factor)
        x = self.system.to_newtons(x_scaled)
        log.debug("collapse LP: lambda %.6g, %d iterations", factor, iterations)
        return CollapseResult(
            factor if dead_load_feasible else None, dead_load_feasible,
            "optimal" if dead_load_feasible else "dead load infeasible",
            time_s=time.perf_counter() - start, residual=residual, x=x,
            forces=interface_forces(self.system.layout, x), **motion, **common)

    def _mechanism(self, dual, load, factor) -> dict:
        """Mechanism, per-interface flags and the work balance from the equilibrium rows'
        dual ``y`` ((6 F,) float, scaled) and the scaled live load."""
        system, blocks = self.system, self.model.blocks
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


class _HighsLP:
    """A collapse LP held by HiGHS: ``run`` from the last basis, the load factors fixed at
    0 for the dead load check, a new lateral direction."""

    def __init__(self, highs, heads, tie_row, parent):
        self.highs, self.heads, self.tie_row = highs, heads, tie_row
        self.name = parent.method
        self.edges, self.time_limit = parent.columns.edges, parent.time_limit

    def _status(self) -> str:
        # HiGHS's time limit counts from its creation: give every run its own
        self.highs.setOptionValue("time_limit", self.highs.getRunTime() + self.time_limit)
        self.highs.run()
        Status = highspy.HighsModelStatus
        status = self.highs.getModelStatus()
        if status == Status.kUnboundedOrInfeasible:
            # presolve's verdict does not say which; the solver without it does
            self.highs.setOptionValue("presolve", "off")
            self.highs.run()
            self.highs.setOptionValue("presolve", "choose")
            status = self.highs.getModelStatus()
        return {Status.kOptimal: "optimal", Status.kInfeasible: "dead load infeasible",
                Status.kUnbounded: "unbounded"}.get(
                    status, self.highs.modelStatusToString(status))

    def run(self):
        """``(status, factor, vertex forces (scaled, the layout's order), row duals,
        iterations)``."""
        status = self._status()
        info = self.highs.getInfo()
        iterations = int(info.simplex_iteration_count + info.ipm_iteration_count)
        if status != "optimal":
            return status, None, None, None, iterations
        solution = self.highs.getSolution()
        values = np.array(solution.col_value)[:self.edges.shape[1]]
        return (status, float(info.objective_function_value), self.edges @ values,
                np.array(solution.row_dual), iterations)

    def stands_unloaded(self) -> bool | None:
        zeros = np.zeros(len(self.heads))
        self.highs.changeColsBounds(len(self.heads), self.heads, zeros, zeros)
        status = self._status()
        self.highs.changeColsBounds(len(self.heads), self.heads, zeros - highspy.kHighsInf,
                                    zeros + highspy.kHighsInf)
        return {"optimal": True, "dead load infeasible": False}.get(status)

    def direct(self, cos, sin):
        self.highs.changeCoeff(self.tie_row, self.heads[0], -sin)
        self.highs.changeCoeff(self.tie_row, self.heads[1], cos)
        self.highs.changeColsCost(2, self.heads, np.array([cos, sin]))


class _InteriorLP:
    """A collapse LP solved by :func:`masonry.rbe.solvers.interior_lp.load_factor`: the
    load columns ``loads`` combined by ``cost`` (a lateral direction: ``cos, sin``) into
    one live load. Without an optimum it hands the LP to the :class:`_ClarabelLP` of the
    same LP, which tells infeasible from unbounded; ``make_fallback`` builds that one
    when it is first needed (on preset 1's dome its KKT matrix takes half a second)."""

    def __init__(self, newton_system, layout, loads, cost, make_fallback):
        self.ns, self.loads, self.make_fallback = newton_system, loads, make_fallback
        self.layout = layout
        self.cost = np.asarray(cost, dtype=float)
        self.name, self._fallback = "interior", None

    def fallback(self):
        """The Clarabel LP, set to the current direction."""
        if self._fallback is None:
            self._fallback = self.make_fallback()
        if len(self.cost) == 2:
            self._fallback.direct(*self.cost)
        return self._fallback

    def run(self):
        """``(status, factor, vertex forces (scaled, the layout's order),
        equilibrium-row duals, iterations)``."""
        outcome = load_factor(self.ns, self.loads @ self.cost, LoadFactorOptions())
        self.name = "interior"
        if outcome.status != OPTIMAL:
            log.info("collapse LP: the interior point method found no optimum (%s); "
                     "Clarabel decides", outcome.status)
            self.name = "interior+clarabel"
            return self.fallback().run()
        return ("optimal", outcome.info["load_factor"],
                self.ns.full_vector(outcome.x, self.layout), outcome.y, outcome.iterations)

    def stands_unloaded(self) -> bool | None:
        """The feasible factors are an interval: ``lambda = 0`` lies in it when the
        largest factor of the reversed load is also at least 0."""
        reversed_load = load_factor(self.ns, -(self.loads @ self.cost), LoadFactorOptions())
        if reversed_load.status == OPTIMAL:
            return reversed_load.info["load_factor"] >= 0
        return self.fallback().stands_unloaded()

    def direct(self, cos, sin):
        self.cost = np.array([cos, sin])


class _ClarabelLP:
    """A collapse LP held by Clarabel (interior point, direct LDL): ``minimize -cost .
    lambda`` over ``[g, lambda]`` with the equilibrium (and tie) rows in the zero cone and
    the columns' cone constraints (:class:`_Columns`) after them. A new lateral direction
    updates two entries of ``A`` and the costs in place, which keeps the symbolic
    factorization."""

    def __init__(self, matrix, loads, rhs, cost, tie, time_limit, columns: _Columns):
        n, m = matrix.shape[1], loads.shape[1]
        top = sp.hstack([matrix, sp.csc_array(loads)])
        rows = [top]
        if tie is not None:
            rows.append(sp.csc_array((np.asarray(tie, dtype=float), ([0, 0], [n, n + 1])),
                                     shape=(1, n + m)))
        self.n_eq = sum(r.shape[0] for r in rows)
        rows.append(sp.hstack([columns.G, sp.csc_array((columns.G.shape[0], m))]))
        self.cones = [clarabel.ZeroConeT(self.n_eq), *columns.cones]
        self.A = sp.csc_matrix(sp.vstack(rows, format="csc"))
        self.A.sort_indices()
        self.b = np.concatenate([rhs, np.zeros(self.n_eq - len(rhs)), columns.h])
        self.q = np.concatenate([np.zeros(n), -np.asarray(cost, dtype=float)])
        self.n, self.m, self.time_limit = n, m, time_limit
        self.edges = columns.edges
        if tie is not None:  # where the tie row's two entries sit in A.data
            self.tie_at = [self.A.indptr[c] + np.flatnonzero(
                self.A.indices[self.A.indptr[c]:self.A.indptr[c + 1]] == self.n_eq - 1)[0]
                for c in (n, n + 1)]
        self.solver = None
        self.name = "clarabel"

    def _settings(self):
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.presolve_enable = False  # keep the rows: data updates need them
        settings.time_limit = float(self.time_limit)
        for name, value in CLARABEL_SETTINGS.items():
            setattr(settings, name, value)
        return settings

    def run(self):
        """``(status, factor, vertex forces (scaled, the layout's order), equality-row
        duals, iterations)``."""
        if self.solver is None:
            size = self.n + self.m
            self.solver = clarabel.DefaultSolver(sp.csc_matrix((size, size)), self.q,
                                                 self.A, self.b, self.cones, self._settings())
        solution = self.solver.solve()
        status = str(solution.status)
        words = {"Solved": "optimal", "AlmostSolved": "optimal",
                 "PrimalInfeasible": "dead load infeasible",
                 "DualInfeasible": "unbounded"}.get(status, status)
        if status == "AlmostSolved":
            x = np.array(solution.x)
            residual = np.abs(self.A[: self.n_eq] @ x - self.b[: self.n_eq]).max()
            # kept when it meets the acceptance tolerance (with a warning)
            if residual > ACCEPT_RESIDUAL * np.abs(self.b[: self.n_eq]).max():
                words = status
            else:
                log.warning("Clarabel: almost solved, kept (relative residual %.1e)",
                            residual / np.abs(self.b[: self.n_eq]).max())
        if words != "optimal":
            return words, None, None, None, int(solution.iterations)
        x = np.array(solution.x)
        return (words, float(-self.q[self.n:] @ x[self.n:]), self.edges @ x[:self.n],
                np.array(solution.z), int(solution.iterations))

    def stands_unloaded(self) -> bool | None:
        """The dead load alone: the load columns dropped, a zero objective."""
        A = sp.csc_matrix(self.A[:, : self.n])
        solver = clarabel.DefaultSolver(sp.csc_matrix((self.n, self.n)), np.zeros(self.n),
                                        A, self.b, self.cones, self._settings())
        status = str(solver.solve().status)
        return {"Solved": True, "PrimalInfeasible": False}.get(status)

    def direct(self, cos, sin):
        self.A.data[self.tie_at[0]], self.A.data[self.tie_at[1]] = -sin, cos
        self.q[self.n:] = (-cos, -sin)
        if self.solver is not None:
            self.solver.update(q=self.q, A=self.A)


def collapse_load(model, live: LiveLoad, *, mu=0.7, density=2000.0, cone="circle",
                  friction=None, dead_load_feasible=None, time_limit=600.0,
                  cores=None) -> CollapseResult:
    """The collapse load factor of ``live`` on ``model``, and its mechanism (SPEC 6.8-6.9).

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
                         cores=cores)
    if friction in (None, "associated"):
        return problem.solve(live, dead_load_feasible=dead_load_feasible)
    if friction == "non-associative":
        return fixed_capacity_factor(problem, live, dead_load_feasible=dead_load_feasible)
    raise ValueError(f"friction must be 'associated' (or None) or 'non-associative', not "
                     f"{friction!r}")


NON_ASSOCIATIVE_ROUNDS = 30
"""Most re-solves of :func:`fixed_capacity_factor`."""


def fixed_capacity_factor(problem: CollapseLP, live: LiveLoad, *, dead_load_feasible=None,
                          rounds=NON_ASSOCIATIVE_ROUNDS, rtol=1e-3) -> CollapseResult:
    """A non-associative estimate of the load factor (SPEC 6.8's friction-law note).

    Start from the associated LP; then fix every vertex's friction capacity at ``mu``
    times its compression at the last collapse (:meth:`CollapseLP.with_friction_capacity`:
    a capacity that does not grow with the compression lets joints slide without
    dilating) and solve again, until the factor changes by less than ``rtol`` in two
    rounds running. This is the iterative scheme of Gilbert, Casapulla and Ahmed (2006,
    Comput. Struct. 84) for non-associative frictional joints: an estimate, not a bound,
    that removes the dilatancy by which the associated factor overestimates a sliding
    collapse. Between rounds a joint's friction may exceed ``mu`` times its compression,
    so only a settled factor is reported: after ``rounds`` (at least 2) re-solves
    without one, or a round whose capacities admit no equilibrium, the factor and the
    mechanism are None (the status says which). The LP's optimum is degenerate, so the
    factor wanders by a few 1e-3 as it settles (the small dome of docs/collapse.md: 0.586
    to 0.590 from the 14th round). ``friction_law`` of the result says
    ``non-associative``; ``associated_factor`` keeps the starting factor.
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
    settled = 0
    for done in range(1, rounds + 1):
        compression = problem.system.to_scaled(result.x).reshape(-1, 4)[:, 0]
        following = problem.with_friction_capacity(problem.mu * compression).solve(
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


def lateral_azimuths(n_webs=None, count=24) -> np.ndarray:
    """Azimuths in degrees for :func:`worst_lateral`: ``count`` equally spaced, plus the
    directions a dome's symmetry makes special (the mid-planes of the webs and the corners,
    every ``180 / n`` degrees), sorted and unique."""
    angles = np.arange(count) * 360.0 / count
    if n_webs is not None:
        angles = np.concatenate([angles, np.arange(2 * n_webs) * 180.0 / n_webs])
    return np.unique(np.round(angles % 360.0, 9))


def worst_lateral(model, azimuths=None, *, mu=0.7, density=2000.0, cone="circle",
                  n_webs=None, period_deg=None, dead_load_feasible=None, time_limit=600.0,
                  method=None, cores=None) -> CollapseResult:
    """The smallest lateral load factor over ``azimuths`` (``--lateral all``).

    One LP serves every azimuth (:meth:`CollapseLP.solve_lateral`: the interior point
    method and Clarabel keep their symbolic factorization, HiGHS's simplex restarts from
    the last basis), ``method`` one of :data:`METHODS`, and the dead load is checked once
    (unless ``dead_load_feasible`` is given); on large models, when ``cores`` (default
    the process's, :func:`masonry.forking.cores`) allow two, two azimuths at once
    (:func:`masonry.forking.two_at_once`). ``period_deg``: the model repeats under a
    rotation by this angle about the z axis (a full dome of ``n`` webs: ``360 / n``), so
    azimuths that differ by it have the same factor and each is solved once. Returns the
    worst azimuth's result with every azimuth's factor in ``azimuths`` ((azimuth, factor
    or None) pairs).
    """
    azimuths = lateral_azimuths(n_webs) if azimuths is None else np.asarray(azimuths, float)
    problem = CollapseLP(model, mu=mu, density=density, cone=cone, time_limit=time_limit,
                         method=method, cores=cores)
    start = time.perf_counter()
    keys = [round(float(a) % period_deg, 9) if period_deg else float(a) for a in azimuths]
    todo = {}
    for key, azimuth in zip(keys, azimuths):
        todo.setdefault(key, float(azimuth))
    solved = _solve_azimuths(problem, list(todo.items()), dead_load_feasible,
                             two=forking.usable_cores(cores) >= 2)
    results = []
    for key in keys:
        if key not in solved:  # the dead load cannot stand: the search ended
            break
        results.append(solved[key])
        if solved[key].dead_load_feasible is False:
            break
    log.info("lateral search: %d azimuths, %d solved", len(results), len(solved))
    factors = [(float(a), r.load_factor) for a, r in zip(azimuths, results)]
    found = [r for r in results if r.load_factor is not None]
    worst = results[-1]
    if found:
        least = min(r.load_factor for r in found)
        worst = next(r for r in found
                     if r.load_factor <= least + FACTOR_TIE_REL * abs(least))
    return dataclasses.replace(worst, azimuths=tuple(factors),
                               time_s=time.perf_counter() - start)


def _solve_azimuths(problem, todo, known, two) -> dict:
    """Solve the ``(key, azimuth)`` pairs of ``todo`` in order, each told what the earlier
    ones found of the dead load; once it is known to stand, and when ``two`` cores may be
    used, the rest two at once on a large model (:func:`masonry.forking.two_at_once`).
    Returns key -> :class:`CollapseResult`; ends at the first that finds the dead load
    cannot stand."""
    solved = {}
    for index, (key, azimuth) in enumerate(todo):
        # the interior point method factors on this process's cores; Clarabel and HiGHS
        # keep their own threads, and HiGHS's simplex gains from one model's warm starts
        if known is True and two and problem.method == "interior":
            keys, azimuths = zip(*todo[index:])
            standing = functools.partial(problem.solve_lateral, dead_load_feasible=True)
            solved.update(zip(keys, forking.two_at_once(
                standing, azimuths, blocks=len(problem.system.free_block))))
            break
        solved[key] = problem.solve_lateral(azimuth, dead_load_feasible=known)
        known = solved[key].dead_load_feasible
        if known is False:
            break
    return solved
