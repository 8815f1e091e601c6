"""Interfaces drawn as polygons coloured by one value each: their area (thesis figures
3.12-3.13), the forces they carry (figures 4.1-4.8) and the adhesion they use
(docs/model.md 6.12), in the views of the model's
extent; for a cyclic section also the whole dome, the section's forces rotated into
every web. A force no interface carries beyond the solver's noise, or a value the same
on every interface (one colour), has no figure: the returned dict maps it to the reason
instead."""

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import Normalize
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from masonry.blocks import concatenate, rotated_web, rotation_z
from masonry.plots.colours import (EMPHASIS, NO_ADHESION, SEQUENTIAL, colour_bar,
                                   colour_scale, one_value)
from masonry.plots.common import (ELEVATIONS, HORIZONTAL_KINDS, NO_FILL, PNG, add_points,
                                  add_polygons, as_files, axes_3d, figure_files,
                                  legend_below, recolour, view_axes, views_of,
                                  visible_faces)
from masonry.plots.faces import face_array, interface_array
from masonry.tolerances import ADHESION_REPORTED_REL


def _interface_linewidth(count: int) -> float:
    """Edge width of interface polygons: wide for a few (seen edge on they are lines),
    thin for thousands (wide edges would cover their faces)."""
    return float(np.clip(12.0 / np.sqrt(max(count, 1)), 0.3, 3.0))


class _ViewFigures:
    """The colour plots of one view, drawn one after the other on one figure: the axes,
    their ticks and the colour bar are made once, and a plot of the same polygons as the
    one before only recolours them (a fifth to a third of each figure's time)."""

    def __init__(self, bounds, view, fast, render):
        self.fig, self.ax = view_axes(bounds, view)
        self.view, self.dpi, self.render = view, 60 if fast else 110, render
        self.polygons = self.collection = self.bar = None

    def png(self, polygons, values, title, quantity, signed=False, is_force=True,
            subtitle="", unit="") -> dict:
        """The interfaces ``polygons`` ((n, m, 3), :func:`interface_array`) coloured by
        ``values`` (SI units, or ``unit`` for values that are not forces): its files by
        format (:func:`~masonry.plots.common.figure_files`)."""
        scale = colour_scale(values, signed, is_force, unit)
        colours = scale["cmap"](scale["norm"](np.asarray(values, dtype=float)
                                              * scale["factor"]))
        if polygons is self.polygons:
            recolour(self.collection, colours)
        else:
            if self.collection is not None:
                self.collection.remove()
            # edges in the face colour: interfaces seen edge on stay visible as lines
            self.collection = add_polygons(self.ax, self.view, polygons, colours,
                                           linewidths=_interface_linewidth(len(polygons)))
            self.polygons = polygons
        self.bar = colour_bar(self.fig, self.ax, scale, quantity, self.bar)
        self.ax.set_title(f"{title} ({len(polygons)} interfaces)\n{subtitle}", fontsize=9)
        return figure_files(self.fig, self.dpi, self.render, close=False)

    def __enter__(self):
        return self

    def __exit__(self, *exception):
        plt.close(self.fig)
        return False


def _groups(interfaces) -> dict:
    """{selection: interface ids}: bed joints with the supports, head joints, all."""
    horizontal = np.isin(interfaces.kind, HORIZONTAL_KINDS)
    return {"horizontal": np.flatnonzero(horizontal), "vertical": np.flatnonzero(~horizontal),
            "all": np.arange(len(interfaces))}


def interface_pngs(blocks, interfaces, fast=False, title="", render=PNG) -> dict:
    """Horizontal and vertical interfaces drawn as polygons (thesis figures 3.12-3.13),
    coloured by area; a group without interfaces has no plot, one whose interfaces all
    have the same area (one colour: an arch's joints) maps ``*/<name>.png`` to the reason
    instead. ``title`` is the line under each figure's own; each figure in the formats
    of ``render``."""
    out = {}
    groups = {f"interfaces_{name}": index
              for name, index in list(_groups(interfaces).items())[:2] if len(index)}
    for name, index in list(groups.items()):
        same = one_value(interfaces.area[index])
        if same is not None:  # one colour: the structure's figures show where they are
            out[f"*/{name}.png"] = (f"{name.replace('_', ' ')}: nothing to show: every one "
                                    f"has the same area, {same * 1e4:.4g} cm^2")
            del groups[name]
    polygons = {name: interface_array(interfaces, index) for name, index in groups.items()}
    for view in views_of(blocks.bounds, fast):
        with _ViewFigures(blocks.bounds, view, fast, render) as figures:
            for name, index in groups.items():
                out.update(as_files(f"{view}/{name}.png", figures.png(
                    polygons[name], interfaces.area[index] * 1e4, name.replace("_", " "),
                    "area", is_force=False, subtitle=title, unit="cm^2")))
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


def _noise(values, noise) -> str | None:
    """Why ``values`` (N) make no figure: every one within ``noise`` N of zero (the
    solver's rounding, or none at all), or every one the same (one colour,
    :func:`~masonry.plots.colours.one_value`); None when they show something."""
    largest = float(np.abs(values).max(initial=0.0))
    if largest <= noise:
        return (f"nothing to show: the largest is {largest:.2g} N, within the solver's "
                f"noise ({noise:.2g} N)")
    same = one_value(values)
    if same is not None:
        return f"nothing to show: every one is {same:.4g} N"
    return None


def force_pngs(blocks, interfaces, forces: dict, fast=False, title="", webs=None,
               noise=0.0, render=PNG) -> dict:
    """Force plots (sums over each interface's vertices), per view of the model's extent
    (``<view>/<name>.png``); with ``webs`` (a section that stands for the whole dome of
    ``webs`` webs) also the whole dome (``05_dome/<name>.png``). A selection without
    interfaces has no plot; one whose forces all lie within ``noise`` newtons of zero
    maps ``*/<name>.png`` to the reason instead. ``title`` is the line under each
    figure's own; each figure in the formats of ``render``."""
    select = _groups(interfaces)
    out, drawn = {}, []
    for name, key, group, heading, signed in FORCE_PLOTS:
        values = np.asarray(forces[key], dtype=float)[select[group]]
        if len(values):
            reason = _noise(values, noise)
            if reason is None:
                drawn.append((name, key, interface_array(interfaces, select[group]), values,
                              heading, signed))
            else:
                out[f"*/{name}.png"] = f"{heading}: {reason}"
    for view in views_of(blocks.bounds, fast):
        with _ViewFigures(blocks.bounds, view, fast, render) as figures:
            for name, key, polygons, values, heading, signed in drawn:
                out.update(as_files(f"{view}/{name}.png", figures.png(
                    polygons, values, heading, FORCE_LABELS[key], signed, subtitle=title)))
    if webs:
        out.update(_whole_dome_pngs(blocks, interfaces, forces, fast, title, webs, noise,
                                    render))
    return out


def _whole_dome_pngs(blocks, interfaces, forces, fast, title, n, noise, render) -> dict:
    """Normal force and tension on the whole dome: the section's interfaces (its boundary
    interfaces with the next web included) rotated ``n`` times, each copy with the
    section's forces (exact under the cyclic symmetry of docs/model.md 6.4); tension within
    ``noise`` has no figure."""
    section = interface_array(interfaces, np.arange(len(interfaces)))
    polygons = np.concatenate([section @ rotation_z(2 * np.pi * w / n).T for w in range(n)])
    whole = concatenate([rotated_web(blocks, w, n) for w in range(n)])
    out = {}
    for name, heading, signed in (("normal", "normal force (tension +)", True),
                                  ("tension", "tension", False)):
        values = np.tile(np.asarray(forces[name], dtype=float), n)
        reason = _noise(values, noise)
        if reason is not None:
            out[f"05_dome/{name}.png"] = f"{heading}: {reason}"
            continue
        fig, ax = axes_3d(whole.bounds)
        scale = colour_scale(values, signed)
        colours = scale["cmap"](scale["norm"](values * scale["factor"]))
        add_polygons(ax, "01_angle", polygons, colours, linewidths=0.2)
        colour_bar(fig, ax, scale, FORCE_LABELS[name])
        ax.set_title(f"the whole dome ({n} webs by rotation): {heading}\n"
                     f"{title}", fontsize=9)
        out.update(as_files(f"05_dome/{name}.png", figure_files(fig, 70 if fast else 130,
                                                                render)))
    return out


RINGED_JOINTS = (30, 0.05)
"""When at most this many joints use adhesion, and at most this fraction of them,
:func:`adhesion_pngs` rings each (:data:`~masonry.plots.colours.EMPHASIS`): a few joints
among thousands show at any scale (where many use it, they show themselves)."""


def adhesion_pngs(blocks, interfaces, used_kPa, a_kPa, fast=False, title="",
                  render=PNG, drawn=None) -> dict:
    """The interfaces coloured by the adhesion each uses at the least adhesion's optimum
    (docs/model.md 6.12), kPa, on the magnitude map from 0 to the largest (the joint
    that uses most in the map's top colour; no percentile: the largest is the point);
    those that use at most :data:`~masonry.tolerances.ADHESION_REPORTED_REL` of ``a_kPa``
    (the joints dry friction holds) light grey (:data:`~masonry.plots.colours.NO_ADHESION`),
    under the others; a few joints that use it ringed too (:data:`RINGED_JOINTS`).
    ``<view>.png`` per view of the model's extent, in the formats of ``render``.

    Parameters
    ----------
    blocks, interfaces : the analysed model's
    used_kPa : (K,) float
        :attr:`~masonry.rbe.adhesion.AdhesionResult.interface_kPa`.
    a_kPa : float
        ``a*`` > 0.
    drawn : (B,) bool, optional
        The blocks outlined (default all; a construction stage's laid ones), faintly.
    """
    used = np.asarray(used_kPa, dtype=float)
    needs = used > ADHESION_REPORTED_REL * a_kPa
    top = float(used.max())
    scale = {"factor": 1.0, "unit": "kPa", "norm": Normalize(0.0, top),
             "cmap": matplotlib.colormaps[SEQUENTIAL], "extend": "neither", "above": 0,
             "below": 0, "largest": top}
    polygons = interface_array(interfaces, np.arange(len(interfaces)))
    width = _interface_linewidth(len(polygons))
    out = {}
    for view in views_of(blocks.bounds, fast):
        fig, ax = view_axes(blocks.bounds, view)
        if view not in ELEVATIONS:
            ax.computed_zorder = False  # in the order below: the joints that use it on top
        # the blocks' outlines, faint: where the joints are in the structure
        faces = visible_faces(blocks, np.ones(blocks.n_blocks, bool) if drawn is None
                              else drawn, view)
        add_polygons(ax, view, face_array(blocks, faces), NO_FILL, edgecolors="0.7",
                     linewidths=0.2)
        handles = []
        if not needs.all():
            add_polygons(ax, view, polygons[~needs], NO_ADHESION, linewidths=width)
            handles.append(Patch(facecolor=NO_ADHESION, label="no adhesion: dry friction "
                                                              "holds the joint"))
        add_polygons(ax, view, polygons[needs], scale["cmap"](scale["norm"](used[needs])),
                     linewidths=width)
        if needs.sum() <= min(RINGED_JOINTS[0], RINGED_JOINTS[1] * len(used)):
            add_points(ax, view, interfaces.centre[needs], s=160, facecolors="none",
                       edgecolors=EMPHASIS, linewidths=1.2)
            handles.append(Line2D([], [], color=EMPHASIS, marker="o", markersize=9,
                                  fillstyle="none", linestyle="none",
                                  label="uses adhesion (ringed)"))
        colour_bar(fig, ax, scale, "adhesion the joint uses")
        legend_below(fig, ax, handles)
        ax.set_title(f"joints coloured by the adhesion they use: a* = {a_kPa:.4g} kPa, "
                     f"{int(needs.sum())} of {len(used)} joints use it\n{title}",
                     fontsize=9)
        out.update(as_files(f"{view}.png", figure_files(fig, 60 if fast else 110, render)))
    return out
