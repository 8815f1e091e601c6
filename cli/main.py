"""Entry point of the ``masonry`` command. ``main(argv)`` returns the exit code."""

import logging
import sys

from masonry.scenes.imported import AssemblyError
from masonry.params import ParameterError
from masonry.rbe.solvers.newton import use_one_blas_thread

from . import analyze, arch_thickness, bench, build, run, stages, structures, sweep
from .options import Parser

SUBCOMMANDS = (build, run, structures, analyze, arch_thickness, sweep, bench, stages)


def make_parser():
    parser = Parser(prog="masonry", description=(
        "Brunelleschi-style double-helix masonry domes: bricks, interfaces, rigid block "
        "equilibrium, printable exports."))
    subparsers = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in SUBCOMMANDS:
        module.register(subparsers)
    return parser


def main(argv=None) -> int:
    args = make_parser().parse_args(argv)
    # progress on a terminal only; --quiet silences it there too
    verbose = sys.stderr.isatty() and not getattr(args, "quiet", False)
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="masonry: %(message)s", stream=sys.stderr)
    logging.getLogger("matplotlib").setLevel(logging.WARNING)
    use_one_blas_thread()

    def report(line):
        print(line)

    try:
        return args.handler(args, report)
    except (ParameterError, AssemblyError) as error:
        print(f"masonry: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("masonry: interrupted; the previous output is untouched", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
