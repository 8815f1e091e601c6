"""Scenes: what one run models, as :class:`~masonry.blocks.Blocks` (SPEC 4.6).

- ``section``: one web of the dome, facing +x, on a ground slab (:mod:`.section`).
- ``dome``: all ``n`` webs explicitly (:mod:`.section`).
- ``wall``: a straight running-bond wall on a ground slab, for validation (:mod:`.wall`).
- ``arch``: voussoirs on two supports (:mod:`.arch`).
- ``assembly``: blocks read from mesh files (:mod:`.imported`, built by
  :func:`~masonry.scenes.imported.load_assembly`, not from parameters alone).

:class:`~masonry.scenes.base.Scene` is what every builder returns.
"""

import math

import numpy as np

from masonry.dome.levels import Dimensions
from masonry.params import ParameterError, Params
from masonry.scenes.arch import build_arch
from masonry.scenes.base import Scene
from masonry.scenes.section import build_dome, build_section
from masonry.scenes.wall import build_wall
from masonry.tolerances import BYTES_PER_BRICK, MAX_BRICKS, UNITS_PER_BRICK

BUILDERS = {"section": build_section, "wall": build_wall, "dome": build_dome,
            "arch": build_arch}
"""Scene name -> builder of a :class:`Scene` from :class:`~masonry.params.Params`."""


def build(params: Params) -> Scene:
    """The scene ``params.scene`` asks for."""
    try:
        builder = BUILDERS[params.scene]
    except KeyError:
        raise NotImplementedError(f"scene {params.scene!r} is not built from parameters "
                                  "alone") from None
    return builder(params)


def estimate_bricks(params: Params) -> float:
    """The number of blocks ``params`` would build, from its dimensions alone (without
    building anything): exact for the arch, within a factor 1.4 for a dome section.

    The section's count is its intrados area (the web's width integrated along the
    quarter ellipse) over :data:`~masonry.tolerances.UNITS_PER_BRICK`; the dome has ``n``
    sections.
    """
    p = params
    if p.scene == "arch":
        return float(p.arch_blocks)
    if p.scene == "wall":
        return p.wall_courses * (p.wall_length / 4 + 1)
    if p.scene not in ("section", "dome"):
        return 0.0
    with np.errstate(all="ignore"):  # absurd inputs give inf, which is refused
        d = Dimensions.of(p)
        theta = np.linspace(0.0, np.arcsin(min(d.z_max / d.c, 1.0)), 257)
        width = 2 * d.a * np.cos(theta) * np.tan(np.pi / p.n)
        speed = np.hypot(d.a * np.sin(theta), d.c * np.cos(theta))
        f = width * speed
        area = np.sum((f[1:] + f[:-1]) / 2 * np.diff(theta)) / p.unit**2
    bricks = float(area) / UNITS_PER_BRICK
    return bricks * p.n if p.scene == "dome" else bricks


def check_size(params: Params, max_bricks=MAX_BRICKS) -> float:
    """Refuse a model larger than ``max_bricks`` before building it; returns the
    estimate (:func:`estimate_bricks`).

    Raises
    ------
    ParameterError
        Named ``max_bricks``: how large the model would be and its memory.
    """
    bricks = estimate_bricks(params)
    if not bricks <= max_bricks:
        memory = bricks * BYTES_PER_BRICK / 2**30
        raise ParameterError(
            "max_bricks", max_bricks,
            f"a model of at most {max_bricks:,} blocks: this one would have about "
            f"{_about(bricks)} (about {memory:.2g} GiB of memory to solve); raise "
            f"--max-bricks to build it anyway")
    return bricks


def _about(value: float) -> str:
    if not math.isfinite(value):
        return "more than can be counted"
    return f"{value:,.0f}" if value < 1e7 else f"{value:.1e}"
