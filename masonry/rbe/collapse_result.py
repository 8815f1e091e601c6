"""The outcome of a collapse load factor LP (docs/model.md 6.8, 6.9): the factor, its mechanism,
and what they mean (:mod:`masonry.rbe.collapse` computes it)."""

import math
from dataclasses import dataclass, field

import numpy as np

from masonry.contact import ContactLaw
from masonry.friction import FrictionCone
from masonry.rbe.loads import LiveLoad
from masonry.tolerances import ACCEPT_RESIDUAL, MECHANISM_MAIN

ASSOCIATED_NOTE = (
    "sliding interfaces take part in this mechanism: the load factor assumes associated "
    "friction (the friction cone's normal as flow rule, joints that dilate as they slide) "
    "and can overestimate the collapse load of real, non-dilatant joints (docs/model.md 6.8)")

COHESIVE_NOTE = (
    "the joints have mortar: its cohesion and tensile strength are taken as rigid-plastic "
    "with associated flow (no softening once a joint opens or slides), an idealisation "
    "like associated friction's (docs/model.md 6.3)")

ANISOTROPIC_NOTE = (
    "the friction model is the thesis's square pyramid: it carries up to 41 % more "
    "friction than Coulomb's cone where joints slide diagonally to their axes, so this "
    "factor depends on how the model is turned and may be too high")

UNBOUNDED_NOTE = (
    "the live load stands at any factor: rigid blocks pass it to the supports in "
    "compression without a joint reaching its limit (a downward load on the nearly flat "
    "top ring of a dome cut low; a lateral load on a section whose rigid boundary holds "
    "it)")

VERDICTS = ("optimal", "dead load infeasible", "unbounded")
"""The statuses of a decided collapse load factor: any other (a time limit, a solver that
stopped short, a non-associative estimate that did not settle) leaves it without one."""

RESULT_KEYS = ("load_factor", "dead_load_feasible", "status", "solver", "iterations",
               "time_s", "residual", "work_balance", "mu", "friction_model",
               "friction_capacity_error", "azimuth_deg", "opening", "sliding", "hinges",
               "main_hinges", "main_sliding", "friction_law", "associated_factor", "note",
               "solved_on", "contact_law")
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
        ``optimal``, ``dead load infeasible``, ``unbounded`` or the solver's words.
    solver : str
        The backend (:mod:`masonry.rbe.solvers`; ``interior+clarabel`` when Clarabel
        decided for the interior point method, :data:`masonry.rbe.collapse.FALLBACK`).
    iterations : int
        The solver's iterations of this solve.
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
        Per-interface sums (:func:`masonry.rbe.result.interface_forces`).
    mechanism : (B, 6) float or None
        ``(ux, uy, uz, rx, ry, rz)`` per block: translation of the centroid and rotation
        (radians per unit), normalised so the largest displacement of any block vertex is
        1; zero on supports.
    opens, slides, hinge : (K,) bool or None
        Per interface: some vertex separates (relative normal motion >
        :data:`~masonry.tolerances.MOTION_TOL`); some vertex slips; opens with some vertex
        still closed (a hinge, not a separation).
    gap, slip : (K,) float or None
        Per interface: the largest opening (relative motion along the normal) and slip
        (along the plane) of its vertices, per largest block displacement (1). An interior
        point's mechanism moves many joints by little (see ``MOTION_TOL``): these say
        which joints carry it.
    azimuths : tuple of (float, float or None)
        After :func:`~masonry.rbe.lateral_search.worst_lateral`: every azimuth sampled and its factor.
    refined : tuple of (float, float or None)
        After :func:`~masonry.rbe.lateral_search.worst_lateral`: the azimuths its refinement between the samples
        solved, in the order solved, and their factors.
    friction_law : str
        ``associated`` (the LP of docs/model.md 6.8) or ``non-associative`` (see
        :func:`fixed_capacity_factor`).
    associated_factor : float or None
        With ``non-associative``: the associated factor it started from.
    cone : FrictionCone
        The friction model.
    law : ContactLaw
        The contact law (friction model, ``mu``, the mortar's strengths).
    solved_on : {'whole', 'half', 'whole, the half rejected'}
        As :attr:`masonry.rbe.result.RBEResult.solved_on`.
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
    refined: tuple = field(default=())
    friction_law: str = "associated"
    associated_factor: float | None = None
    cone: FrictionCone = FrictionCone("circle")
    solved_on: str = "whole"
    law: ContactLaw = ContactLaw()

    @property
    def contact_law(self) -> str:
        """The contact law in one line (:meth:`~masonry.contact.ContactLaw.describe`)."""
        return self.law.describe()

    def checked(self) -> bool:
        """Whether a factor's equilibrium residual, recomputed on the model this result
        describes, meets the acceptance tolerance (:data:`ACCEPT_RESIDUAL`); a result
        without a factor has nothing to check."""
        if self.load_factor is None:
            return True
        return math.isfinite(self.residual) and self.residual <= ACCEPT_RESIDUAL

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
        """(K,) bool: the hinges that carry the mechanism
        (:data:`~masonry.tolerances.MECHANISM_MAIN`)."""
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
        :data:`ASSOCIATED_NOTE` when sliding takes part in an associated mechanism,
        :data:`COHESIVE_NOTE` when joints with mortar open or slide in it, and
        :data:`ANISOTROPIC_NOTE` for a model that is not isotropic."""
        notes = []
        if self.status == "unbounded":
            notes.append(UNBOUNDED_NOTE)
        elif self.sliding > 0 and self.friction_law == "associated":
            notes.append(ASSOCIATED_NOTE)
        if (not self.law.is_dry and self.status != "unbounded"
                and self.sliding + self.opening > 0):
            notes.append(COHESIVE_NOTE)
        if not self.cone.is_isotropic:
            notes.append(ANISOTROPIC_NOTE)
        return "; ".join(notes) if notes else None

    def to_dict(self) -> dict:
        """Plain values for run.json: :data:`RESULT_KEYS`, ``live_load`` and, after a
        search, every azimuth's factor (``azimuths`` the samples, ``refined`` the
        refinement's)."""
        out = {}
        for key in RESULT_KEYS:
            value = getattr(self, key)
            out[key] = value.item() if isinstance(value, np.generic) else value
        out["live_load"] = self.live.description
        if self.azimuths:
            out["azimuths"] = [{"azimuth_deg": a, "load_factor": f} for a, f in self.azimuths]
            out["refined"] = [{"azimuth_deg": a, "load_factor": f} for a, f in self.refined]
        return out


def vertex_displacements(blocks, mechanism) -> np.ndarray:
    """(V, 3) float: the virtual displacement of every vertex of ``blocks`` by
    ``mechanism`` ((B, 6), per block ``(u, theta)`` about its centroid)."""
    mechanism = np.asarray(mechanism, dtype=float)
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    arm = blocks.vertices - blocks.block_centroid[owner]
    return mechanism[owner, :3] + np.cross(mechanism[owner, 3:], arm)


def _count(flags) -> int:
    """How many interfaces ``flags`` marks; -1 without a mechanism (None)."""
    return -1 if flags is None else int(flags.sum())


def _main(flags, motion) -> np.ndarray:
    """Of the interfaces flagged, those whose motion is at least
    :data:`~masonry.tolerances.MECHANISM_MAIN` of the largest among them."""
    if not flags.any():
        return flags
    return flags & (motion >= MECHANISM_MAIN * motion[flags].max())
