"""Options shared by the subcommands, and their translation into ``Params``."""

import argparse

from masonry.params import (BOUNDARIES, FRICTIONS, PRESETS, SCENES, SOLVERS, Params,
                            from_preset, load, validate)

GEOMETRY = ("stretch", "n", "r", "p", "cut", "unit", "min_fill", "wall_length",
            "wall_courses")


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
    g.add_argument("--scene", choices=[s for s in SCENES if s in ("section", "wall", "dome")],
                   help="section (one web, default), dome (all n webs), wall (validation)")
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


def add_analysis_options(parser):
    g = parser.add_argument_group("analysis")
    g.add_argument("--mu", type=float, help="friction coefficient (default 0.7)")
    g.add_argument("--density", type=float, help="kg/m^3 (default 2000)")
    g.add_argument("--friction", choices=FRICTIONS,
                   help="net, plus, or auto (net, then plus if infeasible; default)")
    g.add_argument("--solver", choices=SOLVERS,
                   help="QP solver: clarabel (interior point, default) or osqp")
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
    report(f"{record['structure_id']}: {counts['bricks']} bricks "
           f"({counts['regular']} regular, {counts['pattern']} pattern, "
           f"{counts['fill_in']} fill-in) in {counts['courses']} courses, "
           f"{interfaces} interfaces, weight {record['weight_N']:.4g} N")
    report(f"{state}: {record['path']}")
