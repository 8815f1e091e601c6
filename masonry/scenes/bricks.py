"""Posed bricks: boxes of a course layout, inclined with their course and mitered at the
corner planes, built directly from their eight corners (no hull). Shared by the
``section`` (and ``dome``) and ``wall`` scenes.
"""

import numpy as np

from masonry.blocks import GROUND, Blocks
from masonry.dome.courses import PAT, REG, Layout
from masonry.dome.levels import LevelTable

# brick cross-sections in units: (width through the wall, height up the course); a
# pattern brick's height is its two-course chord (LevelTable.pattern_height)
SECTION = {REG: (2.0, 1.0), PAT: (4.0, 2.0)}


def posed_corners(base, gamma, width, height, y0, y1, tan_left, tan_right):
    """Corners (B, 8, 3) of posed boxes, optionally mitered.

    Parameters
    ----------
    base : (B, 2) float
        Inner bottom edge ``(x, z)`` of each brick, metres.
    gamma : (B,) float
        Inward inclination from vertical, radians.
    width, height : (B,) float
        Through the wall and up the course, metres.
    y0, y1 : (B,) float
        Extent along the wall, metres.
    tan_left, tan_right : (B,) float
        ``tan(pi/n)`` for an end mitered by that corner plane, NaN for a plain end.
    """
    up = np.stack([-np.sin(gamma), np.cos(gamma)], axis=1)
    out = np.stack([np.cos(gamma), np.sin(gamma)], axis=1)
    corners = np.empty((len(base), 8, 3))
    for iz in (0, 1):
        for ix in (0, 1):
            xz = base + ix * width[:, None] * out + iz * height[:, None] * up
            for iy, (y, tan, sign) in enumerate(((y0, tan_left, -1), (y1, tan_right, 1))):
                i = ix + 2 * iy + 4 * iz
                corners[:, i, 0] = xz[:, 0]
                corners[:, i, 1] = np.where(np.isnan(tan), y, sign * xz[:, 0] * tan)
                corners[:, i, 2] = xz[:, 1]
    return corners


def blocks_from_layout(layout: Layout, levels: LevelTable, unit, tan_miter, ground_corners):
    k = layout.course
    pattern = layout.klass == PAT
    width = np.where(pattern, SECTION[PAT][0], SECTION[REG][0]) * unit
    height = np.where(pattern, levels.pattern_height[k - 1], SECTION[REG][1] * unit)
    gamma = np.where(pattern, levels.gamma_pat[k - 1], levels.gamma_reg[k - 1])
    base = np.stack([levels.x[k - 1], levels.z[k - 1]], axis=1)
    nan = np.full(len(k), np.nan)
    corners = posed_corners(base, gamma, width, height, layout.s0 * unit, layout.s1 * unit,
                       np.where(layout.miter_left, tan_miter, nan),
                       np.where(layout.miter_right, tan_miter, nan))
    return Blocks.from_hexahedra(
        np.concatenate([ground_corners[None], corners]),
        block_class=np.concatenate([[GROUND], layout.klass]),
        block_course=np.concatenate([[0], k]),
    )
