"""End-to-end runs on the demo building (a small map of our own)."""

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.metrics import COLUMNS
from semsearch_cli.tasks import build_task
from semsearch_cli.runner import expand, run_batch
from semsearch_cli.planners import PLANNERS, Variant, expand_variants
from semsearch_cli.config import PlannerSpec


@pytest.mark.parametrize("name", sorted(n for n, c in PLANNERS.items() if c.task == "doors"))
def test_every_planner_finds_the_goal_on_the_demo(demo_loaded, name):
    L = demo_loaded
    for goal in L.sc.goals:
        res = L.task.run(Variant(name, ()), goal, 0)
        assert res.outcome == "found"
        assert res.distance_m >= L.shortest[goal] - 0.5  # never better than the ground-truth optimum
        assert res.decisions >= 1


def test_same_seed_same_run(demo_loaded):
    L = demo_loaded
    a = L.task.run(Variant("greedy", ()), 452, 1)
    b = L.task.run(Variant("greedy", ()), 452, 1)
    assert (a.outcome, a.distance_m, a.steps, a.decisions) == (b.outcome, b.distance_m, b.steps, b.decisions)
    assert (a.path == b.path).all()


def test_seeds_change_start_heading_and_runs(demo_loaded):
    L = demo_loaded
    d = {L.task.run(Variant("greedy", ()), 452, s).distance_m for s in range(4)}
    assert len(d) > 1


KEY = ["planner", "goal", "seed"]


def _rows(df):
    return df.drop(columns=["wall_s"]).sort_values(KEY).reset_index(drop=True)


def test_rows_do_not_depend_on_worker_count(demo_loaded, tmp_path):
    specs = expand(demo_loaded, seeds=2)
    one = run_batch(demo_loaded, specs, tmp_path / "w1", workers=1)
    two = run_batch(demo_loaded, specs, tmp_path / "w2", workers=2)
    assert len(one) == len(specs) == 8
    pd.testing.assert_frame_equal(_rows(one), _rows(two))


def test_interrupted_batch_resumes(demo_loaded, tmp_path):
    out = tmp_path / "r"
    specs = expand(demo_loaded, seeds=2)
    run_batch(demo_loaded, specs[:3], out)
    with open(out / "runs.csv", "a") as fh:
        fh.write("demo,greedy,{},304,1,fou")  # a row torn by an interruption
    seen = []
    runs = run_batch(demo_loaded, specs, out, progress=seen.append)
    assert len(seen) == len(specs) - 3  # only the missing runs were run
    assert len(runs) == len(specs)
    assert sorted(map(tuple, runs[KEY].astype(str).values)) == sorted((s.variant.label, str(s.goal), str(s.seed)) for s in specs)


def test_run_command_writes_rows_summary_and_plots(demo_dir, tmp_path):
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "2", "--goal", "304", "--workers", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    runs = pd.read_csv(out / "runs.csv")
    assert list(runs.columns) == COLUMNS
    assert len(runs) == 4 and set(runs["planner"]) == {"greedy", "bvp"} and set(runs["kind"]) == {"doors"}
    s = pd.read_csv(out / "summary.csv")
    g = runs[runs.planner == "greedy"]["distance_m"]
    row = s[s.planner == "greedy"].iloc[0]
    assert row["n"] == 2 and row["mean"] == pytest.approx(g.mean(), abs=1e-3) and row["std"] == pytest.approx(g.std(), abs=1e-3)
    assert (out / "figures" / "paths_demo_goal304.png").is_file()  # the median run of each planner


def test_list_valued_parameters_expand_into_variants():
    vs = expand_variants([PlannerSpec(name="bvp", window=[5.0, 10.0]), PlannerSpec(name="greedy")])
    assert [v.label for v in vs] == ["bvp[window=5.0]", "bvp[window=10.0]", "greedy"]


def test_api_run_filters_planner(demo_dir, tmp_path):
    res = api.run(demo_dir / "scenario.yaml", seeds=1, workers=1, goals=[452], planners=["bvp"], out=tmp_path / "o", plots=False)
    assert list(res.runs["planner"]) == ["bvp"]


def test_show_draws_the_scenario(demo_dir, tmp_path):
    import matplotlib.image

    res = CliRunner().invoke(app, ["show", str(demo_dir / "scenario.yaml"), "--out", str(tmp_path / "m.png")])
    assert res.exit_code == 0, res.output
    img = matplotlib.image.imread(tmp_path / "m.png")
    assert img.shape[0] > 300 and img.shape[1] > 600


def test_start_facing_a_dead_end_turns_around(demo_loaded):
    """A start at the end of a wing, facing the end wall: the 180-degree laser sees no way on
    until the robot turns on the spot."""
    from semsearch_cli.config import StartSpec
    from semsearch_cli.world.scenario import build_world

    L = demo_loaded
    sc = L.sc.model_copy(update={"start": StartSpec(x=8.0, y=17.3, heading=90.0)})
    world = build_world(sc, L.path.parent, str(L.path))
    res = build_task(sc, world, L.path).run(Variant("greedy", ()), 452, 0)
    assert res.outcome == "found"
    assert res.path[0].tolist() == [8.0, 17.299999237060547]


def test_goal_behind_a_mid_corridor_start_is_found(tmp_path):
    """The forward laser never sees behind the start: once the corridor ahead is done, the robot
    must come back for the half it has never seen (the classic frontier)."""
    from semsearch_cli.config import StartSpec
    from semsearch_cli.runner import Loaded
    from semsearch_cli.world.generate import generate_building
    from semsearch_cli.world.scenario import build_world

    p = generate_building("single", "floor", 0, tmp_path)
    L = Loaded.load(p)
    sc = L.sc.model_copy(update={"start": StartSpec(x=L.sc.start.x, y=L.sc.start.y, heading=0.0)})
    world = build_world(sc, p.parent, str(p))
    s = world.signs
    behind = int(np.argmin(s.x))  # the westernmost sign, behind a robot facing east
    res = build_task(sc, world, p).run(Variant("greedy", ()), s.number[behind], 0)
    assert res.outcome == "found"
    assert res.path[:, 0].max() > L.sc.start.x + 20  # it went east first, then came back
