"""`semsearch ros live` against a real rosbridge server on loopback (semsearch_cli/ros2/loopback.py:
the rosbridge v2 JSON protocol over a WebSocket), whose robot is semsearch's simulator, and the
robot-message session it shares with `ros replay`."""

import json
import math
import re
import select
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("roslibpy", reason="the ros extra (roslibpy) is not installed")
pytest.importorskip("websockets", reason="the ros extra (websockets) is not installed")
from rosbags.rosbag2 import Reader  # noqa: E402
from websockets.sync.client import connect  # noqa: E402

from semsearch_cli import api  # noqa: E402
from semsearch_cli.cli import app  # noqa: E402
from semsearch_cli.ros2 import replay_bag  # noqa: E402
from semsearch_cli.ros2.bag import Messages, from_json, to_json  # noqa: E402
from semsearch_cli.ros2.live import LIVE_TOPICS  # noqa: E402
from semsearch_cli.ros2.loopback import Rosbridge, SimRobot  # noqa: E402
from semsearch_cli.ros2.robot import GOAL_STATUS, RobotSession, RobotTask, fold_map, goal_ended, map_frame, pose_of  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.planners.doors import nsos  # noqa: E402
from semsearch_cli.tasks.base import Observer  # noqa: E402
from semsearch_cli.tasks.doors import DoorDecision  # noqa: E402
from tests.llm_server import ChatServer, first_target  # noqa: E402

PERIOD = 0.04  # s between the stand-in robot's steps: ros live answers a step within it (see docs/robot.md)


@pytest.fixture
def robot(demo_loaded):
    """A rosbridge server on 127.0.0.1 (a free port) and a stand-in robot factory behind it."""
    bridge = Rosbridge().start()
    made = []

    def make(goal, seed=0, **kw):
        made.append(SimRobot(bridge, demo_loaded, goal, seed, period=PERIOD, **kw).start())
        return made[-1]

    yield bridge, make
    bridge.stop()


def live(bridge, planner, goal, tmp_path, **kw):
    """ros live on loopback: the run's folder ``out`` when given, else (the deprecated way) a
    failed run's bag at tmp_path/repro."""
    kw.setdefault("silence", 20.0)
    if "out" not in kw:
        kw["repro"] = tmp_path / "repro"
    return api.ros_live(bridge.url, planner, goal, **kw)


class Decisions(Observer):
    def __init__(self):
        self.rows = []

    def see(self, event):
        if isinstance(event, DoorDecision):
            self.rows.append({"step": int(event.step), "target": [round(float(v), 6) for v in event.target_xy]})


@pytest.mark.parametrize("planner,goal", [("greedy", "304"), ("nsos", "452")])
def test_live_finds_the_goal_and_travels_what_run_travels(robot, demo_loaded, tmp_path, planner, goal, monkeypatch):
    """Over the loopback rosbridge, with the simulator as the robot (Nav2's NavigateToPose goals
    driven as `semsearch run` drives its paths), ros live finds the goal. When every goal reached
    the robot before its next step, it makes the run's decisions, step and target, and the robot
    travels the run's distance; a late goal (a slow machine), or a tie the planner broke with its
    generator (in a run, the generator the robot senses with; live, the planner's own), may part
    them: after a late goal the distance is within 5% (benchmarks/ros_live.py measures both;
    docs/robot.md); after a tie the two go on as two draws of the episode."""
    bridge, make = robot
    seen = Decisions()
    drawn = []  # where the run's planner broke a tie with the generator (the robot's own, in a run)
    real_pick = nsos.pick

    def pick(phi, D, keep, hysteresis, rng):
        state = rng.bit_generator.state["state"]["state"]
        j = real_pick(phi, D, keep, hysteresis, rng)
        if rng.bit_generator.state["state"]["state"] != state:
            drawn.append(len(seen.rows))  # the decisions made before it
        return j

    monkeypatch.setattr(nsos, "pick", pick)
    run = demo_loaded.task.run(Variant(planner, ()), goal, 0, observer=seen)
    monkeypatch.setattr(nsos, "pick", real_pick)
    bot = make(goal)
    res = live(bridge, planner, goal, tmp_path, out=tmp_path / "live")
    assert res.outcome == "found" and run.outcome == "found"
    assert res.repro is None and res.bag == tmp_path / "live" / "bag" and not list(tmp_path.glob(".*"))
    # the run's folder replays from its record alone, found again at the same decisions
    checked = api.verify(tmp_path / "live").verdict
    assert (checked.runs, checked.verified, checked.failed) == (1, 1, [])
    got = [{"step": r["step"], "target": [round(v, 6) for v in r["target"]]} for r in res.decisions]
    if max(bot.late) == 0 and not any(drawn):
        assert got == seen.rows and bot.found_at == pytest.approx(run.distance_m, abs=1e-9)
    elif max(bot.late) == 0:  # a tie broken at random (the live planner's generator is not the robot's):
        assert got[:drawn[0]] == seen.rows[:drawn[0]]  # the same decisions up to it, then another episode's way
    else:
        assert bot.found_at == pytest.approx(run.distance_m, rel=0.05)
    # every goal went to Nav2's action, stamped with the pose it was planned on; none was ignored
    sent = [op for op in bridge.ops if op["op"] == "send_action_goal"]
    assert len(sent) == res.goals == len(bot.goals) > 0
    assert {(op["action"], op["action_type"]) for op in sent} == {("/navigate_to_pose", "nav2_msgs/action/NavigateToPose")}
    assert all(op["args"]["pose"]["header"]["frame_id"] == "map" for op in sent)
    # explore_lite's frontiers, the goal and the decision, as advertised, at each decision
    advertised = {op["topic"]: op["type"] for op in bridge.ops if op["op"] == "advertise"}
    assert advertised == {"/explore/frontiers": "visualization_msgs/msg/MarkerArray", "/semsearch/goal": "geometry_msgs/msg/PoseStamped",
                          "/semsearch/decision": "std_msgs/msg/String"}
    deadline = time.monotonic() + 5
    while bridge.advertised and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not bridge.advertised  # unadvertised at the end
    published = [t for t, _ in bridge.received]
    assert published.count("/explore/frontiers") == published.count("/semsearch/goal") == len(res.decisions)
    fronts = next(m for t, m in bridge.received if t == "/explore/frontiers")
    assert fronts["markers"][0]["action"] == 3 and {m["ns"] for m in fronts["markers"]} == {"frontiers"}  # DELETEALL first
    decision = json.loads(next(m for t, m in bridge.received if t == "/semsearch/decision")["data"])
    assert decision == res.decisions[0]


def free_port() -> int:
    with socket.socket() as sock:  # a port nobody listens on once it is closed
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def test_the_command_line_finds_the_goal_and_a_failing_run_leaves_a_repro_bag_that_replays(demo_dir, demo_loaded, tmp_path):
    """`semsearch ros sim` (another process) is the robot; `semsearch ros live` exits 0 when
    found. A run stopped by its budget exits 1 and leaves a repro bag (map, pose, detections, goal
    ends) of a few kilobytes, which `ros replay` runs to the live run's decisions."""
    port = free_port()
    sim = subprocess.Popen([sys.executable, "-X", "faulthandler", "-c", "from semsearch_cli.cli import main; main()", "ros",
                            "sim", str(demo_dir / "scenario.yaml"), "--goal", "304", "--port", str(port), "--period", str(PERIOD)],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           # Ctrl-C as at a terminal: a child inherits an ignored SIGINT, and a test run
                           # earlier in the same pytest worker can leave it ignored (the stand-in's stacks
                           # showed it sleeping in its loop 30 s after the SIGINT)
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        assert select.select([sim.stdout], [], [], 60)[0], "ros sim said nothing in 60 s"
        first = sim.stdout.readline()
        assert first.startswith(f"rosbridge on ws://127.0.0.1:{port}: the robot of "), sim.stderr.read() if not first else first
        r = CliRunner().invoke(app, ["ros", "live", "--rosbridge", f"ws://127.0.0.1:{port}", "--planner", "greedy", "--goal",
                                     "304", "--repro", str(tmp_path / "ok")])
    finally:
        sim.send_signal(signal.SIGINT)
        try:
            rest, _ = sim.communicate(timeout=30)
        except subprocess.TimeoutExpired:  # where it is stuck: faulthandler writes every thread's stack on SIGABRT
            sim.send_signal(signal.SIGABRT)
            _, err = sim.communicate(timeout=30)
            raise AssertionError(f"ros sim still running 30 s after SIGINT; its threads:\n{err}") from None
    assert r.exit_code == 0, r.output
    assert "found: read the goal's sign; " in r.output and "repro" not in r.output and not (tmp_path / "ok").exists()
    run = demo_loaded.task.run(Variant("greedy", ()), "304", 0)
    said = " ".join(rest.split())
    found_at = float(re.search(r"read the sign 304 after ([0-9.]+) m", said).group(1))
    assert found_at == pytest.approx(run.distance_m, rel=0.05) and said.endswith(" goals") and sim.returncode == 0

    bridge = Rosbridge().start()
    try:
        SimRobot(bridge, demo_loaded, "452", 0, period=PERIOD).start()
        r = CliRunner().invoke(app, ["ros", "live", "--rosbridge", bridge.url, "--planner", "greedy", "--goal", "452",
                                     "--max-distance", "15", "--repro", str(tmp_path / "repro")])
    finally:
        bridge.stop()
    assert r.exit_code == 1, r.output
    out = " ".join(r.output.split())
    assert "budget: travelled 15." in out and f"repro bag: {tmp_path / 'repro'}" in out
    bag = tmp_path / "repro"
    size = sum(p.stat().st_size for p in bag.rglob("*") if p.is_file())
    assert size < 200_000
    m = Messages()
    with Reader(bag) as rd:
        topics = {c.topic: c.msgtype for c in rd.connections}
        stamps, chosen = [], []
        for c, t, raw in rd.messages():
            stamps.append(t)
            if c.topic == "/semsearch/decision":
                chosen.append(json.loads(m.ts.deserialize_cdr(raw, c.msgtype).data))
    took = {"/map": "nav_msgs/msg/OccupancyGrid", "/semsearch/pose": "geometry_msgs/msg/PoseStamped",
            "/semsearch/detections": "std_msgs/msg/String", "/explore/frontiers": "visualization_msgs/msg/MarkerArray",
            "/semsearch/goal": "geometry_msgs/msg/PoseStamped", "/semsearch/decision": "std_msgs/msg/String"}
    assert took.items() <= topics.items() <= {**took, GOAL_STATUS: "action_msgs/msg/GoalStatusArray"}.items()
    assert stamps == sorted(set(stamps))
    decided = int(re.search(r"poses, (\d+) decisions?,", out).group(1))
    rep = replay_bag(None, bag, Variant("greedy", ()), tmp_path / "replayed", "mcap", "452")
    assert rep.decisions == chosen and len(chosen) == decided > 0  # what the live run chose, decision for decision
    r2 = CliRunner().invoke(app, ["ros", "replay", str(bag), "--planner", "greedy", "--goal", "452", "--out",
                                  str(tmp_path / "replayed2")])
    assert r2.exit_code == 0, r2.output


def test_live_decisions_are_the_repro_bags_decisions(robot, tmp_path):
    bridge, make = robot
    make("452")
    res = live(bridge, "nsos", "452", tmp_path, max_distance=12.0)
    assert res.outcome == "budget" and res.repro == tmp_path / "repro"
    rep = replay_bag(None, res.repro, Variant("nsos", ()), tmp_path / "replayed", "mcap", "452")
    assert rep.decisions == res.decisions and len(res.decisions) > 3


def test_publish_only_drives_nothing_and_the_robots_own_stack_follows_its_goals(robot, demo_loaded, tmp_path):
    """--publish-only sends no action goal: the goal goes out as a PoseStamped on
    /semsearch/goal, which the robot's own navigation (here the stand-in's, following that topic)
    drives to; a goal counts as reached when the pose comes within 0.5 m of it."""
    bridge, make = robot
    bot = make("304", follow="/semsearch/goal")
    res = live(bridge, "greedy", "304", tmp_path, publish_only=True)
    assert res.outcome == "found"
    assert not [op for op in bridge.ops if op["op"] in ("send_action_goal", "cancel_action_goal")] and res.goals == 0
    goals = [m for t, m in bridge.received if t == "/semsearch/goal"]
    assert len(goals) == len(bot.goals) == len(res.decisions) > 3
    run = demo_loaded.task.run(Variant("greedy", ()), "304", 0)
    assert bot.found_at == pytest.approx(run.distance_m, rel=0.25)


def test_explore_resume_pauses_and_resumes(robot, tmp_path):
    """/explore/resume False cancels the goal under way and stops the re-plans (the robot stands
    still); True re-plans at once and the search goes on to the goal."""
    bridge, make = robot
    bot = make("304")
    box = {}
    worker = threading.Thread(target=lambda: box.update(res=live(bridge, "greedy", "304", tmp_path)))
    worker.start()
    deadline = time.monotonic() + 30
    while bot.st.steps < 40 and time.monotonic() < deadline:
        time.sleep(0.01)
    bridge.call(bot.resume, False)
    time.sleep(0.5)
    steps, goals = bot.st.steps, len(bot.goals)
    time.sleep(0.5)
    assert (bot.st.steps, len(bot.goals)) == (steps, goals)  # standing, no new goal
    # the goal under way was cancelled (unless it had just been reached as the pause came)
    assert bot.ended[-1][1] == 5 and any(op["op"] == "cancel_action_goal" for op in bridge.ops) or bot.ended[-1][1] == 4
    bridge.call(bot.resume, True)
    worker.join(60)
    assert not worker.is_alive() and box["res"].outcome == "found" and len(bot.goals) > goals


def test_a_bad_address_no_server_and_an_existing_repro_folder_exit_2(tmp_path):
    runner = CliRunner()
    base = ["ros", "live", "--planner", "greedy", "--goal", "304", "--repro", str(tmp_path / "r")]
    r = runner.invoke(app, base + ["--rosbridge", "http://localhost:9090"])
    assert r.exit_code == 2 and "is not a WebSocket address: give ws://HOST:PORT" in " ".join(r.output.split())
    port = free_port()
    r = runner.invoke(app, base + ["--rosbridge", f"ws://127.0.0.1:{port}"])
    assert r.exit_code == 2 and "no rosbridge answers at" in " ".join(r.output.split())
    (tmp_path / "r").mkdir()
    r = runner.invoke(app, base + ["--rosbridge", f"ws://127.0.0.1:{port}"])
    assert r.exit_code == 2 and "exists already" in r.output
    r = runner.invoke(app, ["ros", "live", "--planner", "nsoss", "--goal", "304", "--rosbridge", f"ws://127.0.0.1:{port}"])
    assert r.exit_code == 2 and "'nsos'" in r.output, r.output
    live = ["ros", "live", "--planner", "greedy", "--rosbridge", f"ws://127.0.0.1:{port}"]
    for args, field in [(["--goal", ""], "--goal"), (["--goal", "304", "--silence", "0"], "--silence"),
                        (["--goal", "304", "--margin", "nan"], "--margin"), (["--goal", "304", "--max-distance", "-5"], "--max-distance")]:
        r = runner.invoke(app, live + args)
        assert r.exit_code == 2 and f"field '{field}'" in r.output and "Traceback" not in r.output, (args, r.output)


def test_ros_sim_refuses_what_it_cannot_be(demo_dir):
    runner = CliRunner()
    sim = ["ros", "sim", str(demo_dir / "scenario.yaml")]
    for args, field in [(["--goal", "999"], "--goal"), (["--goal", ""], "--goal"), (["--goal", "304", "--period", "nan"], "--period"),
                        (["--goal", "304", "--follow", "semsearch/goal"], "--follow")]:
        r = runner.invoke(app, sim + args)
        assert r.exit_code == 2 and f"field '{field}'" in r.output and "Traceback" not in r.output, (args, r.output)
    for args in (["--goal", "304", "--port", "99999"], ["--goal", "304", "--seed", "-1"]):
        r = runner.invoke(app, sim + args)
        assert r.exit_code == 2 and "Invalid value" in r.output, (args, r.output)
    said = " ".join(runner.invoke(app, sim + ["--goal", "3044"]).output.split())
    assert "no door sign carries 3044 in this scenario (did you mean '304'?); its goals: 304, 452 (any of its 24 signs" in said, said


def test_the_loopback_server_speaks_rosbridge_v2(robot, demo_loaded):
    """Subscribe (a latched topic's last message at once), publish to another client, unsubscribe,
    an action goal answered by its result, and a status error for an op it does not serve."""
    bridge, make = robot
    bot = make("304")
    with connect(bridge.url) as a, connect(bridge.url) as b:
        b.send(json.dumps({"op": "subscribe", "id": "s0", "topic": "/semsearch/pose", "type": "geometry_msgs/msg/PoseStamped"}))
        assert json.loads(b.recv(timeout=5))["msg"]["pose"]["position"]["x"] == bot.st.x  # the robot's first frame
        a.send(json.dumps({"op": "subscribe", "id": "s1", "topic": "/map", "type": "nav_msgs/msg/OccupancyGrid"}))
        first = json.loads(a.recv(timeout=5))  # latched
        assert first["op"] == "publish" and first["topic"] == "/map"
        grid = first["msg"]
        assert (grid["info"]["width"], grid["info"]["height"]) == (demo_loaded.world.frame.width, demo_loaded.world.frame.height)
        assert set(grid["data"]) <= {-1, 0, 100} and 0 in grid["data"]
        a.send(json.dumps({"op": "unsubscribe", "id": "s1", "topic": "/map"}))
        b.send(json.dumps({"op": "subscribe", "id": "s2", "topic": "/chatter", "type": "std_msgs/msg/String"}))
        time.sleep(0.1)
        a.send(json.dumps({"op": "advertise", "id": "p1", "topic": "/chatter", "type": "std_msgs/msg/String"}))
        a.send(json.dumps({"op": "publish", "topic": "/chatter", "msg": {"data": "hello"}}))
        assert json.loads(b.recv(timeout=5)) == {"op": "publish", "topic": "/chatter", "msg": {"data": "hello"}}
        a.send(json.dumps({"op": "call_service", "id": "c1", "service": "/rosapi/topics", "args": {}}))
        err = json.loads(a.recv(timeout=5))
        assert err["op"] == "status" and err["level"] == "error" and "call_service" in err["msg"]
        a.send(json.dumps({"op": "send_action_goal", "id": "g1", "action": "/navigate_to_pose",
                           "action_type": "nav2_msgs/action/NavigateToPose", "feedback": True,
                           "args": {"pose": {"header": {"frame_id": "map"},
                                             "pose": {"position": {"x": bot.st.x, "y": bot.st.y}}}}}))
        end = json.loads(a.recv(timeout=5))  # the goal is where the robot stands: reached at once
        assert (end["op"], end["id"], end["status"], end["result"]) == ("action_result", "g1", 4, True)


def test_json_messages_round_trip_and_maps_fold_into_a_grid_with_a_margin():
    m = Messages()
    frame0 = type("F", (), {"res": 0.1, "origin_x": -1.0, "origin_y": 2.0, "height": 3, "width": 4})()
    states = np.array([[-1, 0, 100, 0], [0, 0, 0, 0], [100, 100, -1, -1]], np.int8)
    grid = m.grid(7, states, frame0)
    back = from_json(m.ts, "nav_msgs/msg/OccupancyGrid", json.loads(json.dumps(to_json(grid))))
    assert m.serialize(back) == m.serialize(grid)
    frame = map_frame(grid, margin=0.25)  # 3 whole cells around it
    assert (frame.height, frame.width, frame.origin_x, frame.origin_y) == (9, 10, pytest.approx(-1.3), pytest.approx(1.7))
    task = RobotTask(frame)
    b = task.new_belief()
    assert fold_map(b, grid).clipped is False
    assert b.seen[3:6, 3:7].tolist() == (states >= 0).tolist() and b.free[3:6, 3:7].tolist() == (states == 0).tolist()
    assert not b.seen[:3].any() and not b.seen[6:].any()
    # a map that outgrew the grid: the cells beyond it are left out, and said to be
    small = RobotTask(map_frame(grid)).new_belief()
    grid.info.origin.position.x = -1.2
    assert fold_map(small, grid).clipped is True
    assert small.seen[:, :2].tolist() == (states[:, 2:] >= 0).tolist() and not small.seen[:, 2:].any()  # 2 cells to the left


def test_a_session_takes_goal_ends_once_and_resume_replans_at_once():
    m = Messages()
    frame0 = type("F", (), {"res": 0.1, "origin_x": 0.0, "origin_y": 0.0, "height": 20, "width": 20})()
    states = np.zeros((20, 20), np.int8)
    states[0], states[-1], states[:, 0], states[:, -1] = 100, 100, 100, 100
    grid = m.grid(0, states, frame0)
    s = RobotSession(RobotTask(map_frame(grid)), Variant("greedy", ()).build(), "7")
    assert s.take("/semsearch/pose", m.pose_stamped(0, 1.0, 1.0, 0.0)) is None  # no map yet
    assert s.take("/map", grid) is None
    assert s.take("/semsearch/pose", m.pose_stamped(0, 1.05, 1.0, 0.0)) == "plan"  # the first pose with a map
    s.plan()
    assert s.take("/semsearch/pose", m.pose_stamped(0, 1.1, 1.0, 0.0)) is None
    assert s.take(GOAL_STATUS, goal_ended(m, 1, 4)) == "plan"  # goal 1 reached
    s.plan()
    assert s.take(GOAL_STATUS, goal_ended(m, 1, 4)) is None  # the same end again: taken once
    assert s.take(GOAL_STATUS, goal_ended(m, 2, 5)) is None  # cancelled: not a path done
    replaced = goal_ended(m, 4, 6)  # Nav2 aborts goal 4 as goal 5 replaces it: the newest, 5, is under way
    replaced.status_list.append(goal_ended(m, 5, 2).status_list[0])
    assert s.take(GOAL_STATUS, replaced) is None
    assert s.take("/explore/resume", m.T["std_msgs/msg/Bool"](data=False)) is None
    assert s.take(GOAL_STATUS, goal_ended(m, 3, 6)) is None  # paused: no re-plan
    assert s.take("/explore/resume", m.T["std_msgs/msg/Bool"](data=True)) == "plan"
    assert s.take("/semsearch/detections", m.string({"label": 8})) is None
    assert s.take("/semsearch/detections", m.string({"label": "7"})) == "found"
    assert math.isclose(s.st.distance, 0.1)


def test_the_live_topics_table_is_the_codes():
    page = (Path(__file__).resolve().parents[1] / "docs" / "robot.md").read_text()
    section = page.split("## Live on a robot")[1].split("\n## ")[0].split("\n### ")[0]
    rows = [line for line in section.splitlines() if line.startswith("| `/")]
    assert rows == [f"| `{t}` | `{ty}` | {way} | {what} |" for t, (ty, way, what) in LIVE_TOPICS.items()]


def test_a_silent_robot_is_lost_and_its_repro_bag_kept(tmp_path):
    """A rosbridge with no robot behind it: after --silence seconds without a message the run
    ends as lost, exit status 1, and leaves its (empty) repro bag."""
    bridge = Rosbridge().start()
    try:
        r = CliRunner().invoke(app, ["ros", "live", "--rosbridge", bridge.url, "--planner", "greedy", "--goal", "304",
                                     "--silence", "1", "--repro", str(tmp_path / "repro")])
    finally:
        bridge.stop()
    assert r.exit_code == 1 and "lost: no message from the robot for 1 s; 0.0 m along 0 poses" in " ".join(r.output.split())
    with Reader(tmp_path / "repro") as rd:
        assert rd.message_count == 0
    assert not list(tmp_path.glob(".repro*"))


def test_an_axis_heading_comes_back_from_its_quaternion_to_the_bit():
    """A grid path's headings (multiples of 45 degrees, as atan2 gives them) survive the pose's
    quaternion exactly, so that nsos's heading bins (edges on +-90 degrees) see what the simulator
    saw; other headings come back within 1e-15 rad."""
    m = Messages()
    for dx, dy in [(0.1, 0.0), (0.1, 0.1), (0.0, 0.1), (-0.1, 0.1), (-0.1, 0.0), (-0.1, -0.1), (0.0, -0.1), (0.1, -0.1)]:
        yaw = math.atan2(dy, dx)
        assert pose_of(m.pose_stamped(0, 1.0, 2.0, yaw)) == (1.0, 2.0, yaw)
    for yaw in (0.3, -2.0, 1.5707963):
        assert pose_of(m.pose_stamped(0, 1.0, 2.0, yaw))[2] == pytest.approx(yaw, abs=1e-15)


def test_a_language_model_on_a_robot_is_seated_as_in_a_batch_and_its_run_folder_verifies(robot, tmp_path, monkeypatch):
    """ros live with the llm planner (the scripted chat server of the tests, on loopback) seats it
    as a batch does: its transcript and cost columns are kept, the run's folder holds its bag,
    decisions record and run.json, and `semsearch verify` replays the bag from the record alone
    (the server gone); a record edited, or cut short, does not verify."""
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    bridge, make = robot
    make("452")
    folder = tmp_path / "live"
    with ChatServer(first_target) as srv:
        res = api.ros_live(bridge.url, f"llm[base_url={srv.base_url},model=scripted]", "452", out=folder, silence=20.0,
                           max_distance=12.0)
        calls = len(srv.requests)
    assert res.outcome == "budget" and len(res.decisions) > 3 and calls >= len(res.decisions)
    assert res.costs["llm_calls"] == calls and res.costs["tokens_in"] == 100 * calls and res.costs["tokens_out"] == 3 * calls
    assert sorted(p.name for p in folder.iterdir()) == ["bag", "decisions.json", "run.json", "transcripts.jsonl"]
    transcript = [json.loads(line) for line in (folder / "transcripts.jsonl").read_text().splitlines()]
    assert len(transcript) >= len(res.decisions) and all("452" in json.dumps(t) for t in transcript[:1])
    run = json.loads((folder / "run.json").read_text())
    assert run["format"] == "semsearch-live" and run["costs"] == res.costs and run["decisions"] == res.decisions
    record = json.loads((folder / "decisions.json").read_text())
    assert record["planner"].startswith("llm[") and record["goal"] == "452" and record["engine"] == 2
    assert res.repro == folder / "bag"
    r = CliRunner().invoke(app, ["verify", str(folder)])  # the server is gone: the record answers
    assert r.exit_code == 0, r.output
    assert "1 of 1 runs replayed from their decisions" in r.output
    # tampered: a choice moved to another cell, then the record cut short
    items = record["decisions"]
    k = next(i for i, item in enumerate(items) if isinstance(item, list))
    record["decisions"] = items[:k] + [[items[k][0] + 1, items[k][1]]] + items[k + 1:]
    (folder / "decisions.json").write_text(json.dumps(record))
    r = CliRunner().invoke(app, ["verify", str(folder)])
    assert r.exit_code == 1 and "does not replay: live run llm[" in r.output, r.output
    record["decisions"] = items[:-1]
    (folder / "decisions.json").write_text(json.dumps(record))
    r = CliRunner().invoke(app, ["verify", str(folder)])
    assert r.exit_code == 1 and "does not replay" in r.output, r.output
    record["decisions"], record["goal"] = items, "999"  # the record of another run
    (folder / "decisions.json").write_text(json.dumps(record))
    r = CliRunner().invoke(app, ["verify", str(folder)])
    assert r.exit_code == 1 and "records another run (its goal: 999)" in r.output, r.output


RUN = {"format": "semsearch-live", "version": 1, "decisions": [], "planner": "greedy", "goal": "304", "outcome": "found",
       "margin": 10, "scenario": None, "fingerprint": None, "max_distance": None}


@pytest.mark.parametrize("name,make,says", [
    ("run.json not JSON", lambda d: (d / "run.json").write_text("{"), ["run.json", "not a live run's run.json"]),
    ("run.json a list", lambda d: (d / "run.json").write_text("[1]"), ["run.json", "not a JSON object"]),
    ("run.json of another format", lambda d: (d / "run.json").write_text('{"format": "x"}'), ["run.json", "format"]),
    ("run.json without its goal", lambda d: (d / "run.json").write_text(json.dumps(
        {"format": "semsearch-live", "version": 1, "decisions": [], "planner": "greedy", "outcome": "found", "margin": 10})),
     ["run.json", "goal"]),
    ("the bag gone", lambda d: (d / "run.json").write_text(json.dumps(RUN)), ["bag", "is gone"]),
    ("its scenario a number", lambda d: (d / "run.json").write_text(json.dumps({**RUN, "scenario": 5})), ["run.json", "scenario"]),
    ("its decisions an object", lambda d: (d / "run.json").write_text(json.dumps({**RUN, "decisions": {}})),
     ["run.json", "decisions"]),
    ("a fingerprint and no scenario", lambda d: (d / "run.json").write_text(json.dumps({**RUN, "fingerprint": "ab"})),
     ["names no scenario", "--scenario"]),
    ("the run stopped: its bag alone", lambda d: (d / "bag").mkdir(), ["run.json", "stopped before it ended"]),
])
def test_a_live_folder_that_is_not_one_is_refused_in_one_paragraph(tmp_path, name, make, says):
    d = tmp_path / "live"
    d.mkdir()
    make(d)
    r = CliRunner().invoke(app, ["verify", str(d)])
    assert r.exception is None or isinstance(r.exception, SystemExit), r.output  # no traceback
    assert r.exit_code == 2 and all(w in " ".join(r.output.split()) for w in says), r.output


def test_ros_live_refuses_an_out_folder_that_exists(tmp_path):
    (tmp_path / "live").mkdir()
    r = CliRunner().invoke(app, ["ros", "live", "--rosbridge", "ws://127.0.0.1:9", "--planner", "greedy", "--goal", "304",
                                 "--out", str(tmp_path / "live")])
    assert r.exit_code == 2 and "--out" in r.output and "exists already" in r.output, r.output
