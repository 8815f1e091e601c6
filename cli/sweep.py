"""``masonry sweep STUDY.toml``: a parameter study, serially or on a Dask cluster."""

import logging
import sys
from contextlib import contextmanager
from pathlib import Path

from masonry.errors import ParameterError
from masonry.optional import optional_import
from masonry.runfolder import check_output_root, check_study_folder
from masonry.studies.study_file import load_study

from .options import add_verbosity

log = logging.getLogger("masonry")


NAME = "sweep"
HELP = "a parameter study: every variant an ordinary run, on Dask workers"
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    parser.add_argument("study", metavar="STUDY.toml",
                        help="[base] fixed inputs, [grid] lists, optional [sample] ranges "
                             "with count and seed; inputs named as 'masonry run' options")
    add_cluster_options(parser)
    parser.set_defaults(handler=handle)


def add_cluster_options(parser):
    """Where the variants run and go: ``--workers``, ``--scheduler``, ``--out``, and the
    verbosity options (sweeps and optimisations)."""
    parser.add_argument("--workers", type=int, default=None,
                        help="local Dask worker processes; 1 runs serially without Dask. "
                             "Default: serially when the variants are few or small (their "
                             "estimated blocks add up to fewer than 5,000), else one per "
                             "core")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786 (its "
                             "workers must reach --out)")
    parser.add_argument("--out", default="exports", metavar="DIR",
                        help="output root of the variants' run folders and of the "
                             "study's folder (default exports)")
    add_verbosity(parser)


def check_workers(args):
    """Refuse ``--workers`` below 1."""
    if args.workers is not None and args.workers < 1:
        raise ParameterError("workers", args.workers, "an integer >= 1")


def resolve_cluster(args, bricks):
    """``(workers, scheduler)`` from ``--workers`` and ``--scheduler``, checked; without
    either, serially or one worker per core as the study's estimated blocks say
    (``bricks()``, one per variant: :func:`masonry.studies.workers.local_workers`); serially
    (1, None), with a warning, when Dask is not installed. Dask loads here: call it once
    the study is read.

    Raises
    ------
    ParameterError
        For ``--workers`` below 1 or a scheduler address Dask cannot parse.
    """
    from masonry.studies.workers import local_workers

    check_workers(args)
    workers, scheduler = args.workers, args.scheduler
    if workers is None:
        workers = 1 if scheduler else local_workers(bricks())
    if (workers > 1 or scheduler) and optional_import("dask.distributed") is None:
        log.warning("Dask is not installed: running serially. For workers or a "
                    "cluster: pip install 'masonry[dask]'")
        return 1, None
    if scheduler is not None:
        from masonry.studies.sweep import check_scheduler_address

        check_scheduler_address(scheduler)
    logging.getLogger("distributed").setLevel(logging.ERROR)  # cluster start and stop
    return workers, scheduler


def progress_bar(done, total, failed):
    """One line on stderr, redrawn: the variants done of ``total``, and failed ones."""
    width = 30
    filled = int(width * done / max(total, 1))
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total}"
                     f"{f', {failed} failed' if failed else ''}")
    sys.stderr.flush()


@contextmanager
def quiet_progress(show: bool):
    """While ``show`` (a progress bar on a terminal), the variants' stage lines are off:
    the bar replaces them (warnings still show; --verbose shows the lines instead)."""
    library = logging.getLogger("masonry")
    level = library.level
    if show:
        library.setLevel(logging.WARNING)
    try:
        yield
    finally:
        library.setLevel(level)


def handle(args, report):
    check_workers(args)
    check_output_root(args.out)
    study = load_study(args.study)
    from masonry.studies.sweep import execute, publish_summary, summary_rows
    from masonry.studies.workers import estimated_bricks

    stem = Path(args.study).stem
    check_study_folder(args.out, f"sweep_{stem}", args.study)
    variants = study.variants()  # validates the study before any run
    total = len(variants)
    workers, scheduler = resolve_cluster(
        args, lambda: [estimated_bricks(inputs) for inputs in variants])
    show = sys.stderr.isatty() and not args.quiet and not args.verbose
    results, failed = [], 0
    with quiet_progress(show):
        try:
            for i, inputs, row in execute(study, args.out, workers, scheduler):
                results.append((i, inputs, row))
                failed += row["status"] == "failed"
                if show:
                    progress_bar(len(results), total, failed)
        finally:
            if show:
                sys.stderr.write("\n")
    rows = summary_rows(study, results)
    record = publish_summary(study, rows, args.out, f"sweep_{stem}", stem, args.study)
    counts = record["variants"]
    report(f"{total} variants: {counts['computed']} computed, {counts['reused']} reused, "
           f"{counts['failed']} failed")
    report(f"summary: {record['path']}")
    return 3 if counts["failed"] else 0
