"""The ``arch`` scene: an arch of voussoirs on two supports, and its thrust line.

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

The thrust line (:func:`thrust_line_minimum_thickness`) is an independent check of the
rigid block equilibrium on this scene: the classical limit analysis of a symmetric arch
of rigid, no-tension voussoirs (Heyman), written on the 2D profile, not on the RBE
matrices.
"""

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from .blocks import BLOCK_CLASSES, Blocks
from .params import ParameterError, Params

GROUND = BLOCK_CLASSES.index("ground")
BLOCK = BLOCK_CLASSES.index("block")


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
    h = span * np.sqrt(3) / 2 if rise is None else rise
    return (span**2 / 4 + h**2) / span, h


def check_arch(params: Params) -> None:
    """Refuse arch parameters that make no arch (:class:`ParameterError`).

    The ranges that do not depend on the shape are checked by
    :func:`masonry.params.validate`; here: the rise against the shape, an even number of
    voussoirs for a pointed arch, and a thickness that leaves an intrados.
    """
    p = params
    span, rise, t = p.arch_span, p.arch_rise, p.arch_thickness
    if p.arch_shape == "semicircular" and rise is not None and rise != span / 2:
        raise ParameterError("arch_rise", rise, f"none for a semicircular arch (its rise is "
                                                f"span / 2 = {span / 2:g} m)")
    if p.arch_shape == "segmental" and rise is not None and not 0 < rise < span / 2:
        raise ParameterError("arch_rise", rise, f"0 < rise < span / 2 = {span / 2:g} m for "
                                                "a segmental arch")
    if p.arch_shape == "pointed":
        if rise is not None and not rise > span / 2:
            raise ParameterError("arch_rise", rise, f"> span / 2 = {span / 2:g} m for a "
                                                    "pointed arch")
        if p.arch_blocks % 2:
            raise ParameterError("arch_blocks", p.arch_blocks, "an even number for a "
                                                               "pointed arch")
    radius, _ = arch_radius(p.arch_shape, span, rise)
    # the intrados must exist: radius R - t/2 > 0, and for a pointed arch it must still
    # reach the crown, R - t/2 > R - span/2
    limit = span if p.arch_shape == "pointed" else 2 * radius
    if not t < limit:
        raise ParameterError("arch_thickness", t, f"< {limit:g} m (the intrados of this "
                                                  f"arch vanishes at t = {limit:g} m)")


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


def _polygon_area_centroid(polygons):
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
    from .scenes import Scene

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


# ---------------------------------------------------------------------- thrust line
@dataclass(frozen=True)
class ThrustLine:
    """Outcome of :func:`thrust_line_minimum_thickness`.

    Parameters
    ----------
    t_over_r : float
        Minimum thickness over the centre-line radius.
    thickness, radius : float, metres
    thrust : float
        Horizontal thrust at the minimum, per weight of the whole arch.
    intrados_hinges, extrados_hinges : tuple of int
        Joints (0 = right springing) where the thrust line touches the intrados or the
        extrados at the minimum (both halves: the line is symmetric).
    """

    t_over_r: float
    thickness: float
    radius: float
    thrust: float
    intrados_hinges: tuple
    extrados_hinges: tuple


def _half_arch(profile: ArchProfile):
    """Joints and loads of the right half, for :func:`thrust_line_margin`.

    Returns ``A, B`` ((J, 2) intrados and extrados ends of the joints from the right
    springing up to the crown), ``V, M`` ((J,) weight, per unit depth and unit weight
    density, of the part between each joint and the crown, and its moment about x = 0)
    and the total weight of the arch. For even N the crown joint is the last joint (no
    load above it); for odd N the keystone is cut at x = 0 and its right half belongs
    to the half arch, whose crown section is then no joint.
    """
    n = profile.n_blocks
    quads = profile.voussoirs
    area, centroid = _polygon_area_centroid(quads)
    area = np.abs(area)
    last = n // 2  # voussoirs 0 .. last - 1 are whole in the right half
    w, wx = area[:last], area[:last] * centroid[:last, 0]
    if n % 2:
        i, e = profile.intrados[last], profile.extrados[last]
        half_key = np.array([[i, e, [0.0, e[1]], [0.0, i[1]]]])
        a, c = _polygon_area_centroid(half_key)
        w, wx = np.append(w, abs(a[0])), np.append(wx, abs(a[0]) * c[0, 0])
    # part above joint j: voussoirs j .. the crown; for even N the crown joint (last)
    # carries nothing above it
    V = np.cumsum(w[::-1])[::-1]
    M = np.cumsum(wx[::-1])[::-1]
    if n % 2 == 0:
        V, M = np.append(V, 0.0), np.append(M, 0.0)
    A, B = profile.intrados[:last + 1], profile.extrados[:last + 1]
    return A, B, V, M, float(area.sum())


def thrust_line_margin(profile: ArchProfile, mu=np.inf):
    """How far the best thrust line stays inside the arch (> 0) or leaves it (< 0).

    The arch is symmetric, so a thrust line exists iff a symmetric one does (the mean
    of a line and its mirror image is one): at the crown a horizontal thrust ``H`` acts
    at height ``y``. Moment equilibrium of the part between joint ``j`` and the crown
    about the point ``P`` where the thrust line crosses joint ``j`` gives
    ``H (P_z - y) = M_j - V_j P_x``. With ``u = H y``, ``P`` lies on the joint between
    its intrados end ``A_j`` and extrados end ``B_j`` iff::

        l_j(H) = H A_jz + V_j A_jx - M_j  <=  u  <=  H B_jz + V_j B_jx - M_j = u_j(H)

    (the joint's direction has non-negative components on the right half, so the
    thrust crosses every joint the same way). For a given ``H`` the feasible ``u`` lie
    between ``L(H) = max_j l_j(H)`` and ``U(H) = min_j u_j(H)``; the margin
    ``g(H) = U(H) - L(H)`` is concave (piecewise linear), and its maximum over ``H > 0``
    is found by a bounded scalar search. Coulomb friction ``|T| <= mu N`` of the joint
    force ``(-H, V_j)`` bounds ``H``.

    Returns
    -------
    margin : float
        ``max g`` per (total weight x R), dimensionless; >= 0 iff a thrust line fits and
        no joint slides; -inf when friction leaves no thrust.
    H : float
        The thrust at the maximum, per unit weight density and depth (NaN if none).
    lower_active, upper_active : (J,) bool or None
        The joints whose intrados (lower) or extrados (upper) bound is active there,
        within 1e-7 of the margin's scale.
    """
    A, B, V, M, total = _half_arch(profile)
    d = B - A
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    h_lo, h_hi = 0.0, np.inf
    if np.isfinite(mu):
        # T = -H dx + V dz, N = H dz + V dx: T <= mu N and -T <= mu N, as a H <= b
        for a, b in ((-d[:, 0] - mu * d[:, 1], V * (mu * d[:, 0] - d[:, 1])),
                     (d[:, 0] - mu * d[:, 1], V * (mu * d[:, 0] + d[:, 1]))):
            if ((a == 0) & (b < 0)).any():
                return -np.inf, np.nan, None, None
            h_hi = min(h_hi, np.min(b[a > 0] / a[a > 0], initial=np.inf))
            h_lo = max(h_lo, np.max(b[a < 0] / a[a < 0], initial=0.0))
    if h_lo > h_hi:
        return -np.inf, np.nan, None, None

    def lines(H):
        H = np.asarray(H, dtype=float)[..., None]
        return H * A[:, 1] + V * A[:, 0] - M, H * B[:, 1] + V * B[:, 0] - M

    def gap(H):
        low, high = lines(H)
        return high.min(axis=-1) - low.max(axis=-1)

    # g is concave: double an upper bound until g falls, then search inside it
    top = h_hi if np.isfinite(h_hi) else max(h_lo, total)
    while not np.isfinite(h_hi) and gap(2 * top) > gap(top):
        top *= 2
    top = min(2 * top, h_hi)
    found = minimize_scalar(lambda H: -gap(H), bounds=(h_lo, top), method="bounded",
                            options={"xatol": 1e-13 * total})
    H = float(found.x)
    low, high = lines(H)
    scale = 1e-7 * total * profile.radius
    return (float(gap(H) / (total * profile.radius)), H,
            low >= low.max() - scale, high <= high.min() + scale)


def thrust_line_minimum_thickness(shape: str, n_blocks: int, span: float, rise=None,
                                  mu=np.inf, xtol=1e-12) -> ThrustLine:
    """The thinnest arch of this shape that a thrust line fits (Heyman's minimum
    thickness), by root finding on :func:`thrust_line_margin` in ``t``.

    ``t/R`` is scanned on a grid from 1e-3 up to the intrados's limit for the first
    thickness with a thrust line, then refined with Brent's method (``xtol`` in t/R):
    the smallest feasible thickness even if the margin were not monotonic in ``t``.

    Raises
    ------
    ValueError
        No thickness up to the limit has a thrust line (friction too low).
    """
    radius, rise = arch_radius(shape, span, rise)
    limit = (span if shape == "pointed" else 2 * radius) / radius

    def margin(ratio):
        profile = arch_profile(shape, n_blocks, span, ratio * radius, rise)
        return thrust_line_margin(profile, mu)[0]

    grid = np.geomspace(1e-3, 0.999 * limit, 60)
    for lo, hi in itertools.pairwise(grid):
        if margin(hi) >= 0:
            break
    else:
        raise ValueError(f"no thrust line fits this {shape} arch below t/R = {grid[-1]:.3g}")
    ratio = brentq(margin, lo, hi, xtol=xtol) if margin(lo) < 0 else lo
    profile = arch_profile(shape, n_blocks, span, ratio * radius, rise)
    _, H, lower, upper = thrust_line_margin(profile, mu)
    _, _, _, _, total = _half_arch(profile)
    n = n_blocks

    def both_halves(active):
        joints = np.flatnonzero(active)
        return tuple(sorted(set(joints.tolist()) | set((n - joints).tolist())))

    return ThrustLine(t_over_r=float(ratio), thickness=float(ratio * radius),
                      radius=float(radius), thrust=float(H / total),
                      intrados_hinges=both_halves(lower), extrados_hinges=both_halves(upper))
