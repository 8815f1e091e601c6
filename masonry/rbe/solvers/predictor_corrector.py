"""Mehrotra's predictor-corrector iterations shared by the interior point methods of the
least adhesion (:mod:`.interior_adhesion`) and the centering force
(:mod:`.interior_centering`): the loop with its stops, the step, and the start's slacks
and multipliers. Each method states its program (its rows, their residuals and the
reduced system that gives a direction); this module walks the central path.

A program passed to :func:`iterate` has:

- ``cones``: the cones of its slacks and multipliers, one per list entry of ``s`` and
  ``z``; ``degree``: their complementarity pairs;
- ``residuals(p)``, the residuals of its rows at a point ``p`` (which has ``s`` and
  ``z``), and ``measures(p, residuals)``, ``(primal, dual, gap)``;
- ``objective(p)`` and ``gap_floor``, the least objective a gap is relative to;
- ``iterate_at(s, z)``, the reduced system factored at the scalings of ``(s, z)``: a
  :class:`ConeIterate`, whose ``direction`` ends in ``(ds, dz)``;
and its points are dataclasses whose fields are the unknowns in the order of a
direction's, the last two the lists of ``s`` and ``z`` (:func:`moved`).
"""

import dataclasses
import logging

import numpy as np

from masonry.rbe.solvers.base import OPTIMAL, OPTIMAL_INACCURATE, USER_LIMIT
from masonry.rbe.solvers.interior import largest_step, scaling_of

log = logging.getLogger(__name__)


def iterate(program, p, options, tolerances, name) -> tuple:
    """``(status, point, iterations)`` from the start ``p``: ``optimal`` where the point
    is within ``tolerances`` (``(primal, dual, gap, gap_floor)``: the gap relative to
    the objective, at least the floor), else ``optimal_inaccurate`` with the last point
    within ``options.reduced`` where the method stalls or runs out of iterations, else
    ``user_limit`` with the last point. ``options`` has ``max_iter``, ``min_step``,
    ``step_fraction``, ``refinements`` and ``refine_gap`` (refinements of a direction
    once the gap is below that times the objective); ``name`` is the log's."""
    status, iterations, best = USER_LIMIT, 0, None
    for iterations in range(options.max_iter + 1):
        residuals = program.residuals(p)
        measures = program.measures(p, residuals)
        objective = program.objective(p)
        if within(measures, tolerances, objective):
            status = OPTIMAL
            break
        if within(measures, options.reduced, objective):
            best = p
        if iterations == options.max_iter:
            break
        refinements = options.refinements if measures[2] <= options.refine_gap * max(
            abs(objective), program.gap_floor) else 0
        try:
            step, direction = _step(program, p, residuals, measures[2], refinements,
                                    options.step_fraction)
        except np.linalg.LinAlgError as error:
            log.debug("%s: reduced matrix not positive definite: %s", name, error)
            step = 0.0
        if not step >= options.min_step:  # NaN too: a direction that did not solve
            log.debug("%s: stopped at iteration %d (step %.1e; primal %.1e, dual %.1e, "
                      "gap %.1e)", name, iterations, step, *measures)
            break
        p = moved(p, step, direction)
        log.debug("%s %d: objective %.6e, primal %.1e, dual %.1e, gap %.1e, step %.3f",
                  name, iterations, objective, *measures, step)
    if status != OPTIMAL and best is not None:  # the last point within the reduced ones
        status, p = OPTIMAL_INACCURATE, best
    return status, p, iterations


def moved(p, step, direction):
    """The point ``p + step direction`` (a direction's entries in the order of ``p``'s
    fields; lists, one array per cone, entry by entry)."""
    values = (getattr(p, field.name) for field in dataclasses.fields(p))
    return type(p)(*([a + step * b for a, b in zip(v, d)] if isinstance(v, list)
                     else v + step * d for v, d in zip(values, direction)))


def within(measures, tolerances, objective) -> bool:
    """Whether ``measures`` ``(primal, dual, gap)`` meet ``tolerances`` ``(tol,
    dual_tol, gap_tol, gap_floor)``: the gap at most ``gap_tol`` times the objective or
    ``gap_floor``, the larger."""
    primal, dual, gap = measures
    tol, dual_tol, gap_tol, gap_floor = tolerances
    return primal <= tol and dual <= dual_tol and gap <= max(gap_tol * abs(objective),
                                                                gap_floor)


def _step(program, p, residuals, gap, refinements, step_fraction) -> tuple:
    """``(step, direction)`` from ``p`` (whose gap ``s^T z`` is ``gap``): Mehrotra's
    predictor, then the corrector on the same factor (``LinAlgError`` where the reduced
    matrix does not factor)."""
    cones = program.cones
    point = program.iterate_at(p.s, p.z)
    squares = [cone.product(sc.lam, sc.lam) for cone, sc in zip(cones, point.scalings)]
    ds, dz = point.direction(*residuals, squares, refinements=refinements)[-2:]
    step = largest_step(cones, p.s, p.z, ds, dz)
    predicted = float(sum(np.sum((sb + step * dsb) * (zb + step * dzb))
                          for sb, zb, dsb, dzb in zip(p.s, p.z, ds, dz)))
    target = (predicted / gap) ** 3 * gap / program.degree
    r_comp = [square + cone.product(sc.times_w_inverse(dsb), sc.times_w(dzb))
              - target * cone.identity(len(square))
              for cone, sc, square, dsb, dzb in zip(cones, point.scalings, squares, ds, dz)]
    direction = point.direction(*residuals, r_comp, refinements=refinements)
    return step_fraction * largest_step(cones, p.s, p.z, *direction[-2:]), direction


START_MARGIN = 0.1
"""A start's slacks' least eigenvalue, relative to the root mean square force of the
least-squares point it starts from (:func:`inside_start`)."""


def inside_start(cones, s, z, margin) -> tuple:
    """``(s, z)`` of a start: every slack at least ``margin`` inside its cone (its least
    eigenvalue raised along the cone's identity), the multipliers shifted inside by 1.5
    times their most negative eigenvalue and then by half the complementarity over the
    slacks' trace (:func:`~.cones.centred_start`'s rule, the slacks kept)."""
    s = [sb + np.maximum(0.0, margin - cone.min_eigenvalue(sb))[:, None]
         * cone.identity(len(sb)) for cone, sb in zip(cones, s)]
    least = min(float(cone.min_eigenvalue(zb).min()) for cone, zb in zip(cones, z))
    z = [zb + max(0.0, -1.5 * least) * cone.identity(len(zb)) for cone, zb in zip(cones, z)]
    product = sum(float(np.sum(sb * zb)) for sb, zb in zip(s, z))
    trace = sum(cone.trace(sb) for cone, sb in zip(cones, s))
    z = [zb + (0.5 * product / trace) * cone.identity(len(zb)) for cone, zb in zip(cones, z)]
    return s, z


class ConeIterate:
    """The Nesterov-Todd scalings of a point's slacks ``s`` and multipliers ``z`` in
    ``cones`` (lists, one entry per cone), and a direction from them: a subclass factors
    its reduced system and solves it (``_solve(*rows, q_c)``, the rows' residuals and
    ``W^-1 ds + W dz = q_c`` per cone) and says what a direction leaves of the rows
    (``_left(d, target)``, the right-hand side of its correction)."""

    def __init__(self, cones, s, z):
        self.cones = cones
        self.scalings, self.w_inverse = zip(*(scaling_of(cone, sb, zb) for cone, sb, zb
                                              in zip(cones, s, z)))
        self.w2_inverse = [w * w if w.ndim == 2 else w @ w for w in self.w_inverse]

    def w2i(self, b, v):
        """``W_b^-2 v`` per vertex (or block) of cone ``b``."""
        w = self.w2_inverse[b]
        return w * v if w.ndim == 2 else np.einsum("vij,vj->vi", w, v)

    def direction(self, *rows, refinements=0) -> tuple:
        """The direction for the residuals of the program's rows (``rows`` but the last)
        and the scaled complementarity ``lam o (W^-1 ds + W dz) = -r_comp`` (the last,
        per cone), with ``refinements`` passes of iterative refinement on the unreduced
        rows: each adds the solution of what the last leaves."""
        q_c = [-cone.divide(sc.lam, rc)
               for cone, sc, rc in zip(self.cones, self.scalings, rows[-1])]
        target = (*rows[:-1], q_c)
        d = self._solve(*target)
        for _ in range(refinements):
            d = tuple(_add(u, v) for u, v in zip(d, self._solve(*self._left(d, target))))
        return d


def _add(u, v):
    if isinstance(u, list):
        return [a + b for a, b in zip(u, v)]
    return u + v
