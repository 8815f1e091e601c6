"""How the command ends on an interrupt: Ctrl-C (SIGINT) and ``kill`` (SIGTERM) unwind
the run as an exception, so that it cleans up, and end it with one line and the shell's
exit code for the signal.

Python runs a signal's handler in whatever Python code the main thread runs next, and
that may be a ``__del__`` method or a weakref finalizer (multiprocessing closes a forked
process's pipes in both): an exception raised there is printed as "Exception ignored"
and dropped, and the run would go on as if never interrupted. :func:`heard` makes the
signal arrive again, so that its exception is raised where the run can unwind.
"""

import _thread
import signal
import sys
import threading
from contextlib import contextmanager

from masonry.optional import interrupt_of

EXIT_CODES = {signal.SIGINT: 130, signal.SIGTERM: 143}
"""Exit code of a command ended by the signal: 128 + its number, as a shell reports a
process the signal killed."""


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, ``timeout``), handled like Ctrl-C: runs unwind and clean up."""


def signal_of(interrupt: BaseException) -> int:
    """The signal ``interrupt`` was raised for: SIGTERM for :class:`Terminated`, else
    SIGINT."""
    return signal.SIGTERM if isinstance(interrupt, Terminated) else signal.SIGINT


def interrupted(interrupt: BaseException) -> int:
    """Say that the command was interrupted, in one line on stderr; returns its exit code
    (:data:`EXIT_CODES`)."""
    print("masonry: interrupted; the previous output is untouched", file=sys.stderr)
    return EXIT_CODES[signal_of(interrupt)]


def interrupt_behind(error: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C or SIGTERM that ``error`` was made from (an extension module's loader
    raises an ``ImportError`` from it: :mod:`masonry.optional`), or None."""
    interrupt = interrupt_of(error)
    return interrupt if isinstance(interrupt, KeyboardInterrupt) else None


def _terminate(signum, frame):
    raise Terminated()


@contextmanager
def heard():
    """Within it, SIGTERM raises :class:`Terminated`, and an interrupt Python drops
    (raised in a ``__del__`` method or a finalizer) is not printed but made to arrive
    again (``_thread.interrupt_main``), to be raised in the code that runs next. Only on
    the main thread, where signals are handled: elsewhere it changes nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    handler, hook = signal.signal(signal.SIGTERM, _terminate), sys.unraisablehook

    def again(unraisable):
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            return hook(unraisable)
        signum = signal_of(unraisable.exc_value)
        while True:  # from another thread: here, the handler would run inside this hook
            try:
                _thread.start_new_thread(_thread.interrupt_main, (signum,))
                return None
            except KeyboardInterrupt as interrupt:  # it arrived before this hook returned
                signum = signal_of(interrupt)

    sys.unraisablehook = again
    try:
        yield
    finally:
        sys.unraisablehook = hook
        signal.signal(signal.SIGTERM, handler)
