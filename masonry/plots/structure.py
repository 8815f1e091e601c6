"""The structure views (thesis figures 3.7, 3.10, 3.11): the web's boundaries, the
pattern bricks and the complete structure in the four views, blocks in their class
colours; a cyclic section also as the whole dome."""

import numpy as np
from matplotlib.patches import Patch

from masonry.blocks import BLOCK_CLASSES, PATTERN, concatenate, rotated_web
from masonry.plots.common import (CLASS_COLOURS, VIEWS, add_polygons, axes_3d, draw_outline,
                                  png_bytes, view_axes)


def _faces_3d(blocks, mask):
    """The faces ((m, 3) float, metres) of the blocks of ``mask`` and their class
    colours."""
    faces = np.flatnonzero(mask[blocks.face_block])
    polys = [blocks.face_polygon(f) for f in faces]
    colours = [CLASS_COLOURS[BLOCK_CLASSES[blocks.block_class[blocks.face_block[f]]]]
               for f in faces]
    return polys, colours


def _class_legend(ax, codes):
    """A legend of the block classes of ``codes``."""
    handles = [Patch(facecolor=CLASS_COLOURS[BLOCK_CLASSES[c]], edgecolor="k",
                     label=BLOCK_CLASSES[c].replace("_", "-")) for c in np.unique(codes)]
    ax.legend(handles=handles, loc="upper left", fontsize=8, frameon=False)


def _draw_blocks(ax, view, blocks, mask, linewidth=0.1):
    """The blocks of ``mask`` in their class colours, black edges, and their legend."""
    if mask.any():
        polys, colours = _faces_3d(blocks, mask)
        add_polygons(ax, view, polys, colours, edgecolors="k", linewidths=linewidth)
        _class_legend(ax, blocks.block_class[mask])


def structure_pngs(scene, fast=False, title="", webs=None) -> dict:
    """Structure plots in the thesis's stages (figures 3.7, 3.10, 3.11): the web's
    boundaries, the pattern bricks, the complete structure; in the four views, or one
    view at lower resolution when ``fast``; with ``webs`` (a section that stands for the
    whole dome) also the whole dome (``05_dome/3_structure.png``, the section rotated
    ``webs`` times). ``title`` is the line under each figure's own."""
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
            fig, ax = view_axes(bounds, view)
            draw_outline(ax, view, scene)
            _draw_blocks(ax, view, blocks, mask)
            count = int((mask & ~blocks.block_is_support).sum())
            shown = (f"{count} {scene.kind.block_word}" if mask.any()
                     else "the web's outline (blue), before any brick is laid")
            ax.set_title(f"{stage[2:]}: {shown}\n{title}", fontsize=9)
            out[f"{view}/{stage}.png"] = png_bytes(fig, 60 if fast else 110)
    if webs:
        n = webs
        whole = concatenate([rotated_web(blocks, k, n, ~blocks.block_is_support)
                             for k in range(n)])
        fig, ax = axes_3d(whole.bounds)
        _draw_blocks(ax, "01_angle", whole, np.ones(whole.n_blocks, bool), linewidth=0.05)
        ax.set_title(f"the whole dome: the section rotated {n} times, {whole.n_blocks} "
                     f"bricks\n{title}", fontsize=9)
        out["05_dome/3_structure.png"] = png_bytes(fig, 70 if fast else 130)
    return out
