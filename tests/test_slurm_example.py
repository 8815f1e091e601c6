"""examples/slurm_study.py end to end: dask-jobqueue's SLURMCluster submits a job that
starts a Dask worker, the study runs on it, the job is cancelled; ``sbatch`` and
``scancel`` are played by two scripts that run the job on this machine (loopback)."""

import csv
import os
import subprocess
import sys

import pytest

from masonry_cli.main import main

pytest.importorskip("dask_jobqueue")

STUDY = """
[base]
scene = "arch"
lateral = 0
[grid]
blocks = [6, 8]
"""

FAKE_SBATCH = """#!/bin/sh
# sbatch on this machine: run the job script in a process group of its own; its
# process id is the job id
cp "$1" "$(dirname "$0")/job-$$.sh"
setsid bash "$(dirname "$0")/job-$$.sh" > "$(dirname "$0")/job-$$.log" 2>&1 &
echo "Submitted batch job $!"
"""

FAKE_SCANCEL = """#!/bin/sh
for job in "$@"; do kill -TERM -- "-$job" 2>/dev/null; done
exit 0
"""


def _summary(root):
    with open(root / "sweep_two" / "summary.csv") as f:
        return [{k: r[k] for k in ("arch_blocks", "feasible", "load_factor", "weight_N",
                                   "structure_id")} for r in csv.DictReader(f)]


@pytest.mark.slow
def test_the_slurm_example_runs_a_study_through_sbatch(tmp_path):
    bin = tmp_path / "bin"
    bin.mkdir()
    for name, text in (("sbatch", FAKE_SBATCH), ("scancel", FAKE_SCANCEL)):
        (bin / name).write_text(text)
        (bin / name).chmod(0o755)
    study = tmp_path / "two.toml"
    study.write_text(STUDY)
    assert main(["sweep", str(study), "--workers", "1", "--out", str(tmp_path / "serial"),
                 "-q"]) == 0
    example = os.path.join(os.path.dirname(__file__), "..", "examples", "slurm_study.py")
    env = {**os.environ, "PATH": f"{bin}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run(
        [sys.executable, example, "--jobs", "1", "--interface", "lo", "--", "sweep",
         str(study), "--out", str(tmp_path / "out"), "-q"],
        env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "2 variants: 2 computed" in done.stdout
    assert _summary(tmp_path / "out") == _summary(tmp_path / "serial")
    jobs = [p for p in bin.iterdir() if p.suffix == ".sh"]
    assert len(jobs) == 1 and "distributed.cli.dask_worker" in jobs[0].read_text()
