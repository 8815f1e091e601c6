"""Entry point of the ``masonry`` command. ``main(argv)`` returns the exit code.

The command itself is :mod:`masonry_cli.app`. It is imported here, inside ``main`` and
after SIGTERM's handler is installed, so that Ctrl-C or ``kill`` while numpy, scipy and
the solvers load (a second or two), or while the command's options are built, ends as an
interruption like any other: one line, exit code 130 or 143, no traceback. This module
imports nothing else before ``main`` runs (what loads before it, Python's start and the
launcher's import of this module, is out of its reach). ``--version`` answers without it.
"""

import os
import sys

from masonry_cli.streams import silence_stdout

BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
"""BLAS runs on one thread in the command (:func:`masonry.forking.use_one_blas_thread`,
which limits the libraries loaded when it runs): these say so to the libraries that load
later, as the solvers import scipy's only when a command solves."""


def main(argv=None) -> int:
    if argv is None:  # the command itself, not a host calling it: its own environment
        for name in BLAS_THREADS:
            os.environ[name] = "1"
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv == ["--version"]:
        from masonry import __version__

        try:
            print(f"masonry {__version__}", flush=True)
        except BrokenPipeError:
            silence_stdout()
        return 0
    try:
        from . import interrupts

        with interrupts.heard():
            from . import app

            return app.main(argv)
    except KeyboardInterrupt as interrupt:  # before the command's own handling, or after
        from .interrupts import interrupted  # loaded again if the interrupt stopped it

        return interrupted(interrupt)


if __name__ == "__main__":
    sys.exit(main())
