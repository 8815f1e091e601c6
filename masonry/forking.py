"""Work on the second core: calls made in a forked copy of this process.

A forked process shares this one's memory at the moment of the fork (copy on write), so
it needs nothing pickled to start: the calls are closures over what this process
already holds. Only their results travel back, pickled through a pipe. The run's
exporters use it (the 3DM file and the plots beside the other files) and so does the
rigid block equilibrium (friction+ beside friction-net, :mod:`masonry.rbe.solve`).
"""

import multiprocessing
import os
import signal
import sys
import traceback

HELD_SIGNALS = {signal.SIGINT, signal.SIGTERM}
"""The signals that end a run (Ctrl-C, ``kill``): held while the process forks."""


def can_fork() -> bool:
    """Whether a second process can start as a copy of this one: fork exists and is safe
    (not on macOS, whose system libraries do not survive it) and this process may have
    children (a daemonic worker of a process pool may not)."""
    return ("fork" in multiprocessing.get_all_start_methods() and sys.platform != "darwin"
            and not multiprocessing.current_process().daemon)


def cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1


class Forked:
    """Makes ``calls`` (callables without arguments) in order in a forked process;
    :meth:`result` receives the next one's return value. Used as a context manager it
    starts on entering and, on leaving, waits for the process (or ends it, on an error
    or an interrupt); :meth:`start` and :meth:`close` do the same by hand.

    The process stops at the first call that raises: :meth:`result` raises that error
    (its text, if it does not pickle) here.
    """

    def __init__(self, calls):
        self.calls, self.process = list(calls), None

    @property
    def started(self) -> bool:
        return self.process is not None

    def start(self) -> "Forked":
        context = multiprocessing.get_context("fork")
        self.receiver, sender = context.Pipe(duplex=False)
        self.process = context.Process(target=_serve, daemon=True,
                                       args=(self.calls, self.receiver, sender))
        try:
            # a signal during the fork would reach its handler inside the fork's own
            # callbacks, which swallow the handler's exception: it waits for the fork
            signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS)
            try:
                self.process.start()
            finally:
                signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD_SIGNALS)
            sender.close()
        except BaseException:  # interrupted as it started
            self.close(cancel=True)
            raise
        return self

    def result(self):
        """The next call's return value; its error, raised here, if it failed."""
        try:
            ok, value = self.receiver.recv()
        except EOFError:
            raise RuntimeError(f"the forked process ended without its result (exit code "
                               f"{self.process.exitcode})") from None
        if not ok:
            raise value
        return value

    def close(self, cancel=False):
        """Wait for the process to end, or end it first (``cancel``)."""
        if self.process is None:
            return
        if self.process.pid is not None:  # started
            if cancel:
                self.process.terminate()
            self.process.join()
        self.receiver.close()

    def __enter__(self):
        return self.start() if self.calls else self

    def __exit__(self, kind, error, trace):
        self.close(cancel=kind is not None)
        return False


def _serve(calls, receiver, sender):
    """In the forked process: make each call and send its result, or its error. An
    interrupt or a terminate ends it without a word (the handlers copied by the fork
    are for the process that reports), and so does the end of the process that forked
    it (its pipe breaks: this process holds no reading end of its own)."""
    receiver.close()
    for held in HELD_SIGNALS:
        signal.signal(held, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD_SIGNALS)
    for call in calls:
        try:
            outcome = (True, call())
        except Exception as error:
            outcome = (False, error)
        try:
            sender.send(outcome)
        except OSError:  # the process that forked this one did not wait for it
            return
        except Exception:  # an error or a result that does not pickle: its text
            sender.send((False, RuntimeError(traceback.format_exc())))
            return
        if not outcome[0]:
            return
    sender.close()
