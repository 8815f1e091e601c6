"""Names and scope: every brick's name is unique in its scene, a point load loads the
blocks it names, a cyclic section's files show the whole dome it stands for, the API
takes the command line's defaults, and a size estimate is near what is built."""

import json
from pathlib import Path

import numpy as np
import pytest

import masonry
from masonry.errors import ParameterError
from masonry.params import Params, from_preset, validate
from masonry.rbe.loads import point_loads
from masonry.rbe.accuracy import ACCURACY
from masonry.scenes import build, check_size, memory_estimate
from masonry.tolerances import BYTES_PER_BRICK
from masonry_cli.main import main

SMALL = {
    "section": dict(n=6, r=0, p=3, cut=0.5),
    "dome": dict(n=6, r=0, p=3, cut=0.5),
    "revolution": dict(radius=20, p=2),
    "sector": dict(radius=20, p=2),
    "arch": dict(),
    "wall": dict(),
}


@pytest.mark.parametrize("scene", sorted(SMALL))
def test_every_brick_name_is_unique_in_its_scene(scene):
    blocks = build(validate(Params.of(scene=scene, **SMALL[scene]))).blocks
    assert len(set(blocks.block_name)) == blocks.n_blocks


def test_a_named_point_load_loads_one_brick_of_a_dome_of_revolution():
    blocks = build(validate(Params.of(scene="revolution", **SMALL["revolution"]))).blocks
    name = str(blocks.block_name[blocks.n_blocks - 1])
    assert name.startswith("w9_")  # the last sector's last brick
    load = point_loads(blocks, [f"{name}:0,0,-100"])
    assert load.description["blocks"] == 1
    assert np.count_nonzero(np.abs(load.wrench).sum(axis=1)) == 1
    assert load.description["total_force_N"] == pytest.approx([0, 0, -100], abs=1e-9)


def _record(folder):
    (path,) = folder.glob("*/run.json")
    return json.loads(path.read_text()), path.parent


def test_a_cyclic_sections_bricks_obj_is_the_whole_dome_with_the_runs_verdict(tmp_path):
    options = ["--n", "6", "--r", "0", "--p", "3", "--cut", "0.5", "--no-plots",
               "--no-printable", "-q"]
    assert main(["run", *options, "--out", str(tmp_path / "run")]) == 0
    record, folder = _record(tmp_path / "run")
    assert record["params"]["boundary"] == "cyclic" and record["rbe"]["feasible"]
    text = (folder / "bricks.obj").read_text()
    names = [line[2:] for line in text.splitlines() if line.startswith("o ")]
    per_web = len(names) // 6
    assert len(names) == 6 * per_web and len(set(names)) == len(names)
    assert [line for line in text.splitlines() if line.startswith("g ")] == [
        "g solved_section", "g turned_copies"]
    assert all(name.startswith(f"w{k // per_web}_") for k, name in enumerate(names)
               if k >= per_web)
    locations = masonry.read_table(folder / "locations.csv")
    assert locations["name"].nunique() == len(names)
    assert main(["analyze", str(folder / "bricks.obj"), "--support", "*_ground_*",
                 "--no-plots", "--no-printable", "-q", "--out", str(tmp_path / "b")]) == 0
    analysed, _ = _record(tmp_path / "b")
    assert analysed["rbe"]["feasible"] is True
    assert analysed["source"]["supports"] == 6


def test_the_api_takes_a_sections_boundary_as_the_command_line_does():
    assert masonry.build(**SMALL["section"]).params.analysis.boundary == "cyclic"
    given = masonry.build(**SMALL["section"], boundary="free")
    assert given.params.analysis.boundary == "free"
    assert masonry.build(scene="dome", **SMALL["dome"]).params.analysis.boundary == "free"


@pytest.mark.parametrize("scene", ["sector", "revolution"])
@pytest.mark.parametrize("inputs", [dict(radius=20, p=2), dict(radius=30, p=3),
                                    dict(radius=40, p=4, cut=0.3),
                                    dict(radius=25, p=3, stretch=0.6),
                                    dict(radius=30, p=2, helix="clelia"),
                                    dict(radius=30, p=2, helix_angle=60),
                                    dict(radius=40, p=3, pattern="none")])
def test_a_dome_of_revolutions_size_estimate_is_within_a_quarter_of_its_bricks(scene,
                                                                              inputs):
    params = validate(Params.of(scene=scene, **inputs))
    estimate = check_size(params)
    assert estimate == pytest.approx(build(params).blocks.n_blocks, rel=0.25)


@pytest.mark.parametrize("scene", ["revolution", "sector"])
def test_a_huge_dome_is_refused_before_anything_is_laid_out(scene, monkeypatch, tmp_path):
    from masonry.scenes import revolution

    def never(*args, **kwargs):
        raise AssertionError("laid out a dome that is refused by its size")

    for name in ("ring_pattern", "rings_of", "profile_of", "build_sector"):
        monkeypatch.setattr(revolution, name, never)
    for radius in ("1e5", "10000"):
        assert main(["build", "--scene", scene, "--radius", radius,
                     "--out", str(tmp_path)]) == 2
    with pytest.raises(ParameterError, match="max_bricks"):
        check_size(validate(Params.of(scene=scene, radius=1e5)))
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("scene, inputs", [
    ("section", dict(preset="1", p=30)), ("section", dict(preset="3", p=48)),
    ("section", dict(preset="2", p=21, pattern="none")),
    ("dome", dict(n=6, r=0, p=3, cut=0.5)), ("dome", dict(preset="3", p=4))])
def test_a_polygonal_domes_size_check_counts_the_blocks_it_builds(scene, inputs):
    """Counted from the web's plan: exact where the intrados estimate was 26 % (preset 1
    at p 30: 41,072 bricks and 8 slabs) and 33 % (preset 3 at p 48) too high."""
    inputs = dict(inputs)
    preset = inputs.pop("preset", None)
    params = (from_preset(preset, scene=scene, **inputs) if preset
              else validate(Params.of(scene=scene, **inputs)))
    assert check_size(params, max_bricks=10**6) == build(params).blocks.n_blocks


def test_a_huge_polygonal_dome_is_refused_before_its_plan_is_laid(monkeypatch, tmp_path):
    from masonry.scenes import polygonal

    def never(*args, **kwargs):
        raise AssertionError("laid out a dome that is refused by its size")

    monkeypatch.setattr(polygonal, "web_plan", never)
    assert main(["build", "--scene", "dome", "--p", "2000", "--out", str(tmp_path)]) == 2
    with pytest.raises(ParameterError, match="max_bricks"):
        check_size(from_preset("1", p=2000))
    assert not any(tmp_path.iterdir())


PEAKS = json.loads((Path(__file__).parent.parent / "fixtures" / "scale" / "peaks.json")
                   .read_text())["rows"]


@pytest.mark.parametrize("row", PEAKS, ids=[row["structure"] for row in PEAKS])
def test_the_size_checks_estimates_are_within_a_quarter_of_the_measured(row):
    """``--max-bricks``'s count and memory against what runs of a wall and of preset 1's
    full dome built and took, 1,025 to 100,250 bricks (fixtures/scale/peaks.json): the
    dome's count exact (its 8 ground slabs are blocks), the wall's (a full brick more in
    every course than the odd courses hold) within 3 %."""
    params = from_preset(row["preset"], **row["inputs"])
    blocks = check_size(params, max_bricks=10**7)
    if row["preset"] == "1":
        assert blocks == row["bricks"] + 8
    else:
        assert 0 <= blocks / row["bricks"] - 1 < 0.03
    estimate = memory_estimate(row["bricks"], params.analysis.accuracy) / 2**30
    assert abs(estimate / row["peak_gib"] - 1) < 0.25


def test_the_memory_estimate_knows_every_accuracy_preset():
    assert BYTES_PER_BRICK.keys() == ACCURACY.keys()


def test_a_refused_model_names_its_memory_if_it_stands(capsys, tmp_path):
    assert main(["run", "--scene", "wall", "--wall-length", "800", "--wall-courses", "500",
                 "--out", str(tmp_path)]) == 2
    line = capsys.readouterr().err.strip()
    assert "100,500" in line and "6.1 GiB of memory to solve, if it stands" in line
    assert not any(tmp_path.iterdir())
