"""The thrust line: where the resultant of the bed joints at the structure's mid-plane
acts, drawn in that plane over the joints, hinges and points outside their joint marked.

The joints the plane reaches are grouped by level: joints that share a block facing
both the same way bear between the same bricks (a brick on two that meet at the plane,
whose joints only touch it along their edge, or two under one), and act as one joint
whose resultant is their sum. A line joins the levels' points along a chain (each level shares
a block with the next: one column of blocks); it breaks where a level shares no block
with the next (the plane leaves the column: the load passes beside it) and where a
level carries no normal force (its resultant has no point)."""

import matplotlib.pyplot as plt
import numpy as np
from scipy.sparse.csgraph import connected_components

from masonry.plots.colours import HINGE, NO_FORCE, TENSION, THRUST
from masonry.plots.common import HORIZONTAL_KINDS, PNG, figure_files
from masonry.rbe.resultants import NO_NORMAL_FORCE_REL
from masonry.tolerances import THRUST_PLANE_REL

HINGE_ECCENTRICITY = 0.99
"""A level whose resultant lies at least this far out (eccentricity in the section, 1 =
on the joint's end) is marked as a hinge in the thrust line plot."""


def _count(n, noun) -> str:
    """``'1 hinge'``, ``'3 hinges'``."""
    return f"{int(n)} {noun}{'' if n == 1 else 's'}"


def _cut_at_y(interfaces, index, y, tolerance=0.0):
    """(n, 2, 3) where the polygons ``index`` meet the plane y = ``y``: the two points
    farthest apart among their edges' crossings and their vertices within
    ``tolerance`` of it (a polygon that touches the plane along an edge gives that
    edge)."""
    segments = []
    for k in index:
        polygon = interfaces.polygon(k)
        following = np.roll(polygon, -1, axis=0)
        a, b = polygon[:, 1] - y, following[:, 1] - y
        crossing = ((a < -tolerance) & (b > tolerance)) | ((a > tolerance) & (b < -tolerance))
        s = a[crossing] / (a[crossing] - b[crossing])
        points = np.concatenate([
            polygon[crossing] + s[:, None] * (following[crossing] - polygon[crossing]),
            polygon[np.abs(a) <= tolerance]])
        apart = np.linalg.norm(points[:, None] - points[None], axis=-1)
        first, last = np.unravel_index(np.argmax(apart), apart.shape)
        segments.append(points[[first, last]])
    return np.array(segments).reshape(-1, 2, 3)


def _plane_joints(section, interfaces, tolerance):
    """The bed joints that reach the plane of ``section`` (a
    :class:`~masonry.scenes.base.ThrustSection`) within ``tolerance`` (metres), crossing
    it or touching it along an edge."""
    y = section.y
    low = np.minimum.reduceat(interfaces.vertices[:, 1], interfaces.offsets[:-1])
    high = np.maximum.reduceat(interfaces.vertices[:, 1], interfaces.offsets[:-1])
    bed = (np.isin(interfaces.kind, HORIZONTAL_KINDS) & (low <= y + tolerance)
           & (high >= y - tolerance))
    if section.facing_x:
        bed &= interfaces.centre[:, 0] > 0
    return np.flatnonzero(bed)


def joint_levels(pairs, normals) -> np.ndarray:
    """The level of each bed joint: joints that share a block which faces both the same
    way (a brick on two, or two bricks under one) bear between the same bricks.

    Parameters
    ----------
    pairs : (n, 2) int
        The blocks of each joint.
    normals : (n, 3) float
        Each joint's unit normal, from its first block into its second.

    Returns
    -------
    (n,) int
        A label per joint, equal for the joints of one level.
    """
    pairs = np.asarray(pairs).reshape(-1, 2)
    normals = np.asarray(normals, dtype=float).reshape(-1, 3)
    if len(pairs) == 0:
        return np.zeros(0, int)
    # a block faces a joint along its normal from the first block, against it from the
    # second; the crown of an arch, where both neighbours lean on one voussoir from
    # either side, faces them opposite ways
    facing = normals @ normals.T
    linked = np.zeros(facing.shape, bool)
    for s, t in ((0, 0), (0, 1), (1, 0), (1, 1)):
        sign = 1 if s == t else -1
        linked |= (pairs[:, s][:, None] == pairs[:, t][None, :]) & (sign * facing > 0)
    return connected_components(linked, directed=False)[1]


def chains(blocks, has_point=None) -> list:
    """The runs of consecutive levels that form a chain: each shares a block with the
    next (one column of bricks, the block above a level the one below the next), and
    each has a point (a normal force).

    Parameters
    ----------
    blocks : sequence of collections of int
        The blocks of each level (a joint's pair), in order along the section.
    has_point : (n,) bool, optional
        Whether each level's resultant has a point (all, when None).

    Returns
    -------
    list of (k,) int
        Positions into ``blocks``, every level in exactly one run, in order; a level
        that shares no block with its neighbours, or has no point, is a run of one.
    """
    count = len(blocks)
    if count == 0:
        return []
    has_point = np.ones(count, bool) if has_point is None else np.asarray(has_point)
    linked = np.array([bool(set(a) & set(b)) for a, b in zip(blocks[:-1], blocks[1:])],
                      dtype=bool) & has_point[:-1] & has_point[1:]
    return np.split(np.arange(count), np.flatnonzero(~linked) + 1)


def _levels(section, interfaces, resultants):
    """The levels of the bed joints at the plane of ``section`` (:func:`joint_levels`),
    in order along it (an arch left to right, a web upward).

    Returns
    -------
    dict
        ``joints`` (list of (k,) int, interface ids), ``blocks`` (list of sets),
        ``segment`` ((L, 2, 2) float, metres: in x-z, each level's inner end, nearer the
        arch's or dome's centre, then its outer one), ``point`` ((L, 2) float, metres:
        the point of the level's resultant in x-z, NaN where it has no normal force),
        ``eccentricity`` ((L,) float: the point's distance from the segment's middle
        over half its length, along it; NaN without a point). None when no bed joint
        reaches the plane.
    """
    size = float(np.ptp(interfaces.vertices, axis=0).max()) if len(interfaces) else 0.0
    tolerance = THRUST_PLANE_REL * size
    index = _plane_joints(section, interfaces, tolerance)
    if len(index) == 0:
        return None
    label = joint_levels(interfaces.pair[index], interfaces.normal[index])
    members = [index[label == k] for k in range(label.max() + 1)]
    along = [interfaces.centre[joints, section.axis].mean() for joints in members]
    members = [members[k] for k in np.argsort(along, kind="stable")]
    cut = _cut_at_y(interfaces, index, section.y, tolerance)[:, :, [0, 2]]
    where = {int(k): n for n, k in enumerate(index)}
    centre = np.array(section.centre)
    segment, point = np.zeros((len(members), 2, 2)), np.full((len(members), 2), np.nan)
    for n, joints in enumerate(members):
        ends = cut[[where[int(k)] for k in joints]].reshape(-1, 2)
        radius = np.linalg.norm(ends - centre, axis=1)
        segment[n] = ends[[np.argmin(radius), np.argmax(radius)]]
        point[n] = _level_point(resultants, joints)[[0, 2]]
    span = segment[:, 1] - segment[:, 0]
    t = np.einsum("ij,ij->i", point - segment[:, 0], span) / np.einsum("ij,ij->i", span, span)
    return {"joints": members, "segment": segment, "point": point,
            "blocks": [set(interfaces.pair[joints].ravel().tolist()) for joints in members],
            "eccentricity": np.abs(2 * t - 1)}


def _level_point(resultants, joints) -> np.ndarray:
    """(3,) the point of the resultant of ``joints`` (one level: coplanar, their normals
    parallel), where the normal forces' sum acts: their points weighted by their net
    normal forces; NaN where that sum is within :data:`~masonry.rbe.resultants.
    NO_NORMAL_FORCE_REL` of their sizes (a couple, or no force)."""
    sigma, point = resultants["sigma"][joints], resultants["point"][joints]
    has_point = np.isfinite(point).all(axis=1)
    total = sigma[has_point].sum()
    if not has_point.any() or abs(total) <= NO_NORMAL_FORCE_REL * np.abs(sigma).sum():
        return np.full(3, np.nan)
    return sigma[has_point] @ point[has_point] / total


def _draw_points(ax, levels) -> dict:
    """The levels' points, joined by a line along each chain (:func:`chains`), alone
    (hollow) where a level is in none, and a grey cross at the middle of a level with no
    normal force; returns how many levels are alone and without force."""
    point, has_point = levels["point"], np.isfinite(levels["point"]).all(axis=1)
    runs = chains(levels["blocks"], has_point)
    line = dict(color=THRUST, markersize=2.5, linewidth=1.2)
    for k, run in enumerate(run for run in runs if len(run) > 1):
        ax.plot(point[run, 0], point[run, 1], "-o", **line,
                label="the resultant's point on each joint, joined along a column of "
                      "blocks (thrust line)" if k == 0 else None)
    alone = np.array([run[0] for run in runs if len(run) == 1 and has_point[run[0]]], int)
    if len(alone):
        ax.plot(point[alone, 0], point[alone, 1], "D", markerfacecolor="none",
                markeredgecolor=THRUST, markersize=4, linestyle="none",
                label="a joint's point, the line broken: no block joins it to the next "
                      "joint at the plane (the load passes beside the plane)")
    empty = ~has_point
    if empty.any():
        middle = levels["segment"][empty].mean(axis=1)
        ax.plot(middle[:, 0], middle[:, 1], "x", color=NO_FORCE, markersize=6,
                label="a joint with no normal force (no point: the line broken)")
    return {"alone": len(alone), "empty": int(empty.sum())}


def thrust_line_png(interfaces, resultants, section, fast=False, title="", render=PNG):
    """The thrust line: the resultants' points of application on the bed joints at the
    structure's mid-plane (an arch's plane; a dome web's meridian section at its centre
    line, y = 0), a level's joints as one (:func:`joint_levels`), in x-z, hinges and
    points outside their joint marked: its files by format
    (:func:`~masonry.plots.common.figure_files` of ``render``). None when no bed joint
    reaches the plane.

    Parameters
    ----------
    interfaces : Interfaces
    resultants : dict
        :func:`masonry.rbe.resultants.interface_resultants` of ``interfaces``.
    section : masonry.scenes.base.ThrustSection
        The plane and the order of its joints (the scene kind's ``thrust_section``).
    title : str
        The line under the figure's own.
    """
    levels = _levels(section, interfaces, resultants)
    if levels is None:
        return None
    segments = levels["segment"]
    width, height = np.ptp(segments.reshape(-1, 2), axis=0)
    # a figure of the structure's proportions (equal scales), the legend below the axes
    fig, ax = plt.subplots(figsize=(7, min(6.0 * height / width, 8.0) + 2.0),
                           layout="constrained")
    for seg in segments:
        ax.plot(seg[:, 0], seg[:, 1], color="0.55", linewidth=1)
    for end in (0, 1):
        ax.plot(segments[:, end, 0], segments[:, end, 1], color="0.3", linewidth=0.6)
    ax.plot([], [], color="0.55", label="bed joints at the plane and their ends (the section)")
    shown = _draw_points(ax, levels)
    point, e = levels["point"], levels["eccentricity"]
    hinge = (e >= HINGE_ECCENTRICITY) & (e <= 1 + 1e-6)
    outside = e > 1 + 1e-6
    if hinge.any():
        ax.plot(point[hinge, 0], point[hinge, 1], "o", markerfacecolor="none", markersize=8,
                markeredgewidth=1.5, color=HINGE,
                label=f"hinge ({HINGE_ECCENTRICITY:g} <= eccentricity <= 1)")
    if outside.any():
        ax.plot(point[outside, 0], point[outside, 1], "x", markersize=7, color=TENSION,
                label="the line leaves the section: outside its joint (needs tension)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    fig.legend(loc="outside lower center", fontsize=7, frameon=False)
    broken = [_count(shown[key], noun) for key, noun in
              (("alone", "joint off the column"), ("empty", "joint without force"))
              if shown[key]]
    joints = sum(len(k) for k in levels["joints"])
    ax.set_title(f"thrust line under self-weight through {_count(len(segments), 'level')} "
                 f"of bed joints ({joints} joints) at {section.name}"
                 f"{', ' if broken else ''}{', '.join(broken)}: "
                 f"{_count(hinge.sum(), 'hinge')}, {int(outside.sum())} outside\n{title}",
                 fontsize=9)
    return figure_files(fig, 80 if fast else 150, render)
