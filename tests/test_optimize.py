"""Optimisation (``masonry optimize``): the optimum an exhaustive sweep finds, constraints,
several objectives, resuming, bad input."""

import csv
import json

import numpy as np
import pytest

from masonry_cli.main import main

pytest.importorskip("optuna")

# 15 semicircular, pointed and segmental arches of 6 to 16 voussoirs (0.2 to 0.5 s
# each) under a lateral load: the collapse load factor lambda is cheap and uneven in
# the number of voussoirs
ARCHES = """
[base]
scene = "arch"
lateral = 0
[grid]
shape = ["semicircular", "pointed", "segmental"]
blocks = [6, 8, 10, 12, 16]
"""

FLOATS = ("load_factor", "weight_N", "bricks")


def _read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def _optimize(study, out, *options, plots=False):
    return main(["optimize", str(study), *options, "--workers", "1", "--out", str(out),
                 "-q", *([] if plots else ["--no-plots"])])


@pytest.fixture
def arches(tmp_path):
    path = tmp_path / "arches.toml"
    path.write_text(ARCHES + "[constraints]\nbricks = [8, 12]\n")
    return path


@pytest.mark.slow
def test_the_optimum_an_exhaustive_sweep_finds_in_fewer_trials(tmp_path, arches, capsys):
    assert main(["sweep", str(arches), "--workers", "1", "--out", str(tmp_path), "-q"]) == 0
    grid = _read(tmp_path / "sweep_arches" / "summary.csv")
    assert len(grid) == 15 and all(r["status"] == "computed" for r in grid)
    met = [r for r in grid if r["constraints_met"] == "True"]
    assert {int(r["bricks"]) for r in met} == {8, 10, 12}
    for option, pick in (("--maximize", max), ("--minimize", min)):
        expected = pick(met, key=lambda r: float(r["load_factor"]))
        # 12 of the 15 variants (the first 10 at random, TPE's start), seed 0; the
        # variants are the sweep's run folders, reused
        assert _optimize(arches, tmp_path, option, "load_factor", "--trials", "12",
                         plots=option == "--minimize") == 0
        out = capsys.readouterr().out
        trials = _read(tmp_path / "optimize_arches" / "trials.csv")
        assert len(trials) == 12 and all(r["status"] == "reused" for r in trials)
        assert len({(r["arch_shape"], r["arch_blocks"]) for r in trials}) == 12
        best = [r for r in trials if r["best"] == "True"]
        assert len(best) == 1 and best[0]["structure_id"] == expected["structure_id"]
        assert best[0]["load_factor"] == expected["load_factor"]
        assert expected["structure_id"] in out
        # the best variant's run folder has its plots, unless --no-plots
        record = json.loads((tmp_path / expected["structure_id"] / "run.json").read_text())
        assert record["outputs"]["plots"] is (option == "--minimize")
        assert (tmp_path / "optimize_arches" / "convergence.png").stat().st_size > 10_000


@pytest.mark.slow
def test_every_variant_once_then_the_search_stops(tmp_path, arches):
    assert _optimize(arches, tmp_path, "--minimize", "weight_N", "--trials", "40") == 0
    trials = _read(tmp_path / "optimize_arches" / "trials.csv")
    assert sorted((r["arch_shape"], int(r["arch_blocks"])) for r in trials) == sorted(
        (s, b) for s in ("semicircular", "pointed", "segmental") for b in (6, 8, 10, 12, 16))
    record = json.loads((tmp_path / "optimize_arches" / "run.json").read_text())
    assert record["trials"]["finished"] == 15 and record["trials"]["asked"] == 40
    met = [r for r in trials if r["constraints_met"] == "True"]
    lightest = min(met, key=lambda r: float(r["weight_N"]))
    assert [r["trial"] for r in trials if r["best"] == "True"] == [lightest["trial"]]
    assert record["best"][0]["values"]["weight_N"] == pytest.approx(
        float(lightest["weight_N"]), rel=1e-9)


def test_two_objectives_give_the_pareto_front_of_the_trials(tmp_path):
    path = tmp_path / "thick.toml"
    path.write_text(ARCHES.replace("blocks = [6, 8, 10, 12, 16]", "blocks = [8, 12]")
                    + "[sample]\nthickness = [0.5, 1.0]\n")
    assert _optimize(path, tmp_path, "--maximize", "load_factor", "--minimize", "weight_N",
                     "--trials", "8", "--seed", "3") == 0
    trials = _read(tmp_path / "optimize_thick" / "trials.csv")
    assert len(trials) == 8
    assert all(0.5 <= float(r["arch_thickness"]) <= 1.0 for r in trials)
    # on the range's grid (steps of 0.0001 for a width of 0.5), as a person writes them
    assert all(abs(1e4 * float(r["arch_thickness"]) - round(1e4 * float(r["arch_thickness"])))
               < 1e-6 for r in trials)
    points = {r["trial"]: np.array([float(r["load_factor"]), -float(r["weight_N"])])
              for r in trials if r["load_factor"]}
    front = [t for t, p in points.items()
             if not any(np.all(q >= p) and np.any(q > p) for q in points.values())]
    assert sorted(r["trial"] for r in trials if r["best"] == "True") == sorted(front)
    record = json.loads((tmp_path / "optimize_thick" / "run.json").read_text())
    assert len(record["best"]) == len(front)
    assert record["optimisation"]["objectives"] == [["load_factor", "maximize"],
                                                   ["weight_N", "minimize"]]


@pytest.mark.slow
def test_an_interrupted_optimisation_resumes_to_the_same_trials(tmp_path, monkeypatch):
    import masonry.studies.sweep as sweep

    path = tmp_path / "thick.toml"
    path.write_text(ARCHES + "[sample]\nthickness = [0.5, 1.0]\n")
    options = ("--maximize", "load_factor", "--trials", "12", "--batch", "4")
    assert _optimize(path, tmp_path / "a", *options) == 0
    real, calls = sweep.run_variant, []

    def interrupted(*args, **kwargs):
        if len(calls) == 10:  # in the third batch: after TPE's 10 random trials
            raise KeyboardInterrupt
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(sweep, "run_variant", interrupted)
    assert _optimize(path, tmp_path / "b", *options) == 130
    assert not (tmp_path / "b" / "optimize_thick").exists()
    calls.clear()
    monkeypatch.setattr(sweep, "run_variant", lambda *args, **kwargs: (
        calls.append(args), real(*args, **kwargs))[1])
    assert _optimize(path, tmp_path / "b", *options) == 0
    keep = ("trial", "arch_shape", "arch_blocks", "arch_thickness", "load_factor", "best")
    first, resumed = (_read(tmp_path / r / "optimize_thick" / "trials.csv") for r in "ab")
    assert [{k: r[k] for k in keep} for r in resumed] == [{k: r[k] for k in keep}
                                                          for r in first]
    assert len(calls) == 2  # the two unfinished trials


@pytest.mark.parametrize("options, study, shown", [
    (("--maximize", "frobnicate"), ARCHES, "--maximize frobnicate: expected a result column"),
    (("--minimize", "structure_id"), ARCHES, "--minimize structure_id: expected a result"),
    (("--trials", "5"), ARCHES, "--maximize: expected --maximize COLUMN or --minimize"),
    (("--maximize", "bricks", "--trials", "0"), ARCHES, "--trials 0: expected an integer"),
    (("--maximize", "bricks", "--minimize", "bricks"), ARCHES, "--minimize bricks: expected "
                                                               "each column once"),
    (("--maximize", "bricks"), "[base]\nscene = 'arch'\n", "no [grid] or [sample]"),
    (("--maximize", "bricks"), ARCHES + "[constraints]\nbrick = [1, 2]\n",
     "constraints.brick = [1, 2]: expected a result column"),
    (("--maximize", "bricks"), ARCHES + "[constraints]\nbricks = [2, 1]\n",
     "constraints.bricks = [2, 1]: expected [low, high]"),
    (("--maximize", "bricks"), ARCHES + "[sample]\nthickness = [0.5, 90.0]\n",
     "sample.thickness = 90.0: expected"),
])
def test_bad_input_is_one_line_before_any_work(tmp_path, capsys, options, study, shown):
    path = tmp_path / "bad.toml"
    path.write_text(study)
    assert _optimize(path, tmp_path / "x", *options) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and shown in error[0], error
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_the_first_course_that_needs_support_is_latest_where_none_does(tmp_path):
    """The small dome's course stages (a section laid cyclic) at mu 0.1, 0.3 and 0.7:
    at 0.3 and 0.7 every stage stands (first_unsupported_course empty, read as
    infinite), the latest first course that needs support; at 0.1 it is course 5."""
    path = tmp_path / "stages.toml"
    path.write_text('[base]\npreset = 1\nn = 4\np = 3\nr = 1\n[grid]\nmu = [0.1, 0.3, 0.7]\n'
                    '[outputs]\nstages = "course"\n')
    assert _optimize(path, tmp_path, "--maximize", "first_unsupported_course",
                     "--trials", "3") == 0
    trials = {r["mu"]: r for r in _read(tmp_path / "optimize_stages" / "trials.csv")}
    assert trials["0.1"]["first_unsupported_course"] == "5"
    assert trials["0.7"]["first_unsupported_course"] == ""
    assert trials["0.7"]["stages_standing"] == trials["0.7"]["stages"] == "11"
    # the first trial of the best value: 0.3 or 0.7, whichever was asked first
    best = [r for r in trials.values() if r["best"] == "True"]
    assert len(best) == 1 and best[0]["mu"] in ("0.3", "0.7")
    assert best[0]["first_unsupported_course"] == ""
    assert int(best[0]["trial"]) == min(int(trials[mu]["trial"]) for mu in ("0.3", "0.7"))


@pytest.mark.slow
def test_the_least_adhesion_over_the_stages_is_least_where_every_stage_stands(tmp_path):
    """The small dome's course stages at mu 0.1 (courses 5 to 11 need support, so
    adhesion) and 0.7 (every stage stands dry: 0 kPa): minimizing ``adhesion_max_kPa``
    picks 0.7, and the trials' column reads back typed."""
    import masonry

    path = tmp_path / "stages.toml"
    path.write_text('[base]\npreset = 1\nn = 4\np = 3\nr = 1\n[grid]\nmu = [0.1, 0.7]\n'
                    '[outputs]\nstages = "course"\n')
    assert _optimize(path, tmp_path, "--minimize", "adhesion_max_kPa", "--trials", "2") == 0
    trials = masonry.read_table(tmp_path / "optimize_stages" / "trials.csv")
    assert trials["adhesion_max_course"].dtype == "Int64"
    by_mu = trials.set_index("mu")
    assert by_mu.loc[0.1, "adhesion_max_kPa"] > 0 and by_mu.loc[0.7, "adhesion_max_kPa"] == 0
    assert bool(by_mu.loc[0.7, "best"]) and not bool(by_mu.loc[0.1, "best"])


def test_a_column_empty_when_every_stage_stands_measures_infinite():
    from masonry.studies.sweep import measure

    stands = {"status": "computed", "stages": 11, "stages_standing": 11,
              "first_unsupported_course": None, "load_factor": None, "feasible": True}
    assert measure(stands, "first_unsupported_course") == float("inf")
    assert measure(stands, "load_factor") is None and measure(stands, "feasible") == 1.0
    assert measure({**stands, "stages_standing": 10}, "first_unsupported_course") is None
    assert measure({**stands, "status": "failed"}, "feasible") is None


def test_columns_are_named_as_summary_csv_names_them(tmp_path):
    from masonry.studies.optimize import Search

    from masonry.studies.study_file import load_study

    path = tmp_path / "named.toml"
    path.write_text(ARCHES + "[constraints]\nmoi_N = [0, 1e6]\n")
    study = load_study(path, draws=False)
    assert study.constraints == {"moi": [0, 1e6]}
    search = Search(study, (("moi_N", "minimize"), ("bricks", "maximize"))).checked()
    assert search.objectives == (("moi", "minimize"), ("bricks", "maximize"))
