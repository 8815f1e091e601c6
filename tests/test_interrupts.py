"""Every interrupt is heard: Ctrl-C and SIGTERM end the command with 130 / 143 and one
line, wherever they land (while a module loads, while the command starts, inside a
finalizer), and nothing is published."""

import importlib.abc
import signal
import sys
import time

import pytest

from masonry.export import rhino
from masonry.optional import interrupt_of, optional_import
from masonry.studies import sweep
from masonry_cli import app
from masonry_cli.interrupts import Terminated, heard
from masonry_cli.main import main

WALL = ["run", "--preset", "wall", "--wall-courses", "3", "--wall-length", "12", "--fast",
        "--no-plots", "--no-printable", "-q"]
INTERRUPTED = "masonry: interrupted; the previous output is untouched"
WAIT_S = 30
"""How long a test waits for an interrupt to arrive again before it fails."""


class FailingLoader(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports of ``name`` fail as ``error()`` says: a pybind11 module's initialisation
    interrupted by Ctrl-C raises ``ImportError("initialization failed")`` from the
    ``KeyboardInterrupt``."""

    def __init__(self, name, error):
        self.name, self.error = name, error

    def find_spec(self, fullname, path, target=None):
        if fullname != self.name:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        raise self.error()


def interrupted_init():
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as interrupt:
        raise ImportError("initialization failed") from interrupt


def missing():
    raise ModuleNotFoundError("No module named 'rhino3dm'")


@pytest.fixture
def rhino3dm_fails(monkeypatch):
    """``rhino3dm_fails(error)``: the next imports of rhino3dm raise ``error()``."""
    def install(error):
        monkeypatch.delitem(sys.modules, "rhino3dm", raising=False)
        monkeypatch.setattr(sys, "meta_path", [FailingLoader("rhino3dm", error),
                                               *sys.meta_path])
    return install


def published(root):
    """The entries of an output root (run folders and leftovers), none when it is
    missing."""
    return sorted(p.name for p in root.iterdir()) if root.exists() else []


def test_the_interrupt_behind_an_import_error_is_found_through_causes_and_contexts():
    interrupt = Terminated()
    try:
        try:
            raise interrupt
        except Terminated:
            raise ValueError("while handling it") from None
    except ValueError as plain:
        # an error raised as the interrupt unwinds (a cleanup failing) is its doing
        assert interrupt_of(plain) is interrupt
    outer = ImportError("initialization failed")
    outer.__cause__ = interrupt
    interrupt.__context__ = outer  # a cycle, as re-raising the interrupt makes
    assert interrupt_of(outer) is interrupt
    assert interrupt_of(ValueError("no interrupt")) is None


def test_an_interrupt_while_rhino3dm_loads_is_raised_not_taken_for_its_absence(
        rhino3dm_fails):
    rhino3dm_fails(interrupted_init)
    with pytest.raises(KeyboardInterrupt):
        rhino.available()
    with pytest.raises(KeyboardInterrupt):
        optional_import("rhino3dm")
    rhino3dm_fails(missing)
    assert rhino.available() is False and optional_import("rhino3dm") is None


def test_a_run_interrupted_while_rhino3dm_loads_ends_130_and_publishes_nothing(
        rhino3dm_fails, tmp_path, capsys):
    rhino3dm_fails(interrupted_init)
    assert main([*WALL, "--out", str(tmp_path / "out")]) == 130
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [INTERRUPTED]
    assert "not installed" not in err
    assert published(tmp_path / "out") == []


def test_a_sweep_variant_interrupted_inside_an_import_error_stops_the_sweep(monkeypatch):
    def interrupted_run(params, out_root, analyse=True):
        interrupted_init()

    def failing_run(params, out_root, analyse=True):
        raise ValueError("a variant's own failure")

    inputs = {"scene": "wall", "wall_courses": 3, "wall_length": 12.0}
    monkeypatch.setattr(sweep, "run", failing_run)
    row = sweep.run_variant(inputs, "unused")
    assert row["status"] == "failed" and "a variant's own failure" in row["error"]
    monkeypatch.setattr(sweep, "run", interrupted_run)
    with pytest.raises(KeyboardInterrupt):
        sweep.run_variant(inputs, "unused")


class DropsSigterm:
    """SIGTERM arrives while it is collected: its handler's exception is raised inside
    ``__del__``, where Python drops it (as in a multiprocessing finalizer closing a
    forked process's pipes)."""

    def __del__(self):
        signal.raise_signal(signal.SIGTERM)


def wait_for_an_interrupt():
    """Run Python code until an interrupt is raised in it, at most :data:`WAIT_S`."""
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        time.sleep(0.01)


def test_a_sigterm_dropped_in_a_finalizer_arrives_again(capsys):
    with pytest.raises(Terminated):
        with heard():
            DropsSigterm()  # collected at once
            wait_for_an_interrupt()
    assert capsys.readouterr().err == ""  # no "Exception ignored"


def test_a_run_whose_sigterm_lands_in_a_finalizer_ends_143_and_publishes_nothing(
        monkeypatch, tmp_path, capsys):
    from masonry import pipeline

    solve = pipeline.solve

    def solve_as_sigterm_lands(*args, **kwargs):
        DropsSigterm()
        wait_for_an_interrupt()
        return solve(*args, **kwargs)

    monkeypatch.setattr(pipeline, "solve", solve_as_sigterm_lands)
    assert main([*WALL, "--out", str(tmp_path / "out")]) == 143
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [INTERRUPTED]
    assert published(tmp_path / "out") == []


@pytest.mark.parametrize("raise_signal, code", [(signal.SIGINT, 130),
                                                (signal.SIGTERM, 143)])
def test_an_interrupt_while_the_command_starts_is_one_line(monkeypatch, capsys,
                                                           raise_signal, code):
    # the command's options are built before its run catches interrupts: an interrupt
    # there (a subcommand's modules loading) is caught by the entry point
    def interrupted_parser(argv=None):
        signal.raise_signal(raise_signal)

    monkeypatch.setattr(app, "make_parser", interrupted_parser)
    # Python's own Ctrl-C handler, as a new process has it (an earlier test's library may
    # have left another in this one)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(["run", "--preset", "wall"]) == code
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capsys.readouterr().err.strip().splitlines() == [INTERRUPTED]
    assert signal.getsignal(signal.SIGTERM) is not None  # the host's handler given back
