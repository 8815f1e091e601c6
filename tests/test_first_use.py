"""What a new user meets first: the default run, the files it writes, and bad input that
must end in one line and exit code 2 (not an internal error) before any work."""

import json

import numpy as np
import pytest

from masonry_cli.main import main

WALL = ["--preset", "wall", "--wall-courses", "3", "--wall-length", "12", "--fast",
        "--no-plots", "--no-printable"]
WALL_ID = "wall_fast1_fricauto_L12_k3_u0.1"


def one_error_line(capsys) -> str:
    """The one line a refused input prints on stderr."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("masonry: error: ")
    return err[0]


def test_a_run_writes_the_3dm_and_a_folder_without_it_is_not_up_to_date(
        tmp_path, monkeypatch, capsys):
    pytest.importorskip("rhino3dm")
    folder = tmp_path / WALL_ID
    monkeypatch.setattr("masonry.export.rhino.available", lambda: False)
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "bricks.3dm not written: rhino3dm, a dependency of masonry, is not installed" in err
    assert not (folder / "bricks.3dm").exists()
    assert json.loads((folder / "run.json").read_text())["outputs"]["3dm"] is False
    monkeypatch.undo()  # rhino3dm installed now: the folder lacks what a run can make
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "up to date" not in out and "written:" in out
    assert (folder / "bricks.3dm").stat().st_size > 0
    record = json.loads((folder / "run.json").read_text())
    assert record["outputs"]["3dm"] is True and "bricks.3dm" in record["coordinates"]["model"]
    assert main(["run", *WALL, "--out", str(tmp_path)]) == 0  # and now it is
    assert "up to date, reused" in capsys.readouterr().out


SMALL = ["--p", "5", "--no-plots", "--no-printable"]  # 220 bricks


def test_the_default_run_is_the_cyclic_section_and_says_what_its_verdict_means(
        tmp_path, capsys):
    assert main(["run", *SMALL, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.name.startswith(".")]
    assert folder.name.startswith("dome1_")  # the section with cyclic neighbours
    assert json.loads((folder / "run.json").read_text())["params"]["boundary"] == "cyclic"
    assert "RBE: feasible" in out
    assert ("meaning: the whole dome (this web with its neighbours by rotational symmetry) "
            "stands under its own weight") in out
    # the web alone is one option away, and says what its verdict means
    assert main(["run", *SMALL, "--boundary", "free", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "RBE: infeasible" in out
    assert ("meaning: this web alone, without its neighbours, cannot stand under its own "
            "weight") in out


def test_the_readme_says_what_the_default_run_does(fixtures_dir):
    readme = (fixtures_dir.parent / "README.md").read_text()
    assert "come next" not in readme
    assert "exports/dome1_fast0_fricauto_s1_n8_r1_p10_c0.1_u0.1/" in readme


def test_a_lateral_load_on_the_default_section_names_the_scene_that_takes_it(
        tmp_path, capsys):
    assert main(["run", *SMALL, "--lateral", "0", "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert line.startswith("masonry: error: --lateral 0: expected a symmetric load on a "
                           "cyclic section (a section's default boundary)")
    assert "--scene dome" in line and "--boundary free" in line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("table, key, value, expected", [
    ("base", "no-plots", "true", "the [outputs] table chooses it for all variants "
                                 "(outputs.plots)"),
    ("base", "no-printable", "true", "the [outputs] table chooses it for all variants "
                                     "(outputs.printable)"),
    ("grid", "dpi", "[100, 200]", "the [outputs] table chooses it for all variants "
                                  "(outputs.dpi)"),
    ("base", "out", '"x"', "the study's output root is masonry sweep's --out"),
    ("grid", "force", "[true]", "not an option of the command)"),
])
def test_a_study_table_refuses_a_run_option_that_is_no_input(tmp_path, capsys, table, key,
                                                             value, expected):
    study = tmp_path / "study.toml"
    grid = "" if table == "grid" else "[grid]\nmu = [0.5, 0.7]\n"
    study.write_text(f"[base]\npreset = 3\n{grid}[{table}]\n{key} = {value}\n"
                     if table == "grid" else f"[base]\npreset = 3\n{key} = {value}\n{grid}")
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"masonry: error: {study}: {table}.{key} = ")
    assert line.endswith(expected) and "expected an input of each variant" in line
    assert not (tmp_path / "o").exists()


def test_the_example_study_shows_its_outputs_table(fixtures_dir):
    import tomllib

    study = tomllib.loads((fixtures_dir / "studies" / "stretch_mu.toml").read_text())
    assert study["outputs"] == {"plots": False, "printable": False}


def test_the_collapse_line_says_the_mechanism_as_its_file_does(tmp_path, capsys):
    assert main(["run", *WALL, "--lateral", "0", "--out", str(tmp_path)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines()
                if ln.startswith("collapse:"))
    text = next((tmp_path).glob("wall_*_lat0")).joinpath("collapse", "00_collapse.txt")
    (mechanism,) = [ln for ln in text.read_text().splitlines() if ln.startswith("mechanism:")]
    words = mechanism.split(":", 1)[1].strip()
    assert f"mechanism: {words}; " in line and "collapse/00_collapse.txt" in line


def test_obj_files_state_their_axes_for_blender(tmp_path):
    import trimesh

    assert main(["build", *WALL[:-2], "--no-plots", "--out", str(tmp_path), "-q"]) == 0
    folder = tmp_path / WALL_ID
    for name in ("bricks.obj", "dome.obj"):
        first = (folder / name).read_text().splitlines()[0]
        assert "z up" in first and "Up Axis Z and Forward Axis Y" in first, name
    # and the model does stand on z: 3 courses of 0.1 m (the unit) on a slab 0.1 m deep,
    # 1.2 m long along y (grown by 1e-5 of the size so that touching bricks fuse)
    body = trimesh.load(folder / "dome.obj", process=False)
    np.testing.assert_allclose(body.bounds[:, 1:], [[-0.6, -0.1], [0.6, 0.3]], atol=1e-4)


def test_a_herringbone_dome_whose_pattern_ends_on_the_first_course_is_refused(tmp_path,
                                                                             capsys):
    # two courses: the pattern lines from the corners end on the first, so the inputs
    # would build a dome without a herringbone (p = 1 is refused by its range already)
    out = tmp_path / "o"
    assert main(["build", "--p", "2", "--r", "0", "--n", "3", "--cut", "0.3",
                 "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert line.startswith("masonry: error: --cut 0.3: expected a dome high enough for its "
                           "herringbone: its pattern lines end on the first of its 2 courses")
    assert "--pattern none" in line and not out.exists()
    assert main(["build", "--p", "2", "--r", "0", "--n", "3", "--cut", "0.3", "--pattern",
                 "none", "--no-plots", "--no-printable", "--out", str(out), "-q"]) == 0


def test_a_sweep_of_point_loads_writes_its_summary_and_plots(tmp_path):
    # lists as swept values (the point loads) beside another swept input: its values
    # name the groups of the plots
    study = tmp_path / "loads.toml"
    study.write_text('[base]\npreset = "wall"\nwall-courses = 3\nwall-length = 12\n'
                     'fast = true\n[grid]\nmu = [0.5, 0.7]\n'
                     'point-load = [["*_c3:100,0,0"], ["*_c2:100,0,0"]]\n')
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path), "-q"]) == 0
    summary = tmp_path / "sweep_loads"
    assert len((summary / "summary.csv").read_text().splitlines()) == 5
    for name in ("moi_factor_mu.png", "moi_factor_point_loads.png",
                 "load_factor_point_loads.png"):
        assert (summary / name).stat().st_size > 10_000, name


def test_an_out_path_too_long_for_a_run_folder_is_refused_before_any_work(tmp_path, capsys):
    from masonry.runfolder import RUN_FOLDER_DEPTH, _path_max

    limit = _path_max(tmp_path) - RUN_FOLDER_DEPTH
    root = tmp_path / "/".join(["d" * 150] * (limit // 151 + 1))
    assert main(["run", *WALL, "--out", str(root)]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"masonry: error: --out {root}: expected a folder path at most "
                           f"{limit} bytes long (this one has {len(str(root))};")
    assert list(tmp_path.iterdir()) == []


def test_mesh_coordinates_beyond_any_map_are_refused_naming_the_file(tmp_path, capsys):
    from masonry.blocks import Blocks
    from masonry.export.obj import blocks_obj

    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1  # corner ix + 2 iy + 4 iz
    corners = np.stack([bits * [2, 2, 1] - [0.5, 0.5, 1], bits * 0.5]).astype(float)
    for scale, refused in ((1e7, False), (1e300, True)):
        path = tmp_path / f"far{scale:g}.obj"
        far = corners + np.array([scale, 0, 0]) if not refused else corners * scale
        with np.errstate(all="ignore"):  # the file's own frames overflow at 1e300
            path.write_bytes(blocks_obj(Blocks.from_hexahedra(far, ["ground", "block"])))
        code = main(["analyze", str(path), "--support", "*ground*", "--no-plots",
                     "--no-printable", "--out", str(tmp_path / "o"), "-q"])
        if refused:
            assert code == 2
            line = one_error_line(capsys)
            assert line.startswith(f"masonry: error: {path}: ") and "farther than 1e+08 m" in line
        else:  # map coordinates (UTM northings reach 1e7 m) are read
            assert code == 0
    (folder,) = [p for p in (tmp_path / "o").iterdir() if p.is_dir() and not p.name.startswith(".")]
    assert folder.name.startswith("assembly_far1e")


def test_a_parameter_file_naming_the_assembly_scene_is_refused_naming_its_key(tmp_path,
                                                                              capsys):
    path = tmp_path / "assembly.toml"
    path.write_text('scene = "assembly"\n')
    assert main(["run", "--params", str(path), "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert line.startswith(f"masonry: error: {path}: scene = 'assembly': expected one of "
                           f"section, ")
    assert "masonry analyze" in line and not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_a_toml_file_nested_thousands_deep_is_one_line(tmp_path, capsys, command):
    path = tmp_path / "deep.toml"
    path.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")
    args = ["--params", str(path)] if command == "run" else [str(path), "--workers", "1"]
    assert main([command, *args, "--out", str(tmp_path / "o")]) == 2
    assert "nested a few levels deep, not thousands" in one_error_line(capsys)
    assert not (tmp_path / "o").exists()


def test_a_collapse_factor_without_a_verdict_exits_3(tmp_path, monkeypatch, capsys):
    import dataclasses

    import masonry.pipeline

    solved = masonry.pipeline.collapse_load

    def stopped_short(*args, **kwargs):  # as a solver that hit its time limit
        result = solved(*args, **kwargs)
        return dataclasses.replace(result, load_factor=None, status="time limit reached")

    monkeypatch.setattr(masonry.pipeline, "collapse_load", stopped_short)
    assert main(["run", *WALL, "--lateral", "0", "--out", str(tmp_path)]) == 3
    out = capsys.readouterr().out
    assert ("collapse: no load factor (time limit reached), lateral at 0 deg; interior "
            "stopped without a verdict") in out
    # a decided answer without a factor is a verdict: exit 0
    monkeypatch.undo()
    assert main(["run", "--scene", "dome", "--stretch", "1", "--n", "6", "--r", "0", "--p",
                 "3", "--cut", "0.5", "--crown-load", "2000", "--no-plots",
                 "--no-printable", "--out", str(tmp_path)]) == 0
    assert "collapse: no load factor (unbounded), crown load" in capsys.readouterr().out


@pytest.mark.parametrize("args, typed", [
    (["--support", "x"], "--support x"),
    (["--ground"], "--ground"),
    (["--support-below", "0.5"], "--support-below 0.5"),
    (["blocks.obj", "--support", "b*", "--scene", "dome"], "--scene dome"),
    (["blocks.obj", "--support", "b*", "--preset", "1"], "--preset 1"),
    (["blocks.obj", "--support", "b*", "--n", "5"], "--n 5"),
])
def test_stages_refuses_options_that_do_not_apply(tmp_path, capsys, args, typed):
    assert main(["stages", *args, "--out", str(tmp_path / "o")]) == 2
    assert one_error_line(capsys).startswith(f"masonry: error: {typed}: expected ")
    assert not (tmp_path / "o").exists()


DIMENSIONLESS = {"eccentricity", "moi_factor", "load_factor", "residual_eq", "t_over_r",
                 *(f"{v}_{a}" for v in ("normal", "t1", "t2") for a in "xyz")}
"""Float columns without a unit: ratios and unit vectors (docs/outputs.md, unit 1)."""


def test_every_csv_column_names_its_unit_and_reads_typed_even_when_empty(tmp_path):
    import re
    import types

    import pandas

    import masonry
    from masonry.studies.thickness import steps_csv

    assert main(["run", *WALL, "--lateral", "0", "--out", str(tmp_path), "-q"]) == 0
    steps = tmp_path / "steps.csv"  # arch-thickness's: True/False as every other CSV
    steps.write_bytes(steps_csv(types.SimpleNamespace(steps=((0.11, True), (0.10, False)),
                                                      radius=5.0)))
    assert steps.read_text().splitlines()[1:] == ["0,0.11,0.55,True", "1,0.1,0.5,False"]
    files = [*tmp_path.glob("wall_*/**/*.csv"), steps]
    assert {p.name for p in files} >= {"forces.csv", "tension_top.csv", "interfaces.csv",
                                       "locations.csv", "mechanism.csv"}
    for path in files:
        frame = masonry.read_table(path)
        for name, dtype in frame.dtypes.items():
            if dtype.kind == "f":
                assert (re.search(r"_(N|N2|Nm|m|m2|deg|s|rel|per_m|kPa)$", name)
                        or name in DIMENSIONLESS), f"{path.name}: {name}"
        # a file of its header alone reads with the types of one with rows
        empty = tmp_path / "empty.csv"
        empty.write_text(path.read_text().splitlines()[0] + "\n")
        assert masonry.read_table(empty).dtypes.to_dict() == frame.dtypes.to_dict(), path
        assert pandas.read_csv(path).shape == frame.shape
    assert list(masonry.read_table(steps)["stands"]) == [True, False]
