"""The ``wall`` scene: a straight running-bond wall on a ground slab (validation, thesis
3.3.6)."""

import numpy as np

from masonry.dome.courses import fill_courses
from masonry.dome.levels import LevelTable
from masonry.dome.pattern import Pattern
from masonry.params import Params
from masonry.scenes.base import Scene, hexahedra_frames
from masonry.scenes.bricks import blocks_from_layout, posed_corners


def build_wall(params: Params) -> Scene:
    """A straight vertical running-bond wall on a ground slab (thesis 3.3.6)."""
    u = params.unit
    count = params.wall_courses
    half = params.wall_length / 2
    half_width = np.full(count, half)
    empty = np.zeros(0, int)
    no_pattern = Pattern(empty, empty, empty, *[np.zeros((0, 2), int)] * 4)
    layout = fill_courses(half_width, no_pattern, params.min_fill, miter=False)
    levels = LevelTable(
        theta=np.zeros(count + 1), x=np.zeros(count + 1), y=np.full(count + 1, half * u),
        z=np.arange(count + 1) * u, gamma_reg=np.zeros(count), gamma_pat=np.zeros(count),
        pattern_height=np.full(count, 2 * u))
    ground = posed_corners(np.array([[0.0, -u]]), np.zeros(1), np.array([2 * u]),
                           np.array([u]), np.array([-half * u]), np.array([half * u]),
                           np.full(1, np.nan), np.full(1, np.nan))[0]
    blocks = blocks_from_layout(layout, levels, u, np.nan, ground)
    return Scene(params, blocks, levels, None, layout, None, *hexahedra_frames(blocks))
