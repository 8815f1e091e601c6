"""Mirror symmetry: a model solved on its half (docs/model.md 6.11).

A model that is its own mirror image in a vertical plane through the z axis, under a load
that is too (self weight, a crown load, a lateral load along the plane), has a symmetric
optimum among its optima: the mirror image of a solution is a solution, and so is the
mean of the two, the programs being convex (the RBE's quadratic program has one optimum,
which is therefore symmetric). The symmetric solutions are the solutions of the half:

- The blocks on one side of the plane. A block the plane cuts is its own mirror image; it
  becomes its half on that side (the hull of its vertices there and of its edges'
  crossings with the plane), of half its weight, at the half's centroid.
- A cut block keeps its motion in the plane: by symmetry the other half holds it there,
  with a force normal to the plane and moments about the two axes in it (unconstrained
  reactions). Its rows of these three are dropped.
- An interface on one side keeps its vertices. One cut by the plane (between two cut
  blocks, or a cut block and a cut support) keeps its vertices on that side and in the
  plane; a vertex in the plane stands for one force of the whole, of which the half
  carries half (its ``vertex_share`` 1/2). Its other vertices' forces are the mirror
  images of these.
- A joint in the plane, between a brick and its mirror image, carries a normal force
  only (the mirror image of the force on one brick is the force on the other). The
  image is kept as a support and its side of the joint is routed onto the brick with
  the reflection, as a cyclic image's is with a rotation (docs/model.md 6.4): the two sides'
  friction cancels and their normal forces add, so the brick receives twice the
  vertices' compression: half the whole's per variable (``vertex_share`` 1/2).
- A side the whole routes onto a block on the other side (a cyclic section's image of
  the next web, routed onto a left end brick) goes to that block's mirror image, with
  the reflection: the half web of a cyclic section is bounded by two mirror planes, its
  mid-plane and its corner plane.

With a vertex's variables carrying ``share`` times the whole's force and weighed by
``h / share`` in the objective (:func:`masonry.rbe.equilibrium.assemble`), the half's
objective is half the whole's on every symmetric point, and its equilibrium rows are
the whole's rows of the blocks on that side, and half the kept rows of a cut block (its
weight is half, and the kept rows of the force in the plane and the moment about the
plane's normal are the same about either centroid, which differ along that normal only).
So the half's programs are the whole's restricted to symmetric points: the same collapse
load factor, and the same RBE optimum, mirrored.

The half is posed with its mirror plane as the xz-plane: the model turned by minus the
plane's azimuth, so that the dropped rows are a cut block's scaled rows ``Fy`` (1),
``Mx`` (3) and ``Mz`` (5) of docs/model.md 6.2, zero in ``A_eq``, ``f_ext`` and every
live load (:attr:`~masonry.rbe.equilibrium.EquilibriumSystem.row_kept`). :class:`Half`
maps its forces and its mechanism back onto the whole (turned back, mirrored onto the
other side).
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, cKDTree

from masonry.blocks import Blocks, blocks_from_hulls, concatenate, hull_faces, rotation_z
from masonry.errors import MasonryError
from masonry.friction import FrictionCone
from masonry.interfaces import Interfaces
from masonry.rbe.boundary import Model
from masonry.rbe.equilibrium import assemble
from masonry.rbe.loads import CrownLoad, Lateral
from masonry.rbe.solvers.residuals import rbe_residuals
from masonry.tolerances import (MIRROR_ANGLE_DEG, MIRROR_NORMAL_MISS, MIRROR_VOLUME_REL,
                                Tolerances)

MIRROR = np.diag([1.0, -1.0, 1.0])
"""The reflection in the xz-plane, the half's mirror plane."""

DROPPED = np.array([False, True, False, True, False, True])
"""The rows a cut block drops, in the half's frame: the force along y, the moments about x
and z (docs/model.md 6.2's row order)."""

class MirrorError(MasonryError, ValueError):
    """The model is not its own mirror image in the plane asked for (a block, an interface
    or a vertex without its image); the message names the first."""


@dataclass(frozen=True, eq=False)
class Half:
    """The half of a model symmetric in a vertical plane, and the map back onto it.

    Parameters
    ----------
    model : Model
        The half, turned so that its mirror plane is the xz-plane and its side is y > 0.
    whole : Model
        The model it is the half of.
    azimuth_deg : float
        The mirror plane's azimuth in the whole, degrees.
    block_source : (B_w,) int
        The half's block that is each whole block or its mirror image; -1 for an image
        of the whole without one (a cyclic section's image of the next web's end).
    block_mirrored : (B_w,) bool
        The whole block is the mirror image of its source.
    vertex_source : (IV_w, 2) int
        The half's vertices whose forces make each whole vertex's: itself or its mirror
        image, and a partner (-1: none) where a half vertex carries half a force of the
        whole (a vertex in the plane, a joint sent across it): the whole's ``c`` and
        ``t`` are their sum.
    friction_map : (IV_w, 2, 2, 2) float
        Per source, the map of its ``(f1, f2)`` into the whole vertex's: the tangential
        force as it is, mirrored, or mapped by the partner's routing, in the whole
        vertex's frame.
    """

    model: Model
    whole: Model
    azimuth_deg: float
    block_source: np.ndarray
    block_mirrored: np.ndarray
    vertex_source: np.ndarray
    friction_map: np.ndarray

    @property
    def turn(self) -> np.ndarray:
        """(3, 3): the rotation from the half's frame to the whole's."""
        return rotation_z(np.radians(self.azimuth_deg))

    def whole_forces(self, x) -> np.ndarray:
        """(4 IV_w,) float: the whole's vertex forces ``(c, t, f1, f2)`` from the half's
        ``x`` ((4 IV,) float, any unit)."""
        forces = np.asarray(x, dtype=float).reshape(-1, 4)
        given = (self.vertex_source >= 0)[:, :, None]
        source = np.where(given, forces[np.maximum(self.vertex_source, 0)], 0.0)
        out = np.empty((len(source), 4))
        out[:, :2] = source[:, :, :2].sum(axis=1)
        out[:, 2:] = np.einsum("vsij,vsj->vi", self.friction_map, source[:, :, 2:])
        return out.ravel()

    def whole_motion(self, motion) -> np.ndarray:
        """(B_w, 6) float: every whole block's ``(u, theta)`` from the half's blocks'
        ``motion`` ((B, 6) float, the half's frame): mirrored onto the other side (a
        rotation is a pseudovector: ``-M theta``), turned back."""
        motion = np.asarray(motion, dtype=float)
        out = np.zeros((len(self.block_source), 6))
        own = self.block_source >= 0
        out[own] = motion[self.block_source[own]]
        flip = self.block_mirrored
        out[flip, :3] = out[flip, :3] @ MIRROR
        out[flip, 3:] = -out[flip, 3:] @ MIRROR
        turn = self.turn
        out[:, :3] = out[:, :3] @ turn.T
        out[:, 3:] = out[:, 3:] @ turn.T
        return out

    def live(self, case, density: float, copies: int = 1):
        """The half's share of the load ``case`` (a :class:`~masonry.rbe.loads.Lateral`
        along the plane or a :class:`~masonry.rbe.loads.CrownLoad`) on a model that is
        one of ``copies`` parts of the structure (:meth:`CrownLoad.on`)."""
        if isinstance(case, Lateral):
            case = Lateral(float(case.azimuth_deg) - self.azimuth_deg)
        return case.on(self.model, density, copies=2 * copies)


def equilibrium_on_the_whole(half: Half, result, density: float):
    """An RBE result of ``half.model`` (:class:`~masonry.rbe.result.RBEResult`, at
    ``density``) as its whole's: the forces mirrored back, the objective, the MoI, the
    weight and the residuals computed again on the whole's matrices (the residuals check
    the map); the verdict and the solvers' record stay the half's."""
    whole = half.whole
    system = assemble(whole.blocks, whole.interfaces, mu=result.mu, density=density,
                      cone=result.cone, **whole.assembly)
    weight = system.total_weight
    if result.x is None:
        return dataclasses.replace(result, layout=system.layout, weight_N=weight,
                                   moi_factor=result.moi / weight)
    x = half.whole_forces(result.x)
    checks = rbe_residuals(system, system.to_scaled(x), result.friction)
    moi = float(system.layout.component(x, "t").sum())
    return dataclasses.replace(
        result, x=x, layout=system.layout, objective=float(0.5 * np.sum(system.h * x**2)),
        moi=moi, moi_factor=moi / weight, weight_N=weight, residual_eq=checks.equilibrium,
        friction_violation=checks.friction, net_friction_violation=checks.net_friction)


def states_exactly(cone, cohesion=0.0) -> bool:
    """Whether a half states the friction model ``cone`` (a name or a
    :class:`~masonry.friction.FrictionCone`) exactly: Coulomb's cone is its own mirror
    image in any joint's frame; a pyramid is only where the joints' axes are mirror
    images of each other, which the half does not ask of a model. A ``cohesion`` (Pa)
    is not: a joint cut by the plane has other vertices, so other tributary areas, in
    the half than in the whole (:func:`masonry.contact.tributary_area`)."""
    return not FrictionCone.parse(cone).is_polyhedral and cohesion == 0


def symmetric_plane(case, mirrors) -> float | None:
    """The mirror plane (an azimuth of ``mirrors``, degrees) in which the load ``case`` is
    its own mirror image, or None: a lateral load along a plane, a crown load in any
    (the first); None for point loads and for a search of azimuths."""
    if isinstance(case, CrownLoad):
        return float(mirrors[0]) if len(mirrors) else None
    if isinstance(case, Lateral) and case.azimuth_deg != "all":
        return in_plane(float(case.azimuth_deg), mirrors)
    return None


def in_plane(azimuth_deg: float, mirrors) -> float | None:
    """The plane of ``mirrors`` (azimuths, degrees) that holds the horizontal direction
    ``azimuth_deg``, or None."""
    for plane in mirrors:
        offset = (azimuth_deg - plane) % 180.0
        if min(offset, 180.0 - offset) <= MIRROR_ANGLE_DEG:
            return float(plane)
    return None


def half_model(model: Model, azimuth_deg: float) -> Half:
    """The half of ``model`` in the vertical plane at ``azimuth_deg`` degrees, on the side
    of the plane's normal ``(-sin a, cos a, 0)`` (module docstring).

    Raises
    ------
    MirrorError
        ``model`` is not its own mirror image in that plane.
    """
    turn = rotation_z(np.radians(azimuth_deg))
    blocks = model.blocks.transformed(_motion(turn.T))
    interfaces = _turned_interfaces(model.interfaces, turn)
    tol = Tolerances.for_points(blocks.vertices).contact
    name = f"the plane at {azimuth_deg:g} degrees"
    mirror = _mirror_blocks(blocks, tol)
    side = _sides(blocks.block_centroid[:, 1], tol)
    wrong = np.flatnonzero(~blocks.block_is_support & (mirror < 0) | (side == 0)
                           & (mirror != np.arange(len(mirror))))
    if len(wrong):
        raise MirrorError(f"the model is not its own mirror image in {name}: block "
                          f"{blocks.block_name[wrong[0]]!r} has none")
    link = _Link(model, interfaces, turn, mirror, side,
                 _sides(interfaces.centre[:, 1], tol), tol, name)
    half_blocks, index, cut = _half_blocks(blocks, side, link.kept_pairs(), tol)
    dropped = np.zeros((half_blocks.n_blocks, 6), bool)
    dropped[index[cut & ~blocks.block_is_support]] = DROPPED
    whole_of = np.empty(half_blocks.n_blocks, int)
    whole_of[index[index >= 0]] = np.flatnonzero(index >= 0)
    source = (np.arange(blocks.n_blocks) if model.block_source is None
              else model.block_source)
    half = Model(half_blocks, link.half_interfaces(index), index[link.block],
                 link.rotation, block_source=source[whole_of], dropped_rows=dropped,
                 vertex_share=link.share)
    mirrored = (side < 0) & (mirror >= 0)
    block_source = np.where(side >= 0, index, -1)
    block_source[mirrored] = index[mirror[mirrored]]
    return Half(half, model, float(azimuth_deg), block_source, mirrored,
                *link.whole_map())


def _motion(rotation) -> np.ndarray:
    """(4, 4): the rigid motion of ``rotation`` ((3, 3)) about the origin."""
    out = np.eye(4)
    out[:3, :3] = rotation
    return out


def _turned_interfaces(interfaces: Interfaces, turn) -> Interfaces:
    """``interfaces`` in the frame turned by ``turn`` ((3, 3), the frame's axes)."""
    return Interfaces(pair=interfaces.pair, kind=interfaces.kind,
                      vertices=interfaces.vertices @ turn, offsets=interfaces.offsets,
                      area=interfaces.area, centre=interfaces.centre @ turn,
                      normal=interfaces.normal @ turn, t1=interfaces.t1 @ turn,
                      t2=interfaces.t2 @ turn)


def _sides(y, tol) -> np.ndarray:
    """(n,) int: +1 above the plane (y > tol), 0 in it, -1 below."""
    return np.where(y > tol, 1, np.where(y < -tol, -1, 0))


def _mirror_blocks(blocks: Blocks, tol) -> np.ndarray:
    """(B,) int: the block that is each block's mirror image (centroid and volume), -1
    for none."""
    centroid = blocks.block_centroid
    distance, image = cKDTree(centroid).query(centroid @ MIRROR)
    volume = blocks.block_volume
    same = (distance <= tol) & np.isclose(volume[image], volume, rtol=MIRROR_VOLUME_REL,
                                          atol=0.0)
    return np.where(same, image, -1)


class _Link:
    """How the whole's interfaces and their vertices stand to the half's
    (:func:`half_model`): which are kept, the mirror image of each one in the plane or on
    the other side, the routing of the kept ones' sides, and the map of every whole
    vertex onto the half's vertices.

    ``block_side`` (B,) and ``side`` (K,) int: each block's and each interface's side of
    the plane (their centroid's or centre's), 0 in it."""

    def __init__(self, model: Model, interfaces: Interfaces, turn, mirror, block_side,
                 side, tol, name):
        self.interfaces, self.mirror, self.side, self.tol = interfaces, mirror, side, tol
        self.name = name
        self.kept = side >= 0
        self.image, self.sign = self._images()
        self.block, self.rotation, across = self._routing(model, turn, block_side)
        vertex = interfaces.vertex_interface
        y = interfaces.vertices[:, 1]
        on = side[vertex] == 0
        self.vertex_kept = (side[vertex] > 0) | on & (y >= -tol)
        self.half_index = np.cumsum(self.vertex_kept) - 1
        self.across = np.zeros((len(interfaces), 2), bool)
        self.across[self.kept] = across
        self.partner, self.partner_force = self._partners(on & (np.abs(y) <= tol))
        self.share = np.where(self.partner >= 0, 0.5, 1.0)[self.vertex_kept]
        """(IV,) float: the half's vertex shares."""

    def _fail(self, what):
        raise MirrorError(f"the model is not its own mirror image in {self.name}: {what}")

    def _images(self) -> tuple:
        """(K,) int, (K,) float: the mirror image of every interface in the plane or on
        the other side (itself in the plane), and +1 where it joins the mirror images of
        the same blocks in the same order (main block first), -1 where in the other;
        -1 and 0 on the kept side."""
        interfaces, mirror = self.interfaces, self.mirror
        image, sign = np.full(len(interfaces), -1), np.zeros(len(interfaces))
        which = np.flatnonzero(self.side <= 0)
        distance, found = cKDTree(interfaces.centre).query(interfaces.centre[which] @ MIRROR)
        mapped = mirror[interfaces.pair[which]]
        target = interfaces.pair[found]
        same = (mapped == target).all(axis=1)
        swapped = (mapped[:, ::-1] == target).all(axis=1)
        good = (distance <= self.tol) & (same | swapped) & (
            (self.side[which] < 0) | (found == which))
        if not good.all():
            k = which[np.flatnonzero(~good)[0]]
            self._fail(f"interface {k} (blocks {tuple(interfaces.pair[k])}) has none")
        image[which], sign[which] = found, np.where(same, 1.0, -1.0)
        return image, sign

    def _routing(self, model: Model, turn, block_side) -> tuple:
        """The whole's blocks receiving each side of every kept interface ((K_h, 2) int),
        the rotation or reflection applied on the way ((K_h, 2, 3, 3), the half's frame)
        and the sides sent across ((K_h, 2) bool): a side the whole routes onto a block on
        the other side of the plane goes to that block's mirror image, reflected."""
        block = (self.interfaces.pair if model.side_block is None
                 else model.side_block)[self.kept]
        rotation = np.broadcast_to(np.eye(3), block.shape + (3, 3))
        if model.side_rotation is not None:
            rotation = turn.T @ model.side_rotation[self.kept] @ turn
        # where each side acts: a cut block receives a side routed onto its other half
        # (a course of one brick across the web, closed by its cyclic images) there
        acting = np.einsum("ksij,kj->ksi", rotation, self.interfaces.centre[self.kept])
        across = (block_side[block] < 0) | (block_side[block] == 0) & (
            acting[..., 1] < -self.tol)
        image = self.mirror[block]
        if (image[across] < 0).any() or across.all(axis=1).any():
            self._fail("a side of a kept interface acts on the other side of the plane "
                       "without a mirror image there")
        rotation = np.where(across[..., None, None], MIRROR @ rotation, rotation)
        return np.where(across, image, block), rotation, across

    def _partners(self, in_plane) -> tuple:
        """Per whole vertex, the kept vertex (the whole's index, -1 for none) whose force
        adds to its own in the whole, and the (3, 3) map of that force into its frame.

        A vertex in the plane of an interface the plane cuts is its own partner, its
        force's mirror image added (``s M``). A kept interface with a side sent across
        acts on the same block as its mirror image's other side (itself, for a joint in
        the plane): the whole force is the sum of the two, the partner's mapped by
        ``(s_r' / s_d) Q_d^T Q_r'`` (``s`` -1 for side 0, +1 for side 1; ``Q_d`` this
        one's direct side's rotation, ``Q_r'`` the partner's side sent across)."""
        itf = self.interfaces
        vertex = itf.vertex_interface
        partner = np.full(len(vertex), -1)
        force = np.zeros((len(vertex), 3, 3))
        cut = in_plane & ~self.across[vertex].any(axis=1)
        partner[cut] = np.flatnonzero(cut)
        force[cut] = self.sign[vertex[cut], None, None] * MIRROR
        sent = self.vertex_kept & self.across[vertex].any(axis=1)
        if not sent.any():
            return partner, force
        which = np.flatnonzero(sent)
        row = np.cumsum(self.kept) - 1  # the kept interfaces' rows of the routing
        k = row[vertex[which]]
        r = self.across[vertex[which]].argmax(axis=1)
        d = 1 - r
        there = np.full(itf.vertices.shape, np.inf)
        there[which] = np.einsum("vij,vj->vi", self.rotation[k, r], itf.vertices[which])
        here = np.einsum("vij,vj->vi", self.rotation[k, d], itf.vertices[which])
        # the partner interface's side sent across acts where this one's direct side
        # does: the same points (their mean), on the same block
        joint = np.unique(vertex[which])
        mean = [np.stack([np.bincount(vertex[which], values[:, i],
                                      minlength=len(itf))[joint] for i in range(3)],
                         axis=1) / np.bincount(vertex[which])[joint, None]
                for values in (there[which], here)]
        distance, found = cKDTree(mean[0]).query(mean[1])
        mate = np.full(len(itf), -1)
        mate[joint] = joint[found]
        on_block = self.block[row[mate[joint]], self.across[mate[joint]].argmax(axis=1)]
        if (distance > self.tol).any() or (
                on_block != self.block[row[joint], 1 - self.across[joint].argmax(axis=1)]
        ).any():
            self._fail("a joint sent across the plane meets no mirror image")
        partner[which] = self._nearest(mate[vertex[which]], here, there)
        p = partner[which]
        sign = np.where(self.across[vertex[p], 1], 1.0, -1.0) / np.where(d == 1, 1.0, -1.0)
        force[which] = sign[:, None, None] * (self.rotation[k, d].transpose(0, 2, 1)
                                             @ self.rotation[row[vertex[p]], 1 - d])
        return partner, force

    def kept_pairs(self) -> np.ndarray:
        """The whole's blocks joined by a kept interface."""
        return np.unique(self.interfaces.pair[self.kept])

    def half_interfaces(self, index) -> Interfaces:
        """The kept interfaces with their kept vertices, blocks renumbered by ``index``
        ((B_w,) int); area and centre stay the whole interface's (a half is solved,
        never exported)."""
        itf, kept = self.interfaces, self.kept
        counts = np.bincount(itf.vertex_interface[self.vertex_kept],
                             minlength=len(itf))[kept]
        return Interfaces(pair=index[itf.pair[kept]], kind=itf.kind[kept],
                          vertices=itf.vertices[self.vertex_kept],
                          offsets=np.concatenate([[0], np.cumsum(counts)]),
                          area=itf.area[kept], centre=itf.centre[kept],
                          normal=itf.normal[kept], t1=itf.t1[kept], t2=itf.t2[kept])

    def whole_map(self) -> tuple:
        """:class:`Half`'s ``vertex_source`` and ``friction_map``: every whole vertex's
        kept vertex (a vertex on the other side: its mirror image's, mirrored) and
        partner."""
        itf = self.interfaces
        vertex = itf.vertex_interface
        source = np.arange(len(vertex))
        force = np.broadcast_to(np.eye(3), (len(vertex), 3, 3)).copy()
        away = np.flatnonzero(~self.vertex_kept)
        source[away] = self._nearest(self.image[vertex[away]],
                                     itf.vertices[away] @ MIRROR, itf.vertices)
        force[away] = self.sign[vertex[away], None, None] * MIRROR
        if (self.partner[source[away]] >= 0).any():
            self._fail("a vertex off the plane is the mirror image of one in it")
        sources = np.stack([source, self.partner], axis=1)
        forces = np.stack([force, self.partner_force], axis=1)
        frame = np.stack([itf.t1, itf.t2], axis=2)              # (K, 3, 2)
        there = vertex[np.maximum(sources, 0)]
        normal = np.einsum("vsij,vsj->vsi", forces, itf.normal[there])
        miss = np.linalg.norm(normal - itf.normal[vertex][:, None], axis=2)
        if (miss[sources >= 0] > MIRROR_NORMAL_MISS).any():
            self._fail("an interface does not face as its mirror image does")
        friction = frame[vertex][:, None].transpose(0, 1, 3, 2) @ forces @ frame[there]
        return np.where(sources >= 0, self.half_index[np.maximum(sources, 0)], -1), friction

    def _nearest(self, target, points, positions) -> np.ndarray:
        """Per point of ``points`` ((n, 3)), the vertex of interface ``target`` ((n,) int)
        at ``positions`` ((IV, 3), of every vertex) that lies there (whole index)."""
        itf = self.interfaces
        count = itf.vertex_count
        slot = itf.offsets[target][:, None] + np.arange(int(count.max()))
        valid = np.arange(slot.shape[1]) < count[target][:, None]
        slot = np.where(valid, slot, itf.offsets[target][:, None])
        gap = np.linalg.norm(positions[slot] - points[:, None], axis=2)
        gap[~valid] = np.inf
        best = gap.argmin(axis=1)
        if (gap[np.arange(len(points)), best] > self.tol).any():
            self._fail("an interface vertex has no mirror image")
        return slot[np.arange(len(points)), best]


def _half_blocks(blocks: Blocks, side, joined, tol) -> tuple:
    """The half's blocks: those on the kept side, the halves of those in the plane, and
    the others ``joined`` ((n,) int) by a kept interface, as supports. Returns
    ``(blocks, index, cut)``: the half's :class:`Blocks`, the half's index of every whole
    block ((B_w,) int, -1 for none) and the cut ones ((B_w,) bool)."""
    count = blocks.n_blocks
    wanted = (side >= 0) | np.isin(np.arange(count), joined)
    cut = side == 0
    plain = blocks.subset(wanted & ~cut)
    plain = dataclasses.replace(plain, block_is_support=plain.block_is_support
                                | (side[wanted & ~cut] < 0))
    index = np.full(count, -1)
    index[wanted & ~cut] = np.arange(plain.n_blocks)
    which = np.flatnonzero(cut)
    if len(which) == 0:
        return plain, index, cut
    points = [_half_points(blocks, j, tol) for j in which]
    halves = blocks_from_hulls(
        points, [hull_faces(p, ConvexHull(p), tol) for p in points],
        blocks.block_class[which], list(blocks.block_name[which]),
        block_course=blocks.block_course[which],
        block_is_support=blocks.block_is_support[which], block_web=blocks.block_web[which])
    index[which] = plain.n_blocks + np.arange(len(which))
    return concatenate([plain, halves]), index, cut


def _half_points(blocks: Blocks, block: int, tol) -> np.ndarray:
    """(n, 3): the vertices of ``block`` on the kept side or in the plane (y >= -tol,
    put in it within ``tol``) and its edges' crossings with the plane."""
    start, stop = blocks.vertex_offsets[block], blocks.vertex_offsets[block + 1]
    vertices = blocks.vertices[start:stop]
    faces = np.flatnonzero(blocks.face_block == block)
    loops = [blocks.face_vertices[blocks.face_offsets[f]:blocks.face_offsets[f + 1]] - start
             for f in faces]
    a = np.concatenate(loops)
    b = np.concatenate([np.roll(loop, -1) for loop in loops])
    y = vertices[:, 1]
    crossing = (y[a] > tol) & (y[b] < -tol)  # each edge once, from the kept side
    a, b = a[crossing], b[crossing]
    along = (y[a] / (y[a] - y[b]))[:, None]
    points = np.concatenate([vertices[y >= -tol],
                             vertices[a] + along * (vertices[b] - vertices[a])])
    points[np.abs(points[:, 1]) <= tol, 1] = 0.0
    return points
