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
- a robot's own bag (no events) is run through
  :class:`~semsearch_cli.ros2.robot.RobotSession`, as ``semsearch ros live`` runs a robot: its
  map (``/map``), its pose (the first of :data:`~semsearch_cli.ros2.robot.POSE_TOPICS` it holds;
  else /tf and /tf_static composed from map to ``base_link`` or ``base_footprint``, in the plane)
  and its sign detections (``/semsearch/detections``); the belief's grid is its first map and
  ``--margin`` metres around it, as ``ros live`` makes it; the goal's label is ``--goal``.
"""

from __future__ import annotations

import json
import math
import shutil
from collections import deque
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config.base import sign_label
from ..engine import engine_of, refusal as engine_refusal  # (robot.refusal: a message a robot may not send)
from ..geometry import GridFrame
from ..errors import BudgetSpent, MissingExtra, PlannerError, ScenarioError
from ..optional import lazy_module
from ..planners import Variant
from ..runner.specs import Loaded
from ..tasks.base import RobotState
from ..tasks.decisions import Seat, set_rng
from ..tasks.loop import answer_all
from ..tasks.doors import DoorSearch, DoorTask
from .bag import BagWriter, Messages, drop_bag, rosbag2
from .robot import (BASE_FRAMES, MAX_MAP_CELLS, POSE_TOPICS, GoalWriter, RobotSession, RobotTask, TfTree,
                    map_frame, refusal, within)


mcap_stream = lazy_module("mcap.stream_reader", "ros")  # optional: the ros extra
mcap_records = lazy_module("mcap.records", "ros")

MAX_MESSAGE_BYTES = 64 << 20  # one message of a bag: a map of MAX_MAP_CELLS int8 cells is 25 MB
MAX_RECORD_BYTES = 1 << 30  # one MCAP record (a chunk of messages, decompressed): what a bag may claim


def check_mcap(f: Path) -> None:
    """Read an MCAP file through once, checked: its checksums where it has them (rosbags writes
    none), and its messages counted against its statistics record. rosbags reads a damaged chunk
    without a word, the messages after the damage lost; a ScenarioError names the file. A record
    claiming more than :data:`MAX_RECORD_BYTES` is refused before it is read."""
    counts: dict = {}
    stats = None
    try:
        with f.open("rb") as fh:
            for rec in mcap_stream.StreamReader(fh, validate_crcs=True, record_size_limit=MAX_RECORD_BYTES).records:
                if isinstance(rec, mcap_records.Message):
                    counts[rec.channel_id] = counts.get(rec.channel_id, 0) + 1
                elif isinstance(rec, mcap_records.Statistics):
                    stats = rec
    except MissingExtra:
        raise
    except Exception as exc:  # noqa: BLE001  the mcap library's errors (CRC, a truncated record, zstd's): the bag named
        raise ScenarioError(str(f), "", f"is damaged: {type(exc).__name__}: {str(exc)[:160]} (the MCAP file's checks fail; "
                            "record the bag again, or copy it from where it was recorded)") from None
    if stats is not None and stats.channel_message_counts and {k: v for k, v in stats.channel_message_counts.items() if v} != counts:
        raise ScenarioError(str(f), "", f"is damaged: its chunks hold {sum(counts.values()):,} messages, its statistics count "
                            f"{stats.message_count:,} (a chunk that does not decompress whole; record the bag again, or copy "
                            "it from where it was recorded)")


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
        for f in sorted(self.path.glob("*.mcap")):
            check_mcap(f)
        self.topics = {c.topic for c in self.reader.connections}
        conns = [c for c in self.reader.connections if c.topic in only] if only else None  # only these topics decoded
        self._it = self.reader.messages(connections=conns) if conns is not None else self.reader.messages()
        self._ahead: deque = deque()

    def _decode(self, item):
        conn, t, raw = item
        if len(raw) > MAX_MESSAGE_BYTES:
            raise ScenarioError(str(self.path), conn.topic, f"holds a message of {len(raw):,} bytes, more than any a search "
                                f"reads ({MAX_MESSAGE_BYTES:,}: a map of {MAX_MAP_CELLS:,} cells and its header)")
        try:
            return conn.topic, t, self.m.ts.deserialize_cdr(raw, conn.msgtype)
        except Exception as exc:  # noqa: BLE001  bytes that are not a message of the connection's type
            raise ScenarioError(str(self.path), conn.topic, f"holds a message that is not a {conn.msgtype} (at {t} ns; "
                                f"{type(exc).__name__}: {str(exc)[:120]}): the bag is damaged") from None

    def peek(self):
        """The next message (topic, stamp, message), or None at the bag's end; a damaged bag (a
        chunk that does not decompress, a message that does not decode) is a ScenarioError
        naming it."""
        if not self._ahead:
            try:
                nxt = next(self._it, None)
            except Exception as exc:  # noqa: BLE001  rosbags' and its storage's errors (ZstdError, a truncated chunk, ...)
                raise ScenarioError(str(self.path), "", f"is damaged: its messages cannot be read on ({type(exc).__name__}: "
                                    f"{str(exc)[:160]})") from None
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
        b.add_view(v, u, st.heading)
        event = False
        reads = ev.get("reads", [])
        bearings = ev.get("bearings")
        if not isinstance(bearings, list) or len(bearings) != len(reads):  # a bag of an older semsearch: not known
            bearings = [None] * len(reads)
        for label, bearing in zip(reads, bearings):
            bearing = float(bearing) if isinstance(bearing, (int, float)) and math.isfinite(bearing) else None
            if b.reads.add(sign_label(label), r * fr.width + c, st.x, st.y, st.heading, bearing) == b.spec.min_reads:
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


@dataclass
class Replayed:
    """What a replay gave: the output bag folder, the decisions [{step, target_cell, target}],
    whether the goal's sign was read in the bag, and what of a robot's bag was not taken."""

    folder: Path
    decisions: list
    found: bool
    dropped: str = ""  # a robot's bag: its messages not taken, by reason (RobotSession.dropped_text)


def replay_bag(loaded: Loaded | None, bag: Path, variant: Variant, out: Path, fmt: str = "mcap", goal=None,
               margin: float = 10.0, seat: Seat | None = None, max_distance: float | None = None) -> Replayed:
    """Run door planner ``variant`` over ``bag`` and write its decisions to the new bag folder
    ``out`` (which must not exist). A bag ``semsearch export`` wrote replays on ``loaded``, the
    scenario it was recorded on; a robot's own bag needs ``goal`` (the label to find), is folded
    into a grid of its first map and ``margin`` metres around it (as ``ros live`` folds a robot's
    maps), and takes the belief's, robot's and navigation's settings from ``loaded`` when given,
    else their defaults. ``seat`` answers the re-plans' decisions (default: the variant's planner,
    seated as in a batch; a :class:`~semsearch_cli.tasks.decisions.Replay` answers from a live
    run's record, no planner built). ``max_distance``: a robot's bag ends at the first pose that
    has travelled it (where ``ros live --max-distance`` ended the run), before its re-plan."""
    seat = Seat() if seat is None else seat
    if loaded is not None and not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind}: a bag replays door planners only")
    msgs = Messages()
    stream = BagStream(bag, msgs)
    try:
        if "/semsearch/events" in stream.topics:
            setup = _setup(stream, bag)
            why = engine_refusal(setup["engine"], f"the bag {bag.name}")
            if why:
                raise ScenarioError(str(bag), "/semsearch/setup.engine", why)
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
            frame = _robot_frame(bag, msgs, margin)
            task, goal, run, rng_inc = RobotTask(frame, loaded.sc if loaded is not None else None), sign_label(goal), _run_robot, None
        if out.exists():
            raise ScenarioError(str(out), "", "exists already: give a new folder for the replay's bag")
        work = out.with_name(f".{out.name}.partial")  # written here, then moved into place whole
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        writer = None
        try:
            writer = BagWriter(work / out.name, fmt, msgs)
            found, rows, dropped = run(task, variant, goal, stream, writer, frame, rng_inc, seat, max_distance)
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
    return Replayed(out, rows, found, dropped)


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
        setup = json.loads(item[2].data)
    except (ValueError, KeyError, AttributeError):  # a setup that is not ours to read
        return None
    finally:
        stream.close()
    if not isinstance(setup, dict):
        return None
    try:  # another engine's bag: refused before its scenario is looked for (the release that made it replays it)
        why = engine_refusal(engine_of(setup.get("engine")), f"the bag {bag.name}")
    except ValueError:
        why = None  # named by the replay's own check of the setup
    if why:
        raise ScenarioError(str(bag), "/semsearch/setup.engine", why)
    return setup.get("file")


SETUP_KEYS = {"fingerprint": str, "goal": (str, int), "rng_inc": int}  # what a replay reads of /semsearch/setup


def _setup(stream: BagStream, bag: Path) -> dict:
    """The bag's /semsearch/setup (its first message), checked: a JSON object with
    :data:`SETUP_KEYS` of their types."""
    item = stream.peek()
    if item is None or item[0] != "/semsearch/setup":
        raise ScenarioError(str(bag), "/semsearch/setup", "is not the bag's first message: not a bag `semsearch export` wrote")
    stream.next()
    try:
        setup = json.loads(item[2].data)
    except (ValueError, RecursionError):
        setup = None
    if not isinstance(setup, dict):
        raise ScenarioError(str(bag), "/semsearch/setup", "is not a JSON object: not a setup `semsearch export` wrote")
    for key, kind in SETUP_KEYS.items():
        if not isinstance(setup.get(key), kind) or isinstance(setup.get(key), bool):
            raise ScenarioError(str(bag), f"/semsearch/setup.{key}", f"is {setup.get(key)!r}: not a setup `semsearch export` "
                                "wrote")
    try:  # a bag exported before engines were recorded: engine 1
        setup["engine"] = engine_of(setup.get("engine"))
    except ValueError:
        raise ScenarioError(str(bag), "/semsearch/setup.engine", f"is {setup.get('engine')!r}: not a setup `semsearch export` "
                            "wrote") from None
    if not 0 <= setup["rng_inc"] < 2**128:
        raise ScenarioError(str(bag), "/semsearch/setup.rng_inc", f"{setup['rng_inc']} is not a generator's increment (0 to 2**128)")
    return setup


def _run(task, variant, goal, stream: BagStream, writer: BagWriter, frame, rng_inc: int, seat: Seat,
         max_distance=None) -> tuple[bool, list]:
    planner = seat.planner(variant)
    out = GoalWriter(writer.write, writer.msgs, frame)
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
            _plan(search, st, seat)
            while (item := stream.next()) is not None:  # what the bag's re-plan sensed and this one did not ask for
                ev = _fold(search, st, item)
                if ev is not None and ev["event"] == "plan":
                    break
    seat.finish()
    return search.found, out.rows, ""


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


def _plan(search: ReplaySearch, st: RobotState, seat: Seat) -> None:
    """One re-plan, each decision point answered by the seat (the planner under test); its path is
    not followed (the bag's robot moves as it moved)."""
    answer_all(search.plan(st), seat.decide)


def _robot_frame(bag: Path, msgs: Messages, margin: float) -> GridFrame:
    """The grid of a robot's bag: its first /map and ``margin`` metres around it, as ``ros live``
    makes it."""
    stream = BagStream(bag, msgs, only=("/map",))
    try:
        if "/map" not in stream.topics or not any(t in stream.topics for t in (*POSE_TOPICS, "/tf")):
            raise ScenarioError(str(bag), "/map", "a robot's bag needs /map (nav_msgs/OccupancyGrid) and a pose on one of "
                                f"{', '.join(POSE_TOPICS)} or /tf (map to {' or '.join(BASE_FRAMES)}); or it is a bag of "
                                "`semsearch export`, with /semsearch/events")
        first = None  # why the first map could not be read
        while (item := stream.next()) is not None:  # the first map that can be read (as ros live drops the others)
            try:
                return map_frame(item[2], margin)
            except ValueError as exc:
                first = first or str(exc)
        raise ScenarioError(str(bag), "/map", f"no map of the bag can be read (the first: {first})" if first else "holds no message")
    finally:
        stream.close()


def _run_robot(task: RobotTask, variant, goal, stream: BagStream, writer: BagWriter, frame, rng_inc=None,
               seat: Seat | None = None, max_distance: float | None = None) -> tuple[bool, list]:
    """A robot's bag, through :class:`~semsearch_cli.ros2.robot.RobotSession` (as ``ros live``
    runs a robot): its robot moves as it moved, the seat (the planner) is asked where it would go."""
    out = GoalWriter(writer.write, writer.msgs, frame)
    session = RobotSession(task, variant, goal, out, next((t for t in POSE_TOPICS if t in stream.topics), None), seat=seat)
    tf = TfTree()  # no pose topic: /tf, map -> odom -> base_link
    while (item := stream.next()) is not None:
        topic, t, msg = item
        out.t = t
        if session.pose_topic is None and topic in ("/tf", "/tf_static"):
            why = refusal(topic, msg)
            if why:
                session.drop(topic, why)
                continue
            pose = next(filter(None, map(tf.pose, BASE_FRAMES)), None) if tf.add(msg) & set(BASE_FRAMES) else None
            what = "plan" if pose is not None and within(*pose[:2]) and math.isfinite(pose[2]) and session.pose(*pose) else None
        else:
            what = session.take(topic, msg)
        if what == "found":
            break
        if max_distance is not None and session.st.distance >= max_distance:
            break  # where the live run's budget ended it, before the re-plan
        if what == "plan":
            session.plan()  # a plan that ends the run (stuck, a spent budget) ended the live run's bag there too
    session.finish()
    return session.found, out.rows, session.dropped_text()

