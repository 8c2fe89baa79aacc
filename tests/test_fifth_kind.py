"""A kind of search from outside the package: tests/fifth_kind/beacons_kind.py (beacon search: its
scenario section, task, planner, row column, report section and Gymnasium environment), installed
as another package would install it (a distribution on the path declaring the entry point
``semsearch.kinds``), runs through ``semsearch run``, ``report``, ``verify`` and a Gymnasium
environment, each in a process of its own; semsearch's code is not touched."""

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """A folder holding the kind's module and its distribution's metadata, as pip installs them."""
    d = tmp_path_factory.mktemp("site")
    shutil.copy(HERE / "fifth_kind" / "beacons_kind.py", d / "beacons_kind.py")
    info = d / "beacons_kind-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: beacons-kind\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[semsearch.kinds]\nbeacons = beacons_kind\n")
    return d


def semsearch(site, *args, cwd=None):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", *map(str, args)],
                          capture_output=True, text=True, env=env, cwd=cwd, timeout=600)


def python(site, code: str):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=env, timeout=600)


@pytest.fixture(scope="module")
def ran(site, tmp_path_factory):
    """The kind's example scenario, run with its decisions recorded."""
    work = tmp_path_factory.mktemp("beacons")
    r = python(site, f"import beacons_kind; beacons_kind.write_example(__import__('pathlib').Path({str(work / 'sc')!r}))")
    assert r.returncode == 0, r.stderr
    scenario = work / "sc" / "scenario.yaml"
    res = semsearch(site, "run", scenario, "--decisions", "--workers", "1", "--out", work / "r")
    assert res.returncode == 0, res.stderr
    return scenario, work / "r", res


def test_semsearch_runs_and_reports_a_kind_it_does_not_know(ran):
    scenario, out, res = ran
    rows = pd.read_csv(out / "runs.csv")
    assert set(rows["kind"]) == {"beacons"} and len(rows) == 4  # goals B and E x 2 seeds
    assert "posts_read" in rows.columns and (rows["posts_read"] >= 1).all()  # the kind's own column
    assert rows["outcome"].eq("found").all() and (rows["distance_m"] >= rows["shortest_m"] - 1e-6).all()
    assert "beacon search: success, distance (m) and posts read" in res.stdout  # its console table
    report = (out / "report.md").read_text()
    assert "## Beacon search (4 runs)" in report and (out / "tables" / "beacons.csv").is_file()


def test_its_runs_replay_from_their_decisions(site, ran):
    scenario, out, _ = ran
    res = semsearch(site, "verify", out)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "4 of 4 runs replayed from their decisions" in res.stdout
    f = next((out / "decisions").glob("*.json"))
    kept = f.read_text()
    d = json.loads(kept)
    d["decisions"][0] = [(d["decisions"][0][0] + 1) % 6]  # another post first
    f.write_text(json.dumps(d))
    try:
        res = semsearch(site, "verify", out)
    finally:
        f.write_text(kept)
    assert res.returncode == 1 and "does not replay: nearest_post goal" in res.stdout


def test_its_environment_answers_the_same_decision_points(site, ran):
    """The agent answers with the posts the batch's planner chose: the same run, step for step."""
    scenario, out, _ = ran
    rows = pd.read_csv(out / "runs.csv")
    row = rows[(rows["goal"] == "E") & (rows["seed"] == 1)].iloc[0]
    stem = f"nearest_post__goalE__ep{row['episode']}__seed1"
    code = f"""
        import json, gymnasium as gym
        from semsearch_cli.plugins import load_kinds
        load_kinds()
        env = gym.make("beacons/BeaconSearch-v0", scenario={str(scenario)!r}).unwrapped
        env.reset(options={{"episode": {int(row['episode'])}, "repeat": 1}})
        items = json.load(open({str(out / 'decisions' / (stem + '.json'))!r}))["decisions"]
        last = None
        for item in items:
            item = last if item == 0 else item
            last = item
            *_, info = env.step(item[0])
        print(json.dumps([info["outcome"], info["steps"], info["distance_m"]]))
    """
    r = python(site, code)
    assert r.returncode == 0, r.stderr
    outcome, steps, distance = json.loads(r.stdout.strip().splitlines()[-1])
    assert (outcome, steps) == (row["outcome"], row["steps"]) and distance == pytest.approx(row["distance_m"], abs=1e-3)
