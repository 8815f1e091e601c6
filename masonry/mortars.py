"""Mortars whose strength grows with age after laying (docs/model.md 6.13), and the
inputs that name a stage study's mortar by age.

A :class:`Mortar` is a table of the cohesion and the tensile strength (kPa) against the
hours after laying, non-decreasing in both; between rows the strength is interpolated
linearly in time, before the first row it is the first row's and after the last the
last row's. :data:`MORTARS` holds the named ones (``lime``, ``gypsum``: indicative orders
of magnitude with their sources in docs/model.md 6.13); :meth:`Mortar.constant` is one
strength at every age.

The rate at which a construction lays its bricks, which turns its stages into the
joints' ages, is :class:`masonry.stages.laying.Laying`.
"""

import math
from dataclasses import dataclass

import numpy as np

from masonry.errors import MasonryError


class MortarError(MasonryError, ValueError):
    """A mortar's table out of order or with negative or non-finite values, an unknown
    mortar or a laying rate that is not positive."""


@dataclass(frozen=True)
class Mortar:
    """A mortar's strength against its age.

    Parameters
    ----------
    name : str
    hours : (R,) float
        Hours after laying, increasing, from 0.
    cohesion_kPa, tensile_kPa : (R,) float
        The strengths at those ages, non-decreasing, >= 0.
    source : str
        Where the orders of magnitude come from (one line).
    """

    name: str
    hours: tuple
    cohesion_kPa: tuple
    tensile_kPa: tuple
    source: str = ""

    @classmethod
    def of_table(cls, name: str, rows, source: str = "") -> "Mortar":
        """The mortar of ``rows`` ``(hours, cohesion kPa, tensile kPa)``, checked.

        Raises
        ------
        MortarError
            One line naming the mortar and the first row at fault.
        """
        rows = [tuple(row) for row in rows]
        if not rows or any(len(row) != 3 for row in rows):
            raise MortarError(f"mortar {name!r}: expected rows (hours, cohesion kPa, "
                              f"tensile kPa), at least one")
        for index, row in enumerate(rows):
            if not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                       and math.isfinite(v) and v >= 0 for v in row):
                raise MortarError(f"mortar {name!r}: row {index + 1} {row}: expected "
                                  f"finite numbers >= 0")
        if rows[0][0] != 0:
            raise MortarError(f"mortar {name!r}: row 1 at {rows[0][0]:g} h: expected the "
                              f"table to start at 0 h (the strength when laid)")
        for index, (before, row) in enumerate(zip(rows, rows[1:]), start=2):
            if row[0] <= before[0] or row[1] < before[1] or row[2] < before[2]:
                raise MortarError(f"mortar {name!r}: row {index} {row} out of order: "
                                  f"expected hours increasing and strengths not "
                                  f"decreasing after row {index - 1} {before}")
        hours, cohesion, tensile = (tuple(float(v) for v in column) for column in zip(*rows))
        return cls(name, hours, cohesion, tensile, source)

    @classmethod
    def constant(cls, cohesion_kPa: float, tensile_kPa: float) -> "Mortar":
        """One strength at every age (``--cohesion-kpa``, ``--tensile-kpa``)."""
        return cls.of_table("constant", [(0.0, cohesion_kPa, tensile_kPa)],
                            "the strengths given")

    def strength_kPa(self, age_h) -> tuple:
        """``(cohesion, tensile)``, kPa, each shaped as ``age_h`` (hours, >= 0): the table
        interpolated linearly, held at its ends."""
        age = np.asarray(age_h, dtype=float)
        return (np.interp(age, self.hours, self.cohesion_kPa),
                np.interp(age, self.hours, self.tensile_kPa))

    def hours_to_hold(self, adhesion_kPa, ratio) -> float | None:
        """The age (hours) from which this mortar holds an adhesion ``a``: cohesion at
        least ``a`` and tensile strength at least ``ratio a`` (the least adhesion's law,
        docs/model.md 6.12); 0 where it holds when laid, None where it never does
        (beyond its last row) or ``adhesion_kPa`` is None. The table interpolated
        linearly, as :meth:`strength_kPa`."""
        if adhesion_kPa is None:
            return None
        return max((_first_age(self.hours, strength, need) for strength, need in (
            (self.cohesion_kPa, adhesion_kPa), (self.tensile_kPa, ratio * adhesion_kPa))),
            key=lambda age: math.inf if age is None else age)

    def describe(self) -> str:
        """One line: the name and the strengths at the table's ends."""
        if len(self.hours) == 1:
            return (f"{self.name} mortar: cohesion {self.cohesion_kPa[0]:g} kPa, tensile "
                    f"strength {self.tensile_kPa[0]:g} kPa at every age")
        return (f"{self.name} mortar: cohesion {self.cohesion_kPa[0]:g} kPa when laid to "
                f"{self.cohesion_kPa[-1]:g} kPa at {_age(self.hours[-1])}, tensile strength "
                f"{self.tensile_kPa[0]:g} to {self.tensile_kPa[-1]:g} kPa")

    def record(self) -> dict:
        return {"name": self.name, "table": [list(row) for row in zip(
            self.hours, self.cohesion_kPa, self.tensile_kPa)], "source": self.source}


def _first_age(hours, strength, need) -> float | None:
    """The first age at which the piecewise linear ``strength`` reaches ``need``; None
    where it never does."""
    if need <= strength[0]:
        return 0.0
    for (h0, s0), (h1, s1) in zip(zip(hours, strength), zip(hours[1:], strength[1:])):
        if s1 >= need:
            return h0 + (h1 - h0) * (need - s0) / (s1 - s0)
    return None


def _age(hours: float) -> str:
    return f"{hours / 24:g} days" if hours >= 48 else f"{hours:g} h"


MORTARS = {
    "lime": Mortar.of_table("lime", [
        (0.0, 0.1, 0.05), (1.0, 0.2, 0.1), (4.0, 0.5, 0.25), (24.0, 2.0, 1.0),
        (168.0, 20.0, 10.0), (672.0, 100.0, 50.0)],
        "fresh tack 0.1-1 kPa (the yield stress of fresh mortar, Banfill 1991); hardened "
        "initial shear strength 0.1 MPa at 28 days (EN 1996-1-1 Table 3.4, weakest "
        "mortars); tension half of it; rows between: a smooth guess, not measured"),
    "gypsum": Mortar.of_table("gypsum", [
        (0.0, 0.1, 0.05), (0.05, 1.0, 0.5), (0.25, 20.0, 10.0), (1.0, 100.0, 50.0),
        (24.0, 300.0, 150.0)],
        "a fast-setting gypsum plaster, setting within minutes (EN 13279-1 initial "
        "setting time; the tile vaults of Guastavino 1893, Ochsendorf 2010, laid "
        "without centering on it); hardened bond 0.1-0.3 MPa as EN 1996-1-1's initial "
        "shear strength; tension half of it; rows between: a smooth guess, not measured"),
}
"""The named mortars (docs/model.md 6.13): indicative orders of magnitude, not
measurements; ``constant`` is :meth:`Mortar.constant` of the run's strengths."""

MORTAR_NAMES = ("constant", *MORTARS)

LAYING_INPUTS = ("mortar", "laying_rate", "masons")
"""A stage study's mortar by age (``masonry stages --mortar --laying-rate --masons``):
inputs of the construction, not of a run's analysis, which a parameter file's
``[mortar]`` table and a study file take beside the analysis's mortar inputs."""


def split_laying(inputs: dict) -> tuple:
    """A study variant's inputs (flat names) as ``(run inputs, mortar by age)``: the
    second its :data:`LAYING_INPUTS` (of its stage study), the first every other."""
    return ({k: v for k, v in inputs.items() if k not in LAYING_INPUTS},
            {k: v for k, v in inputs.items() if k in LAYING_INPUTS})
