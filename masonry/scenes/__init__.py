"""Scenes: what one run models, as :class:`~masonry.blocks.Blocks` (docs/model.md 4.6).

Every kind of scene is a :class:`~masonry.scenes.base.SceneKind` in a module of its own,
listed once in :data:`KINDS`:

- ``section``: one web of the polygonal dome, facing +x, on a ground slab
  (:mod:`.polygonal`); ``dome``: all ``n`` webs explicitly (:mod:`.polygonal`).
- ``wall``: a straight running-bond wall on a ground slab, for validation (:mod:`.wall`).
- ``arch``: voussoirs on two supports (:mod:`.arch`).
- ``revolution``: the dome of revolution, courses as rings and the pattern as
  loxodromes; ``sector``: one of its sectors (:mod:`.revolution`).
- ``assembly``: blocks read from mesh files (:mod:`.mesh_files` reads them,
  :mod:`.imported` checks them; built by :func:`~masonry.scenes.imported.load_assembly`,
  not from parameters alone).

:class:`~masonry.scenes.base.Scene` is what every kind builds.
"""

import math

from masonry.errors import ParameterError
from masonry.scenes.arch import Arch
from masonry.scenes.base import Scene, SceneKind
from masonry.scenes.imported import Assembly
from masonry.scenes.polygonal import Dome, Section
from masonry.scenes.revolution import Revolution, Sector
from masonry.scenes.wall import Wall
from masonry.tolerances import BYTES_PER_BRICK, MAX_BRICKS, RUN_BYTES

KINDS = {kind.name: kind for kind in (Section, Wall, Dome, Assembly, Arch, Revolution, Sector)}
"""Scene name -> its :class:`~masonry.scenes.base.SceneKind`."""

__all__ = ["KINDS", "Scene", "SceneKind", "build", "check_size", "kind_of", "memory_estimate"]


def kind_of(name: str) -> type:
    """The scene kind named ``name`` (:data:`KINDS`); raises
    :class:`~masonry.errors.ParameterError` naming ``scene``."""
    try:
        return KINDS[name]
    except (KeyError, TypeError):
        raise ParameterError("scene", name, f"one of {', '.join(KINDS)}") from None


def build(params) -> Scene:
    """The scene of ``params`` (:class:`~masonry.params.Params`: its scene kind and
    geometry)."""
    return params.kind.build(params.geometry)


def check_size(params, max_bricks=MAX_BRICKS) -> float:
    """Refuse a model larger than ``max_bricks`` before building it; returns the
    estimate (:meth:`~masonry.scenes.base.SceneKind.estimate_blocks`).

    Raises
    ------
    ParameterError
        Named ``max_bricks``: how large the model would be and its memory.
    """
    bricks = params.kind.estimate_blocks(params.geometry)
    if not bricks <= max_bricks:
        memory = memory_estimate(bricks, params.analysis.accuracy) / 2**30
        raise ParameterError(
            "max_bricks", max_bricks,
            f"a model of at most {max_bricks:,} blocks: this one would have about "
            f"{_about(bricks)} (about {memory:.2g} GiB of memory to solve, if it stands); raise "
            f"--max-bricks to build it anyway")
    return bricks


def memory_estimate(bricks: float, accuracy: str) -> float:
    """The peak memory, bytes, of a run (``masonry run`` without plots) of ``bricks``
    bricks that stands, at the ``accuracy`` preset: :data:`~masonry.tolerances.RUN_BYTES`
    and :data:`~masonry.tolerances.BYTES_PER_BRICK` of the preset for each brick."""
    return RUN_BYTES + bricks * BYTES_PER_BRICK[accuracy]


def _about(value: float) -> str:
    if not math.isfinite(value):
        return "more than can be counted"
    return f"{value:,.0f}" if value < 1e7 else f"{value:.1e}"
