"""``masonry clean``: remove from an output root what a command makes again when asked
(:mod:`masonry.cleaning`), or list it with ``--dry-run``."""

from masonry.cleaning import clean, plan

from .options import add_verbosity

NAME = "clean"
HELP = ("remove what can be made again (figures, dome.html, printable body, bricks.3dm, "
        "the geometry cache) from the run folders of an output root")
"""The subcommand's name and its line in ``masonry --help``."""


def register(subparsers):
    parser = subparsers.add_parser(NAME, help=HELP, description=(
        "Remove from the run folders of OUT the files a command writes again when asked "
        "(the figures, dome.html and the shared plotly.js, dome.stl, dome.obj, dome.3mf, "
        "bricks.3dm) and the geometry cache; keep run.json (which then says the folder no "
        "longer holds them), the CSV tables, 00_parameters.txt and the model's files. "
        "Nothing else in OUT is touched."))
    parser.add_argument("out", nargs="?", default="exports", metavar="OUT",
                        help="the output root (default exports)")
    parser.add_argument("--dry-run", action="store_true",
                        help="list what would be removed, and its size; remove nothing")
    add_verbosity(parser)
    parser.set_defaults(handler=handle)


def handle(args, report):
    cleaning = plan(args.out)
    verb = "would remove" if args.dry_run else "removed"
    if args.dry_run:
        for path, size in cleaning.files:
            report(f"{size:>12,d}  {path.relative_to(cleaning.root)}")
    else:
        clean(cleaning)
    files, folders = len(cleaning.files), len(cleaning.records)
    report(f"{verb} {files} file{'s' * (files != 1)}, {megabytes(cleaning.bytes)}, from "
           f"{args.out} (run.json of {folders} run folder{'s' * (folders != 1)} "
           f"{'would be ' if args.dry_run else ''}updated)")
    return 0


def megabytes(size: int) -> str:
    """``size`` bytes as a person reads it."""
    return f"{size / 1e6:.1f} MB" if size >= 1e5 else f"{size:,d} bytes"
