"""Where it fails: the interfaces of largest tension, coloured by it and numbered by
rank, over the faint rest of the interfaces."""

import matplotlib
import numpy as np
from mpl_toolkits.mplot3d import proj3d

from masonry.plots.colours import bar_3d, force_unit
from masonry.plots.common import PNG, add_polygons, axes_3d, figure_files
from masonry.plots.faces import interface_array

RANKED = 10
"""The interfaces of largest tension numbered in ``where_it_fails.png``."""


def _rank_labels(centres, bounds, near=0.03):
    """``(text, position)`` labels for the ranks 1, 2, ... of points ``centres`` (3D, or
    as the figure projects them); points within ``near`` of the bounding box's diagonal
    of an earlier label share it (``'1, 4'``) instead of printing over it."""
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


LABEL_NEAR = 0.05
"""Rank labels closer than this fraction of the model's projected size, as drawn, share
one label."""


def _label_ranks(ax, centres, bounds):
    """The rank labels of ``centres`` in the 3D axes ``ax``, merged where they would
    print over each other as the axes project them (:data:`LABEL_NEAR`)."""
    corners = np.array(np.meshgrid(*bounds.T)).reshape(3, -1)
    projection = ax.get_proj()
    flat = np.column_stack(proj3d.proj_transform(*centres.T, projection)[:2])
    box = np.column_stack(proj3d.proj_transform(*corners, projection)[:2])
    for ranks, at in _rank_labels(flat, np.array([box.min(axis=0), box.max(axis=0)]),
                                  near=LABEL_NEAR):
        first = int(ranks.split(",")[0]) - 1
        # above the polygons (mplot3d orders collections by depth after the texts)
        ax.text(*centres[first], ranks, fontsize=7, color="k", zorder=1e3,
                bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.8,
                      "linewidth": 0})


def failure_png(blocks, interfaces, top, forces, fast=False, title="", render=PNG) -> dict:
    """Where it fails: every interface in light grey and the interfaces ``top`` (the
    rows of ``RBE/tension_top.csv``, largest tension first) coloured by tension, the
    first :data:`RANKED` numbered by their rank (neighbours share a label); ``title`` is the
    line under the figure's own. Returns its files by format (of ``render``)."""
    fig, ax = axes_3d(blocks.bounds)
    add_polygons(ax, "01_angle", interface_array(interfaces, np.arange(len(interfaces))),
                 (0.6, 0.6, 0.6, 0.2), edgecolors="none")
    tension = np.asarray(forces["tension"], dtype=float)[top]
    factor, unit = force_unit(tension.max())
    norm = matplotlib.colors.Normalize(0, tension.max() * factor)
    cmap = matplotlib.colormaps["inferno_r"]
    colours = cmap(norm(tension * factor))
    add_polygons(ax, "01_angle", interface_array(interfaces, top), colours, linewidths=1.0)
    _label_ranks(ax, interfaces.centre[top[:RANKED]], blocks.bounds)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, **bar_3d(fig))
    bar.set_label(f"tension [{unit}]", fontsize=8)
    numbered = (f", the first {RANKED} numbered by rank" if len(top) > RANKED
                else ", numbered by rank")
    ax.set_title(f"where it fails: the {len(top)} interfaces with the largest tension\n"
                 f"{numbered[2:]} (RBE/tension_top.csv)\n{title}", fontsize=9)
    return figure_files(fig, 60 if fast else 130, render)
