"""The command line, in-process (``main([...])``)."""

import json

import numpy as np
import pytest
import trimesh

from masonry_cli.main import main


def run_folders(root):
    """The run folders under an output root (not the hidden geometry cache, nor the
    pages' shared plotly.js)."""
    return [p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")]


@pytest.mark.slow
def test_build_writes_the_run_folder(tmp_path, capsys):
    assert main(["build", "--preset", "1", "--fast", "--out", str(tmp_path), "-q"]) == 0
    (folder,) = run_folders(tmp_path)
    assert folder.name == "dome1_fast1_fricauto_s1_n8_r1_p10_c0.1_u0.1"  # cyclic
    for name in ("00_parameters.txt", "run.json", "locations.csv", "bricks.obj",
                 "00_pattern.png", "01_angle/3_structure.png"):
        assert (folder / name).is_file(), name
    assert not (folder / "02_front").exists()  # fast: one view
    record = json.loads((folder / "run.json").read_text())
    for key in ("params", "structure_id", "scene", "counts", "volume_m3", "weight_N",
                "timings_s", "versions"):
        assert key in record
    assert record["counts"]["bricks"] == 790
    assert record["weight_N"] == pytest.approx(record["volume_m3"] * 2000 * 9.81)
    # locations.csv: one row per brick vertex (the ground slab included), of the whole
    # dome the cyclic section stands for: 8 webs of 791 blocks of 8 corners
    rows = (folder / "locations.csv").read_text().splitlines()
    assert len(rows) == 1 + 8 * 8 * 791
    assert "790 bricks" in capsys.readouterr().out


def test_bricks_obj_splits_into_one_mesh_per_brick(tmp_path):
    assert main(["build", "--preset", "wall", "--no-plots", "--out", str(tmp_path),
                 "-q"]) == 0
    (folder,) = run_folders(tmp_path)
    scene = trimesh.load(folder / "bricks.obj", split_objects=True, group_material=False,
                         process=False)
    meshes = scene.geometry if hasattr(scene, "geometry") else {"one": scene}
    assert len(meshes) == 86
    assert "b0001_fill_in_c1" in meshes or "b0001_regular_c1" in meshes
    volume = sum(abs(m.volume) for m in meshes.values())
    assert volume == pytest.approx(0.64 + 0.1 * 0.2 * 3.2, rel=1e-9)  # bricks + ground


@pytest.mark.parametrize("args", [
    ["--n", "2"], ["--stretch", "0"], ["--stretch", "nan"], ["--r", "-1"], ["--p", "0"],
    ["--cut", "1"], ["--cut", "-0.1"], ["--unit", "0"], ["--min-fill", "0"],
    ["--wall-courses", "0", "--scene", "wall"],
])
def test_bad_parameter_gets_one_line_and_writes_nothing(tmp_path, capsys, args):
    assert main(["build", *args, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    # the option as typed, then the value
    assert len(err) == 1 and err[0].startswith(f"masonry: error: {args[0]} {args[1]}: "
                                               "expected ")
    assert not (tmp_path / "out").exists()


def test_unparsable_value_exits_2(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["build", "--n", "eight"])
    assert exit_info.value.code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_params_file(tmp_path, fixtures_dir):
    assert main(["build", "--params", str(fixtures_dir / "presets" / "preset3.toml"),
                 "--no-plots", "--out", str(tmp_path), "-q"]) == 0
    (folder,) = run_folders(tmp_path)
    assert folder.name.startswith("dome1_fast0_fricauto_s0.8_n4_r1_p13_c0.01")


def test_failed_run_leaves_previous_output(tmp_path, monkeypatch):
    assert main(["build", "--preset", "wall", "--no-plots", "--out", str(tmp_path),
                 "-q"]) == 0
    (folder,) = run_folders(tmp_path)
    before = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}

    def broken(*args, **kwargs):
        raise RuntimeError("injected failure")

    monkeypatch.setattr("masonry.export.obj.blocks_obj", broken)
    monkeypatch.setenv("MASONRY_LOG_DIR", str(tmp_path.parent / "logs"))
    assert main(["build", "--preset", "wall", "--no-plots", "--force", "--out",
                 str(tmp_path), "-q"]) == 1
    after = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert after == before
    assert [p.name for p in tmp_path.iterdir() if ".tmp-" in p.name] == []  # none left


def test_cad_offset_moves_bricks_inward(tmp_path):
    from masonry.params import from_preset
    from masonry.scenes import build

    scene = build(from_preset("1"))
    moved = scene.cad_vertices() - scene.blocks.vertices
    np.testing.assert_allclose(np.linalg.norm(moved, axis=1), 0.1, rtol=1e-12)
    assert np.all(moved[:, 0] < 0)  # the section faces +x: inward is -x
    # run.json says which files are moved and by how much
    from masonry.pipeline import coordinates_record

    record = coordinates_record(scene, cad_offset=1.0)
    assert record["cad_offset_m"] == pytest.approx(0.1, rel=1e-12)
    assert {"locations.csv", "dome.stl"} <= set(record["moved_inward"])
    assert {"bricks.obj", "bricks.3dm", "RBE/forces.csv"} <= set(record["model"])


def test_print_size_writes_a_3mf_and_rejects_bad_sizes(tmp_path, capsys):
    assert main(["run", "--preset", "wall", "--fast", "--no-plots", "--print-size", "120",
                 "--out", str(tmp_path), "-q"]) == 0
    folder = next(tmp_path.glob("wall_*"))
    record = json.loads((folder / "run.json").read_text())
    assert (folder / "dome.3mf").is_file()
    assert record["printable"]["print"]["readback"]["unit"] == "millimeter"
    assert max(record["printable"]["print"]["readback"]["extents_mm"]) == pytest.approx(120)
    for bad in (["--print-size", "-5"], ["--print-size", "1e5"],
                ["--print-size", "120", "--no-printable"]):
        assert main(["run", "--preset", "wall", *bad, "--out", str(tmp_path / "bad"),
                     "-q"]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"masonry: error: --print-size {bad[1]}: expected "), err
        assert err.count("\n") == 1
    assert not (tmp_path / "bad").exists()


def test_analyze_writes_the_3mf_it_is_asked_for(tmp_path):
    # two unit cubes stacked, the lower one a support: the 3MF's height is the size asked
    path = tmp_path / "tower.obj"
    boxes = [trimesh.creation.box(extents=(1, 1, 1)) for _ in range(2)]
    for k, box in enumerate(boxes):
        box.apply_translation((0.5, 0.5, 0.5 + k))
    lines, offset = [], 0
    for k, box in enumerate(boxes):
        lines += [f"o block{k}"] + [f"v {x:g} {y:g} {z:g}" for x, y, z in box.vertices]
        lines += ["f " + " ".join(str(offset + 1 + i) for i in f) for f in box.faces]
        offset += len(box.vertices)
    path.write_text("\n".join(lines) + "\n")
    assert main(["analyze", str(path), "--support", "block0", "--no-plots",
                 "--print-size", "50", "--out", str(tmp_path / "out"), "-q"]) == 0
    (folder,) = run_folders(tmp_path / "out")
    record = json.loads((folder / "run.json").read_text())
    assert (folder / "dome.3mf").is_file()
    extents = record["printable"]["print"]["readback"]["extents_mm"]
    assert extents[2] == pytest.approx(50, rel=1e-9)
    # the printable body grows each block by OVERLAP_REL (1e-5) of the scene's size
    assert extents[:2] == pytest.approx([25, 25], rel=1e-4)


def test_a_flag_that_does_not_apply_is_refused_by_name(tmp_path, capsys):
    """``structures --lateral`` is the full domes' factor: refused without them, the flag
    named alone (not with the next option as its value)."""
    assert main(["structures", "--no-full-dome", "--lateral", "--out", str(tmp_path)]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert error == ["masonry: error: --lateral: expected the full domes, whose factor "
                     "it is: not with --no-full-dome"]
    assert not any(tmp_path.iterdir())


def test_an_infeasible_verdict_without_its_moi_exits_3():
    """friction-net certified infeasible, friction+ stopped short: the verdict stands, the
    MoI the run was for is missing, and the exit code says so."""
    from masonry_cli.options import rbe_summary

    lines = []
    record = {"params": {"friction": "auto"},
              "rbe": {"verdict": "infeasible", "friction": "plus", "mu": 0.01, "moi": np.nan,
                      "solver": "osqp", "status": "user_limit", "residual_eq": 1.1e-4}}
    assert rbe_summary(record, lines.append) == 3
    assert lines == ["RBE: infeasible (friction-net has no equilibrium, mu 0.01); MoI not "
                     "computed: osqp stopped with status 'user_limit' on friction-plus, "
                     "residual 0.00011"]
