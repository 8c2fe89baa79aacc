"""Runs exported as ROS 2 bags (`semsearch export`), read back without ROS: rosbags for the
messages, the mcap library for the file (its chunks' checksums)."""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
mcap_reader = pytest.importorskip("mcap.reader", reason="the ros extra (mcap) is not installed")
from rosbags.rosbag2 import Reader  # noqa: E402
from rosbags.typesys import Stores, get_types_from_msg, get_typestore  # noqa: E402

from semsearch_cli.cli import app  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.ros2 import TOPICS  # noqa: E402
from semsearch_cli.ros2.bag import BagWriter, Messages  # noqa: E402
from semsearch_cli.runner import BatchOptions, Loaded, RunSpec, run_batch  # noqa: E402
from semsearch_cli.tasks import TASKS  # noqa: E402
from semsearch_cli.tasks.base import Observer  # noqa: E402
from semsearch_cli.tasks.doors import DoorFrame  # noqa: E402
from semsearch_cli.tasks.decisions import Replay  # noqa: E402
from semsearch_cli.runner.store import read_decisions  # noqa: E402
from semsearch_cli.world.buildings.numbered import generate_building  # noqa: E402

TS = get_typestore(Stores.ROS2_HUMBLE)
RUN = "greedy__goal452__ep0__seed0"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """The demo building, goal 452, greedy and nsos, one seed each, decisions recorded."""
    out = tmp_path_factory.mktemp("ros2")
    scenario = TASKS["doors"].example(out / "src", "greedy")
    L = Loaded.load(scenario)
    specs = [RunSpec(L.task.episodes[0], v, 0) for v in (Variant("greedy", ()), Variant("nsos", (("alpha", 0.9),)))]
    runs = run_batch(L, specs, out / "results", BatchOptions(workers=1, decisions=True))
    return out, L, runs, scenario


def messages(bag):
    """{topic: [(stamp ns, message)]} of a bag folder, decoded with the definitions the bag
    carries (a type outside rosbags' Humble store, map_msgs's, from the bag alone)."""
    out = {}
    with Reader(bag) as r:
        for c in r.connections:
            if c.msgtype not in TS.types:
                TS.register(get_types_from_msg(c.msgdef.data, c.msgtype))
        for c, t, raw in r.messages():
            out.setdefault(c.topic, []).append((t, TS.deserialize_cdr(raw, c.msgtype)))
    return out


class Final(Observer):
    """The frames of a run (the last one's belief is the run's last) and its reads."""

    steps = True

    def __init__(self):
        self.frames = []
        self.reads = []

    def see(self, event):
        if isinstance(event, DoorFrame):
            self.frames.append(event)
            self.reads += list(event.reads)


@pytest.mark.parametrize("fmt", ["mcap", "rosbag2"])
def test_a_run_exports_as_a_bag_that_reads_back_step_for_step(recorded, fmt):
    out, L, runs, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / fmt), "--format", fmt, "--run", RUN,
                                   "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    assert "1 bag(s) written" in res.output
    bag = out / fmt / RUN
    row = runs[runs["planner"] == "greedy"].iloc[0]
    got = messages(bag)
    assert set(got) == set(TOPICS)
    steps, decisions = int(row["steps"]), int(row["decisions"])
    events = [json.loads(m.data) for _, m in got["/semsearch/events"]]
    frames = [e for e in events if e["event"] == "frame"]
    assert len([e for e in events if e["event"] == "step"]) == steps + 1  # the start's step too
    plans = [e for e in events if e["event"] == "plan"]
    assert [p["plan"] for p in plans] == ["start", "end"] * (len(plans) // 2) and len(plans) >= 2 * decisions
    # every frame (one a step, more when turning on the spot) has its pose, /tf and scan; every decision its target and frontiers
    for topic in ("/semsearch/pose", "/tf", "/scan"):
        assert len(got[topic]) == len(frames) >= steps + 1
    stamps = [t for topic in got for t, _ in got[topic] if topic != "/semsearch/setup"]
    assert len(set(stamps)) == len(stamps)  # strictly ordered: reading by time gives the order of writing
    for topic in ("/semsearch/goal", "/explore/frontiers", "/semsearch/decision"):
        assert len(got[topic]) == decisions
    assert len(got["/map"]) == decisions + 2 and 2 <= len(got["/semsearch/path"]) <= decisions + 1
    # stamps: simulated time, 0.2 s a step (0.1 m at 0.5 m/s), then a microsecond a message
    stamps = [t for t, _ in got["/tf"]]
    assert stamps[0] == 1_000_000_000 and np.all(np.diff(stamps) > 0) and stamps[-1] - 200_000_000 * steps < 1_000_100_000
    # the same run, replayed here with an observer: its poses, reads and final map are the bag's
    fin = Final()
    ep = L.task.episodes[0]
    record = read_decisions(out / "results" / "decisions" / f"{RUN}.json")
    rerun = L.task.run(Variant("greedy", ()), ep, 0, observer=fin, seat=Replay(record))
    trail = [(e["x"], e["y"]) for e in events if e["event"] == "step"]
    poses = np.array([[m.pose.position.x, m.pose.position.y] for _, m in got["/semsearch/pose"]])
    assert np.array_equal(poses, [[f.x, f.y] for f in fin.frames])  # exact: float64 both ways
    assert np.array_equal(np.float32([[e["x"], e["y"]] for e in events if e["event"] == "step"]), rerun.path)  # rows keep float32
    path = np.array([[p.pose.position.x, p.pose.position.y] for p in got["/semsearch/path"][-1][1].poses])
    assert np.allclose(path, np.vstack([trail[::5], trail[-1:]]) if (len(trail) - 1) % 5 else trail[::5], atol=1e-5)  # every 0.5 m
    last = got["/semsearch/pose"][-1][1].pose.orientation
    assert math.isclose(2 * math.atan2(last.z, last.w), fin.frames[-1].heading, abs_tol=1e-9)
    grid = got["/map"][-1][1]
    b, fr = fin.frames[-1].belief, L.world.frame
    H, W = fr.height, fr.width
    assert (grid.info.height, grid.info.width) == (H, W) and math.isclose(grid.info.resolution, fr.res, rel_tol=1e-6)
    data = grid.data.reshape(H, W)[::-1]  # back to the simulator's rows (row 0 at the top)
    want = np.where(b.seen, np.where(b.free, 0, 100), -1)
    assert np.array_equal(data, want)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == (fr.origin_x, fr.origin_y)
    # the map updates, folded in order over an unknown grid, give the same map
    state = np.full((H, W), -1, np.int8)
    for _, u in got["/semsearch/map_updates"]:
        r0 = H - u.y - u.height
        state[r0:r0 + u.height, u.x:u.x + u.width] = u.data.reshape(u.height, u.width)[::-1]
    assert np.array_equal(state, want)
    # a detection per read, at the sign's position, with its label; the goal was read last
    det = [json.loads(m.data) for _, m in got["/semsearch/detections"]]
    assert len(det) == len(fin.reads) > 0
    s = L.world.signs
    for d, (i, label) in zip(det, fin.reads):
        assert d["label"] == label and (d["x"], d["y"], d["facing"]) == (float(s.x[i]), float(s.y[i]), float(s.facing[i]))
    assert det[-1]["label"] == 452
    # scans in m, +inf where a beam returned nothing, within the laser's range
    scan = got["/scan"][0][1]
    finite = scan.ranges[np.isfinite(scan.ranges)]
    assert scan.range_max == L.sc.laser.range and finite.size and finite.max() <= scan.range_max + 1e-4
    assert math.isclose(scan.angle_max - scan.angle_min, math.radians(L.sc.laser.fov), abs_tol=1e-6)  # float32 fields
    # the chosen target is among the frontiers of its decision, drawn larger
    for (_, goal), (_, fronts) in zip(got["/semsearch/goal"], got["/explore/frontiers"]):
        spheres = [m for m in fronts.markers if m.action == 0]
        big = [m for m in spheres if m.scale.x == 0.5]
        assert len(big) == 1 and math.isclose(big[0].pose.position.x, goal.pose.position.x, abs_tol=1e-9)


def test_the_mcap_file_checks_out_with_the_mcap_library(recorded):
    out, _, _, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / "all"), "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    bags = sorted(b for b in (out / "all").iterdir() if not b.name.startswith("."))  # not the folder's lock
    assert {b.name for b in bags} == {RUN, "nsos_alpha0.9__goal452__ep0__seed0"}
    for bag in bags:
        files = list(bag.glob("*.mcap"))
        assert len(files) == 1 and files[0].stem == bag.name
        with open(files[0], "rb") as fh:
            reader = mcap_reader.make_reader(fh, validate_crcs=True)
            n = sum(1 for _ in reader.iter_messages())
            summary = reader.get_summary()
        assert n == summary.statistics.message_count > 0
        assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
    again = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / "all"), "--scenario", str(scenario)])
    said = " ".join(again.output.split())
    assert again.exit_code == 0 and "0 bag(s) written" in said and "; 2 kept as they were (their bags were there already)" in said


def test_export_of_another_kind_of_search_says_so_and_writes_nothing(tmp_path):
    res = CliRunner().invoke(app, ["run", "office", "--seeds", "1", "--decisions", "--out", str(tmp_path / "r"), "--workers", "1",
                                   "--planner", "lsos", "--goal", "Static.mug@12"])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, ["export", str(tmp_path / "r"), "--out", str(tmp_path / "bags")])
    said = " ".join(res.output.split())
    assert res.exit_code == 2 and "field 'kind': is objects search: semsearch export writes door-search runs" in said, said
    assert "do not replay" not in said and not (tmp_path / "bags").exists()


def test_export_errors_name_the_flag_and_leave_no_bag(recorded, tmp_path):
    out, _, _, scenario = recorded
    cases = [(["--run", "greedy__goal452__ep0__seed9"], "did you mean 'greedy__goal452__ep0__seed0'"),
             (["--format", "bag"], "use one of mcap, rosbag2")]
    for extra, says in cases:
        res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(tmp_path / "x"), "--scenario", str(scenario),
                                       *extra])
        assert res.exit_code == 2 and says in " ".join(res.output.split()), res.output
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "runs.csv").write_text((out / "results" / "runs.csv").read_text())  # rows without their decisions
    res = CliRunner().invoke(app, ["export", str(bare), "--out", str(tmp_path / "y"), "--scenario", str(scenario)])
    assert res.exit_code == 2 and "no run of this folder has a decisions record" in " ".join(res.output.split())
    assert not [p for p in (tmp_path / "y").rglob("*") if not p.name.startswith(".")]  # nothing but the folder's lock
    # another scenario than the rows': the replay goes elsewhere, and no bag (nor a partial one) is left
    other = scenario.with_name("other.yaml")
    other.write_text(scenario.read_text() + "laser: {range: 4.0}\n")
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(tmp_path / "z"), "--scenario", str(other),
                                   "--run", RUN])
    assert res.exit_code == 2 and "made with another scenario" in " ".join(res.output.split()), res.output
    # a record edited after the run: checked as verify checks it, no bag (nor a partial one) left
    edited = tmp_path / "edited"
    shutil.copytree(out / "results", edited)
    f = edited / "decisions" / f"{RUN}.json"
    f.write_text(f.read_text().replace('"decisions":[[', '"decisions":[[1, 1], [', 1))  # a first choice the run never made
    res = CliRunner().invoke(app, ["export", str(edited), "--out", str(tmp_path / "z"), "--scenario", str(scenario)])
    said = " ".join(res.output.split())
    assert res.exit_code == 2 and "1 run(s) do not replay (1 other bag(s) written)" in said and RUN in said, res.output
    assert sorted(p.name for p in (tmp_path / "z").iterdir() if not p.name.startswith(".semsearch")) == [
        "nsos_alpha0.9__goal452__ep0__seed0"]


def decisions_of(bag):
    """[(step, target x, y)] of a bag's /semsearch/decision messages."""
    return [(d["step"], tuple(d["target"])) for d in (json.loads(m.data) for _, m in messages(bag).get("/semsearch/decision", []))]


def test_a_run_replayed_from_its_bag_makes_its_decisions_decision_for_decision(recorded):
    """The round trip: a run exported and replayed through `ros replay` with its own planner gives
    the run's decisions, step and target; another planner is asked at the same re-plans."""
    out, _, _, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / "trip"), "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    for name, label in ((RUN, "greedy"), ("nsos_alpha0.9__goal452__ep0__seed0", "nsos[alpha=0.9]")):
        bag = out / "trip" / name
        res = CliRunner().invoke(app, ["ros", "replay", str(bag), "--planner", label, "--out", str(out / "replayed" / name),
                                       "--scenario", str(scenario)])
        assert res.exit_code == 0, res.output
        want = decisions_of(bag)
        got = [(s, tuple(round(v, 2) for v in t)) for s, t in decisions_of(out / "replayed" / name)]
        assert len(want) > 5 and got == want
        assert "(the goal was read in the bag)" in " ".join(res.output.split())
    other = CliRunner().invoke(app, ["ros", "replay", str(out / "trip" / RUN), "--planner", "numbering", "--out",
                                     str(out / "replayed" / "numbering"), "--scenario", str(scenario)])
    assert other.exit_code == 0, other.output
    asked = decisions_of(out / "replayed" / "numbering")
    assert asked and all(0 <= s <= max(s for s, _ in decisions_of(out / "trip" / RUN)) + 1 for s, _ in asked)


def test_the_bearings_of_the_reads_go_into_the_bag_and_wall_numbers_replays_from_them(tmp_path):
    """wall_numbers places signs by the bearing of each read: an exported bag's frame events carry
    the bearings, and the run replayed from the bag makes its decisions decision for decision; a
    bag without them (an older semsearch's) replays with the bearings not known."""
    scenario = generate_building("single", "loop", 3, tmp_path / "b", spacing=2.5)
    L = Loaded.load(scenario)
    ep = next(e for e in L.task.episodes
              if L.task.run(Variant("wall_numbers", ()), e, 0).distance_m != L.task.run(Variant("greedy", ()), e, 0).distance_m)
    run_batch(L, [RunSpec(ep, Variant("wall_numbers", ()), 0)], tmp_path / "results", BatchOptions(workers=1, decisions=True))
    res = CliRunner().invoke(app, ["export", str(tmp_path / "results"), "--out", str(tmp_path / "trip"), "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    (bag,) = [p for p in (tmp_path / "trip").iterdir() if p.is_dir()]
    frames = [json.loads(m.data) for _, m in messages(bag)["/semsearch/events"]]
    frames = [f for f in frames if f.get("event") == "frame" and f["reads"]]
    assert frames and all(len(f["bearings"]) == len(f["reads"]) for f in frames)
    res = CliRunner().invoke(app, ["ros", "replay", str(bag), "--planner", "wall_numbers", "--out", str(tmp_path / "again"),
                                   "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    want = decisions_of(bag)
    got = [(s, tuple(round(v, 2) for v in t)) for s, t in decisions_of(tmp_path / "again")]
    assert len(want) > 5 and got == want


def test_ros_replay_refuses_a_bag_of_another_scenario_and_a_bag_it_cannot_replay(recorded, tmp_path):
    out, _, _, scenario = recorded
    CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / "trip2"), "--scenario", str(scenario), "--run", RUN])
    other = scenario.with_name("other2.yaml")
    other.write_text(scenario.read_text() + "laser: {range: 4.0}\n")
    res = CliRunner().invoke(app, ["ros", "replay", str(out / "trip2" / RUN), "--planner", "greedy", "--out", str(tmp_path / "a"),
                                   "--scenario", str(other)])
    assert res.exit_code == 2 and "recorded on another scenario" in " ".join(res.output.split()), res.output
    for extra, says in ((["--goal", "304"], "the bag records a search for 452"),):
        res = CliRunner().invoke(app, ["ros", "replay", str(out / "trip2" / RUN), "--planner", "greedy", "--out", str(tmp_path / "c"),
                                       "--scenario", str(scenario), *extra])
        assert res.exit_code == 2 and says in " ".join(res.output.split()), res.output
    mcap_file = next((out / "trip2" / RUN).glob("*.mcap"))
    res = CliRunner().invoke(app, ["ros", "replay", str(mcap_file), "--planner", "greedy", "--out", str(tmp_path / "d")])
    assert res.exit_code == 2 and "is a file: give the bag's folder" in " ".join(res.output.split()), res.output
    # a robot's own bag with a pose but no map
    m = Messages()
    w = BagWriter(tmp_path / "robot", "mcap", m)
    w.write("/semsearch/pose", 1_000_000_000, m.pose_stamped(1_000_000_000, 1.0, 2.0, 0.0))
    w.close()
    res = CliRunner().invoke(app, ["ros", "replay", str(tmp_path / "robot"), "--planner", "greedy", "--out", str(tmp_path / "b"),
                                   "--goal", "452"])
    assert res.exit_code == 2 and "a robot's bag needs /map" in " ".join(res.output.split()), res.output
    assert not any((tmp_path / n).exists() for n in "abcd")


def test_the_topics_page_lists_every_topic_as_the_code_writes_it():
    page = (Path(__file__).resolve().parents[1] / "docs" / "robot.md").read_text()
    section = page.split("## Topics and frames")[1].split("\n## ")[0]
    rows = [line for line in section.splitlines() if line.startswith("| `/")]
    assert rows == [f"| `{t}` | `{ty}` | {when} | {what} |" for t, (ty, when, what) in TOPICS.items()]


def test_a_robots_own_bag_replays_from_its_map_poses_and_detections(recorded, tmp_path):
    """A robot's bag: a SLAM map now and then, poses, detections, and nothing of semsearch's own
    (made here from an exported run's /map, /semsearch/pose and /semsearch/detections). The
    planner is asked every metre; its targets are free cells of the map it had."""
    out, L, _, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(tmp_path / "sim"), "--scenario", str(scenario),
                                   "--run", RUN])
    assert res.exit_code == 0, res.output
    m, robot = Messages(), tmp_path / "robot"
    w = BagWriter(robot, "mcap", m)
    with Reader(tmp_path / "sim" / RUN) as r:
        for c, t, raw in r.messages():
            if c.topic in ("/map", "/semsearch/pose", "/semsearch/detections"):
                w.write(c.topic, t, TS.deserialize_cdr(raw, c.msgtype))
    w.close()
    no_goal = CliRunner().invoke(app, ["ros", "replay", str(robot), "--planner", "greedy", "--out", str(tmp_path / "x")])
    assert no_goal.exit_code == 2 and "give the label to find, --goal" in " ".join(no_goal.output.split())
    res = CliRunner().invoke(app, ["ros", "replay", str(robot), "--planner", "greedy", "--goal", "452", "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    assert "(the goal was read in the bag)" in " ".join(res.output.split())
    got = messages(tmp_path / "out")
    targets = [(g.pose.position.x, g.pose.position.y) for _, g in got["/semsearch/goal"]]
    sim_decisions = len(decisions_of(tmp_path / "sim" / RUN))
    assert 5 <= len(targets) and abs(len(targets) - sim_decisions) <= sim_decisions  # about as many decisions as the run made
    maps = messages(tmp_path / "sim" / RUN)["/map"]
    fr = L.world.frame
    for (t, _), (x, y) in zip(got["/semsearch/goal"], targets):
        grid = [g for s, g in maps if s <= t][-1]  # the last map before the decision
        r, c = (int(v) for v in fr.to_index(x, y))
        assert grid.data.reshape(fr.height, fr.width)[::-1][r, c] == 0  # free
    # the same robot with its pose in /tf only: map -> odom (sent once) -> base_link (every pose)
    ox, oy, oyaw = 0.5, -0.25, 0.3
    tf_bag = tmp_path / "robot_tf"
    w = BagWriter(tf_bag, "mcap", m)
    first = True
    with Reader(tmp_path / "sim" / RUN) as r:
        for c, t, raw in r.messages():
            msg = TS.deserialize_cdr(raw, c.msgtype)
            if c.topic == "/semsearch/pose":
                x, y = msg.pose.position.x, msg.pose.position.y
                yaw = 2 * math.atan2(msg.pose.orientation.z, msg.pose.orientation.w)
                dx, dy = x - ox, y - oy  # the pose in odom: the inverse of map -> odom applied to it
                lx, ly = math.cos(oyaw) * dx + math.sin(oyaw) * dy, -math.sin(oyaw) * dx + math.cos(oyaw) * dy
                tf = m.tf(t, lx, ly, yaw - oyaw)
                tf.transforms[0].header.frame_id = "odom"
                if first:
                    root = m.tf(t - 1, ox, oy, oyaw)
                    root.transforms[0].child_frame_id = "odom"
                    w.write("/tf", t - 1, root)
                    first = False
                w.write("/tf", t, tf)
            elif c.topic in ("/map", "/semsearch/detections"):
                w.write(c.topic, t, msg)
    w.close()
    res = CliRunner().invoke(app, ["ros", "replay", str(tf_bag), "--planner", "greedy", "--goal", "452", "--out", str(tmp_path / "out_tf")])
    assert res.exit_code == 0, res.output
    via_tf = [(round(g.pose.position.x, 6), round(g.pose.position.y, 6)) for _, g in messages(tmp_path / "out_tf")["/semsearch/goal"]]
    assert via_tf == [(round(x, 6), round(y, 6)) for x, y in targets]  # the same targets, the poses composed to within rounding


def test_a_bag_names_its_engine_and_a_bag_of_another_engine_is_refused(recorded, tmp_path):
    """/semsearch/setup names the simulator engine; a bag of another engine is refused by `ros
    replay` before its scenario is looked for, naming the release that replays it (issue 54)."""
    from semsearch_cli.engine import ENGINE, release
    from semsearch_cli.ros2.replay import BagStream
    out, _, _, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(tmp_path / "bags"), "--scenario", str(scenario),
                                   "--run", RUN])
    assert res.exit_code == 0, res.output
    other = 2 if ENGINE == 1 else 1
    m = Messages()
    stream = BagStream(tmp_path / "bags" / RUN, m)
    w = BagWriter(tmp_path / "other", "mcap", Messages())
    item = stream.next()
    setup = json.loads(item[2].data)
    assert setup["engine"] == ENGINE
    w.write(item[0], item[1], w.msgs.string({**setup, "engine": other}))
    while (item := stream.next()) is not None:
        w.write(item[0], item[1], item[2])
    stream.close()
    w.close()
    res = CliRunner().invoke(app, ["ros", "replay", str(tmp_path / "other"), "--planner", "greedy", "--out", str(tmp_path / "a")])
    text = " ".join(res.output.split())
    assert res.exit_code == 2 and f"made by simulator engine {other}" in text and release(other) in text, res.output
    assert not (tmp_path / "a").exists()
