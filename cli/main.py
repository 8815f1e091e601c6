"""Entry point of the ``masonry`` command. ``main(argv)`` returns the exit code.

The command itself is :mod:`masonry_cli.app`. It is imported here, inside ``main``, so
that Ctrl-C while numpy, scipy and the solvers load (a second or two) ends as an
interruption like any other, with exit code 130 and no traceback.
"""

import sys


def main(argv=None) -> int:
    try:
        from masonry_cli import app
    except KeyboardInterrupt:
        print("masonry: interrupted while starting", file=sys.stderr)
        return 130
    return app.main(argv)


if __name__ == "__main__":
    sys.exit(main())
