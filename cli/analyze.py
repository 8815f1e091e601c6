"""``masonry analyze``: interfaces and rigid block equilibrium of blocks read from files."""

from .options import (add_analysis_options, add_live_load_options, add_output_options,
                      add_overlap_option,
                      check_print_size, collapse_summary, given_inputs, rbe_summary, summary)


NAME = "analyze"
HELP = ("any assembly of convex blocks from OBJ, STL, PLY or COMPAS JSON files: "
        "interfaces, rigid block equilibrium, exports")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    parser.add_argument("files", nargs="+", metavar="FILE",
                        help="OBJ (one block per object or group), STL or PLY (one block "
                             "per connected body), COMPAS JSON (one block per mesh, its "
                             "is_support); several files add up")
    g = parser.add_argument_group("supports (at least one; --support and --support-below "
                                  "replace a COMPAS file's)")
    g.add_argument("--support", action="append", default=[], metavar="NAME_OR_PATTERN",
                   help="blocks fixed in place, by name or shell pattern ('pier_*'); "
                        "repeat for more")
    g.add_argument("--support-below", dest="support_below", type=float, metavar="Z",
                   help="every block reaching down to z <= Z (metres) is a support")
    g.add_argument("--ground", action="store_true",
                   help="add a ground slab (a support) under the lowest blocks")
    add_overlap_option(g)
    add_analysis_options(parser, boundary=False)
    add_live_load_options(parser)
    parser.add_argument("--fast", action="store_true", default=None,
                   help="reduced output: one view, lower resolution")
    add_output_options(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    from masonry.assembly import read_assembly

    # the options are checked before any file is read; they win over a Problem's
    params, scene, source = read_assembly(
        args.files, support=args.support, support_below=args.support_below,
        ground=args.ground, overlap_tolerance=args.overlap_tolerance,
        inputs=given_inputs(args), check=lambda params: check_print_size(args, params))
    from masonry.pipeline import run  # the whole pipeline: once the options are read

    record = run(params, args.out, analyse=True, force=args.force, scene=scene,
                 source=source)
    report(f"read {scene.blocks.n_blocks} blocks ({source['supports']} supports) from "
           f"{len(source['files'])} file(s) in {source['read_s']:.3g} s")
    summary(record, report)
    code = rbe_summary(record, report)
    if "collapse" in record:
        code = max(code, collapse_summary(record, report))
    return code
