"""An optimisation's convergence: every trial's objective values, the best value so far
and the best trials; with two objectives or more also the Pareto front of the first two."""

import math

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator

from masonry.plots.common import png_bytes


def convergence_png(rows, objectives, value, title="") -> bytes:
    """The convergence figure of an optimisation's trials.

    Parameters
    ----------
    rows : list of dict
        The trials table (:func:`masonry.studies.optimize.trial_rows`): ``trial``,
        ``status``, the objective columns, ``constraints_met`` and ``best``.
    objectives : sequence of (str, str)
        ``(column, "maximize" | "minimize")``.
    value : callable
        ``value(row, column)``: the column's value as a number, None when it has none,
        infinity for "never" (:func:`masonry.studies.sweep.measure`; drawn above the
        others).
    title : str

    Returns
    -------
    bytes
        PNG: one panel per objective (trials that meet the constraints as dots, the
        others as grey crosses, the best so far as a step line, the best trials as
        stars), then the Pareto front of the first two objectives when there are two or
        more. Failed trials are counted in the title.
    """
    pareto = len(objectives) >= 2
    fig, axes = plt.subplots(len(objectives) + pareto, 1, squeeze=False,
                             figsize=(6.5, 2.6 * (len(objectives) + pareto)))
    axes = axes[:, 0]
    for ax, (column, direction) in zip(axes, objectives):
        points = [(r["trial"], value(r, column), r["constraints_met"], r["best"])
                  for r in rows if value(r, column) is not None]
        # infinite (no stage needs support): drawn above the largest finite value
        finite = [v for _, v, _, _ in points if math.isfinite(v)]
        top = max(finite, default=0.0) + 0.1 * (np.ptp(finite) if finite else 0.0) + 1.0
        if len(finite) < len(points):
            ax.axhline(top, color="0.8", linewidth=0.8, linestyle=":")
            ax.annotate("every stage stands", (0, top), fontsize=7, color="0.4",
                        xytext=(2, 2), textcoords="offset points")
        points = [(t, v if math.isfinite(v) else top, ok, b) for t, v, ok, b in points]
        met = np.array([(t, v) for t, v, ok, _ in points if ok]).reshape(-1, 2)
        other = np.array([(t, v) for t, v, ok, _ in points if not ok]).reshape(-1, 2)
        best = np.array([(t, v) for t, v, _, b in points if b]).reshape(-1, 2)
        ax.plot(*met.T, "o", color="C0", markersize=4, label="trial")
        if len(other):
            ax.plot(*other.T, "x", color="0.6", markersize=5, label="constraints not met")
        if len(met) and not pareto:
            running = (np.maximum if direction == "maximize" else np.minimum).accumulate(
                met[:, 1])
            ax.step(met[:, 0], running, where="post", color="C1", linewidth=1.2,
                    label="best so far")
        if len(best):
            ax.plot(*best.T, "*", color="C3", markersize=12, label="best")
        ax.set_ylabel(f"{column}\n({direction.replace('ize', 'ized')})", fontsize=8)
        ax.set_xlabel("trial")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.legend(fontsize=7, frameon=False)
    if pareto:
        _pareto(axes[-1], rows, objectives[:2], value)
    failed = sum(r.get("status") == "failed" for r in rows)
    best = [r for r in rows if r["best"]]
    found = (f"; best {objectives[0][0]} {value(best[0], objectives[0][0]):.4g} at trial "
             f"{best[0]['trial']}" if len(best) == 1 and not pareto else
             f"; {len(best)} on the Pareto front" if best else "")
    axes[0].set_title(f"{title + ': ' if title else ''}{len(rows)} trials"
                      f"{f' ({failed} failed)' if failed else ''}{found}", fontsize=9)
    fig.tight_layout()
    return png_bytes(fig, 100)


def _pareto(ax, rows, objectives, value):
    """The first two objectives of every trial that meets the constraints, the best ones
    (the Pareto front) joined in order of the first."""
    (a, _), (b, _) = objectives
    done = [r for r in rows if r["constraints_met"] and value(r, a) is not None
            and value(r, b) is not None]
    ax.plot([value(r, a) for r in done], [value(r, b) for r in done], "o", color="0.6",
            markersize=4, label="trial")
    front = sorted((value(r, a), value(r, b)) for r in done if r["best"])
    if front:
        ax.plot(*zip(*front), "*-", color="C3", markersize=10, linewidth=1,
                label="Pareto front")
    ax.set_xlabel(a)
    ax.set_ylabel(b)
    ax.legend(fontsize=7, frameon=False)
