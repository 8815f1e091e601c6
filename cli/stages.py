"""``masonry stages``: does the structure stand at every stage of its laying (docs/model.md 4.7)?"""

from masonry.errors import ParameterError

from .options import (add_analysis_options, add_figure_options, add_model_options,
                      add_overlap_option, add_verbosity, centering_line, given_inputs,
                      params_from_args, pattern_note)


NAME = "stages"
HELP = ("construction stages without centering: the rigid block equilibrium of every "
        "stage, by course, brick by brick, or block by block for imported assemblies")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    from masonry.mortars import MORTAR_NAMES
    from masonry.stages.orders import BLOCK_ORDERS, BRICK_ORDERS

    parser = subparsers.add_parser(NAME, help=HELP)
    parser.add_argument("files", nargs="*", metavar="FILE",
                        help="an assembly from OBJ, STL or PLY files (as 'masonry "
                             "analyze'), laid block by block; without files, the dome "
                             "of the model options")
    g = parser.add_argument_group("stages")
    g.add_argument("--by", choices=("course", "brick", "block"),
                   help="course: stage k holds courses 1..k (default for a dome or "
                        "wall); brick: every course one brick at a time, bottom to top "
                        "(the whole construction), or --course K alone; block: one block "
                        "at a time (default with FILE)")
    g.add_argument("--course", type=int, metavar="K",
                   help="with --by brick: lay only course K brick by brick, on courses "
                        "1..K-1 complete")
    g.add_argument("--order", choices=(*BRICK_ORDERS, *BLOCK_ORDERS),
                   help="laying order: pattern-first (default) or along for --by brick; "
                        "z (bottom up, default) or names for --by block")
    g = parser.add_argument_group("supports of FILE (as 'masonry analyze')")
    g.add_argument("--support", action="append", default=[], metavar="NAME_OR_PATTERN",
                   help="blocks fixed in place, by name or shell pattern; repeat for more")
    g.add_argument("--support-below", dest="support_below", type=float, metavar="Z",
                   help="every block reaching down to z <= Z (metres) is a support")
    g.add_argument("--ground", action="store_true",
                   help="add a ground slab (a support) under the lowest blocks")
    add_overlap_option(g)
    add_model_options(parser)
    add_analysis_options(parser)
    g = parser.add_argument_group("mortar by age (docs/model.md 6.13)")
    g.add_argument("--mortar", choices=MORTAR_NAMES,
                   help="every joint has the strength of its age: lime or gypsum (a "
                        "table of cohesion and tensile strength against the hours after "
                        "laying; needs --laying-rate), or constant (--cohesion-kpa and "
                        "--tensile-kpa at every age); default: --cohesion-kpa and "
                        "--tensile-kpa at every joint")
    g.add_argument("--laying-rate", dest="laying_rate", type=float,
                   metavar="BRICKS_PER_HOUR",
                   help="bricks per hour per mason: a stage laying n bricks of the scene "
                        "takes n / (rate x masons) hours, which ages the joints made "
                        "before it")
    g.add_argument("--masons", type=int, metavar="N",
                   help="masons laying side by side (default 1; a section's scene is one "
                        "web: its mason's rate; a whole dome's webs: give the webs)")
    g = parser.add_argument_group("live load")
    g.add_argument("--lateral", metavar="AZIMUTH",
                   help="also the collapse load factor lambda of every stage that stands, "
                        "under a horizontal body force lambda x each block's weight at "
                        "AZIMUTH degrees from +x toward +y (one azimuth; not on a cyclic "
                        "section: use --scene dome)")
    g = parser.add_argument_group("output")
    g.add_argument("--out", default="exports", metavar="DIR",
                   help="output root; the run folder is DIR/<structure id>_stages_<plan>")
    g.add_argument("--no-plots", dest="plots", action="store_false", help="skip all plots")
    add_figure_options(g)
    g.add_argument("--force", action="store_true",
                   help="recompute even if the run folder holds this input's results")
    add_verbosity(g)
    parser.set_defaults(handler=handle)


def _timing(stages) -> str:
    """How long the stages took: wall time, and the stages' own solves when they ran side
    by side (their sum is then more than the wall time)."""
    wall, solves = stages.get("wall_s"), stages["solve_s"]
    if wall is None:  # a record written before the wall time was
        return f"the stages' solves add up to {solves:.3g} s"
    text = f"{stages['count']} stages solved in {wall:.3g} s"
    if solves > wall:
        text += f" (two at once: their solves add up to {solves:.3g} s)"
    return text


def _refuse_inapplicable(args):
    """Options that choose what FILE... would not be (the scene to build), or the
    supports of blocks read from files when there are none."""
    if args.files:
        for name in ("preset", "params", "scene"):
            if getattr(args, name) is not None:
                raise ParameterError(name, getattr(args, name), "no FILE beside it: the "
                                     "files are the assembly laid block by block, read, "
                                     "not built")
        return
    given = {"support": bool(args.support), "support_below": args.support_below is not None,
             "ground": args.ground, "overlap_tolerance": args.overlap_tolerance is not None}
    name = next((name for name, is_given in given.items() if is_given), None)
    if name is not None:
        raise ParameterError(name, getattr(args, name),
                             "FILE... beside it: it applies to blocks read from files; a "
                             "dome or wall stands on its ground slab")


def handle(args, report):
    _refuse_inapplicable(args)
    from masonry.assembly import read_assembly
    from masonry.stages.run import run_stages, stage_params

    if args.files:
        params, scene, source = read_assembly(
            args.files, support=args.support, support_below=args.support_below,
            ground=args.ground, overlap_tolerance=args.overlap_tolerance,
            inputs=given_inputs(args))
        by = args.by or "block"
    else:
        scene = source = None
        params, by = params_from_args(args, laying=True), args.by or "course"
        if not params.kind.has_courses and args.by is None:
            by = "block"
        params = stage_params(params, args.boundary is not None or args.dome)
    record = run_stages(params, args.out, by=by, order=args.order, course=args.course,
                        force=args.force, scene=scene, source=source,
                        max_bricks=args.max_bricks, **_laying(args, params))
    stages = record["stages"]
    state = "up to date, reused" if record.get("reused") else "written"
    report(f"{record['structure_id']}: {record['plan']['described']}")
    pattern_note(record, report)
    report(f"{_with_mortar(record)}{stages['standing']} of {stages['count']} stages stand "
           f"without {'centering' if record.get('mortar') else 'support'} (mu "
           f"{params.analysis.mu:g}, friction {params.analysis.friction}); "
           f"{_timing(stages)}")
    factors = [(r["load_factor"], r["stage"]) for r in record["rows"]
               if r.get("load_factor") is not None] if "rows" in record else []
    if factors:
        low, at = min(factors)
        report(f"lateral load factor at {params.load.azimuth_deg:g} deg: smallest {low:.4g} "
               f"(stage {at}), {factors[-1][0]:.4g} at stage {factors[-1][1]} (stages.csv)")
    first = stages["first_unsupported"]
    if record.get("mortar"):
        report(f"contact law: {record['mortar']['law']}")
    if first is not None:
        report(f"first stage that needs support: {first['stage']} ({first['bricks']} "
               f"bricks{_moi(first)}){_loose(first)}")
        report(centering_line(first["centering_N"], first["centering_fraction"],
                              first["held"], len(first["held"]),
                              "first_unsupported/held.csv"))
    if stages["centering_max_stage"] is not None:
        report(f"largest centering force: {stages['centering_max_N']:.4g} N "
               f"({stages['centering_max_fraction']:.3g} of the stage's weight) at stage "
               f"{stages['centering_max_stage']} (stages.csv, column centering_N)")
    line = _adhesion_line(stages, record["plan"]["by"])
    if line:
        report(line)
    if record.get("mortar") and "hold_max_h" in record["mortar"]:
        report(_hold_line(record["mortar"], stages))
    loose = [str(r["stage"]) for r in record.get("rows", ()) if r.get("loose")]
    if loose:
        report(f"stages with blocks joined to no support, so no MoI: {', '.join(loose[:10])}"
               f"{', ...' if len(loose) > 10 else ''} (stages.csv, column loose)")
    report(f"{state}: {record['path']}")
    return 0


def _laying(args, params) -> dict:
    """The mortar by age (:data:`~masonry.mortars.LAYING_INPUTS`): the options given,
    else the ``--params`` file's ``[mortar]``; checked here, so that a file's value is
    refused naming the file and key."""
    from masonry.mortars import LAYING_INPUTS
    from masonry.stages.laying import stage_laying
    from masonry.params import laying_inputs

    given = {name: getattr(args, name) for name in LAYING_INPUTS}
    from_file = {} if getattr(args, "params", None) is None else {
        name: value for name, value in laying_inputs(args.params).items()
        if given[name] is None}
    inputs = {**given, **from_file}
    try:
        stage_laying(params, **inputs)
    except ParameterError as error:
        if error.name not in from_file:
            raise
        raise ParameterError(error.name, error.value, error.expected,
                             where=args.params) from None
    return inputs


def _with_mortar(record) -> str:
    """``with lime mortar at 60 bricks per hour (1 mason): `` where the study aged its
    joints, else ''."""
    mortar = record.get("mortar")
    return "" if mortar is None else f"with {mortar['text']}: "


def _moi(first) -> str:
    """The MoI factor of the first stage that needs support, where it has one."""
    if first["moi_factor"] is None:
        return ""
    return f", MoI factor {first['moi_factor']:.3g}: the QP's optimality measure"


def _loose(first) -> str:
    """The loose blocks of that stage, where it has some."""
    if not first.get("loose"):
        return ""
    return f": {', '.join(first['loose'][:3])} touch nothing that joins them to a support"


def _hold_line(mortar, stages) -> str:
    """How long the brick just laid must be held until the mortar holds its stage."""
    name = mortar["mortar"]["name"]
    if mortar["hold_never_stage"] is not None:
        return (f"{name} mortar never holds the least adhesion of stage "
                f"{mortar['hold_never_stage']} (stages.csv, column hold_h)")
    if not mortar["hold_max_h"]:
        return f"{name} mortar holds every stage when laid: no brick needs holding"
    hours = mortar["hold_max_h"]
    held = f"{hours:.3g} h" if hours >= 1 else f"{60 * hours:.3g} min"
    return (f"{name} mortar: a brick just laid is held at most {held} (stage "
            f"{mortar['hold_max_stage']}) until its mortar holds the stage's least adhesion "
            f"(stages.csv, column hold_h)")


def _adhesion_line(stages, by) -> str:
    """The least adhesion over the stages (docs/model.md 6.12): the largest, where it
    peaks and what it means, or the stages that have none; '' for a record written
    before the stages computed it."""
    if "adhesion_max_kPa" not in stages:
        return ""
    top, missing = stages["adhesion_max_kPa"], stages["adhesion_unsolved"]
    if missing is not None:
        count = missing["count"]
        return (f"least adhesion: none builds it in this order: {count} "
                f"stage{' has' if count == 1 else 's have'} no value, from stage "
                f"{missing['first_stage']} ({missing['reason']}; stages.csv, column "
                f"adhesion_kPa)")
    if top == 0:
        return "least adhesion: 0 kPa, every stage stands with dry joints"
    course = stages["adhesion_max_course"]
    where = f"stage {stages['adhesion_max_stage']}" + (
        "" if course is None else f", course {course}")
    brick, other = stages["adhesion_max_joint"]
    return (f"least adhesion: {top:.4g} kPa at most ({where}, brick {brick} on {other}): "
            f"mortar holding {top:.4g} kPa of cohesion (and {stages['adhesion_tension_ratio']:g}"
            f" x that in tension) within the time a {'stage' if by == 'block' else 'course'}"
            f" takes to lay builds it without centering (stages.csv, column adhesion_kPa)")
