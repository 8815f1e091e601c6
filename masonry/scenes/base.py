"""What a scene is: the blocks one run models, and what a kind of scene tells the later
stages about itself.

A scene kind is one module of :mod:`masonry.scenes` with one :class:`SceneKind` (or two,
as the polygonal dome's section and whole dome): its geometry's declared parameters
(:mod:`masonry.parameters`), how it builds its blocks and supports, its symmetry, and the
few things the analysis, the plots and the exports ask of a scene. Nothing outside
:mod:`masonry.scenes` asks which kind a scene is: it asks the kind.
"""

from dataclasses import dataclass

import numpy as np

from masonry.blocks import Blocks
from masonry.dome.courses import Layout
from masonry.dome.levels import Dimensions, LevelTable
from masonry.dome.pattern import Pattern
from masonry.parameters import values


@dataclass(frozen=True)
class Symmetry:
    """How a scene repeats about the z axis (docs/model.md 6.4) and in vertical planes
    through it (docs/model.md 6.11).

    Parameters
    ----------
    order : int
        Turns by ``360 / order`` degrees map the whole structure onto itself (1: no
        rotational symmetry).
    unit : bool
        The scene is one of the ``order`` equal parts (a section of the dome), not the
        whole: a load on the whole structure falls ``1 / order`` on it, and its
        boundary may stand for the rest.
    mirrors : tuple of float
        Azimuths in degrees, in [0, 180), of the vertical planes through the z axis in
        which the scene is its own mirror image (with its boundary: a section's images
        are mirror images of each other); a plane at ``a`` is the plane at ``a + 180``.
    """

    order: int = 1
    unit: bool = False
    mirrors: tuple = ()

    @property
    def period_deg(self) -> float | None:
        """The angle under which a whole structure repeats (None: it does not, or the
        scene is one part of it)."""
        return 360.0 / self.order if self.order > 1 and not self.unit else None

    @property
    def webs(self) -> int | None:
        """The number of equal parts about z (None: one)."""
        return self.order if self.order > 1 else None


@dataclass(frozen=True)
class ThrustSection:
    """Where a scene's thrust line is drawn: the bed joints cut by the vertical plane
    ``y = y``, ordered along ``axis`` (0: x, 2: z), their ends inner to outer about the
    point ``centre`` (x, z); ``facing_x`` keeps the joints at x > 0 only (the web facing
    +x); ``name`` is how a title calls the plane."""

    y: float
    axis: int
    centre: tuple
    facing_x: bool
    name: str


class SceneKind:
    """One kind of scene: a class (never instantiated) whose subclasses set the attributes
    and override the class methods. A scene keeps its kind, and a class pickles by name,
    so a cached scene comes back with its kind.

    Attributes
    ----------
    name : str
        The scene's name (``--scene``).
    geometry : type
        Its geometry, a declared dataclass (:mod:`masonry.parameters`).
    block_word : str
        What its blocks are called in reports: ``bricks`` or ``blocks``.
    boundaries : tuple of str
        The boundary modes its analysis takes (docs/model.md 6.4): ``free`` only, or a
        section's ``free``, ``rigid``, ``cyclic``.
    has_courses : bool
        Its blocks are laid in courses (course and brick construction stages).
    crown : bool
        It has a top course that a crown load rests on.
    from_parameters : bool
        It is built from its parameters (an assembly is read from files).
    moved_for_cad : bool
        Its blocks are bricks with an inner face, which the CAD files move inward by the
        CAD offset (an arch's voussoirs and imported blocks stay where they are).
    id_prefix_name : str
        The first word of its structure ids.
    summary : str
        One line on what it is (the command line's help).
    """

    name = ""
    geometry = None
    block_word = "bricks"
    boundaries = ("free",)
    has_courses = True
    crown = False
    from_parameters = True
    moved_for_cad = True
    id_prefix_name = ""
    summary = ""

    @classmethod
    def build(cls, geometry) -> "Scene":
        """The scene of ``geometry`` (a validated instance of :attr:`geometry`)."""
        raise NotImplementedError(f"scene {cls.name!r} is not built from parameters alone")

    @classmethod
    def check(cls, geometry):
        """Refuse a geometry that makes no scene of this kind, beyond each field's own
        range (:class:`~masonry.errors.ParameterError`)."""

    @classmethod
    def estimate_blocks(cls, geometry) -> float:
        """The number of blocks ``geometry`` would build, without building it."""
        return 0.0

    @classmethod
    def id_prefix(cls, geometry, boundary: str) -> str:
        """The head of a structure id, before ``_fast``."""
        return cls.id_prefix_name

    @classmethod
    def symmetry(cls, geometry) -> Symmetry:
        return Symmetry()

    @classmethod
    def thrust_section(cls, scene) -> ThrustSection | None:
        """Where to draw the thrust line, or None when the scene has none."""
        return None

    @classmethod
    def describe(cls, boundary: str) -> str:
        """The scene named in a figure's title."""
        return cls.name

    unit_word = ""
    """What one unit of a symmetric scene is called (``web``, ``sector``), for kinds with
    boundaries besides ``free``."""

    @classmethod
    def verdict_subject(cls, boundary: str) -> str:
        """What a verdict on the scene with ``boundary`` is about, for the line that
        says what it means (docs/model.md 6.4)."""
        if len(cls.boundaries) == 1:
            return f"this structure (the {cls.name} scene)"
        return {"cyclic": f"the whole dome (this {cls.unit_word} with its neighbours by "
                          f"rotational symmetry)",
                "rigid": f"this {cls.unit_word} between immovable neighbours",
                }.get(boundary, f"this {cls.unit_word} alone, without its neighbours,")

    @classmethod
    def edge_blocks(cls, scene) -> tuple:
        """``(left, right)`` (B,) bool: the blocks of a unit of a symmetric scene (a
        section) that bear on the previous and the next unit (docs/model.md 6.4); their
        images stand for the neighbours. Only kinds with boundaries besides ``free``
        have them."""
        raise NotImplementedError(f"a {cls.name} scene has no neighbours")

    @classmethod
    def pattern_caption(cls, geometry) -> str:
        """What the flattened pattern figure shows of the scene."""
        return cls.name

    pattern_axis = "position along the wall s [units]"
    """The flattened pattern figure's horizontal axis."""

    pattern_ends = "the web grew too narrow for them"
    """Why its pattern lines end below the top (``run.json``'s pattern record)."""

    @classmethod
    def shown(cls, geometry) -> dict:
        """The geometry's values as a run used them (defaults resolved), for
        ``00_parameters.txt``."""
        return values(geometry)


@dataclass(frozen=True)
class Scene:
    """A built scene: its blocks and, for dome scenes, how they were laid out.

    ``kind`` the :class:`SceneKind` subclass that built it, ``geometry`` its declared
    geometry.
    ``block_up`` (B, 3): each block's course direction (bed joints are the interfaces
    across it; the interface detector names kinds by it), the z axis when None.
    ``block_inward`` (B, 3): the direction the CAD offset moves each block (thesis
    3.4.1), no offset when None.
    """

    kind: type
    geometry: object
    blocks: Blocks
    levels: LevelTable | None = None
    pattern: Pattern | None = None
    layout: Layout | None = None
    dims: Dimensions | None = None
    block_up: np.ndarray | None = None
    block_inward: np.ndarray | None = None

    @property
    def symmetry(self) -> Symmetry:
        return self.kind.symmetry(self.geometry)

    @property
    def unit(self) -> float | None:
        """The brick unit in metres (None: the scene has none)."""
        return getattr(self.geometry, "unit", None)

    def cad_vertices(self, cad_offset=1.0) -> np.ndarray:
        """(V, 3) float, metres: the vertices moved inward by ``cad_offset`` units along
        each block's inward normal (``block_inward``; thesis 3.4.1), as ``locations.csv``
        and the printable body use them. Scenes without one are not moved."""
        blocks = self.blocks
        if self.block_inward is None:
            return blocks.vertices
        shift = cad_offset * self.unit * self.block_inward
        return blocks.vertices + np.repeat(shift, np.diff(blocks.vertex_offsets), axis=0)


def hexahedra_frames(blocks: Blocks):
    """``(up, inward)`` of hexahedral bricks: the normals of their top face (face 5) and of
    their inner face (face 0), see :data:`masonry.blocks.HEX_FACES`."""
    first = blocks.block_face_offsets[:-1]
    return blocks.face_normal[first + 5], blocks.face_normal[first]
