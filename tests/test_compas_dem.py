"""A compas_dem Problem read (the barrel vault of compas_dem, fixtures/compas/compas_dem/),
its forces against LMGC90's, bad Problems refused, and masonry as a compas_dem solver."""

import csv
import json
import runpy
from pathlib import Path

import numpy as np
import pytest

import masonry
from masonry_cli.main import main

SAMPLES = Path(__file__).parent.parent / "fixtures" / "compas" / "compas_dem"
PROBLEM = SAMPLES / "barrel_vault_problem.json"
EXAMPLE = Path(__file__).parent.parent / "examples" / "compas_dem_solver.py"


@pytest.fixture(scope="module")
def vault():
    structure = masonry.read(PROBLEM)
    return structure, structure.solve(), structure.forces()


def _lmgc90():
    """LMGC90's joints: ``{frozenset(nodes): (normal sum N, force on node_u (3,))}``."""
    with open(SAMPLES / "barrel_vault_lmgc90_joints.csv", newline="") as fh:
        return {frozenset((int(r["node_u"]), int(r["node_v"]))): (
                    float(r["normal_N"]), np.array([float(r[f"force_{a}_N"]) for a in "xyz"]),
                    int(r["node_u"]))
                for r in csv.DictReader(fh)}


def test_problem_inputs_and_supports(vault):
    structure, _, _ = vault
    data = json.loads(PROBLEM.read_text())["data"]
    fixed = {d["block_index"] for d in data["boundary_conditions"]["data"]["displacements"]}
    assert structure.blocks.n_blocks == 121
    # the node keys are 0..120 in order: block i is node i
    assert list(data["model"]["data"]["graph"]["node"]) == [str(i) for i in range(121)]
    assert set(np.flatnonzero(structure.blocks.block_is_support)) == fixed
    assert len(fixed) == 26
    assert structure.params.analysis.mu == pytest.approx(0.5, abs=1e-12)
    assert structure.params.analysis.density == 2000.0
    # the caller's input wins over the Problem's
    assert masonry.read(PROBLEM, mu=0.7).params.analysis.mu == 0.7


def test_reactions_equal_weight_and_lmgc90s(vault):
    structure, result, forces = vault
    blocks = structure.blocks
    support = blocks.block_is_support
    weight = 2000.0 * 9.81 * blocks.block_volume[~support].sum()
    # force on block_b: -normal_N n + shear; on the free block from the support
    n = forces[["normal_x", "normal_y", "normal_z"]].to_numpy()
    on_b = (-forces["normal_N"].to_numpy()[:, None] * n
            + forces[["shear_x_N", "shear_y_N", "shear_z_N"]].to_numpy())
    a, b = forces["block_a"].to_numpy(), forces["block_b"].to_numpy()
    from_support = np.where((support[a] & ~support[b])[:, None], on_b, 0.0) \
        - np.where((support[b] & ~support[a])[:, None], on_b, 0.0)
    total = from_support.sum(axis=0)
    assert total[2] == pytest.approx(weight, rel=1e-6)
    assert np.abs(total[:2]).max() < 1e-6 * weight
    lmgc = _lmgc90()
    lmgc_total = np.zeros(3)
    for k, (_, force_on_u, u) in lmgc.items():
        v = next(iter(k - {u}))
        if support[v] != support[u]:  # the force on the free node from the support
            lmgc_total += force_on_u if support[v] else -force_on_u
    # LMGC90's dynamics ends with a residual: its reactions within 0.1 % of the weight
    assert lmgc_total[2] == pytest.approx(weight, rel=1e-3)
    assert result.verdict == "feasible"  # as LMGC90: at rest (|u| < 1e-6 m)


def test_joint_normal_forces_side_by_side(vault):
    structure, _, forces = vault
    lmgc = _lmgc90()
    mine = {}
    for a, b, normal in zip(forces["block_a"], forces["block_b"], forces["normal_N"]):
        key = frozenset((int(a), int(b)))
        mine[key] = mine.get(key, 0.0) - normal  # compression positive, as LMGC90's
    assert set(mine) <= set(lmgc)
    # the joints masonry does not find carry nothing in LMGC90 (support-support faces)
    assert all(abs(lmgc[k][0]) < 1e-9 for k in set(lmgc) - set(mine))
    keys = sorted(mine, key=sorted)
    ours = np.array([mine[k] for k in keys])
    theirs = np.array([lmgc[k][0] for k in keys])
    # statically indeterminate: two equilibria, close but not equal (docs/assemblies.md)
    assert np.corrcoef(ours, theirs)[0, 1] > 0.95
    assert abs(ours.sum() - theirs.sum()) < 0.05 * theirs.sum()


def _problem(edit):
    document = json.loads(PROBLEM.read_text())
    edit(document["data"])
    return json.dumps(document)


def _bc(data):
    return data["boundary_conditions"]["data"]


def _law(data):
    return data["contact_properties"]["data"]["contact_model"]


BAD = {
    "unknown contact model": (
        lambda d: _law(d).update(dtype="compas_dem.interactions/Hertz"),
        "contact model 'compas_dem.interactions/Hertz': not supported"),
    "nan mu": (lambda d: _law(d)["data"].update(mu=float("nan")), "mu is nan"),
    "load on a missing block": (
        lambda d: _bc(d)["point_loads"].append(
            {"block_index": 500, "force": [0, 0, -1000], "point": None, "moment": None}),
        "block_index 500 is no block of the model"),
    "settlement": (
        lambda d: _bc(d)["displacements"][0].update(translation=[0.0, 0.0, -0.01]),
        "prescribed displacement on block 0"),
    "body force": (
        lambda d: _bc(d)["body_forces"].append({"acceleration": [1.0, 0, 0]}),
        "body force 0 of boundary condition 0: not supported"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_problem_one_line_exit_2(case, tmp_path, capsys):
    edit, expected = BAD[case]
    path = tmp_path / "problem.json"
    path.write_text(_problem(edit))
    out = tmp_path / "out"
    code = main(["analyze", str(path), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and str(path) in err[0] and expected in err[0], err
    assert not out.exists()


def test_point_loads_become_a_collapse_load(tmp_path, vault):
    structure, _, _ = vault
    blocks = structure.blocks
    free = int(np.flatnonzero(~blocks.block_is_support)[0])
    top = masonry.rbe.loads.top_faces(blocks)[free]
    centre = blocks.face_centre[top].tolist()
    on_line = tmp_path / "on_line.json"
    on_line.write_text(_problem(lambda d: _bc(d)["point_loads"].append(
        {"block_index": free, "force": [0, 0, -5000.0], "point": centre, "moment": None})))
    loaded = masonry.read(on_line)
    assert loaded.params.load.specs == (f"element_{free}:0.0,0.0,-5000.0",)
    # a second point on the same vertical line: the same load
    above = [centre[0], centre[1], centre[2] + 1.0]
    again = tmp_path / "above.json"
    again.write_text(_problem(lambda d: _bc(d)["point_loads"].append(
        {"block_index": free, "force": [0, 0, -5000.0], "point": above, "moment": None})))
    assert masonry.read(again).params.load.specs == loaded.params.load.specs
    aside = tmp_path / "aside.json"
    aside.write_text(_problem(lambda d: _bc(d)["point_loads"].append(
        {"block_index": free, "force": [0, 0, -5000.0],
         "point": [centre[0] + 0.1, centre[1], centre[2]], "moment": None})))
    with pytest.raises(masonry.errors.MasonryError, match="misses the centre .* by 0.1 m"):
        masonry.read(aside)


def test_compas_dem_solver_example_runs():
    pytest.importorskip("compas_dem")
    results = runpy.run_path(str(EXAMPLE))["main"]()
    assert results.metadata["verdict"] == "feasible"
    weight = results.metadata["weight_N"]
    # the springers (the chain's two ends) carry the weight
    edges = list(results.edges())
    ends = {n for n in {n for e in edges for n in e}
            if sum(n in e for e in edges) == 1}
    assert len(ends) == 2
    on_ends = sum(results.resultant_global(e)[2] * (1 if e[0] in ends else -1)
                  for e in edges if ends & set(e))
    assert on_ends == pytest.approx(-weight, rel=1e-6)
