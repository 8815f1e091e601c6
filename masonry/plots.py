"""Plots as PNG bytes (matplotlib, Agg): the flattened pattern, the structure views, the
interfaces coloured by their forces, the thrust line and where the structure fails.

Every function returns PNG bytes or ``{relative path: png bytes}`` so the run folder
writer is the one place that touches the disk.

Colour scales: forces in N, kN or MN by their magnitude, a perceptually uniform
sequential map (viridis) for magnitudes and a diverging one (RdBu_r, 0 white, tension
red) for signed quantities. A scale ends at the :data:`COLOUR_PERCENTILE` th percentile
of the plotted magnitudes; values beyond are drawn in the end colour, the colour bar's
arrow and its label say so.
"""

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
from matplotlib.transforms import ScaledTranslation  # noqa: E402
from mpl_toolkits.axes_grid1 import make_axes_locatable  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from masonry.blocks import BLOCK_CLASSES, PATTERN, concatenate, rotated_web, rotation_z  # noqa: E402
from masonry.interfaces import INTERFACE_KINDS  # noqa: E402
from masonry.params import structure_id  # noqa: E402
from masonry.tolerances import MECHANISM_MAIN  # noqa: E402

CLASS_COLOURS = {
    "ground": "#9e9e9e",
    "regular": "#e8d5b0",
    "pattern": "#d62728",
    "fill_in": "#f2a541",
    "block": "#c9b79c",
}

# the thesis's four views (section 3.4): a 3D view from an angle (elevation, azimuth in
# degrees) and three elevations, drawn as 2D projections at equal scale (3D axes seen
# end on pile their tick labels up): (horizontal axis, vertical axis, depth axis, +1 when
# a larger depth coordinate is nearer the viewer)
VIEWS = ("01_angle", "02_front", "03_top", "04_side")
ANGLE = (25, -50)
ELEVATIONS = {"02_front": (1, 2, 0, 1), "03_top": (0, 1, 2, 1), "04_side": (0, 2, 1, -1)}

BAR_3D = dict(shrink=0.6, pad=0.16)
"""A colour bar beside a 3D box (which sits inside its axes): shorter, and far enough
out to clear the z axis's label."""

COLOUR_PERCENTILE = 99.0
"""Colour scales end at this percentile of the plotted magnitudes: a few support values
would otherwise set the scale and leave every other interface in one colour."""

SEQUENTIAL, DIVERGING = "viridis", "RdBu_r"
ONE_SIDED = 1e-6
"""A signed quantity whose values of one sign all stay within this fraction of the colour
range (solver rounding) is drawn on the other sign's half of the diverging map."""

HORIZONTAL_KINDS = (INTERFACE_KINDS.index("horizontal"), INTERFACE_KINDS.index("support"))


def scene_title(scene) -> str:
    """One line naming the structure and scene of a run, for figure titles."""
    params = scene.params
    what = params.scene
    if params.scene == "section":
        what += f", boundary {params.boundary}"
    return f"{what} | {structure_id(params)}"


def force_unit(magnitude: float) -> tuple:
    """``(factor, unit)`` that prints forces of ``magnitude`` newtons with at most three
    digits before the point: N, kN or MN."""
    for factor, unit in ((1e-6, "MN"), (1e-3, "kN")):
        if magnitude >= 1 / factor:
            return factor, unit
    return 1.0, "N"


def _png(fig, dpi) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _count(n, noun) -> str:
    """``'1 hinge'``, ``'3 hinges'``."""
    return f"{int(n)} {noun}{'' if n == 1 else 's'}"


def pattern_png(scene, fast=False) -> bytes:
    """The flattened section (thesis figures 3.8-3.9): position along the wall (units)
    against course, pattern, regular and fill-in bricks in distinct colours, the web's
    half width at every course in blue."""
    layout, levels, unit = scene.layout, scene.levels, scene.params.unit
    height = np.where(layout.klass == PATTERN, 2, 1)
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
        ax.add_patch(Rectangle((0, 0), 0, 0, facecolor=CLASS_COLOURS[name],
                               label=name.replace("_", "-")))
    ax.legend(loc="upper right", fontsize=7)
    ax.set_xlabel("position along the wall s [units]")
    ax.set_ylabel("course")
    ax.set_xlim(-w.max() - 1, w.max() + 1)
    ax.set_ylim(-0.5, len(w) + 0.5)
    pattern = int((layout.klass == PATTERN).sum())
    what = {"section": f"one web of {scene.params.n}, flattened",
            "dome": f"web 0 of {scene.params.n}, flattened"}.get(scene.params.scene,
                                                               scene.params.scene)
    ax.set_title(f"{what}: {len(layout)} bricks "
                 f"({pattern} pattern)\n{scene_title(scene)}", fontsize=9)
    return _png(fig, 80 if fast else 130)


def _faces_3d(blocks, mask):
    faces = np.flatnonzero(mask[blocks.face_block])
    polys = [blocks.face_polygon(f) for f in faces]
    colours = [CLASS_COLOURS[BLOCK_CLASSES[blocks.block_class[blocks.face_block[f]]]]
               for f in faces]
    return polys, colours


def _axes(bounds, view):
    """Axes for ``view`` on ``bounds`` ((2, 3) float, metres), equal scale."""
    if view not in ELEVATIONS:
        return _axes3d(bounds)
    h, v, _, _ = ELEVATIONS[view]
    fig, ax = plt.subplots(figsize=(7, 6))
    margin = 0.03 * float(np.ptp(bounds, axis=0).max())
    ax.set_xlim(bounds[0, h] - margin, bounds[1, h] + margin)
    ax.set_ylim(bounds[0, v] - margin, bounds[1, v] + margin)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[h]} [m]")
    ax.set_ylabel(f"{'xyz'[v]} [m]")
    return fig, ax


def _axes3d(bounds):
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


def _add_polygons(ax, view, polygons, facecolors, edgecolors="face", linewidths=0.3):
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


def _line(ax, view, points, **style):
    """A polyline ((m, 3) float, metres) in ``view``."""
    points = np.asarray(points, dtype=float)
    if view not in ELEVATIONS:
        ax.plot(points[:, 0], points[:, 1], points[:, 2], **style)
    else:
        h, v, _, _ = ELEVATIONS[view]
        ax.plot(points[:, h], points[:, v], **style)


def _interface_linewidth(count: int) -> float:
    """Edge width of interface polygons: wide for a few (seen edge on they are lines),
    thin for thousands (wide edges would cover their faces)."""
    return float(np.clip(12.0 / np.sqrt(max(count, 1)), 0.3, 3.0))


def _class_legend(ax, codes):
    handles = [Patch(facecolor=CLASS_COLOURS[BLOCK_CLASSES[c]], edgecolor="k",
                     label=BLOCK_CLASSES[c].replace("_", "-")) for c in np.unique(codes)]
    ax.legend(handles=handles, loc="upper left", fontsize=8, frameon=False)


def _outline(ax, view, scene):
    levels = scene.levels
    if levels is None or scene.dims is None:
        return
    for sign in (-1, 1):
        _line(ax, view, np.column_stack([levels.x, sign * levels.y, levels.z]), color="b",
              linewidth=1)
    _line(ax, view, [[levels.x[0], -levels.y[0], 0.0], [levels.x[0], levels.y[0], 0.0]],
          color="b", linewidth=1)


def _draw_blocks(ax, view, blocks, mask, linewidth=0.1):
    if mask.any():
        polys, colours = _faces_3d(blocks, mask)
        _add_polygons(ax, view, polys, colours, edgecolors="k", linewidths=linewidth)
        _class_legend(ax, blocks.block_class[mask])


def structure_pngs(scene, fast=False) -> dict:
    """Structure plots in the thesis's stages (figures 3.7, 3.10, 3.11): the web's
    boundaries, the pattern bricks, the complete structure; in the four views, or one
    view at lower resolution when ``fast``; a cyclic section also as the whole dome
    (``05_dome/3_structure.png``, the section rotated ``n`` times)."""
    blocks = scene.blocks
    bounds = blocks.bounds
    pattern = blocks.block_class == PATTERN
    stages = {"3_structure": np.ones(blocks.n_blocks, bool)}
    if pattern.any():
        stages = {"1_boundaries": np.zeros(blocks.n_blocks, bool),
                  "2_pattern": pattern, **stages}
    views = ["01_angle"] if fast else VIEWS
    out = {}
    for view in views:
        for stage, mask in stages.items():
            fig, ax = _axes(bounds, view)
            _outline(ax, view, scene)
            _draw_blocks(ax, view, blocks, mask)
            count = int((mask & ~blocks.block_is_support).sum())
            what = "blocks" if scene.params.scene in ("arch", "assembly") else "bricks"
            shown = (f"{count} {what}" if mask.any()
                     else "the web's outline (blue), before any brick is laid")
            ax.set_title(f"{stage[2:]}: {shown}\n{scene_title(scene)}", fontsize=9)
            out[f"{view}/{stage}.png"] = _png(fig, 60 if fast else 110)
    if is_cyclic(scene):
        n = scene.params.n
        whole = concatenate([rotated_web(blocks, k, n, ~blocks.block_is_support)
                             for k in range(n)])
        fig, ax = _axes3d(whole.bounds)
        _draw_blocks(ax, "01_angle", whole, np.ones(whole.n_blocks, bool), linewidth=0.05)
        ax.set_title(f"the whole dome: the section rotated {n} times, {whole.n_blocks} "
                     f"bricks\n{scene_title(scene)}", fontsize=9)
        out["05_dome/3_structure.png"] = _png(fig, 70 if fast else 130)
    return out


def _points(ax, view, points, **style):
    """Markers at ``points`` ((m, 3) float, metres) in ``view``."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if view not in ELEVATIONS:
        ax.scatter(*points.T, depthshade=False, **style)
    else:
        h, v, _, _ = ELEVATIONS[view]
        ax.scatter(points[:, h], points[:, v], zorder=10, **style)


NO_FILL = (0.0, 0.0, 0.0, 0.0)
"""Face colour of polygons drawn as outlines only."""

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
        fig, ax = _axes(blocks.bounds, view)
        if view not in ELEVATIONS:
            ax.computed_zorder = False  # draw in the order below: the rings on top
        _outline(ax, view, scene)
        if len(ghost):
            _add_polygons(ax, view, [blocks.face_polygon(f) for f in ghost], NO_FILL,
                          edgecolors="0.87", linewidths=0.1)
        _add_polygons(ax, view, [blocks.face_polygon(f) for f in shown], face_colours,
                      edgecolors="k", linewidths=0.1)
        handles = [Patch(facecolor="none", edgecolor="0.7", label="not yet laid")]
        if is_outlined is not None and is_outlined.any():
            edged = np.flatnonzero(is_outlined[owner] & is_present[owner])
            _add_polygons(ax, view, [blocks.face_polygon(f) for f in edged], NO_FILL,
                          edgecolors=OUTLINE_COLOUR, linewidths=2.0)
            # a ring around each, so that a single brick shows at any scale
            centre = blocks.block_centroid[is_outlined & is_present]
            _points(ax, view, centre, s=160, facecolors="none", edgecolors=OUTLINE_COLOUR,
                    linewidths=1.5)
            handles.append(Line2D([], [], color=OUTLINE_COLOUR, marker="o", markersize=9,
                                  fillstyle="none", linewidth=2, label=outline_label))
        if is_marked.any():
            below = bool(((face_value > 0) & ~is_marked).any())
            bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                               extend="min" if below else "neither",
                               **(BAR_3D if view not in ELEVATIONS else dict(pad=0.05)))
            bar.set_label(value_label)
            handles.append(Patch(facecolor=CLASS_COLOURS["regular"], edgecolor="k",
                                 label="laid, below the scale (class colours)"))
        ax.legend(handles=handles, loc="upper left", fontsize=8)
        ax.set_title(f"{title}\n{scene_title(scene)}", fontsize=9)
        out[f"{view}.png"] = _png(fig, 60 if fast else 110)
    return out


def stage_chart_png(stage, moi_factor, feasible, load_factor=None, title="",
                    xlabel="stage", loose=None) -> bytes:
    """MoI factor (and the collapse load factor, where given) against the construction
    stage: stages that stand in green, those that need support in red, the first of
    them marked by a dashed line; stages with loose blocks (no MoI) as red crosses at 0.

    Parameters
    ----------
    stage : (N,) int
    moi_factor : (N,) float (NaN: not solved)
    feasible : (N,) bool
    load_factor : (N,) float or None (NaN: not computed)
    loose : (N,) int or None
        Blocks per stage that touch nothing joining them to a support.
    """
    stage = np.asarray(stage)
    moi = np.asarray(moi_factor, dtype=float)
    feasible = np.asarray(feasible, dtype=bool)
    loose = np.zeros(len(stage), int) if loose is None else np.asarray(loose)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(stage, moi, color="0.6", linewidth=0.8, zorder=1)
    ax.scatter(stage[feasible], moi[feasible], s=14, color="#2ca02c",
               label=f"stands ({int(feasible.sum())})", zorder=2)
    ax.scatter(stage[~feasible], moi[~feasible], s=14, color="#d62728",
               label=f"needs support ({int((~feasible).sum())})", zorder=2)
    if loose.any():
        ax.scatter(stage[loose > 0], np.zeros(int((loose > 0).sum())), marker="x", s=24,
                   color="#d62728", zorder=2, label=f"a block touches nothing that holds "
                   f"it, no MoI ({int((loose > 0).sum())})")
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
        right.set_ylim(0, 1.1 * np.nanmax(np.asarray(load_factor, float)))
        extra = right.get_legend_handles_labels()
        handles, labels = handles + extra[0], labels + extra[1]
        # below the plot: two axes' curves leave no free corner
        ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=4,
                  fontsize=8, frameon=False)
    else:
        ax.legend(handles, labels, loc="best", fontsize=8)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    return _png(fig, 110)


def is_cyclic(scene) -> bool:
    """Whether a run's section stands for the whole dome by rotation (SPEC 6.4)."""
    return scene.params.scene == "section" and scene.params.boundary == "cyclic"


def _polygons(interfaces, index):
    return [interfaces.polygon(k) for k in index]


def colour_scale(values, signed: bool, is_force: bool = True, unit: str = "") -> dict:
    """How to colour ``values``: a robust range (:data:`COLOUR_PERCENTILE`), the unit and
    the map.

    Parameters
    ----------
    values : (n,) float
        In newtons when ``is_force``.
    signed : bool
        A diverging map symmetric about 0 (the half of one sign when every value has it,
        within :data:`ONE_SIDED` of the range); else sequential from 0 (or the minimum).
    unit : str
        Of values that are not forces (``is_force`` False).

    Returns
    -------
    dict
        ``factor`` (multiply values for the display unit), ``unit``, ``norm``, ``cmap``,
        ``extend`` (the colour bar's arrows where values are clipped), ``above`` and
        ``below`` (how many values lie beyond the range's ends), ``largest`` (the largest
        magnitude, display unit).
    """
    values = np.asarray(values, dtype=float)
    magnitude = np.abs(values)
    largest = float(magnitude.max()) if len(values) else 0.0
    top = float(np.percentile(magnitude, COLOUR_PERCENTILE)) if len(values) else 0.0
    top = top if top > 0 else (largest if largest > 0 else 1.0)
    # the unit of the bar's range, not of a few clipped supports
    factor, unit = force_unit(top) if is_force else (1.0, unit)
    if signed:
        # one sign only (no tension anywhere): the bar keeps the map's half of that sign,
        # zero still white at its end
        low = -top if (values < -ONE_SIDED * top).any() else 0.0
        high = top if (values > ONE_SIDED * top).any() or low == 0 else 0.0
        norm = matplotlib.colors.Normalize(low * factor, high * factor)
        part = (0.5 + 0.5 * low / top, 0.5 + 0.5 * high / top)
        cmap = matplotlib.colormaps[DIVERGING]
        if part != (0.0, 1.0):
            cmap = matplotlib.colors.ListedColormap(cmap(np.linspace(*part, 128)),
                                                    name=f"{DIVERGING}_part")
        below = int((values < -top).sum())
        extend = "both" if below and (values > top).any() else (
            "min" if below else "max" if (values > top).any() else "neither")
    else:
        low = min(float(values.min()), 0.0) if len(values) else 0.0
        norm = matplotlib.colors.Normalize(low * factor, top * factor)
        below = 0
        extend = "max" if (values > top).any() else "neither"
        cmap = matplotlib.colormaps[SEQUENTIAL]
    return {"factor": factor, "unit": unit, "norm": norm, "cmap": cmap, "extend": extend,
            "above": int((values > top).sum()), "below": below, "largest": largest * factor}


def _colour_bar(fig, ax, scale, quantity):
    """A colour bar labelled ``quantity [unit]``, saying where the scale is clipped."""
    mappable = matplotlib.cm.ScalarMappable(norm=scale["norm"], cmap=scale["cmap"])
    if hasattr(ax, "get_zlim"):  # a 3D box sits inside its axes: a shorter bar
        bar = fig.colorbar(mappable, ax=ax, extend=scale["extend"], **BAR_3D)
    else:  # as tall as the equal-scale plot
        cax = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.12)
        bar = fig.colorbar(mappable, cax=cax, extend=scale["extend"])
    label = f"{quantity} [{scale['unit']}]" if scale["unit"] else quantity
    if scale["largest"] == 0:
        label += "\nall zero"
    beyond = [f"{scale[end]} {end}" for end in ("above", "below") if scale[end]]
    if beyond:
        label += (f"\nscale ends at the {COLOUR_PERCENTILE:g}th percentile; "
                  f"{', '.join(beyond)}, up to {scale['largest']:.3g} {scale['unit']}"
                  + (" in size" if scale["below"] else "")).rstrip()
    bar.set_label(label, fontsize=8)


def _colour_plot(blocks, interfaces, index, values, title, view, fast, quantity,
                 signed=False, is_force=True, subtitle="", unit=""):
    """One view of the interfaces ``index`` coloured by ``values`` (SI units, or ``unit``
    for values that are not forces)."""
    fig, ax = _axes(blocks.bounds, view)
    scale = colour_scale(values, signed, is_force, unit)
    shown = np.asarray(values, dtype=float) * scale["factor"]
    colours = scale["cmap"](scale["norm"](shown))
    # edges in the face colour: interfaces seen edge on stay visible as coloured lines
    _add_polygons(ax, view, _polygons(interfaces, index), colours,
                  linewidths=_interface_linewidth(len(index)))
    _colour_bar(fig, ax, scale, quantity)
    ax.set_title(f"{title} ({len(index)} interfaces)\n{subtitle}", fontsize=9)
    return _png(fig, 60 if fast else 110)


def interface_pngs(scene, blocks, interfaces, fast=False) -> dict:
    """Horizontal and vertical interfaces drawn as polygons (thesis figures 3.12-3.13),
    coloured by area; a group without interfaces has no plot."""
    out = {}
    views = ["01_angle"] if fast else VIEWS
    horizontal = np.isin(interfaces.kind, HORIZONTAL_KINDS)
    groups = {"interfaces_horizontal": np.flatnonzero(horizontal),
              "interfaces_vertical": np.flatnonzero(~horizontal)}
    for view in views:
        for name, index in groups.items():
            if len(index):
                out[f"{view}/{name}.png"] = _colour_plot(
                    blocks, interfaces, index, interfaces.area[index] * 1e4,
                    name.replace("_", " "), view, fast, "area", is_force=False,
                    subtitle=scene_title(scene), unit="cm^2")
    return out


FORCE_PLOTS = (
    # (file, result key, interface selection, title, signed): thesis figures 4.1-4.8; the
    # friction components t1, t2 are in forces.csv, not drawn: a bed joint's in-plane
    # axes follow its longest edge, so their signs have no common meaning across joints
    ("compression_horizontal", "compression", "horizontal",
     "bed joints and supports: compression", False),
    ("compression_vertical", "compression", "vertical", "head joints: compression", False),
    ("tension", "tension", "all", "all interfaces: tension", False),
    ("normal", "normal", "all", "all interfaces: normal force (tension +)", True),
    ("friction", "friction", "all", "all interfaces: friction", False),
)
FORCE_LABELS = {"compression": "compression", "tension": "tension",
                "normal": "normal force", "t1": "friction along t1",
                "t2": "friction along t2", "friction": "friction"}
"""Colour bar labels of the force sums (each interface's sum over its vertices)."""


def force_pngs(scene, blocks, interfaces, forces: dict, fast=False) -> dict:
    """Force plots (sums over each interface's vertices), per view
    (``<view>/<name>.png``); for a cyclic section also the whole dome
    (``05_dome/<name>.png``). A selection without interfaces has no plot."""
    horizontal = np.isin(interfaces.kind, HORIZONTAL_KINDS)
    select = {"horizontal": np.flatnonzero(horizontal),
              "vertical": np.flatnonzero(~horizontal),
              "all": np.arange(len(interfaces))}
    out = {}
    views = ["01_angle"] if fast else VIEWS
    for view in views:
        for name, key, group, title, signed in FORCE_PLOTS:
            index = select[group]
            if len(index):
                out[f"{view}/{name}.png"] = _colour_plot(
                    blocks, interfaces, index, np.asarray(forces[key])[index], title, view,
                    fast, FORCE_LABELS[key], signed, subtitle=scene_title(scene))
    if is_cyclic(scene):
        out.update(_whole_dome_pngs(scene, interfaces, forces, fast))
    return out


def _whole_dome_pngs(scene, interfaces, forces, fast) -> dict:
    """Normal force and tension on the whole dome: the section's interfaces (its boundary
    interfaces with the next web included) rotated ``n`` times, each copy with the
    section's forces (exact under the cyclic symmetry of SPEC 6.4)."""
    n = scene.params.n
    polygons = [interfaces.polygon(k) @ rotation_z(2 * np.pi * w / n).T
                for w in range(n) for k in range(len(interfaces))]
    whole = concatenate([rotated_web(scene.blocks, w, n) for w in range(n)])
    out = {}
    for name, title, signed in (("normal", "normal force (tension +)", True),
                                ("tension", "tension", False)):
        values = np.tile(np.asarray(forces[name], dtype=float), n)
        fig, ax = _axes3d(whole.bounds)
        scale = colour_scale(values, signed)
        colours = scale["cmap"](scale["norm"](values * scale["factor"]))
        _add_polygons(ax, "01_angle", polygons, colours, linewidths=0.2)
        _colour_bar(fig, ax, scale, FORCE_LABELS[name])
        ax.set_title(f"the whole dome ({n} webs by rotation): {title}\n"
                     f"{scene_title(scene)}", fontsize=9)
        out[f"05_dome/{name}.png"] = _png(fig, 70 if fast else 130)
    return out


HINGE_ECCENTRICITY = 0.99
"""A joint whose resultant lies at least this far out (eccentricity, 1 = on the edge) is
marked as a hinge in the thrust line plot."""


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


def thrust_line_png(scene, interfaces, resultants, fast=False):
    """The thrust line: the resultants' points of application on the bed joints that
    cross the structure's mid-plane (an arch's plane; a dome web's meridian section at
    its centre line, y = 0), in x-z, hinges marked. None when no bed joint crosses it.

    Parameters
    ----------
    scene : Scene
    interfaces : Interfaces
    resultants : dict
        :func:`masonry.rbe.resultants.interface_resultants` of ``interfaces``.
    """
    bounds = scene.blocks.bounds
    y = 0.0 if scene.params.scene in ("section", "dome") else float(bounds[:, 1].mean())
    low = np.minimum.reduceat(interfaces.vertices[:, 1], interfaces.offsets[:-1])
    high = np.maximum.reduceat(interfaces.vertices[:, 1], interfaces.offsets[:-1])
    bed = np.isin(interfaces.kind, HORIZONTAL_KINDS) & (low < y) & (high > y)
    if scene.params.scene in ("section", "dome"):
        bed &= interfaces.centre[:, 0] > 0  # web 0, the web facing +x
    index = np.flatnonzero(bed & np.isfinite(resultants["eccentricity"]))
    if len(index) == 0:
        return None
    # along the arch (left to right) or up the web
    along = interfaces.centre[index, 0 if scene.params.scene == "arch" else 2]
    index = index[np.argsort(along, kind="stable")]
    segments = _cut_at_y(interfaces, index, y)[:, :, [0, 2]]
    # order each joint's ends inner (nearer the arch's or dome's centre) to outer: the
    # ends then trace the intrados and the extrados
    centre = np.array([0.0 if scene.params.scene != "arch" else bounds[:, 0].mean(),
                       bounds[0, 2]])
    outer_first = (np.linalg.norm(segments[:, 0] - centre, axis=1)
                   > np.linalg.norm(segments[:, 1] - centre, axis=1))
    segments[outer_first] = segments[outer_first, ::-1]
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
    ax.plot(point[:, 0], point[:, 2], "-o", color="#c0392b", markersize=2.5, linewidth=1.2,
            label="point of application of the resultant (thrust line)")
    e = resultants["eccentricity"][index]
    hinge = (e >= HINGE_ECCENTRICITY) & (e <= 1 + 1e-6)
    outside = e > 1 + 1e-6
    if hinge.any():
        ax.plot(point[hinge, 0], point[hinge, 2], "o", markerfacecolor="none", markersize=8,
                color="k", label=f"hinge ({HINGE_ECCENTRICITY:g} <= eccentricity <= 1)")
    if outside.any():
        ax.plot(point[outside, 0], point[outside, 2], "x", markersize=7, color="k",
                label="outside its joint (needs tension)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    fig.legend(loc="outside lower center", fontsize=7, frameon=False)
    where = "the arch" if scene.params.scene == "arch" else f"y = {y:g} m"
    ax.set_title(f"thrust line under self-weight through {len(index)} bed joints at {where}: "
                 f"{_count(hinge.sum(), 'hinge')}, {int(outside.sum())} outside\n"
                 f"{scene_title(scene)}", fontsize=9)
    return _png(fig, 80 if fast else 150)


RANKED = 10
"""The interfaces of largest tension numbered in ``where_it_fails.png``."""


def _rank_labels(centres, bounds, near=0.03):
    """``(text, position)`` labels for the ranks 1, 2, ... of points ``centres``; points
    within ``near`` of the bounding box's diagonal of an earlier label share it
    (``'1, 4'``) instead of printing over it."""
    size = float(np.linalg.norm(bounds[1] - bounds[0]))
    labels = []
    for rank, centre in enumerate(centres, start=1):
        for label in labels:
            if np.linalg.norm(label[1] - centre) <= near * size:
                label[0].append(str(rank))
                break
        else:
            labels.append(([str(rank)], centre))
    return [(", ".join(ranks), at) for ranks, at in labels]


def failure_png(scene, blocks, interfaces, top, forces, fast=False) -> bytes:
    """Where it fails: every interface in light grey and the interfaces ``top`` (the
    rows of ``RBE/tension_top.csv``, largest tension first) coloured by tension, the
    first :data:`RANKED` numbered by their rank (neighbours share a label)."""
    fig, ax = _axes3d(blocks.bounds)
    _add_polygons(ax, "01_angle", _polygons(interfaces, range(len(interfaces))),
                  (0.6, 0.6, 0.6, 0.2), edgecolors="none")
    tension = np.asarray(forces["tension"], dtype=float)[top]
    factor, unit = force_unit(tension.max())
    norm = matplotlib.colors.Normalize(0, tension.max() * factor)
    cmap = matplotlib.colormaps["inferno_r"]
    colours = cmap(norm(tension * factor))
    _add_polygons(ax, "01_angle", _polygons(interfaces, top), colours, linewidths=1.0)
    for ranks, at in _rank_labels(interfaces.centre[top[:RANKED]], blocks.bounds):
        # above the polygons (mplot3d orders collections by depth after the texts)
        ax.text(*at, ranks, fontsize=7, color="k", zorder=1e3,
                bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.8,
                      "linewidth": 0})
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, **BAR_3D)
    bar.set_label(f"tension [{unit}]", fontsize=8)
    numbered = (f", the first {RANKED} numbered by rank" if len(top) > RANKED
                else ", numbered by rank")
    ax.set_title(f"where it fails: the {len(top)} interfaces with the largest tension"
                 f"{numbered} (RBE/tension_top.csv)\n{scene_title(scene)}", fontsize=9)
    return _png(fig, 60 if fast else 130)


MECHANISM_SCALE = 0.08
"""Drawn exaggeration of a collapse mechanism: the largest displacement (1 after
normalising) is drawn as this fraction of the model's bounding-box diagonal."""


def _mechanism_faces(blocks, mechanism):
    """The free blocks' faces undeformed and displaced by ``mechanism`` drawn at
    :data:`MECHANISM_SCALE`, and each face's block's largest vertex displacement."""
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    arm = blocks.vertices - blocks.block_centroid[owner]
    displacement = mechanism[owner, :3] + np.cross(mechanism[owner, 3:], arm)
    size = float(np.linalg.norm(blocks.bounds[1] - blocks.bounds[0]))
    moved = blocks.vertices + MECHANISM_SCALE * size * displacement
    per_block = np.zeros(blocks.n_blocks)
    np.maximum.at(per_block, owner, np.linalg.norm(displacement, axis=1))
    faces = np.flatnonzero(~np.asarray(blocks.block_is_support)[blocks.face_block])
    starts, ends = blocks.face_offsets[faces], blocks.face_offsets[faces + 1]
    undeformed = [blocks.vertices[blocks.face_vertices[a:b]] for a, b in zip(starts, ends)]
    deformed = [moved[blocks.face_vertices[a:b]] for a, b in zip(starts, ends)]
    bounds = np.array([np.minimum(blocks.bounds[0], moved.min(axis=0)),
                       np.maximum(blocks.bounds[1], moved.max(axis=0))])
    return undeformed, deformed, per_block[blocks.face_block[faces]], bounds


def azimuths_png(scene, collapse) -> bytes:
    """``collapse/azimuths.png``: the lateral load factor against the load's azimuth
    (``--lateral all``) on polar axes, the worst marked."""
    angle = np.array([a for a, _ in collapse.azimuths])
    factor = np.array([np.nan if f is None else f for _, f in collapse.azimuths])
    order = np.argsort(angle)  # the line breaks where an azimuth has no factor
    theta = np.radians(np.append(angle[order], angle[order][0]))
    fig, ax = plt.subplots(figsize=(5.5, 5.5), subplot_kw={"projection": "polar"})
    ax.plot(theta, np.append(factor[order], factor[order][0]), "-o", color="C0",
            markersize=3, linewidth=1)
    worst = np.radians(collapse.azimuth_deg)
    ax.plot([worst], [collapse.load_factor], "o", color="#d62728", markersize=8,
            label=f"worst: {collapse.load_factor:.4g} at {collapse.azimuth_deg:g} deg")
    ax.set_ylim(0, 1.1 * np.nanmax(factor))
    ax.set_rlabel_position(100)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, -0.15), fontsize=8, frameon=False)
    ax.set_title(f"lateral load factor against the load's azimuth (from +x toward +y)\n"
                 f"{scene_title(scene)}", fontsize=9, pad=20)
    return _png(fig, 110)


def _live_load_marks(ax, view, blocks, live, bounds) -> list:
    """Where the live load acts: the loaded blocks marked when not every block is loaded
    (a point or crown load), and its resultant's direction as an arrow, into them, or
    from the plot's edge the load comes from (none for forces that cancel). Returns the
    legend handles."""
    handles = []
    loaded = np.flatnonzero(np.abs(live.wrench[:, :3]).max(axis=1) > 0)
    some = len(loaded) < int((~np.asarray(blocks.block_is_support)).sum())
    if some:
        _points(ax, view, blocks.block_centroid[loaded], marker="v", color="k", s=18)
        handles.append(Line2D([], [], marker="v", color="k", linestyle="none",
                              label=f"loaded blocks ({len(loaded)})"))
    total = live.total_force
    if np.linalg.norm(total) <= 1e-9 * np.abs(live.wrench[:, :3]).sum():
        return handles  # a couple, a push and a pull: no one direction
    direction = total / float(np.linalg.norm(total))
    start, end = _arrow(blocks.block_centroid[loaded].mean(axis=0) if some else None,
                        direction, bounds)
    if view not in ELEVATIONS:
        ax.quiver(*start, *(end - start), color="k", linewidth=1.5, arrow_length_ratio=0.3)
    else:
        h, v, _, _ = ELEVATIONS[view]
        if np.hypot(*direction[[h, v]]) < 0.1:  # seen along the load
            return handles
        ax.annotate("", xy=end[[h, v]], xytext=start[[h, v]], zorder=11,
                    arrowprops=dict(arrowstyle="-|>", color="k", linewidth=1.5))
    handles.append(Line2D([], [], marker=r"$\rightarrow$", color="k", linestyle="none",
                          markersize=12, label="live load's direction"))
    return handles


def _arrow(target, direction, bounds):
    """``(start, end)`` of an arrow along ``direction`` (a unit (3,)): into ``target``, as
    long as the box ``bounds`` leaves room for behind it, or (None) from the box's edge."""
    size = float(np.abs(direction) @ (bounds[1] - bounds[0]))  # the box along it
    if target is None:
        start = bounds.mean(axis=0) - 0.45 * size * direction
        return start, start + 0.25 * size * direction
    room = np.where(direction > 0, target - bounds[0], bounds[1] - target)
    moving = np.abs(direction) > 1e-9  # not empty: a unit vector
    length = min(0.25 * size, 0.9 * float((room[moving] / np.abs(direction[moving])).min()))
    return target - length * direction, target


def mechanism_pngs(scene, blocks, interfaces, collapse, title, fast=False) -> dict:
    """The collapse mechanism (SPEC 6.9) drawn exaggerated over the undeformed structure,
    in the four views (``collapse/<view>_mechanism.png``; one view when ``fast``):
    displaced blocks coloured by their largest vertex displacement, the undeformed ones as
    grey outlines, the hinges and sliding joints that carry the mechanism
    (:data:`~masonry.tolerances.MECHANISM_MAIN`) filled red and outlined blue, at their
    undeformed places (seen through the blocks).

    Parameters
    ----------
    scene : Scene
        For the figure titles.
    blocks, interfaces : the analysed model's
    collapse : masonry.rbe.collapse.CollapseResult
        With a mechanism: ``mechanism`` ((B, 6), per block ``(u, theta)`` about its
        centroid, largest vertex displacement 1) and the joints that carry it.
    title : str
    """
    undeformed, deformed, value, bounds = _mechanism_faces(
        blocks, np.asarray(collapse.mechanism))
    scale = colour_scale(value, signed=False, is_force=False)
    colours = scale["cmap"](scale["norm"](value))
    share = f"\u2265 {MECHANISM_MAIN:.0%} of the largest"
    handles = [Patch(facecolor="none", edgecolor="0.6", label="undeformed")]
    if collapse.hinges:
        handles.append(Patch(facecolor="red", edgecolor="red",
                             label=f"hinges opening {share}: {collapse.main_hinges} of "
                                   f"{collapse.hinges}"))
    if collapse.sliding:
        handles.append(Patch(facecolor="none", edgecolor="blue",
                             label=f"sliding {share}: {collapse.main_sliding} of "
                                   f"{collapse.sliding}"))
    joints = [(_polygons(interfaces, np.flatnonzero(mask)), face, edge, width)
              for mask, face, edge, width in ((collapse.main_slides, NO_FILL, "blue", 0.6),
                                              (collapse.main_hinge, "red", "red", 0.8))
              if mask.any()]
    out = {}
    for view in ["01_angle"] if fast else list(VIEWS):
        fig, ax = _axes(bounds, view)
        if view not in ELEVATIONS:
            ax.computed_zorder = False  # in the order drawn: the joints on top
        _add_polygons(ax, view, undeformed, NO_FILL, edgecolors="0.6", linewidths=0.1)
        _add_polygons(ax, view, deformed, colours, edgecolors="k", linewidths=0.05)
        for polygons, face, edge, width in joints:
            _add_polygons(ax, view, polygons, face, edgecolors=edge, linewidths=width)
        shown = handles + (_live_load_marks(ax, view, blocks, collapse.live, bounds)
                           if collapse.live is not None else [])
        _colour_bar(fig, ax, scale, "virtual displacement (largest = 1)")
        if view in ELEVATIONS:  # below the plot: an elevation fills its axes
            # 0.45 inch below the axes, clear of the tick labels at any aspect
            below = ax.transAxes + ScaledTranslation(0, -0.45, fig.dpi_scale_trans)
            ax.legend(handles=shown, loc="upper center", bbox_to_anchor=(0.5, 0),
                      bbox_transform=below, ncol=3, fontsize=7, frameon=False)
        else:
            ax.legend(handles=shown, loc="upper left", fontsize=7)
        ax.set_title(f"{title}; displacement drawn at {MECHANISM_SCALE:g} x size\n"
                     f"{scene_title(scene)}", fontsize=9)
        out[f"collapse/{view}_mechanism.png"] = _png(fig, 60 if fast else 110)
    return out
