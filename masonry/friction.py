"""Friction models: the set of forces one interface vertex can carry (docs/model.md
6.3).

At a vertex with compression ``c`` and friction ``(f1, f2)`` along the joint's axes
``t1, t2``, Coulomb's law is isotropic: ``||(f1, f2)|| <= mu c``, a circular cone. The
models here, one :class:`FrictionCone` each:

- ``circle``: that cone itself (a second-order cone);
- ``polygon:K``: the regular K-sided pyramid inscribed in it, edge rays
  ``(1, mu cos(2 pi k / K), mu sin(2 pi k / K))``: a joint carries between
  ``mu cos(pi / K) c`` and ``mu c`` in every direction, never more than Coulomb;
- ``square``: the thesis's pyramid ``|f1|, |f2| <= mu c`` (eq. 3.25-3.26). It
  circumscribes the cone: ``sqrt(2) mu c`` at 45 degrees to the joint's axes, so the
  result depends on how those axes lie, and overstates friction by up to 41 %. Kept to
  reproduce the thesis only.

A polyhedral model is a regular pyramid with ``K`` edge rays at radius ``rho mu`` and
angles ``offset + 2 pi k / K`` (``polygon:K``: ``rho = 1``, ``offset = 0``; ``square``:
``K = 4``, ``rho = sqrt(2)``, ``offset = pi / 4``); its face ``k`` lies between rays
``k`` and ``k + 1``, with the outward normal at angle ``offset + (2 k + 1) pi / K`` in
the joint's plane and the apothem ``rho mu cos(pi / K)``.
"""

import math
from dataclasses import dataclass

import numpy as np

from masonry.errors import MasonryError
CIRCLE, POLYGON, SQUARE = "circle", "polygon", "square"
KINDS = (CIRCLE, POLYGON, SQUARE)

MIN_SIDES = 8
"""Fewest sides of ``polygon:K``: an 8-sided pyramid already carries 92.4 % of Coulomb's
capacity in its weakest direction; fewer sides are the square's problem turned around."""

MAX_SIDES = 256
"""Most sides of ``polygon:K`` (0.008 % short of the cone): beyond it the cone itself is
cheaper than the pyramid's rays."""


class FrictionModelError(MasonryError, ValueError):
    """A friction model name that is not ``circle``, ``polygon:K`` or ``square``."""


@dataclass(frozen=True)
class FrictionCone:
    """One friction model (module docstring).

    Parameters
    ----------
    kind : {'circle', 'polygon', 'square'}
    sides : int
        ``K`` of a polygon, 4 for the square, 0 for the circle.
    """

    kind: str
    sides: int = 0

    @classmethod
    def parse(cls, text) -> "FrictionCone":
        """The model named ``text``: ``'circle'``, ``'polygon:K'`` (``MIN_SIDES <= K <=
        MAX_SIDES``) or ``'square'``; a :class:`FrictionCone` passes through.

        Raises
        ------
        FrictionModelError
            Naming what is expected.
        """
        if isinstance(text, FrictionCone):
            return text
        expected = (f"circle, polygon:K ({MIN_SIDES} <= K <= {MAX_SIDES}) or square")
        if not isinstance(text, str):
            raise FrictionModelError(expected)
        kind, colon, count = text.strip().partition(":")
        if kind == CIRCLE and not colon:
            return cls(CIRCLE, 0)
        if kind == SQUARE and not colon:
            return cls(SQUARE, 4)
        # ASCII digits only: str.isdigit also takes '\u00b2', which int() refuses
        if (kind == POLYGON and count.isascii() and count.isdigit()
                and MIN_SIDES <= int(count) <= MAX_SIDES):
            return cls(POLYGON, int(count))
        raise FrictionModelError(expected)

    @property
    def name(self) -> str:
        """``'circle'``, ``'polygon:K'`` or ``'square'``."""
        return f"{POLYGON}:{self.sides}" if self.kind == POLYGON else self.kind

    def __str__(self) -> str:
        return self.name

    @property
    def is_polyhedral(self) -> bool:
        """Whether the model is a pyramid (edge rays and faces), not the cone."""
        return self.kind != CIRCLE

    @property
    def is_isotropic(self) -> bool:
        """Whether its capacity is Coulomb's within :attr:`capacity_error` in every
        direction with no direction favoured beyond it (every model but the square)."""
        return self.kind != SQUARE

    @property
    def capacity_range(self) -> tuple:
        """``(least, most)`` sliding capacity over all directions in the joint's plane,
        as a fraction of Coulomb's ``mu c``."""
        if self.kind == CIRCLE:
            return 1.0, 1.0
        radius, _ = self._ray_geometry()
        return radius * math.cos(math.pi / self.sides), radius

    @property
    def capacity_error(self) -> float:
        """The largest relative error of the sliding capacity against Coulomb's in any
        direction: 0 (circle), ``1 - cos(pi / K)`` short (polygon), ``sqrt(2) - 1`` over
        (square)."""
        least, most = self.capacity_range
        return max(1.0 - least, most - 1.0)

    def describe(self) -> str:
        """One line for the text outputs: the model and its bound on the error of the
        friction capacity."""
        if self.kind == CIRCLE:
            return "circle: Coulomb's isotropic cone, exact (capacity error 0)"
        if self.kind == POLYGON:
            least = self.capacity_range[0]
            return (f"polygon:{self.sides}: the inscribed {self.sides}-sided pyramid, "
                    f"isotropic and safe: capacity {least:.4f} to 1 times mu c in every "
                    f"direction (error at most {100 * self.capacity_error:.2f} %, "
                    f"never more than Coulomb)")
        return ("square: the thesis's pyramid |f1|, |f2| <= mu c, direction dependent: "
                "capacity 1 to 1.414 times mu c, up to 41 % more than Coulomb's (the "
                "result changes when the model is turned; use it to reproduce the "
                "thesis only)")

    def record(self) -> dict:
        """run.json's ``friction_model``: name, isotropy and the capacity's bounds."""
        least, most = self.capacity_range
        return {"name": self.name, "isotropic": self.is_isotropic,
                "capacity_min": least, "capacity_max": most,
                "capacity_error": self.capacity_error}

    # ------------------------------------------------------------ polyhedral geometry
    def _ray_geometry(self) -> tuple:
        """``(rho, offset)``: the edge rays' radius (per ``mu``) and first angle."""
        if self.kind == SQUARE:
            return math.sqrt(2.0), math.pi / 4
        if self.kind == POLYGON:
            return 1.0, 0.0
        raise ValueError("the circle has no edge rays")

    def rays(self, mu) -> np.ndarray:
        """(3, K) float: the edge rays as columns in ``(c, f1, f2)``; a vertex force of the
        model is a nonnegative combination of them."""
        radius, offset = self._ray_geometry()
        angle = offset + 2.0 * np.pi * np.arange(self.sides) / self.sides
        return np.vstack([np.ones(self.sides), mu * radius * np.cos(angle),
                          mu * radius * np.sin(angle)])

    def face_normals(self) -> np.ndarray:
        """(K, 2) float: the faces' outward unit normals in the joint's plane."""
        _, offset = self._ray_geometry()
        angle = offset + (2.0 * np.arange(self.sides) + 1.0) * np.pi / self.sides
        normals = np.column_stack([np.cos(angle), np.sin(angle)])
        # exact zeros where a normal lies along an axis (the square's: cos(pi / 2) is
        # 6e-17), so that the faces' rows store no noise
        return np.where(np.abs(normals) < 1e-15, 0.0, normals)

    def apothem(self, mu) -> float:
        """The faces' distance from the axis per unit compression: face ``k`` is
        ``(f1, f2) . normal_k <= apothem c``."""
        radius, _ = self._ray_geometry()
        return mu * radius * math.cos(math.pi / self.sides)

    def faces(self, mu) -> np.ndarray:
        """(K, 3) float: the rows ``G`` with ``G (c, f1, f2) <= 0``, one per face."""
        return np.column_stack([np.full(self.sides, -self.apothem(mu)), self.face_normals()])

    # ------------------------------------------------------------ per vertex
    def excess(self, load, f1, f2, mu) -> np.ndarray:
        """(V,) float: how far each vertex's friction lies outside the model, in force
        units: ``||f|| - mu load`` (circle) or the largest ``f . normal_k - apothem load``
        (pyramids); negative inside. ``load`` is ``c`` (friction+) or ``c - t``
        (friction-net)."""
        load, f1, f2 = (np.asarray(v, dtype=float) for v in (load, f1, f2))
        if self.kind == CIRCLE:
            return np.hypot(f1, f2) - mu * load
        normals = self.face_normals()
        reach = np.max(f1[:, None] * normals[:, 0] + f2[:, None] * normals[:, 1], axis=1)
        return reach - self.apothem(mu) * load

    def project(self, p, mu, floor=None):
        """Euclidean projection onto the model and an element of its generalized Jacobian.

        Parameters
        ----------
        p : (V, 3) float
            Points ``(c, f1, f2)``.
        mu : float
        floor : (V,) float, optional
            A lower bound ``c >= floor`` (>= 0) per point: the cone truncated by a
            tension cut-off (:mod:`masonry.contact`); the circle only.

        Returns
        -------
        x : (V, 3) float
        jacobian : (V, 3, 3) float
            Identity inside, the projector onto the face or edge where a pyramid's
            projection lands (piecewise constant), the derivative of the projection onto
            the cone's surface (which varies with the point), zero at the apex.
        """
        p = np.asarray(p, dtype=float)
        if floor is not None:
            if self.kind != CIRCLE:
                raise ValueError(f"{self.name}: no closed-form projection onto a truncated "
                                 f"pyramid")
            return _project_truncated(p, mu, np.asarray(floor, dtype=float))
        if self.kind == CIRCLE:
            return _project_circle(p, mu)
        radius, offset = self._ray_geometry()
        return _project_pyramid(p, mu * radius, offset, self.sides)


def _project_circle(p, mu):
    """:meth:`FrictionCone.project` for ``||f|| <= mu c``: inside stays, the polar cone
    (``c <= -mu ||f||``) goes to the apex, the rest to the nearest point of the ray through
    ``f``'s direction, ``s (1, mu d)`` with ``s = (c + mu ||f||) / (1 + mu^2)``."""
    c, f = p[:, 0], p[:, 1:]
    norm = np.hypot(f[:, 0], f[:, 1])
    x = np.zeros_like(p)
    jacobian = np.zeros((len(p), 3, 3))
    inside = norm <= mu * c
    x[inside] = p[inside]
    jacobian[inside] = np.eye(3)
    side = ~inside & (c > -mu * norm)
    d = f[side] / norm[side, None]
    s = (c[side] + mu * norm[side]) / (1.0 + mu * mu)
    x[side, 0] = s
    x[side, 1:] = mu * s[:, None] * d
    # d x / d p: the 2D projection onto the ray (1, mu) in (c, ||f||), plus the turn of
    # the direction d, mu s / ||f|| (I - d d^T), which is at most 1
    u = np.concatenate([np.ones((len(d), 1)), mu * d], axis=1) / math.sqrt(1.0 + mu * mu)
    turn = mu * s / norm[side]
    jacobian[side] = u[:, :, None] * u[:, None, :]
    jacobian[side, 1:, 1:] += turn[:, None, None] * (np.eye(2) - d[:, :, None] * d[:, None, :])
    return x, jacobian


def _project_truncated(p, mu, floor):
    """:meth:`FrictionCone.project` for ``{c >= floor, ||f|| <= mu c}``: in the half-plane
    ``(c, ||f||)`` a 2D projection onto the slanted side (as :func:`_project_circle`,
    where it lands at ``c >= floor``), the flat side ``c = floor`` (Jacobian
    ``diag(0, 1, 1)``) or the corner ``(floor, mu floor d)`` (``c`` fixed, ``d`` turning:
    ``mu floor / ||f|| (I - d d^T)``)."""
    c, f = p[:, 0], p[:, 1:]
    norm = np.hypot(f[:, 0], f[:, 1])
    s = (c + mu * norm) / (1.0 + mu * mu)
    inside = (norm <= mu * c) & (c >= floor)
    flat = ~inside & (c < floor) & (norm <= mu * floor)
    slant = ~inside & ~flat & (s >= floor)
    corner = ~(inside | flat | slant)
    x = np.zeros_like(p)
    jacobian = np.zeros((len(p), 3, 3))
    x[inside] = p[inside]
    jacobian[inside] = np.eye(3)
    x[flat, 0] = floor[flat]
    x[flat, 1:] = f[flat]
    jacobian[flat, 1, 1] = jacobian[flat, 2, 2] = 1.0
    safe = np.where(norm > 0, norm, 1.0)
    d = f / safe[:, None]
    across = np.eye(2) - d[:, :, None] * d[:, None, :]
    x[slant, 0] = s[slant]
    x[slant, 1:] = mu * s[slant, None] * d[slant]
    u = np.concatenate([np.ones((len(d), 1)), mu * d], axis=1) / math.sqrt(1.0 + mu * mu)
    jacobian[slant] = u[slant, :, None] * u[slant, None, :]
    jacobian[slant, 1:, 1:] += (mu * s / safe)[slant, None, None] * across[slant]
    x[corner, 0] = floor[corner]
    x[corner, 1:] = mu * floor[corner, None] * d[corner]
    jacobian[corner, 1:, 1:] = (mu * floor / safe)[corner, None, None] * across[corner]
    return x, jacobian


def _project_pyramid(p, rho, offset, sides):
    """:meth:`FrictionCone.project` for a regular pyramid of ``sides`` edge rays at radius
    ``rho`` (per unit ``c``) and angles ``offset + 2 pi k / sides``.

    Every point is handled in the frame of the face whose angular sector holds its
    friction ``f``: the face's outward normal along the first axis, its edges at angles
    ``+-pi / K``. The projection of a point in that sector lands on that face, on one of
    its two edges (the one on the point's side) or on the apex (the normal cones of the
    other faces and edges lie in other sectors), so the cases are tried in that order.
    """
    half = np.pi / sides
    apothem, half_width = rho * math.cos(half), rho * math.sin(half)
    c = p[:, 0]
    angle = np.arctan2(p[:, 2], p[:, 1]) - offset
    sector = np.floor(angle / (2.0 * half)) % sides
    bisector = offset + (2.0 * sector + 1.0) * half
    cos, sin = np.cos(bisector), np.sin(bisector)
    u = cos * p[:, 1] + sin * p[:, 2]            # along the face's normal
    v = -sin * p[:, 1] + cos * p[:, 2]           # along the face
    x_local = np.zeros((len(p), 3))
    j_local = np.zeros((len(p), 3, 3))

    inside = u <= apothem * c
    x_local[inside] = np.column_stack([c, u, v])[inside]
    j_local[inside] = np.eye(3)
    todo = ~inside
    # the face: move along its normal (-apothem, 1, 0)
    norm2 = 1.0 + apothem * apothem
    k = (u - apothem * c) / norm2
    c_face = c + apothem * k
    face = todo & (c_face > 0) & (np.abs(v) <= half_width * c_face)
    x_local[face] = np.column_stack([c_face, apothem * c_face, v])[face]
    normal = np.array([-apothem, 1.0, 0.0])
    j_local[face] = np.eye(3) - np.outer(normal, normal) / norm2
    todo &= ~face
    # the edge on the point's side: the ray (1, apothem, +-half_width)
    side = np.where(v >= 0, 1.0, -1.0)
    ray2 = norm2 + half_width * half_width
    s = (c + apothem * u + half_width * np.abs(v)) / ray2
    edge = todo & (s > 0)
    ray = np.column_stack([np.ones(len(p)), np.full(len(p), apothem), half_width * side])
    x_local[edge] = s[edge, None] * ray[edge]
    j_local[edge] = ray[edge, :, None] * ray[edge, None, :] / ray2
    # the rest lies in the polar cone: the apex, x = 0, J = 0
    # back to the joint's axes: x = R x_local, J = R J_local R^T
    rotation = np.zeros((len(p), 3, 3))
    rotation[:, 0, 0] = 1.0
    rotation[:, 1, 1], rotation[:, 1, 2] = cos, -sin
    rotation[:, 2, 1], rotation[:, 2, 2] = sin, cos
    x = np.einsum("vij,vj->vi", rotation, x_local)
    jacobian = rotation @ j_local @ rotation.transpose(0, 2, 1)
    return x, jacobian
