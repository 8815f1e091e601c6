"""The contact law with mortar (docs/model.md 6.3, masonry/contact.py): cohesion c and
tensile strength t_c at every joint, ``||f_i|| <= mu n_i + c A_i`` and ``n_i >= -t_c
A_i`` at a vertex of tributary area ``A_i``, against statics by hand.

The blocks on a slope are ``incline``'s (tests/test_rbe.py): a 1.0 x 0.2 x 0.1 m block
of density 2000 kg/m^3, weight ``W = 392.4 N`` on a bed of area ``A = 0.2 m^2``, so
``p = W / A = 1962 Pa``; the slope falls along the joint's t2 axis, where the 16-sided
pyramid has an edge ray at the cone's radius and the square a face at it, so all three
friction models carry the same on it. Verdicts are checked 2 % either side of a
threshold: the solvers' acceptance tolerance is 1e-5 of the weight.
"""

import json

import numpy as np
import pytest
from test_friction import tilted_block
from test_rbe import cantilever, incline

from masonry.contact import ContactLaw, ContactLawError, tributary_area
from masonry.rbe.boundary import Model
from masonry.rbe.centering import centering_force
from masonry.rbe.collapse import collapse_load
from masonry.rbe.loads import lateral
from masonry.rbe.solve import solve_rbe
from masonry_cli.main import main

MU = 0.7
PHI = np.arctan(MU)
DENSITY = 2000.0
MARGIN = 0.02
"""A verdict is asked 2 % below and above its threshold."""


def pressure(blocks, interfaces):
    """``p = W / A``: the free block's weight over its bed's area, Pa."""
    weight = DENSITY * 9.81 * blocks.block_volume[1]
    return weight / interfaces.area[0]


# ---------------------------------------------------------------- the tributary areas
def test_tributary_areas_sum_to_each_polygon_and_split_a_rectangle_in_quarters():
    """A rectangle's vertices each get the quarter between the vertex, its two edge
    midpoints and the centroid; any polygon's shares sum to its area."""
    blocks, interfaces = cantilever()
    area = tributary_area(interfaces)
    assert area == pytest.approx([0.3 * 0.5 / 4] * 4, rel=1e-12)
    model = tilted_block(np.radians(20.0), 30.0)
    area = tributary_area(model.interfaces)
    sums = np.bincount(model.interfaces.vertex_interface, weights=area)
    assert sums == pytest.approx(model.interfaces.area, rel=1e-12)
    assert (area > 0).all()


# ---------------------------------------------------------------- a block on a slope
@pytest.mark.parametrize("cone", ["circle", "polygon:16", "square"])
@pytest.mark.parametrize("degrees", [40.0, 55.0])
def test_a_block_on_a_slope_stands_with_the_cohesion_of_its_sliding_limit(cone, degrees):
    """A squat block of weight W on a bed of area A inclined at a > phi: along the slope
    W sin a <= mu W cos a + c A, so it stands iff c >= c* = p (sin a - mu cos a), p = W /
    A (no tension needed: t_c = 0, the cut-off truncates the cone at n = 0)."""
    a = np.radians(degrees)
    blocks, interfaces = incline(a, base=1.0, height=0.1)
    needed = pressure(blocks, interfaces) * (np.sin(a) - MU * np.cos(a))
    below = solve_rbe(blocks, interfaces, mu=MU, cone=cone, cohesion=(1 - MARGIN) * needed)
    above = solve_rbe(blocks, interfaces, mu=MU, cone=cone, cohesion=(1 + MARGIN) * needed)
    assert below.verdict == "infeasible"
    assert below.moi > 0
    assert above.verdict == "feasible"
    # the law's one line and its record
    assert f"cohesion {(1 + MARGIN) * needed / 1e3:g} kPa" in above.contact_law
    # the forces are physical: along the slope friction carries W sin a, the normal
    # forces sum to W cos a (t2 points up the slope)
    forces = above.per_interface()
    weight = pressure(blocks, interfaces) * interfaces.area[0]
    assert forces["compression"][0] == pytest.approx(weight * np.cos(a), rel=1e-4)
    assert forces["t2"][0] == pytest.approx(weight * np.sin(a), rel=1e-4)


@pytest.mark.parametrize("cohesion", [250.0, 500.0, 1000.0])
def test_the_steepest_bed_a_brick_holds_on_with_cohesion(cohesion):
    """The brick holds while p sin a <= mu p cos a + c, i.e. sin(a - phi) <= c cos(phi) /
    p: alpha_max = atan(mu) + asin(c / (p sqrt(1 + mu^2))) (41, 47 and 60 degrees for a
    10 cm brick, p = 1962 Pa, at c = 0.25, 0.5 and 1 kPa)."""
    p = pressure(*incline(0.3, base=1.0, height=0.1))
    steepest = PHI + np.arcsin(cohesion / (p * np.sqrt(1 + MU * MU)))
    for offset, verdict in ((-0.5, "feasible"), (0.5, "infeasible")):
        blocks, interfaces = incline(steepest + np.radians(offset), base=1.0, height=0.1)
        assert solve_rbe(blocks, interfaces, mu=MU, cohesion=cohesion).verdict == verdict


def test_a_tensile_strength_beyond_cohesion_over_mu_is_cut_off_at_the_apex():
    """With t_c >= c / mu the cone's apex is the cut-off: no lower bound, the same
    threshold c* on the slope, solved by the preset's own solvers (no refusal)."""
    a = np.radians(45.0)
    blocks, interfaces = incline(a, base=1.0, height=0.1)
    needed = pressure(blocks, interfaces) * (np.sin(a) - MU * np.cos(a))
    law = ContactLaw.of("circle", MU, (1 + MARGIN) * needed, 10 * needed)
    assert law.cutoff_Pa == pytest.approx(law.cohesion_Pa / MU)
    assert not law.is_truncated
    result = solve_rbe(blocks, interfaces, mu=MU, cohesion=law.cohesion_Pa,
                       tensile=law.tensile_Pa)
    assert result.verdict == "feasible"
    assert not any(a["status"] == "refused" for a in result.attempts)


def test_pyramids_with_a_cut_off_are_refused_by_newton_and_said_so():
    """Newton projects onto the truncated circle only: a pyramid's truncation is handed
    on, and the refusal is in the attempts."""
    blocks, interfaces = incline(np.radians(45.0), base=1.0, height=0.1)
    result = solve_rbe(blocks, interfaces, mu=MU, cone="polygon:16", cohesion=500.0)
    refused = [a for a in result.attempts if a["status"] == "refused"]
    assert refused and refused[0]["solver"] == "newton"
    assert "tension cut-off" in refused[0]["reason"]
    with pytest.raises(ValueError, match="interior does not state"):
        solve_rbe(blocks, interfaces, mu=MU, cohesion=500.0, solver="interior")


@pytest.mark.parametrize("direction", [22.5, 40.0])
def test_the_pyramids_shifted_faces_bracket_the_cone(direction):
    """The shifted pyramids carry k (mu n + c A) in the direction of the fall, k between
    cos(pi / K) and 1 for the inscribed K-sided one, between 1 and sqrt(2) for the
    square (faces at mu n + c A): on the slope W sin a <= k (mu W cos a + c A), so a
    pyramid stands from c_k = p (sin a / k - mu cos a). The inscribed 8-sided pyramid
    (k >= 0.924: c_k <= 1.27 c*) stands at 1.3 c* and not below the cone's c*; the
    square stands above c* and not dry (k <= sqrt 2: c_k >= 0.024 c* at 45 degrees). The
    slope falls between the joint's axes (interfaces detected)."""
    a = np.radians(45.0)
    model = tilted_block(a, direction)
    weight = DENSITY * 9.81 * model.blocks.block_volume[1]
    needed = weight / model.interfaces.area[0] * (np.sin(a) - MU * np.cos(a))

    def verdict(cone, cohesion):
        return solve_rbe(model.blocks, model.interfaces, mu=MU, cone=cone,
                         cohesion=cohesion).verdict

    assert verdict("circle", (1 + MARGIN) * needed) == "feasible"
    assert verdict("circle", (1 - MARGIN) * needed) == "infeasible"
    assert verdict("polygon:8", 1.3 * needed) == "feasible"
    assert verdict("polygon:8", (1 - MARGIN) * needed) == "infeasible"
    assert verdict("square", (1 + MARGIN) * needed) == "feasible"
    assert verdict("square", 0.0) == "infeasible"


# ---------------------------------------------------------------- tension
def test_a_cantilevered_block_held_by_the_tension_of_its_bed():
    """A 1.0 x 0.5 x 0.2 m block (W = 1962 N, centroid at x = 0.5) on a bed reaching to
    x = 0.3 (0.3 x 0.5 m, four vertices of A/4 = 0.0375 m^2 each). It tips about the
    bed's edge x = 0.3 unless the two vertices at x = 0 pull it down: moment balance
    about that edge, W (0.5 - 0.3) = T 0.3 with T <= 2 t_c A/4, gives t_c* = W 0.2 /
    (0.3 x 0.075 m^2) (the tension lumped at the vertices, as every force of the
    program). A large cohesion makes t_c the cut-off."""
    blocks, interfaces = cantilever()
    weight = DENSITY * 9.81 * blocks.block_volume[1]
    needed = weight * 0.2 / (0.3 * 2 * 0.0375)
    for factor, verdict in ((1 - MARGIN, "infeasible"), (1 + MARGIN, "feasible")):
        result = solve_rbe(blocks, interfaces, mu=MU, cohesion=10 * needed,
                           tensile=factor * needed)
        assert result.verdict == verdict
    forces = result.per_interface()
    # the net normal force is the weight; the bed carries tension T = 2 W / 3 at x = 0
    assert -forces["normal"][0] == pytest.approx(weight, rel=1e-4)
    normal = result.x.reshape(-1, 4)[:, 0]
    assert normal.min() * 2 == pytest.approx(-weight * 2 / 3, rel=1e-3)


# ---------------------------------------------------------------- dry joints
def test_dry_joints_are_todays_results_bit_for_bit():
    """c = t_c = 0 adds nothing to the arithmetic: the same forces to the last bit; a
    tensile strength without cohesion is cut off at the cone's apex, n = 0: dry."""
    blocks, interfaces = incline(np.radians(30.0), base=1.0, height=0.1)
    dry = solve_rbe(blocks, interfaces, mu=MU)
    same = solve_rbe(blocks, interfaces, mu=MU, cohesion=0.0, tensile=500.0)
    assert np.array_equal(dry.x, same.x)
    assert ContactLaw.of("circle", MU, 0.0, 500.0).is_dry


# ---------------------------------------------------------------- collapse, centering
@pytest.mark.parametrize("tensile_ratio", [0.0, 2.0])
def test_the_collapse_factor_of_a_block_sliding_on_a_slope_with_cohesion(tensile_ratio):
    """A block on a slope a < phi pushed downhill by lambda W horizontally: along the
    slope W sin a + lambda W cos a, the normal force W cos a - lambda W sin a, so it
    slides at mu (W cos a - lambda W sin a) + c A, lambda = (mu cos a - sin a + c / p) /
    (cos a + mu sin a). With t_c = 0 the cone is truncated at n = 0 (Clarabel, the
    interior point method refusing it); with t_c = 2 c / mu it is not."""
    a = np.radians(20.0)
    blocks, interfaces = incline(a, base=1.0, height=0.1)
    p = pressure(blocks, interfaces)
    cohesion = 0.3 * p
    expected = (MU * np.cos(a) - np.sin(a) + cohesion / p) / (np.cos(a) + MU * np.sin(a))
    model = Model(blocks, interfaces)
    result = collapse_load(model, lateral(model, 0.0, DENSITY), mu=MU, density=DENSITY,
                           cohesion=cohesion, tensile=tensile_ratio * cohesion / MU)
    assert result.load_factor == pytest.approx(expected, rel=1e-5)
    dry = (MU * np.cos(a) - np.sin(a)) / (np.cos(a) + MU * np.sin(a))
    assert result.load_factor > dry + 0.1
    assert "cohesion" in result.contact_law


def test_the_centering_force_with_cohesion_is_less_than_dry_and_none_above_c_star():
    a = np.radians(50.0)
    blocks, interfaces = incline(a, base=1.0, height=0.1)
    needed = pressure(blocks, interfaces) * (np.sin(a) - MU * np.cos(a))
    model = Model(blocks, interfaces)
    dry = centering_force(model, mu=MU).total_N
    half = centering_force(model, mu=MU, cohesion=0.5 * needed).total_N
    above = centering_force(model, mu=MU, cohesion=(1 + MARGIN) * needed)
    assert dry == pytest.approx(dry, rel=0) and 0.1 * dry < half < dry
    assert above.total_N == pytest.approx(0.0, abs=1e-6 * above.weight_N)
    assert above.held_count == 0


# ---------------------------------------------------------------- the law and its input
@pytest.mark.parametrize("kwargs", [dict(cohesion_Pa=-1.0), dict(tensile_Pa=float("nan")),
                                    dict(cohesion_Pa=float("inf")), dict(mu=0.0)])
def test_bad_strengths_are_refused_by_the_api(kwargs):
    with pytest.raises(ContactLawError):
        ContactLaw.of(**kwargs)


def test_the_law_in_one_line():
    law = ContactLaw.of("circle", 0.7, 500.0, 250.0)
    assert law.describe() == ("Coulomb circle, mu 0.7, cohesion 0.5 kPa, tensile strength "
                              "0.25 kPa")
    assert json.loads(json.dumps(law.record()))["tension_cutoff_Pa"] == 250.0


@pytest.mark.parametrize("option, value", [("--cohesion-kpa", "-1"), ("--tensile-kpa", "nan"),
                                           ("--cohesion-kpa", "inf")])
def test_bad_strengths_on_the_command_line(tmp_path, capsys, option, value):
    out = tmp_path / "out"
    code = main(["run", "--scene", "wall", "--wall-courses", "2", option, value,
                 "--out", str(out), "-q"])
    err = capsys.readouterr().err
    assert code == 2
    assert option in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_run_with_mortar_records_its_law(tmp_path):
    """The structure id names the mortar, run.json and the text records say the law."""
    out = tmp_path / "out"
    params = tmp_path / "wall.toml"
    params.write_text('scene = "wall"\nwall_courses = 2\nwall_length = 4.0\n'
                      '[mortar]\ncohesion_kpa = 0.5\ntensile_kpa = 0.25\n')
    assert main(["run", "--params", str(params), "--no-plots", "--no-printable",
                 "--no-html", "--out", str(out), "-q"]) == 0
    folder = out / "wall_fast0_fricauto_L4_k2_u0.1_coh0.5_ten0.25"
    assert folder.is_dir()
    record = json.loads((folder / "run.json").read_text())
    line = "Coulomb circle, mu 0.7, cohesion 0.5 kPa, tensile strength 0.25 kPa"
    assert record["rbe"]["contact_law"] == line
    assert line in (folder / "00_parameters.txt").read_text()
    assert line in (folder / "RBE" / "00_objective.txt").read_text()
