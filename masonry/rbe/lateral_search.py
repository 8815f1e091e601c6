"""The lateral load factor over every azimuth (``--lateral all``, docs/model.md 6.8):
the azimuths sampled (24 and a dome's symmetry directions), each orbit of the model's
rotations and mirrors solved once on one held program
(:class:`~masonry.rbe.collapse.CollapseLP`), one in a mirror plane on the half in it
(docs/model.md 6.11), two at once on large models, and the least sample refined between
the samples (:mod:`masonry.rbe.azimuth_refine`)."""

import dataclasses
import functools
import logging
import time

import numpy as np

from masonry import forking
from masonry.rbe.azimuth_refine import refine_least, search_factor
from masonry.rbe.collapse import METHOD, CollapseLP, CollapseResult, on_the_whole
from masonry.rbe.loads import Lateral, lateral
from masonry.rbe.mirror import half_model, in_plane, states_exactly
from masonry.tolerances import AZIMUTH_REFINE_REL, FACTOR_TIE_REL

__all__ = ["lateral_azimuths", "symmetric_key", "worst_lateral"]

log = logging.getLogger(__name__)

TWO_AT_ONCE = ("interior",)
"""Backends whose azimuths a search splits over two processes: the interior point method
factors on this process's cores; Clarabel and HiGHS keep their own threads, and HiGHS's
simplex gains from one model's warm starts."""

def lateral_azimuths(n_webs=None, count=24) -> np.ndarray:
    """Azimuths in degrees for :func:`worst_lateral`: ``count`` equally spaced, plus the
    directions a dome's symmetry makes special (the mid-planes of the webs and the corners,
    every ``180 / n`` degrees), sorted and unique."""
    angles = np.arange(count) * 360.0 / count
    if n_webs is not None:
        angles = np.concatenate([angles, np.arange(2 * n_webs) * 180.0 / n_webs])
    return np.unique(np.round(angles % 360.0, 9))


def worst_lateral(model, azimuths=None, *, mu=0.7, density=2000.0, cone="circle",
                  n_webs=None, period_deg=None, mirrors=(), dead_load_feasible=None,
                  time_limit=600.0, method=None, cores=None, cohesion=0.0,
                  tensile=0.0, refine=True,
                  azimuth_rel=AZIMUTH_REFINE_REL) -> CollapseResult:
    """The smallest lateral load factor over ``azimuths`` (``--lateral all``) and, with
    ``refine``, between them: every bracket between two of them (less than 180 degrees
    apart) where a smaller factor may lie is cut at the corner of its bound, until every
    bound is within ``azimuth_rel`` of the least
    (:func:`~masonry.rbe.azimuth_refine.refine_least`).

    One LP serves every azimuth (:meth:`CollapseLP.solve_lateral`: the interior point
    method and Clarabel keep their symbolic factorization, HiGHS's simplex restarts from
    the last basis), ``method`` a backend as for :class:`CollapseLP`, and the dead load is
    checked once (unless ``dead_load_feasible`` is given); on large models, when
    ``cores`` (default the process's, :func:`masonry.forking.cores`) allow two, two
    azimuths at once (:func:`masonry.forking.two_at_once`). The model's symmetries
    leave fewer azimuths to solve (:func:`symmetric_key`): ``period_deg``, a rotation
    about the z axis that maps it onto itself (a full dome of ``n`` webs: ``360 / n``),
    and ``mirrors``, the azimuths of its mirror planes (docs/model.md 6.11; used with
    Coulomb's cone only, :func:`~masonry.rbe.mirror.states_exactly`): azimuths that these
    map onto each other have the same factor and each is solved once; one that lies in a
    mirror plane is solved on the model's half in it (:mod:`masonry.rbe.mirror`), and
    reported, if it is the worst, on the whole. Returns the worst azimuth's result with
    every azimuth's factor in ``azimuths`` ((azimuth, factor or None) pairs) and those
    the refinement solved in ``refined``; of factors tied with the least
    (:data:`~masonry.tolerances.FACTOR_TIE_REL`) a sample's is reported first.
    """
    azimuths = lateral_azimuths(n_webs) if azimuths is None else np.asarray(azimuths, float)
    start = time.perf_counter()
    mirrors = tuple(mirrors) if states_exactly(cone, cohesion) else ()
    keys = [symmetric_key(a, period_deg, mirrors) for a in azimuths]
    todo = {}
    for key, azimuth in zip(keys, azimuths):
        todo.setdefault(key, float(azimuth))
    cases = _LateralCases(model, mirrors, todo.values(), dict(
        mu=mu, density=density, cone=cone, time_limit=time_limit, method=method,
        cores=cores, cohesion=cohesion, tensile=tensile))
    solved = _solve_azimuths(cases, list(todo.items()), dead_load_feasible,
                             two=forking.usable_cores(cores) >= 2)
    results = []
    for key in keys:
        if key not in solved:  # the dead load cannot stand: the search ended
            break
        results.append(solved[key])
        if solved[key].dead_load_feasible is False:
            break
    log.info("lateral search: %d azimuths, %d solved", len(results), len(solved))
    factors = [(float(a), r.load_factor) for a, r in zip(azimuths, results)]
    refined = {}
    if refine and len(results) == len(keys) and results[-1].dead_load_feasible:
        samples = [(a, search_factor(r)) for a, r in zip(azimuths, results)]
        orbit = functools.partial(symmetric_key, period_deg=period_deg, mirrors=mirrors)

        def factor_at(azimuth):
            refined[azimuth] = cases.solve(azimuth, dead_load_feasible=True)
            return search_factor(refined[azimuth])

        refine_least(samples, factor_at, key=orbit, azimuth_rel=azimuth_rel)
    sampled = [r for r in results if r.load_factor is not None]
    found = sampled + [r for r in refined.values() if r.load_factor is not None]
    worst = results[-1]
    if found:
        least = min(found, key=lambda r: r.load_factor)
        worst = next((r for r in sampled if r.load_factor
                      <= least.load_factor + FACTOR_TIE_REL * abs(least.load_factor)), least)
    return dataclasses.replace(cases.on_the_whole(worst), azimuths=tuple(factors), refined=tuple(
        (float(a), r.load_factor) for a, r in refined.items()), time_s=time.perf_counter() - start)


def symmetric_key(azimuth_deg, period_deg=None, mirrors=()) -> float:
    """The least azimuth (degrees, in [0, 360)) that the rotations by ``period_deg`` and
    the mirrors in the planes at ``mirrors`` (azimuths) map ``azimuth_deg`` to: azimuths
    of one key have the same lateral load factor."""
    orbit, new = set(), [float(azimuth_deg)]
    while new:
        angle = round(new.pop() % 360.0, 9) % 360.0
        if angle in orbit:
            continue
        orbit.add(angle)
        new += [2.0 * plane - angle for plane in mirrors]
        new += [angle + period_deg] if period_deg else []
    return min(orbit)


class _LateralCases:
    """The lateral loads of a search on one model: an azimuth in one of its ``mirrors``
    on the half in that plane (built here for the ``azimuths`` that need it), the others
    on the whole; each program made once, when first solved (in the process that solves
    it)."""

    def __init__(self, model, mirrors, azimuths, options):
        self.model, self.mirrors, self.options = model, tuple(mirrors), options
        planes = {in_plane(float(a), self.mirrors) for a in azimuths} - {None}
        self.halves = {plane: half_model(model, plane) for plane in planes}
        self.method = METHOD if options["method"] is None else options["method"]
        self.blocks = int((~model.blocks.block_is_support).sum())
        self._programs = {}

    def _program(self, plane) -> CollapseLP:
        if plane not in self._programs:
            model = self.model if plane is None else self.halves[plane].model
            self._programs[plane] = CollapseLP(model, **self.options)
        return self._programs[plane]

    def solve(self, azimuth, *, dead_load_feasible=None) -> CollapseResult:
        """The factor at ``azimuth`` (on a half: the half's result, its azimuth set)."""
        plane = in_plane(azimuth, self.mirrors)
        if plane is not None and plane not in self.halves:  # a refinement's azimuth
            self.halves[plane] = half_model(self.model, plane)
        problem = self._program(plane)
        if plane is None:
            return problem.solve_lateral(azimuth, dead_load_feasible=dead_load_feasible)
        live = self.halves[plane].live(Lateral(azimuth), self.options["density"])
        return dataclasses.replace(problem.solve(live, dead_load_feasible=dead_load_feasible),
                                   azimuth_deg=float(azimuth) % 360.0)

    def on_the_whole(self, result) -> CollapseResult:
        """``result`` as the whole model's (:func:`on_the_whole` for a half's)."""
        plane = (None if result.azimuth_deg is None
                 else in_plane(result.azimuth_deg, self.mirrors))
        if plane is None:
            return result
        options = {key: self.options[key] for key in ("mu", "density", "cone")}
        live = lateral(self.model, result.azimuth_deg, options["density"])
        return on_the_whole(self.halves[plane], result, live, **options)



def _solve_azimuths(cases, todo, known, two) -> dict:
    """Solve the ``(key, azimuth)`` pairs of ``todo`` in order (``cases``: a
    :class:`_LateralCases`), each told what the earlier ones found of the dead load; once
    it is known to stand, and when ``two`` cores may be used by a backend of
    :data:`TWO_AT_ONCE`, the rest two at once on a large model
    (:func:`masonry.forking.two_at_once`). Returns key -> :class:`CollapseResult`; ends
    at the first that finds the dead load cannot stand."""
    solved = {}
    for index, (key, azimuth) in enumerate(todo):
        if known is True and two and cases.method in TWO_AT_ONCE:
            keys, azimuths = zip(*todo[index:])
            standing = functools.partial(cases.solve, dead_load_feasible=True)
            solved.update(zip(keys, forking.two_at_once(standing, azimuths,
                                                        blocks=cases.blocks)))
            break
        solved[key] = cases.solve(azimuth, dead_load_feasible=known)
        known = solved[key].dead_load_feasible
        if known is False:
            break
    return solved
