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
  re-plan senses; frames a re-plan of another planner does not ask for are folded in after it.
"""

from __future__ import annotations

import json
import shutil
from collections import deque
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config.base import sign_label
from ..errors import BudgetSpent, PlannerError, ScenarioError
from ..planners import Variant
from ..runner.specs import Loaded
from ..tasks.base import Observer, RobotState
from ..tasks.decisions import DecisionPoint
from ..tasks.doors import DoorDecision, DoorSearch
from .bag import BagWriter, Messages, drop_bag, rosbag2

CAND_RGBA, GOAL_RGBA = (1.0, 0.6, 0.0, 0.9), (0.9, 0.1, 0.1, 1.0)


class BagStream:
    """A bag's messages in stamp order, decoded, with one message of look-ahead."""

    def __init__(self, path: Path, messages: Messages):
        self.path, self.m = Path(path), messages
        try:
            self.reader = rosbag2.Reader(self.path)
            self.reader.open()
        except Exception as exc:  # noqa: BLE001  not a bag rosbags reads: named, never a traceback
            raise ScenarioError(str(path), "", f"is not a ROS 2 bag folder rosbags can read ({type(exc).__name__}: {exc})") from None
        self.topics = {c.topic for c in self.reader.connections}
        self._it = self.reader.messages()
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
            self.rng.bit_generator.state = ev["rng"]
        self.found = self.found or found
        return found, event

    def sense(self, st: RobotState) -> tuple[bool, bool]:
        """A frame sensed inside a re-plan: the bag's next one, if the bag's re-plan sensed it."""
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
        c, t = event.candidates, self.t
        cx, cy = self.frame.to_world(c.rows, c.cols)
        chosen = np.flatnonzero((c.rows == event.decision.row) & (c.cols == event.decision.col))
        items = [self.m.delete_all(t, "frontiers")]
        items += [self.m.marker(t, "frontiers", j, "SPHERE", cx[j], cy[j], GOAL_RGBA if j in chosen else CAND_RGBA,
                                0.5 if j in chosen else 0.35) for j in range(len(c))]
        yaw = float(c.theta[chosen[0]]) if chosen.size else 0.0
        row = {"step": int(event.step), "target_cell": [int(event.decision.row), int(event.decision.col)],
               "target": [float(v) for v in event.target_xy]}
        self.rows.append(row)
        for topic, msg in (("/explore/frontiers", self.m.markers(items)), ("/semsearch/goal", self.m.pose_stamped(t, *event.target_xy, yaw)),
                           ("/semsearch/decision", self.m.string(row))):
            self.last = max(t, self.last + 1)  # after the input's moment, and after every message before
            self.bag.write(topic, self.last, msg)


@dataclass
class Replayed:
    """What a replay gave: the output bag folder, the decisions [{step, target_cell, target}],
    and whether the goal's sign was read in the bag."""

    folder: Path
    decisions: list
    found: bool


def replay_bag(loaded: Loaded, bag: Path, variant: Variant, out: Path, fmt: str = "mcap") -> Replayed:
    """Run door planner ``variant`` over ``bag`` (written by
    ``semsearch export`` from a run of ``loaded``'s scenario) and write its decisions to the new
    bag folder ``out`` (which must not exist)."""
    task = loaded.task
    if task.kind != "doors":
        raise ScenarioError(str(loaded.path), "kind", f"is {task.kind}: a bag replays door planners only")
    msgs = Messages()
    stream = BagStream(bag, msgs)
    try:
        if "/semsearch/events" not in stream.topics:
            raise ScenarioError(str(bag), "/semsearch/events", "not in the bag: it was not written by `semsearch export`, and "
                                "replaying a robot's own bag (map, pose and detections alone) is not built yet")
        setup = _setup(stream, bag)
        if setup["fingerprint"] != loaded.fingerprint:
            raise ScenarioError(str(bag), "/semsearch/setup", f"the bag was recorded on another scenario (fingerprint "
                                f"{setup['fingerprint']}, {loaded.path.name}'s is {loaded.fingerprint}): give the one it was "
                                "recorded on, --scenario")
        if out.exists():
            raise ScenarioError(str(out), "", "exists already: give a new folder for the replay's bag")
        work = out.with_name(f".{out.name}.partial")  # written here, then moved into place whole
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        writer = None
        try:
            writer = BagWriter(work / out.name, fmt, msgs)
            found, rows = _run(task, variant, sign_label(setup["goal"]), stream, writer, loaded.world.frame)
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


def _run(task, variant, goal, stream: BagStream, writer: BagWriter, frame) -> tuple[bool, list]:
    planner = variant.build()
    out = GoalWriter(writer, frame)
    st = RobotState(0.0, 0.0, 0.0, belief=task.new_belief())
    rng = np.random.default_rng(0)
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
            rng.bit_generator.state = ev["rng"]
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
