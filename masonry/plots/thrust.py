"""The thrust line: where the resultant of every bed joint that crosses the structure's
mid-plane acts, drawn in that plane over the joints, hinges and joints that would need
tension marked. A line joins the points only along a chain of joints (one column of
blocks); a joint with no neighbour in its column is a point alone."""

import matplotlib.pyplot as plt
import numpy as np

from masonry.plots.colours import HINGE, TENSION, THRUST
from masonry.plots.common import HORIZONTAL_KINDS, PNG, figure_files

HINGE_ECCENTRICITY = 0.99
"""A joint whose resultant lies at least this far out (eccentricity, 1 = on the edge) is
marked as a hinge in the thrust line plot."""


def _count(n, noun) -> str:
    """``'1 hinge'``, ``'3 hinges'``."""
    return f"{int(n)} {noun}{'' if n == 1 else 's'}"


def _cut_at_y(interfaces, index, y):
    """(n, 2, 3) the segments where the polygons ``index`` cross the plane y = ``y``."""
    segments = []
    for k in index:
        polygon = interfaces.polygon(k)
        following = np.roll(polygon, -1, axis=0)
        a, b = polygon[:, 1] - y, following[:, 1] - y
        crossing = (a <= 0) != (b <= 0)
        s = a[crossing] / (a[crossing] - b[crossing])
        points = polygon[crossing] + s[:, None] * (following[crossing] - polygon[crossing])
        segments.append(points[[0, -1]])
    return np.array(segments).reshape(-1, 2, 3)


def _mid_plane_joints(section, interfaces, resultants):
    """The bed joints that cross the plane of ``section`` (a
    :class:`~masonry.scenes.base.ThrustSection`) with a resultant, in order along it (an
    arch left to right, a web upward); empty when no bed joint crosses it."""
    y = section.y
    low = np.minimum.reduceat(interfaces.vertices[:, 1], interfaces.offsets[:-1])
    high = np.maximum.reduceat(interfaces.vertices[:, 1], interfaces.offsets[:-1])
    bed = np.isin(interfaces.kind, HORIZONTAL_KINDS) & (low < y) & (high > y)
    if section.facing_x:
        bed &= interfaces.centre[:, 0] > 0
    index = np.flatnonzero(bed & np.isfinite(resultants["eccentricity"]))
    along = interfaces.centre[index, section.axis]
    return index[np.argsort(along, kind="stable")]


def _joint_segments(section, interfaces, index):
    """(n, 2, 2) the joints ``index`` cut by the plane of ``section``, in x-z (metres),
    each from its inner end to its outer one."""
    segments = _cut_at_y(interfaces, index, section.y)[:, :, [0, 2]]
    # order each joint's ends inner (nearer the arch's or dome's centre) to outer: the
    # ends then trace the intrados and the extrados
    centre = np.array(section.centre)
    outer_first = (np.linalg.norm(segments[:, 0] - centre, axis=1)
                   > np.linalg.norm(segments[:, 1] - centre, axis=1))
    segments[outer_first] = segments[outer_first, ::-1]
    return segments


def chains(pairs) -> list:
    """The runs of consecutive joints that form a chain: each joint shares a block with
    the next (one column of bricks, the block above a joint the one below the next).

    Parameters
    ----------
    pairs : (n, 2) int
        The blocks of each joint, in order along the section.

    Returns
    -------
    list of (k,) int
        Positions into ``pairs``, every joint in exactly one run, in order; a joint that
        shares no block with its neighbours is a run of one.
    """
    pairs = np.asarray(pairs).reshape(-1, 2)
    if len(pairs) == 0:
        return []
    linked = [bool(set(a) & set(b)) for a, b in zip(pairs[:-1], pairs[1:])]
    breaks = np.flatnonzero(~np.array(linked, dtype=bool)) + 1
    return np.split(np.arange(len(pairs)), breaks)


def _draw_points(ax, point, runs) -> int:
    """The resultants' points, joined by a line along each chain of joints
    (:func:`chains`), alone (hollow) where a joint is in none; returns how many are
    alone."""
    alone = np.concatenate([run for run in runs if len(run) == 1] or [np.zeros(0, int)])
    line = dict(color=THRUST, markersize=2.5, linewidth=1.2)
    for k, run in enumerate(run for run in runs if len(run) > 1):
        ax.plot(point[run, 0], point[run, 2], "-o", **line,
                label="point of application of the resultant (thrust line)" if k == 0
                else None)
    if len(alone):
        ax.plot(point[alone, 0], point[alone, 2], "D", markerfacecolor="none",
                markeredgecolor=THRUST, markersize=4, linestyle="none",
                label="a joint's resultant, not in a chain of joints (no line)")
    return len(alone)


def thrust_line_png(interfaces, resultants, section, fast=False, title="", render=PNG):
    """The thrust line: the resultants' points of application on the bed joints that
    cross the structure's mid-plane (an arch's plane; a dome web's meridian section at
    its centre line, y = 0), in x-z, hinges marked: its files by format
    (:func:`~masonry.plots.common.figure_files` of ``render``). None when no bed joint
    crosses it.

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
    index = _mid_plane_joints(section, interfaces, resultants)
    if len(index) == 0:
        return None
    segments = _joint_segments(section, interfaces, index)
    width, height = np.ptp(segments.reshape(-1, 2), axis=0)
    # a figure of the structure's proportions (equal scales), the legend below the axes
    fig, ax = plt.subplots(figsize=(7, min(6.0 * height / width, 8.0) + 1.8),
                           layout="constrained")
    for seg in segments:
        ax.plot(seg[:, 0], seg[:, 1], color="0.55", linewidth=1)
    for end in (0, 1):
        ax.plot(segments[:, end, 0], segments[:, end, 1], color="0.3", linewidth=0.6)
    ax.plot([], [], color="0.55", label="bed joints and their ends (mid-plane section)")
    point = resultants["point"][index]
    alone = _draw_points(ax, point, chains(interfaces.pair[index]))
    e = resultants["eccentricity"][index]
    hinge = (e >= HINGE_ECCENTRICITY) & (e <= 1 + 1e-6)
    outside = e > 1 + 1e-6
    if hinge.any():
        ax.plot(point[hinge, 0], point[hinge, 2], "o", markerfacecolor="none", markersize=8,
                markeredgewidth=1.5, color=HINGE, label=f"hinge ({HINGE_ECCENTRICITY:g} <= eccentricity <= 1)")
    if outside.any():
        ax.plot(point[outside, 0], point[outside, 2], "x", markersize=7, color=TENSION,
                label="outside its joint (needs tension)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    fig.legend(loc="outside lower center", fontsize=7, frameon=False)
    chained = f", {alone} not in a chain" if alone else ""
    ax.set_title(f"thrust line under self-weight through {len(index)} bed joints at "
                 f"{section.name}{chained}: {_count(hinge.sum(), 'hinge')}, "
                 f"{int(outside.sum())} outside\n{title}", fontsize=9)
    return figure_files(fig, 80 if fast else 150, render)
