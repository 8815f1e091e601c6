"""Rigid block equilibrium of a sequence of parts of one model (construction stages,
docs/stages.md), the work consecutive parts share kept between their solves.

Each part is the model restricted to the blocks present (:func:`masonry.rbe.boundary.restrict`),
and its result is the one :class:`~masonry.rbe.solve.RBEProblem` gives that part alone,
within the solver's accuracy (tests/test_stages.py). What :class:`StageSequence` keeps:

- **The matrices.** The whole model's equilibrium system is assembled once; a part's is
  its rows (the part's free blocks) and columns (the vertices of the interfaces whose two
  blocks are present), :func:`part_system`. The units stay the whole model's (its
  reference weight and length, docs/model.md 6.2): the feasible set and the
  minimiser do not depend on them, and dual points carry over from part to part.
- **The ordering.** One fill-reducing order of the whole model's block graph; a part's
  symbolic factorization takes it restricted to the part's blocks. Every fill path of a
  part's graph is one of the whole graph, so the part's factor has no more fill than the
  whole's restricted to it, and no part is ordered again. The symbolic factorization is
  made for a superset the next parts will not outgrow (``within``: the course being
  laid, complete) and serves each of them
  (:class:`~masonry.rbe.solvers.embedded.Embedded`).
- **The dual points.** The equilibrium multipliers of the last accepted point of each
  friction model, by block (a virtual displacement per block, in the whole model's
  units): the next part's Newton iterations start from them, friction+ included
  (:meth:`RBEProblem.of_system`); a block new to the part starts with the rigid motion of
  its neighbours.
- **A local infeasibility certificate.** Before friction-net, the blocks just laid
  (``local``: the course being laid) alone, every other present block held fixed: if no
  forces within friction carry them, the part cannot stand either (a Farkas certificate
  of that small problem, a virtual motion of the local blocks on which the weight does
  work and no contact resists, is one of the whole part with the other blocks at rest),
  and the part goes straight to friction+ for its measure of infeasibility. Where the
  small problem has a solution nothing follows, and the part is solved as usual.
- **A local centering force.** The centering force of a part that cannot stand
  (docs/model.md 6.10) is first sought on the same small problem: the least support
  force on the local blocks with every other block held fixed is at most the part's
  (the part's optimum, restricted to the local blocks, is a point of the small
  program). If the part then carries those support forces as loads, friction-net has
  a solution (Newton, from the last stage's start), that point with supports on the
  local blocks alone is one of the part's program with the same total: the least, so
  the part's centering force. Otherwise the whole part's program is solved.
- **The centering force** (docs/model.md 6.10) and **the least adhesion** (6.12) of a
  part: their programs on the part's rows and columns of the whole model's matrices
  (:meth:`StageSequence.centering`, :meth:`StageSequence.adhesion`), by the own
  interior point methods on the part's symbolic factorization (the one its RBE solve
  used).
- **Mortar.** A part's strengths (``cohesion``, ``tensile``: one number, or an array
  over the whole model's interface vertices, the joints' ages differing) are sliced
  with its columns and shift its own ``f_ext`` (:meth:`EquilibriumSystem.with_material`);
  the local certificate and the local centering force take the same slice, so both
  state the part's law. The dual points are starts only: a shifted ``f_ext`` changes the
  part's optimum, not what Newton accepts.
"""

import dataclasses
import logging
import time

import numpy as np

from masonry.rbe.adhesion import INTERIOR, TENSION_RATIO, AdhesionResult, solve_adhesion
from masonry.rbe.boundary import Model, kept_blocks
from masonry.rbe.centering import CenteringResult, solve_centering
from masonry.rbe.equilibrium import FRICTION_METHODS, EquilibriumSystem, VariableLayout, assemble
from masonry.rbe.result import RBEResult
from masonry.rbe.solve import ACCURACY, WARM_STALL, WARM_STEPS, RBEProblem, friction_model
from masonry.rbe.solvers import BACKENDS
from masonry.rbe.solvers.base import INFEASIBLE
from masonry.rbe.solvers.cholesky import BlockCholesky, block_graph, fill_reducing_order
from masonry.rbe.solvers.embedded import Embedded

log = logging.getLogger(__name__)

CHECK_TOL = 0.1
"""Newton's stop on the check of a local centering force, relative to the preset's
acceptance tolerance."""

CERTIFICATE = "local-certificate"
"""The local certificate's name in :attr:`RBEResult.attempts`."""


def vertex_slice(strength, whole: EquilibriumSystem, interfaces):
    """A strength (pascals: a number, or (IV,) over ``whole``'s vertices) for the
    vertices of ``interfaces`` ((K,) bool), in :func:`part_system`'s order."""
    if np.ndim(strength) == 0:
        return strength
    return np.asarray(strength)[np.asarray(interfaces, bool)[whole.layout.vertex_interface]]


def part_system(whole: EquilibriumSystem, rows, interfaces) -> EquilibriumSystem:
    """The equilibrium system of a part of ``whole``: its free blocks ``rows`` ((F,)
    bool over ``whole``'s free blocks) and its ``interfaces`` ((K,) bool). A side on a
    block that is not kept is held fixed (a support: no rows, zero coefficients).

    ``free_block`` and ``block_weight`` stay the whole model's (``free_block`` indexes
    the whole model's blocks), and so do the units. ``whole`` has dry joints (a mortar's
    shifted weight is not carried over)."""
    rows, interfaces = np.asarray(rows, bool), np.asarray(interfaces, bool)
    new_row = np.full(len(rows), -1)
    new_row[rows] = np.arange(int(rows.sum()))
    side_row = whole.side_row[interfaces]
    side_row = np.where(side_row >= 0, new_row[np.maximum(side_row, 0)], -1)
    vertices = interfaces[whole.layout.vertex_interface]
    counts = np.diff(whole.layout.offsets)[interfaces]
    layout = VariableLayout(np.concatenate([[0], np.cumsum(counts)]).astype(np.int64))
    coefficients = whole.vertex_coefficients[vertices]             # a copy
    coefficients[(side_row < 0)[layout.vertex_interface]] = 0.0    # supports: zero already
    columns = np.repeat(vertices, VariableLayout.WIDTH)
    f_ext = whole.f_ext.reshape(-1, 6)[rows].ravel()
    area = None if whole.vertex_area is None else whole.vertex_area[vertices]
    return dataclasses.replace(whole, layout=layout, free_block=whole.free_block[rows],
                               f_ext=f_ext, lower=whole.lower[columns], h=whole.h[columns],
                               side_row=side_row, vertex_coefficients=coefficients,
                               vertex_area=area)


class StageSequence:
    """Solve parts of ``model`` one after the other, each from where the last one ended
    (see the module's notes).

    Parameters
    ----------
    model : Model
        The whole structure's analysis model.
    """

    def __init__(self, model: Model):
        self.model = model
        self.whole = assemble(model.blocks, model.interfaces, side_block=model.side_block,
                              side_rotation=model.side_rotation)
        n_free = len(self.whole.free_block)
        rows = self.whole.side_row
        self._position = np.empty(n_free, dtype=np.int64)
        self._position[fill_reducing_order(block_graph(
            n_free, rows[(rows >= 0).all(axis=1)]))] = np.arange(n_free)
        self._duals = {method: np.zeros((n_free, 6)) for method in FRICTION_METHODS}
        self._known = {method: np.zeros(n_free, bool) for method in FRICTION_METHODS}
        # the pairs of free blocks in contact whose forces are not routed elsewhere, and
        # the blocks' centroids in reference lengths: a block new to a part starts with
        # the rigid motion of its neighbours
        routed = (model.side_block if model.side_block is not None
                  else model.interfaces.pair)
        direct = (rows >= 0).all(axis=1) & (routed == model.interfaces.pair).all(axis=1)
        self._pairs = np.unique(np.sort(rows[direct], axis=1), axis=0)
        self._pairs = self._pairs[self._pairs[:, 0] != self._pairs[:, 1]]
        self._centroid = (model.blocks.block_centroid[self.whole.free_block]
                          / self.whole.length_ref)
        self._within = None  # (free blocks, their symbolic factorization)
        self.certified = 0
        """Parts whose local certificate spared the friction-net solve."""

    def solve(self, is_present, local=None, within=None, *, mu=0.7, density=2000.0,
              friction="auto", solver=None, accuracy="balanced", cone=None, cohesion=0.0,
              tensile=0.0) -> RBEResult:
        """The RBE of the part of the model whose scene blocks ``is_present`` ((S,) bool,
        as :func:`~masonry.rbe.boundary.restrict` takes it).

        Parameters
        ----------
        local : (S,) bool, optional
            The scene blocks laid last (a subset of the present ones): with ``friction``
            ``'auto'``, the local certificate is tried on them first.
        within : (S,) bool, optional
            Scene blocks that the next parts will not outgrow (a superset of the present
            ones, e.g. the course being laid complete): the symbolic factorization is
            made once for them and serves every part within
            (:class:`~masonry.rbe.solvers.embedded.Embedded`). Default: the part's own.
        mu, density, friction, solver, accuracy, cone
            As :meth:`RBEProblem.solve`.
        cohesion, tensile : float or (IV,) float, Pa
            The mortar, at every joint or per vertex of the whole model's interfaces.

        Returns
        -------
        RBEResult
            As the part's own :class:`RBEProblem` gives it (in the whole model's units
            inside; ``x`` in newtons in the layout of the part's interfaces, in their
            order in the model). A certified part's ``attempts`` begin with
            :data:`CERTIFICATE`.
        """
        start = time.perf_counter()
        rows, interfaces = self._selection(is_present)
        cone = friction_model(accuracy, cone)
        material = {"mu": mu, "density": density, "cone": cone, "cohesion": cohesion,
                    "tensile": tensile}
        system = self._part(rows, interfaces, **material)
        certificate = None
        if local is not None and friction == "auto" and solver is None:
            local_rows, small = self._local_part(local, rows, interfaces, material)
            if small is not None:
                certificate = self._certificate(small, int(local_rows.sum()), accuracy)
        starts = {method: self._start(method, rows) for method in FRICTION_METHODS
                  if self._known[method][rows].any()}
        problem = RBEProblem.of_system(system, symbolic=self._symbolic(
            rows, rows if within is None else kept_blocks(self.model, within)[
                self.whole.free_block] | rows), starts=starts)
        result = problem.solve(mu=mu, density=density, accuracy=accuracy, cone=cone,
                               friction="plus" if certificate else friction, solver=solver,
                               cohesion=system.cohesion, tensile=system.tensile)
        for method, y in problem.duals.items():
            self._duals[method][rows] = y.reshape(-1, 6)
            self._known[method][rows] = True
        if certificate:
            self.certified += 1
            result = dataclasses.replace(result, attempts=(certificate, *result.attempts))
        return dataclasses.replace(result, time_s=time.perf_counter() - start)

    def _part(self, rows, interfaces, *, cohesion, tensile, **material) -> EquilibriumSystem:
        """:func:`part_system` with its material and its slice of the strengths."""
        return part_system(self.whole, rows, interfaces).with_material(
            cohesion=vertex_slice(cohesion, self.whole, interfaces),
            tensile=vertex_slice(tensile, self.whole, interfaces), **material)

    def forget(self) -> None:
        """Drop the dual points: the next part starts from scratch (its matrices and
        ordering are still the whole model's)."""
        for known in self._known.values():
            known[:] = False

    def _start(self, method, rows) -> np.ndarray:
        """(6 F,) float: the warm start of ``method`` on the part's ``rows``: the last
        dual point of every block that had one; a block without one takes the rigid
        motion of its neighbours that have one (averaged; the dual's six entries per
        block are its virtual translation and rotation times the reference length),
        zero where none has."""
        y = self._duals[method].copy()
        known = self._known[method] & rows
        for _ in range(2):  # a block whose neighbours are new too: from the second ring
            pairs = self._pairs[rows[self._pairs].all(axis=1)
                                & (known[self._pairs[:, 0]] != known[self._pairs[:, 1]])]
            if len(pairs) == 0:
                break
            new = np.where(known[pairs[:, 0]], pairs[:, 1], pairs[:, 0])
            old = pairs[:, 0] + pairs[:, 1] - new
            arm = self._centroid[new] - self._centroid[old]
            moved = np.concatenate([y[old, :3] + np.cross(y[old, 3:], arm), y[old, 3:]],
                                   axis=1)
            total = np.zeros_like(y)
            np.add.at(total, new, moved)
            count = np.bincount(new, minlength=len(y))
            reached = count > 0
            y[reached] = total[reached] / count[reached, None]
            known = known | reached
        y[~known] = 0.0
        return y[rows].ravel()

    def _within_of(self, rows) -> np.ndarray:
        """The free blocks of the last symbolic factorization when they hold ``rows`` (the
        part's own solve made it), else ``rows``."""
        if self._within is not None and not (rows & ~self._within[0]).any():
            return self._within[0]
        return rows

    def _symbolic(self, rows, within) -> Embedded:
        """The part's symbolic factorization: that of the free blocks ``within`` ((F,)
        bool, a superset of ``rows``), made in the whole model's order when they are not
        those of the last part's."""
        if self._within is None or not np.array_equal(self._within[0], within):
            side = self.whole.side_row
            new_row = np.cumsum(within) - 1
            both = (side >= 0).all(axis=1)
            edges = side[both][within[side[both]].all(axis=1)]
            order = np.argsort(self._position[within], kind="stable")
            self._within = within, BlockCholesky(int(within.sum()), new_row[edges],
                                                 block_size=6, ordering=order)
        return Embedded(self._within[1], (np.cumsum(self._within[0]) - 1)[rows])

    def centering(self, is_present, local, *, mu=0.7, density=2000.0, accuracy="balanced",
                  cone=None, cohesion=0.0, tensile=0.0) -> CenteringResult:
        """The centering force (docs/model.md 6.10) of the part whose scene blocks
        ``is_present``: from the ``local`` blocks alone where the whole part carries
        their supports (see the module's notes), else its program on the part's rows and
        columns of the whole model's matrices, on the part's symbolic factorization (the
        one its RBE solve used); both by :func:`masonry.rbe.centering.solve_centering`.
        ``weight_N`` is the part's; ``block`` the scene's blocks; the mortar as
        :meth:`solve` takes it."""
        rows, interfaces = self._selection(is_present)
        material = {"mu": mu, "density": density, "cone": friction_model(accuracy, cone),
                    "cohesion": cohesion, "tensile": tensile}
        system = self._part(rows, interfaces, **material)
        local_rows, small = self._local_part(local, rows, interfaces, material)
        result = None
        if small is not None:
            result = self._local_centering(system, small, rows, local_rows, accuracy)
        if result is None:
            result = solve_centering(system,
                                     symbolic=self._symbolic(rows, self._within_of(rows)))
        source = (np.arange(self.model.blocks.n_blocks) if self.model.block_source is None
                  else self.model.block_source)
        return dataclasses.replace(result, weight_N=system.total_weight,
                                   block=source[result.block])

    def _local_centering(self, system, small, rows, local_rows,
                         accuracy) -> CenteringResult | None:
        """The centering force of the ``local_rows`` alone (their system ``small``, the
        rest of the part held fixed), where the whole part ``system`` carries it (Newton,
        from the last stage's point, within the acceptance tolerance); else None."""
        reduced = solve_centering(small)
        if reduced.total_N is None:
            return None
        load = np.zeros((int(rows.sum()), 6))
        load[(np.cumsum(rows) - 1)[local_rows], :3] = reduced.force / system.weight_ref
        load = load.ravel()
        loaded = dataclasses.replace(  # a mortar's shifted f_ext takes the loads as well
            system, f_ext=system.f_ext + load,
            f_weight=None if system.f_weight is None else system.f_weight + load)
        # the loads are at the limit of what the part carries (the least support), where
        # Newton creeps: a point within the acceptance tolerance is all the check needs
        preset = ACCURACY[accuracy]
        workspace = {"symbolic": self._symbolic(rows, self._within_of(rows))}
        if self._known["net"][rows].any():
            workspace["warm"] = {"net": self._start("net", rows)}
        outcome = BACKENDS["newton"].solve_rbe(loaded, "net", {
            **preset.options.get("newton", {}), "tol": CHECK_TOL * preset.residual,
            "stall": WARM_STALL, "max_iter": WARM_STEPS}, workspace)
        checks = outcome.residuals
        carried = checks is not None and max(checks.equilibrium,
                                             checks.friction) <= preset.residual
        log.debug("local centering force %.6g N: %s on the whole part (Newton, %d steps)",
                  reduced.total_N, "carried" if carried else "not carried",
                  outcome.iterations)
        if not carried:
            return None
        self._duals["net"][rows] = outcome.y.reshape(-1, 6)  # the next check's start
        self._known["net"][rows] = True
        return reduced

    def adhesion(self, is_present, *, mu=0.7, density=2000.0, cone="circle",
                 ratio=TENSION_RATIO, head_ratio=1.0, support_ratio=1.0,
                 solver=INTERIOR) -> AdhesionResult:
        """The least adhesion (docs/model.md 6.12) of the part whose scene blocks
        ``is_present``: :func:`masonry.rbe.adhesion.solve_adhesion` on the part's rows and
        columns of the whole model's matrices, one conic program per part (the part's
        model is the one :func:`~masonry.rbe.boundary.restrict` gives, so is its ``a*``).
        ``interface_pair`` indexes the whole model's blocks."""
        rows, interfaces = self._selection(is_present)
        system = part_system(self.whole, rows, interfaces).with_material(
            mu=mu, density=density, cone=cone)
        return solve_adhesion(system, self.model.interfaces.subset(interfaces), ratio=ratio,
                              head_ratio=head_ratio, support_ratio=support_ratio,
                              solver=solver,
                              symbolic=self._symbolic(rows, self._within_of(rows)))

    def _selection(self, is_present) -> tuple:
        """``(rows, interfaces)``: the free blocks ((F,) bool) and the interfaces ((K,)
        bool) of the part whose scene blocks ``is_present``."""
        keep = kept_blocks(self.model, is_present)
        return keep[self.whole.free_block], keep[self.model.interfaces.pair].all(axis=1)

    def _local_part(self, local, rows, interfaces, material) -> tuple:
        """``(local_rows, small)``: the part's free blocks among the ``local`` scene
        blocks and their system alone, the rest of the part (``rows``, ``interfaces``)
        held fixed, under the part's ``material`` (:meth:`_part`'s keywords); ``small``
        None where none of them is free."""
        local_rows = kept_blocks(self.model, local)[self.whole.free_block] & rows
        if not local_rows.any():
            return local_rows, None
        touching = ((self.whole.side_row >= 0)
                    & local_rows[np.maximum(self.whole.side_row, 0)]).any(axis=1)
        return local_rows, self._part(local_rows, interfaces & touching, **material)

    def _certificate(self, small, blocks, accuracy) -> dict | None:
        """Friction-net of the local blocks alone (their system ``small``, the rest of
        the part held fixed, under the part's law; ``blocks`` of them, for the record),
        by Clarabel: its record when it certifies infeasibility (the part cannot stand),
        else None."""
        clarabel = BACKENDS["clarabel"]
        outcome = clarabel.solve_rbe(small, "net",
                                     ACCURACY[accuracy].options.get(clarabel.settings, {}),
                                     {})
        record = {"friction": "net", "solver": CERTIFICATE, "status": outcome.status,
                  "iterations": outcome.iterations,
                  "setup_s": round(outcome.setup_time, 4),
                  "solve_s": round(outcome.solve_time, 4), "blocks": blocks}
        log.debug("local certificate on %d blocks: %s", record["blocks"], outcome.status)
        return record if outcome.status == INFEASIBLE else None
