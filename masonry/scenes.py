"""Scenes: what one run models, as :class:`~masonry.blocks.Blocks` (SPEC 4.5, 4.6).

- ``section``: one web of the dome, facing +x, on a ground slab.
- ``wall``: a straight running-bond wall on a ground slab (validation, thesis 3.3.6).

Every brick is a box posed by its course's inclination, its inner face the chord of the
intrados, built directly from its eight corners (no hull). End bricks are mitered: their
end face lies in the corner plane ``y = +-x tan(pi/n)`` where this web meets the next.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from .arch import build_arch
from .blocks import BLOCK_CLASSES, Blocks, concatenate
from .courses import PAT, REG, Layout, fill_courses
from .levels import Dimensions, LevelTable, level_table
from .params import ParameterError, Params
from .tolerances import Tolerances
from .pattern import Pattern, build_pattern

GROUND = BLOCK_CLASSES.index("ground")

# brick cross-sections in units: (width through the wall, height up the course); a
# pattern brick's height is its two-course chord (LevelTable.pattern_height)
_SECTION = {REG: (2.0, 1.0), PAT: (4.0, 2.0)}


@dataclass(frozen=True)
class Scene:
    """A built scene: its blocks and, for dome scenes, how they were laid out.

    ``block_up`` (B, 3): each block's course direction (bed joints are the interfaces
    across it; the interface detector names kinds by it), the z axis when None.
    ``block_inward`` (B, 3): the direction the CAD offset moves each block (thesis
    3.4.1), no offset when None.
    """

    params: Params
    blocks: Blocks
    levels: LevelTable | None = None
    pattern: Pattern | None = None
    layout: Layout | None = None
    dims: Dimensions | None = None
    block_up: np.ndarray | None = None
    block_inward: np.ndarray | None = None


def hexahedra_frames(blocks: Blocks):
    """``(up, inward)`` of hexahedral bricks: the normals of their top face (face 5) and of
    their inner face (face 0), see :data:`masonry.blocks.HEX_FACES`."""
    first = np.searchsorted(blocks.face_block, np.arange(blocks.n_blocks))
    return blocks.face_normal[first + 5], blocks.face_normal[first]


def _corners(base, gamma, width, height, y0, y1, tan_left, tan_right):
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


def _blocks_from_layout(layout: Layout, levels: LevelTable, unit, tan_miter, ground_corners):
    k = layout.course
    pattern = layout.klass == PAT
    width = np.where(pattern, _SECTION[PAT][0], _SECTION[REG][0]) * unit
    height = np.where(pattern, levels.pattern_height[k - 1], _SECTION[REG][1] * unit)
    gamma = np.where(pattern, levels.gamma_pat[k - 1], levels.gamma_reg[k - 1])
    base = np.stack([levels.x[k - 1], levels.z[k - 1]], axis=1)
    nan = np.full(len(k), np.nan)
    corners = _corners(base, gamma, width, height, layout.s0 * unit, layout.s1 * unit,
                       np.where(layout.miter_left, tan_miter, nan),
                       np.where(layout.miter_right, tan_miter, nan))
    return Blocks.from_hexahedra(
        np.concatenate([ground_corners[None], corners]),
        block_class=np.concatenate([[GROUND], layout.klass]),
        block_course=np.concatenate([[0], k]),
    )


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
                             f"(this one holds {levels.n_courses}); lower cut or unit")
    widest = float(levels.wedge_angles.max())
    limit = Tolerances().max_gap_angle
    if widest > limit:
        raise ParameterError(
            "p", params.p,
            f"a dome large enough for its bricks: its courses meet in wedges of up to "
            f"{np.degrees(widest):.1f} degrees, more than the {np.degrees(limit):g} "
            f"degrees whose gaps can be closed; raise p or r, or the stretch")
    half_width = levels.y[1:] / params.unit
    pattern = build_pattern(half_width, params.p, params.r)
    layout = fill_courses(half_width, pattern, params.min_fill, miter=True)
    tan = np.tan(np.pi / params.n)
    u = params.unit
    # ground slab: one mitered slab under course 1, as deep as a pattern brick
    ground = _corners(np.array([[dims.a, -u]]), np.zeros(1), np.array([4 * u]),
                      np.array([u]), np.zeros(1), np.zeros(1),
                      np.array([tan]), np.array([tan]))[0]
    blocks = _blocks_from_layout(layout, levels, u, tan, ground)
    return Scene(params, blocks, levels, pattern, layout, dims, *hexahedra_frames(blocks))


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
    ground = _corners(np.array([[0.0, -u]]), np.zeros(1), np.array([2 * u]), np.array([u]),
                      np.array([-half * u]), np.array([half * u]),
                      np.full(1, np.nan), np.full(1, np.nan))[0]
    blocks = _blocks_from_layout(layout, levels, u, np.nan, ground)
    return Scene(params, blocks, levels, None, layout, None, *hexahedra_frames(blocks))


def build_dome(params: Params) -> Scene:
    """All ``n`` webs explicitly: the section rotated by ``2 pi k / n`` (SPEC 4.6). The
    mitered end bricks of neighbouring webs meet face to face in the corner planes.
    Blocks are ordered web after web; every web keeps its ground slab as a support."""
    from .boundary import rotated_web, rotation_z

    section = build_section(params)
    n = params.n
    blocks = concatenate([rotated_web(section.blocks, k, n) for k in range(n)])
    turns = [rotation_z(2 * np.pi * k / n).T for k in range(n)]
    up = np.concatenate([section.block_up @ q for q in turns])
    inward = np.concatenate([section.block_inward @ q for q in turns])
    return dataclasses.replace(section, blocks=blocks, block_up=up, block_inward=inward)


BUILDERS = {"section": build_section, "wall": build_wall, "dome": build_dome,
            "arch": build_arch}


def build(params: Params) -> Scene:
    """The scene ``params.scene`` asks for."""
    try:
        builder = BUILDERS[params.scene]
    except KeyError:
        raise NotImplementedError(f"scene {params.scene!r} is not built yet") from None
    return builder(params)
