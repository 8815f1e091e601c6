"""``masonry run``: build, interfaces, rigid block equilibrium and every output."""

from .options import (add_analysis_options, add_live_load_options, add_model_options,
                      add_output_options, collapse_summary, params_from_args, rbe_summary,
                      summary)


NAME = "run"
HELP = "the full job: model, interfaces, rigid block equilibrium, exports"
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    add_model_options(parser)
    add_analysis_options(parser)
    add_live_load_options(parser)
    add_output_options(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    params = params_from_args(args)
    from masonry.pipeline import run  # the whole pipeline: once the options are read

    record = run(params, args.out, analyse=True, force=args.force,
                 max_bricks=args.max_bricks)
    summary(record, report)
    code = rbe_summary(record, report)
    if "collapse" in record:
        code = max(code, collapse_summary(record, report))
    return code
