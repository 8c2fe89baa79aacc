"""Labels from the known map for every frontier target of every door decision
(semsearch_cli/learn): exact values, and a labelled run is the planner's own run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semsearch_cli import api
from semsearch_cli.learn import FEATURES, LabelSeat, collect, oracle_costs
from semsearch_cli.planners import Variant
from semsearch_cli.runner import Loaded
from semsearch_cli.tasks.decisions import Seat


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    folder = tmp_path_factory.mktemp("demo")
    api.init("demo", folder, force=True)
    return folder / "demo.yaml"


def test_the_oracle_is_the_path_to_the_target_plus_the_true_distance_from_it():
    field = np.array([[0.0, 0.1, np.inf], [0.2, 0.3, 0.4]])
    got = oracle_costs(field, np.array([1.5, 2.0, 3.0, np.inf]), np.array([0, 1, 0, 1]), np.array([1, 2, 2, 0]))
    assert got.tolist() == [1.6, 2.4, math.inf, math.inf]


@pytest.mark.parametrize("planner", ["greedy", "nsos"])
def test_a_labelled_run_is_the_planners_own(demo, planner):
    task = Loaded.load(demo).task
    for ep in task.episodes[:2]:
        alone = task.run(Variant(planner, ()), ep, 0, seat=Seat())
        seat = LabelSeat(task)
        labelled = task.run(Variant(planner, ()), ep, 0, seat=seat)
        assert (labelled.outcome, labelled.distance_m, labelled.steps, labelled.decisions) == \
               (alone.outcome, alone.distance_m, alone.steps, alone.decisions)
        np.testing.assert_array_equal(labelled.path, alone.path)
        assert labelled.read_signs == alone.read_signs
        assert seat.rows and {r["decision"] for r in seat.rows} == set(range(max(r["decision"] for r in seat.rows) + 1))


def test_labels_are_ground_truth_distances_and_the_best_is_the_least(demo):
    df = collect(demo, "greedy", seeds=1)
    task = Loaded.load(demo).task
    assert len(df) > 50 and set(FEATURES) <= set(df.columns) and (df["outcome"] == "found").all()
    ok = np.isfinite(df["oracle_m"])
    assert ok.mean() > 0.9
    for _, r in df[ok].sample(20, random_state=0).iterrows():  # G(c): the ground truth's geodesic from the target to the goal
        g, _ = task.world.geodesic((int(r["row"]), int(r["col"])), task.goal_cells(r["goal"]))
        assert r["oracle_m"] - r["d_m"] == pytest.approx(g, abs=1e-9)
    best = df[ok].groupby(["goal", "episode", "seed", "decision"])
    for _, g in best:
        assert g["best"].sum() >= 1 and g.loc[g["best"], "oracle_m"].min() == g["oracle_m"].min()
        assert (g["d_rank"].sort_values().to_numpy() == np.arange(len(g))).all()
    first = df[df["decision"] == 0]
    for _, r in first.iterrows():  # at the start, the path through a target is no shorter than the shortest path
        ep = next(e for e in task.episodes if str(e.goal) == str(r["goal"]) and e.index == r["episode"])
        assert r["oracle_m"] >= task.distance_left(ep.goal, ep.x, ep.y) - 2 * task.world.frame.res


def test_training_floors_are_drawn_apart_from_the_benchmarks_and_repeat(tmp_path):
    from semsearch_cli.learn import benchmark_seeds, training_floor
    taken = benchmark_seeds()
    assert len(taken) == 40  # doors-v1 val's floors
    path, recipe = training_floor(0, tmp_path / "a")
    again, same = training_floor(0, tmp_path / "b")
    assert recipe == same and (path.parent / "map.png").read_bytes() == (again.parent / "map.png").read_bytes()
    assert recipe["seed"] not in taken
    assert Loaded.load(path).task.episodes  # it runs as it is
