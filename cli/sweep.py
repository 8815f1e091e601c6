"""``masonry sweep STUDY.toml``: a parameter study, serially or on a Dask cluster."""

import logging
import os
import sys
import tomllib
from pathlib import Path

from masonry.params import PRESETS, ParameterError
from masonry.runfolder import RunFolder
from masonry.studies.sweep import (Study, execute, summary_csv, summary_parquet, summary_pngs,
                           summary_rows)

from . import run as run_command
from .options import Parser

log = logging.getLogger("masonry")


def register(subparsers):
    parser = subparsers.add_parser(
        "sweep", help="a parameter study: every variant an ordinary run, on Dask workers")
    parser.add_argument("study", metavar="STUDY.toml",
                        help="[base] fixed inputs, [grid] lists, optional [sample] ranges "
                             "with count and seed; inputs named as 'masonry run' options")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                        help="local Dask worker processes (default: one per core); 1 runs "
                             "serially without Dask")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786")
    parser.add_argument("--out", default="exports", metavar="DIR",
                        help="output root of the variants' run folders and the summary")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(handler=handle)


def option_names() -> dict:
    """``masonry run``'s long option names (dashes or underscores) -> Params fields."""
    parser = Parser(prog="masonry")
    run_command.register(parser.add_subparsers())
    run_parser = parser._subparsers._group_actions[0].choices["run"]
    names = {}
    for action in run_parser._actions:
        for option in action.option_strings:
            if option.startswith("--"):
                long = option[2:]
                names[long] = names[long.replace("-", "_")] = action.dest
    return names


def load_study(path) -> Study:
    """Read a study file; names are 'masonry run' options without their dashes."""
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as error:
        raise ParameterError("study", str(path), f"a readable TOML file ({error.strerror})")
    except tomllib.TOMLDecodeError as error:
        raise ParameterError("study", str(path), f"valid TOML ({error})")
    names = option_names()

    def fields(table, where):
        out = {}
        for key, value in table.items():
            if key not in names:
                raise ParameterError(f"{where}.{key}", value, "a 'masonry run' option")
            dest = names[key]
            if dest == "dome":  # --dome: cyclic boundary
                dest, value = "boundary", "cyclic" if value else "free"
            out[dest] = value
        return out

    base = dict(data.get("base", {}))
    preset = base.pop("preset", None)
    if preset is not None and str(preset) not in PRESETS:
        raise ParameterError("base.preset", preset, f"one of {', '.join(PRESETS)}")
    sample = dict(data.get("sample", {}))
    count, seed = sample.pop("count", 0), sample.pop("seed", 0)
    outputs = data.get("outputs", {})
    return Study(
        base={**(PRESETS[str(preset)] if preset is not None else {}), **fields(base, "base")},
        grid=fields(data.get("grid", {}), "grid"),
        sample=fields(sample, "sample"), count=count, seed=seed,
        plots=bool(outputs.get("plots", False)),
        printable=bool(outputs.get("printable", False)))


def _progress(done, total, failed):
    width = 30
    filled = int(width * done / max(total, 1))
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total}"
                     f"{f', {failed} failed' if failed else ''}")
    sys.stderr.flush()


def handle(args, report):
    study = load_study(args.study)
    total = len(study.variants())  # validates the study before any run
    workers, scheduler = args.workers, args.scheduler
    if workers < 1:
        raise ParameterError("workers", workers, "an integer >= 1")
    if workers > 1 or scheduler:
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            log.warning("Dask is not installed: running serially. For workers or a "
                        "cluster: pip install 'masonry[dask]'")
            workers, scheduler = 1, None
    logging.getLogger("distributed").setLevel(logging.ERROR)  # cluster start and stop
    show = sys.stderr.isatty() and not args.quiet
    results, failed = [], 0
    for i, inputs, row in execute(study, args.out, workers, scheduler):
        results.append((i, inputs, row))
        failed += row["status"] == "failed"
        if show:
            _progress(len(results), total, failed)
    if show:
        sys.stderr.write("\n")
    rows = summary_rows(study, results)
    name = f"sweep_{Path(args.study).stem}"
    with RunFolder(args.out, name) as folder:
        folder.write("summary.csv", summary_csv(study, rows))
        parquet = summary_parquet(study, rows)
        if parquet is not None:
            folder.write("summary.parquet", parquet)
        for png_name, png in summary_pngs(study, rows).items():
            folder.write(png_name, png)
    counts = {s: sum(r["status"] == s for r in rows) for s in ("computed", "reused", "failed")}
    report(f"{total} variants: {counts['computed']} computed, {counts['reused']} reused, "
           f"{counts['failed']} failed")
    report(f"summary: {folder.target}")
    return 0
