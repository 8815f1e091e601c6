"""A construction's laying: the mortar of its joints by age and the rate it lays its bricks
at (docs/model.md 6.13), which turn a stage study's stages into hours.

A :class:`Laying` takes a mortar's table (:class:`masonry.mortars.Mortar`): a stage
that lays ``n`` bricks of the scene takes ``n / (rate x masons)`` hours, and a joint made
at stage ``j`` is, at the end of stage ``k``, as old as the stages ``j+1..k`` took
(:func:`masonry.stages.analysis.joint_strength`). :func:`stage_laying` checks a stage
study's options into one.
"""

import math
from dataclasses import dataclass

import numpy as np

from masonry.errors import ParameterError
from masonry.mortars import MORTAR_NAMES, MORTARS, Mortar, MortarError


@dataclass(frozen=True)
class Laying:
    """A mortar and the rate a construction lays its bricks at.

    Parameters
    ----------
    mortar : Mortar
    rate_per_hour : float or None
        Bricks per hour per mason, > 0; None for a mortar of one strength at every age.
    masons : int
        Masons laying side by side, >= 1: a stage of ``n`` bricks of the scene takes
        ``n / (rate x masons)`` hours.
    """

    mortar: Mortar
    rate_per_hour: float | None = None
    masons: int = 1

    @classmethod
    def of(cls, mortar: Mortar, rate_per_hour=None, masons=1) -> "Laying":
        """Checked: a mortar that ages needs a rate, > 0; ``masons`` an integer >= 1."""
        if rate_per_hour is None and len(mortar.hours) > 1:
            raise MortarError(f"mortar {mortar.name!r}: a laying rate (bricks per hour "
                              f"per mason) is needed to age its joints")
        if rate_per_hour is not None and not (math.isfinite(rate_per_hour)
                                              and rate_per_hour > 0):
            raise MortarError(f"laying rate {rate_per_hour!r}: expected bricks per hour "
                              f"per mason, a finite number > 0")
        if isinstance(masons, bool) or not isinstance(masons, int) or masons < 1:
            raise MortarError(f"masons {masons!r}: expected an integer >= 1")
        return cls(mortar, None if rate_per_hour is None else float(rate_per_hour), masons)

    def stage_hours(self, bricks_laid) -> np.ndarray:
        """(N+1,) float: the hours from the start to the end of stages ``0..N``, for the
        bricks each stage ``1..N`` lays ((N,) int); zeros without a rate."""
        laid = np.concatenate([[0.0], np.asarray(bricks_laid, dtype=float)])
        if self.rate_per_hour is None:
            return np.zeros(len(laid))
        return np.cumsum(laid) / (self.rate_per_hour * self.masons)

    def describe(self) -> str:
        """One line, e.g. ``lime mortar at 60 bricks per hour (1 mason)``."""
        if self.rate_per_hour is None:
            return self.mortar.describe()
        crew = "1 mason" if self.masons == 1 else f"{self.masons} masons"
        return f"{self.mortar.name} mortar at {self.rate_per_hour:g} bricks per hour ({crew})"

    def record(self) -> dict:
        return {"mortar": self.mortar.record(), "rate_bricks_per_hour": self.rate_per_hour,
                "masons": self.masons, "text": self.describe()}


def stage_laying(params, mortar=None, laying_rate=None, masons=None) -> Laying | None:
    """The :class:`Laying` of a stage study's options, checked
    (:class:`ParameterError` naming the option): ``mortar`` a name of
    :data:`MORTAR_NAMES` (``constant``: ``params``' cohesion and tensile
    strength at every age), ``laying_rate`` bricks per hour per mason (needed by a mortar
    that ages), ``masons`` >= 1 (default 1). None without ``mortar``: ``params``'
    contact law at every joint."""
    if mortar is None:
        for name, value in (("laying_rate", laying_rate), ("masons", masons)):
            if value is not None:
                raise ParameterError(name, value, "--mortar NAME beside it (the rate ages "
                                     "a mortar's joints)")
        return None
    if mortar not in MORTAR_NAMES:
        raise ParameterError("mortar", mortar, f"one of {', '.join(MORTAR_NAMES)}")
    analysis = params.analysis
    if mortar != "constant":
        for name in ("cohesion_kpa", "tensile_kpa"):
            if getattr(analysis, name) != 0:
                raise ParameterError(name, getattr(analysis, name), f"0 with --mortar "
                                     f"{mortar}: its table gives the strengths (or "
                                     f"--mortar constant)", related=("mortar",))
    table = (MORTARS[mortar] if mortar != "constant" else
             Mortar.constant(analysis.cohesion_kpa, analysis.tensile_kpa))
    if laying_rate is None and mortar != "constant":
        raise ParameterError("laying_rate", None, f"bricks per hour per mason with "
                             f"--mortar {mortar} (its joints' age)", related=("mortar",))
    if laying_rate is not None and not (isinstance(laying_rate, (int, float))
                                        and np.isfinite(laying_rate) and laying_rate > 0):
        raise ParameterError("laying_rate", laying_rate, "bricks per hour per mason, a "
                             "finite number > 0 (a mason lays 30 to 100 an hour)")
    if masons is not None and (isinstance(masons, bool) or not isinstance(masons, int)
                               or masons < 1):
        raise ParameterError("masons", masons, "an integer >= 1 (masons laying side by "
                             "side)")
    return Laying.of(table, laying_rate, 1 if masons is None else masons)
