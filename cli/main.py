"""Entry point of the ``masonry`` command. ``main(argv)`` returns the exit code.

The command itself is :mod:`masonry_cli.app`. It is imported here, inside ``main``, so
that Ctrl-C while numpy, scipy and the solvers load (a second or two) ends as an
interruption like any other, with exit code 130 and no traceback. ``--version`` answers
without it.
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
        from masonry_cli import app
    except KeyboardInterrupt:
        print("masonry: interrupted while starting", file=sys.stderr)
        return 130
    return app.main(argv)


if __name__ == "__main__":
    sys.exit(main())
