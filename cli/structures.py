"""``masonry structures``: the thesis's table 4.1 and friction test, every boundary model
side by side."""

from masonry.params import ParameterError
from masonry.rbe.settings import Analysis
from masonry.runfolder import RunFolder, check_output_root

from .options import add_verbosity


NAME = "structures"
HELP = ("reproduce the thesis's structures 1.1 to 3.2 and its friction test, with free, "
        "rigid and cyclic sections and the full dome")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP)
    parser.add_argument("--out", default="exports", metavar="DIR",
                        help="output root: writes DIR/structures/table.csv and table.md "
                             "(default exports)")
    parser.add_argument("--no-full-dome", dest="full_dome", action="store_false",
                        help="leave out the full domes (the slowest rows)")
    parser.add_argument("--lp-check", action="store_true",
                        help="also run the HiGHS feasibility LP on every row")
    parser.add_argument("--lateral", action="store_true",
                        help="also the worst lateral load factor of each full dome (the "
                             "x.2 domes as a whole), over the azimuths its symmetry leaves")
    parser.add_argument("--friction-cone", dest="friction_cone",
                        metavar="circle|polygon:K|square",
                        help="friction model (default circle, Coulomb's cone); square "
                             "reproduces the thesis's pyramid; a model other than the "
                             "default writes DIR/structures_<model>/")
    add_verbosity(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    if args.lateral and not args.full_dome:
        raise ParameterError("lateral", True, "the full domes, whose factor it is: "
                             "not with --no-full-dome")
    # checked as every analysis's friction model (the default: the preset's, Coulomb's)
    cone = Analysis(friction_cone=args.friction_cone).checked().cone
    check_output_root(args.out)
    from masonry.studies.structures import structures_table, table_csv, table_markdown

    rows = structures_table(full_dome=args.full_dome, lp_check=args.lp_check,
                            lateral=args.lateral, cone=cone)
    markdown = table_markdown(rows)
    name = "structures" if args.friction_cone is None else (
        f"structures_{cone.name.replace(':', '')}")
    with RunFolder(args.out, name) as folder:
        folder.write("table.csv", table_csv(rows))
        folder.write("table.md", markdown)
    report(markdown)
    report(f"written: {folder.target}")
    return 0
