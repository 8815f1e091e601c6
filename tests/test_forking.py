"""Calls made in a forked process (masonry.forking): results, errors, ends."""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from masonry import forking

pytestmark = pytest.mark.skipif(not forking.can_fork(), reason="needs fork")


def refuse():
    raise TypeError("refused")


class Refuses:
    """Pickles, but does not unpickle."""

    def __reduce__(self):
        return refuse, ()


def unpicklable_error():
    error = ValueError("the original message")
    error.lock = threading.Lock()
    raise error


def test_results_come_back_in_order_and_an_error_is_raised_here():
    with forking.Forked([lambda: os.getpid(), lambda: [1, 2], lambda: 1 / 0]) as forked:
        assert forked.result() != os.getpid()
        assert forked.result() == [1, 2]
        with pytest.raises(ZeroDivisionError):
            forked.result()


@pytest.mark.parametrize("call, message", [
    (unpicklable_error, "the original message"),
    (lambda: threading.Lock(), "cannot pickle"),
    (lambda: Refuses(), "does not unpickle: TypeError: refused"),
    (lambda: os._exit(3), "ended without its result (exit code 3)"),
])
def test_what_cannot_come_back_is_a_runtime_error_that_says_why(call, message):
    with forking.Forked([call]) as forked:
        with pytest.raises(RuntimeError, match=message.replace("(", r"\(").replace(")", r"\)")):
            forked.result()


def test_a_cancelled_process_is_gone():
    forked = forking.Forked([lambda: time.sleep(60)]).start()
    process = forked.process
    forked.close(cancel=True)
    assert not process.is_alive() and process.exitcode == -signal.SIGTERM


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG")
def test_the_forked_process_ends_with_a_killed_parent():
    script = ("import sys, time\n"
              "from masonry import forking\n"
              "forked = forking.Forked([lambda: time.sleep(60)]).start()\n"
              "print(forked.process.pid, flush=True)\n"
              "time.sleep(60)\n")
    parent = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                              text=True)
    child = int(parent.stdout.readline())
    parent.kill()
    parent.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        time.sleep(0.05)
    else:
        os.kill(child, signal.SIGKILL)
        pytest.fail("the forked process outlived its killed parent")
