"""ROS 2 messages of a door search, and the bag they are written to (`rosbags`, pure Python: no
ROS install). Topics, types and frames are :data:`TOPICS` (docs/robot.md lists them).

Frames: ``map`` (the world's metres: x right, y up) and ``base_link`` (the robot, x ahead);
``/tf`` carries map -> base_link at every step. Stamps are simulated time: step k at
``1 + k * step / SPEED`` seconds (a run has no clock of its own; ``SPEED`` is a Pioneer's cruise).
"""

from __future__ import annotations

import base64
import json
import math
import shutil
from pathlib import Path

import numpy as np

from ..config.base import sign_label
from ..optional import lazy_module

typesys = lazy_module("rosbags.typesys", "ros")  # optional: pip install 'semsearch[ros]'
rosbag2 = lazy_module("rosbags.rosbag2", "ros")
interfaces = lazy_module("rosbags.interfaces", "ros")

SIGN_RGBA, GOAL_RGBA, CAND_RGBA = (0.1, 0.3, 0.9, 1.0), (0.9, 0.1, 0.1, 1.0), (1.0, 0.6, 0.0, 0.9)  # markers' colours
SPEED = 0.5  # m/s: the simulated clock's robot speed (stamps only)
START_NS = 1_000_000_000  # the first step's stamp (1 s: some tools read 0 as "no stamp")

# topic -> (message type, when it is published, what it holds)
TOPICS = {
    "/semsearch/setup": ("std_msgs/msg/String", "once, first",
                         'JSON {"scenario", "file", "fingerprint", "engine", "rng_inc", "goal", "planner", "episode", "seed"}: '
                         'the run this bag records (its scenario\'s name, file name and fingerprint; the simulator engine it '
                         'ran on; its generator\'s increment)'),
    "/map": ("nav_msgs/msg/OccupancyGrid", "at the start, at each decision and at the end",
             "the belief over the whole grid: -1 never seen, 0 free, 100 occupied"),
    "/semsearch/map_updates": ("map_msgs/msg/OccupancyGridUpdate", "each frame that changed the map",
                               "the cells it changed (their bounding box), as RViz's map update topic"),
    "/scan": ("sensor_msgs/msg/LaserScan", "every frame", "the laser scan folded into the belief (m; +inf: no return)"),
    "/tf": ("tf2_msgs/msg/TFMessage", "every frame", "map -> base_link"),
    "/semsearch/pose": ("geometry_msgs/msg/PoseStamped", "every frame", "the robot's pose in map"),
    "/semsearch/path": ("nav_msgs/msg/Path", "at the first decision, the first after each further 5 m, and at the end",
                        "the path travelled so far, a pose every 0.5 m"),
    "/semsearch/detections": ("std_msgs/msg/String", "each sign read",
                              'JSON {"label", "x", "y", "facing"}: the sign read (m, rad) and its label as read'),
    "/semsearch/signs": ("visualization_msgs/msg/MarkerArray", "when a sign is read for the first time, and at the start",
                         "every sign read so far as a text marker (its label), the goal's number at the top left"),
    "/explore/frontiers": ("visualization_msgs/msg/MarkerArray", "at each decision",
                           "the frontier candidates (spheres, as explore_lite publishes its frontiers)"),
    "/semsearch/goal": ("geometry_msgs/msg/PoseStamped", "at each decision", "the chosen target, facing along its branch"),
    "/semsearch/decision": ("std_msgs/msg/String", "at each decision", "JSON: the decision's row (as --trace writes it)"),
    "/semsearch/events": ("std_msgs/msg/String", "each frame, step and re-plan",
                          'JSON {"event": "frame" (step, x, y, heading, reads: the labels read, found: the goal\'s sign '
                          'among them, rng inside a re-plan), "step" (step, x, y, heading, distance: where the visited kernel '
                          'is marked), "plan" (step, "start" with rng, or "end")}: what `semsearch ros replay` replays'),
}
FORMATS = {"mcap": "MCAP", "rosbag2": "SQLITE3"}  # --format -> rosbags' storage plugin
UPDATE = "map_msgs/msg/OccupancyGridUpdate"
UPDATE_MSG = "std_msgs/Header header\nint32 x\nint32 y\nuint32 width\nuint32 height\nint8[] data\n"


def map_states(seen: np.ndarray, free: np.ndarray) -> np.ndarray:
    """A belief's map as an OccupancyGrid's values (int8): -1 never seen, 0 free, 100 occupied."""
    return np.where(seen, np.where(free, 0, 100), -1).astype(np.int8)


def stamp_ns(step: int, step_m: float) -> int:
    """The stamp (ns) of step ``step`` of a run whose steps are ``step_m`` metres."""
    return START_NS + int(round(step * step_m / SPEED * 1e9))


def step_of(stamp: int, step_m: float) -> int:
    """The step whose stamp is ``stamp`` (:func:`stamp_ns`'s inverse)."""
    return int(round((stamp - START_NS) * SPEED / step_m / 1e9))


class Messages:
    """Builds the messages of :data:`TOPICS` (rosbags' ROS 2 Humble types)."""

    def __init__(self):
        self.ts = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
        if UPDATE not in self.ts.types:  # not among rosbags' Humble types: its definition, from map_msgs
            self.ts.register(typesys.get_types_from_msg(UPDATE_MSG, UPDATE))
        self.T = self.ts.types

    def serialize(self, msg) -> bytes:
        return self.ts.serialize_cdr(msg, msg.__msgtype__)

    # -- parts -------------------------------------------------------------------------
    def header(self, t_ns: int, frame: str = "map"):
        return self.T["std_msgs/msg/Header"](stamp=self.time(t_ns), frame_id=frame)

    def time(self, t_ns: int):
        """A builtin_interfaces/Time of ``t_ns`` nanoseconds."""
        return self.T["builtin_interfaces/msg/Time"](sec=int(t_ns // 1_000_000_000), nanosec=int(t_ns % 1_000_000_000))

    def pose(self, x: float, y: float, yaw: float):
        P = self.T
        return P["geometry_msgs/msg/Pose"](position=P["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
                                           orientation=self._quat(yaw))

    def _quat(self, yaw: float):
        return self.T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    # -- messages ----------------------------------------------------------------------
    def pose_stamped(self, t_ns: int, x: float, y: float, yaw: float):
        return self.T["geometry_msgs/msg/PoseStamped"](header=self.header(t_ns), pose=self.pose(x, y, yaw))

    def tf(self, t_ns: int, x: float, y: float, yaw: float):
        P = self.T
        tr = P["geometry_msgs/msg/Transform"](translation=P["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=0.0),
                                              rotation=self._quat(yaw))
        ts = P["geometry_msgs/msg/TransformStamped"](header=self.header(t_ns), child_frame_id="base_link", transform=tr)
        return P["tf2_msgs/msg/TFMessage"](transforms=[ts])

    def grid(self, t_ns: int, states: np.ndarray, frame) -> object:
        """The map over the whole grid from ``states`` (H, W) int8 (-1 never seen, 0 free, 100
        occupied; a few kilobytes once compressed, unknown cells being most), rows flipped to
        ROS's order (row 0 at the lowest y), its origin the grid's lower-left corner."""
        P = self.T
        info = P["nav_msgs/msg/MapMetaData"](map_load_time=self.time(t_ns), resolution=float(frame.res),
                                             width=int(frame.width), height=int(frame.height),
                                             origin=self.pose(frame.origin_x, frame.origin_y, 0.0))
        return P["nav_msgs/msg/OccupancyGrid"](header=self.header(t_ns), info=info,
                                               data=np.ascontiguousarray(states[::-1]).ravel())

    def grid_update(self, t_ns: int, states: np.ndarray, r0: int, c0: int, height: int) -> object:
        """``states`` (h, w) int8 of the grid's cells from row ``r0``, column ``c0`` (the
        simulator's rows, row 0 at the top of a grid of ``height`` rows) as a
        map_msgs/OccupancyGridUpdate of /map (x, y: the window's first cell in ROS's order)."""
        h, w = states.shape
        return self.T[UPDATE](header=self.header(t_ns), x=int(c0), y=int(height - r0 - h), width=int(w), height=int(h),
                              data=np.ascontiguousarray(states[::-1]).ravel())

    def scan(self, t_ns: int, thetas: np.ndarray, dist_cells: np.ndarray, hit: np.ndarray, heading: float, res: float,
             max_range: float):
        """The scan in base_link: beams evenly spaced from ``thetas[0]`` (world) relative to the
        heading, ranges in m, +inf where a beam returned nothing."""
        rel = np.asarray(thetas, float) - heading
        inc = float(rel[1] - rel[0]) if rel.size > 1 else 0.0
        ranges = np.where(np.asarray(hit, bool), np.asarray(dist_cells, float) * res, np.inf).astype(np.float32)
        return self.T["sensor_msgs/msg/LaserScan"](header=self.header(t_ns, "base_link"), angle_min=float(rel[0]),
                                                   angle_max=float(rel[-1]), angle_increment=inc, time_increment=0.0,
                                                   scan_time=0.0, range_min=0.0, range_max=float(max_range), ranges=ranges,
                                                   intensities=np.zeros(0, np.float32))

    def path(self, t_ns: int, trail) -> object:
        xy = np.asarray(trail, float).reshape(-1, 2)
        poses = []
        for k in range(len(xy)):
            yaw = math.atan2(xy[k, 1] - xy[k - 1, 1], xy[k, 0] - xy[k - 1, 0]) if k else 0.0
            poses.append(self.pose_stamped(t_ns, xy[k, 0], xy[k, 1], yaw))
        return self.T["nav_msgs/msg/Path"](header=self.header(t_ns), poses=poses)

    def string(self, obj) -> object:
        return self.T["std_msgs/msg/String"](data=json.dumps(obj, separators=(",", ":")))

    def detection(self, signs, i: int, label) -> object:
        """A sign detection (``/semsearch/detections``): sign ``i`` of ``signs`` read as ``label``."""
        return self.string({"label": sign_label(label), "x": float(signs.x[i]), "y": float(signs.y[i]),
                            "facing": float(signs.facing[i])})

    def marker(self, t_ns: int, ns: str, mid: int, kind: str, x: float, y: float, rgba, scale: float, text: str = ""):
        P = self.T
        M = P["visualization_msgs/msg/Marker"]
        return M(header=self.header(t_ns), ns=ns, id=int(mid), type=getattr(M, kind), action=M.ADD, pose=self.pose(x, y, 0.0),
                 scale=P["geometry_msgs/msg/Vector3"](x=scale, y=scale, z=scale),
                 color=P["std_msgs/msg/ColorRGBA"](r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3]),
                 lifetime=P["builtin_interfaces/msg/Duration"](sec=0, nanosec=0), frame_locked=False, points=[], colors=[],
                 texture_resource="", texture=P["sensor_msgs/msg/CompressedImage"](header=self.header(t_ns), format="",
                                                                                     data=np.zeros(0, np.uint8)),
                 uv_coordinates=[], text=text, mesh_resource="",
                 mesh_file=P["visualization_msgs/msg/MeshFile"](filename="", data=np.zeros(0, np.uint8)),
                 mesh_use_embedded_materials=False)

    def delete_all(self, t_ns: int, ns: str):
        M = self.T["visualization_msgs/msg/Marker"]
        m = self.marker(t_ns, ns, 0, "SPHERE", 0.0, 0.0, (0.0, 0.0, 0.0, 0.0), 0.1)
        m.action = M.DELETEALL
        return m

    def markers(self, items) -> object:
        return self.T["visualization_msgs/msg/MarkerArray"](markers=list(items))

    def frontiers(self, t_ns: int, frame, cands, decision, target_xy) -> tuple:
        """A decision as explore_lite would show it: (/explore/frontiers, the candidates as
        spheres, the chosen one larger and red; /semsearch/goal, the target facing along its
        branch)."""
        cx, cy = frame.to_world(cands.rows, cands.cols)
        chosen = np.flatnonzero((cands.rows == decision.row) & (cands.cols == decision.col))
        items = [self.delete_all(t_ns, "frontiers")]
        items += [self.marker(t_ns, "frontiers", j, "SPHERE", cx[j], cy[j], GOAL_RGBA if j in chosen else CAND_RGBA,
                              0.5 if j in chosen else 0.35) for j in range(len(cands))]
        yaw = float(cands.theta[chosen[0]]) if chosen.size else 0.0
        return self.markers(items), self.pose_stamped(t_ns, *target_xy, yaw)


class BagWriter:
    """A ROS 2 bag folder (``metadata.yaml`` and one storage file: MCAP or SQLite 3) written with
    rosbags, zstd-compressed (MCAP's chunks, or each SQLite message), one connection per topic
    (of its first message's type) as it is first written."""

    def __init__(self, out: Path, fmt: str, messages: Messages):
        self.msgs = messages
        plugin = getattr(rosbag2.StoragePlugin, FORMATS[fmt])
        self.writer = rosbag2.Writer(Path(out), version=rosbag2.Writer.VERSION_LATEST, storage_plugin=plugin)
        mode = rosbag2.CompressionMode.STORAGE if fmt == "mcap" else rosbag2.CompressionMode.MESSAGE
        self.writer.set_compression(mode, rosbag2.CompressionFormat.ZSTD)
        self.writer.open()
        self.conns: dict = {}
        self.count = 0

    def write(self, topic: str, t_ns: int, msg) -> None:
        conn = self.conns.get(topic)
        if conn is None:
            conn = self.conns[topic] = self.writer.add_connection(topic, msg.__msgtype__, typestore=self.msgs.ts)
        self.writer.write(conn, int(t_ns), self.msgs.serialize(msg))
        self.count += 1

    def close(self) -> None:
        self.writer.close()


def drop_bag(writer: BagWriter | None, work: Path) -> None:
    """Close and remove a bag that will not be kept (``work``: the hidden folder it was written in)."""
    try:
        if writer is not None:
            writer.close()
    except Exception:  # noqa: BLE001  a bag half written is removed whatever closing it says
        pass
    finally:
        shutil.rmtree(work, ignore_errors=True)


def to_json(msg) -> dict:
    """A message (rosbags' dataclass) as rosbridge's JSON holds it: fields by name, arrays as
    lists, ``uint8[]`` as base64 text (rosbridge's rule for bytes)."""
    out = {}
    for name in msg.__dataclass_fields__:
        if name == "__msgtype__":
            continue
        v = getattr(msg, name)
        if isinstance(v, np.ndarray):
            out[name] = base64.b64encode(v.tobytes()).decode() if v.dtype == np.uint8 else v.tolist()
        elif isinstance(v, list):
            out[name] = [to_json(e) if hasattr(e, "__dataclass_fields__") else e for e in v]
        elif hasattr(v, "__dataclass_fields__"):
            out[name] = to_json(v)
        else:
            out[name] = v
    return out


_FLOATS = ("float32", "float64")
_INTS = {f"{u}int{n}": (0, 2**n - 1) if u else (-(2**(n - 1)), 2**(n - 1) - 1) for u in ("", "u") for n in (8, 16, 32, 64)}
_INTS.update(byte=(0, 255), char=(0, 255), octet=(0, 255))


def _base(desc: str, v, where: str):
    """A JSON value as a message's base field of type ``desc``, checked as ROS checks it: a bool is
    true or false, a number is a number (not text) and an integer fits its type; a ValueError
    naming the field otherwise."""
    if v is None:
        return {"bool": False, "string": ""}.get(desc, 0.0 if desc in _FLOATS else 0)
    if desc == "bool":
        if isinstance(v, bool):
            return v
    elif desc == "string":
        if isinstance(v, str):
            return v
    elif desc in _FLOATS:
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return float(v)
    elif desc in _INTS:
        lo, hi = _INTS[desc]
        if isinstance(v, int) and not isinstance(v, bool) and lo <= v <= hi:
            return v
        if isinstance(v, float) and v.is_integer() and lo <= v <= hi:
            return int(v)
    raise ValueError(f"{where} is {str(v)[:40]!r}, not a {desc}")


def _array(desc: str, v, count: int, where: str) -> np.ndarray:
    """A JSON list as a message's array of base type ``desc`` (``count``: a fixed length, 0 for a
    sequence), each value checked as :func:`_base` checks it, at numpy's speed."""
    if v is None:
        v = [0] * count
    if not isinstance(v, list) or (count and len(v) != count):
        raise ValueError(f"{where} is not a list{f' of {count}' if count else ''}")
    if desc == "bool":
        if not all(isinstance(e, bool) for e in v):
            raise ValueError(f"{where} holds a value that is not true or false")
        return np.asarray(v, bool)
    try:
        a = np.asarray(v) if v else np.zeros(0)
    except (TypeError, ValueError):  # ragged
        raise ValueError(f"{where} is not a list of numbers") from None
    if a.ndim != 1 or a.dtype.kind not in "iuf":  # text, lists, objects, integers past int64
        raise ValueError(f"{where} is not a list of numbers")
    if desc in _FLOATS:
        return a.astype(desc)
    lo, hi = _INTS[desc] if desc in _INTS else (None, None)
    if lo is None or a.dtype.kind == "f" or (len(a) and (a.min() < lo or a.max() > hi)):
        raise ValueError(f"{where} holds a value that is not a {desc}")
    return a.astype(desc)


def from_json(ts, msgtype: str, d: dict, where: str = ""):
    """A rosbridge JSON message of type ``msgtype`` as rosbags' dataclass (:func:`to_json`'s
    inverse), through the typestore's field definitions; a field the JSON leaves out takes its
    zero value, as a ROS message's default. A value that is not of its field's type (text for a
    number, 200 for an int8, a list for a message) is a ValueError naming the field."""
    d = {} if d is None else d
    if not isinstance(d, dict):
        raise ValueError(f"{where or msgtype} is {type(d).__name__}, not a {msgtype} object")
    _, fields = ts.fielddefs[msgtype]
    values = {}
    for name, (node, desc) in fields:
        v, at = d.get(name), f"{where}.{name}" if where else name
        if node == interfaces.Nodetype.NAME:
            values[name] = from_json(ts, desc, v, at)
        elif node == interfaces.Nodetype.BASE:
            values[name] = _base(desc[0], v, at)
        else:
            (sub, subdesc), count = desc  # count: an array's fixed length (0: a sequence)
            if sub == interfaces.Nodetype.NAME:
                if v is not None and not isinstance(v, list):
                    raise ValueError(f"{at} is not a list")
                values[name] = [from_json(ts, subdesc, e, f"{at}[{i}]") for i, e in enumerate(v or [])]
            elif subdesc[0] == "string":
                if v is not None and not (isinstance(v, list) and all(isinstance(e, str) for e in v)):
                    raise ValueError(f"{at} is not a list of text")
                values[name] = list(v or [])
            elif subdesc[0] in ("uint8", "char") and isinstance(v, str):
                try:
                    values[name] = np.frombuffer(base64.b64decode(v, validate=True), np.uint8).copy()
                except ValueError:
                    raise ValueError(f"{at} is text that is not base64") from None
            else:
                values[name] = _array(subdesc[0], v, count, at)
    return ts.types[msgtype](**values)
