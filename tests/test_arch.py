"""The arch scene and its minimum thickness (docs/model.md 8): RBE bisection against the
thrust line."""

import csv
import json

import numpy as np
import pytest
import shapely

from masonry.scenes.arch import arch_profile, build_arch
from masonry.studies.thrust_line import thrust_line_minimum_thickness
from masonry.interfaces import detect
from masonry.params import ParameterError, Params, validate
from masonry.studies.thickness import minimum_thickness
from masonry_cli.main import main

MILANKOVITCH = 0.1075  # t/R of the continuous semicircular arch under self weight

# Minimum t/R of semicircular arches of N chord voussoirs (mu = 10, sliding never
# governs), from the thrust line (masonry.studies.thrust_line.thrust_line_minimum_thickness) to 1e-12;
# the RBE bisection brackets the same numbers (test below).
THRUST_LINE = {16: 0.1070762, 32: 0.1071970, 64: 0.1073832}


def arch_params(**changes):
    return validate(Params.of(scene="arch", **changes))


@pytest.mark.parametrize("shape, n", [("semicircular", 16), ("semicircular", 7),
                                      ("segmental", 9), ("pointed", 10)])
def test_arch_geometry_and_joints(shape, n):
    params = arch_params(arch_shape=shape, arch_blocks=n, arch_thickness=0.5)
    scene = build_arch(params.geometry)
    blocks = scene.blocks
    assert blocks.n_blocks == n + 2 and blocks.block_is_support.sum() == 2
    profile = arch_profile(shape, n, params.geometry.arch_span, 0.5)
    area = shapely.area(shapely.polygons(profile.voussoirs))
    np.testing.assert_allclose(blocks.block_volume[2:], area * params.geometry.arch_depth,
                               rtol=1e-12)
    # every joint is a whole rectangle, t x depth (the vertical crown joint of a pointed
    # arch is longer); the joints between voussoirs are bed joints, however steep
    interfaces = detect(blocks, up=scene.block_up)
    assert len(interfaces) == n + 1
    length = np.linalg.norm(profile.extrados - profile.intrados, axis=1)
    assert (~np.isclose(length, 0.5, rtol=1e-12)).sum() == (shape == "pointed")
    np.testing.assert_allclose(np.sort(interfaces.area),
                               np.sort(length) * params.geometry.arch_depth, rtol=1e-9)
    assert interfaces.counts()["horizontal"] == n - 1
    assert interfaces.counts()["support"] == 2
    # the centre line's span and rise
    mid = (profile.intrados + profile.extrados) / 2
    assert mid[0, 0] == pytest.approx(params.geometry.arch_span / 2)
    assert mid[:, 1].min() == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(mid[::-1] * [-1, 1], mid)  # symmetric


@pytest.mark.parametrize("changes, name", [
    ({"arch_shape": "pointed", "arch_blocks": 7}, "arch_blocks"),
    ({"arch_shape": "segmental", "arch_rise": 5.0}, "arch_rise"),
    ({"arch_shape": "pointed", "arch_rise": 4.0}, "arch_rise"),
    ({"arch_rise": 3.0}, "arch_rise"),
    ({"arch_thickness": 10.0}, "arch_thickness"),
    ({"arch_blocks": 0}, "arch_blocks"),
    ({"arch_shape": "gothic"}, "arch_shape"),
])
def test_bad_arch_parameters_are_refused(changes, name):
    with pytest.raises(ParameterError) as error:
        arch_params(**changes)
    assert error.value.name == name


def test_thrust_line_approaches_milankovitch_from_below():
    values = [thrust_line_minimum_thickness("semicircular", n, 10.0, mu=10.0).t_over_r
              for n in (16, 32, 64, 2048)]
    assert values == pytest.approx([THRUST_LINE[16], THRUST_LINE[32], THRUST_LINE[64],
                                    0.107478], abs=1e-6)
    assert np.all(np.diff(values) > 0) and values[-1] < MILANKOVITCH
    assert values[-1] == pytest.approx(MILANKOVITCH, rel=3e-4)


def test_thrust_line_hinges_form_the_five_hinge_mechanism():
    line = thrust_line_minimum_thickness("semicircular", 32, 10.0)
    assert line.extrados_hinges == (0, 16, 32)  # springings and crown
    assert line.intrados_hinges == (6, 26)  # haunches
    # the continuous arch's haunch hinge is 54.5 degrees from the crown; joint 6 of 32
    # is at 56.25, the nearest joint
    assert abs(90 - 6 * 180 / 32 - 54.5) < 180 / 32
    assert line.thrust == pytest.approx(0.198, abs=2e-3)  # H / W (Heyman: about 0.2)


@pytest.mark.parametrize("n", [16, 32, 64])
def test_rbe_minimum_thickness_matches_the_thrust_line(n):
    """The RBE feasibility threshold brackets the thrust line's minimum thickness."""
    params = arch_params(arch_blocks=n, mu=10.0)
    result = minimum_thickness(params, rtol=2e-5, bracket=(0.09, 0.12))
    line = thrust_line_minimum_thickness("semicircular", n, 10.0, mu=10.0)
    assert line.t_over_r == pytest.approx(THRUST_LINE[n], abs=1e-6)
    assert result.lower * (1 - 1e-5) <= line.t_over_r <= result.t_over_r * (1 + 1e-5)
    assert result.t_over_r < MILANKOVITCH


def test_pointed_arch_minimum_thickness_matches_the_thrust_line():
    params = arch_params(arch_shape="pointed", arch_blocks=16, mu=10.0)
    result = minimum_thickness(params, rtol=2e-5, bracket=(0.02, 0.06))
    line = thrust_line_minimum_thickness("pointed", 16, 10.0, mu=10.0)
    assert result.lower * (1 - 1e-5) <= line.t_over_r <= result.t_over_r * (1 + 1e-5)


def test_low_friction_arch_slides_at_its_springings():
    # at the springings the thrust leans H / V = 0.4 from the vertical: more than mu
    with pytest.raises(ValueError, match="voussoirs slide"):
        minimum_thickness(arch_params(mu=0.3))
    with pytest.raises(ValueError, match="no thrust line"):
        thrust_line_minimum_thickness("semicircular", 16, 10.0, mu=0.3)


def test_run_arch_stands_above_and_falls_below_its_minimum(tmp_path):
    common = ["run", "--scene", "arch", "--blocks", "16", "--mu", "10", "--no-plots",
              "--no-printable", "--out", str(tmp_path), "-q"]
    for t_over_r, feasible in ((0.110, True), (0.104, False)):
        assert main([*common, "--thickness", str(t_over_r * 5)]) == 0
        name = f"arch_fast0_fricauto_semicircular_N16_s10_t{t_over_r * 5:g}_d1_mu10"
        record = json.loads((tmp_path / name / "run.json").read_text())
        assert record["rbe"]["feasible"] is feasible
        assert record["counts"]["interfaces"]["horizontal"] == 15
        # the weight is the voussoirs' (chord quadrilaterals x depth x rho g)
        profile = arch_profile("semicircular", 16, 10.0, t_over_r * 5)
        weight = shapely.area(shapely.polygons(profile.voussoirs)).sum() * 2000 * 9.81
        assert record["weight_N"] == pytest.approx(weight, rel=1e-12)
        # the springing joints are horizontal: their normal forces carry the weight
        with open(tmp_path / name / "RBE" / "forces.csv") as f:
            rows = [r for r in csv.DictReader(f) if r["kind"] == "support"]
        assert len(rows) == 2
        assert -sum(float(r["normal_N"]) for r in rows) == pytest.approx(weight, rel=1e-6)
        # where it fails: nothing when it stands; else the joints in tension, largest
        # first; no thrust line fits, so some resultant lies outside its joint
        with open(tmp_path / name / "RBE" / "tension_top.csv") as f:
            top = list(csv.DictReader(f))
        with open(tmp_path / name / "RBE" / "forces.csv") as f:
            forces = {r["id"]: r for r in csv.DictReader(f)}
        assert (len(top) == 0) is feasible
        tension = [float(r["tension_N"]) for r in top]
        assert tension == sorted(tension, reverse=True)
        for r in top:
            assert float(forces[r["id"]]["tension_N"]) == float(r["tension_N"])
            assert r["name_a"] and r["course_a"].isdigit()
        outside = max(float(r["eccentricity"]) for r in forces.values())
        assert (outside <= 1 + 1e-6) is feasible


def test_arch_thickness_command(capsys, tmp_path):
    assert main(["arch-thickness", "--blocks", "16", "--mu", "10", "--rtol", "1e-3",
                 "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "t/R = 0.107" in out and "thrust line" in out
    record = json.loads(next(tmp_path.glob("arch-thickness_*/result.json")).read_text())
    # the arch's inputs as the study used them, not the dome's or the searched thickness
    assert record["params"] == {"arch_blocks": 16, "arch_span": 10.0,
                                "arch_shape": "semicircular", "arch_rise": 5.0,
                                "arch_depth": 1.0, "mu": 10.0, "density": 2000.0,
                                "friction_cone": "circle", "solver": None,
                                "accuracy": "balanced"}
