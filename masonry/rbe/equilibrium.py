"""Rigid block equilibrium (RBE) matrices, without a solver (docs/model.md 6.1 to 6.3, thesis 3.3).

This module only assembles; :mod:`masonry.rbe.solve` calls a solver. Keeping the two apart
makes the matrices testable on their own (the peers compas_cra keep ``cra_helper.py``
apart from ``rbe_pyomo.py`` for the same reason).

Glossary (thesis 3.3 symbol -> name here)
-----------------------------------------
- ``f`` (eq. 3.18, 3.23), the stacked nodal forces ``(f_n-, f_n+, f_t1, f_t2)`` of every
  interface vertex -> ``x``, with per-vertex columns ``(c, t, f1, f2)``; see
  :class:`VariableLayout`.
- ``A_eq`` (eq. 3.14-3.17), force and moment coefficients -> ``A_eq``, 6 rows per free
  block: force x, y, z, then moment x, y, z about the block's centroid.
- ``f_ext`` / ``f_weight`` (eq. 3.14, 3.20), external loads -> ``f_ext``: self weight only.
  The thesis's hoop term (eq. 3.19-3.20) is not reproduced (docs/model.md 6.4); the cyclic and
  rigid boundary modes route interface forces instead (``side_block``, ``side_rotation``).
- ``A_fr`` (eq. 3.24-3.26), the thesis's friction pyramid -> the friction model
  :class:`~masonry.friction.FrictionCone` (``cone``): Coulomb's isotropic cone by
  default; a polyhedral model's faces as rows ``A_fr['net']`` (friction-net) and
  ``A_fr['plus']`` (friction+), ``A_fr x <= 0``, for the solvers that take rows.
- ``alpha`` (eq. 3.25), static friction coefficient -> ``mu``.
- ``H`` (eq. 3.27), diagonal penalty -> ``h`` (its diagonal): 1 for tension, 1e-3 for
  compression and friction. The solver minimises with ``h_solver``, ``h`` times 1e3.
- ``I_lb`` (eq. 3.27), lower bounds -> ``lower``: 0 for c and t, -inf for f1, f2.

Sign convention: at a vertex of interface ``k`` with frame ``(t1, t2, n)``, the force on
the *other* block ``pair[k, 1]`` is ``F = (c - t) n + f1 t1 + f2 t2`` and the main block
``pair[k, 0]`` receives ``-F``; ``n`` points from the main block into the other, so
compression ``c`` pushes the two apart (docs/model.md 6.1).

Scaling (docs/model.md 6.2)
---------------------------
The matrices are stored scaled, and all scaling lives in :class:`EquilibriumSystem`:
variables are in units of a reference weight ``W_ref`` (newtons) and moment rows are
divided by a reference length ``L_ref`` (metres), so every coefficient and right-hand
side is of order one whatever the brick size or ``unit``, and the objective's diagonal
is multiplied by 1e3 (:attr:`EquilibriumSystem.h_solver`). Row scaling, a uniform
variable scaling and a positive factor on the objective change neither the feasible set
nor the minimiser of ``1/2 x^T H x``; use :meth:`EquilibriumSystem.to_newtons` to report
results.
"""

import dataclasses
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from masonry.contact import ContactLaw, as_strength, same_strength, tributary_area
from masonry.friction import FrictionCone
from masonry.tolerances import COEFFICIENT_NOISE, G

TENSION_WEIGHT = 1.0
"""Diagonal of ``H`` for tension (thesis eq. 3.27)."""

OTHER_WEIGHT = 1e-3
"""Diagonal of ``H`` for compression and friction (thesis eq. 3.27)."""

FRICTION_METHODS = ("net", "plus")
"""``net``: friction-net, the friction within the model's cone at ``c - t`` (thesis eq.
3.26: no tension carried at a point that stands); ``plus``: friction+, within it at ``c``
(thesis eq. 3.25: tension allowed and measured)."""


@dataclass(frozen=True, eq=False)
class VariableLayout:
    """Where each interface vertex's unknowns sit in the variable vector ``x``.

    Vertex ``i`` (a row of ``Interfaces.vertices``) owns the 4 consecutive columns
    ``4 i + (0, 1, 2, 3)`` = ``(c, t, f1, f2)``: compression, tension and the friction
    components along ``t1`` and ``t2`` (thesis eq. 3.23). Defined once and used by the
    assembly, the solver wrapper and the results.

    Parameters
    ----------
    offsets : (K + 1,) int
        ``Interfaces.offsets``: interface ``k`` owns vertices ``offsets[k]:offsets[k+1]``.
    """

    offsets: np.ndarray

    COMPONENTS: ClassVar[tuple] = ("c", "t", "f1", "f2")
    WIDTH: ClassVar[int] = 4

    @classmethod
    def from_interfaces(cls, interfaces) -> "VariableLayout":
        """The layout of ``interfaces`` (:class:`masonry.interfaces.Interfaces`)."""
        return cls(np.asarray(interfaces.offsets, dtype=np.int64))

    @property
    def n_interfaces(self) -> int:
        """``K``, the number of interfaces."""
        return len(self.offsets) - 1

    @property
    def n_vertices(self) -> int:
        """``IV``, the number of interface vertices (all interfaces)."""
        return int(self.offsets[-1])

    @property
    def n_columns(self) -> int:
        """``n = 4 IV``, the length of ``x``."""
        return self.WIDTH * self.n_vertices

    @cached_property
    def vertex_interface(self) -> np.ndarray:
        """(IV,) int: interface of every vertex."""
        return np.repeat(np.arange(self.n_interfaces), np.diff(self.offsets))

    def columns(self, component: str) -> np.ndarray:
        """(IV,) int: the column of ``component`` (``'c' | 't' | 'f1' | 'f2'``) per vertex."""
        return self.WIDTH * np.arange(self.n_vertices) + self.COMPONENTS.index(component)

    def vertex_columns(self, vertex: int) -> slice:
        """Columns ``(c, t, f1, f2)`` of vertex ``vertex`` (int), as a slice of ``x``."""
        return slice(self.WIDTH * vertex, self.WIDTH * (vertex + 1))

    def component(self, x, component: str) -> np.ndarray:
        """(IV,) view of one component of ``x`` ((n_columns,) float)."""
        return np.asarray(x).reshape(-1, self.WIDTH)[:, self.COMPONENTS.index(component)]

    def interface_sum(self, values) -> np.ndarray:
        """(K,) float: per-interface sums of per-vertex ``values`` ((IV,) float)."""
        return np.bincount(self.vertex_interface, weights=values,
                           minlength=self.n_interfaces)


@dataclass(frozen=True, eq=False)
class EquilibriumSystem:
    """The scaled RBE constraint matrices of one scene (thesis eq. 3.14-3.27).

    With ``x_s = x / weight_ref`` (``x`` in newtons, layout :class:`VariableLayout`)::

        A_eq x_s + f_ext = 0          (6 rows per free block)
        (c, f1, f2) of every vertex in ``cone`` at mu (c - t) or mu c
        x_s >= lower

    Parameters
    ----------
    layout : VariableLayout
    free_block : (F,) int
        The blocks with equilibrium rows (non-supports), in order; block ``free_block[r]``
        owns rows ``6 r : 6 r + 6``.
    f_ext : (6 F,) float, dimensionless
        Self weight in the same units (moment rows are zero: the weight acts at the
        centroid).
    lower : (n,) float
        0 for c and t, ``-inf`` for f1 and f2.
    h : (n,) float
        Diagonal of ``H``: 1 for t, 1e-3 for c, f1, f2 (over a vertex's share,
        :func:`assemble`).
    mu : float
        Friction coefficient.
    block_weight : (B,) float, newtons
        ``density * g * volume`` of every block (supports included, for reference).
    weight_ref : float, newtons
        Mean weight of the free blocks.
    length_ref : float, metres
        Mean cube root of the free blocks' volumes.
    side_row : (K, 2) int
        The free-block index (``A_eq`` rows ``6 r : 6 r + 6``) that receives each side of
        every interface, -1 for a support.
    vertex_coefficients : (IV, 2, 6, 4) float
        ``A_eq`` by vertex: the six rows a vertex's ``(c, t, f1, f2)`` give the block of
        each side (zero for a support side). ``A_eq`` is their sum, so Newton matrices
        ``A_eq D A_eq^T`` with block-diagonal ``D`` can be formed interface by interface
        (:mod:`masonry.rbe.solvers.newton`) instead of by sparse products.
    density : float, kg/m^3

    Attributes
    ----------
    A_eq : (6 F, n) scipy.sparse.csr_array, dimensionless
        Force rows in units of ``weight_ref``, moment rows (about each block's centroid)
        in units of ``weight_ref * length_ref``; built from ``vertex_coefficients`` on
        first use (the Newton method and :meth:`times_A_eq` do without it).
    A_fr : dict str -> (K IV, n) scipy.sparse.csr_array
        A polyhedral ``cone``'s faces as rows for ``'net'`` and ``'plus'`` (thesis eq.
        3.26, 3.25), at ``mu``; rows ``K i .. K i + K - 1`` are vertex ``i``'s.
    cone : masonry.friction.FrictionCone
        The friction model (default Coulomb's cone).
    row_kept : (6 F,) bool or None
        False on the rows no force enters (:func:`assemble`'s ``dropped_rows``): zero in
        ``A_eq`` and ``f_ext``, and a live load is zeroed there too
        (:meth:`masonry.rbe.collapse.CollapseLP.scaled`); None: every row is kept.
    vertex_area : (IV,) float or None, m^2
        Every vertex's tributary area (:func:`masonry.contact.tributary_area`).
    cohesion, tensile : float or (IV,) float, Pa
        The mortar's cohesion and tensile strength (:class:`masonry.contact.ContactLaw`,
        :attr:`law`), at every vertex or per vertex; 0: dry joints.
    f_weight : (6 F,) float or None
        The self weight before the cohesion shift when there is one: ``f_ext`` is then
        ``f_weight - A_eq[:, c] s`` (:attr:`compression_shift`); None: ``f_ext`` is the
        self weight.
    """

    layout: VariableLayout
    free_block: np.ndarray
    f_ext: np.ndarray
    lower: np.ndarray
    h: np.ndarray
    mu: float
    block_weight: np.ndarray
    weight_ref: float
    length_ref: float
    side_row: np.ndarray
    vertex_coefficients: np.ndarray

    density: float = 1.0
    cone: FrictionCone = FrictionCone("circle")
    row_kept: np.ndarray | None = None
    vertex_area: np.ndarray | None = None
    cohesion: float | np.ndarray = 0.0
    tensile: float | np.ndarray = 0.0
    f_weight: np.ndarray | None = None

    def with_material(self, mu=None, density=None, cone=None, cohesion=None,
                      tensile=None) -> "EquilibriumSystem":
        """The same scene with another friction coefficient, density, friction model or
        mortar, without assembling again: ``mu`` and ``cone`` change only the friction
        constraints, and ``density`` only the newtons per solver unit (the scaled ``A_eq``
        and the self weight depend on none of them, since the reference weight grows with
        the density); a cohesion shifts ``f_ext`` and bounds the compressions
        (:meth:`_with_mortar`).

        Parameters
        ----------
        mu : float, optional
            Friction coefficient; default unchanged.
        density : float, kg/m^3, optional
            Default unchanged.
        cone : FrictionCone or str, optional
            Friction model; default unchanged.
        cohesion, tensile : float or (IV,) float, Pa, optional
            The mortar's strengths, at every vertex or per vertex; default unchanged.

        Returns
        -------
        EquilibriumSystem
            ``self`` when nothing changes.
        """
        out = self
        if cone is not None and FrictionCone.parse(cone) != self.cone:
            out = dataclasses.replace(out, cone=FrictionCone.parse(cone))
        if mu is not None and float(mu) != self.mu:
            out = dataclasses.replace(out, mu=float(mu))
        if density is not None and float(density) != self.density:
            ratio = float(density) / self.density
            out = dataclasses.replace(out, block_weight=self.block_weight * ratio,
                                      weight_ref=self.weight_ref * ratio,
                                      density=float(density))
        for name, value in (("cohesion", cohesion), ("tensile", tensile)):
            if value is not None and not same_strength(value, getattr(self, name)):
                out = dataclasses.replace(out, **{name: as_strength(value)})
        if out is not self and (np.any(out.cohesion) or np.any(self.cohesion)):
            out = out._with_mortar()
        if out is not self and "A_eq" in self.__dict__:  # the matrix depends on neither
            out.__dict__["A_eq"] = self.A_eq
        return out

    @property
    def law(self) -> ContactLaw:
        """The contact law the constraints state (:class:`~masonry.contact.ContactLaw`)."""
        return ContactLaw(self.cone, self.mu, self.cohesion, self.tensile)

    @property
    def compression_shift(self) -> np.ndarray | None:
        """(IV,) float, solver units: ``s_i = c A_i / mu``, the solver's compression
        ``c~ = n + s`` (module docstring of :mod:`masonry.contact`); None for dry joints,
        whose arithmetic takes no shift at all."""
        law = self.law
        return None if law.is_dry else law.shift(self.vertex_area) / self.weight_ref

    @property
    def compression_floor(self) -> np.ndarray | None:
        """(IV,) float, solver units: the lower bound ``c~_i >= l_i`` of a tension
        cut-off before the cone's apex (``t_c < c / mu``); None where the cone's own
        ``c~ >= 0`` is the bound."""
        law = self.law
        return law.floor(self.vertex_area) / self.weight_ref if law.is_truncated else None

    def _with_mortar(self) -> "EquilibriumSystem":
        """``f_ext`` and ``lower`` for the current law from the self weight: ``f_ext =
        f_weight - A_eq[:, c] s`` (so ``A_eq x~ + f_ext = A_eq x + f_weight`` with ``x~``
        the shifted forces) and ``c~ >= l`` where the cut-off truncates the cone."""
        weight = self.f_ext if self.f_weight is None else self.f_weight
        lower = np.tile([0.0, 0.0, -np.inf, -np.inf], self.layout.n_vertices)
        shift = self.compression_shift
        if shift is None:
            return dataclasses.replace(self, f_ext=weight, f_weight=None, lower=lower)
        floor = self.compression_floor
        if floor is not None:
            lower[self.layout.columns("c")] = floor
        return dataclasses.replace(self, f_ext=weight - self.times_A_eq(self.shifted(0.0)),
                                   f_weight=weight, lower=lower)

    def shifted(self, x, sign=1.0) -> np.ndarray:
        """(n,) float: ``x`` (solver units) with ``sign`` times the compression shift
        added to its ``c`` columns (``x`` itself for dry joints); ``sign = -1`` turns a
        solver's point into physical forces, whose ``c`` is the normal force (negative
        where the mortar holds in tension)."""
        shift = self.compression_shift
        if shift is None:
            return np.asarray(x, dtype=float)
        out = np.array(np.broadcast_to(np.asarray(x, dtype=float), (self.layout.n_columns,)))
        out[self.layout.columns("c")] += sign * shift
        return out

    @cached_property
    def A_eq(self) -> sp.csr_array:
        """The equilibrium matrix, built on first use (see the class's attributes)."""
        coefficients = self.vertex_coefficients.reshape(self.layout.n_vertices, 12, -1)
        return equilibrium_columns(coefficients, self.vertex_side_row,
                                   6 * len(self.free_block)).tocsr()

    @property
    def vertex_side_row(self) -> np.ndarray:
        """(IV, 2) int: the free-block index of each side of every vertex's interface,
        0 for a support (whose coefficients are zero)."""
        return np.maximum(self.side_row[self.layout.vertex_interface], 0)

    def times_A_eq(self, x) -> np.ndarray:
        """(6 F,) float: ``A_eq x`` for ``x`` ((n,) float), summed vertex by vertex from
        ``vertex_coefficients``, without the matrix."""
        per_side = np.einsum("vsrc,vc->vsr", self.vertex_coefficients,
                             np.asarray(x, dtype=float).reshape(-1, self.layout.WIDTH))
        rows = 6 * self.vertex_side_row[:, :, None] + np.arange(6)
        return np.bincount(rows.ravel(), weights=per_side.ravel(),
                           minlength=6 * len(self.free_block))

    @cached_property
    def A_fr(self) -> dict:
        """A polyhedral model's faces as rows (see :func:`friction_rows`), built on first
        use: only the solvers that take rows need them."""
        return friction_rows(self.layout.n_vertices, self.cone, self.mu)

    @property
    def total_weight(self) -> float:
        """Weight of the free blocks, newtons (the denominator of the MoI factor)."""
        return float(self.block_weight[self.free_block].sum())

    @property
    def row_scale(self) -> np.ndarray:
        """(6 F,) float: newtons (force rows) or newton-metres (moment rows) per unit row."""
        per_block = np.array([1.0, 1.0, 1.0] + [self.length_ref] * 3) * self.weight_ref
        return np.tile(per_block, len(self.free_block))

    @property
    def h_solver(self) -> np.ndarray:
        """(n,) float: the diagonal of ``H`` the solver sees, ``h / 1e-3`` (1 for c, f1,
        f2 and 1e3 for t). Same minimiser; but with ``h`` itself the objective of a small
        scene is about 1e-4 in solver units, below the absolute gap tolerance of interior
        point solvers (Clarabel left 2e-5 of the weight as spurious tension), and OSQP
        needed more iterations."""
        return self.h / OTHER_WEIGHT

    def to_scaled(self, x) -> np.ndarray:
        """(n,) float: variables ``x`` in newtons ((n,) float) -> solver units."""
        return np.asarray(x, dtype=float) / self.weight_ref

    def to_newtons(self, x_scaled) -> np.ndarray:
        """(n,) float: variables in solver units ((n,) float) -> newtons."""
        return np.asarray(x_scaled, dtype=float) * self.weight_ref

    def contact_wrench(self, x) -> np.ndarray:
        """(F, 6) float: net contact force (N) and moment about the centroid (N m) on
        every free block, for ``x`` in newtons. This is ``A_eq x`` in physical units."""
        return (self.row_scale * (self.A_eq @ self.to_scaled(x))).reshape(-1, 6)

    def external_wrench(self) -> np.ndarray:
        """(F, 6) float: ``f_ext`` in newtons and newton-metres."""
        return (self.row_scale * self.f_ext).reshape(-1, 6)


def assemble(blocks, interfaces, mu=0.7, density=2000.0, side_block=None,
             side_rotation=None, cone="circle", dropped_rows=None,
             vertex_share=None, cohesion=0.0, tensile=0.0) -> EquilibriumSystem:
    """Assemble the scaled RBE matrices: the per-vertex coefficients of ``A_eq``
    (vectorized); the sparse ``A_eq`` is built from them when a solver asks for it.

    Parameters
    ----------
    blocks : masonry.blocks.Blocks
        ``B`` blocks, metres; supports (``block_is_support``) get no equilibrium rows.
    interfaces : masonry.interfaces.Interfaces
        ``K`` interfaces with ``IV`` vertices in all, metres.
    mu : float
        Friction coefficient (thesis ``alpha``).
    density : float, kg/m^3
    side_block : (K, 2) int, optional
        The block that receives the force of each interface side: side 0 receives
        ``-F``, side 1 receives ``+F``. Default ``interfaces.pair``. A side routed to a
        support block contributes no row (the support absorbs it).
    side_rotation : (K, 2, 3, 3) float, optional
        Rotation ``Q`` (about the origin) applied to each side before its force reaches
        ``side_block``: that side's force ``Q (+-F)`` acts at the point ``Q v``. Default
        identity. Cyclic symmetry (docs/model.md 6.4) routes a rotated copy's side back
        with the inverse rotation, mirror symmetry (6.11) a mirror image's with the
        reflection (``det Q = -1``).
    cone : FrictionCone or str
        The friction model (:mod:`masonry.friction`).
    dropped_rows : (B, 6) bool, optional
        Rows of a block that no force enters: its coefficients and its weight are zero
        there, so the rows hold whatever the forces (unconstrained reactions; a half
        model's blocks cut by its mirror plane, docs/model.md 6.11).
    vertex_share : (IV,) float, optional
        The share of a force of the whole structure that a vertex's variables carry
        (a half model's vertices in its mirror plane carry half, docs/model.md 6.11);
        the objective weighs them by ``h / share``. Default 1.
    cohesion, tensile : float, Pa
        The mortar (:mod:`masonry.contact`); default dry joints.

    Returns
    -------
    EquilibriumSystem
        ``A_eq`` (6 F, 4 IV) and ``f_ext`` (6 F,) scaled, for the ``F`` free blocks;
        ValueError when every block is a support.
    """
    layout = VariableLayout.from_interfaces(interfaces)
    n_vertices = layout.n_vertices
    is_support = np.asarray(blocks.block_is_support, dtype=bool)
    free_block = np.flatnonzero(~is_support)
    if len(free_block) == 0:
        raise ValueError("no free block: every block is a support")

    volume = blocks.block_volume
    block_weight = density * G * volume
    weight_ref = float(block_weight[free_block].mean())
    length_ref = float(np.cbrt(volume[free_block]).mean())

    block_row = np.full(blocks.n_blocks, -1)
    block_row[free_block] = np.arange(len(free_block))
    side_block = (np.asarray(interfaces.pair, dtype=np.int64) if side_block is None
                  else np.asarray(side_block, dtype=np.int64))
    kept = (np.ones((blocks.n_blocks, 6), bool) if dropped_rows is None
            else ~np.asarray(dropped_rows, dtype=bool))
    coefficients = _vertex_coefficients(blocks, interfaces, layout, side_block[
        layout.vertex_interface], side_rotation, block_row, length_ref, kept)

    f_ext = np.zeros((len(free_block), 6))
    f_ext[:, 2] = -block_weight[free_block] / weight_ref
    f_ext *= kept[free_block]
    lower = np.tile([0.0, 0.0, -np.inf, -np.inf], n_vertices)
    h = np.tile([OTHER_WEIGHT, TENSION_WEIGHT, OTHER_WEIGHT, OTHER_WEIGHT], (n_vertices, 1))
    if vertex_share is not None:
        h /= np.asarray(vertex_share, dtype=float)[:, None]
    system = EquilibriumSystem(layout=layout, free_block=free_block, f_ext=f_ext.ravel(),
                               lower=lower, h=h.ravel(), mu=float(mu),
                               block_weight=block_weight, weight_ref=weight_ref,
                               length_ref=length_ref, side_row=block_row[side_block],
                               vertex_coefficients=coefficients, density=float(density),
                               cone=FrictionCone.parse(cone),
                               row_kept=None if dropped_rows is None
                               else kept[free_block].ravel(),
                               vertex_area=tributary_area(interfaces))
    return system.with_material(cohesion=cohesion, tensile=tensile)


def _vertex_coefficients(blocks, interfaces, layout: VariableLayout, vertex_side_block,
                         side_rotation, block_row, length_ref: float, kept) -> np.ndarray:
    """(IV, 2, 6, 4) float: the scaled ``A_eq`` rows (force, moment per ``length_ref``)
    that every vertex's ``(c, t, f1, f2)`` give the block of each side,
    ``vertex_side_block`` ((IV, 2) int); zero for a support side (``block_row`` -1), in
    the rows a block drops (``kept`` (B, 6) False) and for coefficients at or below
    :data:`~masonry.tolerances.COEFFICIENT_NOISE`."""
    vertex_interface = layout.vertex_interface
    point = np.asarray(interfaces.vertices, dtype=float)
    # direction of each variable's unit force on the other block: c -> n, t -> -n,
    # f1 -> t1, f2 -> t2; (IV, 4, 3)
    normal = interfaces.normal[vertex_interface]
    direction = np.stack([normal, -normal, interfaces.t1[vertex_interface],
                          interfaces.t2[vertex_interface]], axis=1)
    out = []
    for side, sign in ((0, -1.0), (1, 1.0)):
        block = vertex_side_block[:, side]
        side_direction, side_point = sign * direction, point
        if side_rotation is not None:
            rotation = np.asarray(side_rotation, dtype=float)[vertex_interface, side]
            side_direction = np.einsum("vij,vqj->vqi", rotation, side_direction)
            side_point = np.einsum("vij,vj->vi", rotation, point)
        arm = (side_point - blocks.block_centroid[block]) / length_ref
        moment = np.cross(arm[:, None, :], side_direction)
        coeff = np.concatenate([side_direction, moment], axis=2)  # (IV, 4, 6)
        # drop rows of supports, and the zeros and rounding noise of axis-aligned frames
        # (about 40% of the triplets of a wall; HiGHS warns about them and every solver
        # would carry them)
        keep = ((block_row[block] >= 0)[:, None, None] & kept[block][:, None, :]
                & (np.abs(coeff) > COEFFICIENT_NOISE))
        out.append(np.where(keep, coeff, 0.0).transpose(0, 2, 1))
    return np.stack(out, axis=1)


def equilibrium_columns(coefficients, side_rows, n_rows: int) -> sp.csc_array:
    """Columns of ``A_eq`` ((n_rows, IV width) csc) from per-vertex ``coefficients``
    ((IV, 12, width): side 0's six rows, then side 1's, in the columns wanted) and the
    free-block row of each side ``side_rows`` ((IV, 2) int): all of ``A_eq`` with the four
    columns of :class:`VariableLayout`, the Newton method's subset with its own.

    Every column (a vertex's c, t, f1 or f2) has six rows on each side's block, so the
    matrix is built column by column in CSC form, with no triplet sort; its rows are in
    increasing order (the side on the lower block first) and it stores no zeros.
    """
    n_vertices, _, width = coefficients.shape
    rows = 6 * np.sort(side_rows, axis=1)[:, :, None] + np.arange(6)      # (IV, 2, 6)
    # (IV, width, 12) in place, the side on the lower block first: every vertex as it
    # comes, then the swapped ones again with their sides exchanged
    data = np.empty((n_vertices, width, 12))
    data[:] = coefficients.transpose(0, 2, 1)
    swap = np.flatnonzero(side_rows[:, 0] > side_rows[:, 1])
    data[swap] = np.roll(coefficients[swap], 6, axis=1).transpose(0, 2, 1)
    indices = np.empty(data.shape, dtype=np.int64)
    indices[:] = rows.reshape(n_vertices, 1, 12)
    matrix = sp.csc_array((data.reshape(-1), indices.reshape(-1),
                           np.arange(0, data.size + 1, 12)),
                          shape=(n_rows, n_vertices * width))
    # both sides on one block (cyclic symmetry routes an image onto the brick it copies)
    # add up; then the dropped coefficients go
    matrix.sum_duplicates()
    matrix.eliminate_zeros()
    return matrix


def friction_rows(n_vertices: int, cone: FrictionCone, mu: float) -> dict:
    """A polyhedral model's faces as rows ``A_fr x <= 0`` over every vertex's ``(c, t,
    f1, f2)`` (thesis eq. 3.24-3.26 for the square).

    Parameters
    ----------
    n_vertices : int
        ``IV``, interface vertices.
    cone : FrictionCone
        A polyhedral model (``polygon:K`` or ``square``).
    mu : float
        Friction coefficient (thesis ``alpha``), dimensionless.

    Returns
    -------
    dict str -> (K IV, 4 IV) scipy.sparse.csr_array
        ``'net'``: ``f . normal_k <= apothem (c - t)``; ``'plus'``: ``f . normal_k <=
        apothem c``. Dimensionless, so valid for ``x`` in newtons or in solver units.

    Raises
    ------
    ValueError
        For the circle, which has no faces (its solvers take it as a second-order cone).
    """
    if not cone.is_polyhedral:
        raise ValueError("the circle has no faces: it is a second-order cone")
    faces = cone.faces(mu)                    # (K, 3) over (c, f1, f2)
    net = np.column_stack([faces[:, 0], -faces[:, 0], faces[:, 1], faces[:, 2]])
    plus = net.copy()
    plus[:, 1] = 0.0  # friction+: tension is decoupled (thesis eq. 3.25)
    eye = sp.identity(n_vertices, format="csr")
    return {"net": sp.csr_array(sp.kron(eye, net, format="csr")),
            "plus": sp.csr_array(sp.kron(eye, plus, format="csr"))}


def friction_edges(n_vertices: int, cone: FrictionCone, mu: float) -> sp.csr_array:
    """A polyhedral model with ``t = 0`` by its edge rays (docs/model.md 6.3, 6.8).

    A vertex force with no tension inside the model is a nonnegative combination of its
    ``K`` edge rays (:meth:`~masonry.friction.FrictionCone.rays`), so ``x = E g`` with
    ``g >= 0`` states it without inequality rows. Fixing ``t = 0`` loses nothing: a
    friction-net point with ``0 < t <= c`` stays one with ``(c - t, 0)``.

    Returns
    -------
    E : (4 IV, K IV) scipy.sparse.csr_array
        Column ``K i + k`` is ray ``k`` of vertex ``i`` in the :class:`VariableLayout`
        order.
    """
    rays = cone.rays(mu)                      # (3, K) over (c, f1, f2)
    edges = np.vstack([rays[0], np.zeros(rays.shape[1]), rays[1], rays[2]])
    return sp.csr_array(sp.kron(sp.identity(n_vertices), edges, format="csr"))
