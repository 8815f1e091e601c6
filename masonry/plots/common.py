"""What every figure shares: the block class colours (:data:`masonry.blocks.CLASS_COLOURS`),
the four views and their axes, polygons, lines and markers drawn in any view, titles, and
the PNG bytes a figure becomes.

A view is 3D (``01_angle``, from :data:`ANGLE`) or an elevation (:data:`ELEVATIONS`),
drawn as a 2D projection at equal scale; the drawing helpers take the view's name and
draw in either.
"""

import io

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from masonry.blocks import CLASS_COLOURS  # noqa: F401 (the figures' name for it)
from masonry.interfaces import INTERFACE_KINDS

# the thesis's four views (section 3.4): a 3D view from an angle (elevation, azimuth in
# degrees) and three elevations, drawn as 2D projections at equal scale (3D axes seen
# end on pile their tick labels up): (horizontal axis, vertical axis, depth axis, +1 when
# a larger depth coordinate is nearer the viewer)
VIEWS = ("01_angle", "02_front", "03_top", "04_side")
ANGLE = (25, -50)
ELEVATIONS = {"02_front": (1, 2, 0, 1), "03_top": (0, 1, 2, 1), "04_side": (0, 2, 1, -1)}

NO_FILL = (0.0, 0.0, 0.0, 0.0)
"""Face colour of polygons drawn as outlines only."""

HORIZONTAL_KINDS = (INTERFACE_KINDS.index("horizontal"), INTERFACE_KINDS.index("support"))
"""Interface kinds drawn as bed joints (with the supports); every other kind is a head
joint."""


def png_bytes(fig, dpi) -> bytes:
    """``fig`` as PNG bytes at ``dpi``, cropped to what it draws; the figure is closed."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def view_axes(bounds, view):
    """Axes for ``view`` on ``bounds`` ((2, 3) float, metres), equal scale."""
    if view not in ELEVATIONS:
        return axes_3d(bounds)
    h, v, _, _ = ELEVATIONS[view]
    fig, ax = plt.subplots(figsize=(7, 6))
    margin = 0.03 * float(np.ptp(bounds, axis=0).max())
    ax.set_xlim(bounds[0, h] - margin, bounds[1, h] + margin)
    ax.set_ylim(bounds[0, v] - margin, bounds[1, v] + margin)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[h]} [m]")
    ax.set_ylabel(f"{'xyz'[v]} [m]")
    return fig, ax


def axes_3d(bounds):
    """3D axes from :data:`ANGLE` on ``bounds`` at equal scale in x, y and z."""
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    # the box follows the extents (a cube around a flat dome leaves half the figure
    # empty); very thin extents are widened so the box stays readable
    extent = np.maximum(bounds[1] - bounds[0], 0.15 * (bounds[1] - bounds[0]).max())
    centre = bounds.mean(axis=0)
    low, high = centre - extent / 2, centre + extent / 2
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_zlim(low[2], high[2])
    ax.set_box_aspect(tuple(extent))
    ax.view_init(*ANGLE)
    for k, axis in enumerate("xyz"):
        getattr(ax, f"set_{axis}label")(f"{axis} [m]", labelpad=10)
        # fewer ticks on a shorter side, one on a thin one (a wall's or an arch's
        # thickness): their labels would overlap each other and the next axis's
        ticks = matplotlib.ticker.MaxNLocator(max(2, int(np.ceil(5 * extent[k]
                                                                 / extent.max()))))
        if extent[k] < 0.3 * extent.max():
            nice = ticks.tick_values(low[k], high[k])
            ticks = matplotlib.ticker.FixedLocator([nice[np.argmin(np.abs(nice
                                                                          - centre[k]))]])
        getattr(ax, f"{axis}axis").set_major_locator(ticks)
    return fig, ax


def add_polygons(ax, view, polygons, facecolors, edgecolors="face", linewidths=0.3):
    """Draw ``polygons`` (list of (m, 3) float, metres) in ``view``: 3D, or projected
    onto an elevation's plane, farthest first."""
    polygons = list(polygons)
    faces = np.broadcast_to(matplotlib.colors.to_rgba_array(facecolors),
                            (len(polygons), 4))
    edges = faces if isinstance(edgecolors, str) and edgecolors == "face" else edgecolors
    if view not in ELEVATIONS:
        ax.add_collection3d(Poly3DCollection(polygons, facecolors=faces, edgecolors=edges,
                                             linewidths=linewidths))
        return
    h, v, depth, sign = ELEVATIONS[view]
    order = np.argsort([sign * p[:, depth].mean() for p in polygons], kind="stable")
    if not isinstance(edges, str):
        edges = np.broadcast_to(matplotlib.colors.to_rgba_array(edges),
                                (len(polygons), 4))[order]
    ax.add_collection(PolyCollection([polygons[i][:, [h, v]] for i in order],
                                     facecolors=faces[order], edgecolors=edges,
                                     linewidths=linewidths))


def add_line(ax, view, points, **style):
    """A polyline ((m, 3) float, metres) in ``view``."""
    points = np.asarray(points, dtype=float)
    if view not in ELEVATIONS:
        ax.plot(points[:, 0], points[:, 1], points[:, 2], **style)
    else:
        h, v, _, _ = ELEVATIONS[view]
        ax.plot(points[:, h], points[:, v], **style)


def add_points(ax, view, points, **style):
    """Markers at ``points`` ((m, 3) float, metres) in ``view``."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if view not in ELEVATIONS:
        ax.scatter(*points.T, depthshade=False, **style)
    else:
        h, v, _, _ = ELEVATIONS[view]
        ax.scatter(points[:, h], points[:, v], zorder=10, **style)


def draw_outline(ax, view, scene):
    """The web's boundaries (its level table's half widths, both sides) and its base line
    in blue; nothing for a scene without a level table."""
    levels = scene.levels
    if levels is None or scene.dims is None:
        return
    for sign in (-1, 1):
        add_line(ax, view, np.column_stack([levels.x, sign * levels.y, levels.z]),
                 color="b", linewidth=1)
    add_line(ax, view, [[levels.x[0], -levels.y[0], 0.0], [levels.x[0], levels.y[0], 0.0]],
             color="b", linewidth=1)


def interface_polygons(interfaces, index) -> list:
    """The polygons ((m, 3) float, metres) of the interfaces ``index``."""
    return [interfaces.polygon(k) for k in index]
