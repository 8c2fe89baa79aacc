"""A robot's messages, hostile but well typed, never end a run (issue 52): what ``ros live`` and
``ros replay`` take from a robot is checked where it enters (semsearch_cli/ros2/robot.py's
``refusal``, bag.py's ``from_json``), dropped and counted when it cannot be taken, and the search
goes on. docs/robot.md, "What a robot may send", is the table these tests hold the code to."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
pytest.importorskip("roslibpy", reason="the ros extra (roslibpy) is not installed")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from rosbags.rosbag2 import Reader  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from semsearch_cli.geometry import GridFrame  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.ros2.bag import Messages, from_json, to_json  # noqa: E402
from semsearch_cli.ros2.live import INPUTS, Live, LiveRun, _Repro, rosbridge_address  # noqa: E402
from semsearch_cli.ros2.robot import (DETECTIONS, GOAL_STATUS, MAP, MAX_MAP_CELLS, POSE_TOPICS, RESUME, RobotSession,  # noqa: E402
                                      RobotTask, fold_map, goal_ended, map_frame, refusal)
from semsearch_cli.errors import ScenarioError  # noqa: E402
from semsearch_cli.tasks.decisions import Agent, DecisionPoint  # noqa: E402

M = Messages()
T = M.T
H, W, RES = 30, 40, 0.1  # the robot's first map: 4 m x 3 m, a free room walled round
GOAL = 148


def room(res: float = RES, h: int = H, w: int = W, ox: float = 0.0, oy: float = 0.0, t_ns: int = 1):
    """A walled room of h x w cells at ``res`` m, free inside, as a SLAM node's OccupancyGrid."""
    states = np.full((h, w), 100, np.int8)
    states[1:-1, 1:-1] = 0
    return M.grid(t_ns, states, GridFrame(res, ox, oy, h, w))


def session(planner: str = "greedy") -> RobotSession:
    return RobotSession(RobotTask(map_frame(room(), margin=1.0)), Variant(planner, ()).build(), GOAL)


def drive(s: RobotSession, topic: str, msg) -> str | None:
    what = s.take(topic, msg)
    if what == "plan":
        s.plan()
    return what


def test_each_bad_message_is_dropped_and_counted_and_the_search_goes_on():
    s = session()
    drive(s, MAP, room())
    assert drive(s, POSE_TOPICS[0], M.pose_stamped(10, 1.0, 1.0, 0.0)) == "plan"
    bad = {
        "NaN x": M.pose_stamped(20, math.nan, 1.0, 0.0),
        "inf y": M.pose_stamped(20, 1.0, math.inf, 0.0),
        "1e12 m": M.pose_stamped(20, 1e12, 1.0, 0.0),
        "a quaternion of zeros": T["geometry_msgs/msg/PoseStamped"](header=M.header(20), pose=T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=1.0, y=1.0, z=0.0),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=0.0))),
    }
    for name, msg in bad.items():
        assert refusal(POSE_TOPICS[0], msg), name
        assert drive(s, POSE_TOPICS[0], msg) is None, name
    stamp = M.pose_stamped(20, 1.1, 1.0, 0.0)
    stamp.header.stamp.nanosec = 2_000_000_000  # a uint32 a CDR bag can hold, no Time
    assert "stamp" in refusal(POSE_TOPICS[0], stamp)
    drive(s, POSE_TOPICS[0], stamp)
    maps = {"resolution 0": room(), "resolution NaN": room(), "100000 x 100000 claimed": room(), "data short": room(),
            "origin NaN": room(), "rotated": room()}
    maps["resolution 0"].info.resolution = 0.0
    maps["resolution NaN"].info.resolution = math.nan
    maps["100000 x 100000 claimed"].info.width = maps["100000 x 100000 claimed"].info.height = 100_000
    maps["data short"].data = maps["data short"].data[:10]
    maps["origin NaN"].info.origin.position.x = math.nan
    maps["rotated"].info.origin.orientation.z = 0.5
    for name, msg in maps.items():
        assert refusal(MAP, msg), name
        drive(s, MAP, msg)
    assert drive(s, DETECTIONS, M.string({"label": "x" * 5000})) is None  # past the label's length
    assert drive(s, DETECTIONS, T["std_msgs/msg/String"](data="not json")) is None
    assert drive(s, DETECTIONS, T["std_msgs/msg/String"](data="[" * 3000 + "]" * 3000)) is None  # deep, and past the size
    assert sum(s.dropped.values()) == len(bad) + 1 + len(maps) + 3
    assert s.st.distance == 0.0 and (s.st.x, s.st.y) == (1.0, 1.0)  # no bad pose moved the robot
    assert drive(s, POSE_TOPICS[0], M.pose_stamped(30, 1.5, 1.0, 0.0)) in (None, "plan")  # a good one still does
    assert s.st.distance == pytest.approx(0.5)
    text = s.dropped_text()
    assert "/map (a map at 0 m per cell" in text and "/semsearch/pose (a pose at (nan, 1)" in text
    assert drive(s, DETECTIONS, M.string({"label": GOAL})) == "found"


def test_a_map_at_another_resolution_is_regridded_and_odd_cells_are_unknown():
    s = session()
    fr = s.task.world.frame
    coarse = room(res=0.2, h=15, w=20)  # the same room at twice the cell size
    got = fold_map(s.st.belief, coarse)
    assert got.regridded and not got.clipped and got.odd_cells == 0
    b = s.st.belief
    inside = fr.to_index(2.0, 1.5)
    assert b.seen[inside] and b.free[inside]
    wall = fr.to_index(0.1, 1.5)  # the coarse map's wall column, 0-0.2 m
    assert b.seen[wall] and not b.free[wall]
    outside = fr.to_index(-0.5, 1.5)  # in the margin, never mapped
    assert not b.seen[outside]
    odd = room()
    odd.data[5] = -56  # an int8 outside -1..100 (a CDR bag holds it; JSON's 200 is refused as no int8)
    assert fold_map(s.st.belief, odd).odd_cells == 1


def test_the_first_map_and_its_margin_are_bounded():
    big = room()
    with pytest.raises(ValueError, match="give a smaller --margin"):
        map_frame(big, margin=900.0)  # 18,040 x 18,030 cells at 0.1 m
    with pytest.raises(ValueError, match="margin of 1e"):
        map_frame(big, margin=1e6)
    assert map_frame(big, margin=10.0).height * map_frame(big, margin=10.0).width <= MAX_MAP_CELLS


def test_json_from_rosbridge_is_held_to_its_fields_types():
    ts, pose = M.ts, "geometry_msgs/msg/PoseStamped"
    good = to_json(M.pose_stamped(10, 1.0, 2.0, 0.5))
    assert from_json(ts, pose, good) == M.pose_stamped(10, 1.0, 2.0, 0.5)
    for bad, says in (({"header": {"stamp": {"sec": 2**70}}}, "header.stamp.sec"), ({"pose": {"position": {"x": "1.0"}}}, "pose.position.x"),
                      ("a string", "not a geometry_msgs/msg/PoseStamped object"), ({"pose": [1, 2]}, "pose is list")):
        with pytest.raises(ValueError, match=says.replace(".", r"\.")):
            from_json(ts, pose, bad)
    grid = "nav_msgs/msg/OccupancyGrid"
    for data in ([200], ["1"], [1.5], [[1]], "not base64 !"):
        with pytest.raises(ValueError, match="data"):
            from_json(ts, grid, {"data": data})
    with pytest.raises(ValueError, match="not a bool"):
        from_json(ts, "std_msgs/msg/Bool", {"data": "false"})  # bool("false") would be True


@pytest.mark.parametrize("url,says", [("ws://127.0.0.1:99999", "Port out of range"), ("ws://[::1", "Invalid IPv6"),
                                      ("http://robot:9090", "not a WebSocket address"), ("ws://u:secret@robot:9090", "no credentials"),
                                      ("ws://robot:0", "port 0")])
def test_a_bad_rosbridge_address_is_refused_naming_the_flag(url, says):
    with pytest.raises(ScenarioError) as exc:
        rosbridge_address(url)
    assert exc.value.field == "--rosbridge" and says in exc.value.message
    assert "secret" not in exc.value.message


# -- the property: any sequence of well-typed hostile messages ----------------------------------------
FLOATS = st.one_of(st.floats(-5.0, 5.0), st.sampled_from([math.nan, math.inf, -math.inf, 1e12, -1e300, 0.0]))
STAMPS = st.tuples(st.integers(-(2**31), 2**31 - 1), st.integers(0, 2**32 - 1))


@st.composite
def hostile_map(draw):
    res = draw(st.sampled_from([RES, RES, 0.05, 0.2, 0.0, -0.1, math.nan, math.inf, 1e-9, 100.0]))
    h, w = draw(st.integers(0, 12)), draw(st.integers(0, 12))
    msg = M.grid(1, draw(st.lists(st.integers(-128, 127), min_size=h * w, max_size=h * w).map(
        lambda v: np.asarray(v, np.int8).reshape(h, w))), GridFrame(1.0, 0.0, 0.0, h, w))
    msg.info.resolution = res
    msg.info.origin.position.x, msg.info.origin.position.y = draw(FLOATS), draw(FLOATS)
    claim = draw(st.sampled_from(["own", "own", "wider", "huge"]))
    if claim == "wider":
        msg.info.width += 1
    elif claim == "huge":
        msg.info.width = msg.info.height = 100_000
    if draw(st.booleans()) and draw(st.booleans()):
        msg.info.origin.orientation.z = 0.7
    return MAP, msg


@st.composite
def hostile_pose(draw):
    topic = draw(st.sampled_from(POSE_TOPICS))
    x, y = draw(FLOATS), draw(FLOATS)
    msg = M.pose_stamped(1, x, y, draw(st.floats(-7.0, 7.0)))
    q = msg.pose.orientation
    if draw(st.integers(0, 5)) == 0:
        q.x = q.y = q.z = q.w = draw(st.sampled_from([0.0, math.nan, 1e300]))
    msg.header.stamp.sec, msg.header.stamp.nanosec = draw(STAMPS)
    if topic != POSE_TOPICS[0]:  # PoseWithCovarianceStamped
        P = T["geometry_msgs/msg/PoseWithCovariance"](pose=msg.pose, covariance=np.zeros(36))
        msg = T["geometry_msgs/msg/PoseWithCovarianceStamped"](header=msg.header, pose=P)
    return topic, msg


DETECTION_TEXT = st.one_of(st.text(max_size=30), st.builds(lambda v: json.dumps({"label": v}), st.one_of(
    st.integers(-10**30, 10**30), st.text(max_size=80), st.none(), st.floats(allow_nan=True), st.just(GOAL + 1))),
    st.just("x" * 5000), st.just("[" * 2000))


@st.composite
def hostile_other(draw):
    kind = draw(st.sampled_from(["detection", "resume", "status"]))
    if kind == "detection":
        return DETECTIONS, T["std_msgs/msg/String"](data=draw(DETECTION_TEXT))
    if kind == "resume":
        return RESUME, T["std_msgs/msg/Bool"](data=draw(st.booleans()))
    msg = goal_ended(M, draw(st.integers(0, 2**64)), draw(st.integers(0, 6)))
    g = msg.status_list[0].goal_info.stamp
    g.sec, g.nanosec = draw(STAMPS)
    return GOAL_STATUS, msg


MESSAGES = st.lists(st.one_of(hostile_map(), hostile_pose(), hostile_other()), min_size=1, max_size=25)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(MESSAGES)
def test_a_session_fed_any_hostile_sequence_never_raises(messages):
    s = session()
    drive(s, MAP, room())
    drive(s, POSE_TOPICS[0], M.pose_stamped(5, 1.0, 1.0, 0.0))
    refused = 0
    for topic, msg in messages:
        pose_in_use = topic not in POSE_TOPICS or (s.pose_topic or topic) == topic
        refused += bool(refusal(topic, msg)) and pose_in_use
        if drive(s, topic, msg) == "found":
            break
    assert sum(s.dropped.values()) == refused  # each refused message counted once, no other
    assert math.isfinite(s.st.distance) and math.isfinite(s.st.x) and math.isfinite(s.st.y)


# -- the same through the live bridge's JSON intake --------------------------------------------------------
class _Out:
    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append(msg)


def live_intake(tmp: Path) -> Live:
    """A live run's intake with no socket: its repro bag written, its publishers kept in memory."""
    lv = Live("ws://127.0.0.1:9090", Variant("greedy", ()), GOAL, publish_only=True, repro=tmp / "repro", silence=5.0)
    lv.repro = _Repro(lv.repro_path, lv.m)
    lv.pubs = {t: _Out() for t in ("/explore/frontiers", "/semsearch/goal", "/semsearch/decision")}
    lv.nav = None  # publish_only: no action client
    return lv


JSON = st.recursive(st.one_of(st.none(), st.booleans(), st.integers(-2**80, 2**80), st.floats(), st.text(max_size=10)),
                    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)),
                    max_leaves=12)


def mutate(payload, draw):
    """A good message's JSON with one field (anywhere in it) replaced by any JSON value."""
    if isinstance(payload, dict) and payload:
        key = draw(st.sampled_from(sorted(payload)))
        if draw(st.booleans()):
            return {**payload, key: draw(JSON)}
        return {**payload, key: mutate(payload[key], draw)}
    return draw(JSON)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.data())
def test_live_json_of_any_shape_never_raises_and_the_repro_bag_holds_what_was_taken(tmp_path_factory, data):
    tmp = tmp_path_factory.mktemp("live")
    lv = live_intake(tmp)
    good = {MAP: to_json(room()), POSE_TOPICS[0]: to_json(M.pose_stamped(5, 1.0, 1.0, 0.0)),
            DETECTIONS: to_json(M.string({"label": 7})), RESUME: {"data": True}}
    try:
        assert lv._take(MAP, good[MAP]) is None
        for _ in range(data.draw(st.integers(1, 12))):
            topic = data.draw(st.sampled_from(sorted(good)))
            payload = mutate(good[topic], data.draw) if data.draw(st.booleans()) else good[topic]
            end = lv._take(topic, payload)
            assert end is None or isinstance(end, LiveRun)
            if end is not None:
                break
        assert lv.session is not None
    finally:
        lv.repro.keep()
    assert set(INPUTS) >= set(good)


def test_a_pose_of_strings_a_map_that_is_a_string_and_a_stamp_of_2_70_are_dropped_live(tmp_path):
    lv = live_intake(tmp_path)
    try:
        assert lv._take(MAP, "a map") is None  # before the first map: counted for the session to come
        assert lv._take(MAP, to_json(room())) is None
        pose = to_json(M.pose_stamped(5, 1.0, 1.0, 0.0))
        assert lv._take(POSE_TOPICS[0], {**pose, "pose": {"position": {"x": "1", "y": "2"}}}) is None
        assert lv._take(POSE_TOPICS[0], {**pose, "header": {"stamp": {"sec": 2**70, "nanosec": 0}}}) is None
        assert lv._take(POSE_TOPICS[0], {**pose, "pose": {**pose["pose"], "position": {"x": math.nan, "y": 1.0, "z": 0.0}}}) is None
        assert lv._take(MAP, {**to_json(room()), "data": [200] * (H * W)}) is None
        assert lv.session.posed is False  # none of them was a pose
        assert lv._take(POSE_TOPICS[0], pose) is None  # a good one: a plan, published (publish_only)
        assert lv.session.posed and lv.pubs["/semsearch/goal"].sent
        assert sum(lv.session.dropped.values()) == 5
        text = lv._result("interrupted", "").dropped
        assert "header.stamp.sec" in text and "pose.position.x" in text and "not a nav_msgs/msg/OccupancyGrid" in text
    finally:
        kept = lv.repro.keep()
    # the repro bag holds the messages taken, in order: none of the dropped ones
    with Reader(kept) as r:
        topics = [c.topic for c, _, _ in r.messages()]
    assert topics[:2] == [MAP, POSE_TOPICS[0]] and topics.count(MAP) == 1 and topics.count(POSE_TOPICS[0]) == 1


def test_a_front_end_answers_a_robots_decisions_as_the_planner_would():
    """RobotSession's re-plan stepped from outside (replan, answer), an Agent in the planner's
    seat answering with greedy's own choices, makes the re-plans the seated planner makes."""
    greedy = Variant("greedy", ()).build()
    seated, by_hand = session(), RobotSession(RobotTask(map_frame(room(), margin=1.0)), Variant("agent", ()), GOAL,
                                              seat=Agent(replan_on_signs=greedy.replan_on_signs))
    plans = {"seated": [], "by hand": []}
    for t, (x, y) in enumerate([(1.0, 1.0), (1.5, 1.0), (2.0, 1.2), (2.5, 1.5)], 1):
        for name, s in (("seated", seated), ("by hand", by_hand)):
            if t == 1:
                s.take(MAP, room(t_ns=t))
            if s.take(POSE_TOPICS[0], M.pose_stamped(10 * t, x, y, 0.0)) != "plan":
                continue
            if name == "seated":
                plan = s.plan()
            else:
                point = s.replan()
                while isinstance(point, DecisionPoint):  # the handle's view of the pending decision, as OpenEpisode's
                    assert s.point is point and s.observation is point.observation and s.mask is point.mask
                    point = s.answer(greedy.choose(point.observation, point.choices))
                plan = point
                assert s.point is None and s.observation is None
            plans[name].append(plan if isinstance(plan, str) else [np.round(plan[0], 6).tolist(), np.round(plan[1], 6).tolist()])
    assert plans["seated"] == plans["by hand"] and len(plans["seated"]) >= 1
    with pytest.raises(RuntimeError, match="no decision is pending"):
        by_hand.answer(None)
    with pytest.raises(RuntimeError, match="no decision is pending"):
        by_hand.ask()
