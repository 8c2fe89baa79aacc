"""Requesting mode (thesis 5.2-5.3, SPEC 6): the robot drives a planner's targets on the recorded
map until the object camera detects an instance of the requested class.

A planner for object search yields target points one at a time (:class:`ObjectPlanner`); the
episode drives to each along the cheapest path, sensing at every step, and on arrival turns on the
spot (three quarter turns, no distance) to look around. The run ends ``found`` on the first
detection of the class, ``not_found`` when the planner has no target left (Last Seen after its one
spot, Brute Force after its route), or ``budget`` when ``max_distance`` is used up.

Planners:

- ``lsos``: heat map of the log (Eqs. 5.3-5.4, class filter, sector toward the robot pose of each
  detection), goals by Eqs. 5.5-5.6 in order of windowed heat, then every place the camera has not
  yet had in view, in patrol order (the thesis' fallback "like the brute force").
- ``brute_force``: the patrol route, A to J and back to the start (thesis Fig. 5.11).
- ``last_seen``: the position of the most recent detection of the class (latest day, then hour).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import ClassVar, Iterator

import numpy as np
import pandas as pd
from pydantic import BaseModel, ConfigDict, Field

from ..planners.base import NoParams, Planner, register_planner
from .heatmap import goal_cells, heat_map
from ..geometry import advance, wrap_angle
from .task import ObjectCamera, ObjectTask, Request, detect_probability


class Drive:
    """The robot on the recorded map with the object camera: ``go`` drives to a point, sensing
    at every step; ``on_detect(i, x, y)`` is called for each detection of instance ``i`` and
    returns True to stop. ``seen_places``: the places the camera has had in view (range, field of
    view, line of sight), whether or not anything stood there."""

    def __init__(self, task: ObjectTask, instances, rng: np.random.Generator, heading: float,
                 budget: float = np.inf):
        w = task.world
        self.task, self.world, self.instances, self.rng = task, w, instances, rng
        self.map = task.known_map
        self.step_len = task.sc.robot.step
        cam = task.spec.camera
        # the camera looks at the places (widest fov, longest range of any class); each instance
        # standing at a place in view is then checked against its own class's fov and range
        self.place_names = list(task.places)
        self.camera = ObjectCamera(w, cam.max_fov, cam.max_range, [task.places[n][0] for n in self.place_names],
                                   [task.places[n][1] for n in self.place_names])
        self.at_place = [[i for i, (_, p) in enumerate(instances) if p == n] for n in self.place_names]
        self.cam = [cam.for_class(cls) for cls, _ in instances]  # (fov, range, p_detect) per instance
        self.uniform = all(c == (cam.max_fov, cam.max_range, cam.p_detect) and isinstance(c[2], float) for c in self.cam)
        self.x, self.y = w.start_xy
        self.heading = heading
        self.budget = budget
        self.distance = 0.0
        self.steps = 0
        self.trail = [(self.x, self.y)]
        self.seen_places: set[str] = set()
        self.on_detect = lambda i, x, y: False
        self.stopped = False  # a detection asked to stop
        self.spent = False  # the budget ran out

    def sense(self) -> None:
        for k in self.camera.visible(self.x, self.y, self.heading):
            name = self.place_names[k]
            self.seen_places.add(name)
            for i in self.at_place[k]:
                fov, rng_m, p = self.cam[i]
                if not self.uniform:
                    px, py = self.task.places[name]
                    d = float(np.hypot(px - self.x, py - self.y))
                    bearing = float(np.arctan2(py - self.y, px - self.x))
                    if d > rng_m or abs(float(wrap_angle(bearing - self.heading))) > np.radians(fov) / 2:
                        continue
                    view = float(np.degrees(bearing + np.pi - self.task.facing[name])) % 360.0
                    p = detect_probability(p, d, view)
                if self.rng.random() < p and self.on_detect(i, self.x, self.y):
                    self.stopped = True

    def go(self, x: float, y: float, look: bool = True) -> bool:
        """Drive to the reachable cell nearest (x, y); False when it cannot be reached."""
        fr = self.world.frame
        r, c = (int(v) for v in fr.to_index(self.x, self.y))
        tr, tc = self.map.snap(*(int(v) for v in fr.to_index(x, y)))
        p = self.map.path(r, c, tr, tc)
        if p is None:
            return False
        px, py = fr.to_world(p[0], p[1])
        i = 1
        while i < len(px) and not self.stopped:
            self.x, self.y, i, self.heading, moved = advance(px, py, i, self.x, self.y, self.heading, self.step_len)
            self.distance += moved
            self.steps += 1
            self.trail.append((self.x, self.y))
            self.sense()
            if self.distance >= self.budget:
                self.spent = True
                return True
        if look and not self.stopped:
            for _ in range(3):
                self.heading = float(wrap_angle(self.heading + np.pi / 2))
                self.sense()
                if self.stopped:
                    break
        return True


@dataclass
class ObjectContext:
    task: ObjectTask
    request: Request
    log: pd.DataFrame
    drive: Drive
    info: dict = field(default_factory=dict)


class ObjectPlanner(Planner):
    """An object-search planner: ``targets`` yields (x, y, info) to drive to, in order."""

    task: ClassVar[str] = "objects"

    def targets(self, ctx: ObjectContext) -> Iterator[tuple[float, float, dict]]:  # pragma: no cover
        raise NotImplementedError

    def choose(self, ctx, cands):  # door-search interface; never called for object planners
        raise TypeError(f"{self.name} is an object-search planner")


def patrol_targets(task: ObjectTask, skip_seen: Drive | None = None):
    for name in task.route:
        if skip_seen is not None and name in skip_seen.seen_places:
            continue
        yield (*task.places[name], {"kind": "patrol", "place": name})


class LsosParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    radius: float = Field(1.5, gt=0.0, description="m, kernel radius r of Eq. 5.4")
    sector: float = Field(45.0, gt=0.0, le=180.0, description="degrees, half-angle of the kernel toward the robot pose")
    window: float | None = Field(None, gt=0.0, description="m, radius of the window T of Eq. 5.6 (default: the kernel radius)")
    max_goals: int = Field(10, ge=1, description="heat-map goals before the patrol fallback")


def lsos_goals(task: ObjectTask, log: pd.DataFrame, cls: str, hour: float, p: LsosParams):
    """(heat map, goals [(row, col, phi)]) for a request (Eqs. 5.3-5.6)."""
    dets = log[log["class"] == cls]
    rows = zip(dets["class"], dets["x"], dets["y"], dets["hour"], dets["robot_x"], dets["robot_y"])
    heat = heat_map(rows, cls, hour, task.world.frame, p.radius, task.known, p.sector)
    return heat, goal_cells(heat, (p.window or p.radius) / task.world.frame.res, p.max_goals)


@register_planner("lsos")
class Lsos(ObjectPlanner):
    Params = LsosParams

    def targets(self, ctx):
        fr = ctx.task.world.frame
        _, goals = lsos_goals(ctx.task, ctx.log, ctx.request.cls, ctx.request.hour, self.params)
        for r, c, phi in goals:
            x, y = fr.to_world(r, c)
            yield float(x), float(y), {"kind": "heat", "phi": round(phi, 4)}
        yield from patrol_targets(ctx.task, ctx.drive)


@register_planner("brute_force")
class BruteForce(ObjectPlanner):
    Params = NoParams

    def targets(self, ctx):
        yield from patrol_targets(ctx.task)
        yield (*ctx.task.world.start_xy, {"kind": "home"})


@register_planner("last_seen")
class LastSeen(ObjectPlanner):
    Params = NoParams

    def targets(self, ctx):
        dets = ctx.log[ctx.log["class"] == ctx.request.cls]
        if len(dets):
            last = dets.sort_values(["day", "hour"], kind="stable").iloc[-1]
            yield float(last["x"]), float(last["y"]), {"kind": "last_seen", "day": int(last["day"]), "hour": float(last["hour"])}


class ObjectEpisode:
    """One request answered by one planner variant."""

    def __init__(self, task: ObjectTask, variant, request: Request, log: pd.DataFrame, seed: int, trace: bool = False):
        self.task, self.variant, self.request, self.log, self.seed, self.keep_trace = task, variant, request, log, seed, trace

    def run(self):
        """A :class:`~semsearch_cli.episode.RunResult`."""
        from ..episode import RunResult, run_seed  # the episode module imports the planner registry

        t0 = time.perf_counter()
        task, req, sc = self.task, self.request, self.task.sc
        rng = np.random.default_rng(run_seed(sc.name, req.label, self.seed, sc.experiment.base_seed))
        w = task.world
        heading = w.start_heading if w.start_heading is not None else float(rng.uniform(-np.pi, np.pi))
        inst = task.request_instances(req)
        drive = Drive(task, inst, rng, heading, sc.experiment.max_distance)
        drive.on_detect = lambda i, x, y: inst[i][0] == req.cls
        drive.sense()
        planner = self.variant.build()
        ctx = ObjectContext(task, req, self.log, drive)
        decisions = 0
        trace = []
        outcome = None
        if drive.stopped:
            outcome = "found"
        else:
            for x, y, info in planner.targets(ctx):
                decisions += 1
                if self.keep_trace:
                    trace.append({"distance_m": round(drive.distance, 3), "target": [round(x, 2), round(y, 2)], **info})
                drive.go(x, y)
                if drive.stopped:
                    outcome = "found"
                    break
                if drive.spent:
                    outcome = "budget"
                    break
        if outcome is None:
            outcome = "not_found"
        return RunResult(outcome, drive.distance, drive.steps, decisions, time.perf_counter() - t0,
                         np.asarray(drive.trail, np.float32), [], trace)
