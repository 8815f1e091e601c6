"""The mortar where a user meets it (docs/cli.md, docs/stages.md): study files that sweep
the strengths and a stage study's mortar by age, a parameter file's ``[mortar]``, the
Python API's stages, ``masonry optimize --minimize adhesion_max_kPa`` over pattern
inputs, and a lateral load on joints with mortar; bad values are one line naming the key.

The arch is the default one (tests/test_stages.py): laid block by block from the
springings, two voussoirs a stage, its stages 1, 2 and 8 stand dry and 3 to 7 need
support (their least adhesion grows as the two half arches lengthen).
"""

import json

import numpy as np
import pytest

import masonry
from masonry.errors import ParameterError
from masonry_cli.main import main

ARCH_STAGE = 2
"""Voussoirs the default arch lays per stage (one on each side)."""

DRY_STANDING = 3
"""Stages of the default arch that stand with dry joints (1, 2 and 8)."""


def _sweep(study, out):
    return main(["sweep", str(study), "--workers", "1", "--out", str(out), "-q"])


def _stage_folder(out, suffix):
    (folder,) = out.glob(f"*_stages_z{suffix}")
    return folder


@pytest.fixture(scope="module")
def arch():
    return masonry.build(scene="arch")


@pytest.fixture(scope="module")
def arch_adhesion(arch):
    """The least adhesion over the dry arch's stages (kPa), by the API."""
    return float(arch.stages(by="block")["adhesion_kPa"].max())


# ------------------------------------------------------------------------ study files
def test_a_study_sweeps_the_cohesion_of_its_stages_up_to_the_least_adhesion(
        tmp_path, arch_adhesion):
    """The least adhesion a* of every stage is the uniform mortar (c = a, t_c = 0.5 a)
    it stands with (docs/model.md 6.12): a study with cohesion 1.01 a* and tension
    0.5 x that ([mortar]) has every stage standing, dry joints only the three that stand
    dry; a* itself does not depend on the strengths given, so both variants report it."""
    a = 1.01 * arch_adhesion
    study = tmp_path / "cohesion.toml"
    study.write_text(f'[base]\nscene = "arch"\n[grid]\ncohesion_kpa = [0.0, {a!r}]\n'
                     f'[mortar]\ntensile_kpa = {0.5 * a!r}\n[outputs]\nstages = "block"\n')
    assert _sweep(study, tmp_path / "out") == 0
    table = masonry.read_table(tmp_path / "out" / "sweep_cohesion" / "summary.csv")
    # t_c without cohesion is cut off at the cone's apex: the first variant is dry
    assert list(table["stages_standing"]) == [DRY_STANDING, 8]
    assert np.allclose(table["adhesion_max_kPa"], arch_adhesion, rtol=1e-6)


def test_a_study_sweeps_the_laying_rate_of_a_mortar_that_ages(tmp_path):
    """Gypsum at 6, 600 and 60,000 voussoirs an hour: each variant's stage study is
    laid at its rate (its folder, stage k ends at 2k / rate hours), and a slower rate
    leaves every joint older, so stronger (the table does not decrease): at least as
    many stages stand, more at the slowest (stage 3 holds on joints a third of an hour
    old)."""
    rates = [6.0, 600.0, 60000.0]
    study = tmp_path / "rates.toml"
    study.write_text(f'[base]\nscene = "arch"\n[grid]\nlaying_rate = {rates!r}\n'
                     '[mortar]\nmortar = "gypsum"\n[outputs]\nstages = "block"\n')
    out = tmp_path / "out"
    assert _sweep(study, out) == 0
    table = masonry.read_table(out / "sweep_rates" / "summary.csv")
    assert list(table["laying_rate"]) == rates
    standing = list(table["stages_standing"])
    assert standing[0] > standing[1] >= standing[2] >= DRY_STANDING, standing
    for rate, count in zip(rates, standing):
        stages = masonry.read_table(_stage_folder(out, f"_gypsum{rate:g}") / "stages.csv")
        assert np.allclose(stages["time_h"], np.arange(1, 9) * ARCH_STAGE / rate, rtol=1e-9)
        assert stages["feasible"].sum() == count


def test_a_study_sweeps_the_mortar_and_the_masons_and_reads_back_typed(tmp_path):
    """The per joint kind strengths of [mortar] reach every variant's stage study (its
    folder and its record)."""
    study = tmp_path / "crews.toml"
    study.write_text('[base]\nscene = "arch"\nlaying_rate = 600\n[grid]\n'
                     'mortar = ["lime", "gypsum"]\nmasons = [1, 2]\n'
                     '[mortar]\nsupport_joint_ratio = 0.5\nhead_joint_ratio = 0.25\n'
                     '[outputs]\nstages = "block"\n')
    out = tmp_path / "out"
    assert _sweep(study, out) == 0
    table = masonry.read_table(out / "sweep_crews" / "summary.csv")
    assert list(table["mortar"]) == ["lime", "lime", "gypsum", "gypsum"]
    assert str(table["masons"].dtype) == "Int64" and list(table["masons"]) == [1, 2, 1, 2]
    assert (table["status"] == "computed").all()
    # two masons lay the same stage in half the time
    folder = _stage_folder(out, "_lime600x2")
    assert "_hj0.25_sj0.5_" in folder.name
    params = json.loads((folder / "run.json").read_text())["params"]
    assert (params["head_joint_ratio"], params["support_joint_ratio"]) == (0.25, 0.5)
    stages = masonry.read_table(folder / "stages.csv")
    assert np.allclose(stages["time_h"], np.arange(1, 9) * ARCH_STAGE / 1200, rtol=1e-9)


STAGES = '[outputs]\nstages = "block"\n'


@pytest.mark.parametrize("tables, shown", [
    ('[base]\nmortar = "lime"\n[grid]\nlaying_rate = [30.0, -1.0]\n' + STAGES,
     "grid.laying-rate = -1.0"),
    ('[base]\nmortar = "lime"\nlaying_rate = 60\n[grid]\nmasons = [1, 0]\n' + STAGES,
     "grid.masons = 0"),
    ('[base]\nlaying_rate = 60\n[grid]\nmortar = ["lime", "cement"]\n' + STAGES,
     "grid.mortar = 'cement'"),
    ('[grid]\nmu = [0.7]\n[mortar]\nmortar = "lime"\nlaying_rate = 60\n',
     "mortar.mortar = 'lime': expected [outputs] stages beside it"),
    ('[grid]\nlaying_rate = [60]\n', "grid.laying_rate = [60]: expected [outputs] stages"),
    ('[grid]\nmu = [0.7]\n[mortar]\ncohesion_kpa = -1\n', "mortar.cohesion_kpa = -1"),
    ('[grid]\nmu = [0.7]\n[mortar]\nage = 3\n', "mortar.age = 3"),
    ('[grid]\nmu = [0.7]\n[mortar]\nhead_joint_ratio = 2\n', "mortar.head_joint_ratio = 2"),
    ('[grid]\nmu = [0.7]\n[mortar]\ncohesion_kpa = [1, 2]\n', "mortar.cohesion_kpa"),
    ('[base]\ncohesion_kpa = 1\n[grid]\nmu = [0.7]\n[mortar]\ncohesion_kpa = 2\n',
     "in [mortar] or in [base]"),
    ('[grid]\nmu = [0.7]\n[mortar]\nmortar = "lime"\nlaying_rate = 60\ncohesion_kpa = 1\n'
     + STAGES, "mortar.cohesion_kpa = 1: expected 0 with --mortar lime"),
])
def test_bad_mortar_in_a_study_is_one_line_naming_the_key(tmp_path, capsys, tables, shown):
    study = tmp_path / "bad.toml"
    study.write_text('[base]\nscene = "arch"\n' + tables.removeprefix("[base]\n"))
    out = tmp_path / "out"
    assert _sweep(study, out) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and shown in error[0] and "bad.toml" in error[0], error
    assert not out.exists()


# ---------------------------------------------------------------- a parameter file
def test_a_parameter_file_gives_the_stages_their_mortar_by_age(tmp_path, capsys):
    params = tmp_path / "arch.toml"
    params.write_text('scene = "arch"\n[mortar]\nmortar = "gypsum"\nlaying_rate = 600\n'
                      'masons = 2\n')
    out = tmp_path / "out"
    assert main(["stages", "--params", str(params), "--no-plots", "--out", str(out),
                 "-q"]) == 0
    stages = masonry.read_table(_stage_folder(out, "_gypsum600x2") / "stages.csv")
    assert np.allclose(stages["time_h"], np.arange(1, 9) * ARCH_STAGE / 1200, rtol=1e-9)
    # an option given wins over the file
    assert main(["stages", "--params", str(params), "--laying-rate", "6", "--masons", "1",
                 "--no-plots", "--out", str(out), "-q"]) == 0
    stages = masonry.read_table(_stage_folder(out, "_gypsum6") / "stages.csv")
    assert np.allclose(stages["time_h"], np.arange(1, 9) * ARCH_STAGE / 6, rtol=1e-9)
    capsys.readouterr()


@pytest.mark.parametrize("command, mortar, shown", [
    ("run", 'mortar = "lime"\nlaying_rate = 60\n', "mortar = 'lime': expected none for "
                                                   "masonry run"),
    ("stages", 'mortar = "lime"\nlaying_rate = 60\nmasons = 0\n', "masons = 0"),
    ("stages", 'mortar = "lime"\nlaying_rate = -5\n', "laying_rate = -5"),
    ("stages", 'mortar = "cement"\n', "mortar = 'cement'"),
    ("stages", 'age = 1\n', "age = 1"),
])
def test_bad_mortar_in_a_parameter_file_is_one_line_naming_the_key(tmp_path, capsys,
                                                                   command, mortar, shown):
    params = tmp_path / "arch.toml"
    params.write_text('scene = "arch"\n[mortar]\n' + mortar)
    out = tmp_path / "out"
    assert main([command, "--params", str(params), "--no-plots", "--out", str(out)]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and shown in error[0] and "arch.toml" in error[0], error
    assert not out.exists()


# ------------------------------------------------------------------------ the API
def test_the_api_s_stages_with_mortar_are_the_command_line_s(tmp_path, arch):
    """Structure.stages with a mortar by age gives the numbers of ``masonry stages``'s
    stages.csv (1e-9) on the same arch: verdicts, centering forces, least adhesion and
    the hours, stage k ending at 2k / (rate x masons)."""
    assert main(["stages", "--scene", "arch", "--mortar", "gypsum", "--laying-rate", "3",
                 "--masons", "2", "--no-plots", "--out", str(tmp_path), "-q"]) == 0
    written = masonry.read_table(_stage_folder(tmp_path, "_gypsum3x2") / "stages.csv")
    frame = arch.stages(by="block", mortar="gypsum", laying_rate=3, masons=2)
    assert list(frame["feasible"]) == list(written["feasible"])
    for column in ("centering_N", "adhesion_kPa", "time_h"):
        assert np.allclose(frame[column].astype(float), written[column], rtol=1e-9,
                           atol=1e-9, equal_nan=True), column
    assert np.allclose(frame["time_h"].astype(float), np.arange(1, 9) * ARCH_STAGE / 6,
                       rtol=1e-9)
    # laid slowly, the gypsum of stage 3's joints (20 minutes old) holds it
    assert frame["feasible"].sum() > DRY_STANDING


@pytest.mark.parametrize("kwargs, name", [
    (dict(mortar="cement"), "mortar"), (dict(mortar="lime"), "laying_rate"),
    (dict(mortar="lime", laying_rate=-1.0), "laying_rate"),
    (dict(mortar="lime", laying_rate=float("nan")), "laying_rate"),
    (dict(mortar="lime", laying_rate=60, masons=0), "masons"),
    (dict(mortar="lime", laying_rate=60, masons=1.5), "masons"),
    (dict(laying_rate=60), "laying_rate"), (dict(masons=2), "masons"),
])
def test_the_api_refuses_a_bad_mortar_naming_the_argument(arch, kwargs, name):
    with pytest.raises(ParameterError) as refused:
        arch.stages(by="block", **kwargs)
    assert refused.value.name == name


def test_the_api_refuses_a_mortar_that_ages_beside_the_analysis_s_strengths():
    with pytest.raises(ParameterError) as refused:
        masonry.build(scene="arch", cohesion_kpa=1.0).stages(
            by="block", mortar="lime", laying_rate=60)
    assert refused.value.name == "cohesion_kpa"


# ---------------------------------------------------------------- optimize
@pytest.mark.slow
def test_optimize_minimizes_the_least_adhesion_over_pattern_inputs(tmp_path):
    """A small dome's course stages at mu 0.1 over its pattern (herringbone or none) and
    its p (2 or 3): each trial's ``adhesion_max_kPa`` is the largest of its stage
    study's ``adhesion_kPa``; the best trial holds the least of them; the herringbone at
    p 2 cannot be built (its courses meet in wedges), a failed trial that says why."""
    pytest.importorskip("optuna")
    study = tmp_path / "pattern.toml"
    study.write_text('[base]\npreset = 1\nn = 4\nr = 1\nmu = 0.1\n'
                     '[grid]\npattern = ["herringbone", "none"]\np = [2, 3]\n'
                     '[outputs]\nstages = "course"\n')
    out = tmp_path / "out"
    assert main(["optimize", str(study), "--minimize", "adhesion_max_kPa", "--trials", "4",
                 "--workers", "1", "--no-plots", "--out", str(out), "-q"]) == 0
    trials = masonry.read_table(out / "optimize_pattern" / "trials.csv")
    assert len(trials) == 4
    failed = trials[trials["status"] == "failed"]
    assert list(zip(failed["pattern"], failed["p"])) == [("herringbone", 2)]
    assert "wedges" in failed["error"].iloc[0]
    done = trials[trials["status"] != "failed"]
    for _, trial in done.iterrows():
        suffix = "" if trial["pattern"] == "herringbone" else "_patnone"
        folder = (f"dome1_fast0_fricauto_s1_n4_r1_p{int(trial['p'])}_c0.1_u0.1{suffix}"
                  f"_mu0.1_stages_course")  # the section laid cyclic
        stages = masonry.read_table(out / folder / "stages.csv")
        assert trial["adhesion_max_kPa"] == pytest.approx(stages["adhesion_kPa"].max(),
                                                          rel=1e-9)
    best = trials[trials["best"].astype(bool)]
    assert len(best) == 1
    assert best["adhesion_max_kPa"].iloc[0] == done["adhesion_max_kPa"].min()


# ---------------------------------------------------------------- lateral load
BLOCK = (0.4, 0.4, 0.1)
"""A squat block (m): sliding at lambda = mu + c A / W comes long before tipping at b/h
= 4."""


def _block_obj(path):
    corners = np.array([[x, y, z] for x in (-0.2, 0.2) for y in (-0.2, 0.2)
                        for z in (0.0, 0.1)])
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5),
             (2, 6, 8, 4)]
    path.write_text("o block\n" + "".join(f"v {x:g} {y:g} {z:g}\n" for x, y, z in corners)
                    + "".join("f " + " ".join(map(str, f)) + "\n" for f in faces))
    return path


@pytest.mark.parametrize("lateral", ["90", "all"])
def test_a_block_on_a_bed_with_cohesion_slides_at_mu_plus_c_a_over_w(tmp_path, lateral):
    """A 0.4 x 0.4 x 0.1 m block on the ground slab pushed by lambda W sideways:
    sliding along the bed resists mu W + c A (the associated flow lifts the block by
    mu per unit slip, and the shifted cone's face dissipates exactly c A), so
    lambda = mu + c A / W, here 0.7 + 0.5 = 1.2 with c = p / 2 (p = W / A = 1962 Pa);
    tipping needs b / h = 4. The bed is a square on Coulomb's circle: every azimuth
    gives the same, and so does the search over them."""
    weight = 2000.0 * 9.81 * float(np.prod(BLOCK))
    area = BLOCK[0] * BLOCK[1]
    cohesion_kpa = 0.5 * weight / area / 1e3
    out = tmp_path / "out"
    assert main(["analyze", str(_block_obj(tmp_path / "block.obj")), "--ground",
                 "--lateral", lateral, "--cohesion-kpa", f"{cohesion_kpa!r}",
                 "--tensile-kpa", "0.5", "--no-plots", "--no-printable", "--no-html",
                 "--out", str(out), "-q"]) == 0
    (record,) = [json.loads(p.read_text()) for p in out.glob("*/run.json")]
    assert record["weight_N"] == pytest.approx(weight, rel=1e-12)
    assert record["collapse"]["load_factor"] == pytest.approx(
        0.7 + cohesion_kpa * 1e3 * area / weight, abs=1e-6)


def test_the_arch_s_lateral_load_factor_grows_with_the_cohesion(arch):
    """More cohesion enlarges every joint's strength set, so the collapse load factor
    (the least over mechanisms of a dissipation that grows with c) does not decrease;
    with mortar it is above the dry one."""
    factors = [masonry.build(scene="arch", lateral=0, cohesion_kpa=c,
                             tensile_kpa=0.5 * c).collapse().load_factor
               for c in (0.0, 1.0, 5.0, 20.0)]
    assert all(b >= a - 1e-9 for a, b in zip(factors, factors[1:])), factors
    assert factors[-1] > factors[0] + 1e-3, factors
