"""What every figure shares: the block class colours (:data:`masonry.blocks.CLASS_COLOURS`),
the four views and their axes, polygons, lines and markers drawn in any view, titles, and
the files a figure becomes (PNG, SVG, PDF: :class:`Render`).

A view is 3D (``01_angle``, from :data:`ANGLE`) or an elevation (:data:`ELEVATIONS`),
drawn as a 2D projection at equal scale; the drawing helpers take the view's name and
draw in either.
"""

import io
from dataclasses import dataclass

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import PIL.Image
from matplotlib.collections import PolyCollection
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from masonry.blocks import CLASS_COLOURS  # noqa: F401 (the figures' name for it)
from masonry.interfaces import INTERFACE_KINDS
from masonry.plots.colours import WEB_OUTLINE
from masonry.plots.faces import AWAY, facing

# the thesis's four views (section 3.4): a 3D view from an angle (elevation, azimuth in
# degrees) and three elevations, drawn as 2D projections at equal scale (3D axes seen
# end on pile their tick labels up): (horizontal axis, vertical axis, depth axis, +1 when
# a larger depth coordinate is nearer the viewer)
VIEWS = ("01_angle", "02_front", "03_top", "04_side")
ANGLE_VIEW = VIEWS[0]
ANGLE = (25, -50)
ELEVATIONS = {"02_front": (1, 2, 0, 1), "03_top": (0, 1, 2, 1), "04_side": (0, 2, 1, -1)}

NO_FILL = (0.0, 0.0, 0.0, 0.0)
"""Face colour of polygons drawn as outlines only."""

HORIZONTAL_KINDS = (INTERFACE_KINDS.index("horizontal"), INTERFACE_KINDS.index("support"))
"""Interface kinds drawn as bed joints (with the supports); every other kind is a head
joint."""


PAD_INCHES = 0.1
"""White margin around what a figure draws (matplotlib's ``savefig.pad_inches``)."""

LEGEND_GAP_INCHES = 0.05
"""Space between a legend below the axes (:func:`legend_below`) and their labels."""


@dataclass(frozen=True)
class Render:
    """How a figure is saved: the formats of its files (of
    :data:`~masonry.outputs.FIGURE_FORMATS`) and a PNG's dots per inch (None: each
    figure's own)."""

    formats: tuple = ("png",)
    dpi: int | None = None

    @classmethod
    def of(cls, outputs) -> "Render":
        """The render a run's :class:`~masonry.outputs.Outputs` ask for."""
        return cls(tuple(outputs.figure_format), outputs.dpi)


PNG = Render()
"""A PNG at each figure's own resolution."""

VECTOR_STYLE = {"svg.fonttype": "none", "pdf.fonttype": 42, "svg.hashsalt": "masonry"}
"""Vector figures keep their text as text (SVG: ``<text>`` in the reader's font; PDF:
TrueType fonts, embedded), which a paper's editor can search and restyle; the salt makes
the SVG's ids the same from run to run."""

VECTOR_METADATA = {"svg": {"Date": None, "Creator": None},
                   "pdf": {"CreationDate": None, "Creator": None, "Producer": None}}
"""No date or tool version in a vector file: the same figure is the same bytes."""


def figure_files(fig, dpi, render=PNG, close=True) -> dict:
    """``fig`` in each format of ``render``: ``{format: bytes}``, cropped to what it draws
    (with :data:`PAD_INCHES` around it). ``dpi`` is the figure's own PNG resolution,
    ``render.dpi`` replaces it when set; the figure is closed unless ``close`` is False
    (the next figure of the same view draws on it)."""
    dpi = dpi if render.dpi is None else render.dpi
    out = {}
    for fmt in render.formats:
        if fmt == "png":
            out[fmt] = png_bytes(fig, dpi, close=False)
            continue
        buf = io.BytesIO()
        with matplotlib.rc_context(VECTOR_STYLE):
            fig.savefig(buf, format=fmt, dpi=dpi, bbox_inches="tight",
                        pad_inches=PAD_INCHES, metadata=VECTOR_METADATA[fmt])
        out[fmt] = buf.getvalue()
    if close:
        plt.close(fig)
    return out


def as_files(path, figure: dict) -> dict:
    """``{path with each format's suffix: bytes}`` of a figure's :func:`figure_files`;
    ``path`` names the figure by its PNG (``02_front/1_boundaries.png``)."""
    stem = str(path).removesuffix(".png")
    return {f"{stem}.{fmt}": data for fmt, data in figure.items()}


def png_bytes(fig, dpi, close=True) -> bytes:
    """``fig`` as PNG bytes at ``dpi``, cropped to what it draws (with
    :data:`PAD_INCHES` around it); the figure is closed unless ``close`` is False (the
    next figure of the same view draws on it).

    Drawn once and cropped: ``savefig(bbox_inches="tight")`` draws the figure twice
    (once to measure it), which costs a run's figures about a fifth of their time. A
    figure that draws beyond its canvas (a legend below it) is saved that way; one
    whose margin alone would leave the canvas keeps less of it on that side."""
    fig.set_dpi(dpi)
    canvas = fig.canvas
    canvas.draw()
    box = fig.get_tightbbox(canvas.get_renderer())
    width, height = canvas.get_width_height()
    buf = io.BytesIO()
    if (box.extents[:2] < 0).any() or (box.extents[2:] * dpi > (width, height)).any():
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight",
                    pad_inches=PAD_INCHES, pil_kwargs={"compress_level": 1})
    else:
        x0, y0, x1, y1 = np.clip(box.padded(PAD_INCHES).extents * dpi, 0,
                                 (width, height, width, height))
        rows = slice(height - int(np.ceil(y1)), height - int(np.floor(y0)))
        columns = slice(int(np.floor(x0)), int(np.ceil(x1)))
        # opaque: RGB, quickly compressed (a fifth larger than the slowest, half the time)
        image = np.asarray(canvas.buffer_rgba())[rows, columns, :3]
        PIL.Image.fromarray(image).save(buf, format="png", compress_level=1)
    if close:
        plt.close(fig)
    return buf.getvalue()


EDGE_ON = (0.25, 0.1)
"""An elevation is left out when the model's extents in its plane make less than the
first fraction of the largest elevation's area, or its shorter side less than the
second fraction of its longer side: it would show the model edge on (an arch's or a
wall's thickness) or as a sliver. The largest elevation always stays."""


def views_of(bounds, fast=False) -> list:
    """The views that show a model of ``bounds`` ((2, 3) float, metres): the 3D view and
    the elevations that are not edge on (:data:`EDGE_ON`); the 3D view only when
    ``fast``."""
    if fast:
        return [ANGLE_VIEW]
    extent = np.ptp(np.asarray(bounds, dtype=float), axis=0)
    plane = {view: extent[[h, v]] for view, (h, v, _, _) in ELEVATIONS.items()}
    area = {view: float(np.prod(sides)) for view, sides in plane.items()}
    largest = max(area, key=area.get)
    kept = [view for view in ELEVATIONS if view == largest or (
        area[view] >= EDGE_ON[0] * area[largest]
        and plane[view].min() >= EDGE_ON[1] * plane[view].max())]
    return [ANGLE_VIEW, *kept]


def legend_below(fig, ax, handles, ncol=3, fontsize=7):
    """``handles``' legend under the axes and all they draw beyond their box (tick and
    axis labels, measured), centred on the axes: clear of the model and of the labels.
    Call it last but for the title."""
    if not handles:
        return None
    drawn = ax.get_tightbbox(fig.canvas.get_renderer())  # pixels; also places the axes
    box = ax.get_position()
    top = fig.transFigure.inverted().transform((0.0, drawn.y0))[1]
    top -= LEGEND_GAP_INCHES / fig.get_figheight()
    return ax.legend(handles=handles, loc="upper center",
                     bbox_to_anchor=((box.x0 + box.x1) / 2, top),
                     bbox_transform=fig.transFigure, ncol=min(ncol, len(handles)),
                     fontsize=fontsize, frameon=False)


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


def _figure_size_3d(extent) -> tuple:
    """(width, height) inches of a 3D figure whose box has ``extent`` (3,) seen from
    :data:`ANGLE`: about 7 x 7 in area, in the proportions of the box as drawn (a tall
    section in a square figure leaves half of it empty), within 0.6 to 1.6."""
    elevation, azimuth = np.radians(ANGLE)
    right = np.array([-np.sin(azimuth), np.cos(azimuth), 0.0])
    up = np.cross(toward_viewer(ANGLE_VIEW), right)
    corners = np.array(np.meshgrid(*[[0.0, e] for e in extent])).reshape(3, -1).T
    wide, tall = np.ptp(corners @ right), np.ptp(corners @ up)
    ratio = float(np.clip(np.sqrt(tall / wide), np.sqrt(0.6), np.sqrt(1.6)))
    return 7.0 / ratio, 7.0 * ratio


def axes_3d(bounds):
    """3D axes from :data:`ANGLE` on ``bounds`` at equal scale in x, y and z, in a
    figure of the box's proportions."""
    # the box follows the extents (a cube around a flat dome leaves half the figure
    # empty); very thin extents are widened so the box stays readable
    extent = np.maximum(bounds[1] - bounds[0], 0.15 * (bounds[1] - bounds[0]).max())
    fig = plt.figure(figsize=_figure_size_3d(extent))
    ax = fig.add_subplot(projection="3d")
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


def toward_viewer(view) -> np.ndarray:
    """(3,) the unit direction from the model toward ``view``'s camera: an elevation's
    depth axis, the 3D view's from :data:`ANGLE` (its box is at equal scale, so the
    direction in data coordinates is the box's)."""
    if view in ELEVATIONS:
        _, _, depth, sign = ELEVATIONS[view]
        return sign * np.eye(3)[depth]
    elevation, azimuth = np.radians(ANGLE)
    return np.array([np.cos(elevation) * np.cos(azimuth),
                     np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])


def visible_faces(blocks, mask, view, hidden=None) -> np.ndarray:
    """The faces of the blocks of ``mask`` ((B,) bool) that ``view`` can show: not
    ``hidden`` ((F,) bool, :func:`~masonry.plots.faces.hidden_faces`) and turned toward
    its camera (a 3D view's within :data:`~masonry.plots.faces.AWAY`)."""
    keep = np.asarray(mask, bool)[blocks.face_block]
    if hidden is not None:
        keep &= ~hidden
    keep &= facing(blocks.face_normal, toward_viewer(view),
                   1e-9 if view in ELEVATIONS else AWAY)
    return np.flatnonzero(keep)


def add_polygons(ax, view, polygons, facecolors, edgecolors="face", linewidths=0.3):
    """Draw ``polygons`` ((n, m, 3) float, metres, :func:`~masonry.plots.faces.padded`)
    in ``view``: one 3D collection, or projected onto an elevation's plane, farthest
    first, as one 2D collection (:class:`Projected`). Returns the collection."""
    polygons = np.asarray(polygons, dtype=float).reshape(-1, *np.shape(polygons)[-2:])
    faces = np.broadcast_to(matplotlib.colors.to_rgba_array(facecolors),
                            (len(polygons), 4))
    edges = faces if isinstance(edgecolors, str) and edgecolors == "face" else edgecolors
    if view not in ELEVATIONS:
        collection = Poly3DCollection(polygons, facecolors=faces, edgecolors=edges,
                                      linewidths=linewidths)
        ax.add_collection3d(collection, autolim=False)
    else:
        collection = Projected(view, polygons, faces, edges, linewidths)
        ax.add_collection(collection, autolim=False)
    # the views' limits are set from the model's bounds, and the polygons lie inside
    # the axes, which the figure's tight bounding box holds anyway: measuring thousands
    # of paths for either is wasted
    collection.set_in_layout(False)
    return collection


class Projected(PolyCollection):
    """Polygons projected onto an elevation's plane, drawn farthest first: polygon ``k``
    of the collection is polygon ``order[k]`` of those given."""

    def __init__(self, view, polygons, faces, edges, linewidths):
        h, v, depth, sign = ELEVATIONS[view]
        self.order = np.argsort(sign * polygons[:, :, depth].mean(axis=1), kind="stable")
        if not isinstance(edges, str):
            edges = np.broadcast_to(matplotlib.colors.to_rgba_array(edges),
                                    (len(polygons), 4))[self.order]
        super().__init__(polygons[self.order][:, :, [h, v]], facecolors=faces[self.order],
                         edgecolors=edges, linewidths=linewidths)


def recolour(collection, facecolors):
    """New face colours ((n, 4) RGBA, or one colour) for the polygons of
    :func:`add_polygons`' ``collection``, in the order they were given; edges in the face
    colour."""
    faces = np.broadcast_to(matplotlib.colors.to_rgba_array(facecolors),
                            (len(collection.get_paths()), 4))
    if isinstance(collection, Projected):
        faces = faces[collection.order]
    collection.set_facecolor(faces)
    collection.set_edgecolor(faces)


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
    dashed (:data:`~masonry.plots.colours.WEB_OUTLINE`); nothing for a scene without a
    level table, nor for a whole dome (one web's outline would mark one web of many)."""
    levels = scene.levels
    if levels is None or scene.dims is None or not scene.symmetry.unit:
        return
    for sign in (-1, 1):
        add_line(ax, view, np.column_stack([levels.x, sign * levels.y, levels.z]),
                 color=WEB_OUTLINE, linestyle="--", linewidth=1)
    add_line(ax, view, [[levels.x[0], -levels.y[0], 0.0], [levels.x[0], levels.y[0], 0.0]],
             color=WEB_OUTLINE, linestyle="--", linewidth=1)
