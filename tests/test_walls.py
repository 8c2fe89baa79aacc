"""wall_numbers (issue 53): the numbers along each wall, where the goal's number falls between
them or past a wall's last signs; the sign faces it reads them from; nearest-frontier where nothing
is predicted."""

from __future__ import annotations

import numpy as np
import pytest

from semsearch_cli import api
from semsearch_cli.belief import DoorBelief
from semsearch_cli.belief.doors import DoorReads
from semsearch_cli.config import BeliefSpec
from semsearch_cli.geometry import GridFrame
from semsearch_cli.planners import Variant
from semsearch_cli.planners.doors import walls
from semsearch_cli.planners.doors.walls import WallParams, stretch_predictions
from semsearch_cli.runner import Loaded
from semsearch_cli.world.buildings.numbered import generate_building

P = WallParams()


def test_a_bracket_puts_the_goal_between_its_two_neighbours():
    t = np.array([0.0, 2.5, 5.0, 7.5])
    n = np.array([201.0, 202.0, 204.0, 205.0])  # 203 skipped, or across the corridor
    out = stretch_predictions(t, n, 203.0, P)
    assert [(round(tg, 2), w, gap, round(te, 2)) for tg, w, gap, te in out] == [(3.75, P.w_near, 0.0, 3.75)]


def test_a_wall_rising_toward_the_goal_is_extrapolated_past_its_last_sign_while_the_goal_is_near():
    t = np.array([0.0, 2.5, 5.0])
    n = np.array([210.0, 211.0, 212.0])
    (tg, w, gap, te), = stretch_predictions(t, n, 215.0, P)
    assert tg == pytest.approx(12.5) and w == P.w_near and gap == 3.0 and te == 5.0
    (tg, w, gap, _), = stretch_predictions(t, n, 220.0, P)  # 8 numbers on: a far extrapolation
    assert tg == pytest.approx(25.0) and w == P.w_far
    (tg, w, _, te), = stretch_predictions(t, n, 207.0, P)  # below: past the other end
    assert tg == pytest.approx(-7.5) and te == 0.0


def test_neighbours_tens_of_numbers_apart_or_turning_back_predict_nothing():
    t = np.array([0.0, 2.5, 5.0, 7.5])
    assert stretch_predictions(t, np.array([17.0, 140.0, 62.0, 101.0]), 80.0, P) == []  # a random numbering
    # not monotone at either end: no extrapolation (the numbers are within max_slope, so brackets stay)
    out = stretch_predictions(t, np.array([5.0, 7.0, 6.0, 8.0]), 30.0, P)
    assert out == []


def test_a_rooms_lettered_doors_count_as_one_number_at_their_mean_position():
    t = np.array([0.0, 2.5, 5.0, 7.5])
    n = np.array([210.0, 212.0, 212.0, 213.0])  # 212a, 212b
    out = stretch_predictions(t, n, 211.0, P)
    assert [round(tg, 3) for tg, _, _, _ in out] == [round(0.0 + 0.5 * 3.75, 3)]


def _belief_with_a_wall(known_to: float):
    """A corridor from y = 1 m to 3 m along x, its north wall (row 9, y = 3 m) known to x =
    ``known_to`` m, unknown beyond; signs 210, 211, 212 on it at x = 1, 3.5, 6 m, read facing north."""
    fr = GridFrame(0.1, 0.0, 0.0, 40, 400)
    b = DoorBelief(fr, BeliefSpec(), 0.25)
    seen = np.zeros((40, 400), bool)
    free = np.zeros((40, 400), bool)
    k = int(known_to / 0.1)
    seen[9:31, :k] = True
    free[10:30, :k] = True  # the corridor (rows 10..29: y 1..3 m)
    b.fold_grid(0, 0, seen, free)
    for label, x in ((210, 1.0), (211, 3.5), (212, 6.0)):
        r, c = fr.to_index(x, 2.0)
        for _ in range(3):
            b.reads.add(label, int(r * fr.width + c), x, 2.0, 0.0, float(np.pi / 2))
    return b


def test_a_long_extrapolation_is_kept_only_along_a_wall_the_map_shows():
    class Ctx:
        goal = 225  # 13 numbers past 212: past `far`, 32.5 m on along the wall
    for known_to, kept in ((39.0, True), (8.0, False)):
        Ctx.belief = _belief_with_a_wall(known_to)
        q, w = walls.predictions(Ctx, P)
        if kept:
            assert len(q) == 1 and w[0] == P.w_wall and q[0] == pytest.approx([38.5, 2.5], abs=0.3)
        else:
            assert len(q) == 0


def test_reads_keep_the_bearing_and_the_belief_finds_the_wall_face_of_each_sign():
    fr = GridFrame(0.1, 0.0, 0.0, 40, 100)  # 10 m x 4 m
    b = DoorBelief(fr, BeliefSpec(), 0.25)
    free = np.zeros((40, 100), bool)
    free[10:30, :] = True  # a corridor from y = 1 m to y = 3 m (rows 10..29)
    b.fold_grid(0, 0, np.ones((40, 100), bool), free)
    r, c = fr.to_index(2.0, 2.0)
    sign = (4.0, 3.0)  # on the corridor's wall at y = 3 m
    for x in (2.0, 2.2):
        bearing = float(np.arctan2(sign[1] - 2.0, sign[0] - x))
        b.reads.add(301, int(r * fr.width + c), x, 2.0, 0.0, bearing)
    b.reads.add(302, int(r * fr.width + c), 2.0, 2.0, 0.0)  # no bearing: not placed
    labels, face, axis = b.sign_faces(min_reads=1)
    assert labels == [301]
    assert np.hypot(*(face[0] - sign)) < 0.15
    assert axis[0] == pytest.approx([0.0, 1.0])  # the left camera of a robot heading +x looks at +y
    before = DoorReads()
    before.add(301, 0, 1.0, 1.0, 0.0)
    assert before.bearings[0] == 0 and before.snx[0] == 0.0


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    """One long corridor numbered up one wall and back the other (the loop convention)."""
    out = tmp_path_factory.mktemp("walls")
    return Loaded.load(generate_building("single", "loop", 3, out / "b", spacing=2.5))


def test_the_sign_faces_of_a_run_are_where_the_signs_are(corridor, monkeypatch):
    L = corridor
    seen = {}
    real = walls.predictions

    def spy(ctx, p):
        seen["belief"] = ctx.belief
        return real(ctx, p)

    monkeypatch.setattr(walls, "predictions", spy)
    ep = L.task.episodes[0]
    L.task.run(Variant("wall_numbers", ()), ep, 0)
    labels, face, _ = seen["belief"].sign_faces()
    s = L.task.world.signs
    where = {s.number[i]: (s.x[i], s.y[i]) for i in range(len(s.number))}
    err = np.array([np.hypot(*(f - where[lab])) for lab, f in zip(labels, face)])
    assert len(err) >= 10 and np.median(err) < 0.2 and (err < 0.5).mean() > 0.9


def test_with_nothing_predicted_it_is_nearest_frontier_step_for_step(corridor, monkeypatch):
    L = corridor
    monkeypatch.setattr(walls, "predictions", lambda ctx, p: (np.zeros((0, 2)), np.zeros(0)))  # nothing predicted
    for ep in L.task.episodes[:3]:
        a = L.task.run(Variant("wall_numbers", ()), ep, 0)
        b = L.task.run(Variant("greedy", ()), ep, 0)
        assert a.distance_m == b.distance_m and np.array_equal(a.path, b.path)


def test_on_a_numbered_corridor_reading_the_walls_beats_nearest_frontier(corridor):
    L = corridor
    eps = L.task.episodes
    wall = [L.task.run(Variant("wall_numbers", ()), ep, 0) for ep in eps]
    near = [L.task.run(Variant("greedy", ()), ep, 0) for ep in eps]
    assert all(r.outcome == "found" for r in wall + near)
    assert sum(r.distance_m for r in wall) < sum(r.distance_m for r in near)


def test_the_world_splits_its_signs_into_stretches_of_wall(corridor):
    s = corridor.task.world.signs
    wall = s.walls()
    assert (wall >= 0).all() and len(set(wall)) >= 2  # a corridor's two walls at least
    for w in set(wall.tolist()):
        k = np.flatnonzero(wall == w)
        assert np.ptp(np.round(s.facing[k], 6)) == 0.0  # one way each
        along = np.sort(s.x[k])  # the corridor runs along x
        assert (np.diff(along) <= 12.0).all()


def test_wall_rule_is_privileged_and_bounds_wall_numbers_from_above(corridor):
    listed = {p["name"]: p for p in api.planners()}
    assert "each stretch of wall" in listed["wall_rule"]["privileged"] and not listed["wall_numbers"]["privileged"]
    L = corridor
    rule = [L.task.run(Variant("wall_rule", ()), ep, 0) for ep in L.task.episodes]
    wall = [L.task.run(Variant("wall_numbers", ()), ep, 0) for ep in L.task.episodes]
    assert all(r.outcome == "found" for r in rule)
    assert sum(r.distance_m for r in rule) <= sum(r.distance_m for r in wall)
