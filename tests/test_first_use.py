"""What a new user meets first: the default run, the files it writes, and bad input that
must end in one line and exit code 2 (not an internal error) before any work."""

import json

import pytest

from masonry_cli.main import main

WALL = ["--preset", "wall", "--wall-courses", "3", "--wall-length", "12", "--fast",
        "--no-plots", "--no-printable"]
WALL_ID = "wall_fast1_fricauto_L12_k3_u0.1"


def one_error_line(capsys) -> str:
    """The one line a refused input prints on stderr."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("masonry: error: ")
    return err[0]


def test_a_run_writes_the_3dm_and_a_folder_without_it_is_not_up_to_date(
        tmp_path, monkeypatch, capsys):
    pytest.importorskip("rhino3dm")
    folder = tmp_path / WALL_ID
    monkeypatch.setattr("masonry.export.rhino.available", lambda: False)
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "bricks.3dm not written: rhino3dm, a dependency of masonry, is not installed" in err
    assert not (folder / "bricks.3dm").exists()
    assert json.loads((folder / "run.json").read_text())["outputs"]["3dm"] is False
    monkeypatch.undo()  # rhino3dm installed now: the folder lacks what a run can make
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "up to date" not in out and "written:" in out
    assert (folder / "bricks.3dm").stat().st_size > 0
    record = json.loads((folder / "run.json").read_text())
    assert record["outputs"]["3dm"] is True and "bricks.3dm" in record["coordinates"]["model"]
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0  # and now it is
    assert "up to date, reused" in capsys.readouterr().out


SMALL = ["--p", "5", "--no-plots", "--no-printable"]  # 220 bricks


def test_the_default_run_is_the_cyclic_section_and_says_what_its_verdict_means(
        tmp_path, capsys):
    assert main(["run", *SMALL, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    (folder,) = [p for p in tmp_path.iterdir() if not p.name.startswith(".")]
    assert folder.name.startswith("dome1_")  # the section with cyclic neighbours
    assert json.loads((folder / "run.json").read_text())["params"]["boundary"] == "cyclic"
    assert "RBE: feasible" in out
    assert ("meaning: the whole dome (this web with its neighbours by rotational symmetry) "
            "stands under its own weight") in out
    # the web alone is one option away, and says what its verdict means
    assert main(["run", *SMALL, "--boundary", "free", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "RBE: infeasible" in out
    assert ("meaning: this web alone, without its neighbours, cannot stand under its own "
            "weight") in out


def test_the_readme_says_what_the_default_run_does(fixtures_dir):
    readme = (fixtures_dir.parent / "README.md").read_text()
    assert "come next" not in readme
    assert "exports/dome1_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1/" in readme


def test_a_lateral_load_on_the_default_section_names_the_scene_that_takes_it(
        tmp_path, capsys):
    assert main(["run", *SMALL, "--lateral", "0", "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert line.startswith("masonry: error: --lateral 0: expected a symmetric load on a "
                           "cyclic section (a section's default boundary)")
    assert "--scene dome" in line and "--boundary free" in line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("table, key, value, expected", [
    ("base", "no-plots", "true", "the figures are chosen in the [outputs] table "
                                 "(plots = false)"),
    ("base", "no-printable", "true", "the printable body is chosen in the [outputs] table "
                                     "(printable = false)"),
    ("base", "out", '"x"', "the study's output root is masonry sweep's --out"),
    ("grid", "force", "[true]", "not an option of the command"),
])
def test_a_study_table_refuses_a_run_option_that_is_no_input(tmp_path, capsys, table, key,
                                                             value, expected):
    study = tmp_path / "study.toml"
    grid = "" if table == "grid" else "[grid]\nmu = [0.5, 0.7]\n"
    study.write_text(f"[base]\npreset = 3\n{grid}[{table}]\n{key} = {value}\n"
                     if table == "grid" else f"[base]\npreset = 3\n{key} = {value}\n{grid}")
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"masonry: error: {study}: {table}.{key} = ")
    assert line.endswith(expected) and "expected an input of each variant" in line
    assert not (tmp_path / "o").exists()


def test_the_example_study_shows_its_outputs_table(fixtures_dir):
    import tomllib

    study = tomllib.loads((fixtures_dir / "studies" / "stretch_mu.toml").read_text())
    assert study["outputs"] == {"plots": False, "printable": False}


def test_the_collapse_line_says_the_mechanism_as_its_file_does(tmp_path, capsys):
    assert main(["run", *WALL, "--lateral", "0", "--out", str(tmp_path)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines()
                if ln.startswith("collapse:"))
    text = next((tmp_path).glob("wall_*_lat0")).joinpath("collapse", "00_collapse.txt")
    (mechanism,) = [ln for ln in text.read_text().splitlines() if ln.startswith("mechanism:")]
    words = mechanism.split(":", 1)[1].strip()
    assert f"mechanism: {words}; " in line and "collapse/00_collapse.txt" in line
