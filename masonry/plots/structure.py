"""The structure views (thesis figures 3.7, 3.10, 3.11): the web's boundaries, the
pattern bricks and the complete structure in the views of the model's extent, blocks in
their class colours and supports apart; a cyclic section also as the whole dome.

Only the faces a view can show are drawn (:func:`~masonry.plots.common.visible_faces`):
the outer faces turned toward it."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import to_rgba
from matplotlib.patches import Patch

from masonry.blocks import BLOCK_CLASSES, PATTERN, concatenate, rotated_web
from masonry.plots.common import (CLASS_COLOURS, PNG, add_polygons, as_files, axes_3d,
                                  draw_outline, figure_files, legend_below, view_axes,
                                  views_of, visible_faces)
from masonry.plots.faces import face_array, hidden_faces

SUPPORT_COLOUR = "#5f6b7a"
"""Fill of the support blocks (the ground, an imported assembly's supports): apart from
every block class."""


def block_colours(blocks, mask) -> tuple:
    """((B, 4) RGBA of every block: its class colour, supports in :data:`SUPPORT_COLOUR`;
    {legend label: colour} of the kinds among the blocks of ``mask``)."""
    names = np.array(BLOCK_CLASSES, dtype=object)[blocks.block_class]
    names[np.asarray(blocks.block_is_support, bool)] = "support"
    palette = {**CLASS_COLOURS, "support": SUPPORT_COLOUR}
    present = set(names[mask])
    shown = {name.replace("_", "-"): palette[name] for name in palette if name in present}
    return np.array([to_rgba(palette[name]) for name in names]).reshape(-1, 4), shown


def _draw_blocks(ax, view, blocks, mask, hidden, linewidth=0.1) -> tuple:
    """The blocks of ``mask`` that ``view`` shows, in their colours (:func:`block_colours`)
    with black edges; returns the legend handles of what it drew and its collection
    (None when it drew nothing)."""
    if not mask.any():
        return [], None
    faces = visible_faces(blocks, mask, view, hidden)
    colours, legend = block_colours(blocks, mask)
    drawn = add_polygons(ax, view, face_array(blocks, faces),
                         colours[blocks.face_block[faces]], edgecolors="k",
                         linewidths=linewidth)
    return [Patch(facecolor=colour, edgecolor="k", label=label)
            for label, colour in legend.items()], drawn


def _stages(scene) -> dict:
    """{stage: blocks drawn} of the structure figures: the web's boundaries (a scene with
    one web's outline), the pattern bricks (when it has them), the whole structure."""
    blocks = scene.blocks
    pattern = blocks.block_class == PATTERN
    stages = {"3_structure": np.ones(blocks.n_blocks, bool)}
    if pattern.any():
        stages = {"2_pattern": pattern, **stages}
        if scene.symmetry.unit:
            stages = {"1_boundaries": np.zeros(blocks.n_blocks, bool), **stages}
    return stages


def structure_pngs(scene, fast=False, title="", webs=None, interfaces=None,
                   render=PNG) -> dict:
    """Structure plots in the thesis's stages (figures 3.7, 3.10, 3.11): the web's
    boundaries (one web's outline: a section's only), the pattern bricks, the complete
    structure; in the views of the model's extent (:func:`~masonry.plots.common.views_of`,
    one view at lower resolution when ``fast``); with ``webs`` (a section that stands
    for the whole dome) also the whole dome (``05_dome/3_structure.png``, the section
    rotated ``webs`` times). ``interfaces`` (the analysis model's, whose first blocks are
    the scene's) hide the faces they cover. ``title`` is the line under each figure's
    own. Each figure is written in the formats of ``render`` (``<view>/<stage>.png``,
    ``.svg``, ``.pdf``); a figure left out maps to the reason (str) instead of its bytes."""
    blocks = scene.blocks
    out = {}
    if not scene.symmetry.unit and (blocks.block_class == PATTERN).any():
        out["*/1_boundaries.png"] = ("one web's outline in the frame of the whole "
                                     "structure: the section's figure shows it")
    hidden = hidden_faces(blocks, interfaces)
    for view in views_of(blocks.bounds, fast):
        # the stages of a view one after the other on one figure: axes, ticks and the
        # outline made once
        fig, ax = view_axes(blocks.bounds, view)
        draw_outline(ax, view, scene)
        for stage, mask in _stages(scene).items():
            handles, drawn = _draw_blocks(ax, view, blocks, mask, hidden)
            legend = legend_below(fig, ax, handles)
            count = int((mask & ~blocks.block_is_support).sum())
            shown = (f"{count} {scene.kind.block_word}" if mask.any()
                     else "the web's outline (dashed), before any brick is laid")
            ax.set_title(f"{stage[2:]}: {shown}\n{title}", fontsize=9)
            out.update(as_files(f"{view}/{stage}.png", figure_files(
                fig, 60 if fast else 110, render, close=False)))
            for artist in (drawn, legend):
                if artist is not None:
                    artist.remove()
        plt.close(fig)
    if webs:
        out.update(as_files("05_dome/3_structure.png", _whole_dome_png(
            blocks, interfaces, webs, fast, title, render)))
    return out


def _whole_dome_png(blocks, interfaces, n, fast, title, render) -> dict:
    """The section's bricks rotated ``n`` times in the 3D view, the faces that touch the
    next web (its boundary interfaces) hidden too."""
    bricks = ~np.asarray(blocks.block_is_support, bool)
    whole = concatenate([rotated_web(blocks, k, n, bricks) for k in range(n)])
    hidden = np.tile(hidden_faces(blocks, interfaces, images=True)[bricks[blocks.face_block]],
                     n)
    fig, ax = axes_3d(whole.bounds)
    handles, _ = _draw_blocks(ax, "01_angle", whole, np.ones(whole.n_blocks, bool), hidden,
                              linewidth=0.05)
    legend_below(fig, ax, handles)
    ax.set_title(f"the whole dome: the section rotated {n} times, {whole.n_blocks} "
                 f"bricks\n{title}", fontsize=9)
    return figure_files(fig, 70 if fast else 130, render)
