"""The one place for tolerances and physical constants.

Every length tolerance is relative to the scene's size (the diagonal of its bounding box),
so a model built with ``unit=0.001`` and one built with ``unit=100`` are treated alike.
Pass a :class:`Tolerances` explicitly; never hard-code a tolerance in a stage.
"""

from dataclasses import dataclass

import numpy as np

G = 9.81
"""Gravitational acceleration, m/s^2 (SPEC 2)."""

TENSION_REPORTED_REL = 1e-6
"""An interface's tension counts as tension in ``RBE/tension_top.csv`` above this fraction
of the structure's weight; below, it is the solver's tolerance (a feasible structure's
tensions are of the order of its residual, 1e-5 relative in the balanced preset, spread
over thousands of interfaces)."""


@dataclass(frozen=True)
class Tolerances:
    """Named, documented tolerances.

    Parameters
    ----------
    scale : float
        Scene size in metres (bounding box diagonal). Length tolerances scale with it.
    contact_rel : float
        Two faces touch when their polygons are within ``contact_rel * scale`` of each
        other (SPEC 5, default 1e-6).
    max_gap_angle : float
        Largest wedge angle (radians) between two faces that gap closing rotates shut;
        faces whose outward normals are farther from anti-parallel are not in contact
        (SPEC 5, default 10 degrees).
    min_area_rel : float
        An interface is kept when its area exceeds ``min_area_rel`` times the smaller of
        the two faces' areas (SPEC 5, default 1e-4).
    length_rel : float
        Generic geometric tolerance (point coincidence, coplanarity), relative to
        ``scale``.
    residual : float
        Largest accepted relative equilibrium residual ``||A x + f||_inf / ||f||_inf``
        and relative friction violation for a result to count as solved.
    """

    scale: float = 1.0
    contact_rel: float = 1e-6
    max_gap_angle: float = float(np.radians(10.0))
    min_area_rel: float = 1e-4
    length_rel: float = 1e-9
    residual: float = 1e-5

    @property
    def contact(self) -> float:
        """Contact distance in metres."""
        return self.contact_rel * self.scale

    @property
    def length(self) -> float:
        """Point coincidence distance in metres."""
        return self.length_rel * self.scale

    @classmethod
    def for_points(cls, points, **kwargs) -> "Tolerances":
        """Tolerances scaled to the bounding box of ``points`` ((n, 3) float, metres)."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        scale = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
        return cls(scale=scale if scale > 0 else 1.0, **kwargs)
