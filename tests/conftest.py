"""Shared fixtures: built scenes are cached per session (building is cheap, but many tests
look at the same presets)."""

import functools
import os
from pathlib import Path

import pytest

os.environ.setdefault("OMP_NUM_THREADS", "1")

from masonry.params import from_preset  # noqa: E402
from masonry.scenes import build  # noqa: E402

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures"
PRESETS = ("1", "2", "3")


@functools.lru_cache(maxsize=None)
def scene_of(preset, **overrides):
    return build(from_preset(preset, **overrides))


@pytest.fixture(scope="session")
def fixtures_dir():
    return FIXTURES
