"""The least adhesion: the least uniform strength of mortar with which a structure (or a
construction stage) stands under its own weight without centering (docs/model.md 6.12).

With the scaled matrices of :mod:`masonry.rbe.equilibrium` for dry joints (``A_eq``,
``f_ext`` the self weight) and the contact law of :mod:`masonry.contact` with cohesion
``c = a`` and tensile strength ``t_c = r a`` (``r`` the tension ratio)::

    minimize    a
    subject to  A_eq x + f_ext = 0                 6 rows per free block
                ||f_i|| <= mu n_i + a A_i          every vertex (a pyramid: each face
                                                   shifted, as the law's)
                n_i >= -r a A_i
                a >= 0

``A_i`` the vertex's tributary area (:func:`masonry.contact.tributary_area`). Cohesion is
the cone's shift (:mod:`masonry.contact`): with the shifted compression ``c~_i = n_i + a
A_i / mu`` the friction model is the dry one in ``(c~, f)``, and ``a`` enters linearly,
as one column of the equilibrium rows (``-a A_eq[:, c] A / mu``) and of the cut-off rows
``c~_i >= a A_i (1 / mu - r)`` (where ``r < 1 / mu``; beyond, the cone's apex is the
cut-off). So ``a`` is one more variable of a conic program, solved once, not a
bisection: by the own interior point method on the Newton method's matrix
(:mod:`masonry.rbe.solvers.interior_adhesion`, which a stage sequence runs on the
symbolic factorization its RBE solve made), and where that ends without a checked
optimum by Clarabel on the collapse program's columns
(:func:`masonry.rbe.collapse.friction_columns`,
:func:`masonry.rbe.solvers.direct_clarabel.solve_cone_program`), which also tells an
infeasible program. The program is always feasible for a large enough ``a`` where every
block touches a joint and tension holds (``r > 0``), and bounded below by 0: it has an
optimum, which is 0 exactly when the structure stands dry.

Scaling: forces in units of the reference weight ``W_ref``, moment rows divided by
``L_ref`` (the RBE's); ``a`` in units of ``W_ref / A_ref``, ``A_ref`` the mean tributary
area, so that the shift column is of order one. The equilibrium residual and the law's
violation at ``a*`` are recomputed from the returned point (:func:`_residuals`); a point
beyond :data:`~masonry.tolerances.ACCEPT_RESIDUAL` gives no value.
"""

import logging
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from masonry.contact import TENSION_RATIO, ContactLaw, joint_factor
from masonry.errors import MasonryError, ParameterError
from masonry.interfaces import INTERFACE_KINDS
from masonry.rbe.collapse import friction_columns
from masonry.rbe.equilibrium import EquilibriumSystem, assemble
from masonry.rbe.solvers import interior_adhesion
from masonry.rbe.solvers.base import OPTIMAL, OPTIMAL_INACCURATE
from masonry.rbe.solvers.direct_clarabel import solve_cone_program
from masonry.rbe.solvers.newton import NewtonSystem
from masonry.rbe.solvers.program import NONNEGATIVE
from masonry.tolerances import ACCEPT_RESIDUAL, ADHESION_REPORTED_REL

log = logging.getLogger(__name__)

SOLVER = "clarabel"
INTERIOR = "interior"
SOLVERS = (INTERIOR, SOLVER)
"""The solvers of the program: the own interior point method (default; Clarabel where it
ends without a checked optimum), or Clarabel alone (module docstring)."""

RESULT_KEYS = ("a_kPa", "ratio", "friction_model", "mu", "status", "solver",
               "iterations", "time_s", "residual_eq", "law_violation", "reason")
"""Scalar fields of :class:`AdhesionResult` in run.json, in order (then ``joints``)."""

TOP_JOINTS = 3
"""The joints named in the summary line and in run.json's ``joints``."""


class AdhesionRatioError(MasonryError, ValueError):
    """A tension ratio that is negative or not finite."""


def check_ratio(ratio) -> float:
    """``ratio`` as a float, or :class:`AdhesionRatioError` naming it."""
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) \
            or not np.isfinite(ratio) or ratio < 0:
        raise AdhesionRatioError(f"ratio {ratio!r}: expected a finite number >= 0")
    return float(ratio)


@dataclass(frozen=True, eq=False)
class AdhesionResult:
    """The least adhesion of a structure (module docstring).

    Parameters
    ----------
    a_kPa : float or None
        ``a*``, kPa; None when the program was not solved or its point failed the check
        (``status`` and ``reason`` say why).
    ratio : float
        ``t_c / c``.
    interface_kPa : (K,) float
        The adhesion every interface uses at the optimum, kPa: over its vertices the
        largest ``max((||f|| - mu n) / A_i, -n / (r A_i))`` (0 where dry joints carry
        it; zeros without a solution).
    interface_pair : (K, 2) int
    interface_kind : (K,) int
        Code into :data:`~masonry.interfaces.INTERFACE_KINDS`.
    law : ContactLaw
        The friction model and ``mu`` (dry; the program's adhesion is ``a``).
    status : str
    iterations : int
    time_s : float, s
    residual_eq : float
        ``||A_eq x + f_ext||_inf / ||f_ext||_inf``, recomputed (scaled rows).
    law_violation : float
        The largest excess of a vertex force over the law at ``a*``, per reference
        weight, recomputed.
    reason : str
        Why there is no value ('' when there is one).
    """

    a_kPa: float | None
    ratio: float
    interface_kPa: np.ndarray
    interface_pair: np.ndarray
    interface_kind: np.ndarray
    law: ContactLaw
    status: str
    iterations: int
    time_s: float
    residual_eq: float
    law_violation: float
    reason: str = ""
    solver: str = SOLVER

    @property
    def mu(self) -> float:
        return self.law.mu

    @property
    def friction_model(self) -> str:
        return self.law.cone.name

    @property
    def needing(self) -> np.ndarray:
        """(k,) int: the interfaces that use more than
        :data:`~masonry.tolerances.ADHESION_REPORTED_REL` of ``a*``, most first."""
        if not self.a_kPa:
            return np.zeros(0, dtype=np.int64)
        rows = np.flatnonzero(self.interface_kPa > ADHESION_REPORTED_REL * self.a_kPa)
        return rows[np.argsort(-self.interface_kPa[rows], kind="stable")]

    def law_at(self, margin=1.0) -> ContactLaw:
        """The contact law with ``c = margin a*`` and ``t_c = r c`` (None without a*)."""
        cohesion = margin * 1e3 * self.a_kPa
        return ContactLaw(self.law.cone, self.law.mu, cohesion, self.ratio * cohesion)

    def joints(self, names) -> list:
        """The :data:`TOP_JOINTS` interfaces that need most, as dicts (``interface``,
        ``blocks`` named by ``names`` per model block, ``kind``, ``adhesion_kPa``)."""
        return [{"interface": int(k),
                 "blocks": [str(names[b]) for b in self.interface_pair[k]],
                 "kind": INTERFACE_KINDS[self.interface_kind[k]],
                 "adhesion_kPa": float(self.interface_kPa[k])}
                for k in self.needing[:TOP_JOINTS]]

    def to_dict(self, names) -> dict:
        """Plain values for run.json: :data:`RESULT_KEYS` and ``joints``."""
        out = {key: getattr(self, key) for key in RESULT_KEYS}
        out = {k: v.item() if isinstance(v, np.generic) else v for k, v in out.items()}
        out["joints"] = self.joints(names)
        return out


def least_adhesion(model, *, mu=0.7, density=2000.0, cone="circle", ratio=TENSION_RATIO,
                   head_ratio=1.0, support_ratio=1.0, time_limit=600.0,
                   solver=INTERIOR) -> AdhesionResult:
    """The least uniform adhesion with which ``model`` stands (module docstring).

    Parameters
    ----------
    model : masonry.rbe.boundary.Model
        A structure or a construction stage.
    mu : float
    density : float, kg/m^3
    cone : FrictionCone or str
        The friction model (:mod:`masonry.friction`).
    ratio : float
        ``t_c / c``, >= 0 (:data:`TENSION_RATIO`).
    head_ratio, support_ratio : float
        Head joints and joints with a support hold these fractions of ``a``
        (:func:`masonry.contact.joint_factor`); ``a*`` is the bed joints'.
    time_limit : float, s
        Clarabel's.
    solver : str
        One of :data:`SOLVERS`.

    Returns
    -------
    AdhesionResult

    Raises
    ------
    AdhesionRatioError, masonry.contact.ContactLawError
        A ratio, ``mu`` or model out of range.
    """
    ratio = check_ratio(ratio)
    law = ContactLaw.of(cone, mu)
    if len(model.interfaces) == 0:
        return _unsolved(model.interfaces, law, ratio, "no joints: the blocks touch nothing")
    system = assemble(model.blocks, model.interfaces, mu=mu, density=density,
                      side_block=model.side_block, side_rotation=model.side_rotation,
                      cone=cone)
    return solve_adhesion(system, model.interfaces, ratio=ratio, head_ratio=head_ratio,
                          support_ratio=support_ratio, time_limit=time_limit, solver=solver)


def solve_adhesion(system: EquilibriumSystem, interfaces, *, ratio=TENSION_RATIO,
                   head_ratio=1.0, support_ratio=1.0, time_limit=600.0, solver=INTERIOR,
                   symbolic=None) -> AdhesionResult:
    """:func:`least_adhesion` on assembled matrices (their friction model and ``mu``;
    a mortar they carry is dropped: ``a`` is the program's): by the own interior point
    method (:mod:`masonry.rbe.solvers.interior_adhesion`, on ``symbolic``, the
    :class:`~masonry.rbe.solvers.cholesky.BlockCholesky` analysis of the system's
    blocks, made here when None), and by Clarabel where that ends without a checked
    optimum; by Clarabel alone with ``solver`` ``clarabel``."""
    start = time.perf_counter()
    ratio = check_ratio(ratio)
    if solver not in SOLVERS:
        raise ParameterError("solver", solver, f"one of {', '.join(SOLVERS)}")
    system = system.with_material(cohesion=0.0, tensile=0.0)
    area_ref, held = _held(system, interfaces, head_ratio, support_ratio)
    if solver == SOLVER:
        return _by_clarabel(system, interfaces, area_ref, held, ratio, time_limit, start)
    ns = NewtonSystem(system, "net", symbolic=symbolic)
    found = interior_adhesion.solve(ns, held, ratio)
    if found.status in (OPTIMAL, OPTIMAL_INACCURATE):
        x = ns.full_vector(found.x, system.layout)
        result = _checked(system, interfaces, x, _clamped(found.point.a), area_ref, held,
                          ratio, found.status, found.iterations, start, INTERIOR)
        if result.a_kPa is not None:
            return result
    log.info("least adhesion: the interior point method ended %s; Clarabel", found.status)
    return _by_clarabel(system, interfaces, area_ref, held, ratio, time_limit, start)


def _clamped(a) -> float:
    """``a`` at least 0: within the acceptance tolerance of standing dry is standing dry
    (the point is checked at 0)."""
    return float(a) if a > ACCEPT_RESIDUAL else 0.0


def _by_clarabel(system, interfaces, area_ref, held, ratio, time_limit,
                 start) -> AdhesionResult:
    """The program solved by Clarabel (module docstring)."""
    columns = friction_columns(system)
    A, b, rows, h, cones = _program(system, columns, held, ratio)
    q = np.zeros(A.shape[1])
    q[-1] = 1.0
    status, z, iterations = solve_cone_program(q, A, b, rows, h, cones, time_limit)
    if z is None:
        log.warning("least adhesion: Clarabel ended %s", status)
        reason = (f"infeasible: no adhesion balances it with tension ratio {ratio:g}"
                  if status == "PrimalInfeasible" else f"Clarabel ended {status}")
        return _unsolved(interfaces, system.law, ratio, reason, status,
                         iterations, time.perf_counter() - start)
    a = _clamped(z[-1])
    x = columns.edges @ z[:-1]
    x[system.layout.columns("c")] -= a * held / system.mu       # the physical n
    return _checked(system, interfaces, x, a, area_ref, held, ratio, status, iterations,
                    start, SOLVER)


def _checked(system, interfaces, x, a, area_ref, held, ratio, status, iterations,
             start, solver) -> AdhesionResult:
    """The result of the program's optimum ``a`` (units of ``W_ref / A_ref``) and its
    physical vertex forces ``x``: the equilibrium residual and the law's violation at
    ``a`` recomputed; a point beyond :data:`~masonry.tolerances.ACCEPT_RESIDUAL` gives
    no value."""
    unit_kPa = system.weight_ref / area_ref / 1e3
    residual, violation = _residuals(system, x, a * held, ratio)
    common = dict(ratio=ratio, interface_pair=np.asarray(interfaces.pair),
                  interface_kind=np.asarray(interfaces.kind), law=system.law,
                  iterations=iterations, time_s=time.perf_counter() - start,
                  residual_eq=residual, law_violation=violation, solver=solver)
    if max(residual, violation) > ACCEPT_RESIDUAL:
        # the interior point method's is not the last word: Clarabel follows
        log.log(logging.INFO if solver == INTERIOR else logging.WARNING,
                "least adhesion: the point of %s (%s) rejected: residual %.1e, law "
                "violation %.1e", solver, status, residual, violation)
        return AdhesionResult(None, interface_kPa=np.zeros(len(interfaces)), status=status,
                              reason=f"the optimum failed its check (residual "
                                     f"{residual:.1e}, law violation {violation:.1e})",
                              **common)
    log.info("least adhesion: %.6g kPa, %d iterations", a * unit_kPa, iterations)
    used = _interface_use(system, x, system.vertex_area / area_ref, ratio) * unit_kPa
    return AdhesionResult(a * unit_kPa, interface_kPa=used, status="optimal", **common)


def _held(system, interfaces, head_ratio, support_ratio) -> tuple:
    """``(A_ref, held)``: the mean tributary area (m^2) and every vertex's strength per
    unit ``a`` in units of it, its tributary area times its joint's factor."""
    area_ref = float(np.mean(system.vertex_area))
    factor = joint_factor(interfaces, head_ratio, support_ratio)
    return area_ref, system.vertex_area / area_ref * factor


def stands_dry(interfaces, law, ratio) -> AdhesionResult:
    """``a* = 0`` without a program: the structure stands with dry joints (its RBE verdict
    is feasible), so no joint needs adhesion."""
    zero = np.zeros(len(interfaces))
    return AdhesionResult(0.0, check_ratio(ratio), zero, np.asarray(interfaces.pair),
                          np.asarray(interfaces.kind), law, "stands dry", 0, 0.0, 0.0, 0.0,
                          solver="none")


def _unsolved(interfaces, law, ratio, reason, status="not solved", iterations=0,
              time_s=0.0) -> AdhesionResult:
    return AdhesionResult(None, ratio, np.zeros(len(interfaces)), np.asarray(interfaces.pair),
                          np.asarray(interfaces.kind), law, status, iterations, time_s,
                          np.nan, np.nan, reason=reason)


def _program(system, columns, area, ratio):
    """``(A, b, G, h, cones)`` over ``z = [g, a]`` (module docstring): the equilibrium
    rows with the shift's column, the friction model's cone rows, then one nonnegative
    cone of the cut-off rows (where ``r < 1 / mu``) and ``a >= 0``. ``area``: each
    vertex's strength per unit ``a``, the tributary area times its joint's factor."""
    layout, mu = system.layout, system.mu
    unit_shift = np.zeros(layout.n_columns)
    unit_shift[layout.columns("c")] = area / mu
    shift_column = -system.times_A_eq(unit_shift)[:, None]
    A = sp.hstack([sp.csc_array(system.A_eq @ columns.edges), sp.csc_array(shift_column)],
                  format="csc")
    friction = sp.hstack([columns.G, sp.csc_array((columns.G.shape[0], 1))])
    n = A.shape[1]
    lower = [sp.csc_array(([-1.0], ([0], [n - 1])), shape=(1, n))]       # a >= 0
    apex = 1.0 / mu - ratio
    if apex > 0:  # c~ >= a A (1 / mu - r): -(c~) + a A (1 / mu - r) <= 0
        compression = sp.csc_array(columns.edges[layout.columns("c")])
        lower.insert(0, sp.hstack([-compression, sp.csc_array((area * apex)[:, None])]))
    bounds = sp.vstack(lower)
    rows = sp.vstack([friction, bounds], format="csc")
    h = np.concatenate([columns.h, np.zeros(bounds.shape[0])])
    cones = (*columns.cones, (NONNEGATIVE, bounds.shape[0], 1))
    return A, -system.f_ext, rows, h, cones


def _capacity_factor(cone) -> float:
    """``k``: a shift ``a A`` widens the friction model by ``k a A`` (1 for the circle,
    the pyramid's apothem per unit ``mu``: its faces' shift)."""
    return 1.0 if not cone.is_polyhedral else cone.apothem(1.0)


def _excess(system, x, shift, ratio) -> tuple:
    """Per vertex, solver units: the friction beyond the model at ``mu n + k shift``, and
    the tension beyond ``r shift`` (``shift = a A_i``)."""
    n, _, f1, f2 = np.asarray(x).reshape(-1, 4).T
    friction = system.cone.excess(n, f1, f2, system.mu) - _capacity_factor(system.cone) * shift
    return friction, -n - ratio * shift


def _residuals(system, x, shift, ratio) -> tuple:
    """``(relative equilibrium residual, law violation per reference weight)`` of the
    physical vertex forces ``x`` (solver units) at the shift ``a A_i``."""
    total = system.times_A_eq(x) + system.f_ext
    residual = float(np.abs(total).max() / np.abs(system.f_ext).max())
    friction, tension = _excess(system, x, shift, ratio)
    return residual, max(0.0, float(friction.max(initial=0.0)),
                         float(tension.max(initial=0.0)))


def _interface_use(system, x, area, ratio) -> np.ndarray:
    """(K,) float, units of ``a``: the adhesion each interface uses (its vertices'
    largest ``max(friction excess / (k A_i), -n / (r A_i))``, at least 0)."""
    n, _, f1, f2 = np.asarray(x).reshape(-1, 4).T
    safe = np.where(area > 0, area, np.inf)
    use = system.cone.excess(n, f1, f2, system.mu) / (_capacity_factor(system.cone) * safe)
    if ratio > 0:
        use = np.maximum(use, -n / (ratio * safe))
    per = np.zeros(system.layout.n_interfaces)
    np.maximum.at(per, system.layout.vertex_interface, use)
    return per
