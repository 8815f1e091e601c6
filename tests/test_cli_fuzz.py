"""Fuzz of the command line and its input files.

Every input either succeeds or is refused with exit code 2 and one line on stderr that
names the option as typed (or the file and key), with no traceback and nothing written.
The listed cases are the ones users met; hypothesis draws hundreds more. Inputs that pass
validation are built (scene only, without interfaces and solve) when small, so a value
that validation lets through but the builder cannot take is caught too.
"""

import contextlib
import io
import json
import math
import os
import re
import struct
import tempfile
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from masonry.params import names, validate
from masonry.pipeline import model_record
from masonry.runfolder import check_output_root
from masonry.scenes import build, check_size
from masonry_cli.app import make_parser
from masonry_cli.main import main

OPTION = re.compile(r"--[a-z][a-z-]*")


def call(argv):
    """``main(argv)`` -> (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exit_info:  # argparse
            code = exit_info.code
    return code, out.getvalue(), err.getvalue()


def assert_clean(argv, out_root, code, err, files=()):
    """Success, or one clean refusal: exit 2, one line naming an option (or a file) the
    user gave, no traceback, nothing written."""
    assert "Traceback" not in err, (argv, err)
    if code in (0, 3):  # done; or, from the stub pipeline, not solved
        return
    assert code == 2, (argv, code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, (argv, err)
    line = lines[0]
    assert line.startswith("masonry: error: "), (argv, line)
    typed = [a for a in argv if a.startswith("--")]
    named = (any(t in line for t in typed) or any(str(f) in line for f in files)
             or "(the default)" in line or "(from --preset" in line
             or "--max-bricks" in line or "invalid choice" in line
             or "expected one argument" in line or "required" in line
             or "unrecognized arguments" in line or re.search(r"blocks? .*'", line))
    assert named, (argv, line)
    assert not Path(out_root).exists(), (argv, "wrote output")


def stub_pipeline(params, out_root, **kwargs):
    """The pipeline up to the model: validation, output root, size, and (small) scene;
    no solve (its record says so)."""
    params = validate(params)
    check_output_root(out_root)
    check_size(params, kwargs["max_bricks"])  # the fuzz keeps it at 1500: quick builds
    scene = build(params)
    record = model_record(scene, params.analysis.density)
    rbe = {"verdict": "not solved", "feasible": False, "friction": params.analysis.friction,
           "mu": params.analysis.mu, "residual_eq": math.nan, "solver": "none", "status": "stub"}
    return {**record, "structure_id": "fuzz", "scene": params.scene, "path": str(out_root),
            "params": {"friction": params.analysis.friction}, "rbe": rbe}


# ----------------------------------------------------------------------- listed cases
LISTED = [
    ["--n", "1000000"], ["--p", "1000000"], ["--r", "1000"], ["--stretch", "1e6"],
    ["--stretch", "1e308"], ["--stretch", "0.05"], ["--unit", "1e308"], ["--unit", "1e-308"],
    ["--preset", "wall", "--wall-length", "1e6"],
    ["--scene", "arch", "--span", "1e308"], ["--scene", "arch", "--depth", "1e308"],
    ["--scene", "arch", "--depth", "1e-9"], ["--scene", "arch", "--thickness", "1e-308"],
    ["--scene", "arch", "--shape", "segmental", "--rise", "1e-300"],
    ["--scene", "arch", "--blocks", "1"], ["--scene", "arch", "--blocks", "15",
                                           "--shape", "pointed"],
    ["--scene", "arch", "--n", "5"], ["--preset", "1", "--thickness", "0.3"],
    ["--mu", "1e-12"], ["--mu", "1e12"], ["--mu", "1e308"], ["--density", "1e308"],
    ["--n", "2"], ["--stretch", "nan"], ["--cut", "1"], ["--p", "0"], ["--r", "-1"],
    ["--min-fill", "0"], ["--wall-courses", "0", "--scene", "wall"],
    ["--n", "eight"], ["--scene", "moon"], ["--params", ""], ["--params", "missing.toml"],
    ["--max-bricks", "x"], ["--max-bricks", "10"],
    ["--print-size", "-5"], ["--print-size", "0"], ["--print-size", "nan"],
    ["--print-size", "1e308"], ["--print-size", "150", "--no-printable"],
    ["--lateral", "east"], ["--lateral", "nan"], ["--lateral", "1e400"],
    ["--dome", "--lateral", "30"], ["--dome", "--point-load", "w0_*:1000,0,0"],
    ["--point-load", "w0_*:1,2"], ["--point-load", "w0_*:0,0,0"], ["--point-load", ":1,2,3"],
    ["--point-load", "w0_*:1,2,nan"], ["--crown-load", "0"], ["--crown-load", "-5"],
    ["--crown-load", "nan"], ["--scene", "wall", "--crown-load", "500"],
    ["--lateral", "0", "--crown-load", "500"], ["--point-load", "a*:0,0,-1", "--lateral", "0"],
    ["--friction-law", "non-associative"], ["--friction-law", "coulomb", "--lateral", "0"],
    ["--preset", "wall", "--scene", "dome"], ["--preset", "1", "--scene", "arch"],
    ["--scene", "dome", "--lateral", "all", "--friction-law", "non-associative"],
    ["--pattern", "plain"], ["--pattern", ""], ["--scene", "wall", "--pattern", "none"],
    ["--scene", "arch", "--pattern", "herringbone"], ["--p", "1"],
    ["--pattern", "none", "--p", "0"], ["--friction-cone", "polygon:\u00b2"],
    ["--crown-load", "1e308"], ["--crown-load", "1e19"],
    ["--scene", "dome", "--point-load", "*:1e19,0,0"],
]
RUN_ONLY = [["--scene", "arch", "--boundary", "cyclic"], ["--scene", "wall", "--dome"],
            ["--friction", "none"], ["--solver", "gurobi"]]


@pytest.mark.parametrize("args", LISTED + RUN_ONLY)
def test_listed_command_line_mistakes(tmp_path, args):
    out = tmp_path / "out"
    argv = ["run", *args, "--out", str(out), "-q"]
    code, _, err = call(argv)
    assert code == 2
    assert_clean(argv, out, code, err)


OTHER_COMMANDS = [
    ["bench", "--repeats", "0"], ["bench", "--p", "0"], ["arch-thickness", "--rtol", "0"],
    ["arch-thickness", "--rtol", "nan"], ["arch-thickness", "--blocks", "1"],
    ["arch-thickness", "--mu", "0.01", "--blocks", "8"],  # slides at every thickness
    ["analyze", "missing.obj", "--ground"], ["--bogus"], [],
    ["stages", "--by", "brick", "--order", "sideways"],
    ["stages", "--by", "brick", "--course", "0"],
    ["stages", "--n", "1000000"], ["stages", "--scene", "arch", "--by", "course"],
    ["stages", "--scene", "dome", "--lateral", "all"], ["stages", "--lateral", "30"],
    ["stages", "--scene", "dome", "--lateral", "north"],
    ["arch-thickness", "--blocks", "2"], ["arch-thickness", "--blocks", "3"],
    ["arch-thickness", "--blocks", "4", "--rtol", "1e-17"],
    ["arch-thickness", "--solver", "highs-ipm"], ["stages", "--support-below", "0"],
]


@pytest.mark.parametrize("args", OTHER_COMMANDS)
def test_other_commands_mistakes(tmp_path, args):
    out = tmp_path / "out"
    argv = [*args, "--out", str(out)] if args and not args[0].startswith("--") else args
    code, _, err = call(argv)
    assert code == 2
    assert_clean(argv, out, code, err, files=["missing.obj"])


@pytest.mark.parametrize("command", [["sweep"], ["optimize", "--maximize", "bricks"]])
@pytest.mark.parametrize("address", ["foo://bar", "nonsense"])
def test_a_bad_scheduler_address(tmp_path, address, command):
    pytest.importorskip("dask.distributed")
    study = tmp_path / "study.toml"
    study.write_text("[grid]\nmu = [0.7]\n")
    out = tmp_path / "out"
    argv = [command[0], str(study), *command[1:], "--scheduler", address, "--out", str(out)]
    code, _, err = call(argv)
    assert code == 2 and "running Dask scheduler" in err, err
    assert_clean(argv, out, code, err)


@pytest.mark.parametrize("command", ["run", "build", "structures", "sweep", "optimize",
                                     "bench", "arch-thickness", "stages"])
@pytest.mark.parametrize("where", ["file", "under_file", "proc", "empty", "long_name"])
def test_output_locations(tmp_path, command, where):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    study = tmp_path / "study.toml"
    study.write_text("[grid]\nmu = [0.7]\n")
    out = {"file": a_file, "under_file": a_file / "sub", "proc": "/proc/masonry",
           "empty": "", "long_name": tmp_path / ("a" * 300)}[where]
    head = {"sweep": ["sweep", str(study)], "bench": ["bench", "--repeats", "1"],
            "optimize": ["optimize", str(study), "--maximize", "bricks"]}
    argv = [*head.get(command, [command]), "--out", str(out), "-q"]
    code, _, err = call(argv)
    assert code == 2 and err.startswith("masonry: error: --out ")
    assert_clean(argv, tmp_path / "nothing", code, err)
    assert a_file.read_text() == "x"


PARAM_FILES = {
    "malformed": b"n = [\n", "duplicate": b"n = 4\nn = 5\n", "nul": b"n = 4\x00\n",
    "latin1": "n = 4 # caf\xe9\n".encode("latin-1"), "fast_type": b'fast = "yes"\n',
    "unknown": b"colour = 3\n", "huge_n": b"n = 100000000\n", "bad_n": b"n = 2\n",
    "list": b"stretch = [1, 2]\n", "params_not_table": b"params = 3\n",
    "big_int": b"p = 99999999999999999999\n", "nan": b"unit = nan\n",
    "pattern": b'pattern = "plain"\n', "pattern_type": b"pattern = 0\n",
    "wall_pattern": b'scene = "wall"\npattern = "none"\n',
}


@pytest.mark.parametrize("name", sorted(PARAM_FILES))
def test_broken_parameter_files(tmp_path, name):
    path = tmp_path / f"{name}.toml"
    path.write_bytes(PARAM_FILES[name])
    out = tmp_path / "out"
    argv = ["build", "--params", str(path), "--out", str(out)]
    code, _, err = call(argv)
    assert code == 2
    assert_clean(argv, out, code, err, files=[path])


def test_a_folder_a_device_a_huge_file_or_a_bom_as_parameter_file(tmp_path):
    out = tmp_path / "out"
    for path in (tmp_path, "/dev/zero"):  # a device would be read forever
        argv = ["build", "--params", str(path), "--out", str(out)]
        code, _, err = call(argv)
        assert code == 2 and "not a folder or a device" in err
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * 2**21)
    argv = ["build", "--params", str(big), "--out", str(out)]
    code, _, err = call(argv)
    assert code == 2 and "at most 1 MiB" in err
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbfn = 2\n")  # read (BOM allowed), then refused for n
    argv = ["build", "--params", str(bom), "--out", str(out)]
    code, _, err = call(argv)
    assert code == 2 and "n = 2: expected an integer >= 3" in err


STUDIES = {
    "base_scalar": "base = 5\n", "grid_scalar": "grid = 5\n",
    "sample_scalar": "[sample]\nmu = 0.5\ncount = 2\n",
    "sample_string": '[sample]\nmu = "x"\ncount = 2\n',
    "count_string": '[sample]\nmu = [0.5, 0.7]\ncount = "2"\n',
    "count_huge": "[sample]\nmu = [0.5, 0.7]\ncount = 1000000000\n",
    "misspelled": "[grids]\nmu = [0.5]\n", "plots_string": '[outputs]\nplots = "no"\n',
    "dome_not_bool": "[grid]\ndome = [true, 3]\n", "unknown_option": "[grid]\ncolour = [1]\n",
    "empty_list": "[grid]\nmu = []\n", "preset": "[base]\npreset = 7\n",
    "pattern": '[grid]\npattern = ["herringbone", "plain"]\n',
    "pattern_p1": '[base]\np = 1\n[grid]\npattern = ["none", "herringbone"]\n',
    "stages_list": '[grid]\nmu = [0.7]\n[outputs]\nstages = ["course"]\n',
    "seed_negative": "[sample]\nmu = [0.5, 0.7]\ncount = 2\nseed = -1\n",
    "latin1": None,
}


@pytest.mark.parametrize("name", sorted(STUDIES))
def test_broken_study_files(tmp_path, name):
    path = tmp_path / f"{name}.toml"
    text = STUDIES[name]
    path.write_bytes("mu = 'caf\xe9'\n".encode("latin-1") if text is None else text.encode())
    out = tmp_path / "out"
    argv = ["sweep", str(path), "--workers", "1", "--out", str(out)]
    code, _, err = call(argv)
    assert code == 2
    assert_clean(argv, out, code, err, files=[path])


# ----------------------------------------------------------------------- mesh files
def box_obj(boxes) -> str:
    """OBJ text of unit cubes: ``[(name, (x, y, z)), ...]`` (their lower corners)."""
    lines, offset = [], 0
    for name, corner in boxes:
        box = trimesh.creation.box(extents=(1, 1, 1))
        box.apply_translation(np.asarray(corner, float) + 0.5)
        lines.append(f"o {name}")
        lines += [f"v {x:g} {y:g} {z:g}" for x, y, z in box.vertices]
        lines += ["f " + " ".join(str(offset + 1 + i) for i in face) for face in box.faces]
        offset += len(box.vertices)
    return "\n".join(lines) + "\n"


TOWER = [("base", (0, 0, 0)), ("top", (0, 0, 1))]
MESHES = {
    "floating.obj": (box_obj(TOWER + [("lost", (5, 5, 5))]), "no path of contacts"),
    "gap.obj": (box_obj([("base", (0, 0, 0)), ("top", (0, 0, 1.001))]), "no path"),
    "edge.obj": (box_obj([("base", (0, 0, 0)), ("top", (1, 1, 1))]), "no path"),
    "duplicate.obj": (box_obj(TOWER + [("again", (0, 0, 1))]), "overlap"),
    "interpenetrating.obj": (box_obj([("base", (0, 0, 0)), ("top", (0, 0, 0.5))]),
                             "overlap"),
    "nan.obj": (box_obj(TOWER).replace("v 0 0 1\n", "v nan 0 1\n", 1), "not finite"),
    "inf.obj": (box_obj(TOWER).replace("v 0 0 1\n", "v inf 0 1\n", 1), "not finite"),
    "empty.obj": ("", "empty"), "words.obj": ("hello world\n", "no faces"),
}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_malformed_meshes(tmp_path, name):
    text, expected = MESHES[name]
    path = tmp_path / name
    path.write_text(text)
    out = tmp_path / "out"
    argv = ["analyze", str(path), "--support", "base", "--out", str(out), "-q"]
    code, _, err = call(argv)
    assert code == 2 and expected in err, err
    assert_clean(argv, out, code, err, files=[path])


def test_the_same_file_twice_overlaps(tmp_path):
    path = tmp_path / "tower.obj"
    path.write_text(box_obj(TOWER))
    out = tmp_path / "out"
    argv = ["analyze", str(path), str(path), "--support", "base*", "--out", str(out)]
    code, _, err = call(argv)
    assert code == 2 and "overlap" in err
    assert_clean(argv, out, code, err, files=[path])


def stl_bytes(triangles) -> bytes:
    triangles = np.asarray(triangles, "<f4").reshape(-1, 3, 3)
    records = np.zeros(len(triangles), [("normal", "<f4", 3), ("points", "<f4", (3, 3)),
                                        ("attr", "<u2")])
    records["points"] = triangles
    return b"\0" * 80 + struct.pack("<I", len(triangles)) + records.tobytes()


def test_binary_meshes_with_nan_random_bytes_and_ply(tmp_path):
    box = trimesh.creation.box(extents=(1, 1, 1))
    triangles = box.vertices[box.faces].copy()
    triangles[0, 0, 0] = np.nan
    rng = np.random.default_rng(5)
    cases = {
        "nan.stl": stl_bytes(triangles),
        "random.stl": b"\0" * 80 + struct.pack("<I", 3000) + rng.bytes(50 * 3000),
        "random_size.stl": rng.bytes(5000),
    }
    ply = trimesh.Trimesh(box.vertices.copy(), box.faces, process=False)
    ply.vertices[0] = [np.inf, 0, 0]
    cases["inf.ply"] = ply.export(file_type="ply")
    for name, data in cases.items():
        path = tmp_path / name
        path.write_bytes(data)
        out = tmp_path / "out"
        argv = ["analyze", str(path), "--ground", "--out", str(out)]
        code, _, err = call(argv)
        assert code == 2, (name, err)
        assert_clean(argv, out, code, err, files=[path])


def test_a_fifo_or_a_folder_as_mesh(tmp_path):
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    folder = tmp_path / "folder.obj"
    folder.mkdir()
    for path in (fifo, folder):
        argv = ["analyze", str(path), "--ground", "--out", str(tmp_path / "out")]
        code, _, err = call(argv)
        assert code == 2 and "not a regular file" in err
        assert_clean(argv, tmp_path / "out", code, err, files=[path])


# ----------------------------------------------------------------------- hypothesis
WILD_FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["0", "-1", "1e-308", "1e308", "1e6", "nan", "inf", "-0", "1e-9"]),
    st.text(alphabet="0123456789.-e x", max_size=6))
WILD_INTEGERS = st.one_of(st.integers().map(str),
                          st.sampled_from(["1e3", "x", "", "99999999999999999999", "-0"]))
PLAUSIBLE = {
    # option: values a user would try; wild ones are drawn beside them
    "--stretch": ["0.3", "0.5", "1", "1.5", "2", "4"], "--cut": ["0", "0.05", "0.3", "0.9"],
    "--unit": ["0.05", "0.1", "1", "0.001"], "--min-fill": ["0.5", "1", "2", "4"],
    "--n": ["3", "4", "6", "8", "12"], "--r": ["0", "1", "2"], "--p": ["1", "3", "5", "8"],
    "--wall-length": ["4", "8", "12.5", "32"], "--wall-courses": ["1", "3", "10"],
    "--mu": ["0.3", "0.7", "1", "0.05"], "--density": ["1500", "2000", "2.5e3"],
    "--cohesion-kpa": ["0", "0.5", "1", "300"], "--tensile-kpa": ["0", "0.25", "100"],
    "--adhesion-tension-ratio": ["0", "0.5", "1"],
    "--head-joint-ratio": ["0", "0.5", "1"], "--support-joint-ratio": ["0", "1", "2"],
    "--figure-format": ["png", "svg", "pdf", "png,pdf", "tiff"], "--dpi": ["50", "110", "300"],
    "--html-plotly": ["shared", "inline", "cdn"],
    "--span": ["1", "5", "10", "0.5"], "--thickness": ["0.05", "0.3", "0.6", "2"],
    "--rise": ["1", "2.5", "5", "8"], "--depth": ["0.2", "1", "3"],
    "--blocks": ["2", "3", "8", "16", "40"],
    "--shape": ["semicircular", "pointed", "segmental", "round"],
    "--boundary": ["free", "rigid", "cyclic", "open"],
    "--friction": ["net", "plus", "auto", "none"],
    "--accuracy": ["fast", "balanced", "accurate", "best"],
    "--print-size": ["100", "150", "200"], "--cad-offset": ["0", "0.5", "1", "4", "5"],
    "--lateral": ["0", "30", "-90", "all", "east"],
    "--point-load": ["w0_*:1000,0,0", "*:0,0,-500", "w0_b0001*:0,0,-1e4", "w0:1,2", "x"],
    "--crown-load": ["500", "20000", "0", "-100"],
    "--friction-law": ["associated", "non-associative", "coulomb"],
    "--friction-cone": ["circle", "polygon:16", "square", "polygon:4", "disc"],
    "--radius": ["12", "20", "50", "8"], "--spirals": ["2", "4", "7", "12", "40"],
    "--helix-angle": ["45", "50", "60", "30", "85"],
    "--helix": ["loxodrome", "clelia", "spiral"],
    "--pattern": ["herringbone", "none", "stripes"],
}
INTEGER_OPTIONS = {"--n", "--r", "--p", "--wall-courses", "--blocks", "--spirals", "--dpi"}
REVOLUTION = ["--radius", "--stretch", "--cut", "--unit", "--min-fill", "--p", "--spirals",
              "--helix-angle", "--helix", "--pattern"]
SCENE_OPTIONS = {
    None: ["--stretch", "--cut", "--unit", "--min-fill", "--n", "--r", "--p", "--boundary",
           "--pattern"],
    "dome": ["--stretch", "--cut", "--unit", "--min-fill", "--n", "--r", "--p", "--pattern"],
    "wall": ["--wall-length", "--wall-courses", "--unit"],
    "arch": ["--span", "--thickness", "--rise", "--depth", "--blocks", "--shape"],
    "sector": REVOLUTION + ["--boundary"],
    "revolution": REVOLUTION,
}
EVERY_SCENE = ["--mu", "--density", "--friction", "--accuracy", "--print-size", "--lateral",
               "--point-load", "--crown-load", "--friction-law", "--friction-cone",
               "--cohesion-kpa", "--tensile-kpa", "--head-joint-ratio",
               "--support-joint-ratio", "--adhesion-tension-ratio", "--cad-offset"]


def test_the_tables_cover_every_option_of_run():
    # a new option of `masonry run` that sets a parameter is fuzzed, or at least listed
    parser = make_parser()._subparsers._group_actions[0].choices["run"]
    options = {action.option_strings[-1] for action in parser._actions
               if action.dest in names() and action.nargs != 0}
    covered = set(PLAUSIBLE) | {a for args in LISTED + RUN_ONLY for a in args}
    assert "--print-size" in options and options <= covered, options - covered


def value_of(option):
    plausible = st.sampled_from(PLAUSIBLE[option])
    if option in ("--shape", "--boundary", "--friction", "--accuracy", "--point-load",
                  "--friction-law", "--friction-cone", "--helix", "--pattern",
                  "--figure-format", "--html-plotly"):
        return plausible
    wild = WILD_INTEGERS if option in INTEGER_OPTIONS else WILD_FLOATS
    return st.one_of(plausible, plausible, plausible, wild)


@st.composite
def command_lines(draw):
    """A scene, then up to four options: mostly the scene's own and plausible values,
    sometimes another scene's option or a wild value."""
    scene = draw(st.sampled_from([None, "dome", "wall", "arch", "sector", "revolution"]))
    every = sorted(PLAUSIBLE)
    mostly = SCENE_OPTIONS[scene] + EVERY_SCENE
    names = draw(st.lists(st.one_of(*[st.sampled_from(mostly)] * 6, st.sampled_from(every)),
                          max_size=4, unique=True))
    argv = [] if scene is None else ["--scene", scene]
    if scene == "wall" and draw(st.booleans()):
        argv = ["--preset", "wall"]
    for name in names:
        argv += [name, draw(value_of(name))]
    return argv


@settings(max_examples=400, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck))
@given(command_lines())
@pytest.mark.slow
def test_fuzz_command_line(argv):
    with tempfile.TemporaryDirectory() as tmp, pytest.MonkeyPatch.context() as patch:
        patch.setattr("masonry.pipeline.run", stub_pipeline)  # imported by the command
        out = Path(tmp) / "out"
        full = ["run", *argv, "--max-bricks", "1500", "--out", str(out), "-q"]
        code, _, err = call(full)
        assert_clean(full, out, code, err)


TOML_VALUES = st.one_of(
    st.integers(-5, 30), st.integers(), st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(), st.text(max_size=8), st.lists(st.integers(0, 3), max_size=3))


def toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") \
            if math.isinf(value) else repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(map(str, value)) + "]"
    return json.dumps(value) if isinstance(value, str) else str(value)


@settings(max_examples=200, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck))
@given(st.one_of(
    st.dictionaries(st.sampled_from(sorted(names()) + ["colour"]),
                    TOML_VALUES, max_size=4).map(
        lambda d: "".join(f"{k} = {toml_value(v)}\n" for k, v in d.items()).encode()),
    st.binary(max_size=40)))
@pytest.mark.slow
def test_fuzz_parameter_files(content):
    with tempfile.TemporaryDirectory() as tmp, pytest.MonkeyPatch.context() as patch:
        patch.setattr("masonry.pipeline.run", stub_pipeline)
        path, out = Path(tmp) / "params.toml", Path(tmp) / "out"
        path.write_bytes(content)
        argv = ["build", "--params", str(path), "--max-bricks", "1500", "--out", str(out)]
        code, _, err = call(argv)
        assert_clean(argv, out, code, err, files=[path])


STUDY_KEYS = ["mu", "density", "friction", "stretch", "dome", "preset", "count", "seed",
              "plots", "colour", "wall-length"]


@settings(max_examples=150, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck))
@given(st.one_of(
    st.dictionaries(st.sampled_from(["base", "grid", "sample", "outputs", "grids"]),
                    st.dictionaries(st.sampled_from(STUDY_KEYS), TOML_VALUES, max_size=3),
                    max_size=3).map(
        lambda tables: "".join(f"[{name}]\n" + "".join(f"{k} = {toml_value(v)}\n"
                                                       for k, v in table.items())
                               for name, table in tables.items()).encode()),
    st.binary(max_size=40)))
@pytest.mark.slow
def test_fuzz_study_files(content):
    rows = {"status": "computed", "error": ""}
    with tempfile.TemporaryDirectory() as tmp, pytest.MonkeyPatch.context() as patch:
        # the study is read and checked for real; its variants are not run here
        patch.setattr("masonry.studies.sweep.execute", lambda study, *args: (
            (i, inputs, rows) for i, inputs in enumerate(study.variants()[:3])))
        path, out = Path(tmp) / "study.toml", Path(tmp) / "out"
        path.write_bytes(content)
        argv = ["sweep", str(path), "--workers", "1", "--out", str(out)]
        code, _, err = call(argv)
        assert_clean(argv, out, code, err, files=[path])
