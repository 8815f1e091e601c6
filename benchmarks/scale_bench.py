"""How time and memory grow with the bricks (``masonry bench --scale``): whole ``masonry
run`` processes of one structure at growing sizes, each in a fresh process (its own
start-up, its own peak memory), without plots or the printable body (the command line's
``--no-plots --no-printable``: what the run solves and writes), and the exponent of a
power law fitted to each column.

A row's peak memory is the largest resident set of the run's processes (the kernel's
``ru_maxrss`` of the process and the ones it forked); its times come from the run's own
``run.json`` (``timings_s``: the stages of the process that reports, and the time it
waited for the other's exports) and from the kernel (wall and CPU of the whole process).
"""

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from masonry.scenes import memory_estimate

SCALE_COLUMNS = ("structure", "bricks", "verdict", "wall_s", "cpu_s", "solve_s",
                 "newton_steps", "other_iterations", "newton_setup_s", "exports_s",
                 "peak_gib", "estimate_gib")
"""Columns of a scale row: ``solve_s`` the RBE solve (``timings_s.solve``),
``newton_steps`` and ``newton_setup_s`` its Newton attempts' iterations and symbolic
set-up summed, ``other_iterations`` its other attempts' of both friction models, in
order (the load-path LP, the interior point method, Clarabel, Newton's polish; -1 where
a solver does not say; empty where Newton alone solved), ``exports_s`` the
files after the forces (``timings_s``: ``exports``, ``html`` and the wait for the other
process), ``estimate_gib`` what ``--max-bricks``'s message says the run needs
(:func:`masonry.scenes.memory_estimate`)."""

WALLS = (50, 112, 224, 354, 500)
"""The walls' courses: ``0.4 courses`` bricks in each (``--wall-length 1.6 courses``),
about 1,000, 5,000, 20,000, 50,000 and 100,000 bricks of one shape."""

DOMES = (4, 10, 16, 21, 26)
"""Preset 1's full dome at these ``p``: 1,664 to 31,712 bricks, every one standing
(docs/scale.md: from p 27 its profile does not)."""

ARCHES = (1024, 4096, 8192, 16384)
"""A semicircular arch of 10 m span and 0.6 m thickness (the arch scene's defaults)
in this many voussoirs: one geometry at every size, where the dome's profile thins as
it grows."""

FIT_FROM = 5000
"""The exponents are fitted to the rows of at least this many bricks: below, the
start-up (imports, about a second) hides how the work grows."""


def scale_structures(walls=WALLS, domes=DOMES, arches=ARCHES) -> dict:
    """``{name: (family, preset, inputs)}`` of the default rows: the inputs as
    :func:`~masonry.params.from_preset` takes them (no preset for the arch), the command
    line's options by their names."""
    out = {}
    for courses in walls:
        length = round(1.6 * courses)
        out[f"wall {length} x {courses}"] = ("wall", "wall", {"wall_length": float(length),
                                                              "wall_courses": courses})
    for p in domes:
        out[f"preset 1 full dome, p {p}"] = ("preset 1 full dome", "1",
                                             {"scene": "dome", "p": p})
    for blocks in arches:
        out[f"arch of {blocks:,} voussoirs"] = ("arch", None, {"scene": "arch",
                                                              "blocks": blocks})
    return out


def scale_bench(structures: dict, progress=None) -> list:
    """One ``masonry run`` per structure, each in a fresh process, into a temporary
    folder (removed after).

    Parameters
    ----------
    structures : dict str -> (str, str or None, dict)
        Name -> (its family, its preset (None: none), its inputs): :func:`scale_structures`.
    progress : callable(str), optional
        Called with a line per row.

    Returns
    -------
    list of dict
        Keys :data:`SCALE_COLUMNS` and ``family``.
    """
    rows = []
    for name, (family, preset, inputs) in structures.items():
        options = [f"--{key.replace('_', '-')}={value}" for key, value in inputs.items()]
        with tempfile.TemporaryDirectory(prefix="masonry-scale-") as out:
            arguments = [*([f"--preset={preset}"] if preset else []), *options,
                         "--no-plots", "--no-printable", "--quiet", "--max-bricks=10000000",
                         f"--out={out}"]
            wall, cpu, peak, code = _run(arguments)
            written = list(Path(out).glob("*/run.json"))
            if not written:  # a run that gives no verdict still writes its run.json
                raise RuntimeError(f"masonry run {' '.join(arguments)} ended with {code} "
                                   f"and wrote no run.json")
            record = json.loads(written[0].read_text())
        rows.append({"structure": name, "family": family, "wall_s": wall, "cpu_s": cpu,
                     "peak_gib": peak, **_from_record(record)})
        if progress is not None:
            progress(f"{name}: {rows[-1]['bricks']:,} bricks, {wall:.1f} s, "
                     f"{peak:.2f} GiB")
    return rows


def _run(arguments) -> tuple:
    """``masonry run arguments`` in a fresh process: (wall s, CPU s, peak GiB, exit
    code). The peak is the largest process's (Linux's ``ru_maxrss``, in kilobytes): a
    forked process shares most of its pages with the one that forked it."""
    command = [sys.executable, "-c",
               "import sys; from masonry_cli.main import main; sys.exit(main())", "run",
               *arguments]
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    process.returncode = os.waitstatus_to_exitcode(status)
    return (wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024**2,
            process.returncode)


def _from_record(record: dict) -> dict:
    """A row's columns read from the run's ``run.json``."""
    timings = record["timings_s"]
    attempts = record["rbe"].get("attempts", [])
    newton = [a for a in attempts if a.get("solver") == "newton"]
    bricks = record["counts"]["bricks"]
    estimate = memory_estimate(bricks, record["params"]["accuracy"])
    return {"bricks": bricks, "verdict": record["rbe"]["verdict"],
            "solve_s": timings.get("solve"),
            "newton_steps": sum(a["iterations"] for a in newton),
            "other_iterations": ", ".join(f"{a['solver']} {a['iterations']}"
                                          for a in attempts if a.get("solver") != "newton"),
            "newton_setup_s": sum(a.get("setup_s", 0.0) for a in newton),
            "exports_s": sum(timings.get(k, 0.0) for k in ("exports", "html",
                                                           "other_process")),
            "estimate_gib": estimate / 2**30}


def exponent(rows, column, smallest=FIT_FROM) -> float | None:
    """The exponent ``k`` of ``column = c bricks^k`` fitted (least squares in logs) to
    the ``rows`` of at least ``smallest`` bricks with a positive value; None with fewer
    than two."""
    points = [(row["bricks"], row[column]) for row in rows
              if row["bricks"] >= smallest and (row.get(column) or 0) > 0]
    if len(points) < 2:
        return None
    x, y = np.log(np.array(points, dtype=float)).T
    return float(np.polyfit(x, y, 1)[0])


def scale_markdown(rows) -> str:
    """The rows as a table, then each family's fitted exponents."""
    from masonry_benchmarks.markdown import markdown_table

    table = markdown_table(rows, SCALE_COLUMNS, formats={
        "bricks": "{:,}", "wall_s": "{:.1f}", "cpu_s": "{:.1f}", "solve_s": "{:.2f}",
        "newton_setup_s": "{:.2f}", "exports_s": "{:.2f}", "peak_gib": "{:.2f}",
        "estimate_gib": "{:.2f}"})
    fitted = ("wall_s", "cpu_s", "solve_s", "newton_steps", "exports_s", "peak_gib")
    lines = ["| family | " + " | ".join(fitted) + " |", "|---|" + "---|" * len(fitted)]
    for family in dict.fromkeys(row["family"] for row in rows):
        of = [row for row in rows if row["family"] == family]
        values = [exponent(of, column) for column in fitted]
        lines.append(f"| {family} | " + " | ".join(
            "" if v is None or not math.isfinite(v) else f"{v:.2f}" for v in values) + " |")
    return (table + f"\nexponents k of a fit c bricks^k to the rows of at least "
            f"{FIT_FROM:,} bricks:\n\n" + "\n".join(lines) + "\n")
