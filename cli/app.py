"""The ``masonry`` command once loaded (see :mod:`masonry_cli.main`). ``main(argv)``
returns the exit code.

Exit codes: 0 done; 1 an internal failure (one line on stderr, the traceback in a log
file whose path the line gives); 2 a user mistake (one line naming the option as typed,
the value and what is expected; nothing written); 3 the equilibrium was not solved (no
verdict); 130 / 143 interrupted by SIGINT (Ctrl-C) / SIGTERM. In every case but 0 the
previous output is untouched.
"""

import logging
import os
import sys
import tempfile
import time
import traceback
from pathlib import Path

from masonry import __version__
from masonry.errors import MasonryError
from masonry.forking import use_one_blas_thread

from . import (analyze, arch_thickness, bench, build, clean, optimize, run, stages,
               structures, sweep)
from .interrupts import interrupt_behind, interrupted
from .options import Parser, describe_error, option_names, typed_values
from .streams import silence_stdout

SUBCOMMANDS = (build, run, structures, analyze, arch_thickness, sweep, optimize, bench,
               stages, clean)


def make_parser(argv=None):
    """The command's parser. With ``argv``, only the subcommand it names gets its options
    (the others their line in ``--help``): building a command's options imports what
    they are declared with, and a study's the whole pipeline."""
    parser = Parser(prog="masonry", description=(
        "Brunelleschi-style double-helix masonry domes: bricks, interfaces, rigid block "
        "equilibrium, printable exports."))
    parser.add_argument("--version", action="version", version=f"masonry {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    named = None if argv is None else _command(argv) or ""
    for module in SUBCOMMANDS:
        if named is None or module.NAME == named:
            module.register(subparsers)
        else:
            subparsers.add_parser(module.NAME, help=module.HELP)
    for subparser in subparsers.choices.values():
        subparser.set_defaults(option_names=option_names(subparser))
    return parser


def _command(argv) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option (the options
    before it are the command's own, ``--version`` and ``--help``), or None."""
    return next((word for word in argv if not word.startswith("-")), None)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = make_parser(argv).parse_args(argv)
    args.typed = typed_values(argv)
    # progress on a terminal (or with --verbose); --quiet silences it there too
    verbose = getattr(args, "verbose", False) or (sys.stderr.isatty()
                                                   and not getattr(args, "quiet", False))
    _log_to_stderr(logging.INFO if verbose else logging.WARNING)
    logging.getLogger("matplotlib").setLevel(logging.WARNING)
    use_one_blas_thread()

    def report(line):
        if not stdout_gone:
            try:
                print(line, flush=True)
            except BrokenPipeError:  # its reader left ('| head -1'): the work goes on
                stdout_gone.append(silence_stdout())

    stdout_gone = []

    try:  # inside masonry_cli.main's interrupts.heard(): SIGTERM raises Terminated
        return args.handler(args, report)
    except MasonryError as error:
        print(f"masonry: error: {describe_error(error, args)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as interrupt:
        return interrupted(interrupt)
    except Exception as error:  # anything unexpected: one line, the traceback in a log
        interrupt = interrupt_behind(error)
        if interrupt is not None:  # raised as another error by an extension's loader
            return interrupted(interrupt)
        log_file = write_failure_log(argv)
        print(f"masonry: internal error: {type(error).__name__}: {_first_line(error)}; the "
              f"previous output is untouched; details in {log_file}", file=sys.stderr)
        return 1


class _StderrHandler(logging.StreamHandler):
    """This command's one log handler: ``masonry: <message>`` on the current stderr."""


def _log_to_stderr(level):
    """Log at ``level`` to the current stderr, replacing the handler an earlier ``main``
    call in this process installed (and no other: a host's handlers stay)."""
    root = logging.getLogger()
    for handler in [h for h in root.handlers if isinstance(h, _StderrHandler)]:
        root.removeHandler(handler)
    handler = _StderrHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("masonry: %(message)s"))
    root.addHandler(handler)
    root.setLevel(level)


def _first_line(error) -> str:
    text = str(error).strip().splitlines()
    return text[0] if text else "(no message)"


def log_folder() -> Path:
    """Where failure logs go: ``$MASONRY_LOG_DIR``, else ``$XDG_CACHE_HOME/masonry/logs``
    (``~/.cache/masonry/logs``)."""
    if os.environ.get("MASONRY_LOG_DIR"):
        return Path(os.environ["MASONRY_LOG_DIR"])
    cache = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(cache) / "masonry" / "logs"


def write_failure_log(argv) -> Path:
    """Write the current exception's traceback with the command line and version to a
    new log file; returns its path (in the temporary folder if the log folder is not
    writable)."""
    name = f"masonry-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.log"
    text = (f"masonry {__version__}\ncommand: masonry {' '.join(map(str, argv))}\n"
            f"python {sys.version.split()[0]}\n\n{traceback.format_exc()}")
    for folder in (log_folder(), Path(tempfile.gettempdir())):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            (folder / name).write_text(text)
            return folder / name
        except OSError:
            continue
    return Path("(no writable log folder)")
