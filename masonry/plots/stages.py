"""Construction stages: the chart of every stage's centering force (and collapse load
factor), which stand and which need support; the chart of every stage's least adhesion;
and the structure views of one stage, its bricks coloured by the support force they need
and the bricks just laid outlined."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm, to_rgba
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter, MaxNLocator

from masonry.blocks import BLOCK_CLASSES
from masonry.plots.colours import EMPHASIS, LOOSE, NEEDS_SUPPORT, STANDS, bar_3d
from masonry.plots.common import (CLASS_COLOURS, ELEVATIONS, NO_FILL, PNG, add_points,
                                  add_polygons, as_files, draw_outline, figure_files,
                                  legend_below, view_axes, views_of, visible_faces)
from masonry.plots.faces import face_array
from masonry.tolerances import ADHESION_TIE_REL

OUTLINE_COLOUR = "#ff00ff"
"""Edge colour of the outlined blocks of :func:`marked_structure_pngs`."""

MARK_DECADES = 2
"""Decades of the colour scale of :func:`marked_structure_pngs`: blocks whose value is
below ``10**-MARK_DECADES`` of the largest keep their class colour."""


def marked_structure_pngs(scene, is_present, value, title, value_label="value",
                          is_outlined=None, outline_label="outlined", fast=False,
                          subtitle="", render=PNG) -> dict:
    """The structure views of a part of ``scene`` (e.g. a construction stage): the blocks
    of ``is_present`` ((B,) bool), coloured by ``value`` ((B,) float >= 0, e.g. the
    support force a brick needs, newtons) on a logarithmic scale over
    :data:`MARK_DECADES` decades, in their class colours below it; the blocks of
    ``is_outlined`` ((B,) bool, e.g. the ones just laid) with thick :data:`OUTLINE_COLOUR`
    edges and a ring (legend ``outline_label``); the rest of the scene's blocks as faint
    outlines. ``{view}.png`` per view of its extent (and ``.svg``, ``.pdf`` as ``render``
    asks), one view at lower resolution when ``fast``;
    ``title`` and ``subtitle`` are the figure's title and the line under it."""
    blocks = scene.blocks
    owner = blocks.face_block
    top = max(float(np.max(value[is_present], initial=0.0)), 1e-300)
    norm = LogNorm(top * 10.0**-MARK_DECADES, top)
    cmap = plt.get_cmap("viridis_r")
    colours = np.array([to_rgba(CLASS_COLOURS[BLOCK_CLASSES[k]]) for k in blocks.block_class])
    is_marked = value >= norm.vmin
    colours[is_marked] = cmap(norm(value[is_marked]))
    is_marked &= is_present
    outlined = (np.zeros(blocks.n_blocks, bool) if is_outlined is None
                else is_outlined & is_present)
    out = {}
    for view in views_of(blocks.bounds, fast):
        fig, ax = view_axes(blocks.bounds, view)
        if view not in ELEVATIONS:
            ax.computed_zorder = False  # draw in the order below: the rings on top
        draw_outline(ax, view, scene)
        ghost = visible_faces(blocks, ~is_present & ~blocks.block_is_support, view)
        add_polygons(ax, view, face_array(blocks, ghost), NO_FILL, edgecolors="0.8",
                     linewidths=0.1)
        shown = visible_faces(blocks, is_present, view)
        add_polygons(ax, view, face_array(blocks, shown), colours[owner[shown]],
                     edgecolors="k", linewidths=0.1)
        handles = [Patch(facecolor="none", edgecolor="0.7", label="not yet laid")]
        if outlined.any():
            edged = visible_faces(blocks, outlined, view)
            add_polygons(ax, view, face_array(blocks, edged), NO_FILL,
                         edgecolors=OUTLINE_COLOUR, linewidths=2.0)
            # a ring around each, so that a single brick shows at any scale
            add_points(ax, view, blocks.block_centroid[outlined], s=160, facecolors="none",
                       edgecolors=OUTLINE_COLOUR, linewidths=1.5)
            handles.append(Line2D([], [], color=OUTLINE_COLOUR, marker="o", markersize=9,
                                  fillstyle="none", linewidth=2, label=outline_label))
        if is_marked.any():
            below = bool(((value > 0) & ~is_marked & is_present).any())
            bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                               extend="min" if below else "neither",
                               **(bar_3d(fig) if view not in ELEVATIONS else dict(pad=0.05)))
            bar.set_label(value_label)
            handles.append(Patch(facecolor=CLASS_COLOURS["regular"], edgecolor="k",
                                 label="laid, below the scale (class colours)"))
        legend_below(fig, ax, handles, fontsize=8)
        ax.set_title(f"{title}\n{subtitle}", fontsize=9)
        out.update(as_files(f"{view}.png", figure_files(fig, 60 if fast else 110, render)))
    return out


def stage_chart_png(stage, centering, feasible, load_factor=None, title="",
                    xlabel="stage", loose=None, render=PNG) -> dict:
    """The centering force as a fraction of the weight (and the collapse load factor,
    where given) against the construction stage: stages that stand in green (at 0),
    those that need support in vermillion, the first of them marked by a dashed line;
    stages with loose blocks as black crosses (:mod:`masonry.plots.colours`).

    Parameters
    ----------
    stage : (N,) int
    centering : (N,) float
        Centering force / weight (NaN: not solved).
    feasible : (N,) bool
    load_factor : (N,) float or None (NaN: not computed)
    loose : (N,) int or None
        Blocks per stage that touch nothing joining them to a support.
    render : masonry.plots.common.Render
        The formats of the files returned (format -> bytes).
    """
    stage = np.asarray(stage)
    centering = np.asarray(centering, dtype=float)
    feasible = np.asarray(feasible, dtype=bool)
    loose = np.zeros(len(stage), int) if loose is None else np.asarray(loose)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(stage, centering, color="0.6", linewidth=0.8, zorder=1)
    ax.scatter(stage[feasible], centering[feasible], s=14, color=STANDS,
               label=f"stands ({int(feasible.sum())})", zorder=2)
    held = ~feasible & (loose == 0)
    ax.scatter(stage[held], centering[held], s=14, color=NEEDS_SUPPORT,
               label=f"needs support ({int(held.sum())})", zorder=2)
    if loose.any():
        ax.scatter(stage[loose > 0], centering[loose > 0], marker="x", s=24,
                   color=LOOSE, zorder=2, label=f"a block touches nothing that holds "
                   f"it ({int((loose > 0).sum())})")
    if not feasible.all():
        first = stage[np.argmin(feasible)]
        ax.axvline(first, color=NEEDS_SUPPORT, linestyle="--", linewidth=0.8,
                   label=f"first needs support: {first}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("centering force / weight (least support force)")
    top = float(np.nanmax(centering, initial=0.0))
    ax.set_ylim(bottom=-0.02 * (top if top > 0 else 1.0))
    handles, labels = ax.get_legend_handles_labels()
    if load_factor is not None and np.isfinite(np.asarray(load_factor, float)).any():
        right = ax.twinx()
        right.plot(stage, np.asarray(load_factor, float), color=EMPHASIS, marker=".",
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
    return figure_files(fig, 110, render)


FRESH_MORTAR_KPA = (0.1, 1.0)
"""Reference lines of :func:`stage_adhesion_png`, kPa: fresh lime or gypsum mortar holds
of the order of 0.1 to a few kPa within minutes of laying (docs/model.md 6.12), orders of
magnitude, not a measured mortar."""

REFERENCE_COLOUR = "0.3"
"""Colour of the reference lines of :func:`stage_adhesion_png`."""

LINEAR_DECADES = 10.0
""":func:`stage_adhesion_png`'s axis is linear up to this many times the upper
reference line, symmetric-logarithmic beyond (linear below the lower line), so that the
reference lines and a large ``a*`` show on one axis."""


def stage_adhesion_png(stage, adhesion_kPa, feasible, title="", xlabel="stage",
                       ratio=None, render=PNG) -> dict:
    """The least adhesion of every stage (docs/model.md 6.12) against the stage, kPa:
    stages that stand dry in green (at 0), stages that stand on the study's mortar (a*
    above 0) as green rings, those that need adhesion in vermillion (the largest
    labelled), stages without a value as black crosses at 0, and dotted lines at
    :data:`FRESH_MORTAR_KPA`; a logarithmic axis beyond :data:`LINEAR_DECADES`.

    Parameters
    ----------
    stage : (N,) int
    adhesion_kPa : (N,) float
        ``a*`` per stage, kPa (NaN: no value).
    feasible : (N,) bool
        The stage stands (with dry joints, or with the study's mortar).
    ratio : float, optional
        The tension ratio ``t_c / c``, named in the axis label.
    render : masonry.plots.common.Render
        The formats of the files returned (format -> bytes).
    """
    stage = np.asarray(stage)
    value = np.asarray(adhesion_kPa, dtype=float)
    feasible = np.asarray(feasible, dtype=bool)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(stage, value, color="0.6", linewidth=0.8, zorder=1)
    dry = feasible & ~(value > 0)
    ax.scatter(stage[dry], value[dry], s=14, color=STANDS,
               label=f"stands dry ({int(dry.sum())})", zorder=2)
    mortar = feasible & (value > 0)
    if mortar.any():
        ax.scatter(stage[mortar], value[mortar], s=22, facecolors="none",
                   edgecolors=STANDS, linewidths=1.2, zorder=2,
                   label=f"stands on its mortar ({int(mortar.sum())})")
    held = ~feasible & np.isfinite(value)
    ax.scatter(stage[held], value[held], s=14, color=NEEDS_SUPPORT,
               label=f"needs adhesion ({int(held.sum())})", zorder=2)
    missing = ~np.isfinite(value)
    if missing.any():
        ax.scatter(stage[missing], np.zeros(int(missing.sum())), marker="x", s=24,
                   color=LOOSE, zorder=2,
                   label=f"no value: a block held by nothing ({int(missing.sum())})")
    if held.any():  # at the first stage that reaches the largest (the record's)
        top = np.max(value[held])
        first = np.argmax(held & (value >= top * (1 - ADHESION_TIE_REL)))
        ax.annotate(f"{top:.4g} kPa", (stage[first], value[first]),
                    textcoords="offset points", xytext=(0, 6), ha="center", fontsize=8)
    low, high = FRESH_MORTAR_KPA
    for level in FRESH_MORTAR_KPA:
        ax.axhline(level, color=REFERENCE_COLOUR, linestyle=":", linewidth=1.0, zorder=0,
                   label=f"{low:g} and {high:g} kPa: fresh mortar holds about {low:g} to a "
                         f"few kPa within minutes" if level == low else None)
    ax.set_xlabel(xlabel)
    tension = "" if ratio is None else f", tensile strength {ratio:g} a*"
    ax.set_ylabel(f"least adhesion a* [kPa]\n(cohesion a*{tension})")
    top = max(float(np.nanmax(value, initial=0.0)), high)
    if top > LINEAR_DECADES * high:  # beyond fresh mortar's range: its lines stay apart
        ax.set_yscale("symlog", linthresh=low, linscale=0.5)
        ax.set_ylim(-0.2 * low, 2.0 * top)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    else:
        ax.set_ylim(-0.03 * top, 1.12 * top)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=8,
              frameon=False)  # below the plot: the curve may fill any corner
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    return figure_files(fig, 110, render)
