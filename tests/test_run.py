"""``masonry run`` end to end, in-process: files, records, round trips, cache, atomicity."""

import csv
import json
import os
import time
from pathlib import Path

import meshio
import numpy as np
import pytest
import trimesh

from masonry.export import EXPORTERS, RunOutputs
from masonry.export.columns import COLUMNS
from masonry.params import Params, from_preset, structure_id, validate
from masonry.pipeline import Timer, run, write_exports
from masonry.rbe.boundary import analysis_model
from masonry.rbe.solve import RBEProblem
from masonry.scenes import build
from masonry_cli.main import main

RBE_KEYS = ("feasible", "friction", "mu", "objective", "moi", "moi_factor", "weight_N",
            "solver", "status", "iterations", "residual_eq", "friction_violation", "time_s",
            "lp_feasible")


@pytest.fixture(scope="module")
def wall_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs")
    assert main(["run", "--preset", "wall", "--fast", "--out", str(out), "-q"]) == 0
    return out, out / "wall_fast1_fricauto_L32_k10_u0.1"


def test_run_writes_every_output(wall_run):
    _, folder = wall_run
    for name in ("00_parameters.txt", "run.json", "locations.csv", "bricks.obj",
                 "interfaces.csv", "dome.stl", "dome.obj", "RBE/00_objective.txt",
                 "RBE/forces.csv", "RBE/interfaces.vtu",
                 "RBE/01_angle/compression_horizontal.png", "RBE/01_angle/normal.png"):
        assert (folder / name).is_file(), name
    record = json.loads((folder / "run.json").read_text())
    # the wall stands without tension: no tension figure, and run.json says why
    assert not (folder / "RBE/01_angle/tension.png").exists()
    assert "RBE/*/tension.png" in record["figures"]["skipped"]
    assert set(RBE_KEYS) <= set(record["rbe"])
    assert record["rbe"]["feasible"] is True
    assert record["counts"]["interfaces"] == {"horizontal": 144, "vertical": 75,
                                              "support": 8, "boundary": 0}
    assert record["printable"]["readback"]["watertight"]
    # the record says by how much locations.csv is moved from the model's bricks
    scene = build(from_preset("wall"))
    shift = np.linalg.norm(scene.cad_vertices() - scene.blocks.vertices, axis=1)
    assert record["coordinates"]["cad_offset_m"] == pytest.approx(shift.max(), rel=1e-12)
    assert "locations.csv" in record["coordinates"]["moved_inward"]
    assert record["printable"]["readback"]["bodies"] == 1
    text = (folder / "RBE/00_objective.txt").read_text()
    assert "feasible" in text and "MoI factor" in text and "friction-net" in text


def wall_outputs(plots, printable):
    """What ``masonry run --preset wall --fast`` makes, built here step by step."""
    params = validate(from_preset("wall", fast=True, plots=plots, printable=printable))
    scene = build(params)
    model = analysis_model(scene, params.analysis.boundary)
    result = RBEProblem(model.blocks, model.interfaces).solve(
        mu=params.analysis.mu, density=params.analysis.density, friction=params.analysis.friction,
        solver=params.analysis.solver, accuracy=params.analysis.accuracy)
    return RunOutputs(params, scene, model, result, title=structure_id(params))


class RecordingFolder:
    """Stands in for a RunFolder: writes into ``root`` (a forked process's files land
    there too) and refuses a file written twice, by either process."""

    def __init__(self, root):
        self.root = Path(root)

    def write(self, relative, data):
        path = self.root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        try:
            with open(path, "xb") as file:
                file.write(data.encode() if isinstance(data, str) else data)
        except FileExistsError:
            raise AssertionError(f"{relative} written twice") from None

    @property
    def files(self) -> dict:
        """What was written: path inside the folder -> bytes."""
        return {path.relative_to(self.root).as_posix(): path.read_bytes()
                for path in self.root.rglob("*") if path.is_file()}


def test_the_run_writes_what_the_registry_makes(wall_run, tmp_path):
    """The expected files come from the registry's exporters themselves: each one the
    run wants writes exactly its files, the others none, and the CLI's run folder holds
    the same files (byte for byte where no time is recorded in them)."""
    _, folder = wall_run
    made = wall_outputs(plots=False, printable=False)
    wanted = [e for e in EXPORTERS if e.wanted(made)]
    # plots (and with them dome.html) and the printable body are off
    assert {e.stage for e in wanted} == {"forces", "exports"}
    expected = {}
    for exporter in wanted:
        expected.update(exporter.make(made).files)
    recorder, record = RecordingFolder(tmp_path), {}
    write_exports(recorder, made, record, Timer())
    assert recorder.files.keys() == expected.keys()
    for name, data in expected.items():
        assert (folder / name).is_file(), name
        if name.endswith((".csv", ".obj", ".vtu")):
            data = data.encode() if isinstance(data, str) else data
            assert (folder / name).read_bytes() == data, name


@pytest.mark.parametrize("fork", [True, False])
def test_exporters_shared_with_a_forked_process_equal_the_ones_made_here(
        monkeypatch, tmp_path, fork):
    """The exporters after the forces are shared between this process and a forked one
    where the platform forks (and all made here where it does not): the files are the
    same bytes, each written once (by the process that made it), the names of all of
    them returned, and the time waited for the other process is a stage of its own."""
    monkeypatch.setattr("masonry.forking.can_fork", lambda: fork)
    monkeypatch.setattr("masonry.forking.cores", lambda: 2)
    made = wall_outputs(plots=True, printable=False)
    plots = [e for e in EXPORTERS if e.stage == "plots" and e.wanted(made)]
    expected = {name: data for e in plots for name, data in e.make(made).files.items()}
    assert "RBE/01_angle/normal.png" in expected and "01_angle/3_structure.png" in expected
    recorder, timer = RecordingFolder(tmp_path), Timer()
    written = write_exports(recorder, made, {}, timer)
    files = recorder.files
    assert expected and all(files[name] == data for name, data in expected.items())
    assert "bricks.3dm" in files
    assert sorted(name for names in written.values() for name in names) == sorted(files)
    assert ("other_process" in timer.seconds) == fork


def test_a_forked_process_that_dies_after_writing_has_its_share_made_here(
        monkeypatch, tmp_path, caplog):
    """The forked process writes a file of its share and dies before it reports: this
    process makes and writes that share again (over the file), and the run's files are
    whole and all named."""
    monkeypatch.setattr("masonry.forking.can_fork", lambda: True)
    monkeypatch.setattr("masonry.forking.cores", lambda: 2)
    made = wall_outputs(plots=False, printable=False)
    wanted = [e for e in EXPORTERS if e.wanted(made)]
    expected = {name: data for e in wanted for name, data in e.make(made).files.items()}
    here, waited = os.getpid(), []

    class DiesThere:
        def write(self, relative, data):
            if os.getpid() == here and not waited:  # the other process takes its share
                time.sleep(0.5)
                waited.append(relative)
            path = tmp_path / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data.encode() if isinstance(data, str) else data)
            if os.getpid() != here:
                os._exit(1)

    written = write_exports(DiesThere(), made, {}, Timer())
    assert "the second process failed" in caplog.text
    assert sorted(n for names in written.values() for n in names) == sorted(expected)
    for name, data in expected.items():
        assert (tmp_path / name).is_file(), name
        if name.endswith((".csv", ".obj", ".vtu")):
            data = data.encode() if isinstance(data, str) else data
            assert (tmp_path / name).read_bytes() == data, name


def test_an_exporter_failing_fails_the_run_and_keeps_the_earlier_folder(wall_run, monkeypatch, capsys):
    out, folder = wall_run
    before = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}

    def broken(*args, **kwargs):
        raise OSError("no space left on device")  # in whichever process makes it

    monkeypatch.setattr("masonry.export.rhino.blocks_3dm", broken)
    assert main(["run", "--preset", "wall", "--fast", "--force", "--no-plots",
                 "--out", str(out), "-q"]) == 1
    assert "no space left on device" in capsys.readouterr().err
    after = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert after == before
    assert not [p for p in out.iterdir() if p.name.startswith(".wall")]


def _forces_table(folder):
    with open(folder / "RBE/forces.csv") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in
            ("compression_N", "tension_N", "normal_N", "t1_N", "t2_N", "friction_N")}


def test_interfaces_vtu_round_trips_with_the_forces(wall_run):
    _, folder = wall_run
    table = _forces_table(folder)
    mesh = meshio.read(folder / "RBE/interfaces.vtu")
    order = np.concatenate(mesh.cell_data["interface"]).astype(int)
    assert sorted(order) == list(range(len(table["compression_N"])))
    for name in ("compression", "tension", "normal", "t1", "t2", "friction"):
        values = np.concatenate(mesh.cell_data[f"{name}_N"])
        np.testing.assert_allclose(values, table[f"{name}_N"][order], rtol=1e-9, atol=1e-9)


# every column of interfaces.csv and forces.csv reads, by pandas alone, as the column
# table declares it (masonry.export.columns; undeclared: a float), the same in every run
DECLARED_KIND = {"int": "i", "str": "O", "bool": "b", "float": "f"}


def test_tables_keep_their_column_types_and_vtu_order(wall_run):
    """A wall carries no tension: its tension column is all zeros and must still read as
    floats; forces.csv, interfaces.csv and the VTU cells are in the same order."""
    pandas = pytest.importorskip("pandas")
    _, folder = wall_run
    forces = pandas.read_csv(folder / "RBE/forces.csv")
    interfaces = pandas.read_csv(folder / "interfaces.csv")
    assert (forces["tension_N"].abs() < 1e-6 * forces["compression_N"].max()).all()
    for table in (forces, interfaces):
        for column, dtype in table.dtypes.items():
            declared = COLUMNS.get(column)
            expected = "f" if declared is None else DECLARED_KIND[declared.kind]
            assert (dtype.kind if expected != "O" else dtype.kind in "OT"
                    and "O") == expected, (column, dtype)
    shared = [c for c in interfaces.columns if c != "vertices"]
    pandas.testing.assert_frame_equal(forces[shared], interfaces[shared])
    np.testing.assert_array_equal(forces["id"], np.arange(len(forces)))
    mesh = meshio.read(folder / "RBE/interfaces.vtu")
    np.testing.assert_array_equal(np.concatenate(mesh.cell_data["interface"]), forces["id"])
    for name in ("compression_N", "tension_N", "normal_N", "friction_N", "eccentricity",
                 "torsion_Nm"):
        np.testing.assert_allclose(np.concatenate(mesh.cell_data[name]), forces[name],
                                   rtol=1e-11, atol=1e-9)
    np.testing.assert_allclose(np.concatenate(mesh.cell_data["shear_N"]),
                               forces[["shear_x_N", "shear_y_N", "shear_z_N"]], rtol=1e-11,
                               atol=1e-9)
    # every force column says its unit; the resultant carries the normal force
    assert all(c.endswith(("_N", "_Nm")) for c in forces.columns if c.startswith(
        ("compression", "tension", "t1_N", "t2_N", "friction", "shear", "torsion")))
    shear = forces[["shear_x_N", "shear_y_N", "shear_z_N"]].to_numpy()
    np.testing.assert_allclose(np.linalg.norm(shear, axis=1), forces["friction_N"],
                               rtol=1e-9, atol=1e-9)
    # no tension: every resultant within its joint; none where no force passes
    e = forces["eccentricity"]
    assert ((e.dropna() >= 0) & (e.dropna() <= 1 + 1e-9)).all()
    assert (forces["compression_N"][e.isna()] <= 1e-9 * forces["compression_N"].max()).all()


def test_bricks_obj_round_trips(wall_run):
    _, folder = wall_run
    blocks = build(from_preset("wall")).blocks
    scene = trimesh.load(folder / "bricks.obj", split_objects=True, group_material=False,
                         process=False)
    assert len(scene.geometry) == blocks.n_blocks
    for i, name in enumerate(blocks.block_name):
        mine = np.unique(np.round(blocks.block_vertices(i), 9), axis=0)
        theirs = np.unique(np.round(scene.geometry[name].vertices, 9), axis=0)
        np.testing.assert_allclose(theirs, mine, atol=1e-10)


def test_rerun_is_reused_and_other_mu_reuses_geometry(wall_run, capsys):
    out, folder = wall_run
    stamp = (folder / "run.json").stat().st_mtime_ns
    assert main(["run", "--preset", "wall", "--fast", "--out", str(out), "-q"]) == 0
    assert (folder / "run.json").stat().st_mtime_ns == stamp
    assert "up to date" in capsys.readouterr().out
    assert main(["run", "--preset", "wall", "--fast", "--mu", "0.4", "--no-plots",
                 "--out", str(out), "-q"]) == 0
    record = json.loads((out / "wall_fast1_fricauto_L32_k10_u0.1_mu0.4" / "run.json")
                        .read_text())
    assert record["cache"] == {"geometry": "reused"}
    assert record["rbe"]["mu"] == 0.4


def test_run_failing_midway_leaves_the_earlier_folder(wall_run, monkeypatch):
    out, folder = wall_run
    before = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}

    def broken(*args, **kwargs):
        raise KeyboardInterrupt  # an interrupted run, halfway through its exports

    monkeypatch.setattr("masonry.export.csv.forces_csv", broken)
    assert main(["run", "--preset", "wall", "--fast", "--force", "--out", str(out),
                 "-q"]) == 130
    after = {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert after == before
    assert not [p for p in out.iterdir() if p.name.startswith(".wall")]


def test_invalid_mu_writes_nothing(tmp_path, capsys):
    assert main(["run", "--mu", "-1", "--out", str(tmp_path / "x")]) == 2
    assert "--mu -1: expected" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_run_json_names_only_the_files_the_folder_holds(tmp_path):
    """``coordinates`` lists files by coordinate system: a build without a solve or a
    printable body has no forces and no STL to list."""
    record = run(validate(Params.of(scene="wall", wall_courses=2, wall_length=8, plots=False,
                                    printable=False)), tmp_path, analyse=False)
    folder = Path(record["path"])
    listed = record["coordinates"]["model"] + record["coordinates"]["moved_inward"]
    assert "bricks.obj" in listed and "RBE/forces.csv" not in listed
    assert "dome.stl" not in listed and not (folder / "RBE").exists()
    assert all((folder / name).is_file() for name in listed)


def test_the_output_bench_times_every_exporter_a_run_writes(tmp_path, capsys):
    from masonry_benchmarks.output_bench import output_bench, outputs_markdown

    params = validate(Params.of(scene="arch", fast=True))
    rows = output_bench({"arch": params})
    # every exporter a run of it writes, in the registry's order
    assert [row["exporter"] for row in rows] == [
        "rbe", "force_plots", "printable", "structure_plots", "interface_plots", "rhino",
        "html", "compas", "model"]
    assert all(row["seconds"] > 0 and row["cpu_seconds"] >= 0 for row in rows)
    plots = [row for row in rows if row["exporter"] == "force_plots"]
    assert plots and plots[0]["files"] >= 2 and plots[0]["bricks"] == 16
    assert outputs_markdown(rows).splitlines()[-1].startswith("| arch | | all | |")
    assert main(["bench", "--outputs", "--collapse", "--out", str(tmp_path)]) == 2
    assert "one bench at a time" in capsys.readouterr().err


def test_the_scale_bench_measures_a_fresh_run_and_fits_power_laws(tmp_path, capsys):
    from masonry_benchmarks.scale_bench import exponent, scale_bench, scale_markdown

    power = [{"bricks": b, "x": 3.0 * b**1.5} for b in (1000, 5000, 20000, 80000)]
    assert exponent(power, "x") == pytest.approx(1.5, abs=1e-12)
    assert exponent(power[:2], "x") is None  # one row of at least 5,000 bricks
    # the wall preset: 10 courses of 8 and of 9 bricks (fixtures/README.md), standing
    [row] = scale_bench({"wall": ("wall", "wall", {})})
    assert row["bricks"] == 85 and row["verdict"] == "feasible"
    assert 0 < row["solve_s"] < row["wall_s"] and row["cpu_s"] > 0
    assert row["newton_steps"] >= 1 and 0.05 < row["peak_gib"] < 2.0
    assert "| wall | 85 | feasible |" in scale_markdown([row])
    assert main(["bench", "--scale", "--stages", "--out", str(tmp_path)]) == 2
    assert "one bench at a time" in capsys.readouterr().err
