"""COMPAS JSON in and out: the ecosystem's samples read (fixtures/compas/), bad files
refused, and assembly.json loaded by the real compas_assembly and by masonry."""

import json
import re
import uuid
from pathlib import Path

import numpy as np
import pytest

import masonry
from masonry.export import compas_json
from masonry.export.compas_json import assembly_json
from masonry.interfaces import Interfaces
from masonry.scenes.imported import read_blocks
from masonry.scenes.mesh_files import AssemblyError
from masonry_cli.main import main

SAMPLES = Path(__file__).parent.parent / "fixtures" / "compas"

# sample, support names (None: the file's is_support), mu of its package's examples, verdict
CONVEX = [
    ("compas_assembly/two-blocks_assembly.json", None, 0.84, "feasible"),
    ("compas_assembly/stack_assembly.json", None, 0.84, "infeasible"),
    ("compas_assembly/arch_assembly.json", None, 0.84, "feasible"),
    ("compas_assembly/wall_assembly.json", None, 0.84, "feasible"),
    ("compas_dem/dem_crossvault.json", None, 0.5, "feasible"),
    ("compas_dem/barrel_vault_model.json", None, 0.5, "feasible"),
    ("compas_cra/cubes.json", ["node_0"], 0.84, "feasible"),
    *[(f"compas_cra/{name}.json", ["node_0", "node_1"], 0.84, "feasible")
      for name in ("type-a", "type-b", "type-c", "type-d", "A", "H")],
]


def _file_counts(path):
    """Blocks, supports and interface pairs as the file itself holds them (plain json)."""
    data = json.loads(path.read_text())["data"]
    if "elements" in data:
        elements = data["elements"].values()
        return len(elements), sum(e["data"]["is_support"] for e in elements), None
    graph = data["graph"]["data"]
    nodes = graph["node"]
    pairs = {frozenset((u, v)) for u, nb in graph["edge"].items() for v, a in nb.items()
             if a.get("interfaces")}
    return len(nodes), sum(bool(n.get("is_support")) for n in nodes.values()), pairs


@pytest.mark.parametrize("name", [c[0] for c in CONVEX])
def test_sample_counts_are_the_files(name):
    path = SAMPLES / name
    blocks = read_blocks([path])
    n_blocks, n_supports, pairs = _file_counts(path)
    assert blocks.n_blocks == n_blocks
    assert int(blocks.block_is_support.sum()) == n_supports
    if pairs:  # the file's interfaces: masonry finds the same pairs of blocks in contact
        structure = masonry.read(path)
        found = {frozenset(str(blocks.block_name[i])[len("node_"):] for i in pair)
                 for pair in structure.model.interfaces.pair}
        assert found == pairs


@pytest.mark.parametrize("name, support, mu, verdict", CONVEX)
def test_sample_verdict(name, support, mu, verdict):
    structure = masonry.read(SAMPLES / name, support=support, mu=mu)
    assert structure.solve().verdict == verdict


def test_non_convex_sample_refused_by_name(tmp_path, capsys):
    code = main(["analyze", str(SAMPLES / "compas_cra" / "concave-short.json"),
                 "--support", "node_0", "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "concave-short.json" in err[0] and "'node_1' is not convex" in err[0]
    assert not any(tmp_path.iterdir())


def _two_blocks():
    return json.loads((SAMPLES / "compas_assembly" / "two-blocks_assembly.json").read_text())


def _node(doc, key="1"):
    return doc["data"]["graph"]["data"]["node"][key]


def _bad_two_blocks(edit):
    doc = _two_blocks()
    edit(doc)
    return json.dumps(doc)


def _set(container, key, value):
    container[key] = value


BAD = {
    "not json": ("{'dtype': ", "not a JSON file"),
    "wrong dtype": (_bad_two_blocks(lambda d: _set(d, "dtype", "compas.geometry/Box")),
                    "dtype 'compas.geometry/Box'"),
    "block without faces": (_bad_two_blocks(
        lambda d: _set(_node(d)["block"]["data"], "face", {})), "node '1': the block has no"),
    "face of two vertices": (_bad_two_blocks(
        lambda d: _set(_node(d)["block"]["data"]["face"], "0", [0, 1])),
        "node '1': face '0' is [0, 1]"),
    "NaN coordinate": (_bad_two_blocks(
        lambda d: _set(_node(d)["block"]["data"]["vertex"]["3"], "z", float("nan"))),
        "node '1': vertex '3' has coordinates"),
    "support not a boolean": (_bad_two_blocks(lambda d: _set(_node(d, "0"), "is_support", 1)),
                              "node '0': is_support is 1, expected true or false"),
    "edge to no node": (_bad_two_blocks(
        lambda d: _set(d["data"]["graph"]["data"]["edge"]["0"], "7", {"interfaces": None})),
        "edge (0, 7): node '7' does not exist"),
}


def _model_with_bad_guid():
    doc = json.loads((SAMPLES / "compas_dem" / "dem_crossvault.json").read_text())
    doc["data"]["graph"]["node"]["3"]["element"] = "no-such-guid"
    return json.dumps(doc)


BAD["guid pointing nowhere"] = (_model_with_bad_guid(),
                                "graph node '3': element \"no-such-guid\" points to no element")


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_file_one_line_exit_2(case, tmp_path, capsys):
    text, expected = BAD[case]
    path = tmp_path / "bad.json"
    path.write_text(text)
    out = tmp_path / "out"
    code = main(["analyze", str(path), "--support", "node_0", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert str(path) in err[0] and expected in err[0], err[0]
    assert not out.exists()
    with pytest.raises(AssemblyError, match="bad.json"):
        masonry.read(path, support="node_0")


def test_support_options_replace_the_files():
    path = SAMPLES / "compas_assembly" / "wall_assembly.json"
    assert masonry.read(path).scene.blocks.block_is_support.sum() == 10
    chosen = masonry.read(path, support="node_0").scene.blocks
    assert list(chosen.block_name[chosen.block_is_support]) == ["node_0"]


# ---------------------------------------------------------------------- round trip
@pytest.fixture(scope="module")
def dome_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("dome")
    code = main(["run", "--scene", "dome", "--n", "6", "--r", "0", "--p", "3", "--cut", "0.5",
                 "--no-plots", "--no-printable", "--no-html", "--out", str(out)])
    assert code == 0
    folder = next(p for p in out.iterdir() if p.is_dir() and not p.name.startswith("."))
    return folder, json.loads((folder / "run.json").read_text())


def test_round_trip_masonry_reads_its_assembly_json(dome_run):
    folder, record = dome_run
    path = folder / "assembly.json"
    document = json.loads(path.read_text())
    assert document["data"]["attributes"]["masonry"]["verdict"] == record["rbe"]["verdict"]
    back = masonry.read(path)
    result = back.solve()
    assert result.verdict == record["rbe"]["verdict"] == "feasible"
    # the same forces: per interface point, as written (c_np, c_nn, c_u, c_v)
    written = {}
    for u, neighbours in document["data"]["graph"]["data"]["edge"].items():
        for v, attributes in neighbours.items():
            for interface in attributes["interfaces"]:
                rows = [[f[k] for k in ("c_np", "c_nn", "c_u", "c_v")]
                        for f in interface["data"]["forces"]]
                written[(int(u), int(v))] = np.array(rows)
    interfaces = back.model.interfaces
    assert len(interfaces) == len(written)
    x = result.x.reshape(-1, 4)
    scale = np.abs(x).max()
    for k, (u, v) in enumerate(interfaces.pair):
        rows = x[interfaces.offsets[k]:interfaces.offsets[k + 1]]
        mine = written[(int(u), int(v))]
        # the same normal forces at the same polygon (its start may differ)
        assert np.isclose(mine[:, 0].sum(), rows[:, 0].sum(), rtol=1e-6, atol=1e-6 * scale)
    total = sum(m[:, 0].sum() for m in written.values())
    assert np.isclose(total, x[:, 0].sum(), rtol=1e-6)


def test_round_trip_compas_assembly_loads_it(dome_run):
    compas = pytest.importorskip("compas")
    pytest.importorskip("compas_assembly")
    from compas_assembly.datastructures import Assembly, Block, Interface

    folder, record = dome_run
    names = [line.split()[1] for line in (folder / "bricks.obj").read_text().splitlines()
             if line.startswith("o ")]
    assembly = compas.json_load(str(folder / "assembly.json"))
    assert isinstance(assembly, Assembly)
    graph = assembly.graph
    assert graph.number_of_nodes() == len(names)
    interfaces = [i for edge in graph.edges() for i in graph.edge_attribute(edge, "interfaces")]
    assert len(interfaces) == sum(record["counts"]["interfaces"].values())
    assert all(isinstance(graph.node_attribute(n, "block"), Block) for n in graph.nodes())
    assert all(isinstance(i, Interface) for i in interfaces)
    supports = {graph.node_attribute(n, "block").name for n in graph.nodes()
                if graph.node_attribute(n, "is_support")}
    assert supports == {name for name in names if "_ground_" in name} != set()
    # the frame's normal is x cross y, unit; forces per polygon point
    for interface in interfaces:
        assert len(interface.forces) == len(interface.points)
        assert np.isclose(np.linalg.norm(interface.frame.normal), 1.0, atol=1e-9)


def _turned(faces: Interfaces, x):
    """The same joints described from their other block: pair, normal and polygon
    turned, the axes swapped (still right-handed), and the friction the force on the
    first block (f1, f2 become -f2, -f1)."""
    order = np.concatenate([np.arange(a, b)[::-1] for a, b in
                            zip(faces.offsets[:-1], faces.offsets[1:])])
    turned = Interfaces(pair=faces.pair[:, ::-1], kind=faces.kind,
                        vertices=faces.vertices[order], offsets=faces.offsets,
                        area=faces.area, centre=faces.centre, normal=-faces.normal,
                        t1=faces.t2, t2=faces.t1)
    return turned, x[order][:, [0, 1, 3, 2]] * [1, 1, -1, -1]


@pytest.mark.parametrize("chunk", [1, 3, compas_json.CHUNK])
def test_joints_stored_from_either_block_hold_the_same_forces(monkeypatch, tmp_path, chunk):
    """Every joint of a wall as two halves, the second stored from its other block: the
    file lists both under one edge, and their force on the edge's second block is the
    joint's whole force on that block, each polygon counter-clockwise about its frame's
    normal; whether the file is made one block at a time, a few, or all at once."""
    monkeypatch.setattr(compas_json, "CHUNK", chunk)
    assembly = masonry.read(SAMPLES / "compas_assembly" / "wall_assembly.json")
    result = assembly.solve()
    faces, x = assembly.model.interfaces, result.x.reshape(-1, 4)
    turned, x_turned = _turned(faces, x)
    both = Interfaces(**{name: np.concatenate([getattr(faces, name), getattr(turned, name)])
                         for name in ("pair", "kind", "vertices", "area", "centre", "normal",
                                      "t1", "t2")},
                      offsets=np.concatenate([faces.offsets,
                                              faces.offsets[1:] + faces.offsets[-1]]))
    halves = np.concatenate([x, x_turned]) / 2
    document = json.loads(assembly_json(assembly.model.blocks, both, halves.reshape(-1),
                                        result.to_dict()))
    # each joint's force on its second block, from the solution's own layout
    push = (x[:, :1] - x[:, 1:2]) * np.repeat(faces.normal, faces.vertex_count, axis=0) \
        + x[:, 2:3] * np.repeat(faces.t1, faces.vertex_count, axis=0) \
        + x[:, 3:4] * np.repeat(faces.t2, faces.vertex_count, axis=0)
    on_second = np.add.reduceat(push, faces.offsets[:-1])
    turning = np.add.reduceat(np.cross(faces.vertices, push), faces.offsets[:-1])
    expected = {(int(u), int(v)): (on_second[k], turning[k])
                for k, (u, v) in enumerate(faces.pair)}
    edges = document["data"]["graph"]["data"]["edge"]
    seen = 0
    for u, neighbours in edges.items():
        for v, attributes in neighbours.items():
            assert len(attributes["interfaces"]) == 2
            total, moment = np.zeros(3), np.zeros(3)
            for interface in attributes["interfaces"]:
                data = interface["data"]
                frame = data["frame"]["data"]
                xaxis, yaxis = np.array(frame["xaxis"]), np.array(frame["yaxis"])
                normal = np.cross(xaxis, yaxis)
                polygon = np.array([p["data"] for p in data["points"]])
                area = 0.5 * np.cross(polygon - polygon[0], np.roll(polygon, -1, axis=0)
                                      - polygon[0]).sum(axis=0)
                assert np.isclose(area @ normal, data["size"], rtol=1e-9)
                for point, force in zip(polygon, data["forces"]):
                    vector = (force["c_np"] - force["c_nn"]) * normal \
                        + force["c_u"] * xaxis + force["c_v"] * yaxis
                    total += vector
                    moment += np.cross(point, vector)
            key = (int(u), int(v))
            sign = 1.0 if key in expected else -1.0
            want, want_moment = expected[key] if key in expected else expected[key[::-1]]
            scale = np.abs(x).max()
            assert np.allclose(total, sign * want, rtol=1e-9, atol=1e-9 * scale)
            assert np.allclose(moment, sign * want_moment, rtol=1e-9,
                               atol=1e-9 * scale * np.abs(faces.vertices).max())
            seen += 1
    assert seen == len(faces)
    nodes = document["data"]["graph"]["data"]["node"]
    assert list(nodes) == [str(b) for b in range(assembly.model.blocks.n_blocks)]
    assert [n["block"]["name"] for n in nodes.values()] == list(assembly.model.blocks.block_name)
    (tmp_path / "both.json").write_text(json.dumps(document))
    blocks, back = assembly.model.blocks, masonry.read(tmp_path / "both.json").model.blocks
    assert np.allclose(back.block_volume, blocks.block_volume, rtol=1e-12)
    assert np.allclose(back.block_centroid, blocks.block_centroid, rtol=0,
                       atol=1e-12 * np.abs(blocks.vertices).max())
    guids = re.findall(r'"guid": "([^"]*)"', json.dumps(document))
    assert len(set(guids)) == len(guids) > 2 * len(faces)
    assert all(uuid.UUID(g).version == 4 and uuid.UUID(g).variant == uuid.RFC_4122
               and str(uuid.UUID(g)) == g for g in guids)
