"""The ``wall`` scene: a straight running-bond wall on a ground slab (validation, thesis
3.3.6)."""

from dataclasses import dataclass

import numpy as np

from masonry.dome.courses import fill_courses
from masonry.dome.levels import LevelTable
from masonry.dome.pattern import Pattern
from masonry.parameters import declare
from masonry.scenes.base import Scene, SceneKind, hexahedra_frames
from masonry.scenes.bricks import blocks_from_layout, posed_corners

MIN_FILL = 1.0
"""Units: the shortest fill-in brick of the wall's courses (docs/model.md 4.4)."""


@dataclass(frozen=True)
class WallGeometry:
    """A straight vertical running-bond wall: ``wall_length`` units long,
    ``wall_courses`` courses high, bricks of ``unit`` metres."""

    wall_length: float = declare(32.0, "units", check=lambda v: v >= 4, tag="L", head=True,
                                 names_geometry=True,
                                 expected=">= 4 (units, one regular brick)")
    wall_courses: int = declare(10, "courses", kind="int", check=lambda v: v >= 1, tag="k",
                                head=True, names_geometry=True, expected="an integer >= 1")
    unit: float = declare(0.1, "m, the brick unit", low=1e-3, high=1e2, tag="u", head=True,
                          names_geometry=True,
                          expected="0.001 to 100 (metres: bricks of 1 mm to 100 m; forces "
                                   "scale with unit^3)")


def build_wall(params: WallGeometry) -> Scene:
    """A straight vertical running-bond wall on a ground slab (thesis 3.3.6)."""
    u = params.unit
    count = params.wall_courses
    half = params.wall_length / 2
    half_width = np.full(count, half)
    layout = fill_courses(half_width, Pattern.none(), MIN_FILL, miter=False)
    levels = LevelTable(
        theta=np.zeros(count + 1), x=np.zeros(count + 1), y=np.full(count + 1, half * u),
        z=np.arange(count + 1) * u, gamma_reg=np.zeros(count), gamma_pat=np.zeros(count),
        pattern_height=np.full(count, 2 * u))
    ground = posed_corners(np.array([[0.0, -u]]), np.zeros(1), np.array([2 * u]),
                           np.array([u]), np.array([-half * u]), np.array([half * u]),
                           np.full(1, np.nan), np.full(1, np.nan))[0]
    blocks = blocks_from_layout(layout, levels, u, np.nan, ground)
    return Scene(Wall, params, blocks, levels, None, layout, None, *hexahedra_frames(blocks))


class Wall(SceneKind):
    """``wall``: a straight running-bond wall, for validation."""

    name = "wall"
    geometry = WallGeometry
    id_prefix_name = "wall"
    summary = "a straight running-bond wall, for validation"

    @classmethod
    def build(cls, geometry) -> Scene:
        return build_wall(geometry)

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        return geometry.wall_courses * (geometry.wall_length / 4 + 1)
