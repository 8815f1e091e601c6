"""Options shared by the subcommands, and their translation into ``Params``."""

import argparse

from masonry.params import (ACCURACIES, ARCH_SHAPES, BOUNDARIES, FRICTIONS, PRESETS,
                            SCENES, SOLVERS, Params, from_preset, load, validate)


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2."""

    def error(self, message):
        self.exit(2, f"masonry: error: {message}\n")


def add_model_options(parser):
    g = parser.add_argument_group("model")
    g.add_argument("--preset", choices=list(PRESETS),
                   help="a thesis structure (1 spherical, 2 stretched, 3 compressed) or the "
                        "validation wall; explicit options below override it")
    g.add_argument("--params", metavar="FILE", help="parameters from a TOML file")
    g.add_argument("--scene", choices=[s for s in SCENES if s != "assembly"],
                   help="section (one web, default), dome (all n webs), wall (validation), "
                        "arch (voussoirs, see the arch options)")
    g.add_argument("--stretch", type=float, help="dome height / circumradius (> 0)")
    g.add_argument("--n", type=int, help="walls of the polygonal dome (>= 3)")
    g.add_argument("--r", type=int, help="full rhombi across the section (>= 0)")
    g.add_argument("--p", type=int, help="pattern bricks per rhombus side (>= 1)")
    g.add_argument("--cut", type=float, help="fraction of the height cut off, 0 <= cut < 1")
    g.add_argument("--unit", type=float, help="brick unit in metres (default 0.1)")
    g.add_argument("--min-fill", dest="min_fill", type=float,
                   help="shortest fill-in brick in units (default 1)")
    g.add_argument("--wall-length", dest="wall_length", type=float,
                   help="wall scene: length in units (default 32)")
    g.add_argument("--wall-courses", dest="wall_courses", type=int,
                   help="wall scene: number of courses (default 10)")
    g.add_argument("--fast", action="store_true", default=None,
                   help="reduced output: one view, lower resolution")
    add_arch_options(parser)


def add_arch_options(parser, thickness=True):
    g = parser.add_argument_group("arch scene (metres; the span and rise of the centre line)")
    g.add_argument("--blocks", dest="arch_blocks", type=int,
                   help="number of voussoirs (default 16; even for a pointed arch)")
    if thickness:
        g.add_argument("--thickness", dest="arch_thickness", type=float,
                       help="thickness t along the joints (default 0.6)")
    g.add_argument("--span", dest="arch_span", type=float, help="span (default 10)")
    g.add_argument("--shape", dest="arch_shape", choices=ARCH_SHAPES,
                   help="semicircular (default), pointed or segmental")
    g.add_argument("--rise", dest="arch_rise", type=float,
                   help="rise of a pointed (> span/2, default equilateral) or segmental "
                        "(< span/2, default span/4) arch")
    g.add_argument("--depth", dest="arch_depth", type=float,
                   help="depth along y (default 1)")


def add_analysis_options(parser, boundary=True):
    """Friction, density and solver options; ``boundary`` adds a section's boundary."""
    g = parser.add_argument_group("analysis")
    g.add_argument("--mu", type=float, help="friction coefficient (default 0.7)")
    g.add_argument("--density", type=float, help="kg/m^3 (default 2000)")
    g.add_argument("--friction", choices=FRICTIONS,
                   help="net, plus, or auto (net, then plus if infeasible; default)")
    g.add_argument("--accuracy", choices=ACCURACIES,
                   help="solver preset: fast, balanced (default; fast with --fast) or "
                        "accurate (interior point, tight tolerances, LP check); see "
                        "'masonry bench'")
    g.add_argument("--solver", choices=SOLVERS,
                   help="override the preset's QP solver: newton (semismooth Newton, "
                        "friction-net), clarabel (interior point), osqp (ADMM), or "
                        "clarabel-cvxpy / osqp-cvxpy (through cvxpy, the reference)")
    if not boundary:
        return
    g.add_argument("--boundary", choices=BOUNDARIES,
                   help="boundary of a section: free (free-standing, default), rigid "
                        "(immovable neighbouring webs) or cyclic (exact rotational symmetry)")
    g.add_argument("--dome", action="store_true",
                   help="dome mode: the section with its neighbours, cyclic unless "
                        "--boundary says otherwise")


def add_output_options(parser):
    g = parser.add_argument_group("output")
    g.add_argument("--out", default="exports", metavar="DIR",
                   help="output root; the run folder is DIR/<structure id> (default exports)")
    g.add_argument("--no-plots", dest="plots", action="store_false", help="skip all plots")
    g.add_argument("--no-printable", dest="printable", action="store_false",
                   help="skip the printable body (dome.stl, dome.obj)")
    g.add_argument("--print-size", dest="print_size", type=float, metavar="MM",
                   help="also write dome.3mf for a slicer, in millimetres, its largest "
                        "dimension MM")
    g.add_argument("--force", action="store_true",
                   help="recompute even if the run folder holds this input's results")
    g.add_argument("-q", "--quiet", action="store_true", help="no progress messages")


def params_from_args(args) -> Params:
    """Preset or file first, then every option the user gave; validated."""
    given = {k: v for k, v in vars(args).items()
             if k in Params.__dataclass_fields__ and v is not None}
    if getattr(args, "dome", False) and "boundary" not in given:
        given["boundary"] = "cyclic"
    if args.params:
        return load(args.params, **given)
    if args.preset:
        return from_preset(args.preset, **given)
    if given.get("scene") == "wall":
        return from_preset("wall", **given)
    return validate(Params(**given))


def summary(record, report):
    """The lines every subcommand prints about the model it wrote."""
    counts = record["counts"]
    interfaces = sum(counts.get("interfaces", {}).values())
    state = "up to date, reused" if record.get("reused") else "written"
    what = (f"{counts['bricks']} blocks" if record["scene"] in ("arch", "assembly") else
            f"{counts['bricks']} bricks ({counts['regular']} regular, {counts['pattern']} "
            f"pattern, {counts['fill_in']} fill-in) in {counts['courses']} courses")
    report(f"{record['structure_id']}: {what}, {interfaces} interfaces, "
           f"weight {record['weight_N']:.4g} N")
    report(f"{state}: {record['path']}")


def rbe_summary(record, report):
    """The line about the rigid block equilibrium of a run record."""
    rbe = record["rbe"]
    verdict = "feasible" if rbe["feasible"] else "infeasible"
    report(f"RBE: {verdict} (friction-{rbe['friction']}, mu {rbe['mu']:g}), "
           f"MoI {rbe['moi']:.4g} N, MoI factor {rbe['moi_factor']:.4g}, "
           f"residual {rbe['residual_eq']:.2g}, {rbe['solver']} {rbe['time_s']:.3g} s")
