"""The process's cores: work on the second core, and BLAS's threads.

A forked process shares this one's memory at the moment of the fork (copy on write), so
it needs nothing pickled to start: the calls are closures over what this process
already holds. Only their results travel back, pickled through a pipe. The run's
exporters use it (the printable body and the model's plots beside the other files) and
so does the rigid block equilibrium (friction+ beside friction-net,
:mod:`masonry.rbe.solve`), and :func:`two_at_once` splits independent solves (a collapse
search's azimuths, the construction stages) over two processes.

The solvers (:mod:`masonry.rbe.solvers`) neither fork nor set threads: the analyses that
call them decide, from :func:`cores` or the cores their caller gives them, and run them
inside :func:`one_blas_thread`; the command line sets one BLAS thread for the whole
process (:func:`use_one_blas_thread`).
"""

import contextlib
import ctypes
import functools
import logging
import multiprocessing
import os
import signal
import sys
import traceback


HELD_SIGNALS = {signal.SIGINT, signal.SIGTERM}
"""The signals that end a run (Ctrl-C, ``kill``): held while the process forks."""

PR_SET_PDEATHSIG = 1
"""Linux ``prctl`` option: the signal a process gets when its parent ends (prctl.h)."""

TWO_AT_ONCE_BLOCKS = 500
"""Models of at least this many free blocks split their independent solves over two
processes (:func:`two_at_once`): a collapse LP of preset 1's full dome, or a stage of its
section, does far more on the second core than its factorization's second thread does
there (``docs/bench.md``, "Two azimuths, or two stages, at once"); on smaller models the
fork costs more than their solves."""

log = logging.getLogger(__name__)

_one_core = False  # set by on_one_core()


def can_fork() -> bool:
    """Whether a second process can start as a copy of this one: fork exists and is safe
    (not on macOS, whose system libraries do not survive it) and this process may have
    children (a daemonic worker of a process pool may not)."""
    return ("fork" in multiprocessing.get_all_start_methods() and sys.platform != "darwin"
            and not multiprocessing.current_process().daemon)


def cores() -> int:
    """The cores this process may run on (all of the machine's where the system does
    not say: macOS, Windows); one inside :func:`on_one_core`."""
    if _one_core:
        return 1
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def usable_cores(limit=None) -> int:
    """The cores a caller may use: :func:`cores`, at most ``limit`` (None: no limit)."""
    return cores() if limit is None else max(1, min(int(limit), cores()))


@functools.cache
def _blas_controller():
    """The BLAS libraries loaded (numpy's and scipy's), found once: a
    ``threadpoolctl.ThreadpoolController``."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def use_one_blas_thread():
    """Run BLAS on one thread for the rest of the process (the command line and sweep
    workers call this first).

    A factorization makes thousands of small BLAS calls; with a BLAS thread per core
    every call waits for its threads, and idle BLAS threads spin on the other cores
    (measured in ``docs/bench.md``, "In brief"). The cores are used by factoring independent
    subtrees on threads instead (:meth:`masonry.rbe.solvers.cholesky.BlockCholesky.factor`).
    Clarabel, OSQP and HiGHS have their own threads.
    """
    _blas_controller().limit(limits=1, user_api="blas")


def one_blas_thread():
    """A context in which BLAS runs on one thread (see :func:`use_one_blas_thread`): the
    analyses solve inside it when the library is used without the command line."""
    return _blas_controller().limit(limits=1, user_api="blas")


@contextlib.contextmanager
def on_one_core():
    """Within it, this process (and any forked from it) counts one core: another process
    of the same job works on the other, so neither starts threads or processes of its
    own. A flag of the process: enter it from one thread."""
    global _one_core
    before, _one_core = _one_core, True
    try:
        yield
    finally:
        _one_core = before


def two_at_once(function, items, blocks: int) -> list:
    """``[function(item) for item in items]`` on two cores: every second item in a forked
    copy of this process, the others here, each process on one core
    (:func:`on_one_core`). In order. All here on a model of fewer than
    :data:`TWO_AT_ONCE_BLOCKS` free ``blocks``, or when the process cannot fork or has
    one core; with a warning, all here when the fork cannot start, and the forked share
    here when its process ends without a result (:class:`ForkFailed`). An error of
    ``function`` is raised here, from whichever process made it."""
    items = list(items)
    if (len(items) < 2 or blocks < TWO_AT_ONCE_BLOCKS or not can_fork()
            or cores() < 2):
        return [function(item) for item in items]
    with on_one_core():
        split = _split(function, items)
    if split is None:  # on the cores this process has
        return [function(item) for item in items]
    mine, done = split
    if done is None:
        done = [function(item) for item in items[1::2]]
    out = [None] * len(items)
    out[0::2], out[1::2] = mine, done
    return out


class Shared:
    """``make(0)`` to ``make(count - 1)`` shared between this process and a forked copy:
    each takes the next index that neither has taken (a counter in shared memory), so
    the two finish about together whatever each call costs; order the calls longest
    first. All here when the process cannot fork, has one core or has fewer than two
    calls to share, and, with a warning, when the fork cannot start.

    Used as a context manager: :meth:`take` gives this process's next index (None when
    none is left); :meth:`theirs` then returns the other's results, ``{index: result}``,
    and makes here what it took but did not return when its process failed
    (:class:`ForkFailed`). An error of ``make`` in the other process is raised there.
    """

    def __init__(self, make, count):
        self.make, self.count = make, count
        self.forked, self.next, self.mine = None, None, []

    def __enter__(self):
        context = multiprocessing.get_context("fork") if can_fork() else None
        if context is None or self.count < 2 or cores() < 2:
            return self
        self.next = context.Value("i", 0)
        self.forked = Forked([self._serve])
        try:
            self.forked.start()
        except OSError as error:  # no memory or processes left for a fork
            log.warning("the second core is out of reach (%s): one process does all", error)
            self.forked = None
        return self

    @property
    def forked_off(self) -> bool:
        """Whether a forked process shares the calls."""
        return self.forked is not None

    def take(self):
        """This process's next index, None when every one is taken."""
        if self.forked is None:  # all here
            index = len(self.mine)
        else:
            with self.next.get_lock():
                index = self.next.value
                self.next.value = min(index + 1, self.count)
        if index >= self.count:
            return None
        self.mine.append(index)
        return index

    def _serve(self) -> dict:
        """In the forked process: make every index it takes."""
        done = {}
        while (index := self.take()) is not None:
            done[index] = self.make(index)
        return done

    def theirs(self) -> dict:
        """The other process's results, ``{index: result}`` (empty when all were made
        here); call it once this process takes no more."""
        if self.forked is None:
            return {}
        try:
            return self.forked.result()
        except ForkFailed as error:
            log.warning("the second process failed (%s): its share is done here", error)
            return {index: self.make(index) for index in range(self.count)
                    if index not in self.mine}

    def __exit__(self, kind, error, trace):
        if self.forked is not None:
            self.forked.close(cancel=kind is not None)
        return False


def _split(function, items):
    """:func:`two_at_once`'s work shared with a forked process: (this process's results,
    the other's or None when its process failed), or None when it could not start."""
    theirs = Forked([lambda: [function(item) for item in items[1::2]]])
    try:
        theirs.start()
    except OSError as error:  # no memory or processes left for a fork
        log.warning("the second core is out of reach (%s): one process does all", error)
        return None
    try:
        mine = [function(item) for item in items[0::2]]
        try:
            done = theirs.result()
        except ForkFailed as error:
            log.warning("the second process failed (%s): its share is done here", error)
            done = None
    except BaseException:
        theirs.close(cancel=True)
        raise
    theirs.close()
    return mine, done


class ForkFailed(RuntimeError):
    """A forked process ended without a result, or its result or error could not come
    back (not an error raised by the call itself)."""


class Forked:
    """Makes ``calls`` (callables without arguments) in order in a forked process;
    :meth:`result` receives the next one's return value. Used as a context manager it
    starts on entering and, on leaving, waits for the process (or ends it, on an error
    or an interrupt); :meth:`start` and :meth:`close` do the same by hand.

    The process stops at the first call that raises: :meth:`result` raises that error
    here (a :class:`ForkFailed` with its traceback when it does not pickle, and when
    the process ends without a result). On Linux the process ends with the one that
    forked it, even when that one is killed.
    """

    def __init__(self, calls):
        self.calls, self.process = list(calls), None
        self.exitcode = None  # the process's, once closed (-N: ended by signal N)

    @property
    def started(self) -> bool:
        """Whether the process started (it may have ended since)."""
        return self.process is not None and (self.exitcode is not None
                                             or self.process.pid is not None)

    def start(self) -> "Forked":
        context = multiprocessing.get_context("fork")
        self.receiver, sender = context.Pipe(duplex=False)
        self.process = context.Process(target=_serve, daemon=True,
                                       args=(self.calls, self.receiver, sender, os.getpid()))
        try:
            # a signal during the fork would reach its handler inside the fork's own
            # callbacks, which drop the handler's exception: this thread takes it once
            # forked (another thread may take it meanwhile: the command makes a dropped
            # interrupt arrive again, masonry_cli.interrupts)
            signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS)
            try:
                self.process.start()
            finally:
                signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD_SIGNALS)
        except BaseException:  # interrupted as it started
            self.close(cancel=True)
            raise
        finally:  # closed here: a finalizer would drop an interrupt raised as it closes
            sender.close()
        return self

    def result(self):
        """The next call's return value; its error, raised here, if it failed."""
        try:
            ok, value = self.receiver.recv()
        except EOFError:
            self.process.join()
            raise ForkFailed(f"the forked process ended without its result (exit code "
                             f"{self.process.exitcode})") from None
        except Exception as error:  # pickled there, but does not unpickle here
            raise ForkFailed(f"the forked process's result does not unpickle: "
                             f"{type(error).__name__}: {error}") from None
        if not ok:
            raise value
        return value

    def close(self, cancel=False):
        """Wait for the process to end, or end it first (``cancel``)."""
        if self.process is None:
            return
        if self.exitcode is None and self.process.pid is not None:  # started, not closed
            if cancel:
                self.process.terminate()
            self.process.join()
            self.exitcode = self.process.exitcode
            self.process.close()  # its pipes closed here, not by a finalizer (as above)
        self.receiver.close()

    def __enter__(self):
        return self.start() if self.calls else self

    def __exit__(self, kind, error, trace):
        self.close(cancel=kind is not None)
        return False


def _serve(calls, receiver, sender, parent):
    """In the forked process: make each call and send its result, or its error. An
    interrupt or a terminate ends it without a word (the handlers copied by the fork
    are for the process that reports), and so does the end of the process that forked
    it: on Linux the kernel kills it then (``PR_SET_PDEATHSIG``), elsewhere its next
    send finds the pipe broken."""
    receiver.close()
    for held in HELD_SIGNALS:
        signal.signal(held, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD_SIGNALS)
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # it died before the request
            os._exit(1)
    for call in calls:
        try:
            outcome = (True, call())
        except Exception as error:
            outcome = (False, error)
        try:
            sender.send(outcome)
        except OSError:  # the process that forked this one did not wait for it
            return
        except Exception:  # an error or a result that does not pickle: the text
            error = outcome[1] if not outcome[0] else sys.exception()
            text = "".join(traceback.format_exception(error))
            sender.send((False, ForkFailed(f"in the forked process:\n{text}")))
            return
        if not outcome[0]:
            return
    sender.close()
