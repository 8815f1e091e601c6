"""A study's summary plots: the MoI factor and feasibility (and a live load's collapse
load factor) against each swept input, every other swept input told apart, failed
variants marked with their reason.

The other swept inputs take a channel each, in the study's order: the colour (a colour
scale with its bar for a numeric input of more than :data:`DISTINCT` values, e.g. a
sampled one), the marker, then the line style; the legend below the figure lists every
value of each. A failed variant has no result: a numbered cross at the bottom of each
panel, at its value of the input, its number that of its reason in the legend (the
``error`` of ``summary.csv``, its first line, shortened to :data:`REASON_LENGTH`
characters).
"""

import json
import textwrap
from collections import Counter

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.transforms import blended_transform_factory

from masonry.plots.colours import FAILED, SEQUENTIAL
from masonry.plots.common import PNG, as_files, figure_files

PLOTTED_LIMIT = 1e15
"""Swept values at least this large are drawn one tick per value, not on a numeric axis
(an axis spanning +-1e308 overflows matplotlib's limits)."""
DISTINCT = 8
"""An input of at most this many values gets a colour, marker or line style per value;
a numeric one of more is drawn on a colour scale, any other is not told apart (the
title says so)."""
MARKERS = "osD^vP*h"
LINE_STYLES = ("-", "--", ":", "-.")
RING_SIZES = (4.0, 2.5, 6)
"""A series' markers are open, ``4 + 2.5 (k mod 6)`` points across for the k-th series
(its first value's order): where series coincide their markers show as rings."""
REASON_LENGTH = 150
"""A failed variant's reason in the legend: its error's first line, cut to this many
characters, on lines of at most :data:`REASON_WIDTH`."""
REASON_WIDTH = 80


def _label(value) -> str:
    """A swept value as an axis tick or legend entry (any value a study file holds)."""
    return value if isinstance(value, str) else json.dumps(value)


def _is_numeric(values) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool)
               and abs(v) < PLOTTED_LIMIT for v in values)


CHANNELS = ("colour", "marker", "style")


def _channels(others, rows) -> dict:
    """Which other swept input each channel shows: ``colour``, ``marker``, ``style``
    (an input, or None), ``scale`` (a numeric input of many values on a colour scale, or
    None), ``values`` (each input's values as labels, sorted) and ``untold`` (the inputs
    no channel shows)."""
    values = {name: sorted({_label(r[name]) for r in rows}) for name in others}
    many = [name for name in others if len(values[name]) > DISTINCT]
    scale = next((name for name in many if _is_numeric([r[name] for r in rows])), None)
    few = [name for name in others if name not in many]
    chosen = dict(zip(CHANNELS[1:] if scale else CHANNELS, few))
    return {**{c: chosen.get(c) for c in CHANNELS}, "scale": scale, "values": values,
            "untold": [n for n in others if n != scale and n not in chosen.values()]}


def _channel_style(channels, channel, label) -> dict:
    """The matplotlib keywords that show ``label``, a value of ``channel``'s input."""
    labels = channels["values"][channels[channel]]
    position = labels.index(label)
    if channel == "colour":
        return {"color": plt.cm.viridis(np.linspace(0, 0.9, len(labels)))[position]}
    if channel == "marker":
        return {"marker": MARKERS[position % len(MARKERS)]}
    return {"linestyle": LINE_STYLES[position % len(LINE_STYLES)]}


def _style(channels, row) -> dict:
    """The colour, marker and line style of ``row``'s series."""
    style = {"color": "0.2", "marker": "o", "linestyle": "-"}
    for channel in CHANNELS:
        if channels[channel] is not None:
            style.update(_channel_style(channels, channel, _label(row[channels[channel]])))
    return style


def _legend_handles(channels) -> list:
    """One legend entry per value of each input a channel shows."""
    shown = {"colour": {"marker": "o", "linestyle": "none"},
             "marker": {"color": "0.2", "linestyle": "none"},
             "style": {"color": "0.2"}}
    return [Line2D([], [], markersize=5, label=f"{channels[channel]} = {label}",
                   **shown[channel], **_channel_style(channels, channel, label))
            for channel in CHANNELS if channels[channel] is not None
            for label in channels["values"][channels[channel]]]


def _reason(error) -> str:
    """A failed variant's reason: its error's first line, shortened."""
    text = (error or "").strip()
    line = text.splitlines()[0] if text else "no error recorded"
    line = line if len(line) <= REASON_LENGTH else line[:REASON_LENGTH - 3] + "..."
    return "\n".join(textwrap.wrap(line, REASON_WIDTH))


def _positions(name, rows):
    """The x position of each row's value of ``name`` and the axis's tick labels (None
    on a numeric axis)."""
    x = [r[name] for r in rows]
    if _is_numeric(x):
        return np.array(x, dtype=float), None
    labels = sorted({_label(v) for v in x})
    return np.array([labels.index(_label(v)) for v in x], dtype=float), labels


def _series(rows, channels) -> list:
    """The rows' positions grouped by series (the same colour, marker and line style)."""
    keys = [tuple(_label(r[channels[c]]) for c in CHANNELS if channels[c]) for r in rows]
    return [[i for i, k in enumerate(keys) if k == key] for key in dict.fromkeys(keys)]


def _draw_series(ax, x, y, rows, channels, joined):
    """The points ``(x, y)`` of ``rows``, a series' points joined where ``joined``
    (and its points one per x); on the colour scale of ``channels['scale']`` when it has
    one."""
    scale = channels["scale"]
    norm = None
    if scale is not None:
        values = [r[scale] for r in rows]
        norm = matplotlib.colors.Normalize(min(values), max(values))
    for k, mine in enumerate(_series(rows, channels)):
        mine = sorted(mine, key=lambda i: x[i])
        style = _style(channels, rows[mine[0]])
        if scale is not None:
            colour = matplotlib.colormaps[SEQUENTIAL](norm([rows[i][scale] for i in mine]))
            ax.scatter(x[mine], y[mine], c=colour, marker=style["marker"], s=18)
            continue
        line = style["linestyle"] if joined and len(set(x[mine])) == len(mine) else "none"
        # open markers, each series' larger than the next: series that coincide show
        # as rings around one another
        ax.plot(x[mine], y[mine], color=style["color"], marker=style["marker"],
                markerfacecolor="none", linestyle=line, linewidth=1,
                markersize=RING_SIZES[0] + RING_SIZES[1] * (k % RING_SIZES[2]))
    return norm


def _draw_failed(ax, x, numbers, y=None):
    """Numbered crosses of the failed variants at ``x``: at ``y``, or at the bottom of
    ``ax``; variants that failed at one place for one reason share a number, which says
    how many they are."""
    transform = ax.transData if y is not None else blended_transform_factory(
        ax.transData, ax.transAxes)
    y = np.zeros(len(x)) if y is None else np.full(len(x), float(y))
    ax.plot(x, y, "X", color=FAILED, markersize=7, linestyle="none", transform=transform,
            clip_on=False)
    # one number per place and reason, with how many variants failed there
    places = [(float(xi), number) for xi, number in zip(x, numbers)]
    for (xi, number), count in Counter(places).items():
        ax.annotate(f"{number}" + (f" ({count} variants)" if count > 1 else ""),
                    (xi, y[0] if len(y) else 0.0), xycoords=transform, xytext=(5, 4),
                    textcoords="offset points", fontsize=7, color=FAILED)


def _finish(fig, axes, channels, norm, reasons, title):
    """The legend below ``fig`` (every value each channel shows, each failure's
    reason), the colour scale's bar and the title on ``axes[0]``."""
    handles = _legend_handles(channels) + [
        Line2D([], [], marker="X", color=FAILED, linestyle="none", markersize=6,
               label=f"failed ({k}): {reason}") for k, reason in enumerate(reasons, 1)]
    if norm is not None:
        mappable = matplotlib.cm.ScalarMappable(norm=norm, cmap=SEQUENTIAL)
        fig.colorbar(mappable, ax=axes, shrink=0.8).set_label(channels["scale"], fontsize=8)
    if handles:
        fig.legend(handles=handles, loc="outside lower center", fontsize=7, frameon=False,
                   ncols=2 if len(handles) > 6 and not reasons else 1)
    untold = channels["untold"]
    axes[0].set_title(title + (f"\nnot told apart: {', '.join(untold)}" if untold else ""),
                      fontsize=9)


def _failed_marks(name, rows, reasons):
    """The failed rows' positions on the axis of ``name`` and their reasons' numbers."""
    failed = [r for r in rows if r["status"] == "failed"]
    return failed, [reasons.index(_reason(r.get("error"))) + 1 for r in failed]


def summary_figures(swept, rows, title, render=PNG) -> dict:
    """The MoI factor and feasibility, and a live load's collapse load factor, against
    each swept input: one figure each per input, the other inputs told apart
    (:func:`_channels`), failed variants marked with their reasons.

    Parameters
    ----------
    swept : list of str
        The study's swept inputs (the figures' x axes).
    rows : list of dict
        The summary's rows: the swept inputs, ``status``, ``error``, ``feasible``,
        ``moi_factor``, ``load_factor``.
    title : str
        Every figure's title.
    render : Render
        The figures' formats and resolution.

    Returns
    -------
    dict str -> bytes
        ``moi_factor_<input>.<format>`` and, where a variant has a load factor,
        ``load_factor_<input>.<format>``.
    """
    done = [r for r in rows if r["status"] != "failed"]
    reasons = list(dict.fromkeys(_reason(r.get("error")) for r in rows
                                 if r["status"] == "failed"))
    out = {}
    for name in swept:
        channels = _channels([o for o in swept if o != name], rows)
        positions, labels = _positions(name, rows)
        x = positions[[i for i, r in enumerate(rows) if r["status"] != "failed"]]
        failed, numbers = _failed_marks(name, rows, reasons)
        x_failed = positions[[i for i, r in enumerate(rows) if r["status"] == "failed"]]
        out.update(as_files(f"moi_factor_{name}.png", _moi_figure(
            name, done, x, labels, channels, (x_failed, numbers), reasons, title, render)))
        has_factor = [i for i, r in enumerate(done) if r.get("load_factor") is not None]
        if has_factor:
            fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
            kept = [done[i] for i in has_factor]
            norm = _draw_series(ax, x[has_factor],
                                np.array([r["load_factor"] for r in kept], float),
                                kept, channels, joined=True)
            if len(failed):
                _draw_failed(ax, x_failed, numbers)
            ax.set_ylim(bottom=0)
            ax.set_ylabel("collapse load factor lambda")
            _axis_labels(ax, name, labels)
            _finish(fig, [ax], channels, norm, reasons, title)
            out.update(as_files(f"load_factor_{name}.png", figure_files(fig, 100, render)))
    return out


def _axis_labels(ax, name, labels):
    ax.set_xlabel(name)
    if labels is not None:
        ax.set_xticks(range(len(labels)), labels)


def _moi_figure(name, done, x, labels, channels, failed, reasons, title, render):
    """The MoI factor over the feasibility strip (feasible, infeasible, failed)
    against ``name``: its files by format."""
    x_failed, numbers = failed
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.4, 6.4), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1]},
                                      layout="constrained")
    moi = np.array([np.nan if r["moi_factor"] is None else r["moi_factor"] for r in done],
                   float)
    norm = _draw_series(top, x, moi, done, channels, joined=True)
    # the series' feasibility side by side, not on top of each other
    series = _series(done, channels)
    offset = np.zeros(len(done))
    for k, mine in enumerate(series):
        offset[mine] = 0.5 * (k / (len(series) - 1) - 0.5) if len(series) > 1 else 0.0
    feasible = np.array([np.nan if r["feasible"] is None else float(bool(r["feasible"]))
                         for r in done]) + offset
    _draw_series(bottom, x, feasible, done, channels, joined=False)
    rows = [0, 1]
    if len(x_failed):
        _draw_failed(top, x_failed, numbers)
        _draw_failed(bottom, x_failed, numbers, y=-1)
        rows = [-1, 0, 1]
    top.set_ylabel("MoI factor")
    bottom.set_yticks(rows, ["failed", "infeasible", "feasible"][3 - len(rows):])
    bottom.set_ylim(rows[0] - 0.5, 1.5)  # the markers inside the strip, not cut at its edges
    _axis_labels(bottom, name, labels)
    _finish(fig, [top, bottom], channels, norm, reasons, title)
    return figure_files(fig, 100, render)
