"""The flattened pattern (thesis figures 3.8-3.9): one web's bricks laid out by position
along the wall and course, by class, inside the web's half width."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.patches import Patch

from masonry.blocks import BLOCK_CLASSES, PATTERN
from masonry.plots.colours import WEB_OUTLINE
from masonry.plots.common import CLASS_COLOURS, PNG, figure_files, legend_below


def pattern_png(scene, fast=False, title="", render=PNG) -> dict:
    """The flattened section (thesis figures 3.8-3.9): position along the wall (units)
    against course, pattern, regular and fill-in bricks in distinct colours (the legend
    under the axes names the classes present), the web's half width at every course in
    dashed (:data:`~masonry.plots.colours.WEB_OUTLINE`); ``title`` is the line under the figure's own. Returns its files
    (:func:`~masonry.plots.common.figure_files`: format -> bytes, of ``render``)."""
    layout, levels, unit = scene.layout, scene.levels, scene.unit
    height = np.where(layout.klass == PATTERN, 2, 1)
    # mitered ends reach the web's boundary (at the course's lower, wider edge)
    w_low = levels.y[layout.course - 1] / unit
    s0 = np.where(layout.miter_left, -w_low, layout.s0)
    s1 = np.where(layout.miter_right, w_low, layout.s1)
    fig, ax = plt.subplots(figsize=(6, 7.5))
    # the bricks' rectangles as two collections, the pattern bricks (two courses high)
    # over the others
    bottom = layout.course - 1.0
    corners = np.stack([np.column_stack([s0, bottom]), np.column_stack([s1, bottom]),
                        np.column_stack([s1, bottom + height]),
                        np.column_stack([s0, bottom + height])], axis=1)
    colours = np.array([CLASS_COLOURS[name] for name in BLOCK_CLASSES],
                       dtype=object)[layout.klass]
    for on_top in (False, True):
        mine = (layout.klass == PATTERN) == on_top
        ax.add_collection(PolyCollection(corners[mine], facecolors=list(colours[mine]),
                                         edgecolors="k", linewidths=0.3,
                                         zorder=3 if on_top else 2), autolim=False)
    w = levels.y / unit
    z = np.arange(len(w))
    ax.plot(w, z, -w, z, color=WEB_OUTLINE, linestyle="--", linewidth=1.2)
    ax.set_xlabel(scene.kind.pattern_axis)
    ax.set_ylabel("course")
    # every brick (a sector's reach past the half width on one side) and the outline
    ax.set_xlim(min(float(s0.min()), -float(w.max())) - 1,
                max(float(s1.max()), float(w.max())) + 1)
    ax.set_ylim(-0.5, len(w) + 0.5)
    legend_below(fig, ax, [Patch(facecolor=CLASS_COLOURS[name], edgecolor="k",
                                 label=name.replace("_", "-"))
                           for name in ("pattern", "regular", "fill_in")
                           if np.any(layout.klass == BLOCK_CLASSES.index(name))])
    pattern = int((layout.klass == PATTERN).sum())
    what = scene.kind.pattern_caption(scene.geometry)
    counts = f"{pattern} pattern" if pattern else "no pattern bricks"
    ax.set_title(f"{what}: {len(layout)} bricks ({counts})\n{title}", fontsize=9)
    return figure_files(fig, 80 if fast else 130, render)
