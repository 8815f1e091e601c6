"""What a scene is: the blocks one run models, and how a dome's bricks were laid out."""

from dataclasses import dataclass

import numpy as np

from masonry.blocks import Blocks
from masonry.dome.courses import Layout
from masonry.dome.levels import Dimensions, LevelTable
from masonry.dome.pattern import Pattern
from masonry.params import Params


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

    def cad_vertices(self) -> np.ndarray:
        """(V, 3) float, metres: the vertices moved inward by ``cad_offset`` units along
        each block's inward normal (``block_inward``; thesis 3.4.1), as ``locations.csv``
        and the printable body use them. Scenes without one are not moved."""
        blocks = self.blocks
        if self.block_inward is None:
            return blocks.vertices
        shift = self.params.cad_offset * self.params.unit * self.block_inward
        return blocks.vertices + np.repeat(shift, np.diff(blocks.vertex_offsets), axis=0)


def hexahedra_frames(blocks: Blocks):
    """``(up, inward)`` of hexahedral bricks: the normals of their top face (face 5) and of
    their inner face (face 0), see :data:`masonry.blocks.HEX_FACES`."""
    first = np.searchsorted(blocks.face_block, np.arange(blocks.n_blocks))
    return blocks.face_normal[first + 5], blocks.face_normal[first]
