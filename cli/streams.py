"""Standard output whose reader has left (``masonry run ... | head -1``)."""

import os
import sys


def silence_stdout() -> bool:
    """Point standard output's file at the null device, so that nothing more written to
    it, nor its flush at exit, fails on the closed pipe (Python's documented remedy for
    BrokenPipeError). False where stdout has no file descriptor (a host's stream)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        return False
    return True
