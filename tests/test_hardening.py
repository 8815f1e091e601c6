"""Nothing lost, nothing cryptic: no command degrades another's results, killed
runs leave nothing behind, a corrupt cache is rebuilt, internal failures are one line."""

import json
import os
import pathlib
import pickle
import re
import signal
import socket
import subprocess
import sys
import time

import pytest

from masonry.runfolder import remove_leftovers
from masonry_cli.main import main

WALL = ["--preset", "wall", "--wall-courses", "3", "--wall-length", "12", "--fast"]
WALL_ID = "wall_fast1_fricauto_L12_k3_u0.1"


def snapshot(folder):
    """Every file under ``folder`` with its bytes."""
    return {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_build_after_run_keeps_the_forces(tmp_path, capsys):
    assert main(["run", *WALL, "--out", str(tmp_path), "-q"]) == 0
    before = snapshot(tmp_path / WALL_ID)
    assert any(p.parts[0] == "RBE" for p in before)
    assert main(["build", *WALL, "--out", str(tmp_path), "-q"]) == 0
    assert "up to date, reused" in capsys.readouterr().out
    assert snapshot(tmp_path / WALL_ID) == before


def test_the_print_size_is_an_output_choice_not_another_input(tmp_path, capsys):
    # the 3MF's size is not in the structure id: a build after a run with a 3MF keeps
    # the forces and the 3MF; another size rewrites the 3MF at that size, nothing else
    folder = tmp_path / WALL_ID
    assert main(["run", *WALL, "--print-size", "120", "--out", str(tmp_path), "-q"]) == 0
    before = snapshot(folder)
    assert main(["build", *WALL, "--out", str(tmp_path), "-q"]) == 0
    assert "up to date, reused" in capsys.readouterr().out
    assert snapshot(folder) == before
    assert main(["run", *WALL, "--no-plots", "--print-size", "90", "--out", str(tmp_path),
                 "-q"]) == 0
    record = json.loads((folder / "run.json").read_text())
    assert record["printable"]["print"]["size_mm"] == 90
    assert max(record["printable"]["print"]["readback"]["extents_mm"]) == pytest.approx(90)
    assert set(snapshot(folder)) == set(before)  # the plots kept, nothing lost


def test_run_after_build_adds_the_forces_and_keeps_the_plots(tmp_path):
    assert main(["build", *WALL, "--out", str(tmp_path), "--no-printable", "-q"]) == 0
    assert main(["run", *WALL, "--out", str(tmp_path), "--no-plots", "--no-printable",
                 "-q"]) == 0
    record = json.loads((tmp_path / WALL_ID / "run.json").read_text())
    assert record["outputs"] == {"analyse": True, "centering": True, "adhesion": True,
                                 "plots": True, "printable": False, "html": True,
                                 "quick": True, "figure_format": ["png"], "dpi": None,
                                 "html_plotly": "shared", "3dm": True}
    assert (tmp_path / WALL_ID / "RBE" / "forces.csv").is_file()
    assert (tmp_path / WALL_ID / "00_pattern.png").is_file()


@pytest.mark.slow
def test_sweep_and_run_never_strip_each_other(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text('[base]\npreset = "wall"\nwall-courses = 3\nwall-length = 12\n'
                     'fast = true\n[grid]\nmu = [0.7]\n')
    out = tmp_path / "out"
    assert main(["run", *WALL, "--out", str(out), "-q"]) == 0
    full = snapshot(out / WALL_ID)
    assert (out / WALL_ID / "dome.stl").is_file()
    # the sweep's variant is the same input: it reuses the richer folder untouched
    assert main(["sweep", str(study), "--workers", "1", "--out", str(out), "-q"]) == 0
    assert snapshot(out / WALL_ID) == full
    assert "reused" in (out / "sweep_study" / "summary.csv").read_text()
    # a sweep first, then the run: the run writes everything, the sweep then reuses it
    other = tmp_path / "other"
    assert main(["sweep", str(study), "--workers", "1", "--out", str(other), "-q"]) == 0
    assert not (other / WALL_ID / "dome.stl").exists()
    assert main(["run", *WALL, "--out", str(other), "-q"]) == 0
    assert (other / WALL_ID / "dome.stl").is_file()
    richer = snapshot(other / WALL_ID)
    assert main(["sweep", str(study), "--workers", "1", "--out", str(other), "-q"]) == 0
    assert snapshot(other / WALL_ID) == richer


@pytest.mark.slow
def test_two_commands_at_once_into_one_root(tmp_path):
    # build and run of the same input race to publish the same folder: whichever ends
    # last, the folder holds the run's forces and the build's plots, and nothing is left
    commands = [[sys.executable, "-m", "masonry_cli.main", command, *WALL, "--out",
                 str(tmp_path), "-q"] for command in ("build", "run")]
    processes = [subprocess.Popen(c, stderr=subprocess.PIPE, text=True) for c in commands]
    for process in processes:
        _, err = process.communicate(timeout=120)
        assert process.returncode == 0, err
    record = json.loads((tmp_path / WALL_ID / "run.json").read_text())
    assert record["outputs"]["analyse"] and record["outputs"]["plots"]
    assert (tmp_path / WALL_ID / "RBE" / "forces.csv").is_file()
    assert [p.name for p in tmp_path.iterdir() if ".tmp-" in p.name or ".old-" in p.name] == []


def test_leftovers_of_dead_runs_are_removed_and_live_ones_kept(tmp_path):
    host = "".join(c if c.isalnum() else "_" for c in socket.gethostname())
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    stale = tmp_path / f".{WALL_ID}.tmp-{host}-{dead}-0123abcd"
    legacy = tmp_path / f".{WALL_ID}.tmp-89abcdef"
    live = tmp_path / f".other.tmp-{host}-{os.getpid()}-0123abcd"
    for folder in (stale, legacy, live):
        folder.mkdir()
        (folder / "bricks.obj").write_text("partial")
    # a publish killed between its two renames: the previous folder was set aside
    aside = tmp_path / f".{WALL_ID}.old-{host}-{dead}-0123abcd"
    aside.mkdir()
    (aside / "run.json").write_text("{}")
    assert sorted(remove_leftovers(tmp_path)) == sorted([stale, legacy])
    assert live.is_dir()
    assert (tmp_path / WALL_ID / "run.json").read_text() == "{}" and not aside.exists()


@pytest.mark.slow
def test_sigterm_during_the_exports_leaves_the_previous_run(tmp_path):
    args = ["--preset", "1", "--fast", "--no-printable", "--out", str(tmp_path), "-q"]
    assert main(["build", *args]) == 0
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.name.startswith(".")]
    before = snapshot(folder)
    process = subprocess.Popen([sys.executable, "-m", "masonry_cli.main", "build",
                                "--force", *args], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not any(".tmp-" in p.name for p in tmp_path.iterdir()):
        assert process.poll() is None and time.monotonic() < deadline, "never wrote"
        time.sleep(0.005)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143
    assert err.strip().splitlines()[-1] == ("masonry: interrupted; the previous output is "
                                            "untouched")
    assert snapshot(folder) == before
    assert [p.name for p in tmp_path.iterdir() if ".tmp-" in p.name] == []


def test_a_corrupt_cache_is_rebuilt_with_a_warning(tmp_path, capsys):
    assert main(["build", *WALL, "--no-plots", "--out", str(tmp_path), "-q"]) == 0
    (cache,) = (tmp_path / ".cache").iterdir()
    good = cache.read_bytes()
    cache.write_bytes(good[: len(good) // 2])  # truncated, as by a full disk
    capsys.readouterr()
    assert main(["build", *WALL, "--no-plots", "--force", "--out", str(tmp_path),
                 "-q"]) == 0
    err = capsys.readouterr().err
    assert "geometry cache" in err and "unreadable" in err and "rebuilding" in err
    assert cache.read_bytes() == good  # rebuilt, the same model


class _Planted:
    """A pickle that calls a function when loaded (here a harmless one that leaves a
    file: the marker of code run from a cache someone put in the output folder)."""

    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (pathlib.Path.touch, (pathlib.Path(self.marker),))


def test_a_cache_that_would_run_code_is_refused(tmp_path, capsys):
    assert main(["build", *WALL, "--no-plots", "--out", str(tmp_path), "-q"]) == 0
    (cache,) = (tmp_path / ".cache").iterdir()
    marker = tmp_path / "ran"
    cache.write_bytes(pickle.dumps(_Planted(marker)))
    capsys.readouterr()
    assert main(["build", *WALL, "--no-plots", "--force", "--out", str(tmp_path),
                 "-q"]) == 0
    err = capsys.readouterr().err
    assert "pathlib.Path.touch is not allowed in a geometry cache" in err
    assert not marker.exists()


def test_a_file_where_the_cache_folder_goes_costs_only_the_cache(tmp_path, capsys):
    (tmp_path / ".cache").write_text("not a folder")
    assert main(["build", *WALL, "--no-plots", "--out", str(tmp_path), "-q"]) == 0
    assert "was not written" in capsys.readouterr().err
    assert (tmp_path / WALL_ID / "run.json").is_file()


def test_a_failed_run_writes_no_cache(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("injected failure")

    monkeypatch.setattr("masonry.export.obj.blocks_obj", broken)
    monkeypatch.setenv("MASONRY_LOG_DIR", str(tmp_path / "logs"))
    assert main(["build", *WALL, "--no-plots", "--out", str(tmp_path / "out"), "-q"]) == 1
    assert not (tmp_path / "out" / ".cache").exists() or not any(
        (tmp_path / "out" / ".cache").iterdir())


def test_an_internal_failure_is_one_line_with_its_log(tmp_path, monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise RuntimeError("injected failure\nsecond line")

    monkeypatch.setattr("masonry.export.obj.blocks_obj", broken)
    monkeypatch.setenv("MASONRY_LOG_DIR", str(tmp_path / "logs"))
    assert main(["build", *WALL, "--no-plots", "--out", str(tmp_path / "out")]) == 1
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("masonry: internal error: RuntimeError: injected failure;")
    (log,) = (tmp_path / "logs").iterdir()
    assert line.endswith(str(log))
    text = log.read_text()
    assert "Traceback" in text and "injected failure" in text and "build --preset" in text


def test_not_solved_has_its_own_exit_code(tmp_path, monkeypatch, capsys):
    record = {"structure_id": WALL_ID, "scene": "wall", "weight_N": 1.0, "path": "x",
              "params": {"friction": "auto"},
              "counts": {"bricks": 1, "regular": 1, "pattern": 0, "fill_in": 0,
                         "courses": 1},
              "rbe": {"verdict": "not solved", "feasible": False, "friction": "plus",
                      "mu": 0.7, "moi": float("nan"), "moi_factor": float("nan"),
                      "residual_eq": 230.0, "solver": "newton", "status": "user_limit",
                      "time_s": 1.0}}
    # the command imports the pipeline when it runs
    monkeypatch.setattr("masonry.pipeline.run", lambda *args, **kwargs: record)
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 3
    out = capsys.readouterr().out
    assert "RBE: not solved" in out and "user_limit" in out and "MoI" not in out
    # a record without a verdict: friction+ without a finite MoI was not solved either
    del record["rbe"]["verdict"]
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 3
    record["rbe"].update(moi=12.0, moi_factor=0.1, residual_eq=1e-9)
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0
    assert "RBE: infeasible (friction-plus" in capsys.readouterr().out


def test_friction_net_on_an_infeasible_structure_suggests_auto(tmp_path, capsys):
    # a free-standing web is infeasible without tension
    assert main(["run", "--p", "5", "--boundary", "free", "--friction", "net",
                 "--no-plots", "--no-printable", "--out", str(tmp_path), "-q"]) == 0
    out = capsys.readouterr().out
    assert "RBE: infeasible (friction-net" in out and "--friction auto" in out


def test_version(capsys):
    assert main(["--version"]) == 0  # answered before the command loads
    assert capsys.readouterr().out.strip().startswith("masonry 0.")
    with pytest.raises(SystemExit) as exit_info:  # and by argparse beside other options
        main(["-q", "--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.strip().startswith("masonry 0.")


def test_a_long_stage_says_it_is_still_running(monkeypatch, caplog):
    from masonry import pipeline

    monkeypatch.setattr(pipeline, "HEARTBEAT_S", 0.02)
    timer = pipeline.Timer()
    with caplog.at_level("INFO", logger="masonry.pipeline"):
        with timer.stage("solve"):
            time.sleep(0.3)
    beats = [r.getMessage() for r in caplog.records if re.fullmatch(r"solve \.\.\. \d+ s",
                                                                      r.getMessage())]
    assert beats and timer.seconds["solve"] >= 0.3
    caplog.clear()
    time.sleep(0.1)  # the heartbeat stopped with the stage
    assert not caplog.records


def test_a_stage_study_without_plots_keeps_the_plots_of_one_with(tmp_path, capsys):
    args = ["stages", "--scene", "arch", "--blocks", "6", "--out", str(tmp_path), "-q"]
    assert main(args) == 0
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.name.startswith(".")]
    before = snapshot(folder)
    assert any(p.suffix == ".png" for p in before)
    assert main([*args, "--no-plots"]) == 0
    assert "up to date, reused" in capsys.readouterr().out
    assert snapshot(folder) == before
    assert main([*args, "--no-plots", "--force"]) == 0  # recomputed, the plots kept
    assert set(snapshot(folder)) == set(before)
    assert json.loads((folder / "run.json").read_text())["outputs"] == {
        "plots": True, "quick": False, "figure_format": ["png"], "dpi": None,
        "centering": True, "adhesion": True}
