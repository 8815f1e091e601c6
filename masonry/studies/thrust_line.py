"""The thrust line of a symmetric arch: an independent check of the RBE on the arch scene.

The classical limit analysis of a symmetric arch of rigid, no-tension voussoirs (Heyman),
written on the 2D profile (:class:`~masonry.scenes.arch.ArchProfile`), not on the RBE
matrices: the tests and ``masonry arch-thickness`` hold the RBE's minimum thickness
against it.
"""

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from masonry.scenes.arch import arch_radius
from masonry.scenes.arch import ArchProfile, arch_profile, polygon_area_centroid
from masonry.tolerances import (THRUST_ACTIVE_REL, THRUST_MARGIN_XATOL_REL, THRUST_SCAN,
                                THRUST_XTOL)


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
    area, centroid = polygon_area_centroid(quads)
    area = np.abs(area)
    last = n // 2  # voussoirs 0 .. last - 1 are whole in the right half
    w, wx = area[:last], area[:last] * centroid[:last, 0]
    if n % 2:
        i, e = profile.intrados[last], profile.extrados[last]
        half_key = np.array([[i, e, [0.0, e[1]], [0.0, i[1]]]])
        a, c = polygon_area_centroid(half_key)
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
        within :data:`~masonry.tolerances.THRUST_ACTIVE_REL` of the margin's scale.
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
                            options={"xatol": THRUST_MARGIN_XATOL_REL * total})
    H = float(found.x)
    low, high = lines(H)
    scale = THRUST_ACTIVE_REL * total * profile.radius
    return (float(gap(H) / (total * profile.radius)), H,
            low >= low.max() - scale, high <= high.min() + scale)


def thrust_line_minimum_thickness(shape: str, n_blocks: int, span: float, rise=None,
                                  mu=np.inf, xtol=THRUST_XTOL) -> ThrustLine:
    """The thinnest arch of this shape that a thrust line fits (Heyman's minimum
    thickness), by root finding on :func:`thrust_line_margin` in ``t``.

    ``t/R`` is scanned on a grid up to the intrados's limit
    (:data:`~masonry.tolerances.THRUST_SCAN`) for the first
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

    first, last, count = THRUST_SCAN
    grid = np.geomspace(first, last * limit, count)
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
