"""``masonry build``: parameters to bricks on disk."""

from masonry.pipeline import build_run

from .options import add_model_options, add_output_options, params_from_args


def register(subparsers):
    parser = subparsers.add_parser(
        "build", help="build the model and write bricks, locations and structure plots")
    add_model_options(parser)
    add_output_options(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    params = params_from_args(args)
    record = build_run(params, args.out, plots_wanted=args.plots)
    counts = record["counts"]
    report(f"{record['structure_id']}: {counts['bricks']} bricks "
           f"({counts['regular']} regular, {counts['pattern']} pattern, "
           f"{counts['fill_in']} fill-in) in {counts['courses']} courses, "
           f"weight {record['weight_N']:.4g} N")
    report(f"written to {record['path']}")
    return 0
