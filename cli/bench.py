"""``masonry bench``: time against accuracy for every solver preset (docs/model.md 6.6)."""

import resource

from masonry.friction import FrictionCone, FrictionModelError
from masonry.errors import ParameterError
from masonry.params import Params, from_preset, validate
from masonry.rbe.accuracy import ACCURACY
from masonry.rbe.solvers import RBE, names as solver_names
from masonry.runfolder import RunFolder, check_output_root
from masonry.scenes.polygonal import MIN_PATTERN_P

from .options import add_verbosity


NAME = "bench"
HELP = ("measure time, iterations and accuracy of every solver preset on the thesis "
        "structures (section, cyclic section, full dome)")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    # the benches load the whole pipeline: imported when this command runs (masonry_cli.app)
    from masonry_benchmarks.bench import FRICTION_MODELS, SCENES

    parser = subparsers.add_parser(NAME, help=HELP)
    parser.add_argument("--presets", nargs="+", default=["1", "2", "3"],
                        choices=["1", "2", "3"], help="thesis presets (default 1 2 3)")
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES),
                        help="free section, cyclic section, full dome, full dome at mu 0.05, "
                             "the dome of revolution of the preset's profile and its "
                             "sector (default all)")
    parser.add_argument("--accuracy", nargs="+", default=list(ACCURACY),
                        choices=tuple(ACCURACY), help="accuracy presets (default all)")
    parser.add_argument("--solvers", nargs="+", default=[], choices=solver_names(RBE),
                        help="extra rows: the balanced preset with another solver")
    parser.add_argument("--p", type=int, metavar="P",
                        help="override the presets' pattern bricks per rhombus side "
                             "(smaller: smaller domes, for a quick look)")
    parser.add_argument("--repeats", type=int, default=3,
                        help="runs per row; times are medians (default 3)")
    parser.add_argument("--collapse", action="store_true",
                        help="instead: the lateral collapse load factor at azimuth 0 of "
                             "each preset's full dome, and on its halves along a web's "
                             "mid-plane and a corner plane, against its balanced RBE "
                             "solve, and the azimuth search (--lateral all) on a small "
                             "dome against independent solves; writes "
                             "DIR/bench_collapse/collapse.md")
    parser.add_argument("--friction-models", dest="friction_models", nargs="*",
                        metavar="MODEL",
                        help="instead: each friction model (default: "
                             f"{' '.join(FRICTION_MODELS)}) on each preset's full dome: "
                             "the RBE solve and the lateral collapse LP at azimuth 0, "
                             "times against the square pyramid's and factors against the "
                             "exact cone's; writes DIR/bench_friction/friction.md")
    parser.add_argument("--readers", nargs="+", metavar="FILE",
                        help="instead: masonry's mesh reader against trimesh's and meshio's "
                             "on each OBJ, STL or PLY file, medians of --repeats reads; "
                             "writes DIR/bench_readers/readers.md")
    parser.add_argument("--outputs", action="store_true",
                        help="instead: the time of each exporter (the files and figures a "
                             "run writes) on each preset's cyclic section (--dome) and full "
                             "dome, "
                             "medians of --repeats makes (e.g. --presets 1 3 --repeats "
                             "1); writes DIR/bench_outputs/outputs.md")
    parser.add_argument("--stages", action="store_true",
                        help="instead: every brick stage of each preset's cyclic section "
                             "(masonry stages --dome --by brick), both laying orders, "
                             "solved in sequence and each alone, against one masonry run "
                             "of the dome; writes DIR/bench_stages/stages.md")
    parser.add_argument("--adhesion-course", dest="adhesion_course", type=int,
                        metavar="K",
                        help="instead: course K of each preset's cyclic section laid "
                             "brick by brick (masonry stages --dome --by brick --course "
                             "K): each stage's least adhesion against its RBE solve, both "
                             "in one sequence; writes DIR/bench_adhesion/adhesion.md")
    parser.add_argument("--scale", action="store_true",
                        help="instead: whole masonry run processes (no plots, no printable "
                             "body) of a running-bond wall at about 1,000 to 100,000 bricks "
                             "and of preset 1's full dome at p 4 to 26, and an arch of "
                             "1,024 to 16,384 voussoirs, each fresh: time, solver "
                             "iterations, peak memory and their fitted exponents; writes "
                             "DIR/bench_scale/scale.md")
    parser.add_argument("--out", default="exports", metavar="DIR",
                        help="output root: writes DIR/bench/bench.csv, bench.md and "
                             "frontier.png (default exports)")
    add_verbosity(parser)
    parser.set_defaults(handler=handle)


SMALL_DOME = dict(scene="dome", stretch=1.0, n=6, r=0, p=3, cut=0.5)
"""72 bricks: the azimuth search's row (on a thesis dome every azimuth is a full collapse
LP, and the search would outweigh the rest of the bench)."""


def handle(args, report):
    if args.repeats < 1:
        raise ParameterError("repeats", args.repeats, "an integer >= 1")
    if args.p is not None and args.p < MIN_PATTERN_P:  # the presets lay the pattern
        raise ParameterError("p", args.p, f"an integer >= {MIN_PATTERN_P}")
    chosen = [option for option, on in (
        ("collapse", args.collapse), ("friction_models", args.friction_models is not None),
        ("readers", bool(args.readers)), ("outputs", args.outputs), ("stages", args.stages),
        ("adhesion_course", args.adhesion_course is not None), ("scale", args.scale)) if on]
    if len(chosen) > 1:
        raise ParameterError(chosen[1], getattr(args, chosen[1]), f"one bench at a time: "
                             f"not with --{chosen[0].replace('_', '-')}")
    if args.adhesion_course is not None and args.adhesion_course < 1:
        raise ParameterError("adhesion_course", args.adhesion_course, "a course, >= 1")
    check_output_root(args.out)
    if args.outputs:
        return _outputs(args, report)
    if args.collapse:
        return _collapse(args, report)
    if args.friction_models is not None:
        return _friction(args, report)
    if args.readers:
        return _readers(args, report)
    if args.stages:
        return _stages(args, report)
    if args.adhesion_course is not None:
        return _adhesion(args, report)
    if args.scale:
        return _scale(args, report)
    from masonry_benchmarks.bench import (bench, frontier_png, ratios_markdown, table_csv,
                                       table_markdown)

    rows = bench(presets=args.presets, scenes=args.scenes, accuracies=args.accuracy,
                 repeats=args.repeats, solvers=args.solvers,
                 overrides=None if args.p is None else {"p": args.p},
                 progress=None if args.quiet else _progress)
    markdown = table_markdown(rows)
    pairs = ratios_markdown(rows)
    if pairs:
        markdown += "\ninfeasible against feasible (total_s):\n\n" + pairs
    # ru_maxrss is in kilobytes on Linux
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    with RunFolder(args.out, "bench") as folder:
        folder.write("bench.csv", table_csv(rows))
        folder.write("bench.md", markdown + f"\npeak memory of the bench process: "
                                            f"{peak:.2f} GiB\n")
        folder.write("frontier.png", frontier_png(rows))
    report(markdown)
    report(f"peak memory: {peak:.2f} GiB")
    report(f"written: {folder.target}")
    return 0


def _collapse(args, report):
    from masonry_benchmarks.bench import collapse_bench, collapse_markdown

    overrides = {} if args.p is None else {"p": args.p}
    named = "" if args.p is None else f" (p {args.p})"
    domes = {f"preset {k} full dome{named}": from_preset(k, scene="dome", **overrides)
             for k in args.presets}
    small = {"small dome (n 6, p 3)": validate(Params.of(**SMALL_DOME))}
    progress = None if args.quiet else _progress
    rows = collapse_bench(domes, repeats=args.repeats, progress=progress)
    rows += collapse_bench(small, repeats=args.repeats, search=True, progress=progress)
    markdown = collapse_markdown(rows)
    return _published(args, report, "collapse", markdown)


def _friction(args, report):
    from masonry_benchmarks.bench import FRICTION_MODELS, friction_bench, friction_markdown

    models = args.friction_models or list(FRICTION_MODELS)
    for name in models:
        try:
            FrictionCone.parse(name)
        except FrictionModelError as error:
            raise ParameterError("friction_models", name, str(error)) from None
    overrides = {} if args.p is None else {"p": args.p}
    named = "" if args.p is None else f" (p {args.p})"
    domes = {f"preset {k} full dome{named}": from_preset(k, scene="dome", **overrides)
             for k in args.presets}
    rows = friction_bench(domes, models, repeats=args.repeats,
                          progress=None if args.quiet else _progress)
    markdown = friction_markdown(rows)
    return _published(args, report, "friction", markdown)


def _published(args, report, name, markdown) -> int:
    """``markdown`` written to ``DIR/bench_<name>/<name>.md`` and reported; exit 0."""
    with RunFolder(args.out, f"bench_{name}") as folder:
        folder.write(f"{name}.md", markdown)
    report(markdown)
    report(f"written: {folder.target}")
    return 0


def _sections(args) -> dict:
    """Each of ``--presets``' cyclic section (``--p`` overriding), named."""
    overrides = {} if args.p is None else {"p": args.p}
    named = "" if args.p is None else f" (p {args.p})"
    return {f"preset {k} cyclic section{named}": from_preset(k, boundary="cyclic", **overrides)
            for k in args.presets}


def _stages(args, report):
    from masonry_benchmarks.stages_bench import stages_bench, stages_markdown

    rows = stages_bench(_sections(args), repeats=args.repeats,
                        progress=None if args.quiet else _progress)
    markdown = stages_markdown(rows)
    return _published(args, report, "stages", markdown)


def _adhesion(args, report):
    from masonry_benchmarks.stages_bench import adhesion_bench, adhesion_markdown

    rows = adhesion_bench(_sections(args), args.adhesion_course,
                          progress=None if args.quiet else _progress)
    markdown = adhesion_markdown(rows)
    return _published(args, report, "adhesion", markdown)


def _scale(args, report):
    from masonry_benchmarks.scale_bench import scale_bench, scale_markdown, scale_structures

    rows = scale_bench(scale_structures(), progress=None if args.quiet else _progress)
    return _published(args, report, "scale", scale_markdown(rows))


def _readers(args, report):
    from masonry_benchmarks.reader_bench import reader_bench, readers_markdown

    rows = reader_bench(args.readers, repeats=args.repeats,
                        progress=None if args.quiet else _progress)
    markdown = readers_markdown(rows)
    return _published(args, report, "readers", markdown)


def _outputs(args, report):
    from masonry_benchmarks.output_bench import output_bench, outputs_markdown

    overrides = {} if args.p is None else {"p": args.p}
    named = "" if args.p is None else f" (p {args.p})"
    structures = {f"preset {k} {label}{named}": from_preset(k, **inputs, **overrides)
                  for k in args.presets
                  for label, inputs in (("cyclic section", dict(boundary="cyclic")),
                                        ("full dome", dict(scene="dome")))}
    rows = output_bench(structures, repeats=args.repeats,
                        progress=None if args.quiet else _progress)
    markdown = outputs_markdown(rows)
    return _published(args, report, "outputs", markdown)


def _progress(message):
    import logging

    logging.getLogger("masonry_benchmarks.bench").info(message)
