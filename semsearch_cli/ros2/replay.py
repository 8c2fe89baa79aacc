"""A door planner run over a recorded bag (``semsearch ros replay``).

The bag's robot moves as it moved; the planner under test is asked at each of the bag's re-plans
where it would go, and its answers are written to a new bag (``/semsearch/goal``,
``/explore/frontiers``, ``/semsearch/decision``). Its belief is built from the bag alone:

- a bag that ``semsearch export`` wrote carries ``/semsearch/events`` (every frame, step and
  re-plan, in order) and ``/semsearch/map_updates`` (each frame's changed cells). The replay
  folds them in as the simulator did and re-plans where the simulator re-planned, with the
  run's generator state, so that the run's own planner makes the run's decisions, decision for
  decision;
- a frame sensed by a re-plan (turning on the spot) is taken from the bag when the replayed
  re-plan senses; frames a re-plan of another planner does not ask for are folded in after it;
- a robot's own bag (no events) needs a map (``/map``, nav_msgs/OccupancyGrid, as a SLAM node
  publishes it: free below 20, occupied from 65, as map_saver's thresholds), a pose
  (:data:`POSE_TOPICS`, PoseStamped or PoseWithCovarianceStamped in the map's frame; else /tf
  and /tf_static composed from map to :data:`BASE_FRAMES`, in the plane) and the
  sign detections (``/semsearch/detections``, JSON ``{"label", ...}``, read from the robot's pose
  at that moment). The belief's grid covers every map the bag holds; each pose is a frame and a
  step; a re-plan comes at the first pose that has a map, after every ``replan_every`` metres
  travelled, and when a sign is read ``min_reads`` times (for planners that re-plan on signs), as
  the simulator's periodic policy; the goal's label is ``--goal``.
"""

from __future__ import annotations

import json
import math
import shutil
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ..belief import DoorBelief
from ..config import BeliefSpec, DoorCameraSpec, NavigationSpec, RobotSpec
from ..config.base import sign_label
from ..geometry import GridFrame
from ..errors import BudgetSpent, PlannerError, ScenarioError
from ..planners import Variant
from ..runner.specs import Loaded
from ..tasks.base import Observer, RobotState
from ..tasks.decisions import DecisionPoint, set_rng
from ..tasks.doors import DoorDecision, DoorSearch, DoorTask
from .bag import BagWriter, Messages, drop_bag, rosbag2

POSE_TOPICS = ("/semsearch/pose", "/amcl_pose", "/pose")  # a robot bag's pose: the first of these it holds, else /tf
BASE_FRAMES = ("base_link", "base_footprint")  # the robot's frame in /tf, the first that reaches map
FREE_BELOW = 20  # OccupancyGrid values under it are free (map_saver's 0.196); from it, seen and not free


class BagStream:
    """A bag's messages in stamp order (of the topics ``only`` when given), decoded, with one
    message of look-ahead."""

    def __init__(self, path: Path, messages: Messages, only: tuple = ()):
        self.path, self.m = Path(path), messages
        try:
            self.reader = rosbag2.Reader(self.path)
            self.reader.open()
        except Exception as exc:  # noqa: BLE001  not a bag rosbags reads: named, never a traceback
            raise ScenarioError(str(path), "", f"is not a ROS 2 bag folder rosbags can read ({type(exc).__name__}: {exc})") from None
        self.topics = {c.topic for c in self.reader.connections}
        conns = [c for c in self.reader.connections if c.topic in only] if only else None  # only these topics decoded
        self._it = self.reader.messages(connections=conns) if conns is not None else self.reader.messages()
        self._ahead: deque = deque()

    def _decode(self, item):
        conn, t, raw = item
        return conn.topic, t, self.m.ts.deserialize_cdr(raw, conn.msgtype)

    def peek(self):
        if not self._ahead:
            nxt = next(self._it, None)
            if nxt is None:
                return None
            self._ahead.append(self._decode(nxt))
        return self._ahead[0]

    def next(self):
        item = self.peek()
        if item is not None:
            self._ahead.popleft()
        return item

    def close(self) -> None:
        self.reader.close()


def apply_update(belief, msg) -> None:
    """Fold a map_msgs/OccupancyGridUpdate of /map into the belief (ROS rows to the simulator's);
    a ValueError when it does not lie inside the grid."""
    h, w = int(msg.height), int(msg.width)
    H, W = belief.frame.height, belief.frame.width
    x, y = int(msg.x), int(msg.y)
    if h < 1 or w < 1 or x < 0 or y < 0 or x + w > W or y + h > H or len(msg.data) != h * w:
        raise ValueError(f"a map update of {w} x {h} cells at ({x}, {y}) does not fit the {W} x {H} grid")
    states = np.asarray(msg.data, np.int8).reshape(h, w)[::-1]
    belief.fold_grid(H - y - h, x, states >= 0, states == 0)


class ReplaySearch(DoorSearch):
    """The door search of a bag: sensing is the bag's frames, taken in order (:meth:`sense` is
    called by a re-plan that turns on the spot; :meth:`fold` by the replay for the rest)."""

    def __init__(self, task, planner, goal, rng, observer, stream: BagStream):
        super().__init__(task, planner, goal, rng, observer)
        self.stream = stream
        self.found = False

    def fold(self, st: RobotState, ev: dict) -> tuple[bool, bool]:
        """One frame event: the pose, the camera's view, the labels read (the map update that
        came before it is folded in already)."""
        b, fr = st.belief, self.task.world.frame
        st.x, st.y, st.heading, st.steps = float(ev["x"]), float(ev["y"]), float(ev["heading"]), int(ev["step"])
        v, u, r, c = fr.point_to_cell(st.x, st.y)
        b.views.append((v, u, st.heading))
        event = False
        for label in ev.get("reads", []):
            if b.reads.add(sign_label(label), r * fr.width + c, st.x, st.y, st.heading) == b.spec.min_reads:
                event = True
        found = bool(ev.get("found", False))  # the goal's own sign read (a misread of another as the goal is not)
        if "rng" in ev:  # sensed inside a re-plan: the generator as the sensing left it
            set_rng(self.rng, ev["rng"])
        self.found = self.found or found
        return found, event

    def sense(self, st: RobotState) -> tuple[bool, bool]:
        """A frame sensed inside a re-plan: the bag's next one, if the bag's re-plan sensed it (a
        robot's bag has none: a re-plan that would turn on the spot sees nothing new)."""
        if "/semsearch/events" not in self.stream.topics:
            return False, False
        while True:
            item = self.stream.peek()
            if item is None:
                return False, False
            topic, _, msg = item
            if topic == "/semsearch/events":
                ev = json.loads(msg.data)
                if ev["event"] == "frame":
                    self.stream.next()
                    return self.fold(st, ev)
                if ev["event"] == "plan" or ev["event"] == "step":  # the bag's re-plan sensed no more
                    return False, False
            elif topic == "/semsearch/map_updates":
                apply_update(st.belief, msg)
            self.stream.next()


class GoalWriter(Observer):
    """The replayed planner's decisions into the output bag, stamped at the input's time."""

    def __init__(self, bag: BagWriter, frame):
        self.bag, self.m, self.frame = bag, bag.msgs, frame
        self.t = 0  # the input's stamp at the re-plan
        self.last = -1  # the last stamp written
        self.rows: list[dict] = []

    def see(self, event) -> None:
        if not isinstance(event, DoorDecision):
            return
        row = {"step": int(event.step), "target_cell": [int(event.decision.row), int(event.decision.col)],
               "target": [float(v) for v in event.target_xy]}
        self.rows.append(row)
        fronts, goal = self.m.frontiers(self.t, self.frame, event.candidates, event.decision, event.target_xy)
        for topic, msg in (("/explore/frontiers", fronts), ("/semsearch/goal", goal), ("/semsearch/decision", self.m.string(row))):
            self.last = max(self.t, self.last + 1)  # after the input's moment, and after every message before
            self.bag.write(topic, self.last, msg)


@dataclass
class Replayed:
    """What a replay gave: the output bag folder, the decisions [{step, target_cell, target}],
    and whether the goal's sign was read in the bag."""

    folder: Path
    decisions: list
    found: bool


def replay_bag(loaded: Loaded | None, bag: Path, variant: Variant, out: Path, fmt: str = "mcap", goal=None) -> Replayed:
    """Run door planner ``variant`` over ``bag`` and write its decisions to the new bag folder
    ``out`` (which must not exist). A bag ``semsearch export`` wrote replays on ``loaded``, the
    scenario it was recorded on; a robot's own bag needs ``goal`` (the label to find) and takes
    the belief's, robot's and navigation's settings from ``loaded`` when given, else their
    defaults."""
    if loaded is not None and not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind}: a bag replays door planners only")
    msgs = Messages()
    stream = BagStream(bag, msgs)
    try:
        if "/semsearch/events" in stream.topics:
            setup = _setup(stream, bag)
            if loaded is None or setup["fingerprint"] != loaded.fingerprint:
                have = f"{loaded.path.name}'s is {loaded.fingerprint}" if loaded is not None else "no scenario given"
                raise ScenarioError(str(bag), "/semsearch/setup", f"the bag was recorded on another scenario (fingerprint "
                                    f"{setup['fingerprint']}, {have}): give the one it was recorded on, --scenario")
            if goal is not None and sign_label(goal) != sign_label(setup["goal"]):
                raise ScenarioError(str(bag), "--goal", f"{goal!r}: the bag records a search for {setup['goal']!r}, and its "
                                    "re-plans are that search's; leave --goal out for a bag of `semsearch export`")
            task, goal, frame = loaded.task, sign_label(setup["goal"]), loaded.world.frame
            run, rng_inc = _run, setup["rng_inc"]
        else:
            if goal is None:
                raise ScenarioError(str(bag), "--goal", "a robot's own bag names no goal: give the label to find, --goal")
            frame = _robot_frame(bag, msgs)
            task, goal, run, rng_inc = RobotTask(frame, loaded.sc if loaded is not None else None), sign_label(goal), _run_robot, None
        if out.exists():
            raise ScenarioError(str(out), "", "exists already: give a new folder for the replay's bag")
        work = out.with_name(f".{out.name}.partial")  # written here, then moved into place whole
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        writer = None
        try:
            writer = BagWriter(work / out.name, fmt, msgs)
            found, rows = run(task, variant, goal, stream, writer, frame, rng_inc)
            writer.close()
        except BaseException as exc:
            drop_bag(writer, work)
            if isinstance(exc, ScenarioError):
                raise
            if isinstance(exc, (PlannerError, BudgetSpent, KeyError, ValueError, TypeError)):
                raise ScenarioError(str(bag), "", f"the replay of {variant.label} stopped: {type(exc).__name__}: "
                                    f"{str(exc)[:160]}") from None
            raise
        (work / out.name).rename(out)
        work.rmdir()
    finally:
        stream.close()
    return Replayed(out, rows, found)


def recorded_scenario(bag: Path) -> str | None:
    """The scenario file's name (without .yaml) a bag of ``semsearch export`` was recorded on, or
    None when the bag does not say."""
    stream = BagStream(bag, Messages())
    try:
        if "/semsearch/setup" not in stream.topics:
            return None
        item = stream.peek()
        if item is None or item[0] != "/semsearch/setup":
            return None
        return json.loads(item[2].data).get("file")
    except (ValueError, KeyError, AttributeError):  # a setup that is not ours to read
        return None
    finally:
        stream.close()


def _setup(stream: BagStream, bag: Path) -> dict:
    item = stream.peek()
    if item is None or item[0] != "/semsearch/setup":
        raise ScenarioError(str(bag), "/semsearch/setup", "is not the bag's first message: not a bag `semsearch export` wrote")
    stream.next()
    return json.loads(item[2].data)


def _run(task, variant, goal, stream: BagStream, writer: BagWriter, frame, rng_inc: int) -> tuple[bool, list]:
    planner = variant.build()
    out = GoalWriter(writer, frame)
    st = RobotState(0.0, 0.0, 0.0, belief=task.new_belief())
    rng = np.random.default_rng(0)
    state = rng.bit_generator.state
    state["state"]["inc"] = int(rng_inc)  # the run's: the events' states (rng_word) keep it
    rng.bit_generator.state = state
    search = ReplaySearch(task, planner, goal, rng, out, stream)
    while (item := stream.next()) is not None:
        out.t = item[1]
        ev = _fold(search, st, item)
        if ev is None:
            continue
        if ev["event"] == "step":
            st.distance = float(ev["distance"])
            search.update(st)
        elif ev["event"] == "plan" and ev.get("plan") == "start":
            set_rng(rng, ev["rng"])
            _plan(search, st)
            while (item := stream.next()) is not None:  # what the bag's re-plan sensed and this one did not ask for
                ev = _fold(search, st, item)
                if ev is not None and ev["event"] == "plan":
                    break
    return search.found, out.rows


def _fold(search: ReplaySearch, st: RobotState, item) -> dict | None:
    """Fold in a message of the bag (a map update, a frame); returns its event when it is one."""
    topic, _, msg = item
    if topic == "/semsearch/map_updates":
        apply_update(st.belief, msg)
    elif topic == "/semsearch/events":
        ev = json.loads(msg.data)
        if ev["event"] == "frame":
            search.fold(st, ev)
        return ev
    return None


def _plan(search: ReplaySearch, st: RobotState) -> None:
    """One re-plan, each decision point answered by the planner under test; its path is not
    followed (the bag's robot moves as it moved)."""
    gen = search.plan(st)
    try:
        point = next(gen)
        while isinstance(point, DecisionPoint):
            point = gen.send(point.ask())
    except StopIteration:
        pass


class _NoSigns:
    """A robot's bag knows no sign of the world: the goal is matched by its label alone."""

    def indices_of(self, label) -> list:
        return []


@dataclass
class _RobotWorld:
    frame: GridFrame
    signs: _NoSigns


class RobotTask:
    """What a door search needs of its task, for a robot's bag: the grid its maps cover, and the
    belief's, robot's, camera's and navigation's settings (a scenario's, or the defaults)."""

    def __init__(self, frame: GridFrame, sc=None):
        self.world = _RobotWorld(frame, _NoSigns())
        self.sc = sc if sc is not None else SimpleNamespace(belief=BeliefSpec(), robot=RobotSpec(), door_camera=DoorCameraSpec(),
                                                            navigation=NavigationSpec())

    def new_belief(self) -> DoorBelief:
        return DoorBelief(self.world.frame, self.sc.belief, self.sc.robot.radius)


def _robot_frame(bag: Path, msgs: Messages) -> GridFrame:
    """The grid that covers every /map of a robot's bag, at their resolution."""
    stream = BagStream(bag, msgs, only=("/map",))
    try:
        if "/map" not in stream.topics or not any(t in stream.topics for t in (*POSE_TOPICS, "/tf")):
            raise ScenarioError(str(bag), "/map", "a robot's bag needs /map (nav_msgs/OccupancyGrid) and a pose on one of "
                                f"{', '.join(POSE_TOPICS)} or /tf (map to {' or '.join(BASE_FRAMES)}); or it is a bag of "
                                "`semsearch export`, with /semsearch/events")
        res, box = None, [np.inf, np.inf, -np.inf, -np.inf]
        while (item := stream.next()) is not None:
            info = item[2].info
            q = info.origin.orientation
            if abs(q.z) > 1e-6 or abs(q.x) > 1e-6 or abs(q.y) > 1e-6:
                raise ScenarioError(str(bag), "/map", "a map rotated in its frame (origin orientation not 0) is not read")
            if res is None:
                res = float(info.resolution)
            elif abs(float(info.resolution) - res) > 1e-9:
                raise ScenarioError(str(bag), "/map", f"maps of two resolutions ({res} and {info.resolution} m)")
            x0, y0 = float(info.origin.position.x), float(info.origin.position.y)
            box = [min(box[0], x0), min(box[1], y0), max(box[2], x0 + info.width * res), max(box[3], y0 + info.height * res)]
    finally:
        stream.close()
    W, H = int(round((box[2] - box[0]) / res)), int(round((box[3] - box[1]) / res))
    return GridFrame(res, box[0], box[1], H, W)


def fold_map(belief, msg) -> None:
    """Fold a robot's OccupancyGrid (its SLAM map, placed by its origin in the grid that covers every
    map of the bag) into the belief: -1 unknown, below ``FREE_BELOW`` free, else seen and not free."""
    fr, info = belief.frame, msg.info
    h, w = int(info.height), int(info.width)
    c0 = int(round((float(info.origin.position.x) - fr.origin_x) / fr.res))
    y0 = int(round((float(info.origin.position.y) - fr.origin_y) / fr.res))
    values = np.asarray(msg.data, np.int8).reshape(h, w)[::-1]
    belief.fold_grid(fr.height - y0 - h, c0, values >= 0, (values >= 0) & (values < FREE_BELOW))


def _yaw(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _pose_of(msg) -> tuple[float, float, float]:
    pose = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose  # PoseWithCovarianceStamped or PoseStamped
    return float(pose.position.x), float(pose.position.y), _yaw(pose.orientation)


class TfTree:
    """The latest 2D transform of each frame to its parent, from /tf and /tf_static; ``pose`` of a
    frame in ``map`` composes them (None while the chain is incomplete)."""

    def __init__(self):
        self.parent: dict[str, tuple[str, float, float, float]] = {}

    def add(self, msg) -> set[str]:
        """Take a TFMessage; returns the child frames it updated."""
        done = set()
        for tr in msg.transforms:
            child, t = tr.child_frame_id.lstrip("/"), tr.transform
            self.parent[child] = (tr.header.frame_id.lstrip("/"), float(t.translation.x), float(t.translation.y), _yaw(t.rotation))
            done.add(child)
        return done

    def pose(self, frame: str, root: str = "map") -> tuple[float, float, float] | None:
        x = y = yaw = 0.0
        for _ in range(16):  # a tree of a robot is shallow; a loop in it is not followed for ever
            if frame == root:
                return x, y, yaw
            if frame not in self.parent:
                return None
            frame, px, py, pyaw = self.parent[frame]
            c, s = math.cos(pyaw), math.sin(pyaw)
            x, y, yaw = px + c * x - s * y, py + s * x + c * y, pyaw + yaw
        return None


def _run_robot(task: RobotTask, variant, goal, stream: BagStream, writer: BagWriter, frame, rng_inc=None) -> tuple[bool, list]:
    """A robot's bag: each pose a frame and a step, re-plans as the simulator's periodic policy."""
    planner = variant.build()
    out = GoalWriter(writer, frame)
    st = RobotState(0.0, 0.0, 0.0, belief=task.new_belief())
    search = ReplaySearch(task, planner, goal, np.random.default_rng(0), out, stream)
    pose_topic = next((t for t in POSE_TOPICS if t in stream.topics), None)  # else /tf: map -> odom -> base_link
    tf = TfTree()
    every = task.sc.navigation.replan_every
    on_signs = getattr(planner, "replan_on_signs", False)
    b, fr = st.belief, frame
    have_map = posed = False
    since, due = 0.0, True
    while (item := stream.next()) is not None:
        topic, t, msg = item
        out.t = t
        pose = None
        if topic == "/map":
            fold_map(b, msg)
            have_map = True
        elif topic == pose_topic:
            pose = _pose_of(msg)
        elif pose_topic is None and topic in ("/tf", "/tf_static"):
            if tf.add(msg) & set(BASE_FRAMES):
                pose = next(filter(None, map(tf.pose, BASE_FRAMES)), None)
        elif topic == "/semsearch/detections" and posed:
            try:
                label = sign_label(json.loads(msg.data)["label"])
            except (ValueError, KeyError, TypeError):
                continue  # not a detection this replay reads: skipped, as a robot's stray message would be
            _, _, r, c = fr.point_to_cell(st.x, st.y)
            if 0 <= r < fr.height and 0 <= c < fr.width:
                if b.reads.add(label, r * fr.width + c, st.x, st.y, st.heading) == b.spec.min_reads and on_signs:
                    due = True
                if label == goal:
                    search.found = True
                    break
        if pose is None:
            continue
        x, y, yaw = pose
        if posed:
            moved = math.hypot(x - st.x, y - st.y)
            st.distance += moved
            since += moved
        st.steps += posed  # the first pose is step 0, as in an exported bag
        st.x, st.y, st.heading, posed = x, y, yaw, True
        v, u, r, c = fr.point_to_cell(x, y)
        if not (0 <= r < fr.height and 0 <= c < fr.width):
            continue
        b.views.append((v, u, yaw))
        search.update(st)
        if have_map and (due or since >= every):
            since, due = 0.0, False
            _plan(search, st)
    return search.found, out.rows
