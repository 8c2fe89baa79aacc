"""The Dask executor on a real cluster on this machine: a `dask scheduler` and two `dask worker`
processes on 127.0.0.1. Rows match the process pool's (wall time aside), a worker killed with
SIGKILL mid-batch loses no run and duplicates none, a batch resumes across executors, and a sweep
starts one local cluster for all its values."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import BatchOptions, read_runs

distributed = pytest.importorskip("distributed", reason="the Dask executor's tests need the distributed package, in the "
                                  "test extra that CI installs (pip install '.[test]', or '.[dask]')")
cluster_module = pytest.importorskip("semsearch_cli.runner.cluster")

DASK = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
WORKER = [sys.executable, "-m", "distributed.cli.dask_worker"]
SAME = ["kind", "scenario", "planner", "params", "goal", "seed", "outcome", "success", "distance_m", "shortest_m", "ratio",
        "spl", "steps", "decisions", "navigator", "message", "fingerprint"]  # every column but wall_s


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """(scheduler address, {pid: worker process}) of a scheduler and two single-threaded workers."""
    d = tmp_path_factory.mktemp("dask")
    file = d / "scheduler.json"
    env = {**os.environ, "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    procs = [subprocess.Popen(DASK + ["--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(file), "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=d)]
    deadline = time.monotonic() + 60
    while not file.is_file() and time.monotonic() < deadline:
        time.sleep(0.2)
    address = json.loads(file.read_text())["address"]
    workers = {}
    for k in range(2):
        p = subprocess.Popen(WORKER + ["--scheduler-file", str(file), "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1",
                                       "--no-dashboard", "--name", f"w{k}"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=d)
        procs.append(p)
        workers[p.pid] = p
    with distributed.Client(address, set_as_default=False, timeout=60) as c:
        c.wait_for_workers(2, timeout=60)
    yield address, workers
    for p in procs:
        p.kill()
        p.wait()


def _rows(folder: Path) -> pd.DataFrame:
    df = read_runs(folder / "runs.csv")[SAME]
    return df.sort_values(["planner", "goal", "seed"]).reset_index(drop=True)


def test_rows_on_the_cluster_match_the_process_pool(cluster, demo_dir, tmp_path):
    address, _ = cluster
    pool = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=3, workers=2, out=tmp_path / "pool"), plots=False)
    dask = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=3, out=tmp_path / "dask", executor="dask", scheduler=address), plots=False)
    assert len(pool.runs) == len(dask.runs) == 12
    pd.testing.assert_frame_equal(_rows(tmp_path / "pool"), _rows(tmp_path / "dask"))
    assert len(list((tmp_path / "dask" / "paths").glob("*.npz"))) == 12  # written by the client: no shared folder needed


def test_a_worker_killed_mid_batch_loses_and_duplicates_no_run(cluster, demo_dir, tmp_path):
    address, workers = cluster
    victim = next(iter(workers.values()))
    killed = []

    def tick(row, done, total):
        if done == 3 and not killed:
            os.kill(victim.pid, signal.SIGKILL)  # mid-batch: the other chunks of that worker are lost with it
            killed.append(done)

    res = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=10, out=tmp_path / "o", executor="dask", scheduler=address), plots=False, progress=tick)
    assert killed and victim.wait(timeout=10) == -signal.SIGKILL
    runs = read_runs(tmp_path / "o" / "runs.csv")
    keys = list(zip(runs["planner"], runs["goal"].astype(str), runs["seed"]))
    assert len(runs) == len(res.runs) == 40 and len(set(keys)) == 40  # every run exactly once
    pool = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=10, workers=2, out=tmp_path / "pool"), plots=False)
    pd.testing.assert_frame_equal(_rows(tmp_path / "o"), _rows(tmp_path / "pool"))
    assert len(pool.runs) == 40


def test_a_batch_resumes_across_executors(demo_dir, tmp_path):
    out = tmp_path / "o"
    api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=1, workers=2, out=out), plots=False)  # the process pool starts it
    shutil.copy(out / "runs.csv", tmp_path / "first.csv")
    res = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=2, workers=2, out=out, executor="dask"), plots=False)  # a local cluster ends it
    assert len(res.runs) == 8
    first = pd.read_csv(tmp_path / "first.csv")
    assert res.runs.head(len(first))["wall_s"].tolist() == first["wall_s"].tolist()  # the first rows were kept, not re-run
    whole = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=2, workers=1, out=tmp_path / "one"), plots=False)
    pd.testing.assert_frame_equal(_rows(out), _rows(tmp_path / "one"))
    assert len(whole.runs) == 8


def test_a_sweep_uses_one_cluster_for_all_its_values(demo_dir, tmp_path, monkeypatch):
    started = []

    class Counted(cluster_module.distributed.LocalCluster):
        def __init__(self, *a, **k):
            started.append(1)
            super().__init__(*a, **k)

    monkeypatch.setattr(cluster_module.distributed, "LocalCluster", Counted)
    opts = BatchOptions(seeds=2, goals=[452], planners=["greedy"], workers=2)
    res = api.sweep(demo_dir / "scenario.yaml", "door_camera.p_misread", [0, 0.5, 0.9], opts.replace(out=tmp_path / "dask", executor="dask"))
    assert len(started) == 1  # not one per value
    pool = api.sweep(demo_dir / "scenario.yaml", "door_camera.p_misread", [0, 0.5, 0.9], opts.replace(out=tmp_path / "pool"))
    assert res.table["n"].tolist() == [2, 2, 2]
    pd.testing.assert_frame_equal(res.table, pool.table)
    for v in ("0", "0.5", "0.9"):
        pd.testing.assert_frame_equal(_rows(tmp_path / "dask" / f"door_camera.p_misread={v}"),
                                      _rows(tmp_path / "pool" / f"door_camera.p_misread={v}"))


@pytest.mark.parametrize("address, says", [("tcp://127.0.0.1:1", "Connection refused"),
                                           ("not an address", "is not a scheduler address"),
                                           ("notanaddress", "is not a scheduler address"),
                                           ("tcp://:99999", "is not a scheduler address"),
                                           ("tcp://127.0.0.1:99999", "outside 1-65535"),
                                           ("http://127.0.0.1:8786", "unknown protocol 'http'")])
def test_a_wrong_scheduler_is_exit_2_naming_the_flag_within_10_s(demo_dir, tmp_path, address, says):
    t0 = time.monotonic()
    res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "1", "--executor", "dask",
                                   "--scheduler", address, "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "--scheduler" in res.output and says in res.output, res.output
    assert "Traceback" not in res.output
    assert time.monotonic() - t0 < 10


def test_a_port_that_accepts_but_never_answers_is_refused_within_the_bound(monkeypatch):
    """Dask's client bounds its connect but not the handshake after it: a silent listener held a
    command until the listener went away (40 s here), then a collected client took 16 s more."""
    monkeypatch.setattr(cluster_module, "CONNECT_S", 1.5)
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(4)
        address = "tcp://127.0.0.1:%d" % silent.getsockname()[1]
        t0 = time.monotonic()
        with pytest.raises(ScenarioError, match="no answer; waited at most 1.5 s") as err:
            cluster_module.DaskExecutor(address=address)._client()
        assert time.monotonic() - t0 < 4
    assert err.value.field == "--scheduler"


def test_a_local_cluster_runs_and_closes_cleanly_from_a_fresh_process(tmp_path):
    """`semsearch run demo --executor dask` in a process that had not imported distributed: the
    executor's dask.config.set() inserted a "distributed" section before distributed was imported,
    and removed it whole on leaving (KeyError 'distributed' as the cluster closed, exit 1). The
    rows equal the process pool's with the same seeds."""
    cmd = [sys.executable, "-c", "from semsearch_cli.cli import main; main()", "run", "demo", "--seeds", "2"]
    dask = subprocess.run(cmd + ["--executor", "dask", "--workers", "2", "--out", str(tmp_path / "dask")],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert dask.returncode == 0, dask.stderr[-3000:]
    for bad in ("Traceback", "KeyError", "Exception ignored", "Task exception"):
        assert bad not in dask.stderr + dask.stdout, dask.stderr[-3000:]
    pool = api.run("demo", BatchOptions(seeds=2, workers=2, out=tmp_path / "pool"), plots=False)
    assert len(pool.runs) == 8
    pd.testing.assert_frame_equal(_rows(tmp_path / "dask"), _rows(tmp_path / "pool"))


def test_a_bench_run_on_the_cluster_matches_the_process_pool_and_verifies(cluster, tmp_path):
    """One client for every floor (the slice spans two), the rows as the pool's, every run replayed."""
    address, _ = cluster
    pool = api.bench_run("doors-v1", ["greedy"], tmp_path / "pool", options=BatchOptions(workers=2), limit=22)
    dask = api.bench_run("doors-v1", ["greedy"], tmp_path / "dask", options=BatchOptions(executor="dask", scheduler=address),
                         limit=22)
    assert pool.floors == dask.floors == ["f000", "f001"]
    cols = [c for c in SAME if c != "scenario"] + ["floor", "episode", "suite_hash", "decisions_sha256"]
    key = ["floor", "episode", "seed"]
    pd.testing.assert_frame_equal(pool.runs[cols].sort_values(key).reset_index(drop=True),
                                  dask.runs[cols].sort_values(key).reset_index(drop=True))
    assert api.verify(tmp_path / "dask", workers=1).verdict.verified == 22
