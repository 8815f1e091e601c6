"""Inputs the command once took with an internal error, or silently ignored: each now
works, or is refused before any work with one line and exit code 2, nothing written."""

import contextlib
import io
import json
import types

import pytest
from masonry_cli.app import make_parser
from masonry_cli.main import main
from test_cli_fuzz import call

from masonry.params import Params, validate
from masonry.runfolder import alone
from masonry.studies import thickness
from masonry.tolerances import MIN_SEARCH_RTOL

WALL_STUDY = ('[base]\nscene = "wall"\nwall-courses = 3\nwall-length = 12\nfast = true\n'
              '[grid]\nmu = [0.5, 0.7]\n')
OPTIMIZE = ["--maximize", "bricks", "--trials", "2", "--workers", "1", "-q"]




def refused(argv, *words):
    """``argv`` ends with exit code 2 and one line holding ``words``."""
    code, _, err = call(argv)
    assert code == 2, (argv, code, err)
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert err.startswith("masonry: error: ") and all(w in err for w in words), err
    return err


# ----------------------------------------------------------------------- optimize
def test_a_negative_seed_is_refused_before_the_journal(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(WALL_STUDY)
    out = tmp_path / "out"
    refused(["optimize", str(study), *OPTIMIZE, "--seed", "-1", "--out", str(out)],
            "--seed -1", ">= 0")
    assert not out.exists()


@pytest.mark.parametrize("content", [b"garbage{\n", b"\x00\xff\n", b'{"op_code": 99}\n'])
def test_a_corrupt_journal_is_named(tmp_path, content):
    study = tmp_path / "study.toml"
    study.write_text(WALL_STUDY)
    out = tmp_path / "out"
    out.mkdir()
    journal = out / "optimize_study.journal"
    journal.write_bytes(content)
    refused(["optimize", str(study), *OPTIMIZE, "--out", str(out)], str(journal),
            "Optuna journal")
    assert journal.read_bytes() == content and [p.name for p in out.iterdir()] == [
        journal.name]


def test_a_second_optimisation_of_a_study_at_once_is_refused(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(WALL_STUDY)
    out = tmp_path / "out"
    journal = out / "optimize_study.journal"
    with alone(journal):  # the first one, running
        refused(["optimize", str(study), *OPTIMIZE, "--out", str(out)], str(journal),
                "another process")
    assert journal.read_bytes() == b"" and [p.name for p in out.iterdir()] == [journal.name]


def test_a_scheduler_that_does_not_answer_is_refused_before_the_journal(tmp_path):
    pytest.importorskip("dask.distributed")  # its config first: set() restores to it
    import dask
    study = tmp_path / "study.toml"
    study.write_text(WALL_STUDY)
    out = tmp_path / "out"
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        refused(["optimize", str(study), *OPTIMIZE, "--scheduler", "tcp://127.0.0.1:1",
                 "--out", str(out)], "--scheduler tcp://127.0.0.1:1")
    assert not out.exists()


# ----------------------------------------------------------------------- studies
def test_two_studies_of_one_file_name_never_share_a_folder(tmp_path):
    first, second = tmp_path / "a" / "study.toml", tmp_path / "b" / "study.toml"
    for path in (first, second):
        path.parent.mkdir()
        path.write_text(WALL_STUDY)
    out = tmp_path / "out"
    assert main(["sweep", str(first), "--workers", "1", "--out", str(out), "-q"]) == 0
    summary = (out / "sweep_study" / "summary.csv").read_bytes()
    record = json.loads((out / "sweep_study" / "run.json").read_text())
    assert record["study_file"] == str(first.resolve())
    refused(["sweep", str(second), "--workers", "1", "--out", str(out), "-q"],
            str(second), str(first.resolve()))
    assert (out / "sweep_study" / "summary.csv").read_bytes() == summary
    # the same file again is the same study: it runs
    assert main(["sweep", str(first), "--workers", "1", "--out", str(out), "-q"]) == 0


# ----------------------------------------------------------------------- run
@pytest.mark.parametrize("name", ["plots", "printable", "html"])
def test_the_outputs_of_a_parameter_file_are_honoured(tmp_path, name):
    params = tmp_path / "params.toml"
    params.write_text(f'scene = "wall"\nwall_courses = 3\nwall_length = 12\nfast = true\n'
                      f'{name} = false\n')
    out = tmp_path / "out"
    assert main(["run", "--params", str(params), "--out", str(out), "-q"]) == 0
    folder = next(out.glob("wall_*"))
    record = json.loads((folder / "run.json").read_text())
    # dome.html follows the figures unless asked
    dropped = {name, "html"} if name == "plots" else {name}
    assert {k for k in ("plots", "printable", "html") if record["outputs"][k] is False} == dropped
    files = {p.name for p in folder.rglob("*")}
    written = {"plots": "00_pattern.png" in files or any(f.endswith(".png") for f in files),
               "printable": "dome.stl" in files, "html": "dome.html" in files}
    assert {k for k, v in written.items() if not v} == dropped


class ClosedPipe(io.StringIO):
    """Standard output whose reader has left (``| head -1``) after ``lines`` lines."""

    def __init__(self, lines=1):
        super().__init__()
        self.left = lines

    def write(self, text):
        if self.left <= 0:
            raise BrokenPipeError(32, "Broken pipe")
        self.left -= text.count("\n")
        return super().write(text)


def test_a_reader_that_leaves_ends_nothing(tmp_path):
    out, err = ClosedPipe(lines=1), io.StringIO()
    argv = ["run", "--preset", "wall", "--wall-courses", "3", "--wall-length", "12",
            "--fast", "--no-plots", "--no-printable", "--out", str(tmp_path)]
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    assert code == 0 and err.getvalue() == ""
    assert len(out.getvalue().splitlines()) == 1  # the first line, then nothing
    record = json.loads(next(tmp_path.glob("wall_*/run.json")).read_text())
    assert record["complete"] is True and record["rbe"]["verdict"] == "feasible"


# ----------------------------------------------------------------------- arch-thickness
def test_arch_thickness_offers_only_the_solvers_it_takes():
    parser = make_parser(["arch-thickness"])._subparsers._group_actions[0].choices[
        "arch-thickness"]
    solver = next(a for a in parser._actions if a.dest == "solver")
    assert set(solver.choices) == {"newton", "interior", "clarabel", "osqp",
                                   "clarabel-cvxpy", "osqp-cvxpy"}
    assert "highs" not in parser.format_help()


@pytest.mark.parametrize("bracket", [(0.01, 0.8), (0.0021, 0.05)])
def test_the_thickness_bisection_stops_at_machine_precision(monkeypatch, bracket):
    # a stand-in verdict with a known threshold: the search itself is what is tested
    params = validate(Params.of(scene="arch", arch_blocks=8))
    radius = thickness.arch_radius("semicircular", params.geometry.arch_span, None)[0]
    threshold = bracket[0] * (bracket[1] / bracket[0]) ** 0.3141592653589793
    monkeypatch.setattr(thickness, "is_feasible",
                        lambda p: p.geometry.arch_thickness / radius >= threshold)
    result = thickness.minimum_thickness(params, rtol=MIN_SEARCH_RTOL, bracket=bracket)
    assert result.lower < threshold * (1 + 1e-12) and result.t_over_r >= threshold * (
        1 - 1e-12)
    assert result.t_over_r / result.lower - 1 <= MIN_SEARCH_RTOL
    assert len(result.steps) < 70  # log2(ln(hi/lo) / 1e-15) + 2 is at most 61


def test_fewer_than_four_voussoirs_are_refused_before_any_solve(monkeypatch):
    monkeypatch.setattr(thickness, "is_feasible", types.SimpleNamespace)  # never called
    params = validate(Params.of(scene="arch", arch_blocks=3))
    with pytest.raises(Exception, match="at least 4 voussoirs") as info:
        thickness.minimum_thickness(params)
    assert info.value.name == "arch_blocks"


# ----------------------------------------------------------------------- analyze
def test_a_domes_own_bricks_analysed_back_without_the_printable_body(tmp_path, caplog):
    # the dome's bricks read from its OBJ touch along slivers that make no printable
    # body: the body is skipped with one warning, the analysis gives the run's verdict
    dome = ["--scene", "dome", "--n", "6", "--r", "0", "--p", "3", "--cut", "0.5", "--fast",
            "--no-plots"]
    assert main(["run", *dome, "--no-printable", "--out", str(tmp_path / "run"), "-q"]) == 0
    run = json.loads(next(tmp_path.glob("run/*/run.json")).read_text())
    bricks = next(tmp_path.glob("run/*/bricks.obj"))
    code, _out, err = call(["analyze", str(bricks), "--support", "*_ground_*", "--fast",
                           "--no-plots", "--out", str(tmp_path / "analyze"), "-q"])
    assert code == 0 and "Traceback" not in err, err
    assert len(err.strip().splitlines()) == 1 and "printable body skipped" in err, err
    record = json.loads(next(tmp_path.glob("analyze/*/run.json")).read_text())
    assert record["rbe"]["verdict"] == run["rbe"]["verdict"] == "feasible"
    assert record["weight_N"] == pytest.approx(run["weight_N"], rel=1e-9)
    assert record["outputs"]["printable"] is False and "skipped" in record["printable"]
    folder = next(tmp_path.glob("analyze/*"))
    assert (folder / "RBE" / "forces.csv").is_file() and not (folder / "dome.stl").exists()


@pytest.mark.parametrize("value", ['"cdn"', "true"])
def test_a_study_asks_where_the_page_finds_plotly_by_name(tmp_path, capsys, value):
    """``[outputs] html_plotly`` is ``shared`` or ``inline``: anything else is refused in
    one line naming the file's key, before anything is written."""
    study = tmp_path / "study.toml"
    study.write_text(f'[base]\nscene = "wall"\n[grid]\nmu = [0.7]\n'
                     f'[outputs]\nhtml_plotly = {value}\n')
    out = tmp_path / "out"
    assert main(["sweep", str(study), "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "outputs.html_plotly" in err[0] and "shared, inline" in err[0]
    assert not out.exists()
