"""Plots as PNG bytes (matplotlib, Agg): the flattened pattern and the structure views.

Every function returns ``{relative path: png bytes}`` so the run folder writer is the one
place that touches the disk.
"""

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from masonry.blocks import BLOCK_CLASSES  # noqa: E402

CLASS_COLOURS = {
    "ground": "#9e9e9e",
    "regular": "#e8d5b0",
    "pattern": "#d62728",
    "fill_in": "#f2a541",
    "block": "#c9b79c",
}

# (folder, elevation, azimuth): the thesis's four views (section 3.4)
VIEWS = {
    "01_angle": (25, -50),
    "02_front": (0, 0),
    "03_top": (90, -90),
    "04_side": (0, -90),
}


def _png(fig, dpi) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def pattern_png(scene, fast=False) -> bytes:
    """The flattened section (thesis figures 3.8-3.9): position along the wall (units)
    against course, pattern, regular and fill-in bricks in distinct colours, the web's
    half width at every course in blue."""
    layout, levels, unit = scene.layout, scene.levels, scene.params.unit
    height = np.where(layout.klass == BLOCK_CLASSES.index("pattern"), 2, 1)
    # mitered ends reach the web's boundary (at the course's lower, wider edge)
    w_low = levels.y[layout.course - 1] / unit
    s0 = np.where(layout.miter_left, -w_low, layout.s0)
    s1 = np.where(layout.miter_right, w_low, layout.s1)
    fig, ax = plt.subplots(figsize=(6, 7.5))
    for k, s0, s1, klass, h in zip(layout.course, s0, s1, layout.klass, height):
        name = BLOCK_CLASSES[klass]
        ax.add_patch(Rectangle((s0, k - 1), s1 - s0, h, facecolor=CLASS_COLOURS[name],
                               edgecolor="k", linewidth=0.3, zorder=3 if h == 2 else 2))
    w = levels.y / unit
    z = np.arange(len(w))
    ax.plot(w, z, "b-", -w, z, "b-", linewidth=1.2)
    for name in ("pattern", "regular", "fill_in"):
        ax.add_patch(Rectangle((0, 0), 0, 0, facecolor=CLASS_COLOURS[name], label=name))
    ax.legend(loc="upper right", fontsize=7)
    ax.set_xlabel("position along the wall s [units]")
    ax.set_ylabel("course")
    ax.set_xlim(-w.max() - 1, w.max() + 1)
    ax.set_ylim(-0.5, len(w) + 0.5)
    ax.set_title(f"{scene.params.scene}: {len(layout)} bricks, "
                 f"{int((layout.klass == BLOCK_CLASSES.index('pattern')).sum())} pattern")
    return _png(fig, 80 if fast else 130)


def _faces_3d(blocks, mask):
    faces = np.flatnonzero(mask[blocks.face_block])
    polys = [blocks.face_polygon(f) for f in faces]
    colours = [CLASS_COLOURS[BLOCK_CLASSES[blocks.block_class[blocks.face_block[f]]]]
               for f in faces]
    return polys, colours


def _axes3d(bounds, view):
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    centre = bounds.mean(axis=0)
    half = (bounds[1] - bounds[0]).max() / 2
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(*VIEWS[view])
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    return fig, ax


def _outline(ax, scene):
    levels = scene.levels
    if levels is None or scene.dims is None:
        return
    for sign in (-1, 1):
        ax.plot(levels.x, sign * levels.y, levels.z, color="b", linewidth=1)
    ax.plot(levels.x[[0, 0]], levels.y[[0, 0]] * [-1, 1], [0, 0], color="b", linewidth=1)


def structure_pngs(scene, fast=False) -> dict:
    """Structure plots in the thesis's stages (figures 3.7, 3.10, 3.11): the web's
    boundaries, the pattern bricks, the complete structure; in the four views, or one
    view at lower resolution when ``fast``."""
    blocks = scene.blocks
    bounds = blocks.bounds
    pattern = blocks.block_class == BLOCK_CLASSES.index("pattern")
    stages = {"3_structure": np.ones(blocks.n_blocks, bool)}
    if pattern.any():
        stages = {"1_boundaries": np.zeros(blocks.n_blocks, bool),
                  "2_pattern": pattern, **stages}
    views = ["01_angle"] if fast else list(VIEWS)
    out = {}
    for view in views:
        for stage, mask in stages.items():
            fig, ax = _axes3d(bounds, view)
            _outline(ax, scene)
            if mask.any():
                polys, colours = _faces_3d(blocks, mask)
                ax.add_collection3d(Poly3DCollection(polys, facecolors=colours,
                                                     edgecolors="k", linewidths=0.1))
            ax.set_title(f"{stage[2:]}: {int(mask.sum())} bricks")
            out[f"{view}/{stage}.png"] = _png(fig, 60 if fast else 110)
    return out


OUTLINE_COLOUR = "#ff00ff"
"""Edge colour of the outlined blocks of :func:`marked_structure_pngs`."""

MARK_DECADES = 2
"""Decades of the colour scale of :func:`marked_structure_pngs`: blocks whose value is
below ``10**-MARK_DECADES`` of the largest keep their class colour."""


def marked_structure_pngs(scene, is_present, value, title, value_label="value",
                          is_outlined=None, outline_label="outlined", fast=False) -> dict:
    """The structure views of a part of ``scene`` (e.g. a construction stage): the blocks
    of ``is_present`` ((B,) bool), coloured by ``value`` ((B,) float >= 0, e.g. the
    tension a brick carries, newtons) on a logarithmic scale over
    :data:`MARK_DECADES` decades, in their class colours below it; the blocks of
    ``is_outlined`` ((B,) bool, e.g. the ones just laid) with thick red edges (legend
    ``outline_label``); the rest of the scene's blocks as faint outlines. ``{view}.png``
    per view, one view at lower resolution when ``fast``."""
    from matplotlib.colors import LogNorm, to_rgba

    blocks = scene.blocks
    owner = blocks.face_block
    shown = np.flatnonzero(is_present[owner])
    ghost = np.flatnonzero(~is_present[owner] & ~blocks.block_is_support[owner])
    top = max(float(np.max(value[is_present], initial=0.0)), 1e-300)
    norm = LogNorm(top * 10.0**-MARK_DECADES, top)
    cmap = plt.get_cmap("viridis_r")
    face_value = value[owner[shown]]
    is_marked = face_value >= norm.vmin
    face_colours = np.array([to_rgba(CLASS_COLOURS[BLOCK_CLASSES[k]])
                             for k in blocks.block_class[owner[shown]]])
    face_colours[is_marked] = cmap(norm(face_value[is_marked]))
    out = {}
    for view in ["01_angle"] if fast else list(VIEWS):
        fig, ax = _axes3d(blocks.bounds, view)
        ax.computed_zorder = False  # draw in the order below: the rings on top
        _outline(ax, scene)
        if len(ghost):
            ax.add_collection3d(Poly3DCollection(
                [blocks.face_polygon(f) for f in ghost], facecolors="none",
                edgecolors="0.87", linewidths=0.1))
        ax.add_collection3d(Poly3DCollection([blocks.face_polygon(f) for f in shown],
                                             facecolors=face_colours,
                                             edgecolors="k", linewidths=0.1, zorder=3))
        handles = [Patch(facecolor="none", edgecolor="0.7", label="not yet laid")]
        if is_outlined is not None and is_outlined.any():
            edged = np.flatnonzero(is_outlined[owner] & is_present[owner])
            ax.add_collection3d(Poly3DCollection(
                [blocks.face_polygon(f) for f in edged], facecolors="none",
                edgecolors=OUTLINE_COLOUR, linewidths=2.0, zorder=4))
            # a ring around each, so that a single brick shows at any scale
            centre = blocks.block_centroid[is_outlined & is_present]
            ax.scatter(*centre.T, s=160, facecolors="none", edgecolors=OUTLINE_COLOUR,
                       linewidths=1.5, depthshade=False, zorder=10)
            handles.append(Patch(facecolor="none", edgecolor=OUTLINE_COLOUR,
                                 label=outline_label))
        if is_marked.any():
            bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                               shrink=0.6, pad=0.1)
            bar.set_label(value_label)
        ax.legend(handles=handles, loc="upper left", fontsize=8)
        ax.set_title(title)
        out[f"{view}.png"] = _png(fig, 60 if fast else 110)
    return out


def stage_chart_png(stage, moi_factor, feasible, load_factor=None, title="",
                    xlabel="stage") -> bytes:
    """MoI factor (and the collapse load factor, where given) against the construction
    stage: stages that stand in green, those that need support in red, the first of
    them marked by a dashed line.

    Parameters
    ----------
    stage : (N,) int
    moi_factor : (N,) float (NaN: not solved)
    feasible : (N,) bool
    load_factor : (N,) float or None (NaN: not computed)
    """
    stage = np.asarray(stage)
    moi = np.asarray(moi_factor, dtype=float)
    feasible = np.asarray(feasible, dtype=bool)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(stage, moi, color="0.6", linewidth=0.8, zorder=1)
    ax.scatter(stage[feasible], moi[feasible], s=14, color="#2ca02c",
               label=f"stands ({int(feasible.sum())})", zorder=2)
    ax.scatter(stage[~feasible], moi[~feasible], s=14, color="#d62728",
               label=f"needs support ({int((~feasible).sum())})", zorder=2)
    if not feasible.all():
        first = stage[np.argmin(feasible)]
        ax.axvline(first, color="#d62728", linestyle="--", linewidth=0.8,
                   label=f"first needs support: {first}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("MoI factor (tension / weight)")
    ax.set_ylim(bottom=min(-0.02 * max(np.nanmax(moi, initial=0), 0.05), 0))
    handles, labels = ax.get_legend_handles_labels()
    if load_factor is not None and np.isfinite(np.asarray(load_factor, float)).any():
        right = ax.twinx()
        right.plot(stage, np.asarray(load_factor, float), color="#1f77b4", marker=".",
                   label="load factor")
        right.set_ylabel("collapse load factor")
        extra = right.get_legend_handles_labels()
        handles, labels = handles + extra[0], labels + extra[1]
    ax.legend(handles, labels, loc="best", fontsize=8)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    return _png(fig, 110)


def _polygons(interfaces, index):
    return [interfaces.polygon(k) for k in index]


def _colour_plot(blocks, interfaces, index, values, title, view, fast, label="N"):
    fig, ax = _axes3d(blocks.bounds, view)
    if len(index):
        values = np.asarray(values, dtype=float)
        norm = matplotlib.colors.Normalize(vmin=values.min(), vmax=max(values.max(),
                                                                        values.min() + 1e-12))
        cmap = matplotlib.colormaps["viridis"]
        ax.add_collection3d(Poly3DCollection(_polygons(interfaces, index),
                                             facecolors=cmap(norm(values)),
                                             edgecolors="k", linewidths=0.05))
        bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                           shrink=0.6, pad=0.1)
        bar.set_label(label)
    ax.set_title(f"{title} ({len(index)} interfaces)")
    return _png(fig, 60 if fast else 110)


def interface_pngs(blocks, interfaces, fast=False) -> dict:
    """Horizontal and vertical interfaces drawn as polygons (thesis figures 3.12-3.13),
    coloured by area."""
    from masonry.interfaces import INTERFACE_KINDS

    out = {}
    views = ["01_angle"] if fast else list(VIEWS)
    horizontal = np.isin(interfaces.kind, [INTERFACE_KINDS.index("horizontal"),
                                           INTERFACE_KINDS.index("support")])
    groups = {"interfaces_horizontal": np.flatnonzero(horizontal),
              "interfaces_vertical": np.flatnonzero(~horizontal)}
    for view in views:
        for name, index in groups.items():
            out[f"{view}/{name}.png"] = _colour_plot(
                blocks, interfaces, index, interfaces.area[index] * 1e4,
                name.replace("_", " "), view, fast, label="area [cm^2]")
    return out


FORCE_PLOTS = (
    # (file, result key, interface selection, title): thesis figures 4.1-4.8
    ("compression_horizontal", "compression", "horizontal", "horizontal interfaces - compression"),
    ("compression_vertical", "compression", "vertical", "vertical interfaces - compression"),
    ("tension", "tension", "all", "all interfaces - tension"),
    ("normal", "normal", "all", "all interfaces - normal force (tension - compression)"),
    ("t1", "t1", "all", "all interfaces - t1"),
    ("t2", "t2", "all", "all interfaces - t2"),
    ("friction", "friction", "all", "all interfaces - friction"),
)


def force_pngs(blocks, interfaces, forces: dict, fast=False) -> dict:
    """Force plots with colour bars in newtons, per view (``RBE/<view>/<name>.png``)."""
    from masonry.interfaces import INTERFACE_KINDS

    horizontal = np.isin(interfaces.kind, [INTERFACE_KINDS.index("horizontal"),
                                           INTERFACE_KINDS.index("support")])
    select = {"horizontal": np.flatnonzero(horizontal),
              "vertical": np.flatnonzero(~horizontal),
              "all": np.arange(len(interfaces))}
    out = {}
    views = ["01_angle"] if fast else list(VIEWS)
    for view in views:
        for name, key, group, title in FORCE_PLOTS:
            index = select[group]
            out[f"{view}/{name}.png"] = _colour_plot(
                blocks, interfaces, index, np.asarray(forces[key])[index], title, view, fast)
    return out
