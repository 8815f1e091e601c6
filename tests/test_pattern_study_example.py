"""examples/pattern_study.py (docs/pattern-study.md): runs each course's stages command
once, resumes where it stopped, and tabulates what the runs' own records say."""

import csv
import importlib.util
import json
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).parent.parent / "examples" / "pattern_study.py"
SMALL = "small=--preset 1 --p 3"   # 22 courses; course 21 leans about 60 degrees


@pytest.fixture(scope="module")
def study():
    spec = importlib.util.spec_from_file_location("pattern_study", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_it_runs_each_command_once_and_resumes(study, tmp_path, capsys):
    """Two courses of a small dome, both patterns pattern-first: four runs; again: none;
    with one more course: only its two. Every row's largest adhesion is its run's own
    run.json ``adhesion_max_kPa`` (the stages' summary), and the figure is written."""
    base = ["--out", str(tmp_path), "--profile", SMALL, "--orders", "pattern-first"]
    assert study.main([*base, "--courses", "20-21"]) == 0
    assert "0 done, 4 to run" in capsys.readouterr().out
    assert study.main([*base, "--courses", "20-21"]) == 0
    assert "4 done, 0 to run" in capsys.readouterr().out
    assert study.main([*base, "--courses", "20-22"]) == 0
    assert "4 done, 2 to run" in capsys.readouterr().out
    with open(tmp_path / "pattern_study.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 6
    for row in rows:
        record = json.loads((Path(row["folder"]) / "run.json").read_text())
        assert float(row["adhesion_max_kPa"]) == pytest.approx(
            record["stages"]["adhesion_max_kPa"], rel=1e-9)
    assert any(float(row["adhesion_max_kPa"]) > 0 for row in rows)
    assert (tmp_path / "pattern_study.png").stat().st_size > 10_000


@pytest.mark.parametrize("given, named", [(["--courses", "9-3"], "--courses 9-3"),
                                          (["--profiles", "dome"], "--profiles dome")])
def test_bad_input_is_one_line_and_exit_2(study, tmp_path, capsys, given, named):
    with pytest.raises(SystemExit) as stop:
        study.main(["--out", str(tmp_path), *given])
    assert stop.value.code == 2
    assert named in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("name", ["pattern_search_preset1.toml",
                                  "pattern_search_hemisphere.toml"])
def test_the_pattern_searches_are_studies_of_the_whole_construction(name):
    """The study files of docs/pattern-study.md's search read as studies: a dome of
    revolution's sector (cyclic), its pattern's three inputs sampled, every brick laid
    pattern-first."""
    from masonry.studies.study_file import load_study

    study = load_study(EXAMPLE.parent / name, draws=False)
    assert set(study.sample) == {"p", "spirals", "helix_angle"}
    assert study.base["scene"] == "sector" and study.base["boundary"] == "cyclic"
    assert (study.stages, study.stages_course, study.stages_order) == (
        "brick", None, "pattern-first")
