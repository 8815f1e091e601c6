"""The polygonal dome: the ``section`` scene (one web, facing +x) and the ``dome`` scene
(all ``n`` webs).

One web faces +x on its ground slab (docs/model.md 4.2 to 4.5): level table, pattern,
courses, then posed bricks (:mod:`masonry.scenes.bricks`). End bricks are mitered: their
end face lies in the corner plane ``y = +-x tan(pi/n)`` where this web meets the next, so
``n`` rotated copies close into the whole dome face to face (docs/model.md 4.6). The
plain dome (``pattern = "none"``, docs/model.md 4.9) lays the same courses with no
pattern bricks: running bond, filled and staggered by the same rules.
"""

import dataclasses
import logging
from dataclasses import dataclass

import numpy as np

from masonry.blocks import rotation_z, whole_of_web
from masonry.dome.courses import fill_courses
from masonry.dome.levels import Dimensions, level_table
from masonry.dome.pattern import Pattern, build_pattern
from masonry.errors import ParameterError
from masonry.parameters import declare
from masonry.scenes.base import Scene, SceneKind, Symmetry, ThrustSection, hexahedra_frames
from masonry.scenes.bricks import blocks_from_layout, posed_corners
from masonry.tolerances import (COUNTED_BRICKS, STRETCH_USUAL_RANGE, UNITS_PER_BRICK,
                                UNITS_PER_PLAIN_BRICK, Tolerances)

log = logging.getLogger(__name__)


PATTERNS = ("herringbone", "none")
"""The dome's patterns: the double helix (docs/model.md 4.3) or none, the plain dome of
running bond (docs/model.md 4.9)."""

MIN_PATTERN_P = 2
"""The fewest pattern bricks per rhombus side that make a pattern: with one, every line
from a corner node ends on the first course (:mod:`masonry.dome.pattern`)."""


@dataclass(frozen=True)
class PolygonalDome:
    """A polygonal cloister vault of ``n`` webs with the double-helix pattern, or none
    (docs/model.md 3, 4); lengths in units of ``unit`` metres unless stated."""

    stretch: float = declare(1.0, "dome height / circumradius", low=0.05, high=20.0,
                             tag="s", head=True, names_geometry=True,
                             expected="0.05 to 20 (dome height / circumradius)")
    n: int = declare(8, "walls of the dome", kind="int", check=lambda v: v >= 3,
                     expected="an integer >= 3", tag="n", head=True, names_geometry=True)
    r: int = declare(1, "full rhombi across the section", kind="int",
                     check=lambda v: v >= 0, expected="an integer >= 0", tag="r", head=True,
                     names_geometry=True)
    p: int = declare(10, "pattern bricks per rhombus side", kind="int",
                     check=lambda v: v >= 1, tag="p", head=True, names_geometry=True,
                     expected="an integer >= 2 (>= 1 with --pattern none)")
    cut: float = declare(0.1, "fraction of the height cut off", check=lambda v: 0 <= v < 1,
                         expected="0 <= cut < 1", tag="c", head=True, names_geometry=True)
    unit: float = declare(0.1, "m, the brick unit", low=1e-3, high=1e2, tag="u", head=True,
                          names_geometry=True,
                          expected="0.001 to 100 (metres: bricks of 1 mm to 100 m; forces "
                                   "scale with unit^3)")
    min_fill: float = declare(1.0, "units, shortest fill-in brick",
                              check=lambda v: 0 < v <= 4,
                              expected="0 < min_fill <= 4 (units)", tag="mf",
                              names_geometry=True)
    pattern: str = declare("herringbone", "pattern bricks: herringbone (the double helix) "
                           "or none (running bond, the same courses)", kind="str",
                           choices=PATTERNS, tag="pat", names_geometry=True)


def build_web(geometry: PolygonalDome) -> Scene:
    """One web of the dome (docs/model.md 4.2 to 4.5) on its ground slab (block 0).

    Raises :class:`~masonry.errors.ParameterError` when the dome is too small or too flat
    for its bricks: consecutive courses would meet in wedges wider than the interface
    detector's ``max_gap_angle`` closes, and the courses would not bear on each other.
    """
    dims, levels, pattern, layout = web_plan(geometry)
    low, high = STRETCH_USUAL_RANGE
    if not low <= geometry.stretch <= high:
        log.warning("stretch=%g is outside %g..%g: the dome is unusually flat or tall",
                    geometry.stretch, low, high)
    tan = np.tan(np.pi / geometry.n)
    u = geometry.unit
    # ground slab: one mitered slab under course 1, as deep as a pattern brick
    ground = posed_corners(np.array([[dims.a, -u]]), np.zeros(1), np.array([4 * u]),
                           np.array([u]), np.zeros(1), np.zeros(1),
                           np.array([tan]), np.array([tan]))[0]
    blocks = blocks_from_layout(layout, levels, u, tan, ground)
    return Scene(Section, geometry, blocks, levels, pattern, layout, dims,
                 *hexahedra_frames(blocks))


def web_plan(geometry: PolygonalDome) -> tuple:
    """``(dims, levels, pattern, layout)``: one web in plan, its courses' levels, its
    herringbone and every course's bricks (docs/model.md 4.2 to 4.4), before any brick is
    posed. Raises :class:`~masonry.errors.ParameterError` as :func:`build_web` says."""
    dims = Dimensions.of(geometry)
    levels = level_table(geometry, dims)
    _check_levels(geometry, levels)
    half_width = levels.y[1:] / geometry.unit
    pattern = (build_pattern(half_width, geometry.p, geometry.r)
               if geometry.pattern == "herringbone" else Pattern.none())
    if geometry.pattern == "herringbone" and not np.any(pattern.course > 1):
        raise ParameterError(
            "cut", geometry.cut,
            f"a dome high enough for its herringbone: its pattern lines end on the first of "
            f"its {levels.n_courses} courses, so no pattern is laid above it; lower cut, "
            f"raise p, or --pattern none for the courses without a pattern",
            related=("p", "r", "stretch", "unit"))
    layout = fill_courses(half_width, pattern, geometry.min_fill, miter=True)
    return dims, levels, pattern, layout


def _check_levels(geometry, levels):
    """Refuse a dome of fewer than two courses, or whose courses meet in wedges the
    interface detector cannot close."""
    if levels.n_courses < 2:
        raise ParameterError("cut", geometry.cut, "a dome at least two courses high "
                             f"(this one holds {levels.n_courses}); lower cut or unit",
                             related=("unit", "stretch", "p", "r"))
    wedges = (levels.wedge_angles if geometry.pattern == "herringbone"
              else levels.course_wedge_angles)
    widest = float(wedges.max())
    limit = Tolerances().max_gap_angle
    if widest > limit:
        raise ParameterError(
            "p", geometry.p,
            f"a dome large enough for its bricks: its courses meet in wedges of up to "
            f"{np.degrees(widest):.1f} degrees, more than the {np.degrees(limit):g} "
            f"degrees whose gaps can be closed; raise p or r, or the stretch",
            related=("stretch", "r", "n", "unit"))


def web_bricks(geometry: PolygonalDome) -> float:
    """The number of blocks of one web with its ground slab, before it is built: counted
    from its plan (:func:`web_plan`) where :func:`intrados_bricks` puts it at no more than
    :data:`~masonry.tolerances.COUNTED_BRICKS` bricks; else, or where the plan is
    refused, that estimate."""
    rough = intrados_bricks(geometry)
    if not rough <= COUNTED_BRICKS:
        return rough
    try:
        return float(len(web_plan(geometry)[3].course) + 1)
    except ParameterError:  # refused again, with its reason, when it is built
        return rough


def intrados_bricks(geometry: PolygonalDome) -> float:
    """The number of blocks of one web from its dimensions alone: its intrados area (the
    web's width integrated along the quarter ellipse) over
    :data:`~masonry.tolerances.UNITS_PER_BRICK` (a plain dome's:
    :data:`~masonry.tolerances.UNITS_PER_PLAIN_BRICK`), within a factor 1.4."""
    with np.errstate(all="ignore"):  # absurd inputs give inf, which is refused
        d = Dimensions.of(geometry)
        theta = np.linspace(0.0, np.arcsin(min(d.z_max / d.c, 1.0)), 257)
        width = 2 * d.a * np.cos(theta) * np.tan(np.pi / geometry.n)
        speed = np.hypot(d.a * np.sin(theta), d.c * np.cos(theta))
        f = width * speed
        area = np.sum((f[1:] + f[:-1]) / 2 * np.diff(theta)) / geometry.unit**2
    per_brick = UNITS_PER_BRICK if geometry.pattern == "herringbone" else UNITS_PER_PLAIN_BRICK
    return float(area) / per_brick


class Section(SceneKind):
    """``section``: one web of the dome, free-standing or with its neighbours as a
    boundary (docs/model.md 6.4)."""

    name = "section"
    summary = "one web of the polygonal dome (default; see --boundary)"
    geometry = PolygonalDome
    boundaries = ("free", "rigid", "cyclic")
    unit_word = "web"
    crown = True

    @classmethod
    def build(cls, geometry) -> Scene:
        return build_web(geometry)

    @classmethod
    def check(cls, geometry):
        """Refuse a herringbone dome of one pattern brick per rhombus side: its lines from
        the corners end on the first course (:mod:`masonry.dome.pattern`), and with
        ``r = 1`` no pattern is left above it."""
        if geometry.pattern == "herringbone" and geometry.p < MIN_PATTERN_P:
            raise ParameterError(
                "p", geometry.p,
                f"an integer >= {MIN_PATTERN_P} for the herringbone pattern: with "
                f"{geometry.p} pattern brick per rhombus side the lines from the corners "
                f"end on the first course; --pattern none lays the same courses without "
                f"a pattern")

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        return web_bricks(geometry)

    @classmethod
    def id_prefix(cls, geometry, boundary) -> str:
        return f"dome{int(boundary != 'free')}"

    @classmethod
    def symmetry(cls, geometry) -> Symmetry:
        """Rotations by ``360 / n`` (with a boundary); the web's mid-plane (its layout is
        mirror-symmetric about ``s = 0``, docs/model.md 4.3, 4.4)."""
        return Symmetry(order=geometry.n, unit=True, mirrors=(0.0,))

    @classmethod
    def thrust_section(cls, scene) -> ThrustSection:
        return ThrustSection(0.0, 2, (0.0, float(scene.blocks.bounds[0, 2])), True,
                             "y = 0 m")

    @classmethod
    def describe(cls, boundary) -> str:
        return f"section, boundary {boundary}"

    @classmethod
    def edge_blocks(cls, scene) -> tuple:
        """The bricks mitered at the left (-pi/n) and right (+pi/n) corner planes (the
        ground slab bears on no neighbour)."""
        layout, ground = scene.layout, np.zeros(1, bool)
        return (np.concatenate([ground, layout.miter_left]),
                np.concatenate([ground, layout.miter_right]))

    @classmethod
    def pattern_caption(cls, geometry) -> str:
        return f"one web of {geometry.n}, flattened{_no_pattern(geometry)}"


class Dome(Section):
    """``dome``: all ``n`` webs explicitly, the section rotated by ``2 pi k / n``
    (docs/model.md 4.6). The mitered end bricks of neighbouring webs meet face to face in
    the corner planes. Blocks are ordered web after web; every web keeps its ground slab
    as a support."""

    name = "dome"
    summary = "all n webs of the polygonal dome"
    boundaries = ("free",)
    id_prefix_name = "fulldome"

    @classmethod
    def build(cls, geometry) -> Scene:
        section = build_web(geometry)
        n = geometry.n
        blocks = whole_of_web(section.blocks, n, rename_first=True)
        turns = [rotation_z(2 * np.pi * k / n).T for k in range(n)]
        up = np.concatenate([section.block_up @ q for q in turns])
        inward = np.concatenate([section.block_inward @ q for q in turns])
        return dataclasses.replace(section, kind=Dome, blocks=blocks, block_up=up,
                                   block_inward=inward)

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        return web_bricks(geometry) * geometry.n

    @classmethod
    def id_prefix(cls, geometry, boundary) -> str:
        return cls.id_prefix_name

    @classmethod
    def symmetry(cls, geometry) -> Symmetry:
        """Rotations by ``360 / n``; the mid-plane of every web and every corner plane,
        every ``180 / n`` degrees (a web's mirror image in its corner plane is the next
        web)."""
        return Symmetry(order=geometry.n, unit=False,
                        mirrors=tuple(180.0 * k / geometry.n for k in range(geometry.n)))

    @classmethod
    def describe(cls, boundary) -> str:
        return "dome"

    @classmethod
    def pattern_caption(cls, geometry) -> str:
        return f"web 0 of {geometry.n}, flattened{_no_pattern(geometry)}"


def _no_pattern(geometry) -> str:
    """What a pattern figure's caption adds for a plain dome."""
    return ", no pattern (running bond)" if geometry.pattern == "none" else ""
