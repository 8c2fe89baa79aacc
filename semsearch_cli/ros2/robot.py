"""A door search fed with a robot's own messages, one at a time: its SLAM map, its pose and its
sign detections (a robot's bag, ``semsearch ros replay``; a live robot, ``semsearch ros live``).

Both drivers run :class:`RobotSession`, so a bag recorded on a robot replays with the re-plans the
live bridge made on it:

- the map (``/map``, nav_msgs/OccupancyGrid, as a SLAM node publishes it) is folded in whole at
  each message: -1 unknown, below :data:`FREE_BELOW` free (map_saver's threshold), else seen and
  not free; cells outside the belief's grid are left out (:func:`fold_map`);
- each pose (the first of :data:`POSE_TOPICS` that speaks, or the one given) is a frame and a
  step: the distance grows by the straight line from the pose before (to the nanometre), the
  camera's view is the pose's, the visited kernel is marked;
- a detection (``/semsearch/detections``, JSON ``{"label", ...}``) of the goal's label ends the
  search; another is read from the robot's next pose (a read counts towards ``min_reads`` as the
  simulator's camera read does), so that the reads of a moment are in before that moment's re-plan;
- the end of the newest goal (:data:`GOAL_STATUS`, Nav2's action status: SUCCEEDED or ABORTED,
  taken once; Nav2 aborts a goal that a newer one replaces) is a path done; ``/explore/resume`` False pauses the re-plans, True re-plans at once;
- a re-plan is due as :meth:`~semsearch_cli.tasks.doors.DoorSearch.replan_due` says: at the first
  pose that has a map, when the last goal is done (reached, or given up by the robot), every
  ``replan_every`` metres (``navigation.replan: periodic``) or when the map loses a free cell
  (``events``), and when a sign is read ``min_reads`` times for planners that re-plan on signs;
- the robot senses for itself: a re-plan that would turn on the spot to look (no frontier yet, a
  wall face reached) sees nothing new, since the robot is not asked to turn;
- every message is checked as it enters (:func:`refusal`, against the bounds below): one that a
  robot's stack could send but no search can take (a NaN pose, a map of resolution 0 or of more
  cells than :data:`MAX_MAP_CELLS`, a stamp past ``builtin_interfaces/Time``) is dropped and
  counted by its reason (:attr:`RobotSession.dropped`), and the run goes on; a map at another
  resolution than the grid's is re-gridded onto it, map cells outside -1..100 are unknown
  (docs/robot.md, "What a robot may send").
"""

from __future__ import annotations

import json
import math
from collections import Counter
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from ..belief import DoorBelief
from ..config import BeliefSpec, DoorCameraSpec, NavigationSpec, RobotSpec
from ..config.base import sign_label
from ..geometry import GridFrame
from ..world.images import MAX_CELLS
from ..errors import BudgetSpent
from ..planners import Variant
from ..tasks.base import Observer, RobotState
from ..tasks.decisions import DecisionPoint, Recording, Seat
from ..tasks.doors import DoorDecision, DoorSearch

MAP, DETECTIONS, RESUME = "/map", "/semsearch/detections", "/explore/resume"
GOAL_STATUS = "/navigate_to_pose/_action/status"  # action_msgs/GoalStatusArray: Nav2's goals and how they ended
NAVIGATE_ACTION = ("/navigate_to_pose", "nav2_msgs/action/NavigateToPose")
SUCCEEDED, CANCELED, ABORTED = 4, 5, 6  # action_msgs/GoalStatus
ENDS = (SUCCEEDED, ABORTED)  # the newest goal's path is done (CANCELED: called off by whoever sent it)
# a robot's pose: the first of these topics it publishes (amcl's /amcl_pose, slam_toolbox's /pose), and their types
POSE_TYPES = {"/semsearch/pose": "geometry_msgs/msg/PoseStamped", "/amcl_pose": "geometry_msgs/msg/PoseWithCovarianceStamped",
              "/pose": "geometry_msgs/msg/PoseWithCovarianceStamped"}
POSE_TOPICS = tuple(POSE_TYPES)
BASE_FRAMES = ("base_link", "base_footprint")  # the robot's frame in /tf, the first that reaches map
FREE_BELOW = 20  # OccupancyGrid values under it are free (map_saver's 0.196); from it, seen and not free

# What a robot's message may claim (docs/robot.md, "What a robot may send"); past these it is dropped and counted
MAX_MAP_CELLS = MAX_CELLS  # cells of one map, and of the belief's grid (the first map and its margin): 5000 x 5000
RESOLUTIONS = (0.001, 10.0)  # m per cell, from 1 mm to 10 m
MAX_COORD = 100_000.0  # m: a pose or a map origin farther than 100 km from the map frame's origin is no robot's
MAX_MARGIN = 1000.0  # m of grid around the first map (--margin)
MAX_DETECTION_BYTES = 4096  # a detection's JSON text
MAX_LIST = 1000  # goal statuses of one GoalStatusArray, transforms of one TFMessage
INT32 = 2**31


class _NoSigns:
    """A robot's search knows no sign of the world: the goal is matched by its label alone."""

    def indices_of(self, label) -> list:
        return []


@dataclass
class _RobotWorld:
    frame: GridFrame
    signs: _NoSigns


class RobotTask:
    """What a door search needs of its task, for a robot: the grid its maps are folded into, and
    the belief's, robot's, camera's and navigation's settings (a scenario's, or the defaults)."""

    def __init__(self, frame: GridFrame, sc=None):
        self.world = _RobotWorld(frame, _NoSigns())
        self.sc = sc if sc is not None else SimpleNamespace(belief=BeliefSpec(), robot=RobotSpec(), door_camera=DoorCameraSpec(),
                                                            navigation=NavigationSpec())

    def new_belief(self) -> DoorBelief:
        return DoorBelief(self.world.frame, self.sc.belief, self.sc.robot.radius)


def goal_ended(messages, k: int, status: int):
    """The GoalStatusArray of goal number ``k`` (its UUID: ``k`` in 16 bytes; accepted at ``k``
    ns, so that a later goal is newer) ended with ``status``."""
    T = messages.T
    info = T["action_msgs/msg/GoalInfo"](goal_id=T["unique_identifier_msgs/msg/UUID"](uuid=np.frombuffer(
        int(k).to_bytes(16, "big"), np.uint8).copy()), stamp=messages.time(int(k)))
    return T["action_msgs/msg/GoalStatusArray"](status_list=[T["action_msgs/msg/GoalStatus"](goal_info=info, status=int(status))])


def map_resolution(info) -> float:
    """A map's resolution (m per cell) as its message means it: the field is a float32, so 0.1 read
    from a bag is 0.10000000149; the shortest decimal that float32 holds (0.1), whether the
    message came from a bag or as rosbridge's JSON."""
    return float(str(np.float32(info.resolution)))


def map_frame(msg, margin: float = 0.0) -> GridFrame:
    """The grid of an OccupancyGrid's cells, grown by ``margin`` metres (whole cells) on every
    side; a ValueError for a map :func:`map_refusal` refuses or a grid of more than
    :data:`MAX_MAP_CELLS` cells."""
    why = map_refusal(msg)
    if why:
        raise ValueError(why)
    info = msg.info
    res = map_resolution(info)
    if not (math.isfinite(margin) and 0 <= margin <= MAX_MARGIN):
        raise ValueError(f"a margin of {margin:g} m: give one from 0 to {MAX_MARGIN:g} m")
    k = int(math.ceil(margin / res - 1e-9)) if margin > 0 else 0
    h, w = int(info.height) + 2 * k, int(info.width) + 2 * k
    if h * w > MAX_MAP_CELLS:
        raise ValueError(f"the first map and a margin of {margin:g} m around it make a grid of {w:,} x {h:,} cells at "
                         f"{res:g} m, more than {MAX_MAP_CELLS:,}: give a smaller --margin")
    return GridFrame(res, float(info.origin.position.x) - k * res, float(info.origin.position.y) - k * res, h, w)


def map_refusal(msg) -> str:
    """Why an OccupancyGrid cannot be folded into a grid ("" when it can): its resolution outside
    :data:`RESOLUTIONS`, its size past :data:`MAX_MAP_CELLS` or not that of its data, its origin
    not finite or past :data:`MAX_COORD`, or the map rotated in its frame."""
    info = msg.info
    res = float(info.resolution)
    if not (math.isfinite(res) and RESOLUTIONS[0] <= res <= RESOLUTIONS[1]):
        return f"a map at {res:g} m per cell (from {RESOLUTIONS[0]:g} to {RESOLUTIONS[1]:g} m are read)"
    h, w = int(info.height), int(info.width)
    if h * w > MAX_MAP_CELLS:
        return f"a map of {w:,} x {h:,} cells (at most {MAX_MAP_CELLS:,})"
    if len(msg.data) != h * w:
        return f"a map of {w} x {h} cells holding {len(msg.data)} values"
    o = info.origin.position
    if not all(math.isfinite(v) and abs(v) <= MAX_COORD for v in (float(o.x), float(o.y))):
        return f"a map whose origin ({float(o.x):g}, {float(o.y):g}) is not within {MAX_COORD:g} m"
    q = info.origin.orientation
    if abs(q.z) > 1e-6 or abs(q.x) > 1e-6 or abs(q.y) > 1e-6:
        return "a map rotated in its frame (origin orientation not 0)"
    return ""


def map_values(msg) -> tuple[np.ndarray, int]:
    """A map's values (h, w) int8 in the simulator's row order (row 0 at the top), a value outside
    -1..100 made unknown (-1); and how many were."""
    info = msg.info
    values = np.asarray(msg.data).astype(np.int16, copy=False).reshape(int(info.height), int(info.width))[::-1]
    odd = (values < -1) | (values > 100)
    n = int(odd.sum())
    return np.where(odd, -1, values).astype(np.int8), n


@dataclass
class Folded:
    """What :func:`fold_map` did: whether some of the map fell outside the grid (``clipped``),
    whether it was re-gridded from another resolution, and its cells outside -1..100 (taken as
    unknown)."""

    clipped: bool = False
    regridded: bool = False
    odd_cells: int = 0


def fold_map(belief, msg) -> Folded:
    """Fold a robot's OccupancyGrid (placed by its origin in the belief's grid) into the belief:
    -1 unknown, below ``FREE_BELOW`` free, else seen and not free. A map at another resolution
    than the grid's is re-gridded onto it (each grid cell takes the map cell under its centre);
    cells outside the grid are left out. The map must pass :func:`map_refusal`."""
    fr, info = belief.frame, msg.info
    values, odd = map_values(msg)
    h, w = values.shape
    res = map_resolution(info)
    ox, oy = float(info.origin.position.x), float(info.origin.position.y)
    if abs(res - fr.res) <= 1e-9:
        c0 = int(round((ox - fr.origin_x) / fr.res))
        y0 = int(round((oy - fr.origin_y) / fr.res))
        r0 = fr.height - y0 - h  # the map's top row in the simulator's rows (row 0 at the top)
        top, left = max(r0, 0), max(c0, 0)
        bottom, right = min(r0 + h, fr.height), min(c0 + w, fr.width)
        if bottom <= top or right <= left:
            return Folded(h * w > 0, False, odd)
        values = values[top - r0:bottom - r0, left - c0:right - c0]
        belief.fold_grid(top, left, values >= 0, (values >= 0) & (values < FREE_BELOW))
        return Folded(values.size < h * w, False, odd)
    # another resolution (a SLAM node that re-grids): the map cell under each grid cell's centre
    cols = np.arange(fr.width)
    rows = np.arange(fr.height)
    mc = np.floor((fr.origin_x + (cols + 0.5) * fr.res - ox) / res).astype(np.int64)
    mr = np.floor((oy + h * res - (fr.origin_y + (fr.height - rows - 0.5) * fr.res)) / res).astype(np.int64)  # from the top
    cin, rin = np.flatnonzero((mc >= 0) & (mc < w)), np.flatnonzero((mr >= 0) & (mr < h))
    covered = (ox >= fr.origin_x - 1e-9 and oy >= fr.origin_y - 1e-9 and ox + w * res <= fr.origin_x + fr.width * fr.res + 1e-9
               and oy + h * res <= fr.origin_y + fr.height * fr.res + 1e-9)
    if not len(cin) or not len(rin):
        return Folded(h * w > 0, True, odd)
    top, left = int(rin[0]), int(cin[0])
    window = values[np.ix_(mr[rin[0]:rin[-1] + 1], mc[cin[0]:cin[-1] + 1])]
    belief.fold_grid(top, left, window >= 0, (window >= 0) & (window < FREE_BELOW))
    return Folded(not covered, True, odd)


def within(*values, bound: float = MAX_COORD) -> bool:
    """Every value finite and at most ``bound`` from 0 (coordinates: :data:`MAX_COORD` m)."""
    return all(math.isfinite(v) and abs(v) <= bound for v in values)


def is_rotation(q) -> bool:
    """A quaternion a yaw can be read from: finite, and not all zeros (its norm need not be 1)."""
    quat = (float(q.x), float(q.y), float(q.z), float(q.w))
    return within(*quat, bound=1e6) and math.hypot(*quat) >= 1e-9


def stamp_refusal(stamp) -> str:
    """Why a builtin_interfaces/Time is not one ("" when it is): seconds past int32, nanoseconds
    outside 0..999,999,999."""
    sec, nsec = int(stamp.sec), int(stamp.nanosec)
    if not (-INT32 <= sec < INT32 and 0 <= nsec < 1_000_000_000):
        return f"a stamp of {sec} s {nsec} ns (not a builtin_interfaces/Time)"
    return ""


def pose_refusal(msg) -> str:
    """Why a PoseStamped or PoseWithCovarianceStamped is not a pose a search can take ("" when it
    is): its stamp, a coordinate not finite or past :data:`MAX_COORD`, an orientation that is
    not a rotation (not finite, or of norm 0)."""
    why = stamp_refusal(msg.header.stamp)
    if why:
        return why
    pose = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose
    p, q = pose.position, pose.orientation
    if not within(float(p.x), float(p.y)):
        return f"a pose at ({float(p.x):g}, {float(p.y):g}), not within {MAX_COORD:g} m"
    if not is_rotation(q):
        return f"a pose whose orientation {(float(q.x), float(q.y), float(q.z), float(q.w))} is not a rotation"
    return ""


def refusal(topic: str, msg) -> str:
    """Why a robot's message on ``topic`` is dropped ("" when it is taken): the check of each
    input topic (docs/robot.md, "What a robot may send")."""
    if topic == MAP:
        return map_refusal(msg)
    if topic in POSE_TYPES:
        return pose_refusal(msg)
    if topic == DETECTIONS:
        if len(msg.data) > MAX_DETECTION_BYTES:
            return f"a detection of {len(msg.data):,} characters (at most {MAX_DETECTION_BYTES:,})"
        return "" if detection_label(msg.data) is not None else 'not a detection (JSON {"label": ...} of a sign label)'
    if topic == RESUME:
        return "" if isinstance(msg.data, (bool, np.bool_)) else f"a resume of {msg.data!r}, not true or false"
    if topic == GOAL_STATUS:
        if len(msg.status_list) > MAX_LIST:
            return f"a status array of {len(msg.status_list):,} goals (at most {MAX_LIST:,})"
        return next(filter(None, (stamp_refusal(g.goal_info.stamp) for g in msg.status_list)), "")
    if topic in ("/tf", "/tf_static"):
        if len(msg.transforms) > MAX_LIST:
            return f"a TFMessage of {len(msg.transforms):,} transforms (at most {MAX_LIST:,})"
        for tr in msg.transforms:
            t = tr.transform.translation
            if not within(float(t.x), float(t.y)) or not is_rotation(tr.transform.rotation):
                return f"a transform to {tr.child_frame_id!r} that is not finite, within {MAX_COORD:g} m and a rotation"
    return ""


EIGHTH = math.pi / 4


def _yaw(q) -> float:
    """The yaw of a quaternion. One within 1e-9 rad of a multiple of 45 degrees is that multiple,
    as ``atan2`` gives it: a grid path's headings, which the quaternion gives back only to 1e-16
    rad, and nsos's heading histogram has bin edges on +-90 degrees, so that noise moved a pose of
    a robot driving along y into the neighbouring bin (docs/robot.md)."""
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    k = round(yaw / EIGHTH)
    if abs(yaw - k * EIGHTH) < 1e-9:
        return math.atan2(math.sin(k * EIGHTH), math.cos(k * EIGHTH))
    return yaw


def pose_of(msg) -> tuple[float, float, float]:
    """(x, y, yaw) of a PoseStamped or PoseWithCovarianceStamped."""
    pose = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose
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


def detection_label(data: str):
    """The label of a detection (``std_msgs/String`` JSON ``{"label": ...}``, the label a number or
    text), or None for a message that is not one."""
    try:
        label = json.loads(data)["label"]
        if isinstance(label, bool) or not isinstance(label, (int, float, str)):
            return None  # null, true, a list: what a detector writes for a sign it did not read
        return sign_label(label)
    except (ValueError, KeyError, TypeError, IndexError, RecursionError):  # not JSON, not an object, not a label
        return None


class GoalWriter(Observer):
    """A planner's decisions as the messages explore_lite's users look at (``/explore/frontiers``,
    ``/semsearch/goal``, ``/semsearch/decision``), given to ``sink(topic, stamp_ns, msg)`` (a
    bag's writer, a live robot's publishers), stamped at the input's time :attr:`t` (or just
    after the last one); :attr:`rows` keeps them."""

    def __init__(self, sink, messages, frame):
        self.sink, self.m, self.frame = sink, messages, frame
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
            self.sink(topic, self.last, msg)


class RobotSearch(DoorSearch):
    """The door search of a robot: the robot senses for itself, so a re-plan that would turn on
    the spot senses nothing."""

    found = False

    def sense(self, st: RobotState) -> tuple[bool, bool]:
        return False, False


class RobotSession:
    """One door search over a robot's messages (see the module's text), taken one at a time by
    :meth:`take`: it says when the goal's sign was read and when to re-plan, and :meth:`plan`
    re-plans; decisions go to ``observer``.

    Its planner is seated as in a batch (:class:`~semsearch_cli.tasks.decisions.Seat`, or the
    ``seat`` given): ``planner`` is a :class:`~semsearch_cli.planners.Variant` (built by the
    seat: a :class:`~semsearch_cli.tasks.decisions.Replay` seats a stand-in that answers from a
    record) or a built planner; the seat answers each decision point, keeps the planner's costs
    and transcript (a language model's calls, tokens and prompts: :meth:`seated`), and a
    :class:`~semsearch_cli.tasks.decisions.Recording` keeps the choices. The run's identity, as a
    planner that asks for it is given it: the scenario's name (``robot`` without one), goal,
    episode 0, seed 0."""

    def __init__(self, task: RobotTask, planner, goal, observer=None, pose_topic: str | None = None, seat: Seat | None = None):
        self.task, self.goal = task, sign_label(goal)
        self.st = RobotState(0.0, 0.0, 0.0, belief=task.new_belief())
        self.seat = seat if seat is not None else Seat()
        label = planner.label if isinstance(planner, Variant) else getattr(planner, "name", type(planner).__name__)
        self.seat.run = {"scenario": getattr(task.sc, "name", "robot"), "kind": "doors", "planner": label,
                         "goal": str(self.goal), "episode": 0, "seed": 0}
        planner = self.seat.planner(planner) if isinstance(planner, Variant) else self.seat.seat(planner)
        self.search = RobotSearch(task, planner, self.goal, np.random.default_rng(0), observer)
        self.pose_topic = pose_topic  # None: the first of POSE_TOPICS that speaks
        self.point = None  # the decision point a re-plan waits at (None when none is pending)
        self._plan = None  # the re-plan under way (a kind's search generator)
        self.pending: list = []  # labels read since the last pose
        self.have_map = self.posed = self.paused = self.clipped = self.inside = False
        self.since, self.event, self.done = 0.0, False, True  # done: the last goal ended (none yet at the start)
        self.ended: set = set()  # the goals whose end was taken (their UUIDs)
        self.dropped: Counter = Counter()  # (topic, reason) -> messages dropped (:func:`refusal`)
        self.regridded = self.odd_cells = 0  # maps re-gridded from another resolution; map cells outside -1..100

    @property
    def found(self) -> bool:
        return self.search.found

    def drop(self, topic: str, why: str) -> None:
        """Count a message of ``topic`` that is not taken, by its reason."""
        self.dropped[(topic, why)] += 1

    def take(self, topic: str, msg) -> str | None:
        """One message of the robot's (rosbags' message): ``"found"`` when it reads the goal's
        sign, ``"plan"`` when a re-plan is due now, else None. Topics: ``/map``, the pose
        (:attr:`pose_topic`), ``/semsearch/detections``, ``/explore/resume`` (False pauses the
        re-plans, True re-plans at once) and :data:`GOAL_STATUS` (a goal reached or given up on
        is a path done). A message :func:`refusal` refuses is dropped and counted."""
        if topic in POSE_TYPES and (self.pose_topic or topic) != topic:
            return None  # another pose topic than the one in use
        why = refusal(topic, msg)
        if why:
            self.drop(topic, why)
            return None
        if topic == MAP:
            self.map(msg)
        elif topic == DETECTIONS:
            if self.detection(detection_label(msg.data)):
                return "found"
        elif topic == RESUME:
            self.paused = not msg.data
            if not self.paused:
                self.done = True
                return "plan" if self.due() else None
        elif topic == GOAL_STATUS and msg.status_list:
            # the newest goal only: Nav2 aborts the goal a new one replaces, which is no path done
            newest = max(msg.status_list, key=lambda g: (g.goal_info.stamp.sec, g.goal_info.stamp.nanosec))
            uuid = bytes(newest.goal_info.goal_id.uuid)
            if newest.status in ENDS and uuid not in self.ended:
                self.ended.add(uuid)
                self.done = True
                return "plan" if self.due() else None
        elif topic in POSE_TYPES:
            self.pose_topic = topic
            return "plan" if self.pose(*pose_of(msg)) else None
        return None

    def map(self, msg) -> None:
        """Fold in a map (:attr:`clipped` tells whether some of a map fell outside the grid)."""
        folded = fold_map(self.st.belief, msg)
        self.clipped = folded.clipped or self.clipped
        self.regridded += folded.regridded
        self.odd_cells += folded.odd_cells
        self.have_map = True

    def dropped_text(self) -> str:
        """What was not taken as it came, in a sentence ("" when everything was)."""
        parts = [f"{n} {topic} ({why})" for (topic, why), n in sorted(self.dropped.items(), key=lambda kv: -kv[1])]
        if self.regridded:
            parts.append(f"{self.regridded} maps re-gridded to {self.task.world.frame.res:g} m")
        if self.odd_cells:
            parts.append(f"{self.odd_cells} map cells outside -1..100 taken as unknown")
        return "; ".join(parts)

    def detection(self, label) -> bool:
        """Take a label read; whether it is the goal's (the search is over)."""
        if label == self.goal:
            self.search.found = True
        else:
            self.pending.append(label)
        return self.search.found

    def pose(self, x: float, y: float, yaw: float) -> bool:
        """Take the robot's pose (a frame and a step); whether a re-plan is due."""
        st, fr = self.st, self.task.world.frame
        if self.posed:
            # the straight line from the pose before, to the nanometre: coordinates carry float noise
            # (14.95 - 14.85 is 0.10000000000000142), which is no travel, and summed unrounded puts
            # a periodic re-plan a step away from the simulator's, whose odometer adds 0.1
            moved = round(math.hypot(x - st.x, y - st.y), 9)
            st.distance += moved
            self.since += moved
        st.steps += self.posed  # the first pose is step 0
        if yaw == st.heading:  # one float for a heading that did not change: st.headings grows 8 bytes a pose, not 32
            yaw = st.heading
        st.x, st.y, st.heading, self.posed = x, y, yaw, True
        v, u, r, c = fr.point_to_cell(x, y)
        self.inside = 0 <= r < fr.height and 0 <= c < fr.width
        if not self.inside:  # off the grid (past the first map and its margin): travel counts, no re-plan from here
            return False
        b = st.belief
        for label in self.pending:
            if b.reads.add(label, r * fr.width + c, x, y, yaw) == b.spec.min_reads:
                self.event = True
        self.pending.clear()
        b.add_view(v, u, yaw)
        self.search.update(st)
        return self.due()

    def due(self) -> bool:
        return (self.have_map and self.posed and self.inside and not self.paused
                and self.search.replan_due(self.done, self.since, self.event))

    def replan(self):
        """Start a re-plan: its first decision point (returned, and kept as :attr:`point`: a
        :class:`~semsearch_cli.tasks.decisions.DecisionPoint`, answered by :meth:`answer` or
        :meth:`ask`), or the plan itself when it asks none (waypoints ``(xs, ys)`` m, or an
        outcome). The episode is stepped as an :class:`~semsearch_cli.tasks.base.OpenEpisode` is,
        fed by messages (:meth:`take`) instead of a simulator: ``ros live`` and ``ros replay`` step
        it with :meth:`ask` (:meth:`plan`); a front end that answers a robot's decisions itself (an
        operator choosing the frontier) with :meth:`answer`."""
        self.since, self.event, self.done = 0.0, False, False
        self._plan = self.search.plan(self.st)
        return self._go(None)

    @property
    def observation(self):
        """What a planner reads at the pending decision (None when none is pending)."""
        return None if self.point is None else self.point.observation

    @property
    def mask(self):
        """The legal choices of the pending decision (None when none is pending)."""
        return None if self.point is None else self.point.mask

    def answer(self, choice):
        """Take ``choice`` at the pending decision point of a re-plan; its next point or its plan."""
        self._pending()
        return self._go(choice)

    def ask(self):
        """Have the seat answer the pending decision point (the planner's answer, or a record's);
        its next point or its plan, as :meth:`answer`. A planner whose own budget is spent
        (:class:`~semsearch_cli.errors.BudgetSpent`) ends the re-plan as ``budget``."""
        point = self._pending()
        try:
            choice = self.seat.decide(point)
        except BudgetSpent as exc:
            return self._go(None, spent=exc)
        return self._go(choice)

    def _pending(self):
        if getattr(self, "_plan", None) is None or self.point is None:
            raise RuntimeError("no decision is pending: start a re-plan first (replan)")
        return self.point

    def _go(self, choice, spent: BaseException | None = None):
        self.point = None
        try:
            item = self._plan.throw(spent) if spent is not None else self._plan.send(choice)
        except StopIteration as stop:
            self._plan = None
            return stop.value
        except BudgetSpent:  # thrown back into the re-plan, which does not take it: the run's end
            self._plan = None
            return "budget"
        self.point = item
        return item

    def plan(self):
        """One re-plan, stepped to its end with each decision point answered by the seat (the
        planner): waypoints ``(xs, ys)`` (m), or an outcome (``stuck``: nowhere left to go;
        ``budget``: the planner's own budget, a language model's calls, is spent)."""
        item = self.replan()
        while isinstance(item, DecisionPoint):
            item = self.ask()
        return item

    def seated(self) -> dict:
        """What the seat kept of the run's planner: ``costs`` (column -> number, as a batch row's
        cost columns), ``transcripts`` (a language model's prompts and replies) and ``notes`` (why
        its own budget ended the run); and ``record``, the decisions record, when the seat is a
        :class:`~semsearch_cli.tasks.decisions.Recording` (None otherwise)."""
        s = self.seat
        record = s.record("doors") | s.run if isinstance(s, Recording) else None
        return {"costs": s.costs(), "transcripts": s.transcripts(), "notes": s.notes(), "record": record}

    def finish(self) -> None:
        """The run is over: the seat's checks at the end (a replayed transcript or record used up)."""
        self.seat.finish()
