"""Privileged reference planners (issue 53): told what a robot is not, marked in the planner list,
in the rows and on the board, never ranked with the others; and the rows' columns widened when a
folder's later planner brings columns its first did not have."""

from __future__ import annotations

import csv

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from semsearch_cli import api
from semsearch_cli.belief import DoorBelief
from semsearch_cli.config import BeliefSpec
from semsearch_cli.geometry import GridFrame
from semsearch_cli.planners.doors.oracle import OracleGoal, OracleParams
from semsearch_cli.bench.board import load, tables
from semsearch_cli.planners import PLANNERS
from semsearch_cli.report.stats import ratio_ci
from semsearch_cli.runner import BatchOptions, read_runs
from semsearch_cli.runner.store import RowWriter, widened

COSTLY = '''
from semsearch_cli.planners import DoorPlanner, register_planner
from semsearch_cli.planners.doors.greedy import nearest_candidate


@register_planner("costly_nearest")
class CostlyNearest(DoorPlanner):
    """The nearest candidate, reporting calls as a language model does."""

    cost_columns = ("llm_calls",)

    def choose(self, ctx, cands):
        return nearest_candidate(ctx, cands)

    def costs(self):
        return {"llm_calls": 7}
'''


def test_only_the_references_are_privileged_and_the_planner_list_says_what_they_are_told():
    listed = {p["name"]: p for p in api.planners()}
    assert "goal sign's position" in listed["oracle_goal"]["privileged"]
    assert {n for n, p in listed.items() if p["privileged"]} == {n for n, c in PLANNERS.items() if c.privileged}
    assert all(not listed[n]["privileged"] for n in ("greedy", "nsos", "numbering", "learned", "bvp", "llm"))


def test_oracle_goal_is_the_ceiling_and_the_board_keeps_it_apart(tmp_path):
    """greedy first, then oracle_goal and a planner with a cost column into the same folder: the
    floor's runs.csv is widened (the cost and the privileged columns), every row of the three is
    there, the folder verifies, and the board ranks the oracle in its own table with each other
    planner's share of the greedy-to-oracle gap."""
    planner_file = tmp_path / "costly.py"
    planner_file.write_text(COSTLY)
    out = tmp_path / "b"
    opts = BatchOptions(workers=1)
    api.bench_run("doors-v1", ["greedy"], out, options=opts, limit=4)
    first = (out / "f000" / "runs.csv").read_text().splitlines()
    api.bench_run("doors-v1", ["oracle_goal", "costly_nearest", "numbering"], out, options=opts, limit=4,
                  planner_file=planner_file)
    rows = read_runs(out / "f000" / "runs.csv")
    assert {"llm_calls", "privileged"} <= set(rows.columns)
    assert rows.groupby("planner").size().to_dict() == {"costly_nearest": 4, "greedy": 4, "numbering": 4, "oracle_goal": 4}
    assert (rows.loc[rows["planner"] == "costly_nearest", "llm_calls"] == 7).all()
    assert rows.loc[rows["planner"] == "oracle_goal", "privileged"].str.contains("goal sign").all()
    assert (rows.loc[rows["planner"] != "oracle_goal", "privileged"] == "").all()
    # the greedy rows as they were, in the widened file
    g = rows[rows["planner"] == "greedy"]
    before = pd.DataFrame(list(csv.DictReader(first)))
    assert list(g["distance_m"]) == [float(x) for x in before["distance_m"]]
    o = rows[rows["planner"] == "oracle_goal"].set_index("episode")["distance_m"]
    gd = g.set_index("episode")["distance_m"]
    assert (o <= gd + 1e-9).sum() >= 3  # told where the goal is: shorter on most episodes
    v = api.verify(out).verdict
    assert v.failed == [] and v.verified == v.runs == 16
    t = tables(load([out]))
    assert list(t["references"]["planner"]) == ["oracle_goal"]
    assert t["references"]["official"].str.startswith("no (a privileged reference").all()
    assert "oracle_goal" not in set(t["planners"]["planner"])
    ranked = t["planners"].set_index("planner")
    # what each was tuned on, and a row of the split a planner was tuned on flagged as not held out
    assert ranked.loc["greedy", "tuned on"] == "none"
    assert ranked.loc["numbering", "tuned on"].endswith("TUNED ON THIS SPLIT: not held out")
    assert ranked.loc["costly_nearest", "tuned on"] == "none"  # its class states nothing: the default
    assert ranked.loc["costly_nearest", "SPL gap closed"].startswith("0.0%")  # greedy's twin closes none of it
    assert "SPL gap closed" not in t["references"].columns or not t["references"]["SPL gap closed"].astype(str).str.len().any()
    # a folder that ran no privileged planner (the shuffled ablation) has no privileged column: its rows were told nothing
    api.bench_run("doors-v1", ["numbering"], tmp_path / "s", numbering="shuffled", options=opts, limit=4)
    t = tables(load([out, tmp_path / "s"]))
    ranked = t["planners"].set_index("planner")
    assert list(t["references"]["planner"]) == ["oracle_goal"]
    assert "privileged" not in ranked.loc["numbering", "official"], ranked.loc["numbering", "official"]
    assert ranked.loc["numbering", "semantic gain"] != ""


def test_a_runs_csv_is_widened_in_place_keeping_its_rows(tmp_path):
    p = tmp_path / "runs.csv"
    w = RowWriter(p, ["kind", "planner", "distance_m", "code"])
    w.write([{"kind": "doors", "planner": "greedy", "distance_m": 1.5, "code": "c"}])
    w.close()
    w = RowWriter(p, ["kind", "planner", "distance_m", "llm_calls", "privileged", "code"])
    w.write([{"kind": "doors", "planner": "llm", "distance_m": 2.0, "llm_calls": 3, "privileged": "", "code": "d"}])
    w.close()
    lines = p.read_text().splitlines()
    assert lines == ["kind,planner,distance_m,llm_calls,privileged,code", "doors,greedy,1.5,,,c", "doors,llm,2.0,3,,d"]
    assert widened(["a", "c"], ["x", "a", "b", "c", "d"]) == ["x", "a", "b", "c", "d"]
    assert widened(["c", "a"], ["a", "b"]) == ["c", "a", "b"]


@pytest.mark.parametrize("seed", [0, 1])
def test_the_gap_closed_interval_is_scipys_paired_bca_of_the_ratio_of_means(seed):
    rng = np.random.default_rng(seed)
    den = rng.normal(0.4, 0.3, 200)
    num = 0.25 * den + rng.normal(0, 0.2, 200)
    m, lo, hi = ratio_ci(num, den)
    ref = scipy.stats.bootstrap((num, den), lambda a, b, axis=-1: a.mean(axis) / b.mean(axis), paired=True,
                                vectorized=True, method="BCa", rng=np.random.default_rng(0)).confidence_interval
    assert m == pytest.approx(num.sum() / den.sum())
    assert (lo, hi) == pytest.approx((ref.low, ref.high), rel=1e-9)
    assert ratio_ci([1.0], [2.0])[0] == 0.5 and np.isnan(ratio_ci([1.0], [2.0])[1])
    assert np.isnan(ratio_ci([1.0, -1.0], [1.0, -1.0])[0])  # a gap of 0: no share of it


def test_the_oracle_measures_the_rest_of_the_way_around_a_wall_it_has_seen():
    """beyond=unknown: the way from a cell to the goal goes round the walls the robot has seen and
    through what it has not; beyond=line: the straight line, through the wall."""
    H, W = 40, 60
    b = DoorBelief(GridFrame(0.1, 0.0, 0.0, H, W), BeliefSpec(), robot_radius=0.05)
    b.seen[:] = True
    wall = np.zeros((H, W), bool)
    wall[:30, 30] = True  # a wall from the top down to row 30, seen; open below it
    b.cv[wall] = 10
    b.refresh_free(np.array([0, H - 1, 0, W - 1]))
    goal = np.array([[b.frame.to_world(10, 45)[0], b.frame.to_world(10, 45)[1]]])
    rows, cols = np.array([10]), np.array([15])
    line = OracleGoal(OracleParams(beyond="line")).rest(b, goal, rows, cols)[0]
    around = OracleGoal(OracleParams()).rest(b, goal, rows, cols)[0]
    assert line == pytest.approx(3.0, abs=0.01)  # 30 cells at 0.1 m, through the wall
    assert around > line + 2.0  # down past row 30 and back up
    b.seen[:, 25:] = False  # the wall not seen yet: the unknown taken as free, straight through
    assert OracleGoal(OracleParams()).rest(b, goal, rows, cols)[0] == pytest.approx(line, abs=0.05)
