"""``masonry arch-thickness``: the minimum thickness t/R of an arch, by bisection on RBE
feasibility, beside the thrust line's value."""

from masonry.params import Params, validate
from masonry.rbe.solvers import RBE, names
from masonry.scenes.arch import arch_radius
from masonry.runfolder import RunFolder, check_output_root
from masonry.tolerances import THICKNESS_RTOL

from .options import add_material_options, add_scene_options, add_verbosity

ANALYSIS = ("arch_blocks", "arch_span", "arch_shape", "arch_rise", "arch_depth", "mu",
            "density", "friction_cone", "solver")


NAME = "arch-thickness"
HELP = ("minimum thickness t/R of an arch under self weight, by bisection on rigid block "
        "equilibrium")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    add_scene_options(parser, kinds=("arch",), skip=("arch_thickness",))
    g = parser.add_argument_group("analysis")
    add_material_options(g)
    solvers = names(RBE)  # the bisection solves the equilibrium only: no collapse LPs
    g.add_argument("--solver", choices=solvers,
                   help=f"QP solver (default: the balanced preset's): {', '.join(solvers)}")
    g.add_argument("--rtol", type=float, default=THICKNESS_RTOL,
                   help="relative width of the final bisection bracket (default %(default)g)")
    parser.add_argument("--out", default="exports", metavar="DIR",
                        help="output root: writes DIR/arch-thickness_<inputs>/ with "
                             "result.json and steps.csv (default exports)")
    add_verbosity(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    given = {k: getattr(args, k) for k in ANALYSIS if getattr(args, k) is not None}
    params = validate(Params.of(scene="arch", **given))
    check_output_root(args.out)
    from masonry.studies.thickness import folder_name, minimum_thickness, steps_csv
    from masonry.studies.thrust_line import thrust_line_minimum_thickness

    result = minimum_thickness(params, rtol=args.rtol)
    arch, analysis = params.geometry, params.analysis
    line = thrust_line_minimum_thickness(arch.arch_shape, arch.arch_blocks, arch.arch_span,
                                         arch.arch_rise, mu=analysis.mu)
    inputs = {name: params.inputs()[name] for name in ANALYSIS}
    inputs["arch_rise"] = arch_radius(arch.arch_shape, arch.arch_span,
                                      arch.arch_rise)[1]  # the default resolved
    inputs["accuracy"] = analysis.accuracy
    inputs["friction_cone"] = analysis.cone.name
    record = {"params": inputs, "rtol": args.rtol,
              "rbe": {"t_over_r": result.t_over_r, "lower": result.lower,
                      "thickness_m": result.thickness, "radius_m": result.radius,
                      "solves": len(result.steps), "time_s": result.time_s},
              "thrust_line": {"t_over_r": line.t_over_r, "thrust": line.thrust,
                              "extrados_hinges": list(line.extrados_hinges),
                              "intrados_hinges": list(line.intrados_hinges)}}
    with RunFolder(args.out, folder_name(params, args.rtol)) as folder:
        folder.write_json("result.json", record)
        folder.write("steps.csv", steps_csv(result))
    report(f"{arch.arch_shape} arch, {arch.arch_blocks} voussoirs, span "
           f"{arch.arch_span:g} m, R = {result.radius:.6g} m, mu {analysis.mu:g}")
    report(f"minimum thickness (RBE bisection): t/R = {result.t_over_r:.6f} "
           f"(t = {result.thickness:.6g} m; falls at t/R = {result.lower:.6f}), "
           f"{len(result.steps)} solves, {result.time_s:.3g} s")
    report(f"minimum thickness (thrust line):   t/R = {line.t_over_r:.6f}, hinges at joints "
           f"{list(line.extrados_hinges)} (extrados) and {list(line.intrados_hinges)} "
           f"(intrados), thrust {line.thrust:.4f} of the weight")
    report(f"written: {folder.target}")
    return 0
