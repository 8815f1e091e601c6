"""``masonry optimize STUDY.toml --maximize COLUMN | --minimize COLUMN``: the best
variant of a study's search space, found by Optuna, each trial a sweep variant."""

import argparse
import logging
import sys
from pathlib import Path

from masonry.runfolder import check_output_root, check_study_folder
from masonry.studies.optimize import SAMPLERS, Search
from masonry.studies.study_file import load_study

from .sweep import (add_cluster_options, check_workers, progress_bar, quiet_progress,
                    resolve_cluster)

log = logging.getLogger("masonry")

NAME = "optimize"
HELP = "the best variant of a study's search space (Optuna), each trial a sweep variant"
"""The subcommand's name and its line in ``masonry --help``."""


class Objective(argparse.Action):
    """``--maximize COLUMN`` / ``--minimize COLUMN``: appended in the order given to
    ``objectives`` as ``(column, direction)``, and to the option's own list."""

    def __call__(self, parser, namespace, value, option_string=None):
        direction = self.dest
        namespace.objectives = [*(getattr(namespace, "objectives", None) or []),
                                (value, direction)]
        setattr(namespace, self.dest, [*(getattr(namespace, self.dest) or []), value])


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    parser.add_argument("study", metavar="STUDY.toml",
                        help="[base] fixed inputs, [grid] lists of choices, [sample] "
                             "[low, high] ranges, optional [constraints] bounds on result "
                             "columns; as for 'masonry sweep'")
    parser.add_argument("--maximize", action=Objective, metavar="COLUMN",
                        help="a result column of the summary to maximise (repeatable, "
                             "with --minimize: several objectives, a Pareto front)")
    parser.add_argument("--minimize", action=Objective, metavar="COLUMN",
                        help="a result column of the summary to minimise (repeatable)")
    parser.add_argument("--trials", type=int, default=20,
                        help="trials to finish, those of an interrupted run included "
                             "(default 20)")
    parser.add_argument("--seed", type=int, default=None,
                        help="seeds the sampler (default: the study's [sample] seed, else 0)")
    parser.add_argument("--batch", type=int, default=4,
                        help="trials asked at once and run side by side; the trials depend "
                             "on it, not on the workers (default 4)")
    parser.add_argument("--sampler", choices=SAMPLERS, default="tpe",
                        help="tpe: Optuna's tree-structured Parzen estimator (default); "
                             "random: random search")
    parser.add_argument("--no-plots", action="store_true",
                        help="skip the best variants' plots (the convergence plot is "
                             "always drawn)")
    add_cluster_options(parser)
    parser.set_defaults(handler=handle, objectives=[])


def handle(args, report):
    check_workers(args)
    check_output_root(args.out)
    study = load_study(args.study, draws=False)
    seed = args.seed if args.seed is not None else study.seed
    search = Search(study, tuple(args.objectives), args.trials, seed, args.batch,
                    args.sampler).checked()
    workers, scheduler = resolve_cluster(args, search.estimated_bricks)
    from masonry.studies.optimize import draw_best, optimise, publish_trials
    stem = Path(args.study).stem
    check_study_folder(args.out, f"optimize_{stem}", args.study)
    out = Path(args.out)
    journal = out / f"optimize_{stem}.journal"
    show = sys.stderr.isatty() and not args.quiet and not args.verbose
    with quiet_progress(show):
        rows = optimise(search, out, journal, stem, workers, scheduler,
                        progress_bar if show else None)
        if show:
            sys.stderr.write("\n")
    for row in [] if args.no_plots else draw_best(search, rows, out):
        if row["status"] == "failed":
            log.warning("the best variant's plots failed: %s", row["error"])
    record = publish_trials(search, rows, out, f"optimize_{stem}", journal, stem,
                            args.study)
    counts = record["trials"]
    report(f"{counts['finished']} trials: {counts['computed']} computed, {counts['reused']} "
           f"reused, {counts['failed']} failed; {counts['constraints_met']} meet the "
           f"constraints")
    for best in record["best"]:
        values = ", ".join(f"{c} {_short(v)}" for c, v in best["values"].items())
        inputs = ", ".join(f"{k} {_short(v)}" for k, v in best["inputs"].items())
        report(f"best: {values} at trial {best['trial']} ({inputs}): {best['run_folder']}")
    if not record["best"]:
        report("no trial gave a value that meets the constraints")
    report(f"trials: {record['path']}")
    return 0 if record["best"] else 3


def _short(value):
    return (f"{value:.6g}" if isinstance(value, float) else
            "empty" if value is None else value)
