"""Output folders are safe: one batch per folder, rows of another scenario never reused, a torn
last line (even inside a quoted field) survives, garbage files are refused cleanly; user text is
never read as console markup."""

import fcntl
import os
import signal
import subprocess
import sys
import time

import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import BatchOptions, expand, folder_lock, Loaded, ProcessExecutor, read_runs, run_batch
from semsearch_cli.runner.execution import Watch

runner = CliRunner()


def demo_copy(demo_dir, tmp_path, fname="scenario.yaml", **over):
    d = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    d["map"]["image"] = str(demo_dir / "map.png")
    d["doors"] = str(demo_dir / "doors.csv")
    d["planners"] = [{"name": "greedy"}]
    d.update(over)
    p = tmp_path / fname
    p.write_text(yaml.safe_dump(d))
    return p


def test_a_second_batch_into_a_folder_in_use_is_refused(demo_dir, tmp_path):
    out = tmp_path / "out"
    with folder_lock(out):  # as a running `semsearch run` holds it
        child = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "run",
                                str(demo_dir / "scenario.yaml"), "--seeds", "1", "--out", str(out)],
                               capture_output=True, text=True, timeout=120)
    assert child.returncode == 2, child.stderr
    text = " ".join(child.stderr.split())
    assert f"process {os.getpid()}" in text and "in use" in text and "Traceback" not in text
    assert not (out / "runs.csv").exists()


def test_the_lock_is_reentrant_and_released(tmp_path):
    out = tmp_path / "o"
    with folder_lock(out):
        with folder_lock(out):
            pass
        fh = open(out / ".semsearch.lock")
        with pytest.raises(BlockingIOError):
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        fh.close()
    fh = open(out / ".semsearch.lock")
    fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)  # free again
    fh.close()


def test_rows_of_another_scenario_are_refused_then_forced(demo_dir, tmp_path):
    out = tmp_path / "out"
    a = demo_copy(demo_dir, tmp_path, "a.yaml")
    api.run(a, BatchOptions(seeds=1, workers=1, goals=[452], out=out), plots=False)
    b = demo_copy(demo_dir, tmp_path, "b.yaml", experiment={"seeds": 1, "max_distance": 300.0})  # an edited budget
    with pytest.raises(ScenarioError, match="--force"):
        api.run(b, BatchOptions(seeds=1, workers=1, goals=[452], out=out), plots=False)
    r = runner.invoke(app, ["run", str(b), "--seeds", "1", "--goal", "452", "--out", str(out), "--workers", "1"])
    assert r.exit_code == 2 and "another scenario" in " ".join(r.output.split())
    res = api.run(b, BatchOptions(seeds=1, workers=1, goals=[452], out=out, force=True), plots=False)
    assert len(res.runs) == 1 and res.runs["fingerprint"].nunique() == 1
    assert (out / "runs.1.csv.bak").is_file()  # nothing is lost
    # the same scenario resumes: nothing re-runs
    again = api.run(b, BatchOptions(seeds=1, workers=1, goals=[452], out=out), plots=False)
    assert len(again.runs) == 1


def test_the_fingerprint_ignores_the_run_list_but_not_the_map(demo_dir, tmp_path):
    base = Loaded.load(demo_copy(demo_dir, tmp_path, "a.yaml"))
    more = Loaded.load(demo_copy(demo_dir, tmp_path, "b.yaml", planners=[{"name": "bvp"}], goals=[304],
                                 experiment={"seeds": 7, "max_distance": 500.0}))
    assert base.fingerprint == more.fingerprint  # planners, goals and seeds only choose runs
    img = tmp_path / "map.png"
    img.write_bytes((demo_dir / "map.png").read_bytes())
    moved = demo_copy(demo_dir, tmp_path, "c.yaml")
    d = yaml.safe_load(moved.read_text())
    d["map"]["image"] = "map.png"
    moved.write_text(yaml.safe_dump(d))
    assert Loaded.load(moved).fingerprint == base.fingerprint  # the same bytes
    import cv2

    m = cv2.imread(str(img), cv2.IMREAD_GRAYSCALE)
    m[0, 0] = 0 if m[0, 0] else 255
    cv2.imwrite(str(img), m)
    assert Loaded.load(moved).fingerprint != base.fingerprint


@pytest.mark.parametrize("cut", [5, 40, -3])
def test_a_torn_last_line_is_dropped_wherever_it_is_cut(demo_loaded, tmp_path, cut):
    out = tmp_path / "out"
    run_batch(demo_loaded, expand(demo_loaded, 2)[:2], out, BatchOptions(workers=1))
    f = out / "runs.csv"
    lines = f.read_bytes().split(b"\n")
    last = lines[-2]
    assert b'"{' in last or b"{" in last  # the params field is quoted JSON
    f.write_bytes(b"\n".join(lines[:-2]) + b"\n" + last[:cut])  # cut inside the last row
    assert len(read_runs(f)) == 1
    runs = run_batch(demo_loaded, expand(demo_loaded, 2)[:2], out, BatchOptions(workers=1))
    assert len(runs) == 2 and len(pd.read_csv(f)) == 2


@pytest.mark.parametrize("content", [b"\x00\xff\xfe garbage \x00" * 50, b"a,b,c\n1,2,3\n", "é".encode("latin-1") * 10])
def test_a_garbage_runs_csv_is_refused_cleanly(demo_dir, tmp_path, content):
    out = tmp_path / "out"
    out.mkdir()
    (out / "runs.csv").write_bytes(content)
    r = runner.invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "1", "--out", str(out)])
    assert r.exit_code == 2, r.output
    assert "runs.csv" in r.output and "Traceback" not in r.output
    r = runner.invoke(app, ["report", str(out)])
    assert r.exit_code == 2 and "Traceback" not in r.output


def test_user_text_is_not_console_markup(demo_dir, tmp_path):
    r = runner.invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--planner", "[/x]", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and "[/x]" in r.output and "MarkupError" not in r.output
    r = runner.invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--goal", "[bold]", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and "[bold]" in r.output
    p = demo_copy(demo_dir, tmp_path, "[a].yaml", name="x[/a]")
    r = runner.invoke(app, ["validate", str(p)])
    assert r.exit_code == 2 and "[a].yaml" in r.output


def test_the_run_list_is_computed_not_stored(demo_loaded):
    specs = expand(demo_loaded, 10**6)
    assert len(specs) == 2 * 2 * 10**6  # goals x planners x seeds, with no list behind it
    assert specs[-1].key == (specs.variants[-1].label, str(specs.goals[-1]), specs.episodes[-1].index, 10**6 - 1)
    assert list(specs[:3]) == [next(iter(specs)), specs[1], specs[2]]
    assert specs.has_key(specs[123457].key) and not specs.has_key(("greedy", "304", 0, 10**6))


def test_workers_are_handed_runs_as_they_free_up(demo_loaded, tmp_path):
    pulled = []

    def stream():
        for s in expand(demo_loaded, 50):
            pulled.append(s)
            yield s

    rows = ProcessExecutor(2).rows(demo_loaded, stream(), tmp_path, Watch())  # nothing kept beside the rows
    next(rows)
    # a few runs per worker ahead, not the 200 of the batch: 2 per worker submitted, then one more per
    # run finished before the first result is read (runs that end together are refilled together)
    assert len(pulled) <= 2 * (2 * 2)
    rows.close()  # stops the workers


def test_progress_is_printed_as_lines_off_a_terminal(demo_dir, tmp_path):
    child = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "run",
                            str(demo_dir / "scenario.yaml"), "--seeds", "2", "--workers", "1", "--out", str(tmp_path / "o")],
                           capture_output=True, text=True, timeout=300)
    assert child.returncode == 0, child.stderr
    lines = [ln for ln in child.stderr.splitlines() if ln.startswith("runs: ")]
    assert lines and lines[-1].startswith("runs: 8 of 8 done"), child.stderr  # 2 goals x 2 planners x 2 seeds, counted to the end
    assert "\r" not in child.stderr and "\x1b[" not in child.stderr  # no bar drawn into a log


def test_ctrl_c_stops_the_batch_keeps_its_rows_and_says_how_to_resume(demo_dir, tmp_path):
    out = tmp_path / "o"
    cmd = [sys.executable, "-c", "from semsearch_cli.cli import main; main()", "run", str(demo_dir / "scenario.yaml"),
           "--seeds", "100", "--workers", "2", "--out", str(out)]
    child = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (not (out / "runs.csv").is_file() or len(read_runs(out / "runs.csv")) < 3):
        time.sleep(0.1)
    os.killpg(child.pid, signal.SIGINT)  # as Ctrl-C does: to the whole process group, workers too
    _, err = child.communicate(timeout=60)
    assert child.returncode == 130, err
    assert "interrupted" in err and "run the same command again to resume" in err and "Traceback" not in err
    kept = read_runs(out / "runs.csv")
    assert 3 <= len(kept) < 400
    # resuming reuses every finished run: with fewer seeds, only the missing ones of those run
    res = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=2, workers=1, out=out), plots=False)
    first = {(p, str(g), s) for p, g, s in zip(kept["planner"], kept["goal"], kept["seed"])}
    assert len(res.runs) == len(kept) + len({(p, str(g), s) for p in ("greedy", "bvp") for g in (304, 452) for s in (0, 1)} - first)
