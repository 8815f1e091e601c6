"""The collapse mechanism: the blocks displaced by it, drawn exaggerated over the
undeformed structure in the four views, with the joints that carry it and the live
load's direction."""

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from masonry.plots.colours import HINGE, SLIDING, colour_bar, colour_scale
from masonry.plots.common import (ELEVATIONS, NO_FILL, PNG, add_points, add_polygons,
                                  as_files, figure_files, legend_below, view_axes, views_of)
from masonry.plots.faces import face_array, interface_array, padded
from masonry.rbe.collapse_result import vertex_displacements
from masonry.tolerances import MECHANISM_MAIN

MECHANISM_SCALE = 0.08
"""Drawn exaggeration of a collapse mechanism: the largest displacement (1 after
normalising) is drawn as this fraction of the model's bounding-box diagonal."""


def _mechanism_faces(blocks, mechanism):
    """The free blocks' faces undeformed and displaced by ``mechanism`` drawn at
    :data:`MECHANISM_SCALE`, and each face's block's largest vertex displacement."""
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(blocks.vertex_offsets))
    displacement = vertex_displacements(blocks, mechanism)
    size = float(np.linalg.norm(blocks.bounds[1] - blocks.bounds[0]))
    moved = blocks.vertices + MECHANISM_SCALE * size * displacement
    per_block = np.zeros(blocks.n_blocks)
    np.maximum.at(per_block, owner, np.linalg.norm(displacement, axis=1))
    faces = np.flatnonzero(~np.asarray(blocks.block_is_support)[blocks.face_block])
    undeformed = face_array(blocks, faces)
    deformed = padded(moved[blocks.face_vertices], blocks.face_offsets, faces)
    bounds = np.array([np.minimum(blocks.bounds[0], moved.min(axis=0)),
                       np.maximum(blocks.bounds[1], moved.max(axis=0))])
    return undeformed, deformed, per_block[blocks.face_block[faces]], bounds


def _live_load_marks(ax, view, blocks, live, bounds) -> list:
    """Where the live load acts: the loaded blocks marked when not every block is loaded
    (a point or crown load), and its resultant's direction as an arrow
    (:meth:`~masonry.rbe.loads.LiveLoad.arrow`; none for forces that cancel). Returns the
    legend handles."""
    handles = []
    loaded = live.loaded_blocks(blocks)
    if loaded is not None:
        add_points(ax, view, blocks.block_centroid[loaded], marker="v", color="k", s=18)
        handles.append(Line2D([], [], marker="v", color="k", linestyle="none",
                              label=f"loaded blocks ({len(loaded)})"))
    arrow = live.arrow(blocks, bounds)
    if arrow is None:
        return handles
    start, end = arrow
    if view not in ELEVATIONS:
        ax.quiver(*start, *(end - start), color="k", linewidth=1.5, arrow_length_ratio=0.3)
    else:
        h, v, _, _ = ELEVATIONS[view]
        direction = (end - start) / float(np.linalg.norm(end - start))
        if np.hypot(*direction[[h, v]]) < 0.1:  # seen along the load
            return handles
        ax.annotate("", xy=end[[h, v]], xytext=start[[h, v]], zorder=11,
                    arrowprops=dict(arrowstyle="-|>", color="k", linewidth=1.5))
    handles.append(Line2D([], [], marker=r"$\rightarrow$", color="k", linestyle="none",
                          markersize=12, label="live load's direction"))
    return handles


def _joint_handles(collapse) -> list:
    """Legend handles of the undeformed blocks and of the hinges and sliding joints
    that carry the mechanism."""
    share = f"\u2265 {MECHANISM_MAIN:.0%} of the largest"
    handles = [Patch(facecolor="none", edgecolor="0.6", label="undeformed")]
    if collapse.hinges:
        handles.append(Patch(facecolor=HINGE, edgecolor=HINGE,
                             label=f"hinges opening {share}: {collapse.main_hinges} of "
                                   f"{collapse.hinges}"))
    if collapse.sliding:
        handles.append(Patch(facecolor="none", edgecolor=SLIDING,
                             label=f"sliding {share}: {collapse.main_sliding} of "
                                   f"{collapse.sliding}"))
    return handles


def mechanism_pngs(blocks, interfaces, collapse, title, fast=False, subtitle="",
                   render=PNG) -> dict:
    """The collapse mechanism (docs/model.md 6.9) drawn exaggerated over the undeformed
    structure, in the views of its extent (``collapse/<view>_mechanism.png``; one view
    when ``fast``; :func:`~masonry.plots.common.views_of`):
    displaced blocks coloured by their largest vertex displacement, the undeformed ones as
    grey outlines, the hinges and sliding joints that carry the mechanism
    (:data:`~masonry.tolerances.MECHANISM_MAIN`) filled (:data:`~masonry.plots.colours.HINGE`) and outlined
    (:data:`~masonry.plots.colours.SLIDING`), at their
    undeformed places (seen through the blocks).

    Parameters
    ----------
    blocks, interfaces : the analysed model's
    collapse : masonry.rbe.collapse.CollapseResult
        With a mechanism: ``mechanism`` ((B, 6), per block ``(u, theta)`` about its
        centroid, largest vertex displacement 1) and the joints that carry it.
    title, subtitle : str
        The figure's title and the line under it.
    render : masonry.plots.common.Render
        The formats of each figure's files.
    """
    undeformed, deformed, value, bounds = _mechanism_faces(
        blocks, np.asarray(collapse.mechanism))
    scale = colour_scale(value, signed=False, is_force=False)
    colours = scale["cmap"](scale["norm"](value))
    handles = _joint_handles(collapse)
    joints = [(interface_array(interfaces, np.flatnonzero(mask)), face, edge, width)
              for mask, face, edge, width in ((collapse.main_slides, NO_FILL, SLIDING, 0.8),
                                              (collapse.main_hinge, HINGE, HINGE, 0.8))
              if mask.any()]
    out = {}
    for view in views_of(bounds, fast):
        fig, ax = view_axes(bounds, view)
        if view not in ELEVATIONS:
            ax.computed_zorder = False  # in the order drawn: the joints on top
        add_polygons(ax, view, undeformed, NO_FILL, edgecolors="0.6", linewidths=0.1)
        add_polygons(ax, view, deformed, colours, edgecolors="k", linewidths=0.05)
        for polygons, face, edge, width in joints:
            add_polygons(ax, view, polygons, face, edgecolors=edge, linewidths=width)
        shown = handles + (_live_load_marks(ax, view, blocks, collapse.live, bounds)
                           if collapse.live is not None else [])
        colour_bar(fig, ax, scale, "virtual displacement (largest = 1)")
        legend_below(fig, ax, shown)
        ax.set_title(f"{title}; displacement drawn at {MECHANISM_SCALE:g} x size\n"
                     f"{subtitle}", fontsize=9)
        out.update(as_files(f"collapse/{view}_mechanism.png",
                            figure_files(fig, 60 if fast else 110, render)))
    return out
