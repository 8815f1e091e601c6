"""The least adhesion by the own interior point method (masonry/rbe/solvers/
interior_adhesion.py) against Clarabel on the same program (docs/model.md 6.12): an
independent solver of the same conic program, on brick stages of a small dome where the
cut-off binds and where it does not, under Coulomb's cone and a pyramid, with joint kinds
of their own strength."""

import numpy as np
import pytest
from test_adhesion import weight
from test_rbe import cantilever

from masonry.rbe.adhesion import INTERIOR, SOLVER, least_adhesion, solve_adhesion
from masonry.rbe.boundary import Model, kept_blocks
from masonry.rbe.equilibrium import assemble
from masonry.rbe.sequence import StageSequence, part_system
from masonry.rbe.solvers import interior_adhesion
from masonry.rbe.solvers.newton import NewtonSystem

MU, DENSITY = 0.7, 2000.0


def _stage_system(model, plan, stage, cone):
    sequence = StageSequence(model)
    keep = kept_blocks(model, plan.is_present(stage))
    interfaces = keep[model.interfaces.pair].all(axis=1)
    system = part_system(sequence.whole, keep[sequence.whole.free_block], interfaces)
    return (system.with_material(mu=MU, density=DENSITY, cone=cone),
            model.interfaces.subset(interfaces))


@pytest.mark.parametrize("cone, ratio, head, stage", [
    ("circle", 0.5, 1.0, 1),       # the cut-off inside the cone
    ("circle", 0.5, 1.0, 4),
    ("circle", 2.0, 1.0, 1),       # r > 1 / mu: the cone's apex is the cut-off
    ("polygon:8", 0.5, 1.0, 1),
    ("circle", 0.5, 0.5, 3),       # head joints at half strength
])
def test_the_interior_point_method_meets_clarabel(top_course, cone, ratio, head, stage):
    """Both solvers' a* within 1e-5 (Clarabel's own gap tolerance is 1e-8 of its scaled
    objective), each point checked by the same residuals (equilibrium and law within
    1e-5, recomputed), and the joint each names as needing most uses all of its a* (which
joints reach the limit is not unique at a degenerate optimum)."""
    model, plan = top_course
    system, interfaces = _stage_system(model, plan, stage, cone)
    ours, theirs = (solve_adhesion(system, interfaces, ratio=ratio, head_ratio=head,
                                   solver=solver) for solver in (INTERIOR, SOLVER))
    assert ours.solver == INTERIOR and theirs.solver == SOLVER
    assert theirs.a_kPa > 0.05
    assert ours.a_kPa == pytest.approx(theirs.a_kPa, rel=1e-5)
    assert max(ours.residual_eq, ours.law_violation) <= 1e-5
    for result in (ours, theirs):  # the optimum's joints at the limit may differ
        assert result.interface_kPa[result.needing[0]] == pytest.approx(result.a_kPa,
                                                                        rel=1e-4)


def test_the_stage_stands_just_above_its_least_adhesion_and_not_below(top_course):
    """An independent check through the stage's RBE with the contact law (Newton, the
    stages' solver): with c = a*(1 + 1e-3), t_c = r c the stage stands; with a*(1 -
    1e-3) it does not."""
    model, plan = top_course
    sequence = StageSequence(model)
    present = plan.is_present(1)
    result = sequence.adhesion(present, mu=MU, density=DENSITY, ratio=0.5)
    assert result.solver == INTERIOR
    for margin, verdict in ((1 + 1e-3, True), (1 - 1e-3, False)):
        law = result.law_at(margin)
        rbe = sequence.solve(present, mu=MU, density=DENSITY, cohesion=law.cohesion_Pa,
                             tensile=law.tensile_Pa)
        assert rbe.feasible is verdict, margin


def test_a_program_it_cannot_solve_goes_to_clarabel():
    """No tension (r = 0) and an overhang: no adhesion holds it. The interior point
    method has no infeasibility detection and ends without a point; Clarabel then says
    infeasible, and the result says which solver gave the word."""
    blocks, interfaces = cantilever()
    result = least_adhesion(Model(blocks, interfaces), mu=MU, density=DENSITY, ratio=0.0)
    assert result.a_kPa is None and result.solver == SOLVER
    assert "infeasible" in result.reason


def test_the_method_alone_on_the_cantilever_by_hand():
    """The cantilever of tests/test_adhesion.py at r = 0.5, by the method directly: a* =
    W / (3 A_i) max(1 / r, mu), in the program's units (W_ref / A_ref), with status
    optimal and the equilibrium rows met to 1e-8 of the load."""
    blocks, interfaces = cantilever()
    system = assemble(blocks, interfaces, mu=MU, density=DENSITY)
    area = system.vertex_area
    ns = NewtonSystem(system, "net")
    solution = interior_adhesion.solve(ns, area / area.mean(), 0.5)
    needed = weight(blocks) / (3 * area[0]) * 2.0 / (system.weight_ref / area.mean())
    assert solution.status == "optimal"
    assert solution.point.a == pytest.approx(needed, rel=1e-6)
    residual = system.times_A_eq(ns.full_vector(solution.x, system.layout)) + system.f_ext
    assert np.abs(residual).max() <= 1e-8 * np.abs(system.f_ext).max()
