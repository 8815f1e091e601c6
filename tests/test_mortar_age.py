"""Construction stages with mortar whose strength grows with age (docs/model.md 6.13,
masonry/mortars.py): a constant mortar is the uniform contact law; a joint too young to
hold at a fast laying rate holds at a slower one, at the threshold age computed by hand
from the block's least adhesion and the mortar's table; bad tables and options are
refused in one line.

The slope is ``incline``'s (tests/test_rbe.py, tests/test_adhesion.py): a 1.0 x 0.2 x 0.1
m block on a slab tilted by ``alpha``, ``p = W / A = 1962 Pa``; along the slope it holds
while ``p sin(alpha) <= mu p cos(alpha) + c``, so it needs ``a* = p (sin(alpha) - mu
cos(alpha))`` of cohesion (no tension).
"""

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest
from test_rbe import SUPPORT, box, make_interfaces, rot_y
from test_stage_adhesion import ARCH

from masonry import read_table
from masonry.blocks import Blocks
from masonry.contact import ContactLaw, ContactLawError
from masonry.mortars import MORTARS, Mortar, MortarError
from masonry.rbe.boundary import Model, analysis_model, restrict
from masonry.rbe.solve import solve_rbe
from masonry.scenes import build
from masonry.rbe.sequence import StageSequence
from masonry.stages.analysis import analyse_stage, analyse_stages
from masonry.stages.laying import Laying
from masonry.stages.plans import StagePlan, make_plan
from masonry_cli.main import main

MU = 0.7
P_BED = 2000.0 * 9.81 * 0.1  # Pa: the incline block's weight over its bed
NEEDED_KPA = 0.15
"""The cohesion the slope block needs: alpha is chosen so that p (sin a - mu cos a) =
0.15 kPa."""


def _alpha(needed_kpa) -> float:
    """sin a - mu cos a = q  <=>  sqrt(1 + mu^2) sin(a - atan mu) = q."""
    return np.arctan(MU) + np.arcsin(1e3 * needed_kpa / (P_BED * np.hypot(1.0, MU)))


def slope_and_flat():
    """The slope block (block 1, laid at stage 1) and a block lying flat on a second slab
    (block 3, laid at stage 2, standing dry): stage 2 takes one brick's time, which ages
    the slope's joint."""
    rotation = rot_y(_alpha(NEEDED_KPA))  # as incline() builds it
    tilted = box((-2, -2, -0.1), (2, 2, 0)) @ rotation.T
    slope = box((0, 0, 0), (1.0, 0.2, 0.1)) @ rotation.T
    slab = box((4, -1, -0.1), (6, 1, 0))
    flat = box((4.5, 0, 0), (5.5, 0.2, 0.1))
    blocks = Blocks.from_hexahedra([tilted, slope, slab, flat],
                                   block_class=["ground", "block"] * 2,
                                   block_is_support=[True, False, True, False])
    joints = make_interfaces([(0, 1), (2, 3)], [slope[[0, 1, 3, 2]], flat[[0, 1, 3, 2]]],
                             [rotation[:, 2], (0, 0, 1)], [SUPPORT, SUPPORT])
    plan = StagePlan(np.array([0, 1, 0, 2]), np.zeros(2, int), "block", "names")
    return Model(blocks, joints), plan


RAMP = Mortar.of_table("ramp", [(0.0, 0.0, 0.0), (1.0, 0.3, 0.15)])
"""c(age) = 0.3 kPa x age / 1 h up to an hour: it reaches the slope's 0.15 kPa at 0.5 h."""


@pytest.mark.parametrize("rate, stands", [(1.0, True), (1.9, True), (2.1, False),
                                          (4.0, False)])
def test_the_slope_joint_holds_once_it_is_old_enough(rate, stands):
    """Stage 1 lays the slope block: its joint is 0 h old, c = 0 < 0.15 kPa, it slides.
    Stage 2 lays one brick: at ``rate`` bricks per hour the joint is 1/rate h old, c =
    0.3/rate kPa, which holds iff 0.3/rate >= 0.15, rate <= 2 bricks per hour (the
    threshold age 0.5 h). Both paths: the sequence and each stage alone."""
    model, plan = slope_and_flat()
    laying = Laying.of(RAMP, rate)
    for sequence in (None, StageSequence(model)):
        rows = [analyse_stage(model, ARCH, plan, stage, sequence, laying)
                for stage in (1, 2)]
        assert rows[0]["feasible"] is False
        assert rows[1]["feasible"] is stands, (rate, sequence)
        assert rows[1]["time_h"] == pytest.approx(2.0 / rate, rel=1e-12)
        # the slope needs 0.15 kPa and half of it in tension: the ramp reaches both at
        # 0.5 h, the longest its block must be held whatever the rate
        assert rows[0]["hold_h"] == pytest.approx(0.5, rel=1e-5)  # a*'s precision
        # the least adhesion is the stage's own, whatever the mortar
        assert rows[0]["adhesion_kPa"] == pytest.approx(NEEDED_KPA, rel=1e-5)
        # the least force at the centroid that puts the weight W = p A back on the
        # cone's edge: W sin(alpha - atan mu) = A a* / sqrt(1 + mu^2), at c = 0
        assert rows[0]["centering_N"] == pytest.approx(
            1e3 * NEEDED_KPA * 0.2 / np.hypot(1.0, MU), rel=1e-4)



@pytest.mark.parametrize("rate, stands", [(1.4, True), (1.6, False)])
def test_a_joint_with_a_support_ages_at_its_share_of_the_mortar(rate, stands):
    """With --support-joint-ratio 0.75 the slope's joint (a joint with a support) holds
    0.75 x 0.3/rate kPa at stage 2, which reaches the 0.15 kPa it needs iff rate <= 1.5
    bricks per hour."""
    model, plan = slope_and_flat()
    params = dataclasses.replace(ARCH, analysis=dataclasses.replace(
        ARCH.analysis, support_joint_ratio=0.75))
    row = analyse_stage(model, params, plan, 2, None, Laying.of(RAMP, rate))
    assert row["feasible"] is stands

def test_the_named_lime_table_decides_the_slope_at_its_stated_threshold():
    """With lime (docs/model.md 6.13) c = 0.1 kPa when laid, 0.2 kPa at 1 h, linear
    between: 0.15 kPa at 0.5 h, so the slope holds at stage 2 at 1.9 bricks per hour
    (0.526 h) and not at 2.1 (0.476 h)."""
    lime = MORTARS["lime"]
    assert lime.strength_kPa(0.5)[0] == pytest.approx(0.15, rel=1e-12)
    model, plan = slope_and_flat()
    for rate, stands in ((1.9, True), (2.1, False)):
        row = analyse_stage(model, ARCH, plan, 2, None, Laying.of(lime, rate))
        assert row["feasible"] is stands


@pytest.fixture(scope="module")
def arch():
    scene = build(ARCH)
    model = analysis_model(scene, ARCH.analysis.boundary)
    return model, make_plan(scene, "block", "z")


def test_a_constant_mortar_is_the_uniform_contact_law(arch):
    """--mortar constant with c = 100 kPa, t_c = 50 kPa at every age: each stage's
    verdict and MoI are those of the RBE of that stage's model with the uniform law
    (solved alone, from scratch); the sequence's warm starts, local certificate and
    local centering force do not change them. (The default arch's stages 3 to 7 need
    7 to 1018 kPa dry, tests/test_stage_adhesion.py: 100 kPa holds some, not all.)"""
    model, plan = arch
    laying = Laying.of(Mortar.constant(100.0, 50.0), rate_per_hour=60.0)
    rows = analyse_stages(model, ARCH, plan, laying=laying)
    verdicts = []
    for row in rows:
        part = restrict(model, plan.is_present(row["stage"]))
        alone = solve_rbe(part.blocks, part.interfaces, side_block=part.side_block,
                          side_rotation=part.side_rotation, mu=MU, density=2000.0,
                          cohesion=1e5, tensile=5e4)
        assert row["feasible"] == alone.feasible, row["stage"]
        if not alone.feasible:
            assert row["moi_factor"] == pytest.approx(alone.moi_factor, rel=1e-3)
        verdicts.append(alone.feasible)
    # the case decides something: 100 kPa holds some of stages 3 to 7 and not others
    assert 0 < sum(verdicts[2:7]) < len(verdicts[2:7])


def test_per_vertex_strengths_equal_to_a_uniform_one_give_its_system():
    """The per-vertex law with every vertex at c, t_c shifts f_ext and bounds the
    compressions exactly as the uniform law does."""
    model, _ = slope_and_flat()
    sequence = StageSequence(model)
    whole = sequence.whole
    count = whole.layout.n_vertices
    uniform = whole.with_material(cohesion=300.0, tensile=100.0)
    per_vertex = whole.with_material(cohesion=np.full(count, 300.0),
                                     tensile=np.full(count, 100.0))
    assert np.array_equal(uniform.f_ext, per_vertex.f_ext)
    assert np.array_equal(uniform.lower, per_vertex.lower)
    assert "per joint" in per_vertex.law.describe()


@pytest.mark.parametrize("rows, fault", [
    ([(0, 0.1, 0.05), (2, 0.3, 0.1), (1, 0.5, 0.2)], "row 3"),
    ([(0, 0.2, 0.1), (1, 0.1, 0.1)], "row 2"),
    ([(0, -0.1, 0.0)], "row 1"),
    ([(0, float("nan"), 0.0)], "row 1"),
    ([(1, 0.1, 0.0)], "row 1"),
])
def test_a_table_out_of_order_is_refused_in_one_line_naming_it(rows, fault):
    with pytest.raises(MortarError) as error:
        Mortar.of_table("bad", rows)
    message = str(error.value)
    assert "'bad'" in message and fault in message and "\n" not in message


def test_negative_per_vertex_strengths_are_refused():
    with pytest.raises(ContactLawError, match="cohesion_Pa per vertex"):
        ContactLaw.of("circle", 0.7, np.array([1.0, -1.0]), 0.0)


def test_the_named_mortars_grow_and_a_laying_needs_a_rate():
    for mortar in MORTARS.values():
        assert np.all(np.diff(mortar.cohesion_kPa) >= 0) and mortar.source
    with pytest.raises(MortarError, match="laying rate"):
        Laying.of(MORTARS["lime"])


@pytest.mark.parametrize("argv, option", [
    (["--mortar", "lime"], "--laying-rate"),
    (["--mortar", "lime", "--laying-rate", "-3"], "--laying-rate -3"),
    (["--mortar", "lime", "--laying-rate", "60", "--masons", "0"], "--masons 0"),
    (["--laying-rate", "60"], "--laying-rate 60"),
    (["--mortar", "lime", "--laying-rate", "60", "--cohesion-kpa", "5"], "--cohesion-kpa 5"),
    (["--mortar", "cement"], "--mortar"),
])
def test_bad_mortar_options_are_one_line_and_exit_2(tmp_path, capsys, argv, option):
    out = tmp_path / "out"
    try:
        code = main(["stages", "--scene", "arch", "--out", str(out), *argv])
    except SystemExit as stop:  # argparse's refusal of a choice
        code = stop.code
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and option in err[0], err
    assert not out.exists() or not any(out.iterdir())


def test_the_cli_names_the_mortar_and_the_rate(tmp_path, capsys):
    """The arch laid with gypsum at 600 bricks per hour: the summary line, the law in
    run.json and the stages' hours (two voussoirs a stage: 1/300 h each)."""
    code = main(["stages", "--scene", "arch", "--mortar", "gypsum", "--laying-rate", "600",
                 "--no-plots", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0
    assert "with gypsum mortar at 600 bricks per hour (1 mason): " in out
    (folder,) = tmp_path.glob("*_stages_z_gypsum600")
    record = json.loads((folder / "run.json").read_text())
    assert record["mortar"]["rate_bricks_per_hour"] == 600
    assert record["mortar"]["law"].startswith("Coulomb circle, mu 0.7, per joint by its age")
    table = read_table(folder / "stages.csv")
    assert np.allclose(table["time_h"], np.arange(1, 9) * 2 / 600, rtol=1e-9)
    # the hold: gypsum's table inverted at each stage's least adhesion (or never, past
    # its last row's 300 kPa), independently of the code's own inversion
    for a, hold in zip(table["adhesion_kPa"], table["hold_h"]):
        if a > 300:
            assert pd.isna(hold)
        else:
            expected = np.interp(a, MORTARS["gypsum"].cohesion_kPa, MORTARS["gypsum"].hours)
            assert hold == pytest.approx(expected if a > 0.1 else 0.0, rel=1e-9, abs=1e-12)
    never = int(table["stage"][table["adhesion_kPa"] > 300].min())
    assert record["mortar"]["hold_never_stage"] == never
    assert f"gypsum mortar never holds the least adhesion of stage {never}" in out


def test_the_law_line_of_a_mortar_by_age_names_the_joint_kinds():
    """With --head-joint-ratio 0.5 the one-line law of a stage study with lime says so,
    as the uniform law's does; without ratios it ends with the mortar."""
    from masonry.stages.records import law_line

    laying = Laying.of(MORTARS["lime"], 60.0)
    halved = dataclasses.replace(ARCH, analysis=dataclasses.replace(
        ARCH.analysis, head_joint_ratio=0.5))
    assert law_line(halved, laying).endswith(
        "at bed joints; head joints x0.5, joints with a support x1")
    assert law_line(ARCH, laying).endswith(MORTARS["lime"].describe())



@pytest.mark.parametrize("adhesion, ratio, hours", [
    (0.15, 0.5, 0.5), (0.05, 0.5, 0.0), (200.0, 0.5, None), (0.3, 2.0, 4 + 20 * 0.35 / 0.75),
    (None, 0.5, None)])
def test_the_age_a_mortar_holds_an_adhesion_from(adhesion, ratio, hours):
    """Lime's table by hand: 0.15 kPa and 0.075 in tension at 0.5 h (both halfway from
    0.1/0.05 to 0.2/0.1); 0.05 kPa when laid; 200 kPa never (100 at 28 days); at ratio 2
    the tension decides: 0.6 kPa between 0.25 at 4 h and 1 at 24 h."""
    held = MORTARS["lime"].hours_to_hold(adhesion, ratio)
    assert held == (None if hours is None else pytest.approx(hours, rel=1e-12, abs=1e-15))
