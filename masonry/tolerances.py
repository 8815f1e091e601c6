"""The one place for tolerances and physical constants.

Every length tolerance is relative to the scene's size (the diagonal of its bounding box),
so a model built with ``unit=0.001`` and one built with ``unit=100`` are treated alike.
Pass a :class:`Tolerances` explicitly; never hard-code a tolerance in a stage.
"""

from dataclasses import dataclass

import numpy as np

G = 9.81
"""Gravitational acceleration, m/s^2 (SPEC 2)."""

MAX_BRICKS = 50_000
"""Largest model built without being asked (``--max-bricks``): solving takes about
:data:`BYTES_PER_BRICK` each, so the default stays within 10 GB."""

BYTES_PER_BRICK = 200e3
"""Peak memory of a run per brick, accurate preset: 4.2 GiB for the 21,648 bricks of
preset 1's full dome with ``--p 21`` (docs/bench.md; balanced takes half)."""


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
