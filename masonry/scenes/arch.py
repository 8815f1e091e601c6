"""The ``arch`` scene: an arch of voussoirs on two supports.

Geometry (docs/model.md 4.6, Heyman's conventions). The arch lies in the xz-plane, its span along x,
symmetric about x = 0, springing at z = 0; it is extruded along y by its depth. ``R`` is
the radius of the centre line and ``t`` the thickness, so the intrados has radius
``R - t/2`` and the extrados ``R + t/2``; the span and rise are the centre line's. Joints
are radial. Each voussoir is the quadrilateral of two consecutive joints, so its intrados
and extrados are chords of the circles (flat faces): a voussoir is a convex hexahedron.

- ``semicircular``: ``R = span / 2``, joints every ``pi / N``.
- ``segmental``: a circular arc of rise ``h < span / 2``, ``R = (span^2/4 + h^2) / (2 h)``,
  joints equally spaced in angle; the springings are inclined skewbacks.
- ``pointed``: two arcs of radius ``R = (span^2/4 + h^2) / span`` centred on the
  springing line, meeting at the crown, ``h > span / 2`` (default: equilateral,
  ``R = span``). ``N`` must be even: each leg has ``N / 2`` voussoirs, radial joints
  about its own centre, and the two crown voussoirs meet at the vertical joint x = 0.

Two support blocks stand under the springing joints; their top faces are those joints.
The thrust line (:mod:`masonry.studies.thrust_line`) checks the RBE on this scene
independently.
"""

import math
from dataclasses import dataclass

import numpy as np

from masonry.blocks import BLOCK, GROUND, Blocks
from masonry.errors import ParameterError
from masonry.parameters import declare
from masonry.scenes.base import Scene, SceneKind, ThrustSection

ARCH_SHAPES = ("semicircular", "pointed", "segmental")

ARCH_RATIOS = {
    # name: (low, high) as multiples of the span: the interface detector's tolerances are
    # relative to the scene's size (1e-6), so a part 1e-9 of it would vanish in them
    "arch_thickness": (1e-3, None),
    "arch_depth": (1e-3, 1e3),
    "arch_rise": (1e-2, 1e2),
}


@dataclass(frozen=True)
class ArchGeometry:
    """An arch of voussoirs on two supports, metres (Heyman's conventions; see the
    module docstring): the span and rise of its centre line, its thickness along the
    joints and its depth along y."""

    arch_shape: str = declare("semicircular", "the arch's shape", kind="str",
                              choices=ARCH_SHAPES, tag="", head=True, names_geometry=True,
                              option="--shape")
    arch_blocks: int = declare(
        16, "voussoirs", kind="int", check=lambda v: v >= 2, tag="N", head=True,
        names_geometry=True, option="--blocks",
        help="number of voussoirs (>= 2; default 16; even for a pointed arch)",
        expected="an integer >= 2 (one voussoir is no arch, and a semicircular one is not "
                 "convex)")
    arch_span: float = declare(10.0, "m, of the centre line", low=0.01, high=1e4, tag="s",
                               head=True, names_geometry=True, option="--span",
                               expected="0.01 to 10000 (metres)")
    arch_thickness: float = declare(0.6, "m", check=lambda v: v > 0, tag="t", head=True,
                                    names_geometry=True, expected="> 0 (metres)",
                                    option="--thickness",
                                    help="thickness t along the joints, metres (at least "
                                         "0.001 span; default 0.6)")
    arch_depth: float = declare(1.0, "m, along y", check=lambda v: v > 0, tag="d",
                                head=True, names_geometry=True, expected="> 0 (metres)",
                                option="--depth",
                                help="depth along y, metres (0.001 to 1000 spans; default 1)")
    arch_rise: float | None = declare(None, "m, of the centre line", optional=True,
                                      check=lambda v: v > 0, tag="h", head=True,
                                      names_geometry=True, expected="> 0 (metres) or none",
                                      option="--rise",
                                      help="rise of the centre line, metres: a pointed arch's "
                                           "> span/2 (default equilateral), a segmental "
                                           "one's < span/2 and at least 0.01 span (default "
                                           "span/4)")


def arch_radius(shape: str, span: float, rise=None) -> tuple:
    """``(R, h)``: centre-line radius and rise of an arch of ``span`` (metres).

    ``rise`` None takes the shape's default: ``span / 2`` (semicircular), ``span / 4``
    (segmental), ``span * sqrt(3) / 2`` (pointed, equilateral).
    """
    if shape == "semicircular":
        return span / 2, span / 2
    if shape == "segmental":
        h = span / 4 if rise is None else rise
        return (span**2 / 4 + h**2) / (2 * h), h
    h = span * math.sqrt(3) / 2 if rise is None else rise
    return (span**2 / 4 + h**2) / span, h


def check_arch(p: ArchGeometry) -> None:
    """Refuse arch parameters that make no arch (:class:`~masonry.errors.ParameterError`):
    thickness, depth and rise against the span (:data:`ARCH_RATIOS`), the rise against the
    shape, an even number of voussoirs for a pointed arch, and a thickness that leaves an
    intrados. (Each parameter's own range is checked with its declaration.)"""
    span, rise, t = p.arch_span, p.arch_rise, p.arch_thickness
    for name, (low, high) in ARCH_RATIOS.items():
        value = getattr(p, name)
        if value is None:
            continue
        if value < low * span or (high is not None and value > high * span):
            bounds = f"{low:g} to {high:g}" if high is not None else f"at least {low:g}"
            raise ParameterError(name, value, f"{bounds} times the span ({span:g} m): the "
                                              "contact tolerances are relative to the arch's "
                                              "size", related=("arch_span",))
    _check_rise(p.arch_shape, span, rise, p.arch_blocks)
    radius, _ = arch_radius(p.arch_shape, span, rise)
    # the intrados must exist: radius R - t/2 > 0, and for a pointed arch it must still
    # reach the crown, R - t/2 > R - span/2
    limit = span if p.arch_shape == "pointed" else 2 * radius
    if not t < limit:
        raise ParameterError("arch_thickness", t, f"< {limit:g} m (the intrados of this "
                                                  f"arch vanishes at t = {limit:g} m)",
                             related=("arch_span", "arch_shape", "arch_rise"))


def _check_rise(shape, span, rise, blocks):
    """The rise against the shape, and an even number of voussoirs for a pointed arch."""
    if shape == "semicircular" and rise is not None and rise != span / 2:
        raise ParameterError("arch_rise", rise, f"none for a semicircular arch (its rise is "
                                                f"span / 2 = {span / 2:g} m)",
                             related=("arch_shape",))
    if shape == "segmental" and rise is not None and not 0 < rise < span / 2:
        raise ParameterError("arch_rise", rise, f"0 < rise < span / 2 = {span / 2:g} m for "
                                                "a segmental arch",
                             related=("arch_span", "arch_shape"))
    if shape == "pointed":
        if rise is not None and not rise > span / 2:
            raise ParameterError("arch_rise", rise, f"> span / 2 = {span / 2:g} m for a "
                                                    "pointed arch",
                                 related=("arch_span", "arch_shape"))
        if blocks % 2:
            raise ParameterError("arch_blocks", blocks, "an even number for a pointed arch",
                                 related=("arch_shape",))


@dataclass(frozen=True)
class ArchProfile:
    """The arch in its plane, before extrusion: x along the span, z up, metres.

    Parameters
    ----------
    intrados, extrados : (N + 1, 2) float
        Joint ``j`` runs from ``intrados[j]`` to ``extrados[j]``; joint 0 is the right
        springing (x > 0), joint N the left one.
    radius : float
        Centre-line radius ``R`` (of each leg for a pointed arch).
    thickness : float
        ``t``, the length of every radial joint (the vertical crown joint of a pointed
        arch is longer).
    shape : str
    span, rise : float
        Of the centre line.
    """

    intrados: np.ndarray
    extrados: np.ndarray
    radius: float
    thickness: float
    shape: str
    span: float
    rise: float

    @property
    def n_blocks(self) -> int:
        return len(self.intrados) - 1

    @property
    def voussoirs(self) -> np.ndarray:
        """(N, 4, 2) float: intrados k, extrados k, extrados k+1, intrados k+1."""
        i, e = self.intrados, self.extrados
        return np.stack([i[:-1], e[:-1], e[1:], i[1:]], axis=1)


def arch_profile(shape: str, n_blocks: int, span: float, thickness: float,
                 rise=None) -> ArchProfile:
    """The joints of an arch of ``n_blocks`` voussoirs (see the module docstring).

    Parameters are in metres; ``rise`` None takes the shape's default
    (:func:`arch_radius`). Inputs are assumed valid (:func:`check_arch`).
    """
    radius, rise = arch_radius(shape, span, rise)
    half = thickness / 2
    if shape in ("semicircular", "segmental"):
        alpha = np.pi / 2 if shape == "semicircular" else np.arcsin(span / (2 * radius))
        centre = np.array([0.0, rise - radius])
        phi = np.pi / 2 - alpha + 2 * alpha * np.arange(n_blocks + 1) / n_blocks
        ray = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        intrados, extrados = centre + (radius - half) * ray, centre + (radius + half) * ray
        if shape == "semicircular":
            # exact zeros at the springings and on the axis (cos(pi/2) is 6e-17)
            intrados[[0, -1], 1] = extrados[[0, -1], 1] = 0.0
            if n_blocks % 2 == 0:
                intrados[n_blocks // 2, 0] = extrados[n_blocks // 2, 0] = 0.0
    else:
        # right leg about (c, 0), c = span/2 - R < 0; its crown at angle phi_c
        c = span / 2 - radius
        phi_c = np.arctan2(rise, -c)
        legs = n_blocks // 2
        phi = phi_c * np.arange(legs) / legs
        ray = np.stack([np.cos(phi), np.sin(phi)], axis=1)
        centre = np.array([c, 0.0])
        right_i = np.vstack([centre + (radius - half) * ray,
                             [0.0, np.sqrt((radius - half) ** 2 - c**2)]])
        right_e = np.vstack([centre + (radius + half) * ray,
                             [0.0, np.sqrt((radius + half) ** 2 - c**2)]])
        mirror = np.array([-1.0, 1.0])
        intrados = np.vstack([right_i, right_i[-2::-1] * mirror])
        extrados = np.vstack([right_e, right_e[-2::-1] * mirror])
    profile = ArchProfile(intrados, extrados, float(radius), float(thickness), shape,
                          float(span), float(rise))
    # every corner of every voussoir turns the same way: convex quadrilaterals
    edge = np.roll(profile.voussoirs, -1, axis=1) - profile.voussoirs
    after = np.roll(edge, -1, axis=1)
    turn = edge[..., 0] * after[..., 1] - edge[..., 1] * after[..., 0]
    if not ((turn > 0).all() or (turn < 0).all()):
        raise ValueError(f"a voussoir of this {shape} arch is not convex")
    return profile


def polygon_area_centroid(polygons):
    """Shoelace: (k, m, 2) polygons -> (k,) signed area, (k, 2) centroid."""
    p, q = polygons, np.roll(polygons, -1, axis=1)
    cross = p[..., 0] * q[..., 1] - q[..., 0] * p[..., 1]
    area = cross.sum(axis=1) / 2
    centroid = ((p + q) * cross[..., None]).sum(axis=1) / (6 * area[:, None])
    return area, centroid


# ---------------------------------------------------------------------- the scene
def build_arch(params: ArchGeometry) -> Scene:
    """The arch scene: support blocks 0 (right) and 1 (left), then voussoirs ``v000``,
    ... from the right springing to the left one, as hexahedra extruded along y.

    Each voussoir's course direction (``Scene.block_up``) runs along the arch towards
    the crown, so every joint between voussoirs is a bed joint (``horizontal`` in
    :class:`~masonry.interfaces.Interfaces` kinds, however steep).
    """
    check_arch(params)
    p = params
    profile = arch_profile(p.arch_shape, p.arch_blocks, p.arch_span, p.arch_thickness,
                           p.arch_rise)
    quads = profile.voussoirs
    # supports: the springing joint on top, vertical sides, a thickness t deep below
    supports = []
    for inner, outer in ((profile.intrados[0], profile.extrados[0]),
                         (profile.intrados[-1], profile.extrados[-1])):
        bottom = min(inner[1], outer[1]) - p.arch_thickness
        supports.append([[inner[0], bottom], [outer[0], bottom], outer, inner])
    quads = np.concatenate([np.array(supports), quads])
    # hexahedron corner ix + 2 iy + 4 iz (blocks.HEX_FACES): ix 0 intrados / 1 extrados,
    # iy the depth, iz 0 the joint nearer the right springing (or the bottom)
    corners = np.empty((len(quads), 8, 3))
    for iz, (inner, outer) in enumerate(((0, 1), (3, 2))):
        for ix, corner in enumerate((inner, outer)):
            for iy, y in enumerate((-p.arch_depth / 2, p.arch_depth / 2)):
                corners[:, ix + 2 * iy + 4 * iz] = np.stack(
                    [quads[:, corner, 0], np.full(len(quads), y), quads[:, corner, 1]], axis=1)
    n = p.arch_blocks
    names = ["support_right", "support_left"] + [f"v{k:03d}" for k in range(n)]
    blocks = Blocks.from_hexahedra(corners, block_class=[GROUND] * 2 + [BLOCK] * n,
                                   block_name=names)
    mid = (profile.intrados + profile.extrados) / 2
    along = mid[1:] - mid[:-1]
    along /= np.linalg.norm(along, axis=1, keepdims=True)
    along = np.where((np.arange(n) <= (n - 1) // 2)[:, None], along, -along)
    up = np.zeros((n + 2, 3))
    up[:2, 2] = 1.0
    up[2:, 0], up[2:, 2] = along[:, 0], along[:, 1]
    return Scene(Arch, params, blocks, block_up=up)


class Arch(SceneKind):
    """``arch``: voussoirs on two supports, in the xz-plane."""

    name = "arch"
    geometry = ArchGeometry
    block_word = "blocks"
    has_courses = False
    moved_for_cad = False
    id_prefix_name = "arch"
    summary = "voussoirs on two supports (the arch options)"

    @classmethod
    def build(cls, geometry) -> Scene:
        return build_arch(geometry)

    @classmethod
    def check(cls, geometry):
        check_arch(geometry)

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        return float(geometry.arch_blocks)

    @classmethod
    def thrust_section(cls, scene) -> ThrustSection:
        bounds = scene.blocks.bounds
        return ThrustSection(float(bounds[:, 1].mean()), 0,
                             (float(bounds[:, 0].mean()), float(bounds[0, 2])), False,
                             "the arch")

    @classmethod
    def shown(cls, geometry) -> dict:
        """The arch's dimensions, the rise resolved to the shape's default, the span and
        rise of the centre line first."""
        shown = super().shown(geometry)
        if geometry.arch_rise is None:
            shown["arch_rise"] = arch_radius(geometry.arch_shape, geometry.arch_span)[1]
        order = ("arch_shape", "arch_blocks", "arch_span", "arch_rise", "arch_thickness",
                 "arch_depth")
        return {name: shown[name] for name in order}
