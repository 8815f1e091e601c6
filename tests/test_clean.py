"""``masonry clean`` (masonry/cleaning.py): on a temporary output root, what it removes
and keeps, that a later run writes the removed outputs again, and the roots it refuses."""

import json

import pytest

from masonry.export.html import plotly_file
from masonry import read_table
from masonry_cli.main import main

WALL = ["--scene", "wall", "--wall-length", "8", "--wall-courses", "3", "--fast"]

REMOVED_SUFFIXES = {".png", ".html", ".stl", ".obj", ".3dm", ".pickle", ".js"}
"""The files of a wall's run that cleaning removes (bricks.obj stays: the model)."""


@pytest.fixture()
def root(tmp_path):
    """An output root with one run folder of every output, a folder and a file of the
    user's beside it."""
    out = tmp_path / "out"
    assert main(["run", *WALL, "--out", str(out), "-q"]) == 0
    (out / "notes").mkdir()
    (out / "notes" / "sketch.png").write_bytes(b"not masonry's")
    (out / "photo.png").write_bytes(b"not masonry's either")
    return out


def files_of(root) -> dict:
    """Path (relative, /-separated) -> size, of every file under ``root``."""
    return {p.relative_to(root).as_posix(): p.stat().st_size
            for p in root.rglob("*") if p.is_file()}


def test_a_dry_run_lists_what_clean_removes_and_keeps_the_rest(root, capsys):
    """The dry run lists every file it would remove with its size and their sum, and
    removes nothing; the clean then removes exactly those: the figures, the page and
    the shared plotly.js, the printable body, bricks.3dm and the cache; the tables,
    run.json, the parameters and the model's files stay, and nothing outside the run
    folder is touched."""
    before = files_of(root)
    assert main(["clean", str(root), "--dry-run"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert files_of(root) == before
    listed = {line.split(maxsplit=1)[1]: int(line.split()[0].replace(",", ""))
              for line in lines[:-1]}
    (folder,) = [p for p in root.iterdir() if p.name.startswith("wall_")]
    expected = {path: size for path, size in before.items()
                if path.startswith((folder.name, ".cache")) or path == plotly_file()}
    expected = {path: size for path, size in expected.items()
                if "." + path.rsplit(".", 1)[1] in REMOVED_SUFFIXES
                and not path.endswith("bricks.obj")}
    assert listed == expected
    assert {path.rsplit("/", 1)[-1] for path in listed} >= {
        "dome.html", "dome.stl", "dome.obj", "bricks.3dm", "00_pattern.png", plotly_file()}
    total = sum(expected.values())
    assert lines[-1].startswith(f"would remove {len(expected)} files, "
                                f"{total / 1e6:.1f} MB")
    assert main(["clean", str(root)]) == 0
    after = files_of(root)
    assert set(after) == set(before) - set(expected)
    assert {"notes/sketch.png", "photo.png", f"{folder.name}/RBE/forces.csv",
            f"{folder.name}/bricks.obj", f"{folder.name}/00_parameters.txt"} <= set(after)
    assert len(read_table(folder / "RBE" / "forces.csv")) > 0  # the tables read back
    record = json.loads((folder / "run.json").read_text())
    assert record["complete"] is True and "figures" not in record
    assert {k: record["outputs"][k] for k in ("plots", "html", "printable", "3dm")} == {
        "plots": False, "html": False, "printable": False, "3dm": False}
    assert not (root / ".cache").exists()


def test_a_run_after_clean_writes_the_outputs_again(root):
    """The cleaned folder does not hold what a run asks for: the next run writes it
    (the page, its plotly.js, the figures), and the one after reuses the folder."""
    assert main(["clean", str(root), "-q"]) == 0
    assert main(["run", *WALL, "--out", str(root), "-q"]) == 0
    (folder,) = [p for p in root.iterdir() if p.name.startswith("wall_")]
    assert (folder / "dome.html").is_file() and (root / plotly_file()).is_file()
    assert (folder / "00_pattern.png").is_file() and (folder / "dome.stl").is_file()
    stamp = (folder / "run.json").stat().st_mtime_ns
    assert main(["run", *WALL, "--out", str(root), "-q"]) == 0
    assert (folder / "run.json").stat().st_mtime_ns == stamp


@pytest.mark.parametrize("what", ["missing", "a file", "no run folder"])
def test_a_folder_that_is_not_an_output_root_is_refused(tmp_path, capsys, what):
    """A path that is no output root: one line naming it, exit 2, nothing removed."""
    path = tmp_path / "x"
    if what == "a file":
        path.write_text("text")
    elif what == "no run folder":
        (path / "holiday").mkdir(parents=True)
        (path / "holiday" / "run.json").write_text('{"complete": true}')  # not masonry's
        (path / "holiday" / "beach.png").write_bytes(b"png")
    before = files_of(tmp_path)
    assert main(["clean", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0] and "masonry output root" in err[0]
    assert files_of(tmp_path) == before
