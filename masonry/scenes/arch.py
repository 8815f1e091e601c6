"""The ``arch`` scene: an arch of voussoirs on two supports.

Geometry (SPEC 8, Heyman's conventions). The arch lies in the xz-plane, its span along x,
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

from dataclasses import dataclass

import numpy as np

from masonry.blocks import BLOCK, GROUND, Blocks
from masonry.params import Params, arch_radius, check_arch
from masonry.scenes.base import Scene


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
    (:func:`~masonry.params.arch_radius`). Inputs are assumed valid
    (:func:`~masonry.params.check_arch`).
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
def build_arch(params: Params):
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
    return Scene(params, blocks, block_up=up)
