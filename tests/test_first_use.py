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
