"""Object search over time (thesis ch. 5): places, timelines, cases, requests, ground
truth, the recording mode, and the requesting mode: the robot drives an object planner's targets on
the recorded map until the object camera detects an instance of the requested class.

An episode senses with the object camera at every step and at each quarter turn; its belief is
the set of places the camera has had in view; the target is seen on the first detection of the
class; a re-plan (the next target) happens when the path is used up, after looking around (three
quarter turns, no distance). It ends ``found``, ``not_found`` when the planner has no target left
(Last Seen after its one spot, Brute Force after its route), or ``budget``.

Choices the seeds leave open (also in docs/object-search.md):

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

import io
import zlib
from dataclasses import dataclass
from functools import cached_property, partial
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import yaml

from ..config import ObjectsSpec
from ..errors import ScenarioError
from ..geometry import wrap_angle
from ..kernels.grid import dijkstra
from ..navigation import KnownMap
from ..planners import ObjectContext
from ..sensors import PlaceCamera
from ..world.buildings.office import office_image, office_scenario
from .base import Event, Observer, Outcome, RobotState, OnMapTask, checked_point, register_task
from .decisions import Codec, DecisionPoint
from .loop import drive, run_loop
from ..files import read_user_text, temp_path, user_file

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


@dataclass(frozen=True, kw_only=True)
class ObjectTarget(Event):
    """An object planner's next target point ``target_xy`` (m), ``distance`` m into the search,
    with the planner's ``info``."""

    distance: float
    target_xy: tuple
    info: dict

    def row(self) -> dict:
        x, y = self.target_xy
        return {"distance_m": round(self.distance, 3), "target": [round(x, 2), round(y, 2)], **self.info}


class ObjectSearch:
    """One request answered by an object planner's targets (see the module docstring)."""

    def __init__(self, task: "ObjectTask", targets, cls: str, instances: list, camera: PlaceCamera, ctx: ObjectContext,
                 rng: np.random.Generator, observer: Observer | None = None):
        """``targets``: a function giving the iterator of (x, y, info) that answers the decisions
        (called at the first one: ``planner.targets(ctx)``); ``instances``: [(class, place)] in
        the world."""
        self.task, self.make_targets, self.cls, self.instances = task, targets, cls, instances
        self.camera, self.ctx, self.rng, self.observer = camera, ctx, rng, observer
        self.targets = None
        self.look = False  # look around on arriving at the current target
        self.decisions = 0
        self.start_distance = 0.0
        self.planner_name = ""  # for the checks of its targets
        self.names = list(task.places)
        self.place = None  # the index of the place the current target is, if it is one
        self.here = None  # the place the robot arrived at and looked around, if any
        self.codec = Codec(self._encode, self._decode)

    def _encode(self, target):
        """An object choice in a few bytes: ``[k]`` for place k of ``objects.places``, ``[x, y]``
        (m) for another point; a trailing ``0`` when the robot is not to look around there
        (``info["look"]`` False); null for no target."""
        if target is None:
            return None
        x, y, info = target
        xy = (float(x), float(y))
        k = self.place_at(*xy)
        return ([k] if k is not None else [*xy]) + ([] if info.get("look", True) else [0])

    def _decode(self, item):
        if item is None:
            return None
        place = isinstance(item, list) and len(item) > 0 and isinstance(item[0], int) and not isinstance(item[0], bool)
        n = 1 if place else 2
        if not isinstance(item, list) or len(item) not in (n, n + 1) or item[n:] not in ([], [0]):
            raise ValueError("expected [place], [x, y], or either with a trailing 0")
        if place:
            if not 0 <= item[0] < len(self.names):
                raise ValueError(f"no place {item[0]}")
            x, y = self.task.places[self.names[item[0]]]
        else:
            x, y = float(item[0]), float(item[1])
        return x, y, {} if len(item) == n else {"look": False}

    def place_at(self, x: float, y: float) -> int | None:
        """The index of the place at exactly (x, y) m, or None."""
        return next((k for k, n in enumerate(self.names) if self.task.places[n] == (x, y)), None)

    def next_target(self):
        """The planner's answer: its next target, or None when it has none left."""
        if self.targets is None:
            self.targets = iter(self.make_targets())
        return next(self.targets, None)

    def point(self) -> DecisionPoint:
        """The decision: a target (a place, or any point), or None; every place is legal but the
        one the robot has just looked around at."""
        mask = np.ones(len(self.names), bool)
        if self.here is not None:
            mask[self.here] = False
        return DecisionPoint("objects", self.ctx, self.task.places, mask, self.next_target, self.codec, self.rng)

    def sense(self, st):
        seen, detected = self.camera.look(st.x, st.y, st.heading, self.rng)
        self.ctx.seen_places.update(seen)
        return any(self.instances[i][0] == self.cls for i in detected), False

    def update(self, st):
        pass  # the places in view went into ctx.seen_places as they were sensed

    def replan_due(self, path_done, since_plan, event):
        return path_done

    def _look_around(self, st) -> bool:
        for _ in range(3):
            st.heading = float(wrap_angle(st.heading + np.pi / 2))
            if self.sense(st)[0]:
                return True
        return False

    def plan(self, st):
        """A re-plan, the object search's decision point (a generator, see
        :class:`~semsearch_cli.tasks.loop.Session`): on arriving at a target, look around there
        (three quarter turns); then ask for the next target and drive there on the recorded map
        (a target with no path, or where the robot stands, asks again); no target left is
        ``not_found``."""
        known = self.task.known_map
        if self.place is not None:  # the path to the last target was used up: the robot is there
            self.here = self.place
        while True:
            if self.look and self._look_around(st):
                return "found"
            self.look = False
            c = self.ctx  # where the robot is, for the planner that reads it
            c.x, c.y, c.heading, c.distance = st.x, st.y, st.heading, st.distance - self.start_distance
            c.here = None if self.here is None else self.names[self.here]
            nxt = yield self.point()
            if nxt is None:
                return "not_found"
            x, y, info = nxt
            x, y = checked_point(self.planner_name, x, y, self.task.world.frame)
            self.decisions += 1
            if self.observer is not None:
                self.observer.see(ObjectTarget(distance=st.distance - self.start_distance, target_xy=(x, y), info=info))
            p = known.path_to(st.x, st.y, x, y)
            if p is None:
                continue
            self.look = info.get("look", True)
            if len(p[0]) >= 2:
                self.place = self.place_at(x, y)
                self.here = None
                return self.task.world.frame.to_world(p[0], p[1])


class Patrol(ObjectSearch):
    """Recording mode: drive the route, logging each instance at its first detection."""

    def __init__(self, task, targets, instances, hour, day, rng):
        camera = PlaceCamera(task.world, task.spec.camera, task.places, task.facing, instances)
        ctx = ObjectContext(task.world.frame, task.known, task.places, task.route, None, "", hour,
                            pd.DataFrame(columns=LOG_COLUMNS), rng)
        super().__init__(task, lambda: targets, "", instances, camera, ctx, rng)
        self.hour, self.day = hour, day
        self.rows: list[dict] = []
        self.logged: set[int] = set()

    def sense(self, st):
        seen, detected = self.camera.look(st.x, st.y, st.heading, self.rng)
        for i in detected:
            if i not in self.logged:
                self.logged.add(i)
                cls, place = self.instances[i]
                px, py = self.task.places[place]
                self.rows.append({"day": self.day, "hour": float(self.hour), "class": cls, "x": px, "y": py,
                                  "robot_x": round(st.x, 3), "robot_y": round(st.y, 3), "place": place})
        return False, False


@register_task
class ObjectTask(OnMapTask):
    """Everything an object-search scenario asks, checked against the world. Goals are request
    labels (``Static.mug@12``); each case's detection log is recorded (or read) once, when the
    task is built."""

    kind = "objects"
    planner_kind = "objects"
    noun = "an object of a class at an hour of the day, among places it moves between"
    records = ("soft_spl", "left_m")

    @classmethod
    def example(cls, folder, planner):
        """The office of thesis 5.3 with its moved-mug case alone, one seed, a 300 m budget."""
        folder.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(folder / "map.png"), office_image())
        d = office_scenario()
        d["objects"]["cases"] = [c for c in d["objects"]["cases"] if c["name"] == "Moved-mug"]
        d["planners"] = [{"name": planner}]
        d["experiment"] = {"seeds": 1, "max_distance": 300.0}
        path = folder / "scenario.yaml"
        path.write_text(yaml.safe_dump(d, sort_keys=False))
        return path

    def __init__(self, sc, world, path):
        super().__init__(sc, world, path)
        spec: ObjectsSpec = sc.objects
        file = self.file
        self.spec, self.base = spec, self.path.parent
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
        if len(set(labels)) != len(labels):
            raise ScenarioError(file, "objects.requests", "a request (case, class, hour) appears twice")

    @classmethod
    def build(cls, sc, world, path):
        task = cls(sc, world, path)
        if not task.requests:
            raise ScenarioError(task.file, "objects.requests", "no requests: give at least one {class, hour}")
        task.logs = {c.name: task.log(c) for c in task.cases}
        task.shortest = {r.label: task.shortest_to(r) for r in task.requests}
        task.variants()
        return task

    @property
    def goals(self) -> list:
        return [r.label for r in self.requests]

    def steps(self, state, planner, goal, rng, observer: Observer | None = None):
        """Answer the request labelled ``goal`` from ``state`` (a generator of its decision points)."""
        req = self.request(goal)
        return (yield from self.search_steps(state, planner, req.cls, req.hour, self.request_instances(req),
                                             self.logs[req.case], self.route, self.world.start_xy, rng, observer))

    def search_steps(self, state, planner, cls, hour, instances, log, route, home, rng, observer: Observer | None = None):
        """Search for ``cls`` among ``instances`` [(class, place)] with the places of ``route``."""
        d0, s0 = state.distance, state.steps
        camera = PlaceCamera(self.world, self.spec.camera, self.places, self.facing, instances)
        ctx = ObjectContext(self.world.frame, self.known, self.places, list(route), home, cls, hour, log, rng)
        search = ObjectSearch(self, partial(planner.targets, ctx) if hasattr(planner, "targets") else None, cls, instances,
                              camera, ctx, rng, observer)
        search.planner_name = planner.name
        search.start_distance = d0
        outcome = yield from drive(search, state, self.sc.robot.step, self.sc.experiment.max_distance, self.max_steps())
        return Outcome(outcome, state.distance - d0, state.steps - s0, search.decisions), state

    def write_inputs(self, out: Path) -> None:
        for case, log in self.logs.items():
            write_log(log, out / "logs" / f"{case}.csv")

    def describe(self):
        w = self.world
        return {"name": self.sc.name, "kind": self.kind, "places": len(self.places), "route": " ".join(self.route),
                "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
                "cases": {c.name: f"{len(self.logs[c.name])} detections recorded" for c in self.cases},
                "planners": self.planner_labels(),
                "requests (ground truth: shortest m)": {r.label: f"{','.join(r.truth) or 'absent'}: {self.shortest[r.label]:.2f}"
                                                        for r in self.requests}}

    def patrol(self, instances, hour: float, day: int, rng: np.random.Generator, look: bool = True):
        """One patrol (start, the route's places, back to the start) among ``instances``:
        (the final robot state, the :class:`Patrol` with its log rows). With ``look`` the robot
        looks around at each place."""
        st = RobotState(*self.world.start_xy, self.world.start_heading or 0.0)
        st.trail = [(st.x, st.y)]
        targets = iter([(*self.places[n], {"look": look}) for n in self.route] + [(*self.world.start_xy, {"look": False})])
        search = Patrol(self, targets, instances, hour, day, rng)
        run_loop(search, st, self.sc.robot.step, np.inf, 10**9)
        return st, search

    def patrol_route(self) -> np.ndarray:
        """(n, 2) m: the poses of one patrol, not looking."""
        return np.asarray(self.patrol([], 0.0, 0, np.random.default_rng(0), look=False)[0].trail)

    def record_source(self, record, field: str) -> tuple[tuple, str | None]:
        """A ``record`` entry (timeline names, or a detection-log CSV path), checked:
        (timeline names or (csv path,), csv path or None)."""
        if isinstance(record, str):
            user_file(self.base / record, "detection log", self.file, field)
            return (record,), record
        for n in record:
            if n not in self.spec.timelines:
                raise ScenarioError(self.file, field, f"unknown timeline {n!r}; timelines are {', '.join(self.spec.timelines)}")
        return tuple(record), None

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
            rec, log_file = self.record_source(c["record"], f"objects.cases[{k}].record")
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
            out.append(Case(c["name"], rec, log_file, truth, tuple(reqs)))
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

    def goal_cells(self, goal) -> np.ndarray:
        """The reachable poses that see an instance of the request's target (heading free)."""
        req = self.request(goal)
        rng = self.spec.camera.for_class(req.cls)[1]
        out = np.zeros(self.world.reach.shape, bool)
        for p in req.truth:
            out |= self.view_mask(*self.places[p], rng)
        return out

    def shortest_to(self, req: Request) -> float:
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
    text = read_user_text(path, "detection log")
    try:
        df = pd.read_csv(io.StringIO(text))
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ScenarioError(str(path), "", f"not a readable CSV: {exc}") from None
    need = {"class", "x", "y", "hour", "robot_x", "robot_y"}
    if not need <= set(df.columns):
        raise ScenarioError(str(path), "", f"expected columns {', '.join(sorted(need))} (got {', '.join(df.columns)})")
    for col in ("x", "y", "hour", "robot_x", "robot_y"):
        num = pd.to_numeric(df[col], errors="coerce")
        if num.isna().any() or not np.isfinite(num).all():
            raise ScenarioError(str(path), col, "must be finite numbers on every row")
        df[col] = num
    hours = df["hour"]
    if ((hours < 0) | (hours >= 24)).any():
        raise ScenarioError(str(path), "hour", f"hours lie in 0-24 (got {hours[(hours < 0) | (hours >= 24)].iloc[0]:g})")
    if "day" not in df:
        df["day"] = 0
    if "place" not in df:
        df["place"] = ""
    df["class"] = df["class"].astype(str)
    return df[LOG_COLUMNS]


def write_log(df: pd.DataFrame, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(path)
    df.to_csv(tmp, index=False, float_format="%.3f")
    tmp.replace(path)


def record(task: ObjectTask, timeline: str, hours, day: int = 0, base_seed: int = 0) -> pd.DataFrame:
    """Recording mode: one patrol (start, the route's places, back to the start) at each hour
    with the objects of ``timeline`` at that hour; each instance is logged at its first detection
    of the patrol. Seeded by (base_seed, timeline, hour), so the log is the same on every call."""
    rows = []
    for hour in hours:
        rng = np.random.default_rng([base_seed, zlib.crc32(timeline.encode()), int(round(hour * 60))])
        rows += task.patrol(task.instances(timeline, hour), hour, day, rng)[1].rows
    return pd.DataFrame(rows, columns=LOG_COLUMNS)
