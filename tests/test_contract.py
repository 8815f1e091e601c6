"""The contract every scene kind keeps (docs/model.md 6.4, 6.11): a run's result, solved on
a half or a cyclic section, is the whole model's; its residuals, recomputed on the whole,
meet the acceptance tolerance; every CSV of its folder reads back typed; and its
``bricks.obj``, analysed again by ``masonry analyze``, gives the run's verdict.

The whole is solved independently here, on its own matrices (no half, no cyclic images):
the RBE's optimum is unique, so the forces agree to the accurate preset's Newton
accuracy; collapse load factors to the LP's (1e-6 relative, docs/collapse.md "Solver")."""

import json

import numpy as np
import pandas as pd
import pytest

import masonry
from masonry.params import Params, validate
from masonry.pipeline import Timer, build_model, collapse_of, solve
from masonry.rbe.collapse import collapse_load
from masonry.rbe.solve import RBEProblem
from masonry.tolerances import ACCEPT_RESIDUAL
from masonry_cli.main import main

pytestmark = pytest.mark.slow

FORCE_REL = 1e-6
"""Forces of the unique RBE optimum, relative to the largest (accurate preset)."""
FACTOR_REL = 1e-6
"""The collapse LP's documented accuracy on the factor."""

DOMES = {"cut 0.5": dict(n=6, r=0, p=3, cut=0.5), "cut 0": dict(n=8, r=0, p=4, cut=0.0)}
OF_REVOLUTION = dict(radius=20, p=2)

SCENES = {
    **{f"section free, {k}": dict(scene="section", boundary="free", **v)
       for k, v in DOMES.items()},
    **{f"section cyclic, {k}": dict(scene="section", boundary="cyclic", **v)
       for k, v in DOMES.items()},
    **{f"section rigid, {k}": dict(scene="section", boundary="rigid", **v)
       for k, v in DOMES.items()},
    **{f"dome, {k}": dict(scene="dome", **v) for k, v in DOMES.items()},
    "revolution": dict(scene="revolution", **OF_REVOLUTION),
    "sector cyclic": dict(scene="sector", boundary="cyclic", **OF_REVOLUTION),
    "arch": dict(scene="arch"),
    "wall": dict(scene="wall"),
}

WHOLE_OF = {"section cyclic": "dome", "sector cyclic": "revolution"}
"""The scene a cyclic model stands for: the same verdict and weight per copy."""


def params_of(inputs, **more):
    return validate(Params.of(**{**inputs, **more, "accuracy": "accurate"}))


def whole_rbe(model, params):
    analysis = params.analysis
    return RBEProblem(model.blocks, model.interfaces, **model.assembly).solve(
        mu=analysis.mu, density=analysis.density, accuracy="accurate",
        cone=analysis.friction_cone)


def options_of(inputs) -> list:
    return [f"--{key.replace('_', '-')}={value}" for key, value in inputs.items()]


@pytest.fixture(scope="module", params=list(SCENES), ids=list(SCENES))
def scene_run(request, tmp_path_factory):
    """A run of the scene (no plots, no printable body) and its folder."""
    inputs = SCENES[request.param]
    out = tmp_path_factory.mktemp("run")
    assert main(["run", *options_of(inputs), "--accuracy", "accurate", "--no-plots",
                 "--no-printable", "-q", "--out", str(out)]) == 0
    (record_path,) = out.glob("*/run.json")
    return request.param, json.loads(record_path.read_text()), record_path.parent


@pytest.mark.parametrize("cone", ["circle", "polygon:16", "square"])
def test_the_run_solved_as_reduced_is_the_whole(scene_run, cone):
    """Self weight under each friction model: the pipeline's answer (on a half where the
    scene has a mirror plane and the model is the cone) equals the whole's, with
    residuals recomputed on the whole within the acceptance tolerance."""
    name, _, _ = scene_run
    params = params_of(SCENES[name], friction_cone=cone)
    model = build_model(params)[1]
    ran = solve(model, params, Timer())
    whole = whole_rbe(model, params)
    assert ran.verdict == whole.verdict
    assert ran.checked()
    assert ran.residual_eq <= ACCEPT_RESIDUAL
    if ran.x is not None and whole.x is not None:
        assert np.abs(ran.x - whole.x).max() <= FORCE_REL * np.abs(whole.x).max()


def test_a_cyclic_model_stands_as_its_whole(scene_run):
    """A cyclic section's verdict and weight per copy are its whole dome's."""
    name, record, _ = scene_run
    kind = name.split(",")[0]
    if kind not in WHOLE_OF:
        pytest.skip("not a cyclic model")
    inputs = {**SCENES[name], "scene": WHOLE_OF[kind]}
    inputs.pop("boundary")
    params = params_of(inputs)
    model = build_model(params)[1]
    whole = whole_rbe(model, params)
    order = params.kind.symmetry(params.geometry).order
    assert record["rbe"]["verdict"] == whole.verdict
    assert record["rbe"]["weight_N"] == pytest.approx(whole.weight_N / order, rel=1e-9)


def test_every_csv_of_the_run_reads_back_typed(scene_run):
    _, _, folder = scene_run
    tables = sorted(folder.rglob("*.csv"))
    assert tables
    for path in tables:
        table = masonry.read_table(path)
        assert isinstance(table, pd.DataFrame) and len(table.columns)
        assert not any(table[column].dtype == object and table[column].map(
            lambda v: isinstance(v, str) and v.lower() in ("nan", "true", "false")).any()
            for column in table.columns), path.name


def test_the_runs_bricks_obj_analysed_back_gives_its_verdict(scene_run, tmp_path, capsys):
    """``masonry analyze`` of the run's own OBJ, with the run's supports: the same
    verdict (a cyclic run's OBJ is the whole dome it stands for)."""
    name, record, folder = scene_run
    supports = sorted({n.split("_b")[-1] if "_b" in n else n
                       for n in _support_names(folder)})
    patterns = [f"*{s}" for s in supports]
    if SCENES[name].get("boundary") == "rigid":  # its immovable neighbours, in the file
        patterns.append("w*")
    args = ["analyze", str(folder / "bricks.obj"), "--accuracy", "accurate", "--no-plots",
            "--no-printable", "-q", "--out", str(tmp_path)]
    for pattern in patterns:
        args += ["--support", pattern]
    code = main(args)
    capsys.readouterr()
    assert code == 0
    (path,) = tmp_path.glob("*/run.json")
    again = json.loads(path.read_text())
    assert again["rbe"]["verdict"] == record["rbe"]["verdict"], name


def _support_names(folder) -> list:
    """The names of the run's support blocks, from its locations table."""
    table = masonry.read_table(folder / "locations.csv")
    column = "name" if "name" in table.columns else table.columns[0]
    kind = next(c for c in ("class", "block_class", "kind") if c in table.columns)
    is_support = table[kind].astype(str).isin(["ground", "support"])
    return list(table.loc[is_support, column].astype(str))


LOADED = {"dome, cut 0.5": dict(scene="dome", **DOMES["cut 0.5"]),
          "dome, cut 0": dict(scene="dome", **DOMES["cut 0"]),
          "revolution": SCENES["revolution"]}
LOADS = {"lateral along a mirror plane": dict(lateral=0.0),
         "lateral off every mirror plane": dict(lateral=10.0),
         "crown load": dict(crown_load=2000.0)}


@pytest.mark.parametrize("load", LOADS.values(), ids=LOADS.keys())
@pytest.mark.parametrize("scene", LOADED.values(), ids=LOADED.keys())
def test_a_live_loads_factor_is_the_wholes(scene, load):
    """The run's collapse load factor (on a half where the load is its own mirror image)
    equals the whole's, and its forces balance the whole within the tolerance."""
    params = params_of(scene, **load)
    model = build_model(params)[1]
    ran = collapse_of(model, params)
    analysis = params.analysis
    whole = collapse_load(model, params.load.on(model, analysis.density), mu=analysis.mu,
                          density=analysis.density, cone=analysis.cone)
    assert ran.status == whole.status
    if whole.load_factor is not None:
        assert ran.load_factor == pytest.approx(whole.load_factor, rel=FACTOR_REL)
        assert ran.checked()


def test_an_imported_assembly_analysed_back_gives_its_verdict(fixtures_dir, tmp_path, capsys):
    """Blocks read from a file (Rhino's OBJ of an arch on two piers): the run's residuals
    meet the tolerance, its CSVs read back typed, and its own ``bricks.obj`` analysed
    again gives the same verdict and weight."""
    records = []
    source = fixtures_dir / "assembly" / "arch_rhino.obj"
    for step in range(2):
        out = tmp_path / f"run{step}"
        assert main(["analyze", str(source), "--support", "pier_*", "--no-plots",
                     "--no-printable", "-q", "--out", str(out)]) == 0
        (path,) = out.glob("*/run.json")
        records.append(json.loads(path.read_text()))
        for table in path.parent.rglob("*.csv"):
            masonry.read_table(table)
        source = path.parent / "bricks.obj"
    capsys.readouterr()
    first, again = (record["rbe"] for record in records)
    assert first["residual_eq"] <= ACCEPT_RESIDUAL
    assert again["verdict"] == first["verdict"]
    assert again["weight_N"] == pytest.approx(first["weight_N"], rel=1e-9)
