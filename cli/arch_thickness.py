"""``masonry arch-thickness``: the minimum thickness t/R of an arch, by bisection on RBE
feasibility, beside the thrust line's value."""

from masonry.studies.thrust_line import thrust_line_minimum_thickness
from masonry.params import SOLVERS, Params, validate
from masonry.studies.thickness import minimum_thickness
from masonry.tolerances import THICKNESS_RTOL

from .options import add_arch_options

ANALYSIS = ("arch_blocks", "arch_span", "arch_shape", "arch_rise", "arch_depth", "mu",
            "density", "solver")


def register(subparsers):
    parser = subparsers.add_parser(
        "arch-thickness", help="minimum thickness t/R of an arch under self weight, by "
                               "bisection on rigid block equilibrium")
    add_arch_options(parser, thickness=False)
    g = parser.add_argument_group("analysis")
    g.add_argument("--mu", type=float, help="friction coefficient (default 0.7)")
    g.add_argument("--density", type=float, help="kg/m^3 (default 2000)")
    g.add_argument("--solver", choices=SOLVERS,
                   help="QP solver: clarabel (interior point, default) or osqp")
    g.add_argument("--rtol", type=float, default=THICKNESS_RTOL,
                   help="relative width of the final bisection bracket (default %(default)g)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    parser.set_defaults(handler=handle)


def handle(args, report):
    given = {k: getattr(args, k) for k in ANALYSIS if getattr(args, k) is not None}
    params = validate(Params(scene="arch", **given))
    result = minimum_thickness(params, rtol=args.rtol)
    line = thrust_line_minimum_thickness(params.arch_shape, params.arch_blocks,
                                         params.arch_span, params.arch_rise, mu=params.mu)
    report(f"{params.arch_shape} arch, {params.arch_blocks} voussoirs, span "
           f"{params.arch_span:g} m, R = {result.radius:.6g} m, mu {params.mu:g}")
    report(f"minimum thickness (RBE bisection): t/R = {result.t_over_r:.6f} "
           f"(t = {result.thickness:.6g} m; falls at t/R = {result.lower:.6f}), "
           f"{len(result.steps)} solves, {result.time_s:.3g} s")
    report(f"minimum thickness (thrust line):   t/R = {line.t_over_r:.6f}, hinges at joints "
           f"{list(line.extrados_hinges)} (extrados) and {list(line.intrados_hinges)} "
           f"(intrados), thrust {line.thrust:.4f} of the weight")
    return 0
