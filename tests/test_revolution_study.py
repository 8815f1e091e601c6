"""The herringbone against the plain dome (docs/revolution.md,
benchmarks/revolution_study.py), on tiny domes."""

import numpy as np
import pytest
from scipy.optimize import brentq
from test_interfaces import box_corners

from masonry.blocks import Blocks
from masonry.interfaces import detect
from masonry.rbe.solve import RBEProblem
from masonry.scenes.revolution import profile_of
from masonry_benchmarks import revolution_study as rs

TINY = dict(n=6, r=0, p=5, cut=0.3, profiles={"hemisphere": 1.0})
"""Four domes of 8 courses, 120 to 210 bricks; the chords of courses 7 and 8 lean 35.85
and 41.37 degrees, more than atan(0.7) = 34.99."""


def tiny(kind, pattern):
    return next(d for d in rs.domes(**TINY) if (d.kind, d.pattern) == (kind, pattern))


def test_the_dome_of_revolution_takes_the_polygons_mid_plane_meridian():
    for dome in rs.domes():
        if dome.kind == "polygonal":
            scene = dome.model()[0]
            twin = next(d for d in rs.domes() if d.kind == "revolution"
                        and (d.profile, d.pattern) == (dome.profile, dome.pattern))
            prof = profile_of(twin.params().geometry)
            np.testing.assert_allclose(prof.x, scene.levels.x, atol=1e-5)
            np.testing.assert_allclose(prof.z, scene.levels.z, atol=1e-5)
            if dome.profile == "hemisphere":  # c = a: the mid-plane is a quarter circle
                assert abs(scene.dims.c - scene.dims.a) < 1e-5


def test_a_lone_brick_on_a_bed_steeper_than_the_friction_angle_slides():
    # the plain polygonal dome's top course laid along: its first brick (the fill-in at
    # the corner) lies alone on the top plane of course 7, inclined at gamma_reg of
    # course 7; it stands iff mu >= tan of that, to the solver's accuracy
    dome = tiny("polygonal", "none")
    bed = dome.model()[0].levels.gamma_reg[6]
    assert abs(np.degrees(bed) - 35.85) < 0.01
    for factor, stands in ((0.99, False), (1.01, True)):
        found = rs.brick_course(dome, "along", 8, "balanced", factor * np.tan(bed))
        assert found["feasible"][0] is stands
        assert found["laid"][0] == ["fill_in"]
        assert found["feasible"][-1]  # the closed ring stands


def flank_angle(mu) -> float:
    """The steepest bed a block stands on while pressed against a fixed vertical flank
    that holds the bed's slope line, Coulomb friction on both faces (radians). Weight 1,
    flank push P, flank friction mu P at theta below the slope line (pressing the block
    into its bed): the bed must carry (P, sin a - mu P cos theta) with normal
    cos a + mu P sin theta, a quadratic A P^2 - 2 B P + C <= 0 that some P > 0 meets iff
    B^2 >= A C for some theta."""
    theta = np.linspace(-np.pi / 2, np.pi / 2, 200001)

    def margin(a):
        big_a = 1 + mu**2 * np.cos(theta) ** 2 - mu**4 * np.sin(theta) ** 2
        big_b = mu * (np.sin(a) * np.cos(theta) + mu**2 * np.cos(a) * np.sin(theta))
        return np.max(big_b**2 - big_a * (np.sin(a) ** 2 - mu**2 * np.cos(a) ** 2))
    return brentq(margin, np.arctan(mu), np.pi / 3)


@pytest.mark.parametrize("flank", [False, True])
def test_a_flank_holds_a_brick_on_a_steeper_bed(flank):
    # what a pattern brick gives the brick laid beside it (docs/revolution.md): a brick
    # on a bed tilted about y, against a fixed flank in the plane y = 0, which holds the
    # slope line; alone it stands up to atan(mu) = 34.99 deg, with the flank to 44.43
    mu = 0.7
    limit = flank_angle(mu) if flank else np.arctan(mu)
    assert abs(np.degrees(limit) - (44.43 if flank else 34.99)) < 0.01
    boxes = [([-3, -1, -0.2], [3, 1, 0]), ([-0.2, 0, 0], [0.2, 0.4, 0.1])]
    if flank:
        boxes.insert(1, ([-3, -1, 0], [3, 0, 0.5]))
    for tilt, stands in ((limit - np.radians(0.3), True), (limit + np.radians(0.3), False)):
        c, s = np.cos(tilt), np.sin(tilt)
        turn = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
        blocks = Blocks.from_hexahedra(
            np.array([box_corners(lo, hi) @ turn.T for lo, hi in boxes]),
            ["ground"] * (len(boxes) - 1) + ["regular"])
        interfaces = detect(blocks)
        assert len(interfaces) == len(boxes) - 1
        result = RBEProblem(blocks, interfaces).solve(mu=mu, accuracy="balanced")
        assert result.feasible is stands


@pytest.mark.slow
def test_the_study_measures_every_dome_and_goes_on_where_it_stopped(tmp_path, monkeypatch):
    domes = rs.domes(**TINY)
    rs.study(tmp_path, domes)
    rows = rs.read_csv(tmp_path / "revolution.csv")
    assert [(r["kind"], r["pattern"]) for r in rows] == [(d.kind, d.pattern) for d in domes]
    for row in rows:
        assert row["cyclic"] == "feasible" and row["course_stages_standing"] == 8
        assert row["steep_from"] == 7
        assert 0 < row["lateral_factor"] < 0.7  # the whole dome slides on its bed last
        assert (row["pattern_bricks"] > 0) == (row["pattern"] == "herringbone")
    bricks = rs.read_csv(tmp_path / "revolution_bricks.csv")
    for d in domes:
        for order in rs.BRICK_ORDERS:
            scanned = [b for b in bricks if (b["kind"], b["pattern"], b["order"])
                       == (d.kind, d.pattern, order)]
            assert [b["course"] for b in scanned] == [7, 8]
            assert all(0 <= b["failing"] < b["stages"] for b in scanned)
            if d.pattern == "none":  # the lone first brick on 41.37 degrees, again
                assert scanned[1]["first_failing_stage"] == 1
                assert scanned[1]["confirm_failing"] == scanned[1]["failing"]
    assert len(rs.read_csv(tmp_path / "revolution_azimuths.csv")) == 4 * 24
    for name in ("domes", "bricks", "lateral"):
        assert (tmp_path / f"revolution_{name}.png").read_bytes()[:4] == b"\x89PNG"

    def solved_again(*args):
        raise AssertionError("a kept measurement was solved again")

    for name in ("self_weight", "lateral", "course_stages", "brick_course"):
        monkeypatch.setattr(rs, name, solved_again)
    before = (tmp_path / "revolution_bricks.csv").read_text()
    rs.study(tmp_path, domes)
    assert (tmp_path / "revolution_bricks.csv").read_text() == before
