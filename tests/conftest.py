"""Shared fixtures: built scenes are cached per session (building is cheap, but many tests
look at the same presets)."""

import functools
import os
from pathlib import Path

import pytest

os.environ.setdefault("OMP_NUM_THREADS", "1")

from masonry import forking  # noqa: E402
from masonry.params import from_preset  # noqa: E402
from masonry.pipeline import build_model  # noqa: E402
from masonry.scenes import build  # noqa: E402
from masonry.stages.plans import make_plan  # noqa: E402

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures"
PRESETS = ("1", "2", "3")


@functools.lru_cache(maxsize=None)
def scene_of(preset, **overrides):
    return build(from_preset(preset, **overrides))


@pytest.fixture(scope="session")
def fixtures_dir():
    return FIXTURES


@pytest.fixture
def two_processes(monkeypatch):
    """:func:`masonry.forking.two_at_once` splits whatever the model and the machine: any
    model is large enough and the system lets this process run on two cores. Returns the
    list of processes it starts."""
    monkeypatch.setattr(forking, "TWO_AT_ONCE_BLOCKS", 1)
    if hasattr(os, "sched_getaffinity"):
        monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    else:
        monkeypatch.setattr(os, "cpu_count", lambda: 2)
    forks = []
    start = forking.Forked.start
    monkeypatch.setattr(forking.Forked, "start", lambda self: forks.append(self) or start(self))
    return forks


def support_force(interfaces, forces, mask):
    """(3,) newtons: the total force the main blocks of ``mask``'s interfaces (the
    supports) exert on the blocks they carry: normal and friction components."""
    n, t1, t2 = interfaces.normal[mask], interfaces.t1[mask], interfaces.t2[mask]
    return (-forces["normal"][mask, None] * n + forces["t1"][mask, None] * t1
            + forces["t2"][mask, None] * t2).sum(axis=0)


@pytest.fixture(scope="session")
def top_course():
    """The last but one course of preset 1's cyclic section at p = 4 (230 blocks, 28
    courses), laid brick by brick pattern-first: its stages 1 and 3 to 5 cannot stand
    dry (their beds lean 60 degrees); stage 2 stands."""
    params = from_preset("1", boundary="cyclic", p=4)
    scene, model = build_model(params)
    return model, make_plan(scene, "brick", "pattern-first", 27)
