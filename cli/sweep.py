"""``masonry sweep STUDY.toml``: a parameter study, serially or on a Dask cluster."""

import logging
import math
import os
import sys
from pathlib import Path

from masonry.errors import ParameterError
from masonry.parameters import read_toml
from masonry.params import PRESETS, Params, validate
from masonry.runfolder import check_output_root
from masonry.studies.sweep import Study, execute, publish_summary, summary_rows

from . import run as run_command
from .options import Parser, add_verbosity

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
                        help="output root of the variants' run folders and of "
                             "sweep_<study>/ with the summary (default exports)")
    add_verbosity(parser)
    parser.set_defaults(handler=handle)


def run_option_names() -> dict:
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


TABLES = ("base", "grid", "sample", "outputs")
MAX_VARIANTS = 100_000
"""Largest study (grid points times samples): a study file asking for more is refused."""


def load_study(path) -> Study:
    """Read a study file; names are 'masonry run' options without their dashes.

    Raises
    ------
    ParameterError
        Named ``study`` when the file cannot be read or is not TOML, else named after the
        table and key at fault (``grid.mu``), with the file as ``where``.
    """
    data = read_toml(path, "study")
    where = str(path)

    def refuse(key, value, expected):
        raise ParameterError(key, value, expected, where=where)

    for key, value in data.items():
        if key not in TABLES:
            refuse(key, value, f"one of the tables [{'], ['.join(TABLES)}]")
        if not isinstance(value, dict):
            refuse(key, value, f"a table [{key}]")
    base, grid = dict(data.get("base", {})), dict(data.get("grid", {}))
    sample, outputs = dict(data.get("sample", {})), data.get("outputs", {})
    preset = base.pop("preset", None)
    if preset is not None and str(preset) not in PRESETS:
        refuse("base.preset", preset, f"one of {', '.join(PRESETS)}")
    count, seed = sample.pop("count", 0), sample.pop("seed", 0)
    for key, value, ok, expected in (
            ("sample.count", count, isinstance(count, int) and not isinstance(count, bool)
             and 0 <= count <= MAX_VARIANTS, f"an integer 1 to {MAX_VARIANTS}"),
            ("sample.seed", seed, isinstance(seed, int) and not isinstance(seed, bool),
             "an integer")):
        if not ok:
            refuse(key, value, expected)
    for key, value in outputs.items():
        if key not in ("plots", "printable", "html") or not isinstance(value, bool):
            refuse(f"outputs.{key}", value, "plots, printable or html = true or false")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            refuse(f"grid.{key}", values, "a non-empty list of values")
    for key, bounds in sample.items():
        if not (isinstance(bounds, list) and len(bounds) == 2
                and all(isinstance(b, (int, float)) and not isinstance(b, bool)
                        for b in bounds) and bounds[0] <= bounds[1]):
            refuse(f"sample.{key}", bounds, "[low, high], two numbers with low <= high")
    if sample and count < 1:
        refuse("sample.count", count, f"an integer 1 to {MAX_VARIANTS}")
    size = math.prod(len(v) for v in grid.values()) * max(count, 1)
    if size > MAX_VARIANTS:
        refuse("grid", f"{size} variants", f"at most {MAX_VARIANTS} variants")
    names = run_option_names()
    study = Study(
        base={**(PRESETS[str(preset)] if preset is not None else {}),
              **_fields(base, "base", names, where)},
        grid=_fields(grid, "grid", names, where, lists=True),
        sample=_fields(sample, "sample", names, where), count=count, seed=seed,
        plots=outputs.get("plots", False), printable=outputs.get("printable", False),
        html=outputs.get("html", False))
    _check_variants(study, where)
    return study


def _check_variants(study: Study, where):
    """Every variant's inputs checked as ``masonry run`` checks them, before any runs: a
    value out of range names the table and key it came from (of the inputs the check
    involves, a swept one first; one the study leaves at its default says so)."""
    for inputs in study.variants():
        try:
            validate(Params.of(**inputs))
        except ParameterError as error:
            names = (error.name, *error.related)
            table, name = next(((t, n) for t in ("grid", "sample", "base") for n in names
                                if n in getattr(study, t)), (None, error.name))
            key = name.replace("_", "-")
            raise ParameterError(f"{table}.{key}" if table else f"{key} (the default)",
                                 inputs.get(name, error.value), error.expected,
                                 where=where) from None


def _fields(table, name, names, where, lists=False) -> dict:
    """A study table's 'masonry run' option names -> Params fields (``dome`` is the
    boundary: true is cyclic); ``lists``: the values are lists of values."""
    out = {}
    for key, value in table.items():
        if key not in names:
            raise ParameterError(f"{name}.{key}", value, "a 'masonry run' option (without "
                                 "its dashes)", where=where)
        dest = names[key]
        if dest == "dome":
            def boundary(flag):
                if not isinstance(flag, bool):
                    raise ParameterError(f"{name}.{key}", value, "true or false", where=where)
                return "cyclic" if flag else "free"
            dest, value = "boundary", [boundary(v) for v in value] if lists else boundary(value)
        out[dest] = value
    return out


def _progress(done, total, failed):
    width = 30
    filled = int(width * done / max(total, 1))
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total}"
                     f"{f', {failed} failed' if failed else ''}")
    sys.stderr.flush()


def handle(args, report):
    workers, scheduler = args.workers, args.scheduler
    if workers < 1:
        raise ParameterError("workers", workers, "an integer >= 1")
    check_output_root(args.out)
    study = load_study(args.study)
    total = len(study.variants())  # validates the study before any run
    if workers > 1 or scheduler:
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            log.warning("Dask is not installed: running serially. For workers or a "
                        "cluster: pip install 'masonry[dask]'")
            workers, scheduler = 1, None
    logging.getLogger("distributed").setLevel(logging.ERROR)  # cluster start and stop
    # one display: on a terminal the bar replaces the variants' stage lines (warnings
    # still show); --verbose shows the lines instead
    show = sys.stderr.isatty() and not args.quiet and not args.verbose
    results, failed = [], 0
    library = logging.getLogger("masonry")
    level = library.level
    if show:
        library.setLevel(logging.WARNING)
    try:
        for i, inputs, row in execute(study, args.out, workers, scheduler):
            results.append((i, inputs, row))
            failed += row["status"] == "failed"
            if show:
                _progress(len(results), total, failed)
    finally:
        library.setLevel(level)
        if show:
            sys.stderr.write("\n")
    rows = summary_rows(study, results)
    stem = Path(args.study).stem
    record = publish_summary(study, rows, args.out, f"sweep_{stem}", stem)
    counts = record["variants"]
    report(f"{total} variants: {counts['computed']} computed, {counts['reused']} reused, "
           f"{counts['failed']} failed")
    report(f"summary: {record['path']}")
    return 3 if counts["failed"] else 0
