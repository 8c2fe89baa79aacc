"""A user's planner cannot take the batch down or lie: an exit or exception in
``choose`` is that run's ``error``, one at import is exit 2 naming the file, a planner that hangs is
``timeout`` after ``experiment.run_time_limit``, a target off the map or in a wall is ``error``
naming the planner and the value, and traces are strict JSON whatever ``Decision.info`` holds."""

import json
import textwrap

import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.runner import BatchOptions, expand, Loaded, read_runs, run_batch

runner = CliRunner()

PLANNER = '''
import math
import sys
import time

import numpy as np

from semsearch_cli.planners import Decision, DoorPlanner, register_planner


@register_planner("{name}")
class Bad(DoorPlanner):
    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        {body}
'''

BODIES = {
    "u_exits": "sys.exit(0)",
    "u_sleeps": "time.sleep(30)",
    "u_off_map": "return Decision(-5, 10**6)",
    "u_in_wall": "r, c = np.argwhere(~ctx.belief.free)[0]\n        return Decision(int(r), int(c))",
    "u_not_json": "return Decision(int(cands.rows[0]), int(cands.cols[0]), "
                "{'nan': math.nan, 'inf': -math.inf, 'obj': object(), 'arr': np.arange(2), 7: np.float32(1.5)})",
}


def scenario(demo_dir, tmp_path, name, limit=None):
    (tmp_path / f"{name}.py").write_text(textwrap.dedent(PLANNER.format(name=name, body=BODIES[name])))
    d = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    d["map"]["image"] = str(demo_dir / "map.png")
    d["doors"] = str(demo_dir / "doors.csv")
    d["planners"] = [{"name": "greedy"}, {"name": name, "module": f"{name}.py"}]
    d["experiment"]["seeds"] = 1
    if limit is not None:
        d["experiment"]["run_time_limit"] = limit
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d))
    return p


def run(p, tmp_path, trace=False, workers=1):
    loaded = Loaded.load(p)
    return run_batch(loaded, expand(loaded), tmp_path / "out", BatchOptions(workers=workers, trace=trace))


def test_sys_exit_inside_choose_is_that_runs_error_and_the_batch_goes_on(demo_dir, tmp_path):
    rows = run(scenario(demo_dir, tmp_path, "u_exits"), tmp_path, workers=2)
    bad = rows[rows["planner"] == "u_exits"]
    assert len(bad) == 2 and set(bad["outcome"]) == {"error"} and bad["message"].str.startswith("SystemExit").all()
    assert (rows[rows["planner"] == "greedy"]["outcome"] == "found").all()


def test_sys_exit_at_import_is_exit_2_naming_the_file(demo_dir, tmp_path):
    p = scenario(demo_dir, tmp_path, "u_exits")
    (tmp_path / "u_exits.py").write_text("import sys\nsys.exit(3)\n")
    res = runner.invoke(app, ["run", str(p), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "u_exits.py" in res.output and "SystemExit" in res.output, res.output


def test_a_planner_that_hangs_is_recorded_as_timeout(demo_dir, tmp_path):
    rows = run(scenario(demo_dir, tmp_path, "u_sleeps", limit=0.5), tmp_path)
    bad = rows[rows["planner"] == "u_sleeps"]
    assert set(bad["outcome"]) == {"timeout"} and set(bad["cause"]) == {"timeout"}
    assert bad["message"].str.contains("run_time_limit").all() and (bad["wall_s"] < 5).all()
    assert (rows[rows["planner"] == "greedy"]["outcome"] == "found").all()


def test_targets_off_the_map_or_in_a_wall_are_errors_naming_the_planner_and_the_value(demo_dir, tmp_path):
    (tmp_path / "a").mkdir()
    off = run(scenario(demo_dir, tmp_path / "a", "u_off_map"), tmp_path / "a")
    bad = off[off["planner"] == "u_off_map"]
    assert set(bad["outcome"]) == {"error"}
    assert bad["message"].str.contains("planner 'u_off_map' chose the cell \\(-5, 1000000\\), off the map").all()
    (tmp_path / "b").mkdir()
    wall = run(scenario(demo_dir, tmp_path / "b", "u_in_wall"), tmp_path / "b")
    bad = wall[wall["planner"] == "u_in_wall"]
    assert set(bad["outcome"]) == {"error"} and bad["message"].str.contains("does not hold free").all()


def test_traces_are_strict_json_whatever_the_info_holds(demo_dir, tmp_path):
    rows = run(scenario(demo_dir, tmp_path, "u_not_json"), tmp_path, trace=True)
    assert set(rows["outcome"]) <= {"found", "not_found", "budget", "stuck"}
    files = sorted((tmp_path / "out" / "traces").glob("u_not_json*.jsonl"))
    assert files

    def strict(const):
        raise ValueError(f"non-strict JSON: {const}")

    for f in files:
        for line in f.read_text().splitlines():
            d = json.loads(line, parse_constant=strict)
            assert d["nan"] is None and d["inf"] is None and d["arr"] == [0, 1] and d["7"] == 1.5
            assert d["obj"].startswith("<object object")
    assert len(read_runs(tmp_path / "out" / "runs.csv")) == len(rows)
