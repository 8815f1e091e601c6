"""Live loads as arrays: the load cases of the collapse load factor (docs/model.md 6.8).

A :class:`LiveLoad` is one wrench per block: the applied force (N) and its moment about the
block's centroid (N m), the same reduction as the equilibrium rows of
:mod:`masonry.rbe.equilibrium` (moments about centroids, docs/model.md 6.2). Support blocks carry no
load (they have no rows). The builders are the three load cases of the command line:

- :func:`lateral`: a horizontal body force of each block's weight, at its centroid (the
  static seismic load, the tilting table); no moment.
- :func:`point_loads`: forces at the centre of the top face of named blocks.
- :func:`crown_load`: a downward load on the top course, shared by top-face area (a
  lantern on the oculus ring).

What a run asks for is declared once, as one of the typed load cases :class:`Lateral`,
:class:`PointLoads` and :class:`CrownLoad` (:func:`live_load` parses the options into
one); the case builds its :class:`LiveLoad` on a model.
"""

import fnmatch
import hashlib
import math
import re
from dataclasses import dataclass, field

import numpy as np

from masonry.blocks import BLOCK_CLASSES
from masonry.errors import ParameterError
from masonry.parameters import text_of
from masonry.tolerances import MAX_LIVE_LOAD_N, MIN_LIVE_LOAD_N, G

PATTERN = BLOCK_CLASSES.index("pattern")


@dataclass(frozen=True, eq=False)
class LiveLoad:
    """A live load, per block.

    Parameters
    ----------
    wrench : (B, 6) float
        Force ``(Fx, Fy, Fz)`` in newtons and moment ``(Mx, My, Mz)`` about the block's
        centroid in newton-metres, per block of the model (zero on supports).
    description : dict
        What was applied, for run.json: ``kind`` and the load's inputs, and
        ``total_force_N`` (the resultant force, (3,) list).
    """

    wrench: np.ndarray
    description: dict = field(default_factory=dict)

    @property
    def total_force(self) -> np.ndarray:
        """(3,) float, N: the resultant force."""
        return self.wrench[:, :3].sum(axis=0)

    def loaded_blocks(self, blocks) -> np.ndarray | None:
        """(k,) int: the blocks of ``blocks`` (the model's) the load pushes, when it
        pushes only some of the free ones (a point or crown load); None for a body force
        on every free block."""
        loaded = np.flatnonzero(np.abs(self.wrench[:, :3]).max(axis=1) > 0)
        some = len(loaded) < int((~np.asarray(blocks.block_is_support)).sum())
        return loaded if some else None

    def arrow(self, blocks, bounds, outside=False) -> tuple | None:
        """``(start, end)`` ((3,) float each, metres) of an arrow along the resultant
        force: into the loaded blocks (:meth:`loaded_blocks`), as long as the box
        ``bounds`` ((2, 3), the drawing's) leaves room for behind them, or for a body
        force from the box's edge the load comes from (``outside``: ending just outside
        it, for a view that hides what is inside the structure); None when the forces
        cancel (a couple, a push and a pull: no one direction)."""
        total = self.total_force
        if np.linalg.norm(total) <= 1e-9 * np.abs(self.wrench[:, :3]).sum():
            return None
        direction = total / float(np.linalg.norm(total))
        size = float(np.abs(direction) @ (bounds[1] - bounds[0]))  # the box along it
        loaded = self.loaded_blocks(blocks)
        if loaded is None:
            start = bounds.mean(axis=0) - (0.8 if outside else 0.45) * size * direction
            return start, start + 0.25 * size * direction
        target = blocks.block_centroid[loaded].mean(axis=0)
        room = np.where(direction > 0, target - bounds[0], bounds[1] - target)
        moving = np.abs(direction) > 1e-9  # not empty: a unit vector
        length = min(0.25 * size,
                     0.9 * float((room[moving] / np.abs(direction[moving])).min()))
        return target - length * direction, target


def _blocks(model_or_blocks):
    return getattr(model_or_blocks, "blocks", model_or_blocks)


def _describe(kind, wrench, **inputs) -> dict:
    return {"kind": kind, **inputs,
            "total_force_N": [float(v) for v in wrench[:, :3].sum(axis=0)]}


def lateral(model_or_blocks, azimuth_deg: float, density: float = 2000.0) -> LiveLoad:
    """Horizontal body force: each free block's weight times ``(cos a, sin a, 0)``.

    Parameters
    ----------
    model_or_blocks : masonry.rbe.boundary.Model or masonry.blocks.Blocks
    azimuth_deg : float
        Direction in degrees from +x toward +y.
    density : float, kg/m^3

    Returns
    -------
    LiveLoad
        Forces at the centroids, so no moments (docs/model.md 6.8).
    """
    blocks = _blocks(model_or_blocks)
    weight = density * G * blocks.block_volume * ~np.asarray(blocks.block_is_support)
    angle = np.radians(azimuth_deg)
    wrench = np.zeros((blocks.n_blocks, 6))
    wrench[:, 0], wrench[:, 1] = weight * np.cos(angle), weight * np.sin(angle)
    return LiveLoad(wrench, _describe("lateral", wrench, azimuth_deg=float(azimuth_deg),
                                      per_block="weight"))


def top_faces(blocks) -> np.ndarray:
    """(B,) int: every block's top face, the one whose outward normal points most up."""
    score = blocks.face_normal[:, 2]
    order = np.lexsort((-score, blocks.face_block))  # by block, best score first
    first = np.searchsorted(blocks.face_block[order], np.arange(blocks.n_blocks))
    return order[first]


def _at_points(blocks, block, point, force) -> np.ndarray:
    """(B, 6) wrench of forces ``force`` ((m, 3) N) at ``point`` ((m, 3) m) on ``block``."""
    wrench = np.zeros((blocks.n_blocks, 6))
    moment = np.cross(point - blocks.block_centroid[block], force)
    np.add.at(wrench, block, np.concatenate([force, moment], axis=1))
    return wrench


def point_loads(blocks, specs) -> LiveLoad:
    """Forces at the centre of the top face of the blocks each spec names; its
    description's ``blocks`` counts the blocks loaded (block names are unique in every
    scene, so a name loads one block and a pattern the blocks it matches).

    Parameters
    ----------
    blocks : masonry.blocks.Blocks (or a Model)
    specs : PointLoads or sequence of str
        ``'NAME_OR_PATTERN:FX,FY,FZ'``: a block name or an :mod:`fnmatch` pattern (e.g.
        ``b00*_pattern_c3*``) and a force in newtons applied to *every* matched free block.

    Raises
    ------
    ParameterError
        A spec that is malformed or matches no free block (named ``point_loads``).
    """
    parsed = specs if isinstance(specs, PointLoads) else PointLoads.parse(specs)
    specs = parsed.specs
    blocks = _blocks(blocks)
    free = ~np.asarray(blocks.block_is_support)
    names = [str(name) for name in blocks.block_name]
    top = top_faces(blocks)
    chosen, forces = [], []
    for spec, (pattern, force) in zip(specs, parsed.loads):
        matched = [i for i in np.flatnonzero(free) if fnmatch.fnmatchcase(names[i], pattern)]
        if not matched:
            example = names[int(np.flatnonzero(free)[0])]
            raise ParameterError("point_loads", spec, "a name or pattern that matches a "
                                 f"free block (names are like {example!r}; see bricks.obj "
                                 "or locations.csv)")
        chosen += matched
        forces += [force] * len(matched)
    chosen = np.asarray(chosen, dtype=np.int64)
    wrench = _at_points(blocks, chosen, blocks.face_centre[top[chosen]],
                        np.asarray(forces, dtype=float))
    if not np.any(wrench[:, :3]):
        raise ParameterError("point_loads", specs[0], "point loads that do not cancel "
                             "(these add up to zero on every block they match)")
    return LiveLoad(wrench, _describe("point", wrench, specs=list(specs),
                                      blocks=len(np.unique(chosen))))


def point_load_spec(blocks, block: int, force, point=None, length_tol: float = 0.0) -> str:
    """The ``'NAME:FX,FY,FZ'`` spec of a force ``force`` ((3,) N) at ``point`` ((3,) m;
    None: the block's centroid) on block ``block``, when it is one: its line of action
    passes within ``length_tol`` (m) of the centre of the block's top face, where
    :func:`point_loads` applies it (the same force, the same moment about any point).

    Raises
    ------
    ValueError
        The line of action misses that centre (by how much), or the block is a support.
    """
    name = str(blocks.block_name[block])
    if blocks.block_is_support[block]:
        raise ValueError(f"block {name} is a support: a load on it changes nothing")
    force = np.asarray(force, dtype=float)
    at = blocks.block_centroid[block] if point is None else np.asarray(point, dtype=float)
    lever = blocks.face_centre[top_faces(blocks)[block]] - at
    norm = float(np.linalg.norm(force))
    miss = float(np.linalg.norm(np.cross(lever, force))) / norm if norm else 0.0
    if miss > length_tol:
        raise ValueError(f"its line of action misses the centre of block {name}'s top face "
                         f"by {miss:.3g} m, where masonry applies point loads")
    escaped = "".join(f"[{c}]" if c in "*?[" else c for c in name)  # a name, not a pattern
    return f"{escaped}:{','.join(repr(float(v)) for v in force)}"


def top_course(blocks) -> np.ndarray:
    """(m,) int: the free blocks whose top lies in the highest course (a pattern brick
    spans its course and the next, docs/model.md 2)."""
    free = ~np.asarray(blocks.block_is_support)
    reach = blocks.block_course + (blocks.block_class == PATTERN)
    if not (free & (blocks.block_course > 0)).any():
        raise ValueError("a crown load needs courses: this scene has none")
    return np.flatnonzero(free & (reach == reach[free].max()))


def crown_load(blocks, newtons: float, copies: int = 1) -> LiveLoad:
    """A downward load of ``newtons`` on the top course of a dome, shared by top-face area.

    Each top-course brick carries ``newtons / copies * A_j / sum A`` at the centre of its
    top face (``A_j`` that face's area): a lantern on the oculus ring. The same load in
    every web, so a cyclic section may carry it.

    Parameters
    ----------
    blocks : masonry.blocks.Blocks (or a Model)
    newtons : float, N
        The whole load (the lantern's weight on the whole dome).
    copies : int
        How many copies of these blocks the dome is made of: ``n`` for a section (it
        carries its ``1/n`` share), 1 for the full dome.
    """
    blocks = _blocks(blocks)
    chosen = top_course(blocks)
    face = top_faces(blocks)[chosen]
    share = blocks.face_area[face] / blocks.face_area[face].sum()
    force = np.zeros((len(chosen), 3))
    force[:, 2] = -newtons / copies * share
    wrench = _at_points(blocks, chosen, blocks.face_centre[face], force)
    return LiveLoad(wrench, _describe("crown", wrench, newtons=float(newtons),
                                      copies=int(copies), blocks=len(chosen)))


# ---------------------------------------------------------------------- load cases
def parse_point_load(spec: str) -> tuple:
    """``'NAME_OR_PATTERN:FX,FY,FZ'`` -> ``(pattern, (fx, fy, fz))`` in newtons; raises
    :class:`~masonry.errors.ParameterError` naming ``point_loads`` (``--point-load``)."""
    expected = "NAME_OR_PATTERN:FX,FY,FZ (a block name or fnmatch pattern, newtons)"
    pattern, colon, numbers = str(spec).rpartition(":")
    parts = numbers.split(",")
    if not colon or not pattern or len(parts) != 3:
        raise ParameterError("point_loads", spec, expected)
    try:
        force = tuple(float(v) for v in parts)
    except ValueError:
        raise ParameterError("point_loads", spec, expected) from None
    if not all(math.isfinite(v) for v in force) or not any(force):
        raise ParameterError("point_loads", spec, "finite forces, not all zero")
    if max(abs(v) for v in force) < MIN_LIVE_LOAD_N:
        raise ParameterError("point_loads", spec, f"a force of at least {MIN_LIVE_LOAD_N:g} "
                                                  "N (a smaller one has no finite load "
                                                  "factor)")
    if max(abs(v) for v in force) > MAX_LIVE_LOAD_N:
        raise ParameterError("point_loads", spec, f"forces of at most {MAX_LIVE_LOAD_N:g} N")
    return pattern, force


@dataclass(frozen=True)
class Lateral:
    """A horizontal body force of each block's weight at ``azimuth_deg`` (degrees from +x
    toward +y, in [0, 360)), or ``'all'``: the worst azimuth of a search."""

    azimuth_deg: float | str

    kind = "lateral"

    @property
    def tag(self) -> str:
        """Its part of a structure id: ``_latall`` or ``_lat<azimuth>``."""
        return "_latall" if self.azimuth_deg == "all" else f"_lat{text_of(self.azimuth_deg)}"

    def options(self) -> dict:
        return {"lateral": self.azimuth_deg}

    def on(self, model, density, copies=1) -> LiveLoad:
        return lateral(model, self.azimuth_deg, density)


READABLE_TAG = re.compile(r"[A-Za-z0-9_.,:-]+")
"""A point load named as written in a structure id (:attr:`PointLoads.tag`): characters
every file system takes, without the tag's own ``@`` and ``+`` (so two lists of loads
never share a name); a pattern's ``*`` or ``?``, or ``1e+3``, goes by a digest."""

READABLE_TAG_CHARS = 40
"""The longest point loads named as written in a structure id; longer ones go by a
digest."""


@dataclass(frozen=True)
class PointLoads:
    """Forces at the top faces of named blocks: ``specs`` as the user wrote them
    (``'NAME_OR_PATTERN:FX,FY,FZ'``) and ``loads`` parsed, ``(pattern, (fx, fy, fz))``."""

    specs: tuple
    loads: tuple

    kind = "point"

    @classmethod
    def parse(cls, specs) -> "PointLoads":
        specs = (specs,) if isinstance(specs, str) else tuple(specs)
        if not all(isinstance(spec, str) for spec in specs):
            raise ParameterError("point_loads", specs, "NAME_OR_PATTERN:FX,FY,FZ strings")
        return cls(specs, tuple(parse_point_load(spec) for spec in specs))

    @property
    def tag(self) -> str:
        """``_pl`` and the specs as written, ``:`` as ``@`` and joined by ``+``
        (``_pl_w0_b0123@0,0,-1000``), where they are short and of characters every file
        system takes (:data:`READABLE_TAG`); else ``_pl`` and a digest of them."""
        text = "+".join(self.specs)
        if len(text) <= READABLE_TAG_CHARS and all(map(READABLE_TAG.fullmatch, self.specs)):
            return f"_pl_{text.replace(':', '@')}"
        return f"_pl{hashlib.sha1(chr(10).join(self.specs).encode()).hexdigest()[:8]}"

    def options(self) -> dict:
        return {"point_loads": self.specs}

    def on(self, model, density, copies=1) -> LiveLoad:
        return point_loads(_blocks(model), self)


@dataclass(frozen=True)
class CrownLoad:
    """A downward load of ``newtons`` on the top course of a dome (the whole dome's)."""

    newtons: float

    kind = "crown"

    @property
    def tag(self) -> str:
        return f"_crown{text_of(self.newtons)}"

    def options(self) -> dict:
        return {"crown_load": self.newtons}

    def on(self, model, density, copies=1) -> LiveLoad:
        """On a model that is one of ``copies`` equal parts of the dome (a section: its
        share)."""
        return crown_load(_blocks(model), self.newtons, copies=copies)


LOAD_OPTIONS = ("lateral", "point_loads", "crown_load")
"""The options that name a load case, in the order a run checks them."""


def live_load(lateral=None, point_loads=(), crown_load=None):
    """The load case of a run's options (one of :data:`LOAD_OPTIONS` at most), or None.

    ``lateral`` an azimuth in degrees (a number or its text) or ``'all'``, ``point_loads``
    ``'NAME_OR_PATTERN:FX,FY,FZ'`` strings, ``crown_load`` newtons. Raises
    :class:`~masonry.errors.ParameterError` naming the option.
    """
    given = []
    if lateral is not None:
        given.append(("lateral", lateral, Lateral(_azimuth(lateral))))
    if not isinstance(point_loads, (tuple, list, str)):
        raise ParameterError("point_loads", point_loads, "NAME_OR_PATTERN:FX,FY,FZ strings")
    if point_loads:
        case = PointLoads.parse(point_loads)
        given.append(("point_loads", case.specs[0], case))
    if crown_load is not None:
        if isinstance(crown_load, bool) or not isinstance(crown_load, (int, float)):
            raise ParameterError("crown_load", crown_load, "a number")
        if not math.isfinite(crown_load):
            raise ParameterError("crown_load", crown_load, "a finite number")
        if not crown_load >= MIN_LIVE_LOAD_N:
            raise ParameterError("crown_load", crown_load,
                                 f">= {MIN_LIVE_LOAD_N:g} (newtons, downward; a smaller "
                                 f"load has no finite load factor)")
        if crown_load > MAX_LIVE_LOAD_N:
            raise ParameterError("crown_load", crown_load,
                                 f"at most {MAX_LIVE_LOAD_N:g} (newtons)")
        given.append(("crown_load", crown_load, CrownLoad(float(crown_load))))
    if len(given) > 1:
        raise ParameterError(*given[1][:2], "one live load per run: --lateral, --point-load "
                                            "or --crown-load", related=(given[0][0],))
    return given[0][2] if given else None


def _azimuth(value) -> float | str:
    """An azimuth in [0, 360) degrees, or ``'all'``."""
    expected = "an azimuth in degrees or 'all'"
    if value == "all":
        return "all"
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            raise ParameterError("lateral", value, expected) from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError("lateral", value, expected)
    if not math.isfinite(value):
        raise ParameterError("lateral", value, "a finite number")
    return float(value) % 360.0
