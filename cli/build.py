"""``masonry build``: parameters to bricks and interfaces on disk."""

from .options import (add_boundary_options, add_model_options, add_output_options,
                      params_from_args, summary)


NAME = "build"
HELP = ("build the model and its interfaces; write bricks, locations, the printable body "
        "and plots")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    add_model_options(parser)
    add_boundary_options(parser.add_argument_group("boundary (its interfaces)"))
    add_output_options(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    params = params_from_args(args)
    from masonry.pipeline import run  # the whole pipeline: once the options are read

    record = run(params, args.out, analyse=False, force=args.force,
                 max_bricks=args.max_bricks)
    summary(record, report)
    return 0
