"""The herringbone against the plain dome (docs/revolution.md,
masonry/studies/revolution_study.py), on tiny domes."""

import numpy as np
from masonry.scenes.revolution import profile_of
from masonry.studies import revolution_study as rs

TINY = dict(n=6, r=0, p=5, cut=0.3, profiles={"hemisphere": 1.0})
"""Four domes of 8 courses: 120 to 210 bricks; courses 7 and 8 lie on beds of 35.85 and
41.37 degrees, above atan(0.7) = 34.99."""


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
