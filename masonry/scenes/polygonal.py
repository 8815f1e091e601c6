"""The ``section`` scene (one web of the dome) and the ``dome`` scene (all ``n`` webs).

One web faces +x on its ground slab (SPEC 4.2 to 4.5): level table, pattern, courses, then
posed bricks (:mod:`masonry.scenes.bricks`). End bricks are mitered: their end face lies in
the corner plane ``y = +-x tan(pi/n)`` where this web meets the next, so ``n`` rotated
copies close into the whole dome face to face (SPEC 4.6).
"""

import dataclasses
import logging

import numpy as np

from masonry.blocks import concatenate, rotated_web, rotation_z
from masonry.dome.courses import fill_courses
from masonry.dome.levels import Dimensions, level_table
from masonry.dome.pattern import build_pattern
from masonry.params import ParameterError, Params
from masonry.scenes.base import Scene, hexahedra_frames
from masonry.scenes.bricks import blocks_from_layout, posed_corners
from masonry.tolerances import STRETCH_USUAL_RANGE, Tolerances

log = logging.getLogger(__name__)

def build_section(params: Params) -> Scene:
    """One web of the dome (SPEC 4.2 to 4.5) on its ground slab (block 0).

    Raises :class:`ParameterError` when the dome is too small or too flat for its bricks:
    consecutive courses would meet in wedges wider than the interface detector's
    ``max_gap_angle`` closes, and the courses would not bear on each other.
    """
    dims = Dimensions.of(params)
    levels = level_table(params, dims)
    if levels.n_courses < 2:
        raise ParameterError("cut", params.cut, "a dome at least two courses high "
                             f"(this one holds {levels.n_courses}); lower cut or unit",
                             related=("unit", "stretch", "p", "r"))
    widest = float(levels.wedge_angles.max())
    limit = Tolerances().max_gap_angle
    if widest > limit:
        raise ParameterError(
            "p", params.p,
            f"a dome large enough for its bricks: its courses meet in wedges of up to "
            f"{np.degrees(widest):.1f} degrees, more than the {np.degrees(limit):g} "
            f"degrees whose gaps can be closed; raise p or r, or the stretch",
            related=("stretch", "r", "n", "unit"))
    low, high = STRETCH_USUAL_RANGE
    if not low <= params.stretch <= high:
        log.warning("stretch=%g is outside %g..%g: the dome is unusually flat or tall",
                    params.stretch, low, high)
    half_width = levels.y[1:] / params.unit
    pattern = build_pattern(half_width, params.p, params.r)
    layout = fill_courses(half_width, pattern, params.min_fill, miter=True)
    tan = np.tan(np.pi / params.n)
    u = params.unit
    # ground slab: one mitered slab under course 1, as deep as a pattern brick
    ground = posed_corners(np.array([[dims.a, -u]]), np.zeros(1), np.array([4 * u]),
                           np.array([u]), np.zeros(1), np.zeros(1),
                           np.array([tan]), np.array([tan]))[0]
    blocks = blocks_from_layout(layout, levels, u, tan, ground)
    return Scene(params, blocks, levels, pattern, layout, dims, *hexahedra_frames(blocks))


def build_dome(params: Params) -> Scene:
    """All ``n`` webs explicitly: the section rotated by ``2 pi k / n`` (SPEC 4.6). The
    mitered end bricks of neighbouring webs meet face to face in the corner planes.
    Blocks are ordered web after web; every web keeps its ground slab as a support."""
    section = build_section(params)
    n = params.n
    blocks = concatenate([rotated_web(section.blocks, k, n) for k in range(n)])
    turns = [rotation_z(2 * np.pi * k / n).T for k in range(n)]
    up = np.concatenate([section.block_up @ q for q in turns])
    inward = np.concatenate([section.block_inward @ q for q in turns])
    return dataclasses.replace(section, blocks=blocks, block_up=up, block_inward=inward)
