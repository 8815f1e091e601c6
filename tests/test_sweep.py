"""Parameter studies (``masonry sweep``): Dask against serial, failures, resuming."""

import csv
import json

import pytest

import masonry

from masonry import forking
from masonry.studies import workers
from masonry.studies.sweep import on_grid, sample_step
from masonry_cli.main import main

STUDY = """
[base]
preset = "wall"
wall-courses = 3
wall-length = 12

[grid]
mu = [0.3, 0.7]
friction = ["net", "plus"]
"""


def _summary(root, name="study"):
    with open(root / f"sweep_{name}" / "summary.csv") as f:
        return list(csv.DictReader(f))


def _results(rows):
    keep = ("mu", "friction", "variant", "feasible", "friction_used", "moi_factor",
            "weight_N", "bricks", "interfaces", "structure_id", "error")
    return [{k: row[k] for k in keep} for row in rows]


@pytest.fixture
def study(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    return path


@pytest.mark.slow
def test_local_cluster_gives_the_serial_summary(tmp_path, study, capfd):
    pytest.importorskip("dask.distributed")
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path / "a"),
                 "-q"]) == 0
    capfd.readouterr()
    assert main(["sweep", str(study), "--workers", "2", "--out", str(tmp_path / "b"),
                 "-q"]) == 0
    err = capfd.readouterr().err  # the workers' stderr too: their file descriptor
    assert "Traceback" not in err and "CommClosedError" not in err, err
    serial, parallel = _summary(tmp_path / "a"), _summary(tmp_path / "b")
    assert len(serial) == 4 and all(r["status"] == "computed" for r in serial)
    assert _results(parallel) == _results(serial)
    # every variant is an ordinary run folder; the study's folder says what it holds
    for row in serial:
        assert (tmp_path / "a" / row["structure_id"] / "run.json").is_file()
    record = json.loads((tmp_path / "a" / "sweep_study" / "run.json").read_text())
    assert record["complete"] is True and record["variants"]["computed"] == 4
    assert record["study"]["grid"] == {"mu": [0.3, 0.7], "friction": ["net", "plus"]}


def test_a_failing_variant_is_recorded_the_rest_complete_and_the_exit_says_so(
        tmp_path, study, monkeypatch):
    import masonry.studies.sweep as sweep

    def run(params, *args, **kwargs):
        if params.analysis.mu == 0.3:
            raise MemoryError("no memory for this variant")
        return real(params, *args, **kwargs)

    real = sweep.run
    monkeypatch.setattr(sweep, "run", run)
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path), "-q"]) == 3
    rows = _summary(tmp_path)
    failed = [r for r in rows if r["status"] == "failed"]
    assert len(failed) == 2 and all("no memory" in r["error"] for r in failed)
    assert sum(r["status"] == "computed" for r in rows) == 2
    # the summary's figures still drawn, one per swept input
    assert {"moi_factor_mu.png", "moi_factor_friction.png"} <= {
        p.name for p in (tmp_path / "sweep_study").iterdir()}


def test_a_summary_of_swept_text_inputs_reads_back_typed(tmp_path):
    """Point loads, a lateral azimuth or ``all``, a friction model and a pattern swept:
    summary.csv reads back with each input in its declared type (text, integers,
    floats), as every file the project writes."""
    path = tmp_path / "texts.toml"
    path.write_text('[base]\nscene = "arch"\nblocks = 6\n[grid]\n'
                    'point-load = ["v003:0,0,-100", "v00*:0,0,-10"]\n'
                    'friction-cone = ["circle", "polygon:16"]\n')
    assert main(["sweep", str(path), "--workers", "1", "--out", str(tmp_path), "-q"]) == 0
    table = masonry.read_table(tmp_path / "sweep_texts" / "summary.csv")
    assert set(table["point_loads"]) == {"v003:0,0,-100", "v00*:0,0,-10"}
    assert set(table["friction_cone"]) == {"circle", "polygon:16"}
    assert str(table["bricks"].dtype) == "Int64" and table["feasible"].dtype == "boolean"
    assert table["weight_N"].dtype == "float64"


@pytest.mark.parametrize("values, shown", [("[0.7, -1.0]", "grid.mu = -1.0"),
                                           ('[0.7, "x"]', "grid.mu = 'x'")])
def test_a_variant_masonry_run_would_refuse_stops_the_study_first(tmp_path, capsys,
                                                                  values, shown):
    path = tmp_path / "bad.toml"
    path.write_text(STUDY.replace("mu = [0.3, 0.7]", f"mu = {values}"))
    assert main(["sweep", str(path), "--workers", "1", "--out", str(tmp_path / "x")]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and f"bad.toml: {shown}: expected" in error[0]
    assert not (tmp_path / "x").exists()


def test_interrupted_study_resumes_with_only_the_missing_variants(tmp_path, study,
                                                                  monkeypatch):
    import masonry.studies.sweep as sweep

    real = sweep.run_variant
    calls = []

    def interrupted(inputs, *args, **kwargs):
        if len(calls) == 2:
            raise KeyboardInterrupt
        calls.append(inputs)
        return real(inputs, *args, **kwargs)

    monkeypatch.setattr(sweep, "run_variant", interrupted)
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path), "-q"]) == 130
    assert not (tmp_path / "sweep_study").exists()  # no summary of an unfinished study
    monkeypatch.setattr(sweep, "run_variant", real)
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path), "-q"]) == 0
    status = [r["status"] for r in _summary(tmp_path)]
    assert status.count("reused") == 2 and status.count("computed") == 2


def test_samples_are_seeded_and_bad_names_refused(tmp_path, capsys):
    path = tmp_path / "sampled.toml"
    path.write_text(STUDY + "\n[sample]\ncount = 2\nseed = 3\ndensity = [1000.0, 3000.0]\n")
    from masonry.studies.study_file import load_study

    first, again = load_study(path).variants(), load_study(path).variants()
    assert first == again and len(first) == 8
    assert all(1000 <= v["density"] <= 3000 for v in first)
    # steps of 1 for a range 2000 wide: three digits finer than its width
    assert all(v["density"] == round(v["density"]) for v in first)
    assert len({v["density"] for v in first}) == 2
    path.write_text(STUDY + "\nfrobnicate = [1, 2]\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "x")]) == 2
    assert "grid.frobnicate" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("low, high, value, step, on", [
    (0.4, 1.0, 0.73419062, 1e-4, 0.7342), (0.1, 0.7, 0.30000004, 1e-4, 0.3),
    (1000.0, 3000.0, 1234.5678, 1.0, 1235.0), (0.0, 0.05, 0.05, 1e-5, 0.05),
    (2.0, 2.0, 2.0, 0.0, 2.0)])
def test_a_sampled_float_lies_on_its_ranges_grid(low, high, value, step, on):
    """Three digits finer than the range's width, within the range, to 12 digits."""
    assert sample_step(low, high) == pytest.approx(step, rel=1e-12)
    assert on_grid(value, low, high) == on


# ---------------------------------------------------------------------- stages
SMALL_DOME = {"preset": "1", "n": 4, "p": 3, "r": 1}  # tests/test_stages.py: a 73-brick web


def _stage_study(tmp_path, grid, outputs, base=SMALL_DOME):
    lines = ["[base]", *[f"{k} = {v!r}" for k, v in base.items()], "[grid]",
             *[f"{k} = {v!r}" for k, v in grid.items()], "[outputs]",
             *[f"{k} = {v!r}" for k, v in outputs.items()]]
    path = tmp_path / "staged.toml"
    path.write_text("\n".join(lines).replace("'", '"') + "\n")
    assert main(["sweep", str(path), "--workers", "1", "--out", str(tmp_path / "sweep"),
                 "-q"]) == 0
    return _summary(tmp_path / "sweep", "staged")


def _stages_alone(tmp_path, *args):
    """``masonry stages`` of the same variant in a root of its own: its stages.csv rows
    and its run.json."""
    out = tmp_path / f"alone{len(list(tmp_path.glob('alone*')))}"
    assert main(["stages", *args, "--no-plots", "--out", str(out), "-q"]) == 0
    (folder,) = out.glob("*_stages_*")
    with open(folder / "stages.csv") as f:
        return list(csv.DictReader(f)), json.loads((folder / "run.json").read_text())


def _expected(rows):
    """The sweep's stage columns from a stage study's stages.csv, by hand."""
    failing = [r for r in rows if r["feasible"] == "False"]
    top = max(rows, key=lambda r: float(r["centering_N"]))
    adhesion = max(float(r["adhesion_kPa"]) for r in rows)
    return {"stages": str(len(rows)), "stages_standing": str(len(rows) - len(failing)),
            "first_unsupported_stage": failing[0]["stage"] if failing else "",
            "first_unsupported_course": failing[0]["course"] if failing else "",
            "centering_max_N": float(top["centering_N"]),
            "centering_max_fraction": float(top["centering_fraction"]),
            "adhesion_max_kPa": adhesion}


STAGE_TEXT = ("stages", "stages_standing", "first_unsupported_stage",
              "first_unsupported_course")
STAGE_NUMBERS = ("centering_max_N", "centering_max_fraction", "adhesion_max_kPa")


def _assert_stage_columns(row, expected):
    """The summary row's stage columns equal ``expected``: the counts and names as
    written, the forces to the printed digits."""
    assert {k: row[k] for k in STAGE_TEXT} == {k: expected[k] for k in STAGE_TEXT}
    numbers = {k: float(row[k]) for k in STAGE_NUMBERS}
    assert numbers == pytest.approx({k: expected[k] for k in STAGE_NUMBERS}, rel=1e-9)


@pytest.mark.slow
def test_a_sweep_of_course_stages_gives_the_columns_of_masonry_stages(tmp_path):
    """The small dome by course at mu 0.1 (stages 5-11 need support) and 0.7 (all
    stand): the summary's stage columns equal those ``masonry stages`` writes for the
    same variant (a section laid cyclic in both), to the printed digits."""
    rows = _stage_study(tmp_path, {"mu": [0.1, 0.7]}, {"stages": "course"})
    assert [r["status"] for r in rows] == ["computed", "computed"]
    for row, mu in zip(rows, ("0.1", "0.7")):
        alone, record = _stages_alone(tmp_path, "--preset", "1", "--n", "4", "--p", "3",
                                      "--r", "1", "--mu", mu)
        assert record["params"]["boundary"] == "cyclic"
        expected = _expected(alone)
        _assert_stage_columns(row, expected)
        assert row["first_unsupported_brick"] == row["stages_load_factor_min"] == ""
    low, high = rows
    assert low["first_unsupported_course"] == "5" and float(low["centering_max_N"]) > 0
    assert high["stages_standing"] == "11" and high["first_unsupported_course"] == ""
    assert float(high["centering_max_N"]) == 0.0
    # the least adhesion: some at mu 0.1, on a course that needs support; none at 0.7
    assert float(low["adhesion_max_kPa"]) > 0 and int(low["adhesion_max_course"]) >= 5
    assert float(high["adhesion_max_kPa"]) == 0.0 and high["adhesion_max_course"] == ""
    # the run of the variant itself: a free-standing web, its own centering force
    assert float(low["centering_N"]) > 0 and low["feasible"] == "False"


def test_a_sweep_of_brick_stages_names_the_first_brick_that_needs_support(tmp_path):
    """Course 9 of the small dome brick by brick at mu 0.2 (its course stage 9 is the
    first that needs support): the brick's rank on the course is the stage's number."""
    (row,) = _stage_study(tmp_path, {"mu": [0.2]},
                          {"stages": "brick", "stages_course": 9})
    alone, record = _stages_alone(tmp_path, "--preset", "1", "--n", "4", "--p", "3", "--r",
                                  "1", "--mu", "0.2", "--by", "brick", "--course", "9")
    expected = _expected(alone)
    _assert_stage_columns(row, expected)
    assert row["first_unsupported_course"] == "9"
    assert row["first_unsupported_brick"] == expected["first_unsupported_stage"] != ""
    assert record["stages"]["first_unsupported"]["brick"] == int(row["first_unsupported_brick"])


def test_a_sweep_of_stages_under_a_lateral_load_gives_the_worst_stage(tmp_path):
    """The 72-brick dome (tests/test_collapse.py) under a lateral load at 0 degrees: the
    smallest load factor over its four course stages, as ``masonry stages`` finds it
    (docs/stages.md: 0.7000, 0.6867, 0.6690, 0.6845)."""
    dome = {"stretch": 1.0, "n": 6, "r": 0, "p": 3, "cut": 0.5}
    (row,) = _stage_study(tmp_path, {"mu": [0.7]}, {"stages": "course"},
                          base={"preset": "1", **dome, "scene": "dome", "lateral": "0"})
    alone, _ = _stages_alone(tmp_path, "--preset", "1", *[f"--{k}={v}" for k, v in
                                                          dome.items()],
                             "--scene", "dome", "--lateral", "0")
    factors = [float(r["load_factor"]) for r in alone if r["load_factor"]]
    assert len(factors) == 4 and row["stages_standing"] == "4"
    assert float(row["stages_load_factor_min"]) == pytest.approx(min(factors), rel=1e-9)
    assert float(row["stages_load_factor_min"]) == pytest.approx(0.6690, abs=5e-5)


@pytest.mark.parametrize("outputs, shown", [
    ('stages = "height"', "outputs.stages = 'height'"),
    ('stages = "brick"\nstages_course = 0', "outputs.stages_course = 0"),
    ('stages = "course"\nstages_course = 3', "outputs.stages_course = 3"),
    ('stages = "brick"\nstages_course = 3\nstages_order = "z"', "outputs.stages_order = 'z'"),
    ('stages_course = 3', "outputs.stages_course = 3"),
])
def test_bad_stage_outputs_are_refused_before_any_run(tmp_path, capsys, outputs, shown):
    path = tmp_path / "bad.toml"
    path.write_text(STUDY + f"\n[outputs]\n{outputs}\n")
    assert main(["sweep", str(path), "--workers", "1", "--out", str(tmp_path / "x")]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and f"bad.toml: {shown}: expected" in error[0]
    assert not (tmp_path / "x").exists()


def test_stages_that_masonry_stages_refuses_stop_the_study_first(tmp_path, capsys):
    """A lateral load on the section, which its stages analyse cyclic, and an arch laid
    by course are refused as ``masonry stages`` refuses them, naming where they came
    from."""
    path = tmp_path / "bad.toml"
    path.write_text('[base]\npreset = "1"\nlateral = "0"\n[grid]\nmu = [0.7]\n'
                    '[outputs]\nstages = "course"\n')
    assert main(["sweep", str(path), "--workers", "1", "--out", str(tmp_path / "x")]) == 2
    assert "bad.toml: base.lateral" in capsys.readouterr().err
    path.write_text('[base]\nscene = "arch"\n[grid]\nmu = [0.7]\n[outputs]\n'
                    'stages = "course"\n')
    assert main(["sweep", str(path), "--workers", "1", "--out", str(tmp_path / "x")]) == 2
    assert "bad.toml: outputs.stages = 'course'" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_few_or_small_variants_run_serially_and_a_large_study_on_every_core(monkeypatch):
    monkeypatch.setattr(forking, "cores", lambda: 4)
    line = workers.DASK_MIN_BRICKS
    assert workers.local_workers([90.0] * 4) == 1  # four walls of 90 bricks
    assert workers.local_workers([line / 2, line / 2 - 1]) == 1
    assert workers.local_workers([line / 2, line / 2]) == 4
    assert workers.local_workers([2.0 * line]) == 1  # one variant: nothing to share
    assert workers.local_workers([90.0] * 4, workers=2) == 2  # asked for: Dask
    assert workers.local_workers([2.0 * line] * 8, workers=1) == 1
    monkeypatch.setattr(forking, "cores", lambda: 1)
    assert workers.local_workers([line] * 8) == 1


def test_a_variant_is_estimated_at_its_blocks():
    # an arch has exactly its voussoirs
    assert workers.estimated_bricks({"scene": "arch", "arch_blocks": 12}) == 12
    assert workers.estimated_bricks({"scene": "arch", "arch_blocks": 31}) == 31


def test_a_sweep_without_workers_runs_small_studies_serially(tmp_path, study,
                                                             monkeypatch):
    import masonry.studies.sweep as sweep

    asked = []
    execute = sweep.execute

    def recorded(study, out_root, workers=1, scheduler=None):
        asked.append((workers, scheduler))
        return execute(study, out_root, workers, scheduler)

    monkeypatch.setattr(sweep, "execute", recorded)
    monkeypatch.setattr(forking, "cores", lambda: 4)
    assert main(["sweep", str(study), "--out", str(tmp_path), "-q"]) == 0
    assert asked == [(1, None)]


def test_benign_closed_connections_are_dropped_as_dask_stops_and_nothing_else(capsys):
    import logging

    pytest.importorskip("dask.distributed")
    from distributed.comm.core import CommClosedError

    log, dask = logging.getLogger("distributed.client"), logging.getLogger("distributed")
    handler = logging.StreamHandler()  # on sys.stderr: capsys's
    # only this handler hears them: an earlier test's cluster may have left its own, on a
    # stream since closed
    held = [(logger, logger.handlers[:], logger.propagate) for logger in (log, dask)]
    log.handlers, dask.handlers, dask.propagate = [], [handler], False
    try:
        with workers.quiet_shutdown(), pytest.raises(CommClosedError):
            try:
                raise CommClosedError("in <TCP (closed) Client->Scheduler>: Stream is closed")
            except CommClosedError:
                log.exception("Failed to reconnect to scheduler")
                log.error("a real failure")
                handler.flush()
                raise
    finally:
        for logger, handlers, propagate in held:
            logger.handlers, logger.propagate = handlers, propagate
    err = capsys.readouterr().err
    assert "a real failure" in err and "CommClosedError" not in err
