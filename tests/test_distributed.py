"""Sweeps and optimisations on a real Dask cluster: a scheduler and two workers started
as processes of their own on loopback (``dask scheduler`` / ``dask worker``), as on
machines of a cluster. The results equal the serial ones; a worker killed mid-study
loses nothing."""

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from masonry_cli.main import main

pytest.importorskip("dask.distributed")

# 8 arches of 6 to 16 voussoirs under a lateral load, 0.2 to 0.5 s each
STUDY = """
[base]
scene = "arch"
lateral = 0
[grid]
shape = ["semicircular", "segmental"]
blocks = [6, 8, 12, 16]
"""

RESULTS = ("arch_shape", "arch_blocks", "variant", "feasible", "friction_used", "moi_factor",
           "weight_N", "bricks", "interfaces", "load_factor", "structure_id", "error")


def _start(*args, log):
    return subprocess.Popen([sys.executable, "-m", *args], stdout=log,
                            stderr=subprocess.STDOUT, env={**os.environ, "OMP_NUM_THREADS": "1"})


class Cluster:
    """A Dask scheduler and its workers, each a process of its own on 127.0.0.1."""

    def __init__(self, folder):
        self.folder, self.workers = folder, []
        self.log = open(folder / "cluster.log", "w")
        file = folder / "scheduler.json"
        self.scheduler = _start("distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                "--port", "0", "--dashboard-address", "127.0.0.1:0",
                                "--scheduler-file", str(file), log=self.log)
        deadline = time.monotonic() + 60
        while not (file.exists() and file.stat().st_size):
            assert time.monotonic() < deadline and self.scheduler.poll() is None
            time.sleep(0.2)
        time.sleep(0.2)  # the file written whole
        self.address = json.loads(file.read_text())["address"]

    def add_worker(self):
        """One more single-threaded worker process (no nanny: killing it loses it)."""
        self.workers.append(_start(
            "distributed.cli.dask_worker", self.address, "--nthreads", "1", "--no-nanny",
            "--no-dashboard", "--host", "127.0.0.1", "--local-directory",
            str(self.folder / "workers"), log=self.log))

    def client(self, workers):
        from dask.distributed import Client

        client = Client(self.address, timeout=60)
        client.wait_for_workers(workers, timeout=60)
        return client

    def stop(self):
        """Workers first, then the scheduler: each SIGTERM, then SIGKILL after 10 s."""
        for process in [*self.workers, self.scheduler]:
            if process.poll() is None:
                process.terminate()
                try:
                    process.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
        self.log.close()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    cluster = Cluster(tmp_path_factory.mktemp("cluster"))
    try:
        cluster.add_worker()
        cluster.add_worker()
        cluster.client(2).close()
        yield cluster
    finally:
        cluster.stop()


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The study and its summary run serially."""
    folder = tmp_path_factory.mktemp("serial")
    (folder / "study.toml").write_text(STUDY)
    assert main(["sweep", str(folder / "study.toml"), "--workers", "1", "--out",
                 str(folder), "-q"]) == 0
    return folder / "study.toml", _results(folder)


def _results(root, name="sweep_study"):
    with open(root / name / "summary.csv") as f:
        return [{k: r[k] for k in RESULTS} for r in csv.DictReader(f)]


@pytest.mark.slow
def test_a_sweep_on_the_cluster_equals_the_serial_one(cluster, serial, tmp_path):
    study, expected = serial
    assert main(["sweep", str(study), "--scheduler", cluster.address, "--out",
                 str(tmp_path), "-q"]) == 0
    assert _results(tmp_path) == expected
    assert len(expected) == 8 and not any(r["error"] for r in expected)


def test_an_optimisation_on_the_cluster_equals_the_serial_one(cluster, serial, tmp_path):
    study, _ = serial
    options = ["optimize", str(study), "--maximize", "load_factor", "--trials", "6",
               "--batch", "3", "--no-plots", "-q"]
    # serially beside the serial sweep (its variants reused); on the cluster afresh
    assert main(options + ["--workers", "1", "--out", str(study.parent)]) == 0
    assert main(options + ["--scheduler", cluster.address, "--out", str(tmp_path)]) == 0
    with open(study.parent / "optimize_study" / "trials.csv") as a, \
            open(tmp_path / "optimize_study" / "trials.csv") as b:
        first, second = list(csv.DictReader(a)), list(csv.DictReader(b))
    keep = ("trial", "arch_shape", "arch_blocks", "load_factor", "structure_id", "best")
    assert [{k: r[k] for k in keep} for r in second] == [{k: r[k] for k in keep}
                                                         for r in first]
    assert [r["status"] for r in second] == ["computed"] * 6


@pytest.mark.slow
def test_a_worker_killed_mid_study_loses_nothing(cluster, serial, tmp_path):
    from masonry.studies.sweep import execute, publish_summary, summary_rows

    from masonry.studies.study_file import load_study

    study_file, expected = serial
    study = load_study(study_file)
    client = cluster.client(2)
    try:
        pids = client.run(os.getpid)
        rows, killed = [], None
        for i, inputs, row in execute(study, tmp_path, scheduler=cluster.address):
            rows.append((i, inputs, row))
            if killed is None:  # the first variant is done: kill a worker that is busy
                busy = [w for w, keys in client.processing().items() if keys]
                killed = busy[0]
                os.kill(pids[killed], signal.SIGKILL)
                # reaped, as its parent on a machine of a cluster would (a zombie's
                # process id looks alive: its leftovers would stay)
                next(w for w in cluster.workers if w.pid == pids[killed]).wait()
        assert list(client.scheduler_info()["workers"]) == [w for w in pids if w != killed]
    finally:
        client.close()
    assert killed is not None and len(rows) == 8
    # a variant the killed worker had finished but not handed over runs again: reused
    assert all(row["status"] in ("computed", "reused") for _, _, row in rows), rows
    publish_summary(study, summary_rows(study, rows), tmp_path, "sweep_study")
    assert _results(tmp_path) == expected
    # run again on the worker left: every variant is reused
    assert main(["sweep", str(study_file), "--scheduler", cluster.address, "--out",
                 str(tmp_path), "-q"]) == 0
    with open(tmp_path / "sweep_study" / "summary.csv") as f:
        assert [r["status"] for r in csv.DictReader(f)] == ["reused"] * 8
    assert _results(tmp_path) == expected
    assert not [p for p in tmp_path.iterdir() if ".tmp-" in p.name]

