"""``masonry run``: build, interfaces, rigid block equilibrium and every output."""

from masonry.pipeline import run

from .options import (add_analysis_options, add_model_options, add_output_options,
                      params_from_args, summary)


def register(subparsers):
    parser = subparsers.add_parser(
        "run", help="the full job: model, interfaces, rigid block equilibrium, exports")
    add_model_options(parser)
    add_analysis_options(parser)
    add_output_options(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    record = run(params_from_args(args), args.out, analyse=True, plots_wanted=args.plots,
                 printable=args.printable, force=args.force)
    summary(record, report)
    rbe = record["rbe"]
    verdict = "feasible" if rbe["feasible"] else "infeasible"
    report(f"RBE: {verdict} (friction-{rbe['friction']}, mu {rbe['mu']:g}), "
           f"MoI {rbe['moi']:.4g} N, MoI factor {rbe['moi_factor']:.4g}, "
           f"residual {rbe['residual_eq']:.2g}, {rbe['solver']} {rbe['time_s']:.3g} s")
    return 0
