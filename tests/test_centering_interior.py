"""The centering force by the own interior point method (masonry/rbe/solvers/
interior_centering.py) against Clarabel on the same program (docs/model.md 6.10): an
independent solver of the same second-order cone program, on brick stages of a small
dome that need support and one that stands, under Coulomb's cone, a pyramid and a mortar
whose tension cut-off lies inside the cone; in a stage sequence on the sequence's
symbolic factorization; and Clarabel where the method ends without a checked point."""

import numpy as np
import pytest
from test_rbe import SUPPORT as SUPPORT_KIND
from test_rbe import box, make_interfaces, rot_y

from masonry.blocks import Blocks
from masonry.params import from_preset
from masonry.pipeline import build_model
from masonry.rbe.boundary import Model, kept_blocks, restrict
from masonry.rbe.centering import INTERIOR, SOLVER, centering_force, solve_centering
from masonry.rbe.sequence import StageSequence, part_system
from masonry.rbe.solvers import interior_centering, predictor_corrector
from masonry.rbe.solvers.base import USER_LIMIT
from masonry.rbe.solvers.newton import NewtonSystem
from masonry.stages.plans import make_plan

MU, DENSITY = 0.7, 2000.0
AGREE = (1e-4, 1e-5)
"""Both solvers' totals agree within this, relative and per mean block weight: the
method's point where it ends ``optimal_inaccurate`` (CenteringOptions.reduced; Clarabel's
gaps are 1e-10 of the scaled objective)."""
CHECK = 1e-5
"""The acceptance tolerance both points are held to (equilibrium and friction)."""


def _stage_system(model, plan, stage, cone, cohesion=0.0, tensile=0.0):
    sequence = StageSequence(model)
    keep = kept_blocks(model, plan.is_present(stage))
    interfaces = keep[model.interfaces.pair].all(axis=1)
    system = part_system(sequence.whole, keep[sequence.whole.free_block], interfaces)
    return system.with_material(mu=MU, density=DENSITY, cone=cone, cohesion=cohesion,
                                tensile=tensile)


@pytest.mark.parametrize("cone, cohesion, stage", [
    ("circle", 0.0, 1),
    ("circle", 0.0, 4),
    ("polygon:8", 0.0, 3),
    ("circle", 300.0, 1),      # 300 Pa of cohesion, 150 Pa of tension: the cut-off inside
])
def test_the_interior_point_method_meets_clarabel(top_course, cone, cohesion, stage):
    """Stages of the small dome that need support: both totals within :data:`AGREE`,
    each point checked by the same recomputed residuals, the same blocks held, and the
    mortar needing less than dry joints."""
    model, plan = top_course
    system = _stage_system(model, plan, stage, cone, cohesion, cohesion / 2)
    ours, theirs = (solve_centering(system, solver=solver) for solver in (INTERIOR, SOLVER))
    assert (ours.solver, theirs.solver) == (INTERIOR, SOLVER)
    assert theirs.total_N > 1e-2 * np.mean(theirs.block_weight)  # a tenth of a brick or so
    assert ours.total_N == pytest.approx(theirs.total_N, rel=AGREE[0],
                                         abs=AGREE[1] * np.mean(theirs.block_weight))
    assert max(ours.residual_eq, ours.friction_violation) <= CHECK
    assert ours.block[ours.held[0]] == theirs.block[theirs.held[0]]
    if cohesion:
        dry = solve_centering(_stage_system(model, plan, stage, cone), solver=SOLVER)
        assert ours.total_N < dry.total_N


@pytest.mark.slow
def test_the_method_reaches_the_optimum_where_its_scalings_span_many_decades():
    """A stage of preset 1's cyclic section near its top (728 bricks, laid pattern-first):
    without the primal regularization (CenteringOptions.proximal) the method stalled
    there as its dual rows' residual grew, and Clarabel answered; with it the method's
    own point meets Clarabel's within :data:`AGREE`."""
    stage = 728
    scene, model = build_model(from_preset("1", boundary="cyclic"))
    plan = make_plan(scene, "brick", "pattern-first")
    system = _stage_system(model, plan, stage, "circle")
    ours, theirs = (solve_centering(system, solver=solver) for solver in (INTERIOR, SOLVER))
    assert ours.solver == INTERIOR
    assert ours.total_N == pytest.approx(theirs.total_N, rel=AGREE[0],
                                         abs=AGREE[1] * np.mean(theirs.block_weight))
    assert max(ours.residual_eq, ours.friction_violation) <= CHECK


def test_a_direction_that_does_not_solve_ends_the_iterations(top_course, monkeypatch):
    """A step that is not a number (a direction that did not solve) ends the method at
    once, with the last point within its reduced tolerance or none, instead of walking
    NaNs to the iteration limit."""
    model, plan = top_course
    system = _stage_system(model, plan, 1, "circle")
    steps = []
    solved = predictor_corrector._step

    def failing(*args):
        step, direction = solved(*args)
        steps.append(step)
        return (np.nan if len(steps) > 3 else step), direction

    monkeypatch.setattr(predictor_corrector, "_step", failing)
    found = interior_centering.solve(NewtonSystem(system, "net"))
    assert len(steps) == 4 and found.iterations == 3
    assert found.status == USER_LIMIT and np.isfinite(found.x).all()


def test_a_stage_that_stands_needs_none(top_course):
    """Stage 2 of the small dome stands dry (tests/test_adhesion_interior.py): its
    centering force is 0 within 1e-6 of its weight, and no block is held."""
    model, plan = top_course
    result = solve_centering(_stage_system(model, plan, 2, "circle"))
    assert result.solver == INTERIOR
    assert result.total_N <= 1e-6 * result.weight_N
    assert result.held_count == 0


def test_the_sequence_solves_each_stage_on_its_own_factorization(top_course):
    """The stage sequence's centering force (the course's bricks alone where the stage
    carries their supports, else the stage's program on the symbolic factorization of
    the course being laid) against Clarabel on each stage's model built alone
    (restrict): the same totals within :data:`AGREE` and the same held blocks, named
    by the scene's blocks."""
    model, plan = top_course
    sequence = StageSequence(model)
    for stage in (1, 3, 5):
        present = plan.is_present(stage)
        ours = sequence.centering(present, plan.local(stage), mu=MU, density=DENSITY)
        part = restrict(model, present)
        alone = centering_force(part, mu=MU, density=DENSITY, solver=SOLVER)
        assert ours.solver == INTERIOR
        assert ours.total_N == pytest.approx(alone.total_N, rel=AGREE[0],
                                             abs=AGREE[1] * np.mean(alone.block_weight))
        assert ([b for b, _, _ in ours.held_forces()]
                == [b for b, _, _ in alone.held_forces(part.block_source)])


def test_a_block_no_joint_touches_is_held_by_its_weight():
    """A block on a 60-degree slope beside one in the air that no joint touches: the
    method holds the one in the air by its weight, straight up (its moment rows are
    empty), and the one on the slope by W sin(a - phi) (tests/test_centering.py)."""
    a = np.radians(60.0)
    rotation = rot_y(a)
    corners = [box((-2, -2, -0.1), (2, 2, 0)) @ rotation.T,
               box((0, 0, 0), (1.0, 0.2, 0.1)) @ rotation.T, box((5, 5, 5), (6, 6, 6))]
    blocks = Blocks.from_hexahedra(corners, block_class=["ground", "block", "block"],
                                   block_is_support=[True, False, False])
    interfaces = make_interfaces([(0, 1)], [corners[1][[0, 1, 3, 2]]], [rotation[:, 2]],
                                 SUPPORT_KIND)
    result = centering_force(Model(blocks, interfaces), mu=MU, density=DENSITY)
    assert result.solver == INTERIOR
    slope, air = result.block_weight
    assert result.force[1] == pytest.approx([0.0, 0.0, air], abs=1e-6 * air)
    assert result.magnitude[0] == pytest.approx(slope * np.sin(a - np.arctan(MU)),
                                                rel=1e-6)


def test_clarabel_answers_where_the_method_ends_without_a_point(top_course, monkeypatch):
    """Where the method ends without a point (here made to), Clarabel's is the answer
    and the result says so."""
    model, plan = top_course
    system = _stage_system(model, plan, 1, "circle")
    monkeypatch.setattr(interior_centering, "solve", lambda ns: interior_centering.Solution(
        USER_LIMIT, None, None, 60, 0.0))
    result = solve_centering(system)
    assert result.solver == SOLVER and result.total_N > 0
