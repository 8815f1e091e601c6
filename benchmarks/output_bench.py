"""The exporters, measured: each one's time on the thesis structures (``masonry bench
--outputs``: the cyclic section of ``masonry run --dome`` and the full dome), the figures
among them.

Every structure is built and solved once (the balanced preset); then each exporter of
:data:`masonry.export.EXPORTERS` that a run of it writes makes its files (in memory,
nothing written) ``repeats`` times, in this process, one after the other. A run shares
its exporters between two processes (:func:`masonry.pipeline.write_exports`), so it
takes about half the sum of these rows.
"""

import statistics
import time

from masonry.export import EXPORTERS, RunOutputs
from masonry.params import structure_id
from masonry.pipeline import Timer, build_model, solve

OUTPUT_COLUMNS = ("structure", "bricks", "exporter", "stage", "files", "seconds",
                  "cpu_seconds")
"""Columns of an output bench row: ``seconds`` (wall) and ``cpu_seconds`` (this process's
CPU time, which other processes on a shared machine move less) are medians over the
repeats, ``files`` how many files the exporter made."""


def output_bench(structures: dict, repeats=1, progress=None) -> list:
    """Time every exporter a run of each structure writes.

    Parameters
    ----------
    structures : dict str -> Params
        Name -> inputs (their ``outputs`` choose the exporters, as in a run).
    repeats : int
        Makes per exporter; times are medians.
    progress : callable(str), optional
        Called with a line per row.

    Returns
    -------
    list of dict
        Keys :data:`OUTPUT_COLUMNS`.
    """
    rows = []
    for name, params in structures.items():
        scene, model = build_model(params)
        made = RunOutputs(params, scene, model, solve(model, params, Timer()),
                          title=structure_id(params))
        bricks = int((~scene.blocks.block_is_support).sum())
        for exporter in (e for e in EXPORTERS if e.wanted(made)):
            seconds, cpu = [], []
            for _ in range(repeats):
                start, start_cpu = time.perf_counter(), time.process_time()
                export = exporter.make(made)
                seconds.append(time.perf_counter() - start)
                cpu.append(time.process_time() - start_cpu)
            rows.append({"structure": name, "bricks": bricks, "exporter": exporter.name,
                         "stage": exporter.stage, "files": len(export.files),
                         "seconds": statistics.median(seconds),
                         "cpu_seconds": statistics.median(cpu)})
            if progress is not None:
                progress(f"{name}: {exporter.name} {rows[-1]['seconds']:.3g} s")
    return rows


def outputs_markdown(rows) -> str:
    """The rows as a Markdown table, each structure's total under its rows."""
    lines = ["| " + " | ".join(OUTPUT_COLUMNS) + " |",
             "|" + "---|" * len(OUTPUT_COLUMNS)]
    for name in dict.fromkeys(row["structure"] for row in rows):
        own = [row for row in rows if row["structure"] == name]
        lines += [f"| {r['structure']} | {r['bricks']} | {r['exporter']} | {r['stage']} | "
                  f"{r['files']} | {r['seconds']:.3g} | {r['cpu_seconds']:.3g} |"
                  for r in own]
        lines.append(f"| {name} | | all | | {sum(r['files'] for r in own)} | "
                     f"{sum(r['seconds'] for r in own):.3g} | "
                     f"{sum(r['cpu_seconds'] for r in own):.3g} |")
    return "\n".join(lines) + "\n"
