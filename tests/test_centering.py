"""The centering force (docs/model.md 6.10): the least total force that supports at the
blocks' centroids must give a structure so that it stands, against statics by hand.

The program is solved by the own interior point method (tests/test_centering_interior.py
holds it against Clarabel), and by Clarabel to gaps of 1e-10 in scaled units (forces per
reference weight, the mean block weight) where asked: Clarabel's total is within 1e-6 of
the reference weight of the optimum, the interior point method's within 1e-4 of the
total where it stops short of its own tolerances (:data:`INTERIOR_REL`); these tests allow that and check it against an independent
SOCP.
"""

import csv
import json

import numpy as np
import pytest
import scipy.sparse as sp
from test_friction import tilted_block
from test_rbe import incline

import masonry
from masonry.blocks import Blocks
from masonry.interfaces import detect
from masonry.rbe.boundary import Model, restrict
from masonry.params import Params, validate
from masonry.pipeline import build_model
from masonry.rbe.centering import INTERIOR, SOLVER, centering_force
from masonry.rbe.equilibrium import assemble
from masonry_cli.main import main

MU = 0.7
PHI = np.arctan(MU)
ACCURACY = 1e-6
"""Allowed error of a centering force, per reference weight (module docstring)."""
INTERIOR_REL = 1e-4
"""Allowed error of the interior point method's total, relative to the total: where its
reduced system stops short of its tolerances it accepts a point within 1e-4 of the
optimum (masonry.rbe.solvers.interior_centering.CenteringOptions.reduced; on these
webs 6.5e-7 and 1.6e-6 of the total)."""
DIRECTION = 1e-3
"""Allowed error of a centering force's components, per reference weight: the total is
flat to first order about the optimal direction, so the direction is known to about the
square root of the total's accuracy."""


# ---------------------------------------------------------------------- a slope
@pytest.mark.parametrize("cone", ["circle", "polygon:16", "square"])
@pytest.mark.parametrize("degrees", [40.0, 60.0])
def test_a_block_on_a_slope_steeper_than_the_friction_angle(cone, degrees):
    """A squat block of weight W on a slope of angle a > phi = atan(mu), held at its
    centroid by a force s. The slab's reaction R lies in the friction cone, of half
    angle phi about the slope's normal n; equilibrium is s = -(W + R), W the weight
    vector, so ||s|| is the distance from the point W e_z (straight up, at angle a from
    n towards the uphill side) to the cone. Up lies outside the cone (a > phi), so the
    nearest point of the cone is on its uphill edge ray, at angle phi from n, and the
    distance is W sin(a - phi), with s perpendicular to that ray: at angle 90 + phi from
    n towards uphill, that is phi below the uphill direction of the slope (pressing the
    block into it, which raises the friction it can have), or a - phi above the
    horizontal. Along the slope alone a support would need W (sin a - mu cos a) =
    W sin(a - phi) / cos(phi): more.

    The pyramids: the slope falls along the joint's t2 axis (``incline``), where the
    16-sided pyramid has an edge ray at the cone's radius and the square a face at it,
    so the section through n and t2 is the cone's, and so is the distance."""
    a = np.radians(degrees)
    blocks, interfaces = incline(a, base=1.0, height=0.1)
    result = centering_force(Model(blocks, interfaces), mu=MU, cone=cone)
    weight = result.weight_N
    assert result.status == "optimal"
    assert result.total_N == pytest.approx(weight * np.sin(a - PHI), abs=ACCURACY * weight)
    assert result.fraction == pytest.approx(np.sin(a - PHI), abs=ACCURACY)
    assert np.sin(a - PHI) < np.sin(a) - MU * np.cos(a)
    normal = np.array([np.sin(a), 0.0, np.cos(a)])    # the slope falls towards +x
    uphill = np.array([-np.cos(a), 0.0, np.sin(a)])
    direction = -np.sin(PHI) * normal + np.cos(PHI) * uphill
    (force,) = result.force
    assert force == pytest.approx(result.total_N * direction, abs=DIRECTION * weight)
    assert result.held.tolist() == [0]


@pytest.mark.parametrize("direction", [25.0, 70.0])
def test_the_slope_needs_the_same_whichever_way_it_falls(direction):
    """Coulomb's cone is isotropic: the slope falling towards any azimuth (interfaces
    detected, their axes not along the fall) needs W sin(a - phi)."""
    a = PHI + np.radians(10.0)
    result = centering_force(tilted_block(a, direction), mu=MU)
    assert result.fraction == pytest.approx(np.sin(a - PHI), abs=ACCURACY)


@pytest.mark.parametrize("cone", ["circle", "polygon:16"])
def test_a_block_that_stands_needs_no_force(cone):
    blocks, interfaces = incline(PHI - np.radians(5.0), base=1.0, height=0.1)
    result = centering_force(Model(blocks, interfaces), mu=MU, cone=cone)
    assert result.total_N <= ACCURACY * result.weight_N
    assert result.held.tolist() == []


# ---------------------------------------------------------------------- book stacks
def stack_hold(centre, top, width=1.0, height=0.2):
    """The least force at the centroids that holds the blocks ``1..top`` of a stack of
    equal blocks (``centre`` their x, block 0 on the slab) when those above block ``j``
    tip together about its edge, ``j`` the lowest such block (book stacking).

    Virtual work: the part above block ``j`` turning by d theta about the edge P of ``j``
    its part of the overhang lets go: its weight does ``W_part e d theta`` of work (``e``
    the horizontal distance of its centroid beyond P), a force ``s_i`` at the centroid
    ``c_i`` at most ``||s_i|| |c_i - P| d theta``, and the joints that open do none. So
    ``sum ||s_i|| >= W_part e / max |c_i - P|``: the force on the block farthest from P,
    perpendicular to ``c_i - P``. That force is admissible (:func:`stack_stands`), so it
    is the least. Returns ``(force per block weight, the block held, the force (2,) in
    x, z per block weight)``."""
    centre = np.asarray(centre[:top + 1], dtype=float)
    height_of = (np.arange(len(centre)) + 0.5) * height
    for j in range(len(centre) - 1):
        part = centre[j + 1:].mean()
        side = np.sign(part - centre[j])
        edge = np.array([centre[j] + side * width / 2, (j + 1) * height])
        if abs(part - centre[j]) > width / 2:
            break
    else:
        raise ValueError("no part of the stack tips")
    moment = (len(centre) - j - 1) * abs(part - edge[0])
    arm = np.column_stack([centre[j + 1:], height_of[j + 1:]]) - edge
    far = int(np.argmax(np.linalg.norm(arm, axis=1)))
    lever = np.linalg.norm(arm[far])
    force = moment / lever * np.array([-arm[far, 1], arm[far, 0]]) * side / lever
    return moment / lever, j + 1 + far, force


def stack_stands(centre, held, force, width=1.0, height=0.2):
    """Statics by hand: with ``force`` ((2,) x, z per block weight) at the centroid of
    block ``held``, the load on every part above a joint (its weights and that force)
    crosses the joint within the overlap of the two blocks, and within the friction
    angle."""
    centre = np.asarray(centre, dtype=float)
    for j in range(len(centre) - 1):  # the joint on top of block j
        blocks = np.arange(j + 1, len(centre))
        load = np.array([0.0, -len(blocks)])
        moment = -centre[blocks].sum()            # x F_z - z F_x of the weights
        if held in blocks:
            load += force
            moment += centre[held] * force[1] - (held + 0.5) * height * force[0]
        z = (j + 1) * height
        x = (moment + z * load[0]) / load[1]      # where the load's line crosses z
        low = max(centre[j], centre[j + 1]) - width / 2
        high = min(centre[j], centre[j + 1]) + width / 2
        if not (low - 1e-9 <= x <= high + 1e-9 and abs(load[0]) <= MU * -load[1]):
            return False
    return True


def stack_model(offsets, width=1.0, height=0.2):
    from test_stages import stack

    blocks, centre = stack(offsets, width, height)
    return Model(blocks, detect(blocks)), centre


@pytest.mark.parametrize("offsets, top, expected", [
    (np.full(5, 0.55), 1, 1 / np.sqrt(5)),    # the second block tips: 0.05 / |(0.05, 0.1)|
    (np.full(5, 0.3), 3, 0.3 / np.sqrt(0.41)),  # blocks 2-4 tip over block 1
])
def test_book_stack_holds_its_overhang_by_virtual_work(offsets, top, expected):
    """The first stage of a laid stack that tips (tests/test_stages.py): the force that
    holds it, by virtual work about the hinge (:func:`stack_hold`)."""
    model, centre = stack_model(offsets)
    present = np.zeros(model.blocks.n_blocks, bool)
    present[1:top + 2] = True                      # the slab is block 0 of the scene
    result = centering_force(restrict(model, present), mu=MU)
    size, held, force = stack_hold(centre, top)
    assert size == pytest.approx(expected, rel=1e-12)
    assert stack_stands(centre[:top + 1], held, force)
    brick = result.block_weight[0]
    assert result.total_N == pytest.approx(size * brick, abs=ACCURACY * brick)
    ((block, vector, newtons),) = result.held_forces()
    assert block == held + 1 and newtons == pytest.approx(result.total_N)
    assert vector[[0, 2]] == pytest.approx(force * brick, abs=DIRECTION * brick)


def test_blocks_that_touch_nothing_are_held_by_their_weight():
    """A block alone in the air: its weight, straight up, with no solve."""
    blocks = Blocks.from_hexahedra([np.array(
        [[0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1], [0, 0, 2], [1, 0, 2], [0, 1, 2],
         [1, 1, 2]], float)], block_class=["block"], block_is_support=[False])
    result = centering_force(Model(blocks, detect(blocks)), mu=MU, density=2000.0)
    assert result.total_N == pytest.approx(2000.0 * 9.81)
    assert result.force.tolist() == [[0.0, 0.0, 2000.0 * 9.81]]


# ---------------------------------------------------------------------- an independent SOCP
def independent_centering(model):
    """The centering force's total by cvxpy (Clarabel at gaps of 1e-11) on the model's
    scaled matrices, stated on the vertex forces ``(c, t, f1, f2)`` themselves (not the
    project's friction columns): newtons, and the reference weight."""
    import cvxpy as cp

    system = assemble(model.blocks, model.interfaces, mu=MU, density=2000.0,
                      **model.assembly)
    A = sp.csc_matrix(system.A_eq)
    free = len(system.free_block)
    x, s = cp.Variable(A.shape[1]), cp.Variable((free, 3))
    rows = (6 * np.arange(free)[:, None] + np.arange(3)).ravel()
    B = sp.csc_matrix((np.ones(3 * free), (rows, np.arange(3 * free))),
                      shape=(A.shape[0], 3 * free))
    problem = cp.Problem(cp.Minimize(cp.sum(cp.norm(s, 2, axis=1))), [
        A @ x + system.f_ext + B @ cp.reshape(s, (3 * free,), order="C") == 0,
        x[1::4] == 0, cp.SOC(system.mu * x[0::4], cp.vstack([x[2::4], x[3::4]]))])
    problem.solve(solver="CLARABEL", tol_gap_abs=1e-11, tol_gap_rel=1e-11,
                  tol_feas=1e-11, max_iter=500)
    assert problem.status == "optimal"
    return problem.value * system.weight_ref, system.weight_ref


@pytest.mark.parametrize("geometry", [dict(n=8, p=4, r=1),
                                      dict(n=6, p=3, r=2, stretch=1.5)])
def test_the_centering_force_of_a_free_web_is_the_independent_socps(geometry):
    """Free-standing webs that lean inward and tip (208 and 332 bricks): Clarabel's total
    within :data:`ACCURACY` of the reference weight of an independent SOCP's (docs/model.md
    6.10; at the collapse program's gaps of 1e-8 these were 1.7e-5 and 1.1e-4 apart),
    the interior point method's within :data:`INTERIOR_REL` of it."""
    model = build_model(validate(Params.of(boundary="free", **geometry)))[1]
    expected, weight_ref = independent_centering(model)
    ours, theirs = (centering_force(model, mu=MU, density=2000.0, solver=solver)
                    for solver in (INTERIOR, SOLVER))
    assert (ours.solver, theirs.solver) == (INTERIOR, SOLVER)
    assert ours.held_count > 0 and expected > 10 * weight_ref
    assert theirs.total_N == pytest.approx(expected, abs=ACCURACY * weight_ref)
    assert ours.total_N == pytest.approx(expected, rel=INTERIOR_REL)


# ---------------------------------------------------------------------- a run
def test_a_run_that_cannot_stand_reports_its_centering_force(tmp_path, capsys):
    """A closed arch thinner than its least thickness (t/R 0.08 < 0.1075): run.json's
    ``centering`` record, RBE/centering.csv (the forces summing to the total) and the
    printed line; a run that stands has none."""
    out = tmp_path / "out"
    assert main(["run", "--scene", "arch", "--thickness", "0.4", "--no-plots",
                 "--no-printable", "--out", str(out), "-q"]) == 0
    printed = capsys.readouterr().out
    (folder,) = out.glob("arch_*")
    record = json.loads((folder / "run.json").read_text())
    centering = record["centering"]
    assert record["rbe"]["verdict"] == "infeasible"
    assert centering["status"] == "optimal" and centering["point"] == "centroid"
    assert 0 < centering["fraction"] < 1
    assert centering["total_N"] == pytest.approx(centering["fraction"] * record["weight_N"])
    with open(folder / "RBE" / "centering.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == centering["held_count"] > 0
    assert list(rows[0]) == ["block", "name", "class", "course", "support_N", "force_x_N",
                             "force_y_N", "force_z_N"]
    sizes = [float(r["support_N"]) for r in rows]
    assert sizes == sorted(sizes, reverse=True)
    assert sum(sizes) == pytest.approx(centering["total_N"], rel=1e-3)
    assert rows[0]["name"] == centering["held"][0]["name"]
    assert "centering force: supports must give" in printed
    assert "centering force:" in (folder / "RBE" / "00_objective.txt").read_text()
    api = masonry.build(scene="arch", arch_thickness=0.4).centering()
    assert api.total_N == pytest.approx(centering["total_N"], rel=1e-9)
    assert main(["run", "--scene", "arch", "--no-plots", "--no-printable", "--out",
                 str(out), "-q"]) == 0
    (standing,) = [f for f in out.glob("arch_*") if f != folder]
    assert "centering" not in json.loads((standing / "run.json").read_text())
    assert not (standing / "RBE" / "centering.csv").exists()
