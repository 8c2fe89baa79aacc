"""Every episode of semsearch-bench can be solved (semsearch_cli/bench/solvable.py): the check on
a hand-made floor, its redraw in a builder, and the check over every shipped split."""

from __future__ import annotations

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

from semsearch_cli import bench
from semsearch_cli.bench import make
from semsearch_cli.bench.solvable import solvable_episodes, unsolvable, why_unsolvable
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import Loaded
from semsearch_cli.tasks.episodes import Episode


def hall_over_a_room(folder, episodes=None):
    """A 10 m x 6 m floor at 0.1 m: a hall (x 0.2-9.8 m, y 3.0-5.8 m) over a room (x 4.0-9.8 m,
    y 0.2-2.8 m) joined by a doorway 1.2 m wide (x 6.0-7.2 m) in the wall between them (y 2.8-3.0 m).
    Sign 101 on the hall's top wall; sign 999 on the same wall facing out of the building (no cell
    reads it)."""
    img = np.zeros((60, 100), np.uint8)
    img[2:30, 2:98] = 255  # the hall
    img[32:58, 40:98] = 255  # the room
    img[30:32, 60:72] = 255  # the doorway
    folder.mkdir()
    cv2.imwrite(str(folder / "map.png"), img)
    (folder / "doors.csv").write_text("number,x,y,facing\n101,1.0,5.85,-90.0\n999,5.0,5.85,90.0\n")
    doc = {"name": "hall", "map": {"image": "map.png", "resolution": 0.1}, "start": {"x": 1.5, "y": 4.0, "heading": "random"},
           "doors": "doors.csv", "goals": [101], "planners": [{"name": "greedy"}],
           "experiment": {"seeds": 1, "max_distance": 100.0}}
    if episodes is not None:
        doc["episodes"] = episodes
    (folder / "scenario.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    return Loaded.load(folder / "scenario.yaml").task


def test_a_start_facing_a_wall_across_a_band_too_narrow_to_leave_is_unsolvable_and_every_run_of_it_sticks(tmp_path):
    task = hall_over_a_room(tmp_path / "f")
    # 0.4 m from the wall, facing it: the forward laser shows a band of known free space 0.4 m deep
    # along the wall (the robot needs 0.6 m: its radius and half a cell each side) and, through the
    # doorway 3 m away, the room below, whose frontier it cannot reach; seeing candidates, it does
    # not turn round
    facing = Episode(0, 101, 3.05, 3.35, -90.0, None, task.shortest_from(101, 3.05, 3.35))
    why = why_unsolvable(task, facing)
    assert why is not None and "heading -90 deg the first re-plan has no reachable frontier candidate" in why
    res = task.run(task.variants()[0], facing, 0)
    assert (res.outcome, res.distance_m, res.decisions) == ("stuck", 0.0, 0)
    away = Episode(0, 101, 3.05, 3.35, 90.0, None, facing.shortest_m)  # the same cell, facing into the hall
    assert why_unsolvable(task, away) is None
    assert task.run(task.variants()[0], away, 0).outcome == "found"
    # 0.5 m from the wall, facing it: the band is still too narrow, but the laser shows no candidate
    # at all there, so the search turns on the spot and sees the hall behind it
    assert why_unsolvable(task, Episode(0, 101, 3.05, 3.45, -90.0, None, 1.0)) is None
    # a heading drawn at each repeat: checked at every repeat's
    drawn = Episode(0, 101, 3.05, 3.35, None, None, facing.shortest_m)
    assert why_unsolvable(task, drawn, 10) is not None and why_unsolvable(task, drawn, 1) is None
    # the robot's disk (0.25 m) does not fit 0.2 m from the wall; no cell reads sign 999
    assert "does not fit" in why_unsolvable(task, Episode(0, 101, 3.05, 3.15, 90.0, None, 1.0))
    assert why_unsolvable(task, Episode(0, 999, 3.05, 4.0, 90.0, None, 1.0)) == "no cell the robot can reach reads the sign 999"


def test_a_given_start_that_cannot_be_solved_stops_the_build(tmp_path):
    task = hall_over_a_room(tmp_path / "f", {"list": [{"goal": 101, "x": 3.05, "y": 3.35, "heading": -90.0},
                                                      {"goal": 101, "x": 3.05, "y": 3.35, "heading": 90.0}]})
    assert [(e.index, "first re-plan" in w) for e, w in unsolvable(task)] == [(0, True)]
    with pytest.raises(ScenarioError, match="episode 0 .goal 101. cannot be solved"):
        solvable_episodes(task, 1, np.random.default_rng(0))  # given by hand: not drawn again


def test_a_builder_draws_an_unsolvable_start_again_with_its_own_generator(tmp_path, monkeypatch):
    # a doors-v1 test split of a salt of ours, whose floor f012 drew episode 8 at 0.5 m from a wall
    # and facing it (greedy, nsos and bvp each end it stuck at 0 m); the floors are drawn one by
    # one from the salt, so the first 13 are those of the whole split
    monkeypatch.setitem(make.DOORS_V1_FLOORS, "test", 13)
    make.make_doors_v1("test", "salt-aaaaaaaaaaaaaaaa", tmp_path / "s")
    scenario = tmp_path / "s" / "f012" / "scenario.yaml"
    task = Loaded.load(scenario).task
    old = Episode(8, "W239", 30.65, 22.95, -133.41, None, task.shortest_from("W239", 30.65, 22.95))
    assert "first re-plan" in why_unsolvable(task, old)
    rows = pd.read_csv(scenario.parent / "episodes.csv", dtype={"goal": str})
    assert rows.loc[8, ["goal", "start_x", "start_y", "start_heading"]].tolist() == ["W239", 22.55, 9.05, 109.39]
    assert unsolvable(task) == []
    assert len(rows) == 20 and rows["shortest_m"].min() >= make.DOORS_V1_MIN_DISTANCE


@pytest.mark.parametrize("suite", sorted(n for n, s in bench.SUITES.items() if s.shipped and s.kind == "doors"))
def test_every_episode_of_every_shipped_door_split_can_be_solved(suite):
    s = bench.SUITES[suite]
    for split in s.shipped:
        sp = bench.open_split(suite, split)
        bad = [(f.id, e.index, why) for f in sp.floors for e, why in unsolvable(Loaded.load(f.scenario).task, s.repeats)]
        assert bad == []
