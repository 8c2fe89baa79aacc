"""End-to-end runs on the demo building (a small map of our own)."""

import os

import numpy as np
import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.metrics import COLUMNS
from semsearch_cli.tasks import build_task
from semsearch_cli.runner import BatchOptions, expand, run_batch
from semsearch_cli.planners import PLANNERS, Variant, expand_variants
from semsearch_cli.config import PlannerSpec


@pytest.mark.parametrize("name", sorted(n for n, c in PLANNERS.items() if c.task == "doors" and not c.service))
def test_every_planner_finds_the_goal_on_the_demo(demo_loaded, name):
    L = demo_loaded
    for goal in L.sc.goals:
        res = L.task.run(Variant(name, ()), goal, 0)
        assert res.outcome == "found"
        assert res.distance_m >= L.shortest[goal] - 0.5  # never better than the ground-truth optimum
        assert res.decisions >= 1


@pytest.mark.parametrize("name", ["greedy", "nsos"])
def test_the_events_replanning_policy_finds_every_goal_on_its_own_paths(demo_loaded, name):
    """navigation.replan: events re-plans only on the path used up, a sign read or a lost free
    cell: every run still finds its goal, never below the optimum, and the policy shows in the paths."""
    L = demo_loaded
    sc = L.sc.model_copy(update={"navigation": L.sc.navigation.model_copy(update={"replan": "events"})})
    events = build_task(sc, L.world, L.path)
    differ = 0
    for goal in L.sc.goals:
        for seed in range(3):
            a, b = L.task.run(Variant(name, ()), goal, seed), events.run(Variant(name, ()), goal, seed)
            assert b.outcome == "found" and b.distance_m >= L.shortest[goal] - 0.5
            differ += a.path.shape != b.path.shape or not (a.path == b.path).all()
    assert differ >= 1


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
    one = run_batch(demo_loaded, specs, tmp_path / "w1", BatchOptions(workers=1))
    two = run_batch(demo_loaded, specs, tmp_path / "w2", BatchOptions(workers=2))
    assert len(one) == len(specs) == 8
    pd.testing.assert_frame_equal(_rows(one), _rows(two))


def test_interrupted_batch_resumes(demo_loaded, tmp_path):
    out = tmp_path / "r"
    specs = expand(demo_loaded, seeds=2)
    run_batch(demo_loaded, specs[:3], out)
    with open(out / "runs.csv", "a") as fh:
        fh.write("demo,greedy,{},304,1,fou")  # a row torn by an interruption
    seen = []
    runs = run_batch(demo_loaded, specs, out, progress=lambda row, done, total: seen.append(row))
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
    res = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=1, workers=1, goals=[452], planners=["bvp"], out=tmp_path / "o"), plots=False)
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
    from semsearch_cli.world.ground_truth import build_world

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
    from semsearch_cli.world.buildings.numbered import generate_building
    from semsearch_cli.world.ground_truth import build_world

    p = generate_building("single", "floor", 0, tmp_path)
    L = Loaded.load(p)
    sc = L.sc.model_copy(update={"start": StartSpec(x=L.sc.start.x, y=L.sc.start.y, heading=0.0)})
    world = build_world(sc, p.parent, str(p))
    s = world.signs
    behind = int(np.argmin(s.x))  # the westernmost sign, behind a robot facing east
    res = build_task(sc, world, p).run(Variant("greedy", ()), s.number[behind], 0)
    assert res.outcome == "found"
    assert res.path[:, 0].max() > L.sc.start.x + 20  # it went east first, then came back


def dead_end_scenario(tmp_path):
    """A 2 m x 21.6 m corridor with goal 99 on its east end wall, facing down the corridor: side
    cameras read it only from a robot turned across the corridor near the end. The old search
    drove to both ends (a U-turn flips the heading in one step) and stopped ``stuck`` after
    29.7 m with greedy, though the sign is readable 10.5 m from the start."""
    from semsearch_cli.world.scenario_folder import fill_box, scenario_dict, write_building

    img = np.zeros((30, 220), np.uint8)
    fill_box(img, 0.1, 0.2, 21.8, 0.5, 2.5, 255)
    signs = [(99, 21.8, 1.5, 180.0), (101, 5.0, 2.5, 270.0), (102, 8.0, 0.5, 90.0), (103, 14.0, 2.5, 270.0)]
    sc = scenario_dict("deadend", 0.1, (11.0, 1.5), [99], planners=[{"name": n} for n in ("greedy", "bvp", "nsos", "draft")])
    sc["start"]["heading"] = 0.0
    return write_building(tmp_path, img, signs, sc, "dead-end regression map")


def test_a_sign_readable_only_by_turning_is_found(tmp_path):
    """Completeness: with no frontier left, the robot goes back to the wall faces its cameras
    have not looked at from within reading range, and looks round there."""
    from semsearch_cli.runner import Loaded

    L = Loaded.load(dead_end_scenario(tmp_path))
    for v in L.task.variants():
        res = L.task.run(v, 99, 0)
        assert res.outcome == "found", v.label
        assert res.distance_m >= L.shortest[99] - 0.5
    res = L.task.run(Variant("greedy", ()), 99, 0)
    assert 40 < res.distance_m < 60  # both ends first (29.7 m, where it used to stop), then back east


def test_a_goal_nobody_can_read_ends_stuck_not_in_a_loop(tmp_path):
    """The sweep gives up on each wall face once it has looked round near it: a goal read only
    through a misread that never happens ends ``stuck`` well within the budget."""
    from semsearch_cli.runner import Loaded

    p = dead_end_scenario(tmp_path)
    d = yaml.safe_load(p.read_text())
    d["door_camera"] = {"p_read": 0.0}  # the cameras never read anything
    p.write_text(yaml.safe_dump(d))
    L = Loaded.load(p)
    res = L.task.run(Variant("greedy", ()), 99, 0)
    assert res.outcome == "stuck"
    assert res.distance_m < 200


def test_sweep_runs_one_folder_per_value(demo_dir, tmp_path):
    out = tmp_path / "sw"
    r = CliRunner().invoke(app, ["sweep", str(demo_dir / "scenario.yaml"), "--param", "door_camera.p_misread=0,0.5",
                                 "--seeds", "2", "--planner", "greedy", "--goal", "452", "--workers", "1", "--out", str(out)])
    assert r.exit_code == 0, r.output
    table = pd.read_csv(out / "sweep.csv")
    assert table["door_camera.p_misread"].tolist() == [0.0, 0.5]
    assert table["n"].tolist() == [2, 2] and set(table["planner"]) == {"greedy"}
    for v in ("0", "0.5"):
        rows = pd.read_csv(out / f"door_camera.p_misread={v}" / "runs.csv")
        assert len(rows) == 2
    assert (out / "sweep.png").stat().st_size > 0 and "| door_camera.p_misread |" in (out / "sweep.md").read_text()
    # value 0 is the scenario itself: the same rows as a plain run
    plain = api.run(demo_dir / "scenario.yaml", BatchOptions(seeds=2, workers=1, goals=[452], planners=["greedy"], out=tmp_path / "plain"), plots=False)
    a = pd.read_csv(out / "door_camera.p_misread=0" / "runs.csv").sort_values("seed")
    assert a["distance_m"].tolist() == plain.runs.sort_values("seed")["distance_m"].tolist()


@pytest.mark.parametrize("param,field", [("door_camera.p_misread=2", "door_camera.p_misread"), ("camera.range=3", "--param"),
                                         ("p_misread=0.1", "--param"), ("door_camera.p_misread", "--param"),
                                         ("bvp.bogus=1", "planners[1]")])
def test_sweep_bad_param_exits_2(demo_dir, tmp_path, param, field):
    r = CliRunner().invoke(app, ["sweep", str(demo_dir / "scenario.yaml"), "--param", param, "--out", str(tmp_path / "x")])
    assert r.exit_code == 2, r.output
    assert field in r.output and "Traceback" not in r.output
    assert not (tmp_path / "x").exists()  # every value is checked before anything runs


def test_a_goal_with_a_slash_writes_its_path_file(tmp_path):
    """KTH second doors are labelled e.g. ``2512/2``: the run's files stay in paths/."""
    from semsearch_cli.runner import Loaded, file_stem
    from semsearch_cli.world.scenario_folder import fill_box, scenario_dict, write_building

    img = np.zeros((30, 120), np.uint8)
    fill_box(img, 0.1, 0.2, 11.8, 0.5, 2.5, 255)
    sc = scenario_dict("slash", 0.1, (2.0, 1.5), ["12/2"], planners=[{"name": "greedy"}])
    p = write_building(tmp_path / "b", img, [("12/2", 8.0, 2.5, 270.0), (14, 4.0, 0.5, 90.0)], sc, "a goal with a slash")
    L = Loaded.load(p)
    runs = run_batch(L, expand(L, 1), tmp_path / "out", BatchOptions(workers=1))
    assert runs["outcome"].tolist() == ["found"]
    assert "/" not in file_stem("greedy", "12/2", 0, 0)
    assert (tmp_path / "out" / "paths" / f"{file_stem('greedy', '12/2', 0, 0)}.npz").is_file()


def test_views_needed_for_a_camera_that_misses():
    from semsearch_cli.tasks.doors import views_needed

    assert [views_needed(p) for p in (1.0, 0.99, 0.95, 0.5, 0.0)] == [1, 1, 2, 7, 20]  # (1 - p)^n <= 1%, capped at 20


def test_a_camera_that_misses_half_its_reads_still_finds_the_dead_end_sign(tmp_path):
    """With p_read 0.5 one look from each heading misses the sign half the time: the robot
    dwells views_needed frames per heading, and counts a wall face as looked at only after that
    many poses."""
    from semsearch_cli.runner import Loaded

    p = dead_end_scenario(tmp_path)
    d = yaml.safe_load(p.read_text())
    d["door_camera"] = {"p_read": 0.5}
    L = Loaded.load(p, d)
    assert all(L.task.run(Variant("greedy", ()), 99, s).outcome == "found" for s in range(6))


def test_a_sweep_value_holding_dots_writes_inside_out(demo_dir, tmp_path):
    """``map.image=../<demo>/map.png`` names a folder made safe (one name: no "/", a hash of the
    value): every file the sweep writes lies inside --out."""
    work = tmp_path / "work"
    work.mkdir()
    value = os.path.relpath(demo_dir / "map.png", work)  # ../../.../map.png
    assert value.startswith("..")
    d = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    d["map"]["image"] = value
    d["doors"] = str(demo_dir / "doors.csv")
    (work / "s.yaml").write_text(yaml.safe_dump(d))
    out = work / "sw"
    before = set(tmp_path.rglob("*"))
    r = CliRunner().invoke(app, ["sweep", str(work / "s.yaml"), "--param", f"map.image={value}", "--seeds", "1",
                                 "--planner", "greedy", "--goal", "452", "--workers", "1", "--out", str(out)])
    assert r.exit_code == 0, r.output
    written = set(tmp_path.rglob("*")) - before
    assert written and all(out in p.parents or p == out for p in written), sorted(map(str, written - set(out.rglob("*"))))
    (sub,) = [p for p in out.iterdir() if p.is_dir()]
    assert sub.name.startswith("map.image=") and sub.parent == out and (sub / "runs.csv").is_file()
