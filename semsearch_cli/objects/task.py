"""The object-search task (thesis ch. 5, SPEC 6): places, timelines, cases, requests, ground truth,
the object camera, navigation on the recorded map and the recording mode.

Choices the seeds leave open (also in the README):

- **Timelines.** ``timelines[pattern][class] = {hour: place(s)}``: from that hour on the class
  stands at those places, until the next listed hour (the clock wraps, so before the first entry
  of a day the last entry of the previous day holds). Table 5.2's ground truth is then the timeline
  at the request hour: at 12:00 the 11:00 entry, at 00:00 the 23:00 entry, as the thesis states.
- **Recording.** At each recording hour the robot drives the patrol route (start, the places in
  route order, back to the start) on the known map with the object camera on. Each object
  instance is logged once per patrol, at its first detection: (day, hour, class, x, y, robot_x,
  robot_y, place). A case recording several timelines gives each its own day, in the order given,
  so "most recent" (Last Seen) means the last hour of the last day.
- **The map in requesting mode** is the one the recording built; we take it as complete (the
  patrols cover the building), so the robot plans on the ground-truth free space, with its
  clearance, and no laser is simulated. Q of Eq. 5.2 is 1 on the building's cells (free cells and
  the walls bounding them) and 0 elsewhere.
- **Object camera**: forward field of view and range, line of sight against walls, each visible
  instance detected with probability ``p_detect`` per frame (one frame per step of travel and
  per quarter turn).
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from ..config import ObjectsSpec, Scenario
from ..errors import ScenarioError
from ..geometry import wrap_angle
from ..gridalg import GridSearch, dijkstra
from ..sensors.raycast import line_of_sight

LOG_COLUMNS = ["day", "hour", "class", "x", "y", "robot_x", "robot_y", "place"]


def request_label(case: str, cls: str, hour: float) -> str:
    """``Static.mug@12``: the goal column of an object-search run."""
    return f"{case}.{cls}@{hour:g}"


def parse_label(label: str) -> tuple[str, str, float]:
    """Inverse of :func:`request_label`: (case, class, hour)."""
    head, hour = str(label).rsplit("@", 1)
    case, cls = head.split(".", 1)
    return case, cls, float(hour)


def is_object_label(label) -> bool:
    try:
        parse_label(label)
        return True
    except ValueError:
        return False


@dataclass(frozen=True)
class Request:
    case: str
    cls: str
    hour: float
    truth: tuple  # places holding the class at the request hour

    @property
    def label(self) -> str:
        return request_label(self.case, self.cls, self.hour)


@dataclass(frozen=True)
class Case:
    name: str
    record: tuple  # timeline names (one day each) or (csv path,)
    log_file: str | None
    truth: str | None
    requests: tuple


def _places_of(v) -> tuple:
    if v is None:
        return ()
    return (v,) if isinstance(v, str) else tuple(v)


def timeline_at(timeline: dict, hour: float) -> dict[str, tuple]:
    """class -> places at ``hour``: the latest entry at or before it, wrapping to the previous day."""
    out = {}
    for cls, entries in timeline.items():
        if not entries:
            continue
        hs = sorted(entries)
        before = [h for h in hs if h <= hour]
        out[cls] = _places_of(entries[before[-1] if before else hs[-1]])
    return out


class KnownMap:
    """Planning on the recorded (complete) map: cells where the robot fits, reachable from the
    start, with a cost that keeps paths off the walls (1 in the open, up to 3 against a wall)."""

    def __init__(self, world):
        self.world = world
        self.passable = world.reach
        clear = np.minimum(world.clearance, 1.0)
        self.cost = (3.0 - 2.0 * clear).astype(np.float32)
        self.search = GridSearch(self.passable.shape)
        self._paths: dict = {}  # (r, c, tr, tc) -> cells: patrol legs repeat across hours and runs

    def snap(self, r: int, c: int) -> tuple[int, int]:
        """The reachable cell nearest to (r, c)."""
        H, W = self.passable.shape
        for R in (4, 16, 64, max(H, W)):
            r0, r1, c0, c1 = max(0, r - R), min(H, r + R + 1), max(0, c - R), min(W, c + R + 1)
            rr, cc = np.nonzero(self.passable[r0:r1, c0:c1])
            if rr.size:
                k = int(np.argmin((rr + r0 - r) ** 2 + (cc + c0 - c) ** 2))
                return int(rr[k] + r0), int(cc[k] + c0)
        raise ValueError("no reachable cell")

    def path(self, r: int, c: int, tr: int, tc: int):
        """Cells from (r, c) to (tr, tc) (both reachable), or None."""
        if not self.passable[r, c]:
            r, c = self.snap(r, c)
        key = (r, c, tr, tc)
        if key not in self._paths:
            if len(self._paths) > 4096:
                self._paths.clear()
            ok = self.search.run(self.passable, self.cost, r, c, np.array([tr]), np.array([tc]), 1) >= 1
            self._paths[key] = self.search.path(tr, tc) if ok else None
        return self._paths[key]


def detect_probability(p, distance: float, view_deg: float) -> float:
    """p_detect of the camera spec: a constant, or a :class:`~semsearch_cli.config.DetectTable`
    read at ``distance`` (m, linear, clamped) and ``view_deg`` (nearest tabulated angle)."""
    if isinstance(p, (int, float)):
        return float(p)
    row = 0
    if p.angles:
        a = np.asarray(p.angles, float)
        diff = np.abs((a - view_deg + 180.0) % 360.0 - 180.0)
        row = int(np.argmin(diff))
    return float(np.interp(distance, p.distances, p.p[row]))


class ObjectCamera:
    """Forward camera: points within ``range`` (m) and ``fov`` (degrees) around the heading, in
    line of sight."""

    def __init__(self, world, fov: float, range_m: float, xs, ys):
        self.world, self.range = world, range_m
        self.x, self.y = np.asarray(xs, float), np.asarray(ys, float)
        self.v, self.u = world.frame.to_cell(self.x, self.y)
        self.half = np.radians(fov) / 2

    def visible(self, x: float, y: float, heading: float) -> np.ndarray:
        """Indices of the points in view from pose (x, y, heading)."""
        if self.x.size == 0:
            return np.zeros(0, np.int64)
        dx, dy = self.x - x, self.y - y
        near = np.flatnonzero(dx * dx + dy * dy <= self.range**2)
        if near.size and self.half < np.pi:
            rel = np.abs(wrap_angle(np.arctan2(dy[near], dx[near]) - heading))
            near = near[rel <= self.half]
        v, u = self.world.frame.to_cell(x, y)
        occ = self.world.occ
        return np.array([i for i in near if line_of_sight(occ, float(v), float(u), self.v[i], self.u[i], 0.5)], np.int64)


class ObjectTask:
    """Everything an object-search scenario asks, checked against the world."""

    def __init__(self, sc: Scenario, world, base: Path, file: str):
        spec: ObjectsSpec = sc.objects
        self.sc, self.spec, self.world, self.base, self.file = sc, spec, world, base, file
        names = [p.name for p in spec.places]
        if len(set(names)) != len(names):
            raise ScenarioError(file, "objects.places", "place names must be unique")
        self.places = {p.name: (p.x, p.y) for p in spec.places}
        self.facing = {p.name: float(np.radians(p.facing)) for p in spec.places}
        fr = world.frame
        for k, p in enumerate(spec.places):
            r, c = fr.to_index(p.x, p.y)
            if not (0 <= r < fr.height and 0 <= c < fr.width):
                raise ScenarioError(file, f"objects.places[{k}]", f"place {p.name} at ({p.x}, {p.y}) m lies outside the map")
            if not self.view_mask(p.x, p.y).any():
                raise ScenarioError(file, f"objects.places[{k}]", f"place {p.name} at ({p.x}, {p.y}) m cannot be seen by the "
                                    f"object camera ({spec.camera.max_range} m range) from any pose reachable from the start")
        self.route = list(spec.route) if spec.route is not None else names
        for k, n in enumerate(self.route):
            self._check_place(n, f"objects.route[{k}]")
        for place, cls in spec.fixed.items():
            self._check_place(place, f"objects.fixed.{place}")
        for pat, tl in spec.timelines.items():
            for cls, entries in tl.items():
                for h, v in entries.items():
                    if not 0 <= h < 24:
                        raise ScenarioError(file, f"objects.timelines.{pat}.{cls}", f"hour {h} is not in 0-24")
                    for n in _places_of(v):
                        self._check_place(n, f"objects.timelines.{pat}.{cls}.{h:g}")
        self.cases = self._cases()
        self._recorded: dict[str, pd.DataFrame] = {}  # timeline -> its log (the same in every case)
        self.requests = [r for c in self.cases for r in c.requests]
        labels = [r.label for r in self.requests]
        if not labels:
            raise ScenarioError(file, "objects.requests", "no requests: give at least one {class, hour}")
        if len(set(labels)) != len(labels):
            raise ScenarioError(file, "objects.requests", "a request (case, class, hour) appears twice")

    def _check_place(self, name, field):
        if name not in self.places:
            raise ScenarioError(self.file, field, f"unknown place {name!r}; places are {', '.join(self.places)}")

    def _cases(self) -> list[Case]:
        spec, file = self.spec, self.file
        raw = spec.cases if spec.cases is not None else [
            {"name": n, "record": [n], "truth": n, "requests": None} for n in spec.timelines]
        if not raw:
            raise ScenarioError(file, "objects", "give timelines (one case each) or cases")
        out = []
        for k, c in enumerate(raw):
            c = c if isinstance(c, dict) else c.model_dump(by_alias=True)
            rec = c["record"]
            log_file = None
            if isinstance(rec, str):
                log_file, rec = rec, [rec]
                if not (self.base / log_file).is_file():
                    raise ScenarioError(file, f"objects.cases[{k}].record", f"detection log {self.base / log_file} not found")
            else:
                for n in rec:
                    if n not in spec.timelines:
                        raise ScenarioError(file, f"objects.cases[{k}].record", f"unknown timeline {n!r}; timelines are {', '.join(spec.timelines)}")
            truth = c.get("truth")
            if truth is not None and truth not in spec.timelines:
                raise ScenarioError(file, f"objects.cases[{k}].truth", f"unknown timeline {truth!r}")
            reqs = []
            for j, r in enumerate(c.get("requests") or spec.requests):
                r = r if isinstance(r, dict) else r.model_dump(by_alias=True)
                if r.get("at") is not None:
                    for n in r["at"]:
                        self._check_place(n, f"objects.cases[{k}].requests[{j}].at")
                    at = tuple(r["at"])
                elif truth is not None:
                    at = timeline_at(spec.timelines[truth], r["hour"]).get(r["class"], ())
                    at = tuple(sorted(set(at) | {p for cl, p in self._fixed() if cl == r["class"]}))
                else:
                    raise ScenarioError(file, f"objects.cases[{k}]", "give truth (a timeline) or requests with at: the ground truth")
                reqs.append(Request(c["name"], r["class"], float(r["hour"]), at))
            out.append(Case(c["name"], tuple(rec), log_file, truth, tuple(reqs)))
        return out

    def _fixed(self) -> list[tuple[str, str]]:
        """(class, place) of the objects that stand at their place all day."""
        return [(cl, p) for p, v in self.spec.fixed.items() for cl in _places_of(v)]

    def case(self, name: str) -> Case:
        return next(c for c in self.cases if c.name == name)

    def request(self, label: str) -> Request:
        return next(r for r in self.requests if r.label == str(label))

    # ----------------------------------------------------------------- world state
    def instances(self, timeline: str | None, hour: float) -> list[tuple[str, str]]:
        """(class, place) standing at ``hour``: fixed objects plus the timeline's."""
        out = list(self._fixed())
        if timeline is not None:
            for cls, places in timeline_at(self.spec.timelines[timeline], hour).items():
                out += [(cls, p) for p in places]
        return out

    def request_instances(self, req: Request) -> list[tuple[str, str]]:
        """The world at a request: the truth timeline's other classes and the fixed objects, with
        the target class where the request's ground truth puts it."""
        case = self.case(req.case)
        others = [(cl, p) for cl, p in self.instances(case.truth, req.hour) if cl != req.cls]
        return others + [(req.cls, p) for p in req.truth]

    def view_mask(self, x: float, y: float, rng: float | None = None) -> np.ndarray:
        """Reachable cells from which a point at (x, y) is within ``rng`` (default: the camera's
        longest range) and in line of sight."""
        return self.world.sight_mask(x, y, self.spec.camera.max_range if rng is None else rng, 0.5)

    @cached_property
    def start_distance(self) -> np.ndarray:
        """Geodesic length (m) from the start to every reachable cell."""
        r, c = self.world.start_cell
        _, length, _ = dijkstra(self.world.reach, np.ones((1, 1), np.float32), np.array([r]), np.array([c]),
                                np.zeros_like(self.world.reach), 0, np.inf)
        return length * self.world.frame.res

    def shortest(self, req: Request) -> float:
        """Geodesic from the start to the nearest pose that sees an instance of the target
        (heading free); inf when the request's ground truth holds none."""
        best = np.inf
        rng = self.spec.camera.for_class(req.cls)[1]
        for p in req.truth:
            m = self.view_mask(*self.places[p], rng)
            if m.any():
                best = min(best, float(self.start_distance[m].min()))
        return best

    @cached_property
    def known_map(self) -> KnownMap:
        return KnownMap(self.world)

    @cached_property
    def known(self) -> np.ndarray:
        """Q of Eq. 5.2 on the recorded map: free cells and the walls that bound them."""
        free = self.world.free.astype(np.uint8)
        return cv2.dilate(free, np.ones((3, 3), np.uint8)).astype(bool)

    # ----------------------------------------------------------------- recording
    def log(self, case: Case) -> pd.DataFrame:
        """The case's detection log: read from its CSV, or recorded by patrolling its timelines."""
        if case.log_file is not None:
            return read_log(self.base / case.log_file)
        frames = []
        for day, tl in enumerate(case.record):
            if tl not in self._recorded:
                self._recorded[tl] = record(self, tl, self.spec.recording_hours, 0, self.sc.experiment.base_seed)
            frames.append(self._recorded[tl].assign(day=day))
        return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=LOG_COLUMNS)


def read_log(path: Path) -> pd.DataFrame:
    """A detection log CSV: class, x, y, hour, robot_x, robot_y (day and place optional)."""
    try:
        df = pd.read_csv(path)
    except (pd.errors.ParserError, UnicodeDecodeError, pd.errors.EmptyDataError) as exc:
        raise ScenarioError(str(path), "", f"not a readable CSV: {exc}") from None
    need = {"class", "x", "y", "hour", "robot_x", "robot_y"}
    if not need <= set(df.columns):
        raise ScenarioError(str(path), "", f"expected columns {', '.join(sorted(need))} (got {', '.join(df.columns)})")
    for col in ("x", "y", "hour", "robot_x", "robot_y"):
        if pd.to_numeric(df[col], errors="coerce").isna().any():
            raise ScenarioError(str(path), col, "must be numbers on every row")
    if "day" not in df:
        df["day"] = 0
    if "place" not in df:
        df["place"] = ""
    df["class"] = df["class"].astype(str)
    return df[LOG_COLUMNS]


def write_log(df: pd.DataFrame, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    df.to_csv(tmp, index=False, float_format="%.3f")
    tmp.replace(path)


def record(task: ObjectTask, timeline: str, hours, day: int = 0, base_seed: int = 0) -> pd.DataFrame:
    """Recording mode: one patrol (start, the route's places, back to the start) at each hour
    with the objects of ``timeline`` at that hour; each instance is logged at its first detection
    of the patrol. Seeded by (base_seed, timeline, hour), so the log is the same on every call."""
    from .search import Drive

    rows = []
    for hour in hours:
        inst = task.instances(timeline, hour)
        rng = np.random.default_rng([base_seed, zlib.crc32(timeline.encode()), int(round(hour * 60))])
        drive = Drive(task, inst, rng, heading=task.world.start_heading or 0.0)
        logged: set[int] = set()

        def on_detect(i, x, y, hour=hour, inst=inst, logged=logged):
            if i not in logged:
                logged.add(i)
                cls, place = inst[i]
                px, py = task.places[place]
                rows.append({"day": day, "hour": float(hour), "class": cls, "x": px, "y": py,
                             "robot_x": round(x, 3), "robot_y": round(y, 3), "place": place})
            return False

        drive.on_detect = on_detect
        for name in task.route:
            drive.go(*task.places[name])
        drive.go(*task.world.start_xy, look=False)
    return pd.DataFrame(rows, columns=LOG_COLUMNS)
