"""``masonry build``: parameters to bricks and interfaces on disk."""

from masonry.pipeline import run

from .options import (add_boundary_options, add_model_options, add_output_options,
                      params_from_args, summary)


def register(subparsers):
    parser = subparsers.add_parser(
        "build", help="build the model and its interfaces; write bricks, locations, "
                      "the printable body and plots")
    add_model_options(parser)
    add_boundary_options(parser.add_argument_group("boundary (its interfaces)"))
    add_output_options(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    record = run(params_from_args(args), args.out, analyse=False, force=args.force,
                 max_bricks=args.max_bricks)
    summary(record, report)
    return 0
