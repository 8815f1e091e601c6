"""The contact law of a joint: Coulomb's friction with mortar's cohesion and tensile
strength (docs/model.md 6.3, 6.4).

At an interface vertex ``i`` of tributary area ``A_i`` (:func:`tributary_area`), with
normal force ``n_i`` (compression positive) and friction ``f_i`` in the joint's plane,
Mohr-Coulomb's law with a tension cut-off::

    ||f_i|| <= mu n_i + c A_i          (a pyramid: each face shifted by c A_i)
    n_i >= -t_c A_i

``c`` the cohesion and ``t_c`` the tensile strength, pascals. The cone is empty beyond
its apex ``n = -c A_i / mu``, so the tension a joint carries is cut off at
``min(t_c, c / mu)`` per unit area (:attr:`ContactLaw.cutoff_Pa`); without cohesion a
tensile strength has nothing to act on: the law is the dry one.

Cohesion is a shift of the friction model: with ``s_i = c A_i / mu`` and the solver's
compression ``c~_i = n_i + s_i``, the law is the dry model in ``(c~, f)``
(:class:`~masonry.friction.FrictionCone`), plus the lower bound ``c~_i >= l_i = s_i -
t_c A_i`` where ``t_c < c / mu`` (the truncated cone). The equilibrium's right-hand side
takes the shift (:class:`masonry.rbe.equilibrium.EquilibriumSystem`), so every solver
states the same cones as for dry joints.

The strengths may differ from vertex to vertex (mortar of different ages in a
construction sequence, :mod:`masonry.mortars`): ``c`` and ``t_c`` are then arrays over
the vertices, and so are the shift and the floor; the solvers see the same cones.
"""

import math
from dataclasses import dataclass

import numpy as np

from masonry.errors import MasonryError
from masonry.friction import FrictionCone

TENSION_RATIO = 0.5
"""The default ratio ``t_c / c`` of the least adhesion's tensile strength to its cohesion
(docs/model.md 6.12, :mod:`masonry.rbe.adhesion`): EN 1996-1-1 gives masonry's flexural
(bond) strength and its initial shear strength in about that ratio (f_xk1 about 0.1 MPa
for general purpose mortar against f_vk0 0.1 to 0.3 MPa); 0 is the conservative choice,
no tension at all."""


class ContactLawError(MasonryError, ValueError):
    """A strength that is negative or not finite, or a friction coefficient that is not
    positive."""


@dataclass(frozen=True)
class ContactLaw:
    """One joint's strength (module docstring).

    Parameters
    ----------
    cone : FrictionCone
        The friction model (circle, polygon:K, square).
    mu : float
        Friction coefficient, > 0.
    cohesion_Pa : float or (IV,) float
        ``c``, pascals, >= 0 (0: dry joints); an array: per interface vertex.
    tensile_Pa : float or (IV,) float
        ``t_c``, pascals, >= 0; an array: per interface vertex.
    """

    cone: FrictionCone = FrictionCone("circle")
    mu: float = 0.7
    cohesion_Pa: float | np.ndarray = 0.0
    tensile_Pa: float | np.ndarray = 0.0

    @classmethod
    def of(cls, cone="circle", mu=0.7, cohesion_Pa=0.0, tensile_Pa=0.0) -> "ContactLaw":
        """The law of a friction model (name or :class:`FrictionCone`), ``mu`` and the
        strengths (numbers, or arrays over the interface vertices), checked.

        Raises
        ------
        ContactLawError
            Naming the argument, its value and what is expected.
        """
        for name, value in (("mu", mu), ("cohesion_Pa", cohesion_Pa),
                            ("tensile_Pa", tensile_Pa)):
            if isinstance(value, np.ndarray) and name != "mu":
                bad = value[~(np.isfinite(value) & (value >= 0))] if value.dtype.kind in \
                    "fiu" else value.ravel()
                if value.ndim != 1 or len(bad):
                    raise ContactLawError(f"{name} per vertex {bad[:1].tolist() or value.shape}"
                                          f": expected finite numbers >= 0, one per vertex")
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ContactLawError(f"{name} {value!r}: expected a number")
            low_ok = value > 0 if name == "mu" else value >= 0
            if not (math.isfinite(value) and low_ok):
                raise ContactLawError(f"{name} {value!r}: expected a finite number "
                                      f"{'> 0' if name == 'mu' else '>= 0'}")
        return cls(FrictionCone.parse(cone), float(mu), as_strength(cohesion_Pa),
                   as_strength(tensile_Pa))

    @property
    def is_dry(self) -> bool:
        """No cohesion: the friction model alone (a tensile strength without cohesion is
        cut off at the cone's apex, 0); per vertex: no vertex has any."""
        return not np.any(self.cohesion_Pa)

    @property
    def is_per_vertex(self) -> bool:
        """The strengths are arrays over the interface vertices."""
        return np.ndim(self.cohesion_Pa) > 0 or np.ndim(self.tensile_Pa) > 0

    @property
    def cutoff_Pa(self) -> float | np.ndarray:
        """The tension a joint carries per unit area: ``min(t_c, c / mu)`` (per vertex
        where the strengths are)."""
        if not self.is_per_vertex:
            return min(self.tensile_Pa, self.cohesion_Pa / self.mu)
        return np.minimum(self.tensile_Pa, np.asarray(self.cohesion_Pa) / self.mu)

    @property
    def is_truncated(self) -> bool:
        """The cut-off lies before the cone's apex (``t_c < c / mu``) somewhere: the
        solvers need the lower bound ``c~ >= l``."""
        return not self.is_dry and bool(np.any(
            np.asarray(self.tensile_Pa) < np.asarray(self.cohesion_Pa) / self.mu))

    def shift(self, area) -> np.ndarray:
        """(IV,) float, newtons: ``s_i = c A_i / mu`` for tributary areas ``area``
        ((IV,) float, m^2)."""
        return self.cohesion_Pa / self.mu * np.asarray(area, dtype=float)

    def floor(self, area) -> np.ndarray:
        """(IV,) float, newtons: the lower bound ``l_i = s_i - t_c A_i = (c / mu -
        cutoff) A_i`` of the shifted compression ``c~_i`` (0 where the cut-off is the
        apex)."""
        return (self.cohesion_Pa / self.mu - self.cutoff_Pa) * np.asarray(area, dtype=float)

    def scaled(self, factor) -> "ContactLaw":
        """This law with both strengths times ``factor`` (a float, or (IV,) per vertex:
        :func:`joint_factor`); itself where the factor is 1 everywhere
        or it is dry."""
        if self.is_dry or (np.ndim(factor) == 0 and factor == 1.0):
            return self
        return ContactLaw(self.cone, self.mu, as_strength(factor * np.asarray(self.cohesion_Pa)),
                          as_strength(factor * np.asarray(self.tensile_Pa)))

    def describe(self) -> str:
        """The law in one line, e.g. ``Coulomb circle, mu 0.7, cohesion 0.5 kPa,
        tensile strength 0.25 kPa`` (per vertex: the range of each strength)."""
        head = f"Coulomb {self.cone.name}, mu {self.mu:g}"
        if self.is_dry:
            return f"{head}, dry joints (no cohesion, no tension)"
        if self.is_per_vertex:
            return (f"{head}, per joint: cohesion {_range_kPa(self.cohesion_Pa)}, tensile "
                    f"strength {_range_kPa(self.tensile_Pa)} (cut off at c/mu)")
        text = (f"{head}, cohesion {self.cohesion_Pa / 1e3:g} kPa, tensile strength "
                f"{self.tensile_Pa / 1e3:g} kPa")
        if self.tensile_Pa > self.cohesion_Pa / self.mu:
            text += f" (cut off at the cone's apex, c/mu = {self.cutoff_Pa / 1e3:.4g} kPa)"
        return text

    def __str__(self) -> str:
        return self.describe()

    def record(self) -> dict:
        """run.json's ``contact_law``: the model, ``mu``, the strengths and the
        effective tension cut-off (pascals), and the one line; per vertex, each strength
        is its least and its largest ``[min, max]``."""
        if self.is_per_vertex:
            return {"friction_model": self.cone.name, "mu": self.mu,
                    **{name: _bounds(value) for name, value in (
                        ("cohesion_Pa", self.cohesion_Pa), ("tensile_Pa", self.tensile_Pa),
                        ("tension_cutoff_Pa", self.cutoff_Pa))},
                    "per_vertex": True, "text": self.describe()}
        return {"friction_model": self.cone.name, "mu": self.mu,
                "cohesion_Pa": self.cohesion_Pa, "tensile_Pa": self.tensile_Pa,
                "tension_cutoff_Pa": self.cutoff_Pa, "text": self.describe()}


JOINT_KINDS = {"bed": ("horizontal",), "head": ("vertical", "boundary"),
               "support": ("support",)}
"""The joint kinds whose strengths differ (:func:`joint_factor`) by the interface kinds
(:data:`masonry.interfaces.INTERFACE_KINDS`) they take: a joint between two webs
(``boundary``, at a polygonal dome's corner or a sector's edge) joins bricks of one course
side by side, a head joint."""


def joint_factor(interfaces, head=1.0, support=1.0) -> float | np.ndarray:
    """Every interface vertex's strength over the bed joints' (:data:`JOINT_KINDS`):
    1 at bed joints, ``head`` at head joints, ``support`` at joints with a support;
    ``1.0`` (a float) where both ratios are 1.

    Parameters
    ----------
    interfaces : masonry.interfaces.Interfaces
    head, support : float
        >= 0.

    Returns
    -------
    float or (IV,) float
    """
    if head == 1.0 and support == 1.0:
        return 1.0
    per = np.ones(len(interfaces))
    for name, ratio in (("head", head), ("support", support)):
        per[interfaces.is_kind(*JOINT_KINDS[name])] = ratio
    return np.repeat(per, np.diff(np.asarray(interfaces.offsets)))


def as_strength(value) -> float | np.ndarray:
    """A strength (pascals) as a float, or as a read-only float array per vertex."""
    if not isinstance(value, np.ndarray):
        return float(value)
    out = np.array(value, dtype=float)
    out.flags.writeable = False
    return out


def same_strength(a, b) -> bool:
    """Two strengths (floats or per-vertex arrays) are the same everywhere."""
    if np.ndim(a) == 0 and np.ndim(b) == 0:
        return float(a) == float(b)
    return np.shape(a) == np.shape(b) and bool(np.array_equal(a, b))


def _bounds(value) -> list:
    """``[min, max]`` of a per-vertex strength (pascals), ``[0, 0]`` for no vertex."""
    value = np.broadcast_to(np.asarray(value, dtype=float), (max(np.size(value), 1),))
    return [float(value.min()), float(value.max())]


def _range_kPa(value) -> str:
    """A per-vertex strength's range in kPa, e.g. ``0.1 to 2 kPa``."""
    low, high = _bounds(value)
    return f"{low / 1e3:g} kPa" if low == high else f"{low / 1e3:g} to {high / 1e3:g} kPa"


def tributary_area(interfaces) -> np.ndarray:
    """(IV,) float, m^2: every interface vertex's share of its polygon's area.

    Vertex ``i`` gets the quadrilateral of the vertex, the midpoint of its next edge,
    the polygon's area centroid and the midpoint of its previous edge: the part of the
    polygon nearer to it along the boundary. The two triangles of an edge ``(v_i,
    v_i+1)`` with the centroid make up that edge's triangle, so the shares sum to the
    polygon's area (signed areas about the normal, exact for any polygon).

    Parameters
    ----------
    interfaces : masonry.interfaces.Interfaces
        Polygons counter-clockwise about their normals, metres.
    """
    vertices = np.asarray(interfaces.vertices, dtype=float)
    offsets = np.asarray(interfaces.offsets, dtype=np.int64)
    owner = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
    index = np.arange(len(vertices))
    count = np.diff(offsets)[owner]
    start = offsets[owner]
    following = start + (index - start + 1) % count
    previous = start + (index - start - 1) % count
    centre = np.asarray(interfaces.centre, dtype=float)[owner]
    normal = np.asarray(interfaces.normal, dtype=float)[owner]
    here = vertices
    next_mid = 0.5 * (here + vertices[following])
    prev_mid = 0.5 * (here + vertices[previous])

    def signed(a, b):
        return 0.5 * np.einsum("vi,vi->v", np.cross(a - here, b - here), normal)

    return signed(next_mid, centre) + signed(centre, prev_mid)
