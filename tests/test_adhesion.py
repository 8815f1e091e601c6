"""The least adhesion (docs/model.md 6.12, masonry/rbe/adhesion.py): the least uniform
``a`` with which a structure stands, cohesion ``c = a`` and tensile strength ``t_c = r
a``, against statics by hand and against the RBE solved with that contact law.

The block on a slope is ``incline``'s (tests/test_rbe.py): 1.0 x 0.2 x 0.1 m, density
2000 kg/m^3, weight ``W = 392.4 N`` on a bed of ``A = 0.2 m^2``, ``p = W / A = 1962 Pa``.
The cantilever is ``cantilever``'s: a 1.0 x 0.5 x 0.2 m block (``W = 1962 N``, centroid
at x = 0.5) on a support reaching to x = 0.3, its bed's four vertices each of tributary
area ``A_i = 0.3 x 0.5 / 4 = 0.0375 m^2``.
"""

import dataclasses
import json

import numpy as np
import pytest
from test_friction import tilted_block
from test_rbe import cantilever, incline

import masonry
from masonry.interfaces import INTERFACE_KINDS
from masonry.rbe.adhesion import AdhesionRatioError, least_adhesion
from masonry.rbe.boundary import Model
from masonry.rbe.settings import Analysis
from masonry.rbe.solve import solve_rbe
from masonry.studies.sweep import run_summary
from masonry_cli.main import main

MU = 0.7
DENSITY = 2000.0


def weight(blocks):
    """The free block's weight, N."""
    return DENSITY * 9.81 * blocks.block_volume[1]


@pytest.mark.parametrize("cone", ["circle", "polygon:16", "square"])
@pytest.mark.parametrize("degrees", [30.0, 40.0, 55.0])
def test_a_block_on_a_slope_needs_the_cohesion_of_its_sliding_limit(cone, degrees):
    """Along the slope W sin a <= mu W cos a + a A: a* = p (sin a - mu cos a), p = W / A,
    and 0 below the friction angle (30 < 35 degrees). The slope falls along the joint's
    t2 axis, where the 16-sided pyramid's edge ray and the square's face lie at the
    cone's radius: the three models need the same. No tension is used."""
    alpha = np.radians(degrees)
    blocks, interfaces = incline(alpha, base=1.0, height=0.1)
    p = weight(blocks) / interfaces.area[0]
    needed = max(0.0, p * (np.sin(alpha) - MU * np.cos(alpha))) / 1e3
    result = least_adhesion(Model(blocks, interfaces), mu=MU, density=DENSITY, cone=cone)
    assert result.status == "optimal"
    assert result.a_kPa == pytest.approx(needed, rel=1e-6, abs=1e-9)
    assert result.residual_eq <= 1e-5 and result.law_violation <= 1e-5
    # the one joint uses a*
    assert result.interface_kPa[0] == pytest.approx(needed, rel=1e-5, abs=1e-9)
    assert len(result.needing) == (1 if needed > 0 else 0)


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_a_cantilevered_block_is_held_by_tension_at_its_bed(ratio):
    """Moments about the bed's far edge (x = 0): the near vertices (x = 0.3) carry 5W/3,
    the far pair -2W/3, -W/3 each (the optimum is symmetric across y; an uneven split
    puts more on one of them). A vertex in tension holds while W/3 <= r a A_i and, with
    no friction, mu W/3 <= a A_i (the cone's apex): a* = W / (3 A_i) max(1/r, mu) = 34.88
    kPa at r = 0.5 (the cut-off), 12.21 kPa at r = 2 (the apex at c/mu, r > 1/mu)."""
    blocks, interfaces = cantilever()
    vertex_area = 0.3 * 0.5 / 4
    needed = weight(blocks) / (3 * vertex_area) * max(1 / ratio, MU) / 1e3
    result = least_adhesion(Model(blocks, interfaces), mu=MU, density=DENSITY, ratio=ratio)
    assert result.a_kPa == pytest.approx(needed, rel=1e-6)
    assert result.interface_kPa[0] == pytest.approx(needed, rel=1e-5)


def test_without_tension_a_cantilever_cannot_be_held_and_says_why():
    """r = 0: no joint carries tension, so no adhesion balances the overhang's moment:
    no value, and the reason."""
    blocks, interfaces = cantilever()
    result = least_adhesion(Model(blocks, interfaces), mu=MU, density=DENSITY, ratio=0.0)
    assert result.a_kPa is None
    assert "infeasible" in result.reason.lower()


def test_the_pyramids_bracket_the_cone():
    """At every a the inscribed 8-sided pyramid lies within Coulomb's cone, which lies
    within the square: the least adhesions are in the opposite order, and the circle's
    is p (sin a - mu cos a). The joint's frame is turned by 22.5 degrees about its
    normal, so the fall (along t2 as detected) lies on a face of the 8-sided pyramid
    (capacity cos(pi/8) of the cone's) and between the square's faces (more)."""
    alpha, turn = np.radians(50.0), np.radians(22.5)
    model = tilted_block(alpha, 0.0)
    frame = model.interfaces
    turned = dataclasses.replace(frame, t1=np.cos(turn) * frame.t1 + np.sin(turn) * frame.t2,
                                 t2=-np.sin(turn) * frame.t1 + np.cos(turn) * frame.t2)
    model = Model(model.blocks, turned)
    a = {cone: least_adhesion(model, mu=MU, density=DENSITY, cone=cone).a_kPa
         for cone in ("polygon:8", "circle", "square")}
    p = weight(model.blocks) / frame.area[0]
    assert a["circle"] == pytest.approx(p * (np.sin(alpha) - MU * np.cos(alpha)) / 1e3,
                                        rel=1e-6)
    assert a["polygon:8"] > a["circle"] * (1 + 1e-3)
    assert a["circle"] > a["square"] * (1 + 1e-3)


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_the_rbe_stands_just_above_the_least_adhesion_and_not_below(ratio):
    """An independent check through the RBE with the contact law: the cantilever with c
    = a*(1 + 1e-3), t_c = r c stands; with a*(1 - 1e-3) it does not. (At 1e-4 the
    deficit, 3e-5 W at a vertex, is within what the RBE's solvers accept as standing.)"""
    blocks, interfaces = cantilever()
    result = least_adhesion(Model(blocks, interfaces), mu=MU, density=DENSITY, ratio=ratio)
    for margin, verdict in ((1 + 1e-3, "feasible"), (1 - 1e-3, "infeasible")):
        law = result.law_at(margin)
        rbe = solve_rbe(blocks, interfaces, mu=MU, density=DENSITY,
                        cohesion=law.cohesion_Pa, tensile=law.tensile_Pa)
        assert rbe.verdict == verdict, margin


def test_a_bad_ratio_is_refused_by_the_api():
    blocks, interfaces = cantilever()
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(AdhesionRatioError, match="ratio"):
            least_adhesion(Model(blocks, interfaces), ratio=bad)


@pytest.mark.parametrize("value", ["-1", "nan", "inf"])
def test_a_bad_ratio_option_is_one_line_and_exit_2(tmp_path, capsys, value):
    out = tmp_path / "out"
    code = main(["run", "--scene", "arch", "--adhesion-tension-ratio", value, "--no-plots",
                 "--no-printable", "--out", str(out), "-q"])
    error = capsys.readouterr().err.strip()
    assert code == 2
    assert len(error.splitlines()) == 1 and "--adhesion-tension-ratio" in error
    assert not out.exists()


def test_a_run_reports_the_least_adhesion_beside_the_centering_force(tmp_path, capsys):
    """A closed arch thinner than its least thickness (t/R 0.08 < 0.1075) needs adhesion:
    run.json's ``adhesion``, RBE/adhesion.csv read back typed (the joints' largest use
    is a*), the printed line, the API's value and the summary column; re-solved through
    the RBE it stands at c = a*(1 + 1e-3) and not at a*(1 - 1e-3). An arch that stands
    needs 0."""
    out = tmp_path / "out"
    assert main(["run", "--scene", "arch", "--thickness", "0.4", "--no-plots",
                 "--no-printable", "--out", str(out), "-q"]) == 0
    printed = capsys.readouterr().out
    (folder,) = out.glob("arch_*")
    record = json.loads((folder / "run.json").read_text())
    adhesion = record["adhesion"]
    a = adhesion["a_kPa"]
    assert adhesion["status"] == "optimal" and a > 0 and adhesion["ratio"] == 0.5
    assert adhesion["residual_eq"] <= 1e-5
    table = masonry.read_table(folder / "RBE" / "adhesion.csv")
    assert str(table["interface"].dtype) == "Int64"
    assert set(table["kind"]) <= {"horizontal", "vertical", "support", "boundary"}
    assert table["adhesion_kPa"].max() == pytest.approx(a, rel=1e-4)
    top = adhesion["joints"][0]
    assert top["adhesion_kPa"] == pytest.approx(table["adhesion_kPa"].max())
    assert "least adhesion: mortar must hold" in printed
    assert " | ".join(top["blocks"]) in printed
    arch = masonry.build(scene="arch", arch_thickness=0.4)
    assert arch.least_adhesion().a_kPa == pytest.approx(a, rel=1e-6)
    assert run_summary({**record, "structure_id": "x"})["adhesion_kPa"] == a
    for margin, verdict in ((1 + 1e-3, "feasible"), (1 - 1e-3, "infeasible")):
        c = margin * a
        again = masonry.build(scene="arch", arch_thickness=0.4, cohesion_kpa=c,
                              tensile_kpa=0.5 * c)
        assert again.solve().verdict == verdict, margin
    assert main(["run", "--scene", "arch", "--no-plots", "--no-printable", "--out",
                 str(out), "-q"]) == 0
    (standing,) = [f for f in out.glob("arch_*") if f != folder]
    assert json.loads((standing / "run.json").read_text())["adhesion"]["a_kPa"] == 0.0
    assert "least adhesion: 0 kPa" in capsys.readouterr().out


@pytest.mark.parametrize("kind, head, support, share", [
    ("support", 1.0, 0.5, 0.5), ("vertical", 0.5, 1.0, 0.5), ("boundary", 0.25, 2.0, 0.25),
    ("horizontal", 0.5, 0.5, 1.0)])
def test_a_joint_kind_holds_its_share_of_the_bed_joints_adhesion(kind, head, support, share):
    """The block on a 55 degree slope with its one joint labelled ``kind``: that joint
    holds ``share`` times ``a`` (head joints, a joint between webs: ``head``; a joint with
    a support: ``support``; a bed joint: 1), so a* = p (sin a - mu cos a) / share, and the
    joint uses the same kilopascals as a bed joint would. The RBE with the run's contact
    law per joint (``law_on``) stands with bed cohesion a*(1 + 1e-3) and not a*(1 - 1e-3)."""
    alpha = np.radians(55.0)
    blocks, interfaces = incline(alpha, base=1.0, height=0.1)
    interfaces = dataclasses.replace(interfaces, kind=np.array(
        [INTERFACE_KINDS.index(kind)], dtype=np.int8))
    needed = weight(blocks) / interfaces.area[0] * (np.sin(alpha) - MU * np.cos(alpha)) / 1e3
    result = least_adhesion(Model(blocks, interfaces), mu=MU, density=DENSITY, ratio=0.0,
                            head_ratio=head, support_ratio=support)
    assert result.a_kPa == pytest.approx(needed / share, rel=1e-6)
    assert result.interface_kPa[0] == pytest.approx(needed, rel=1e-5)
    for margin, verdict in ((1 + 1e-3, "feasible"), (1 - 1e-3, "infeasible")):
        law = Analysis(cohesion_kpa=margin * result.a_kPa, head_joint_ratio=head,
                       support_joint_ratio=support).law_on(interfaces)
        rbe = solve_rbe(blocks, interfaces, mu=MU, density=DENSITY,
                        cohesion=law.cohesion_Pa, tensile=law.tensile_Pa)
        assert rbe.verdict == verdict, margin


@pytest.mark.parametrize("option, value", [("--head-joint-ratio", "1.5"),
                                           ("--head-joint-ratio", "-0.1"),
                                           ("--support-joint-ratio", "nan")])
def test_a_bad_joint_ratio_is_one_line_and_exit_2(tmp_path, capsys, option, value):
    out = tmp_path / "out"
    code = main(["run", "--scene", "arch", option, value, "--no-plots", "--no-printable",
                 "--out", str(out), "-q"])
    error = capsys.readouterr().err.strip()
    assert code == 2
    assert len(error.splitlines()) == 1 and option in error and value in error
    assert not out.exists()


def test_the_arch_needs_more_where_its_springings_hold_less(tmp_path):
    """The thin arch (t/R 0.08) with its joints on the supports at half the bed joints'
    strength needs a larger a*, and no joint uses more than its kind holds: the
    springings' joints at most a*/2. The run records the law in one line with the ratio."""
    arch = masonry.build(scene="arch", arch_thickness=0.4)
    weak = masonry.build(scene="arch", arch_thickness=0.4, support_joint_ratio=0.5)
    full, half = arch.least_adhesion(), weak.least_adhesion()
    assert half.a_kPa > full.a_kPa * (1 + 1e-3)
    on_support = half.interface_kind == INTERFACE_KINDS.index("support")
    assert on_support.any()
    assert half.interface_kPa[on_support].max() <= 0.5 * half.a_kPa * (1 + 1e-5)
    assert half.interface_kPa[~on_support].max() <= half.a_kPa * (1 + 1e-5)
    out = tmp_path / "out"
    assert main(["run", "--scene", "arch", "--cohesion-kpa", "1", "--support-joint-ratio",
                 "0.5", "--no-plots", "--no-printable", "--out", str(out), "-q"]) == 0
    (folder,) = out.glob("arch_*")
    assert "_sj0.5" in folder.name
    text = (folder / "00_parameters.txt").read_text()
    assert "at bed joints; head joints x1, joints with a support x0.5" in text


def test_a_cyclic_sections_joints_with_its_neighbours_are_named_in_run_json(tmp_path,
                                                                            monkeypatch):
    """On a cyclic section the least adhesion's joints are the model's, whose blocks past
    the section's are its neighbours' images (``w1_...``): run.json names both blocks of
    a joint with an image as the model does. Preset 1's section at p 30 (mu 0.7) needs
    such a joint most; here a small section's program is run, then the joint's share
    given to one image joint."""
    from masonry import pipeline

    solved = pipeline.adhesion_of

    def image_joint_needs_most(model, params, rbe=None):
        result = solved(model, params, rbe)
        k = int(np.flatnonzero(model.interfaces.pair.max(axis=1) >= n_section)[0])
        need = np.zeros(len(model.interfaces))
        need[k] = 1.0
        return dataclasses.replace(result, a_kPa=1.0, interface_kPa=need)

    n_section = masonry.build(1, p=4).scene.blocks.n_blocks
    monkeypatch.setattr(pipeline, "adhesion_of", image_joint_needs_most)
    assert main(["run", "--p", "4", "--mu", "0.1", "--no-plots", "--no-printable",
                 "--no-html", "--out", str(tmp_path), "-q"]) == 0
    record = json.loads(next(tmp_path.glob("*/run.json")).read_text())
    model = masonry.build(1, p=4).model
    [joint] = record["adhesion"]["joints"]
    pair = model.interfaces.pair[joint["interface"]]
    assert joint["blocks"] == [str(model.blocks.block_name[b]) for b in pair]
    assert any(name.startswith("w1_") for name in joint["blocks"])
