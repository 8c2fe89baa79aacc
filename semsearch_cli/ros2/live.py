"""``semsearch ros live``: a door planner exploring with a robot through rosbridge, in the place of
explore_lite (docs/robot.md).

The robot's side is rosbridge_server's WebSocket (``roslibpy`` speaks to it, ROS 2 actions
included); semsearch subscribes to :data:`INPUTS` and runs a
:class:`~semsearch_cli.ros2.robot.RobotSession` over them, message by message in the order they
come (so a live run makes the re-plans a bag of the same messages replays to). At each re-plan it
publishes explore_lite's ``/explore/frontiers`` (the candidates as markers, the chosen one red),
``/semsearch/goal`` (the target, PoseStamped) and ``/semsearch/decision`` (JSON), and then:

- sends the path's end as a ``nav2_msgs/action/NavigateToPose`` goal on ``/navigate_to_pose`` (a
  goal at every re-plan, so that the robot's planner starts from where the robot is, as the
  simulator's re-plan does; Nav2 preempts the one under way); the goal's end (reached, aborted) is
  a re-plan's "path done";
- or, with ``publish_only``, drives nothing: ``/semsearch/goal`` is the output, and the goal
  counts as reached when the robot's pose comes within ``ARRIVED`` of it.

``/explore/resume`` (std_msgs/Bool) pauses (False: the goal under way is cancelled, no re-plan)
and resumes (True: a re-plan at once), as explore_lite's. The run ends when the goal's sign is
read (found; the goal under way is cancelled), when the planner has nowhere left to go (stuck),
at ``max_distance`` (budget), when the robot has been silent for ``silence`` seconds (lost), or
on Ctrl-C (interrupted).

The planner is seated as in a batch (a :class:`~semsearch_cli.tasks.decisions.Recording`): a
language model keeps its transcript and its cost columns, and every run keeps its decisions
record. With ``out`` (``semsearch ros live --out``), a run writes its folder: the bag of the
messages it took, in the order it took them (``bag/``, for every outcome), which ``semsearch
ros replay`` replays to the same re-plans and ``semsearch verify`` replays from the record
alone; ``run.json``, ``decisions.json`` and the planner's ``transcripts.jsonl``
(:func:`semsearch_cli.api.ros_live` writes them). Without it, a run that ends otherwise than found
leaves its bag at ``repro`` (before 0.4.0 the only output).
"""

from __future__ import annotations

import contextlib
from collections import Counter
import logging
import math
import queue
import shutil
import socket
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlparse

from ..errors import ScenarioError
from ..optional import lazy_module
from ..tasks.decisions import Recording
from .bag import BagWriter, Messages, drop_bag, from_json, to_json
from .robot import (ABORTED, DETECTIONS, GOAL_STATUS, MAP, NAVIGATE_ACTION, POSE_TYPES, RESUME, SUCCEEDED, GoalWriter,
                    RobotSession, RobotTask, goal_ended, map_frame, refusal)

roslibpy = lazy_module("roslibpy", "ros")  # optional: pip install 'semsearch[ros]'

# topic -> (type, direction, what): the live bridge's topics (docs/robot.md lists them)
LIVE_TOPICS = {
    DETECTIONS: ("std_msgs/msg/String", "in", 'a sign read: JSON {"label", ...}'),
    RESUME: ("std_msgs/msg/Bool", "in", "False pauses the exploration (the goal under way is cancelled), True resumes it"),
    MAP: ("nav_msgs/msg/OccupancyGrid", "in", "the SLAM map (a latched map arrives at once)"),
    **{t: (POSE_TYPES[t], "in", what) for t, what in zip(POSE_TYPES, (
        "the robot's pose in map; of the three pose topics, the first that speaks is used",
        "the pose as AMCL publishes it", "the pose as slam_toolbox publishes it"))},
    "/explore/frontiers": ("visualization_msgs/msg/MarkerArray", "out", "at each decision, the candidates as spheres, the "
                           "chosen one larger and red"),
    "/semsearch/goal": ("geometry_msgs/msg/PoseStamped", "out", "at each decision, the target"),
    "/semsearch/decision": ("std_msgs/msg/String", "out", 'at each decision, JSON {"step", "target_cell", "target"}'),
    NAVIGATE_ACTION[0]: (NAVIGATE_ACTION[1], "action goal", "at each re-plan, the path's end (none with "
                          "--publish-only)"),
}
# subscribed in this order: the detections before the poses (a robot's first frame comes with its pose), the map
# before the poses (a latched map is in before the first pose)
INPUTS = {t: ty for t, (ty, way, _) in LIVE_TOPICS.items() if way == "in"}
OUTPUTS = {t: ty for t, (ty, way, _) in LIVE_TOPICS.items() if way == "out"}
ARRIVED = 0.5  # m: with --publish-only, a goal is reached when the pose comes this close (twice Nav2's default 0.25 m)
ABORTS = 5  # goals the robot gives up on in a row, without moving, before the run is stuck


@dataclass
class LiveRun:
    """What a live run gave: its outcome (found, stuck, budget, lost, interrupted), the distance
    its poses travelled (m, straight lines between them), the poses, the decisions [{step,
    target_cell, target}], the NavigateToPose goals sent (none with ``publish_only``), a note,
    the repro bag (None when found), the bag of every run when the run has a folder (``bag``), and
    what the seat kept: the planner's ``costs`` (a batch row's cost columns), its ``transcripts``
    and the decisions ``record``."""

    outcome: str
    distance: float
    poses: int
    decisions: list = field(default_factory=list)
    goals: int = 0
    message: str = ""
    repro: Path | None = None
    dropped: str = ""  # the robot's messages not taken as they came, by reason (RobotSession.dropped_text)
    bag: Path | None = None  # every run's messages, when the run has a folder (out/bag)
    costs: dict = field(default_factory=dict)
    transcripts: list = field(default_factory=list)
    record: dict | None = None


class _Repro:
    """The messages a live run took, written as they come into a hidden bag folder; kept under
    ``path`` when the run fails, removed when it finds the goal."""

    def __init__(self, path: Path, msgs: Messages):
        self.path = path
        self.work = path.with_name(f".{path.name}.partial")
        shutil.rmtree(self.work, ignore_errors=True)
        self.work.mkdir(parents=True)
        self.writer = BagWriter(self.work / path.name, "mcap", msgs)
        self.t = 0

    def write(self, topic: str, msg) -> None:
        self.t = max(time.time_ns(), self.t + 1)  # strictly increasing: read by time, the order they came
        self.writer.write(topic, self.t, msg)

    def keep(self) -> Path:
        self.writer.close()
        (self.work / self.path.name).rename(self.path)
        self.work.rmdir()
        return self.path

    def drop(self) -> None:
        drop_bag(self.writer, self.work)


def rosbridge_address(url: str) -> tuple[str, int, bool]:
    """(host, port, secure) of a rosbridge WebSocket address ``ws://HOST[:PORT]`` or ``wss://...``
    (port 9090 when left out), or a ScenarioError naming ``--rosbridge``."""
    hint = "give ws://HOST:PORT (rosbridge_server listens on 9090)"
    try:
        u = urlparse(url)
        port = u.port  # a ValueError for a port past 65535 or not a number
    except ValueError as exc:
        raise ScenarioError("<command line>", "--rosbridge", f"{url!r} is not a WebSocket address ({exc}): {hint}") from None
    if u.scheme not in ("ws", "wss") or not u.hostname:
        raise ScenarioError("<command line>", "--rosbridge", f"{url!r} is not a WebSocket address: {hint}")
    if u.username or u.password:
        raise ScenarioError("<command line>", "--rosbridge", "a rosbridge address carries no credentials (rosbridge has none to "
                            f"take): {hint}")
    if port == 0:
        raise ScenarioError("<command line>", "--rosbridge", f"{url!r}: port 0 is no server's; {hint}")
    return u.hostname, port or 9090, u.scheme == "wss"


class Live:
    """One live run (see the module's text): :meth:`run` connects, explores and returns a
    :class:`LiveRun`."""

    def __init__(self, url: str, variant, goal, sc=None, publish_only: bool = False, repro: Path | None = None,
                 margin: float = 10.0, max_distance: float | None = None, silence: float = 30.0, log=None,
                 out: Path | None = None):
        self.host, self.port, self.secure = rosbridge_address(url)
        self.variant, self.goal, self.sc = variant, goal, sc
        self.publish_only, self.margin, self.silence = publish_only, margin, silence
        self.max_distance = max_distance if max_distance is not None else math.inf
        self.folder = Path(out) if out is not None else None  # the run's folder: its bag kept for every outcome
        if self.folder is not None and self.folder.exists():
            raise ScenarioError(str(self.folder), "--out", "exists already: give a new folder for the run")
        if repro is None and self.folder is None:
            repro = Path(f"live-repro-{time.strftime('%Y%m%d-%H%M%S')}")
        self.repro_path = Path(repro) if repro is not None else None
        if self.repro_path is not None and self.repro_path.exists():
            raise ScenarioError(str(self.repro_path), "--repro", "exists already: give a new folder for the repro bag")
        self.seat = Recording()  # the planner seated as in a batch: its costs, transcript and choices kept
        self.log = log or (lambda text: None)
        self.m = Messages()
        self.q: queue.Queue = queue.Queue()
        self.session: RobotSession | None = None
        self.out: GoalWriter | None = None
        self.pose_topic: str | None = None
        self.early: list = []  # messages before the first map
        self.stamp = 0  # the last pose's stamp (ns): the goals planned on it carry it
        self.sent = 0  # goals (re-plans' targets) so far, numbered from 1; the one under way is number self.current
        self.current: int | None = None
        self.target: tuple[float, float] | None = None
        self._goal_ids: dict[int, str] = {}  # goal number -> roslibpy's goal id
        self.sent_at = 0.0  # when the goal under way was sent (time.monotonic)
        self.aborts = 0
        self.clipped = False
        self.dropped_early: Counter = Counter()  # messages dropped before the first map made the session
        self.maps_waiting = 0  # maps in the queue (a newer one supersedes the one taken: _superseded)
        self.superseded = 0  # maps skipped for a newer one
        self._maps_lock = threading.Lock()

    # -- the connection ---------------------------------------------------------------
    def run(self) -> LiveRun:
        where = f"no rosbridge answers at {'wss' if self.secure else 'ws'}://{self.host}:{self.port}"
        try:  # at once when nothing listens there (roslibpy would retry until its timeout)
            socket.create_connection((self.host, self.port), timeout=10).close()
        except OSError as exc:
            raise ScenarioError("<command line>", "--rosbridge", f"{where} ({exc.strerror or type(exc).__name__}): is "
                                "rosbridge_server running there?") from None
        # roslibpy logs a traceback for each frame it cannot send once the socket closed, and an error for
        # each rosbridge status message (it has no handler for them): this run says what happened itself
        logger = logging.getLogger("roslibpy")
        level = logger.level
        logger.setLevel(logging.CRITICAL)
        try:
            return self._connected(where)
        finally:
            logger.setLevel(level)

    def _connected(self, where: str) -> LiveRun:
        ros = roslibpy.Ros(self.host, self.port, is_secure=self.secure, transport="asyncio")
        try:
            ros.run(timeout=10)
        except Exception as exc:  # noqa: BLE001  something listens, but no rosbridge: named, never a traceback
            ros.close()
            raise ScenarioError("<command line>", "--rosbridge", f"{where} ({type(exc).__name__}): is it rosbridge_server's "
                                "WebSocket?") from None
        self.pubs = {t: roslibpy.Topic(ros, t, kind) for t, kind in OUTPUTS.items()}
        for topic in self.pubs.values():
            topic.advertise()
        self.nav = roslibpy.ActionClient(ros, *NAVIGATE_ACTION) if not self.publish_only else None
        subs = []
        for t, kind in INPUTS.items():
            sub = roslibpy.Topic(ros, t, kind)
            sub.subscribe(self._enqueue if t == MAP else (lambda msg, t=t: self.q.put((t, msg))))
            subs.append(sub)
        ros.on("close", lambda *_: self.q.put(("closed", None)))
        if self.folder is not None:
            self.folder.mkdir(parents=True)
        self.repro = _Repro(self.folder / "bag" if self.folder is not None else self.repro_path, self.m)
        res = None
        try:
            res = self._loop()
        except KeyboardInterrupt:
            res = self._result("interrupted", "stopped by Ctrl-C")
        finally:  # each step alone: one that fails leaves the others done
            with contextlib.suppress(Exception):
                if self.current is not None:
                    self._cancel()  # the robot stops (rosbridge does not cancel a goal when its client goes)
            for topic in [*subs, *self.pubs.values()]:
                with contextlib.suppress(Exception):
                    topic.unsubscribe() if topic in subs else topic.unadvertise()
            time.sleep(0.05)  # the last messages out before the socket closes
            with contextlib.suppress(Exception):
                ros.close()
            if res is not None and res.outcome == "found" and self.folder is None:
                self.repro.drop()
            else:  # a failed run's, or what a run that raised had taken, or any run that has a folder: kept
                kept = self.repro.keep()
                if self.folder is not None and self.repro_path is not None and (res is None or res.outcome != "found"):
                    shutil.copytree(kept, self.repro_path)  # --repro beside --out: a failed run's bag there too
                    kept = self.repro_path
                if res is None:
                    self.log(f"stopped: the messages taken so far are in {kept}")
                else:
                    res.bag = self.folder / "bag" if self.folder is not None else None
                    res.repro = kept if res.outcome != "found" else None
        return res

    def _enqueue(self, msg) -> None:
        """A map in, on roslibpy's thread: counted, so that the loop folds only the newest of the
        maps waiting (each map is folded whole: a newer one makes an older one moot)."""
        with self._maps_lock:
            self.maps_waiting += 1
        self.q.put((MAP, msg))

    def _superseded(self) -> bool:
        """Whether a newer map waits behind the one taken now (then it is skipped, not folded)."""
        with self._maps_lock:
            self.maps_waiting = max(0, self.maps_waiting - 1)
            return self.maps_waiting > 0

    def _publish(self, topic: str, t_ns: int, msg) -> None:
        """A decision's message out to the robot, and into the repro bag (``ros replay`` reads only
        the robot's topics from it; these say what the live run chose)."""
        self.pubs[topic].publish(roslibpy.Message(to_json(msg)))
        self.repro.write(topic, msg)

    def _cancel(self) -> None:
        gid, self.current = self._goal_ids.get(self.current), None
        if gid is not None and self.nav is not None:
            self.nav.cancel_goal(gid)

    # -- the loop -----------------------------------------------------------------------
    def _loop(self) -> LiveRun:
        heard = moved = time.monotonic()  # the last message; the last time the robot's pose changed
        where = None
        while True:
            try:
                topic, payload = self.q.get(timeout=1.0)
            except queue.Empty:
                topic = payload = None
            now = time.monotonic()
            if topic is not None:
                heard = now if topic != "result" else heard
                end = self._take(topic, payload)
                if end is not None:
                    return end
                s = self.session
                if s is not None and (s.st.x, s.st.y) != where:
                    where, moved = (s.st.x, s.st.y), now
            if now - heard >= self.silence:
                hint = " (with --publish-only, is something driving to /semsearch/goal?)" if self.publish_only else ""
                return self._result("lost", f"no message from the robot for {self.silence:g} s{hint}")
            if self.current is not None and now - max(moved, self.sent_at) >= self.silence:
                # a goal nobody answers (rejected, or lost with a connection) and the robot standing
                self.log(f"goal {self.current}: no answer and no move for {self.silence:g} s; taken as given up")
                moved = now
                end = self._take("result", (self.current, ABORTED))
                if end is not None:
                    return end

    def _take(self, topic: str, payload) -> LiveRun | None:
        """One message (or the end of the goal under way, ``result``); the run's result when it
        ends the run. What the session takes goes into the repro bag first, in this order."""
        if topic == "closed":
            self.log("the connection to rosbridge closed; roslibpy reconnects (the goal under way is given up)")
            if self.current is None:
                return None
            topic, payload = "result", (self.current, ABORTED)
        if topic == "result":
            k, status = payload
            if k != self.current:
                return None  # a goal replaced or cancelled since
            self.current = None
            # the goal under way ended: reached, or not (aborted; cancelled by someone else; a goal
            # rosbridge failed to send, status 0), which is the robot giving up on it
            status = SUCCEEDED if status == SUCCEEDED else ABORTED
            self.aborts = self.aborts + 1 if status == ABORTED else 0
            if self.aborts >= ABORTS:
                return self._result("stuck", f"the robot gave up on {ABORTS} goals in a row")
            topic, msg = GOAL_STATUS, goal_ended(self.m, k, status)
        else:
            if topic == MAP and self._superseded():
                self.superseded += 1  # not taken, not in the repro bag: the replay folds the maps this run folded
                return None
            try:
                msg = from_json(self.m.ts, INPUTS[topic], payload)
            except (ValueError, TypeError, RecursionError) as exc:  # not a message of its type: dropped, counted
                return self._drop(topic, f"not a {INPUTS[topic]}: {str(exc)[:80]}")
            why = refusal(topic, msg)
            if why:
                return self._drop(topic, why)
            if topic in POSE_TYPES:
                if self.pose_topic is None:
                    self.pose_topic = topic
                    self.log(f"pose from {topic}")
                if topic != self.pose_topic:
                    return None
                self.stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec  # a goal carries its pose's stamp
        return self._feed(topic, msg)

    def _drop(self, topic: str, why: str) -> None:
        """A robot's message that is not taken (not written to the repro bag either: it cannot be
        written as its type, or replays as dropped): counted, and said the first time for each
        reason."""
        counts = self.session.dropped if self.session is not None else self.dropped_early
        if not counts[(topic, why)]:
            self.log(f"dropped a message on {topic}: {why} (counted; the run goes on)")
        counts[(topic, why)] += 1
        return None

    def _feed(self, topic: str, msg) -> LiveRun | None:
        self.repro.write(topic, msg)
        s = self.session
        if s is None:
            if topic != MAP:
                self.early.append((topic, msg))  # taken once the first map gives the grid
                return None
            try:
                frame = map_frame(msg, self.margin)
            except ValueError as exc:  # checked before (a margin too wide for this map): the next map may do
                return self._drop(topic, str(exc))
            self.out = GoalWriter(self._publish, self.m, frame)
            s = self.session = RobotSession(RobotTask(frame, self.sc), self.variant, self.goal, self.out, self.pose_topic,
                                            seat=self.seat)
            s.dropped.update(self.dropped_early)
            self.log(f"map: {frame.width} x {frame.height} cells at {frame.res:g} m (the first map and {self.margin:g} m "
                     "around it)")
            for t, m in self.early:
                if s.take(t, m) == "found":
                    return self._found()
        what = s.take(topic, msg)
        if s.clipped and not self.clipped:
            self.clipped = True
            self.log(f"the map outgrew the grid: cells beyond it are left out (give a --margin over {self.margin:g} m)")
        if what == "found":
            return self._found()
        if topic == RESUME:
            self.log(f"explore/resume: {'paused' if s.paused else 'resumed'}")
            if s.paused and self.current is not None and self.nav is not None:
                self._cancel()
        if topic == self.pose_topic:
            if s.st.distance >= self.max_distance:
                return self._result("budget", f"travelled {s.st.distance:.1f} m of {self.max_distance:g}")
            if (what != "plan" and self.publish_only and self.target is not None
                    and math.hypot(s.st.x - self.target[0], s.st.y - self.target[1]) <= ARRIVED):
                # reached (no one says so with --publish-only): recorded as Nav2 would say it, so that
                # the repro bag replays this re-plan
                self.target = None
                topic, msg = GOAL_STATUS, goal_ended(self.m, self.sent, SUCCEEDED)
                self.repro.write(topic, msg)
                what = s.take(topic, msg)
        return self._replan() if what == "plan" else None

    def _replan(self) -> LiveRun | None:
        s = self.session
        self.out.t = self.stamp  # the decisions' messages, stamped as the pose they were made at
        plan = s.plan()
        if isinstance(plan, str):
            return self._result(plan, "nowhere left to go" if plan == "stuck" else plan)
        xs, ys = plan
        x, y = float(xs[-1]), float(ys[-1])
        yaw = math.atan2(float(ys[-1] - ys[-2]), float(xs[-1] - xs[-2]))
        self.target = (x, y)
        self.sent += 1
        if self.nav is not None:
            k = self.sent
            goal = roslibpy.Goal({"pose": to_json(self.m.pose_stamped(self.stamp, x, y, yaw)), "behavior_tree": ""})

            def done(res, k=k):  # on roslibpy's thread: the end goes through the queue, in order
                self.q.put(("result", (k, _status(res))))
            self._goal_ids[k] = self.nav.send_goal(goal, done, lambda fb: None, done)
            self.current, self.sent_at = k, time.monotonic()
        return None

    def _found(self) -> LiveRun:
        return self._result("found", "read the goal's sign")

    def _result(self, outcome: str, message: str) -> LiveRun:
        s = self.session
        if s is None:
            early = "; ".join(f"{n} {topic} ({why})" for (topic, why), n in self.dropped_early.items())
            return LiveRun(outcome, 0.0, 0, [], len(self._goal_ids), message, dropped=early)
        skipped = f"{self.superseded} /map skipped for a newer one waiting" if self.superseded else ""
        s.finish()
        kept = s.seated()
        if outcome == "budget" and kept["notes"]:
            message = kept["notes"]  # the planner's own budget (a language model's calls) ended the run
        return LiveRun(outcome, s.st.distance, s.st.steps + s.posed, self.out.rows, len(self._goal_ids), message,
                       dropped="; ".join(filter(None, (s.dropped_text(), skipped))), costs=kept["costs"],
                       transcripts=kept["transcripts"], record=kept["record"])


def _status(res) -> int:
    """The status (action_msgs/GoalStatus) of a goal's end as roslibpy gives it."""
    status = res.get("status") if hasattr(res, "get") else None
    return int(getattr(status, "value", status) or 0)
