"""Triangle soups: what a mesh or COMPAS file holds, before the blocks are checked
(:mod:`masonry.scenes.mesh_files`, :mod:`masonry.scenes.compas_json`), and the error
every reader raises."""

from dataclasses import dataclass, field

import numpy as np

from masonry.errors import MasonryError


class AssemblyError(MasonryError, ValueError):
    """A mesh file cannot be read, or one of its blocks is not a closed convex solid
    (:mod:`masonry.scenes.imported`). The message names the file and, for a bad block,
    the block."""


@dataclass(frozen=True)
class TriangleSoup:
    """Triangles of named blocks, as a file holds them (struct of arrays).

    Attributes
    ----------
    block_name : list of str
        (B,) names as read; an empty string where the file gives none.
    vertices : (V, 3) float64, metres
        As written in the file (float32 files widened exactly).
    triangles : (T, 3) int64
        Corners, indices into ``vertices``, in file order.
    triangle_block : (T,) int64
        Block of every triangle, index into ``block_name``.
    split_bodies : bool
        The file names no blocks: the soup's connected bodies are its blocks (then
        ``block_name`` holds one name, the one the file gives its only object or group,
        or an empty string).
    block_is_support : (B,) bool or None
        The supports the file flags (a COMPAS assembly's ``is_support``); None: the
        format has no such flag.
    problem : masonry.scenes.compas_problem.ProblemInputs or None
        The analysis inputs a compas_dem Problem states; None for other files.
    """

    block_name: list = field(default_factory=list)
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))
    triangle_block: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    split_bodies: bool = False
    block_is_support: np.ndarray | None = None
    problem: object = None

    def __post_init__(self):
        object.__setattr__(self, "block_name", list(self.block_name))
        object.__setattr__(self, "vertices",
                           np.asarray(self.vertices, dtype=float).reshape(-1, 3))
        object.__setattr__(self, "triangles",
                           np.asarray(self.triangles, dtype=np.int64).reshape(-1, 3))
        object.__setattr__(self, "triangle_block",
                           np.asarray(self.triangle_block, dtype=np.int64))
        if self.block_is_support is not None:
            object.__setattr__(self, "block_is_support",
                               np.asarray(self.block_is_support, dtype=bool))

    @property
    def supports(self) -> np.ndarray:
        """(B,) bool: :attr:`block_is_support`, or no support where the file flags none."""
        if self.block_is_support is None:
            return np.zeros(len(self.block_name), bool)
        return self.block_is_support


def fan(flat, counts):
    """Polygons (flat indices, (n,) vertex counts) -> fan triangles (T, 3) and their
    polygon (T,)."""
    ntri = counts - 2
    face = np.repeat(np.arange(len(counts)), ntri)
    start = np.cumsum(counts) - counts
    k = np.arange(len(face)) - np.repeat(np.cumsum(ntri) - ntri, ntri)
    s = start[face]
    return np.stack([flat[s], flat[s + k + 1], flat[s + k + 2]], axis=1), face
