"""Parameter studies (``masonry sweep``): Dask against serial, failures, resuming."""

import csv
import json

import pytest

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


def test_local_cluster_gives_the_serial_summary(tmp_path, study):
    pytest.importorskip("dask.distributed")
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path / "a"),
                 "-q"]) == 0
    assert main(["sweep", str(study), "--workers", "2", "--out", str(tmp_path / "b"),
                 "-q"]) == 0
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
    from masonry_cli.sweep import load_study

    first, again = load_study(path).variants(), load_study(path).variants()
    assert first == again and len(first) == 8
    assert all(1000 <= v["density"] <= 3000 for v in first)
    path.write_text(STUDY + "\nfrobnicate = [1, 2]\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "x")]) == 2
    assert "grid.frobnicate" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
