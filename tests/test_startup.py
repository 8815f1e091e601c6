"""Start-up: a command imports what it needs when it needs it, so ``masonry --version``
and a refused option answer before numpy's solvers, plots or exporters load (their time
goes to ``masonry bench``, not here: these tests check which modules load)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from masonry.rbe.solvers import BACKENDS, REGISTRY, names

HEAVY = ("scipy", "matplotlib", "cvxpy", "meshio", "rhino3dm", "dask", "pandas", "trimesh",
         "manifold3d", "clarabel", "highspy", "osqp", "pymetis", "lxml", "networkx",
         "plotly")
"""Libraries a command loads only when it does the work that needs them."""


def loaded_by(argv, modules=HEAVY) -> tuple:
    """The exit code of ``masonry ARGV`` in a fresh process, which of ``modules`` it
    loaded and whether it loaded numpy."""
    script = ("import json, sys\n"
              "from masonry_cli.main import main\n"
              "try:\n"
              f"    code = main({argv!r})\n"
              "except SystemExit as exit:\n"
              "    code = exit.code\n"
              f"heavy = sorted(m for m in {tuple(modules)!r} if m in sys.modules)\n"
              "print(json.dumps([code, heavy, 'numpy' in sys.modules]))\n")
    root = Path(__file__).resolve().parent.parent
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        filter(None, [os.environ.get("PYTHONPATH"), str(root)]))}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          env=env, check=False, timeout=600)
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_version_loads_no_library(capsys):
    code, heavy, numpy = loaded_by(["--version"])
    assert code == 0 and heavy == [] and not numpy


@pytest.mark.parametrize("argv", [
    ["run", "--mu", "-1"], ["run", "--scene", "arch", "--n", "5"], ["build", "--p", "0"],
    ["stages", "--support", "x"], ["analyze", "x.obj", "--support", "a", "--mu", "20"],
    ["sweep", "missing.toml"], ["optimize", "missing.toml", "--maximize", "bricks"],
    ["optimize", "--help"], ["run", "--help"], ["--help"],
])
def test_a_refused_option_loads_no_solver_plot_or_exporter(tmp_path, argv):
    code, heavy, _ = loaded_by([*argv, "--out", str(tmp_path / "o")] if "--help" not in argv
                               else argv)
    assert code in (0, 2) and not (tmp_path / "o").exists()
    assert heavy == []


def test_a_run_that_stands_loads_no_optimizer_plot_or_printing_library(tmp_path):
    """The self weight of a wall that stands, without figures or printable body: no
    scipy.optimize (an azimuth's refinement or a dome's levels need it), no plots, no
    printing geometry, no modelling layer."""
    unused = ("scipy.optimize", "matplotlib", "plotly", "cvxpy", "osqp", "trimesh",
              "manifold3d", "meshio", "dask", "compas")
    code, loaded, _ = loaded_by(["run", "--scene", "wall", "--no-plots", "--no-printable",
                                 "-q", "--out", str(tmp_path / "o")], unused)
    assert code == 0 and (tmp_path / "o").is_dir()
    assert loaded == []


def test_the_solver_registry_says_what_each_backend_declares():
    for name, (module, problems, pyramids) in REGISTRY.items():
        backend = BACKENDS[name]
        assert backend.name == name and backend.rbe or backend.collapse
        assert backend.problems == problems and backend.polyhedral_only == pyramids, name
    assert list(BACKENDS) == list(REGISTRY) == list(names())
