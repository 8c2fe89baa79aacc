"""Hostile inputs for the robot surfaces (issue 52): what a robot's stack, a damaged disk or a user
gives ``semsearch ros replay`` and ``semsearch ros live``, in the style of ``tests/hostile_release.py``.

Classes: ``robot messages`` (a robot's bag whose messages are well typed but hostile: a NaN pose,
a map of resolution 0 or claiming 100000 x 100000 cells, a stamp past ``Time``, a map that re-grids
or grows; each replays to its end, the messages it could not take counted and named), ``damaged
bags`` (chunks that do not decompress, a truncated or missing file, a setup that is not JSON or
lacks its fingerprint, events a replay cannot follow, a first map no grid can hold: each refused
with one paragraph naming the bag) and ``live`` (``ros live``'s flags: an address past port 65535
or half an IPv6 bracket, credentials in it, a margin of 1e6 m, no server listening: refused before
any connection is kept).

Each robot bag is a 6 m x 4 m walled room mapped at 0.1 m, a robot driving across it and reading
the goal's sign at the far wall; a hostile message is put in the middle of it, in both bag formats
(the MCAP ones run in CI, the SQLite 3 copies in ``benchmarks/hostile.py``). The other cases are
fast: each is refused before any work, or replays a small bag in a fraction of a second.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import yaml
from mcap.reader import make_reader as mcap_reader
from rosbags.rosbag2 import Reader
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.geometry import GridFrame
from semsearch_cli.ros2.bag import BagWriter, Messages
from semsearch_cli.ros2.robot import DETECTIONS, GOAL_STATUS, MAP, RESUME, goal_ended

from .hostile_inputs import demo_base
from .hostile_release import GOAL as DEMO_GOAL, ReleaseCase

CLASSES = ("robot messages", "damaged bags", "live")
GOAL = 148
H, W, RES = 40, 60, 0.1
POSE = "/semsearch/pose"
M = Messages()
T = M.T


def room(res: float = RES, h: int = H, w: int = W, ox: float = 0.0, oy: float = 0.0, t_ns: int = 1):
    states = np.full((h, w), 100, np.int8)
    states[1:-1, 1:-1] = 0
    return M.grid(t_ns, states, GridFrame(res, ox, oy, h, w))


def robot_messages(hostile: list) -> list:
    """A robot's messages in order: its map, then a pose every 0.1 m across the room (with the map
    again every metre), ``hostile`` (topic, message) in the middle, the goal's sign read at the
    end."""
    out = [(MAP, room())]
    for k in range(41):
        x = 1.0 + 0.1 * k
        out.append((POSE, M.pose_stamped(10 + k, x, 2.0, 0.0)))
        if k % 10 == 9:
            out.append((MAP, room()))
        if k == 20:
            out.extend(hostile)
    out.append((DETECTIONS, M.string({"label": GOAL, "x": 5.9, "y": 2.0, "facing": math.pi})))
    return out


def write_bag(path: Path, fmt: str, messages: list) -> Path:
    w = BagWriter(path, fmt, M)
    for i, (topic, msg) in enumerate(messages):
        w.write(topic, 1_000_000_000 + i * 1_000_000, msg)
    w.close()
    return path


def pose(x=3.0, y=2.0, yaw=0.0, t=30):
    return M.pose_stamped(t, x, y, yaw)


def _quat(msg, x, y, z, w):
    q = msg.pose.orientation
    q.x, q.y, q.z, q.w = x, y, z, w
    return msg


def _info(msg, **kw):
    for k, v in kw.items():
        if k in ("x", "y"):
            setattr(msg.info.origin.position, k, v)
        elif k == "rotated":
            msg.info.origin.orientation.z = v
        else:
            setattr(msg.info, k, v)
    return msg


def _stamp(msg, sec=None, nanosec=None):
    if sec is not None:
        msg.header.stamp.sec = sec
    if nanosec is not None:
        msg.header.stamp.nanosec = nanosec
    return msg


def _cells(value):
    g = room()
    g.data[W * 5 + 5: W * 5 + 15] = value
    return g


def _status_list(n):
    msg = goal_ended(M, 1, 4)
    msg.status_list = msg.status_list * n
    return msg


def hostile_messages() -> list:
    """(name, the hostile messages, what the output must say) of the robot-messages class: each
    replays to the end (found), what it dropped named."""
    s = T["std_msgs/msg/String"]
    tf_nan = M.tf(30, math.nan, 0.0, 0.0)
    return [
        ("a NaN pose", [(POSE, pose(x=math.nan))], ["1 /semsearch/pose (a pose at (nan, 2)"]),
        ("an infinite pose", [(POSE, pose(y=math.inf))], ["(a pose at (3, inf)"]),
        ("a pose 10^12 m away", [(POSE, pose(x=1e12))], ["not within 100000 m"]),
        ("a pose whose quaternion is all zeros", [(POSE, _quat(pose(), 0.0, 0.0, 0.0, 0.0))], ["is not a rotation"]),
        ("a pose whose quaternion is NaN", [(POSE, _quat(pose(), math.nan, 0.0, 0.0, 1.0))], ["is not a rotation"]),
        ("a pose stamped 2e9 ns past its second", [(POSE, _stamp(pose(), nanosec=2_000_000_000))], ["not a builtin_interfaces/Time"]),
        ("three NaN poses in a row", [(POSE, pose(x=math.nan))] * 3, ["3 /semsearch/pose"]),
        ("a pose far off the grid and back", [(POSE, pose(x=500.0)), (POSE, pose(x=3.05))], ["the goal was read"]),
        ("poses whose stamps go backwards", [(POSE, pose(x=3.01, t=5)), (POSE, pose(x=3.02, t=1))], ["the goal was read"]),
        ("a pose of the smallest int32 stamp", [(POSE, _stamp(pose(x=3.01), sec=-(2**31)))], ["the goal was read"]),
        ("a map of resolution 0", [(MAP, _info(room(), resolution=0.0))], ["(a map at 0 m per cell"]),
        ("a map of resolution NaN", [(MAP, _info(room(), resolution=math.nan))], ["(a map at nan m per cell"]),
        ("a map of negative resolution", [(MAP, _info(room(), resolution=-0.1))], ["(a map at -0.1 m per cell"]),
        ("a map of 1e-9 m per cell", [(MAP, _info(room(), resolution=1e-9))], ["from 0.001 to 10 m are read"]),
        ("a map of 100 m per cell", [(MAP, _info(room(), resolution=100.0))], ["from 0.001 to 10 m are read"]),
        ("a map claiming 100000 x 100000 cells", [(MAP, _info(room(), width=100_000, height=100_000))],
         ["a map of 100,000 x 100,000 cells (at most 25,000,000)"]),
        ("a map one column wider than its data", [(MAP, _info(room(), width=W + 1))], [f"holding {H * W} values"]),
        ("a map whose origin is NaN", [(MAP, _info(room(), x=math.nan))], ["whose origin (nan, 0)"]),
        ("a map whose origin is 10^9 m away", [(MAP, _info(room(), y=1e9))], ["is not within 100000 m"]),
        ("a map rotated in its frame", [(MAP, _info(room(), rotated=0.3))], ["rotated in its frame"]),
        ("a map at 0.2 m (re-gridded)", [(MAP, room(res=0.2, h=20, w=30))], ["1 maps re-gridded to 0.1 m"]),
        ("a map at 0.05 m (re-gridded)", [(MAP, room(res=0.05, h=80, w=120))], ["1 maps re-gridded to 0.1 m"]),
        ("map cells of -56 (outside -1..100)", [(MAP, _cells(-56))], ["10 map cells outside -1..100 taken as unknown"]),
        ("a map grown past the grid's margin", [(MAP, room(h=H + 400, w=W))], ["the goal was read"]),
        ("an empty map (0 x 0)", [(MAP, room(h=0, w=0))], ["the goal was read"]),
        ("a detection that is not JSON", [(DETECTIONS, s(data="148 at the door"))], ["(not a detection"]),
        ("a detection of 5000 characters", [(DETECTIONS, s(data="x" * 5000))], ["(a detection of 5,000 characters"]),
        ("a detection that is a JSON list", [(DETECTIONS, s(data="[148]"))], ["(not a detection"]),
        ("a detection whose label is null", [(DETECTIONS, s(data='{"label": null}'))], ["(not a detection"]),
        ("a detection nested 2000 deep", [(DETECTIONS, s(data="[" * 2000 + "]" * 2000))], ["(not a detection"]),
        ("a detection of another label", [(DETECTIONS, M.string({"label": 7}))], ["the goal was read"]),
        ("a goal status array of 2000 goals", [(GOAL_STATUS, _status_list(2000))], ["(a status array of 2,000 goals"]),
        ("a goal status stamped past Time", [(GOAL_STATUS, _stamp_status())], ["not a builtin_interfaces/Time"]),
        ("a resume False then True", [(RESUME, T["std_msgs/msg/Bool"](data=False)), (RESUME, T["std_msgs/msg/Bool"](data=True))],
         ["the goal was read"]),
        ("a /tf of NaN beside the pose topic", [("/tf", tf_nan)], ["the goal was read"]),
    ]


def _stamp_status():
    msg = goal_ended(M, 2, 4)
    msg.status_list[0].goal_info.stamp.nanosec = 3_000_000_000
    return msg


def _rewrite(src: Path, dst: Path, fmt: str, change) -> Path:
    """A copy of bag ``src`` with each (topic, stamp, message) passed through ``change`` (None:
    left out)."""
    w = BagWriter(dst, fmt, M)
    with Reader(src) as r:
        for c, t, raw in r.messages():
            got = change(c.topic, M.ts.deserialize_cdr(raw, c.msgtype))
            if got is not None:
                w.write(c.topic, t, got)
    w.close()
    return dst


def _storage_file(bag: Path) -> Path:
    return next(p for p in bag.iterdir() if p.suffix in (".mcap", ".db3"))


def build_cases(root: Path) -> list[ReleaseCase]:
    """Every case of the robot catalogue, its bags written under ``root`` (one run recorded and
    exported for the damaged export bags, ~3 s)."""
    root.mkdir(parents=True, exist_ok=True)
    cases: list[ReleaseCase] = []

    def add(category, name, args, expect="refuse", says=(), fast=True):
        assert category in CLASSES, category
        cases.append(ReleaseCase(category, name, [str(a) for a in args], expect, False, tuple(says), fast=fast))

    def out_dir() -> Path:
        return root / "out" / f"case{len(cases)}"

    replay = ["ros", "replay"]

    # -- robot messages: each replays to the end, what it dropped said --------------------------------
    for fmt in ("mcap", "rosbag2"):
        for i, (name, hostile, says) in enumerate(hostile_messages()):
            bag = write_bag(root / "robot" / fmt / f"bag{i}", fmt, robot_messages(hostile))
            add("robot messages", f"{name} ({fmt})", [*replay, bag, "--planner", "greedy", "--goal", GOAL, "--out", out_dir()],
                "accept", ["the goal was read in the bag", *says], fast=fmt == "mcap")  # SQLite's copies: the benchmark's

    # -- damaged bags ------------------------------------------------------------------------------
    good = write_bag(root / "damaged" / "good", "mcap", robot_messages([]))
    good_db = write_bag(root / "damaged" / "good_db", "rosbag2", robot_messages([]))

    def damaged(name: str, make, says, src: Path = good, expect="refuse", extra=()):
        bag = root / "damaged" / name.replace(" ", "_").replace("/", "_")[:50]
        shutil.copytree(src, bag)
        make(bag)
        add("damaged bags", name, [*replay, bag, "--planner", "greedy", "--goal", GOAL, "--out", out_dir(), *extra], expect,
            [str(bag), *says])

    def flip(offset_frac: float, n: int = 64):
        def make(bag):
            f = _storage_file(bag)
            data = bytearray(f.read_bytes())
            at = int(len(data) * offset_frac)
            data[at:at + n] = bytes(b ^ 0xA5 for b in data[at:at + n])
            f.write_bytes(bytes(data))
        return make

    def flip_chunk(bag):
        """Bytes in the middle of the first chunk's compressed records: zstd cannot decompress it."""
        f = _storage_file(bag)
        with f.open("rb") as fh:
            chunk = mcap_reader(fh).get_summary().chunk_indexes[0]
        data = bytearray(f.read_bytes())
        at = chunk.chunk_start_offset + chunk.chunk_length // 2
        data[at:at + 32] = bytes(b ^ 0xA5 for b in data[at:at + 32])
        f.write_bytes(bytes(data))

    def truncate(frac: float):
        def make(bag):
            f = _storage_file(bag)
            f.write_bytes(f.read_bytes()[:int(f.stat().st_size * frac)])
        return make

    damaged("an MCAP chunk's bytes flipped (it does not decompress)", flip_chunk, ["damaged"])
    damaged("an MCAP file's head flipped", flip(0.0, 16), ["is not a ROS 2 bag folder rosbags can read"])
    damaged("an MCAP file cut in half", truncate(0.5), [])
    damaged("an MCAP file of 0 bytes", truncate(0.0), ["rosbags can read"])
    damaged("metadata.yaml removed", lambda b: (b / "metadata.yaml").unlink(), ["rosbags can read"])
    damaged("metadata.yaml not YAML", lambda b: (b / "metadata.yaml").write_text("{{{ not: yaml"), ["rosbags can read"])
    damaged("metadata.yaml of another version", lambda b: (b / "metadata.yaml").write_text(
        (b / "metadata.yaml").read_text().replace("version: ", "version: 99 #")), ["rosbags can read"])
    damaged("the storage file removed", lambda b: _storage_file(b).unlink(), ["rosbags can read"])
    damaged("a SQLite bag's file cut in half", truncate(0.5), [], src=good_db)
    damaged("a SQLite bag's pages flipped", flip(0.6, 256), [], src=good_db, expect="either")  # refused, or free pages hit
    empty = root / "damaged" / "empty"
    empty.mkdir(parents=True, exist_ok=True)
    add("damaged bags", "an empty folder", [*replay, empty, "--planner", "greedy", "--goal", GOAL, "--out", out_dir()],
        says=[str(empty), "rosbags can read"])

    def robot_bag(name: str, messages: list, says, extra=(), expect="refuse"):
        bag = write_bag(root / "damaged" / name.replace(" ", "_")[:50], "mcap", messages)
        add("damaged bags", name, [*replay, bag, "--planner", "greedy", "--goal", GOAL, "--out", out_dir(), *extra], expect,
            [str(bag), *says])

    walk = [(t, m) for t, m in robot_messages([]) if t != MAP]  # the poses and the detection, no map
    robot_bag("a robot bag whose only map is at 0 m per cell", [(MAP, _info(room(), resolution=0.0)), *walk],
              ["/map", "no map of the bag can be read (the first: a map at 0 m per cell"])
    robot_bag("a robot bag whose only map claims 100000 x 100000 cells", [(MAP, _info(room(), width=100_000, height=100_000)), *walk],
              ["/map", "100,000 x 100,000 cells"])
    robot_bag("a robot bag whose first map is NaN, the next good", [(MAP, _info(room(), resolution=math.nan)), *robot_messages([])],
              ["the goal was read in the bag"], expect="accept")
    robot_bag("a robot bag with no map", walk, ["/map", "needs /map"])
    robot_bag("a robot bag with a map and no pose", [(MAP, room())], ["needs /map"])
    for margin, says in (("1e6", ["--margin", "1e+06 m"]), ("-1", ["--margin"]), ("nan", ["--margin"]), ("inf", ["--margin"])):
        add("damaged bags", f"--margin {margin}", [*replay, good, "--planner", "greedy", "--goal", GOAL, "--out", out_dir(),
                                                   "--margin", margin], says=says)
    add("damaged bags", "--margin 900 on a 0.1 m map (past 25,000,000 cells)",
        [*replay, good, "--planner", "greedy", "--goal", GOAL, "--out", out_dir(), "--margin", "900"],
        says=["/map", "give a smaller --margin"])
    add("damaged bags", "--out exists", [*replay, good, "--planner", "greedy", "--goal", GOAL, "--out", good], says=["exists already"])
    add("damaged bags", "the bag is a file", [*replay, _storage_file(good), "--planner", "greedy", "--goal", GOAL, "--out", out_dir()],
        says=["is a file"])

    # an export bag's setup and events, edited (a real run recorded and exported once)
    base, _ = demo_base(root)
    exp = root / "export"
    if not (exp / "bags").is_dir():
        scen = exp / "scenario.yaml"
        exp.mkdir(parents=True, exist_ok=True)
        scen.write_text(yaml.safe_dump({**base, "goals": [DEMO_GOAL]}, sort_keys=False))
        r = CliRunner().invoke(app, ["run", str(scen), "--seeds", "1", "--workers", "1", "--decisions", "--out", str(exp / "results")])
        assert r.exit_code == 0, r.output
        r = CliRunner().invoke(app, ["export", str(exp / "results"), "--out", str(exp / "bags"), "--scenario", str(scen)])
        assert r.exit_code == 0, r.output
    scen = exp / "scenario.yaml"
    exported = next(p for p in sorted((exp / "bags").iterdir()) if p.is_dir())

    def export_case(name: str, change, says, expect="refuse"):
        bag = _rewrite(exported, root / "damaged" / ("export_" + name.replace(" ", "_")[:40]), "mcap", change)
        add("damaged bags", f"export bag: {name}", [*replay, bag, "--planner", "greedy", "--scenario", scen, "--out", out_dir()],
            expect, [str(bag), *says])

    def setup(edit):
        def change(topic, msg):
            if topic == "/semsearch/setup":
                return M.T["std_msgs/msg/String"](data=edit(json.loads(msg.data)))
            return msg
        return change

    export_case("setup not JSON", setup(lambda d: "{not json"), ["/semsearch/setup", "not a JSON object"])
    export_case("setup a JSON list", setup(lambda d: json.dumps([d])), ["/semsearch/setup", "not a JSON object"])
    export_case("setup without its fingerprint", setup(lambda d: json.dumps({k: v for k, v in d.items() if k != "fingerprint"})),
                ["/semsearch/setup.fingerprint"])
    export_case("setup's fingerprint a number", setup(lambda d: json.dumps({**d, "fingerprint": 7})), ["/semsearch/setup.fingerprint"])
    export_case("setup's rng_inc text", setup(lambda d: json.dumps({**d, "rng_inc": "x"})), ["/semsearch/setup.rng_inc"])
    export_case("setup's rng_inc negative", setup(lambda d: json.dumps({**d, "rng_inc": -1})), ["/semsearch/setup.rng_inc"])
    export_case("setup's goal null", setup(lambda d: json.dumps({**d, "goal": None})), ["/semsearch/setup.goal"])
    export_case("setup of another scenario", setup(lambda d: json.dumps({**d, "fingerprint": "0" * 16})), ["recorded on another scenario"])
    export_case("setup left out", lambda t, m: None if t == "/semsearch/setup" else m, ["is not the bag's first message"])

    def events(edit):
        seen = [0]

        def change(topic, msg):
            if topic == "/semsearch/events":
                seen[0] += 1
                if seen[0] == 5:
                    return M.T["std_msgs/msg/String"](data=edit(msg.data))
            return msg
        return change

    export_case("an event not JSON", events(lambda t: t[:-3]), ["stopped"])
    export_case("an event without its kind", events(lambda t: json.dumps({k: v for k, v in json.loads(t).items() if k != "event"})),
                ["stopped"])
    export_case("an event a JSON list", events(lambda t: "[1, 2]"), ["stopped"])

    def update(topic, msg):
        if topic == "/semsearch/map_updates":
            msg.x = 10**6
        return msg
    export_case("map updates outside the grid", update, ["stopped", "does not fit"])

    # -- live: ros live's flags -------------------------------------------------------------------
    live = ["ros", "live", "--planner", "greedy", "--goal", GOAL]
    for url, says in (("ws://127.0.0.1:99999", ["Port out of range"]), ("ws://[::1", ["Invalid IPv6 URL"]),
                      ("http://127.0.0.1:9090", ["not a WebSocket address"]), ("127.0.0.1:9090", ["not a WebSocket address"]),
                      ("ws://user:s3cret@127.0.0.1:9090", ["no credentials"]), ("ws://127.0.0.1:0", ["port 0"]),
                      ("", ["not a WebSocket address"]), ("ws://", ["not a WebSocket address"]),
                      ("ws://127.0.0.1:1", ["no rosbridge answers at ws://127.0.0.1:1"])):
        add("live", f"--rosbridge {url!r}", [*live, "--rosbridge", url, "--repro", out_dir()], says=["--rosbridge", *says])
    ok = "ws://127.0.0.1:1"
    for flag, value in (("--margin", "1e6"), ("--margin", "-1"), ("--margin", "nan"), ("--silence", "0"), ("--silence", "nan"),
                        ("--silence", "inf"), ("--max-distance", "0"), ("--max-distance", "nan")):
        add("live", f"{flag} {value}", [*live, "--rosbridge", ok, flag, value, "--repro", out_dir()], says=[flag])
    add("live", "--goal empty", ["ros", "live", "--planner", "greedy", "--goal", "", "--rosbridge", ok], says=["--goal"])
    add("live", "--planner unknown", ["ros", "live", "--planner", "greedyy", "--goal", GOAL, "--rosbridge", ok], says=["greedy"])
    add("live", "--repro exists", [*live, "--rosbridge", ok, "--repro", good], says=["--repro", "exists already"])
    return cases
