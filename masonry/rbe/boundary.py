"""Dome boundary conditions of a section, and the full dome (docs/model.md 4.6, 6.4).

A section's boundary mode decides what its end bricks bear on in the corner planes:

- ``free``: nothing (the thesis's ``dome = False``).
- ``rigid``: the neighbouring webs, immovable. Their end bricks are added as *images*
  (the section's own end bricks rotated by +-2 pi/n) that are fixed supports.
- ``cyclic``: exact rotational symmetry. The image of the next web (+2 pi/n) is added;
  the force an image receives at an interface is the force the brick it copies receives,
  rotated by 2 pi/n, so the RBE routes that side of the interface onto the copied brick
  with the rotation ``R(-2 pi/n)``. Under self weight the full dome is rotationally
  symmetric and the QP's objective strictly convex, so its unique solution is symmetric:
  the cyclic section reproduces the full dome's forces on that web.

The thesis's ``dome = True`` adds a hoop term (eq. 3.19-3.20) that it doubts itself (5.5);
``rigid`` and ``cyclic`` replace it with two well-defined models.

Interfaces between blocks of different webs are named ``boundary``, in a section with
images and in the full dome alike.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components

from masonry.blocks import Blocks, concatenate, rotated_web, rotation_z
from masonry.errors import MasonryError
from masonry.interfaces import INTERFACE_KINDS, Interfaces, detect

BOUNDARY = INTERFACE_KINDS.index("boundary")


@dataclass(frozen=True, eq=False)
class Model:
    """What the RBE analyses: blocks (the scene's, then any images), interfaces, and the
    routing of interface sides for cyclic symmetry (None: every side acts on its block).

    Parameters
    ----------
    blocks : Blocks
        The scene's blocks first (indices unchanged), then the neighbour images.
    interfaces : Interfaces
    side_block : (K, 2) int or None
        Block that receives each side's force (see :func:`masonry.rbe.equilibrium.assemble`).
    side_rotation : (K, 2, 3, 3) float or None
        Rotation applied to each side's force and lever arm.
    block_source : (B,) int or None
        The scene block each block is (the scene's blocks) or copies (an image); None:
        every block is the scene's own (no images).
    dropped_rows : (B, 6) bool or None
        Equilibrium rows a block drops (a half model's blocks cut by its mirror plane,
        :mod:`masonry.rbe.mirror`); None: none.
    vertex_share : (IV,) float or None
        The share of the whole structure's force each interface vertex carries (a half
        model's, :mod:`masonry.rbe.mirror`); None: all of it.
    """

    blocks: Blocks
    interfaces: Interfaces
    side_block: np.ndarray | None = None
    side_rotation: np.ndarray | None = None
    block_source: np.ndarray | None = None
    dropped_rows: np.ndarray | None = None
    vertex_share: np.ndarray | None = None

    @property
    def boundary_count(self) -> int:
        return int((self.interfaces.kind == BOUNDARY).sum())

    def block_largest(self, values) -> np.ndarray:
        """(B,) float: the largest of per-interface ``values`` ((K,), >= 0) over the
        interfaces each block bears on, 0 where none; an interface side routed elsewhere
        (``side_block``, cyclic symmetry) counts for the block it acts on."""
        sides = self.interfaces.pair if self.side_block is None else self.side_block
        largest = np.zeros(self.blocks.n_blocks)
        for side in (0, 1):
            np.maximum.at(largest, sides[:, side], np.asarray(values, dtype=float))
        return largest

    @property
    def assembly(self) -> dict:
        """What :func:`masonry.rbe.equilibrium.assemble` takes from the model besides its
        blocks and interfaces: the routing, the dropped rows, the vertices' shares."""
        return dict(side_block=self.side_block, side_rotation=self.side_rotation,
                    dropped_rows=self.dropped_rows, vertex_share=self.vertex_share)


class UnsupportedError(MasonryError, ValueError):
    """Some blocks have no path of contacts to a support: nothing can carry them, and no
    equilibrium (not even friction+) exists. The message names them."""


def unsupported_blocks(blocks: Blocks, interfaces: Interfaces) -> np.ndarray:
    """Indices of the free blocks that no chain of interfaces joins to a support.

    Returns
    -------
    (k,) int
    """
    n = blocks.n_blocks
    pair = interfaces.pair
    graph = coo_array((np.ones(len(pair)), (pair[:, 0], pair[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    carried = np.isin(label, label[blocks.block_is_support])
    return np.flatnonzero(~carried)


def check_supported(model: "Model") -> None:
    """Raise :class:`UnsupportedError` naming the blocks of ``model`` that no chain of
    interfaces joins to a support (before any solve)."""
    lost = unsupported_blocks(model.blocks, model.interfaces)
    if len(lost) == 0:
        return
    names = model.blocks.block_name
    shown = ", ".join(repr(str(names[i])) if names is not None else str(i) for i in lost[:5])
    more = f" and {len(lost) - 5} more" if len(lost) > 5 else ""
    raise UnsupportedError(
        f"{len(lost)} of {model.blocks.n_blocks} blocks have no path of contacts to a "
        f"support: {shown}{more}. Nothing can carry them: a block floating, touching only "
        f"along an edge or at a point, or with a gap wider than the contact tolerance")


def _mark_web_boundaries(interfaces: Interfaces, blocks: Blocks) -> Interfaces:
    web = blocks.block_web[interfaces.pair]
    kind = np.where(web[:, 0] != web[:, 1], BOUNDARY, interfaces.kind).astype(np.int8)
    return dataclasses.replace(interfaces, kind=kind)


def analysis_model(scene, boundary: str) -> Model:
    """Blocks, interfaces and routing for the scene and its boundary mode.

    Parameters
    ----------
    scene : masonry.scenes.base.Scene
    boundary : {'free', 'rigid', 'cyclic'}
        What a section's end bricks bear on (docs/model.md 6.4): nothing, immovable
        neighbours, or its neighbours by rotational symmetry; one of the modes its kind
        takes (``scene.kind.boundaries``).

    Raises
    ------
    UnsupportedError
        Some block has no path of contacts to a support (:func:`check_supported`).
    """
    if boundary not in scene.kind.boundaries:
        raise ValueError(f"a {scene.kind.name} scene takes boundary "
                         f"{' or '.join(scene.kind.boundaries)}, not {boundary!r}")
    model = _model(scene, boundary)
    check_supported(model)
    return model


def _model(scene, mode) -> Model:
    if mode == "free":
        interfaces = detect(scene.blocks, up=scene.block_up)
        return Model(scene.blocks, _mark_web_boundaries(interfaces, scene.blocks))

    n = scene.symmetry.order
    left, right = scene.kind.edge_blocks(scene)
    # images of the next web's left end, and (rigid) of the previous web's right end
    images = [(1, left)] + ([(-1, right)] if mode == "rigid" else [])
    parts, sources, ups = [scene.blocks], [], [scene.block_up]
    for web, mask in images:
        part = rotated_web(scene.blocks, web, n, mask)
        parts.append(dataclasses.replace(part, block_is_support=np.ones(part.n_blocks, bool)))
        sources.append(np.flatnonzero(mask))
        ups.append(scene.block_up[mask] @ rotation_z(2 * np.pi * web / n).T)
    blocks = concatenate(parts)
    interfaces = _mark_web_boundaries(detect(blocks, up=np.concatenate(ups)), blocks)
    count = scene.blocks.n_blocks
    source = np.concatenate([np.arange(count), *sources])
    if mode == "rigid":
        return Model(blocks, interfaces, block_source=source)

    # cyclic: an image's side acts on the brick it copies, rotated back by -2 pi/n
    side_block = source[interfaces.pair]
    is_image = interfaces.pair >= count
    side_rotation = np.broadcast_to(np.eye(3), (len(interfaces), 2, 3, 3)).copy()
    side_rotation[is_image] = rotation_z(-2 * np.pi / n)
    return Model(blocks, interfaces, side_block, side_rotation, block_source=source)


def kept_blocks(model: Model, is_present) -> np.ndarray:
    """(B,) bool: the blocks of ``model`` that :func:`restrict` keeps for ``is_present``
    ((S,) bool per scene block): the present ones, the images of those present, and the
    scene's supports."""
    blocks = model.blocks
    source = (np.arange(blocks.n_blocks) if model.block_source is None
              else model.block_source)
    is_present = np.asarray(is_present, dtype=bool)
    return is_present[source] | blocks.block_is_support & (source == np.arange(len(source)))


def restrict(model: Model, is_present) -> Model:
    """The model of a part of the scene: the blocks present, the images of those present,
    and the interfaces of ``model`` whose two blocks are both kept (docs/model.md 4.7: a stage of
    construction; interfaces are filtered, never detected again).

    Parameters
    ----------
    model : Model
        Of the whole scene (:func:`analysis_model`).
    is_present : (S,) bool
        Per scene block (the first ``S`` blocks of ``model``): present. Supports are
        kept whatever it says.

    Returns
    -------
    Model
        Blocks in their order in ``model``; ``block_source`` still indexes the scene's
        blocks, so results map back to them. The routing of a kept interface is
        unchanged: a cyclic image is kept only with the brick it copies.
    """
    blocks = model.blocks
    source = (np.arange(blocks.n_blocks) if model.block_source is None
              else model.block_source)
    keep = kept_blocks(model, is_present)
    index = np.flatnonzero(keep)
    remap = np.full(blocks.n_blocks, -1)
    remap[index] = np.arange(len(index))
    chosen = keep[model.interfaces.pair].all(axis=1)
    side_block = None if model.side_block is None else remap[model.side_block[chosen]]
    side_rotation = None if model.side_rotation is None else model.side_rotation[chosen]
    dropped = None if model.dropped_rows is None else model.dropped_rows[index]
    share = (None if model.vertex_share is None else
             model.vertex_share[np.repeat(chosen, model.interfaces.vertex_count)])
    return Model(blocks.subset(index), model.interfaces.subset(chosen, remap), side_block,
                 side_rotation, block_source=source[index], dropped_rows=dropped,
                 vertex_share=share)
