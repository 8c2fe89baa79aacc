"""Process faults end cleanly and lose nothing: a parent killed alone takes its
workers with it and frees its folder; a killed worker, SIGTERM and a full disk end with one
paragraph, never a traceback; rows are never lost or doubled, and the same command resumes."""

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from semsearch_cli import cli
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import batch, BatchOptions, expand, read_runs, run_batch, store
from semsearch_cli.tasks import loop


def start(demo_dir, out: Path, seeds: int = 100) -> subprocess.Popen:
    cmd = [sys.executable, "-c", "from semsearch_cli.cli import main; main()", "run", str(demo_dir / "scenario.yaml"),
           "--seeds", str(seeds), "--workers", "2", "--out", str(out)]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


def wait_for_rows(out: Path, n: int, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if (out / "runs.csv").is_file() and len(read_runs(out / "runs.csv")) >= n:
            return
        time.sleep(0.1)
    raise AssertionError(f"fewer than {n} rows in {out / 'runs.csv'} after {timeout} s")


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (from /proc)."""
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(entry))
    return out


def alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def keys(out: Path) -> list[tuple]:
    runs = read_runs(out / "runs.csv")
    return list(zip(runs["planner"], runs["goal"].astype(str), runs["episode"], runs["seed"]))


def resume_completes(demo_dir, out: Path, seeds: int) -> None:
    """The same command, run again, finishes the batch: every run once."""
    child = start(demo_dir, out, seeds)
    _, err = child.communicate(timeout=600)
    assert child.returncode == 0, err
    k = keys(out)
    assert len(k) == len(set(k)) == 2 * 2 * seeds  # 2 goals x 2 planners x the seeds, none twice


needs_proc = pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads processes from /proc (Linux)")


@needs_proc
def test_a_parent_killed_alone_takes_its_workers_and_frees_its_folder(demo_dir, tmp_path):
    out = tmp_path / "o"
    child = start(demo_dir, out, seeds=40)
    wait_for_rows(out, 3)
    workers = children(child.pid)
    assert len(workers) >= 2
    child.kill()  # SIGKILL to the parent only, as a scheduler or a closed terminal may do
    child.communicate(timeout=60)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(alive(w) for w in workers):
        time.sleep(0.1)
    assert not any(alive(w) for w in workers), "workers outlived their parent"
    resume_completes(demo_dir, out, seeds=40)  # the folder's lock went with the parent


@needs_proc
def test_a_killed_worker_stops_the_batch_with_one_paragraph_and_the_rows_resume(demo_dir, tmp_path):
    out = tmp_path / "o"
    child = start(demo_dir, out, seeds=40)
    wait_for_rows(out, 3)
    os.kill(children(child.pid)[0], signal.SIGKILL)
    _, err = child.communicate(timeout=120)
    assert child.returncode == 1, err
    assert "a worker process died" in err and "run the same command again to resume" in err
    assert "Traceback" not in err
    kept = keys(out)
    assert len(kept) == len(set(kept)) >= 3
    resume_completes(demo_dir, out, seeds=40)


def test_sigterm_to_the_group_ends_with_a_paragraph_and_status_143(demo_dir, tmp_path):
    out = tmp_path / "o"
    child = start(demo_dir, out, seeds=40)
    wait_for_rows(out, 3)
    os.killpg(child.pid, signal.SIGTERM)
    _, err = child.communicate(timeout=120)
    assert child.returncode in (1, 143), err  # the parent's signal, or a worker's death seen first
    assert "run the same command again to resume" in err and "Traceback" not in err
    resume_completes(demo_dir, out, seeds=40)


def test_a_full_disk_keeps_every_whole_run_and_cuts_the_torn_one(tmp_path):
    path = tmp_path / "runs.csv"
    w = store.RowWriter(path)
    w.write([{"planner": "greedy", "goal": 1, "episode": 0, "seed": 0, "outcome": "found", "distance_m": 10.0, "wall_s": 0.1}])
    size = path.stat().st_size

    class Full:  # the file, but half of a write reaches the disk, then the disk is full
        def __init__(self, fh):
            self.fh = fh

        def __getattr__(self, name):
            return getattr(self.fh, name)

        def write(self, text):
            self.fh.write(text[: len(text) // 2])
            self.fh.flush()
            raise OSError(errno.ENOSPC, "No space left on device", str(path))

    w.fh = Full(w.fh)
    with pytest.raises(OSError):
        w.write([{"planner": "greedy", "goal": 1, "episode": 0, "seed": s, "outcome": "found", "distance_m": 10.0, "wall_s": 0.1} for s in (1, 2)])
    assert path.stat().st_size == size  # the torn run is gone, the whole one kept
    w.write([{"planner": "greedy", "goal": 1, "episode": 0, "seed": 3, "outcome": "found", "distance_m": 10.0, "wall_s": 0.1}])  # and writing goes on
    w.close()
    assert list(read_runs(path)["seed"]) == [0, 3]


def test_a_full_disk_ends_the_command_with_one_paragraph(demo_dir, tmp_path, monkeypatch, capsys):
    def full(self, rows):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "o" / "runs.csv"))

    monkeypatch.setattr(store.RowWriter, "write", full)
    monkeypatch.setattr(sys, "argv", ["semsearch", "run", str(demo_dir / "scenario.yaml"), "--seeds", "1",
                                      "--out", str(tmp_path / "o")])
    term = signal.getsignal(signal.SIGTERM)
    try:
        with pytest.raises(SystemExit) as stop:
            cli.main()
    finally:
        signal.signal(signal.SIGTERM, term)
    err = capsys.readouterr().err
    assert stop.value.code == 1, err
    assert "the disk is full" in err and "run the same command again to resume" in err and "Traceback" not in err


def test_a_batch_that_would_not_fit_in_memory_is_refused_with_the_workers_that_fit(demo_loaded, tmp_path, monkeypatch):
    need = demo_loaded.task.memory_per_run()
    monkeypatch.setattr(batch, "available_memory", lambda: int(need * 2.5))
    with pytest.raises(ScenarioError) as err:
        run_batch(demo_loaded, expand(demo_loaded, 2), tmp_path / "o", BatchOptions(workers=4))
    assert err.value.field == "--workers" and "run with --workers 2" in err.value.message
    assert not (tmp_path / "o" / "runs.csv").exists() or len(read_runs(tmp_path / "o" / "runs.csv")) == 0


def test_a_long_run_says_it_is_alive(demo_loaded, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(loop, "PROGRESS_S", 0.0)
    specs = list(expand(demo_loaded, 1))[:1]
    run_batch(demo_loaded, specs, tmp_path / "o", BatchOptions(workers=1))
    err = capsys.readouterr().err
    assert f"run {specs[0].variant.label} goal {specs[0].episode.goal}" in err and "m so far" in err
