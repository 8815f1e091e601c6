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
    pid = forked.process.pid
    forked.close(cancel=True)
    assert forked.exitcode == -signal.SIGTERM
    with pytest.raises(ChildProcessError):  # reaped: no zombie left
        os.waitpid(pid, os.WNOHANG)
    forked.close()  # a second close changes nothing
    assert forked.started


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


def test_two_at_once_gives_every_second_item_to_another_process_in_order(two_processes):
    here = os.getpid()
    out = forking.two_at_once(lambda item: (item * item, os.getpid(), forking.cores()),
                              range(5), blocks=1)
    assert [square for square, _, _ in out] == [0, 1, 4, 9, 16]
    pids = [pid for _, pid, _ in out]
    assert pids[0::2] == [here] * 3 and len(set(pids[1::2])) == 1 and pids[1] != here
    # each process counts one core while they share two, this one two again after
    assert [count for _, _, count in out] == [1] * 5 and forking.cores() == 2


def test_two_at_once_does_the_share_of_a_process_that_ends_without_a_result_here(
        two_processes, caplog):
    here = os.getpid()

    def square(item):
        if os.getpid() != here:
            os._exit(3)
        return item * item

    assert forking.two_at_once(square, range(4), blocks=1) == [0, 1, 4, 9]
    assert ("the second process failed (the forked process ended without its result "
            "(exit code 3)): its share is done here") in caplog.text
    assert forking.cores() == 2  # the process's own cores again


def test_an_error_of_the_function_in_the_other_process_is_raised_here(two_processes):
    here = os.getpid()

    def square(item):
        if os.getpid() != here:
            raise ValueError(f"no square of {item}")
        return item * item

    with pytest.raises(ValueError, match="no square of 1"):
        forking.two_at_once(square, range(4), blocks=1)
    assert len(two_processes) == 1


def test_two_at_once_does_all_here_when_the_fork_cannot_start(two_processes, monkeypatch,
                                                                caplog):
    def no_fork(self):
        raise OSError("no processes left")

    monkeypatch.setattr(forking.Forked, "start", no_fork)
    assert forking.two_at_once(lambda item: (item, os.getpid(), forking.cores()),
                               range(3), blocks=1) == [(i, os.getpid(), 2) for i in range(3)]
    assert "the second core is out of reach (no processes left)" in caplog.text


def test_two_at_once_inside_two_at_once_stays_in_its_process(two_processes):
    inner = forking.two_at_once(
        lambda item: forking.two_at_once(lambda _: os.getpid(), range(3), blocks=1), range(2),
        blocks=1)
    assert all(len(set(pids)) == 1 for pids in inner)  # no process of its own
    assert inner[0][0] != inner[1][0] and len(two_processes) == 1


def test_two_at_once_on_one_core_does_all_here(monkeypatch):
    monkeypatch.setattr(forking, "cores", lambda: 1)
    assert forking.two_at_once(lambda item: os.getpid(), range(3), blocks=1) == [os.getpid()] * 3


def test_shared_calls_are_each_made_once_by_one_of_two_processes(monkeypatch):
    monkeypatch.setattr(forking, "cores", lambda: 2)

    def make(index):
        time.sleep(0.05)  # long enough for both processes to take some
        return index * index, os.getpid()

    mine = {}
    with forking.Shared(make, 9) as shared:
        while (index := shared.take()) is not None:
            mine[index] = make(index)
        theirs = shared.theirs()
    assert sorted([*mine, *theirs]) == list(range(9)) and theirs and mine
    assert {pid for _, pid in theirs.values()} != {os.getpid()}
    assert {**mine, **theirs} == {i: (i * i, pid) for i, (_, pid) in {**mine, **theirs}.items()}


def test_shared_calls_all_here_on_one_core_and_after_a_failed_fork(monkeypatch):
    monkeypatch.setattr(forking, "cores", lambda: 1)
    with forking.Shared(lambda index: index, 3) as shared:
        assert [shared.take() for _ in range(4)] == [0, 1, 2, None]
        assert shared.theirs() == {}
    monkeypatch.setattr(forking, "cores", lambda: 2)
    pid = os.getpid()

    def make(index):
        if os.getpid() != pid:
            os._exit(3)  # the other process dies without a result
        return index

    with forking.Shared(make, 6) as shared:
        mine = []
        while (index := shared.take()) is not None:
            time.sleep(0.05)
            mine.append(make(index))
        theirs = shared.theirs()  # the other's share made here
    assert sorted(mine + list(theirs)) == list(range(6)) and theirs
    assert all(value == index for index, value in theirs.items())


def test_an_error_of_a_shared_call_in_the_other_process_is_raised_here(monkeypatch):
    monkeypatch.setattr(forking, "cores", lambda: 2)
    pid = os.getpid()

    def make(index):
        if os.getpid() != pid:
            raise ValueError(f"call {index} failed")
        time.sleep(0.2)
        return index

    with forking.Shared(make, 4) as shared:
        while (index := shared.take()) is not None:
            make(index)
        with pytest.raises(ValueError, match="failed"):
            shared.theirs()
