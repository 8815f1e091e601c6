"""The lateral load factor against the load's azimuth (``--lateral all``) on polar axes,
the azimuths the search refined between its samples and the least it found marked."""

import matplotlib.pyplot as plt
import numpy as np

from masonry.plots.colours import EMPHASIS
from masonry.plots.common import PNG, figure_files


def azimuths_png(collapse, title="", render=PNG) -> dict:
    """``collapse/azimuths.png``: the lateral load factor against the load's azimuth
    (``--lateral all``) on polar axes: the samples joined by a line, the azimuths
    solved between them by the refinement as dots, the least marked, the radius from a
    little below
    the smallest factor (the title says where); ``title`` is the line under the
    figure's own. Returns its files by format (of ``render``)."""
    angle = np.array([a for a, _ in collapse.azimuths])
    factor = np.array([np.nan if f is None else f for _, f in collapse.azimuths])
    order = np.argsort(angle)  # the line breaks where an azimuth has no factor
    theta = np.radians(np.append(angle[order], angle[order][0]))
    fig, ax = plt.subplots(figsize=(5.5, 5.5), subplot_kw={"projection": "polar"})
    ax.plot(theta, np.append(factor[order], factor[order][0]), "-o", color="C0",
            markersize=3, linewidth=1)
    refined = [(a, f) for a, f in collapse.refined if f is not None]
    if refined:
        ax.plot(np.radians([a for a, _ in refined]), [f for _, f in refined], ".",
                color="0.4", markersize=3, label="refined between the samples")
    worst = np.radians(collapse.azimuth_deg)
    ax.plot([worst], [collapse.load_factor], "o", color=EMPHASIS, markersize=8,
            label=f"least: {collapse.load_factor:.7g} at {collapse.azimuth_deg:.6g} deg")
    # the radius starts below the smallest factor: from 0, factors within a few per
    # cent of each other would look like a circle
    low, high = np.nanmin(factor), np.nanmax(factor)
    margin = max(0.25 * (high - low), 0.02 * high)
    start = max(0.0, low - margin)
    ax.set_ylim(start, high + 0.5 * margin)
    ax.set_rlabel_position(100)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, -0.15), fontsize=8, frameon=False)
    ax.set_title(f"lateral load factor against the load's azimuth (from +x toward +y)\n"
                 f"{'' if start == 0 else f'the radius from {start:.3g}, not 0; '}"
                 f"{title}", fontsize=9, pad=20)
    return figure_files(fig, 110, render)
