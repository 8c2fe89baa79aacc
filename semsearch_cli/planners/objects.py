"""Object-search planners (thesis 5.2-5.3): each yields target points, in order, for the
robot to drive to until the object camera detects an instance of the requested class.

- ``lsos``: heat map of the log (Eqs. 5.3-5.4, class filter, sector toward the robot pose of each
  detection), goals by Eqs. 5.5-5.6 in order of windowed heat, then every place the camera has not
  yet had in view, in patrol order (the thesis' fallback "like the brute force").
- ``brute_force``: the patrol route, A to J and back to the start (thesis Fig. 5.11).
- ``last_seen``: the position of the most recent detection of the class (latest day, then hour).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar, Iterator

import numpy as np
import pandas as pd
from pydantic import BaseModel, ConfigDict, Field

from ..belief.objects import goal_cells, heat_map
from ..geometry import GridFrame
from .base import NoParams, Planner, register_planner


@dataclass
class ObjectContext:
    """What an object-search planner may look at.

    frame : GridFrame; known : (H, W) bool, Q of Eq. 5.2 (cells of the recorded map);
    places : name -> (x, y) m; route : the places to search, in patrol order; home : (x, y) m
    where a patrol ends, or None; cls, hour : the request; log : the detection log (columns
    day, hour, class, x, y, robot_x, robot_y, place); seen_places : the places the camera has had
    in view so far in this search (kept up to date while the robot drives); x, y, heading,
    distance : the robot's pose (m, rad) and the distance it has driven in this search (m), and
    here : the place it has just looked around at (None when it has not), each brought up to date
    before each target is asked for.
    """

    frame: GridFrame
    known: np.ndarray
    places: dict
    route: list
    home: tuple | None
    cls: str
    hour: float
    log: pd.DataFrame
    rng: np.random.Generator
    seen_places: set = field(default_factory=set)
    x: float = math.nan
    y: float = math.nan
    heading: float = math.nan
    distance: float = 0.0
    here: str | None = None


class ObjectPlanner(Planner):
    """An object-search planner: ``targets`` yields (x, y, info) to drive to, in order; the
    robot looks around at each target (unless ``info["look"]`` is False)."""

    task: ClassVar[str] = "objects"

    def targets(self, ctx: ObjectContext) -> Iterator[tuple[float, float, dict]]:  # pragma: no cover
        raise NotImplementedError


def patrol_targets(ctx: ObjectContext, skip_seen: bool = False):
    """The route's places in order (without those already in view, with ``skip_seen``)."""
    for name in ctx.route:
        if skip_seen and name in ctx.seen_places:
            continue
        yield (*ctx.places[name], {"kind": "patrol", "place": name})


class LsosParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    radius: float = Field(1.5, gt=0.0, le=20.0, description="m, kernel radius r of Eq. 5.4")
    sector: float = Field(45.0, gt=0.0, le=180.0, description="degrees, half-angle of the kernel toward the robot pose")
    window: float | None = Field(None, gt=0.0, le=100.0, description="m, radius of the window T of Eq. 5.6 (default: the kernel radius)")
    max_goals: int = Field(10, ge=1, description="heat-map goals before the patrol fallback")


def lsos_goals(frame: GridFrame, known: np.ndarray, log: pd.DataFrame, cls: str, hour: float, p: LsosParams):
    """(heat map, goals [(row, col, phi)]) for a request (Eqs. 5.3-5.6)."""
    dets = log[log["class"] == cls]
    rows = zip(dets["class"], dets["x"], dets["y"], dets["hour"], dets["robot_x"], dets["robot_y"])
    heat = heat_map(rows, cls, hour, frame, p.radius, known, p.sector)
    return heat, goal_cells(heat, (p.window or p.radius) / frame.res, p.max_goals)


@register_planner("lsos")
class Lsos(ObjectPlanner):
    """The thesis' LSOS: the heat map of the log's detections of the class (Eqs. 5.3-5.6) gives
    goals in order of windowed heat, then every place not yet in view, in patrol order."""

    rank = 2

    Params = LsosParams

    def targets(self, ctx):
        fr = ctx.frame
        _, goals = lsos_goals(fr, ctx.known, ctx.log, ctx.cls, ctx.hour, self.params)
        for r, c, phi in goals:
            x, y = fr.to_world(r, c)
            yield float(x), float(y), {"kind": "heat", "phi": round(phi, 4)}
        yield from patrol_targets(ctx, skip_seen=True)


@register_planner("brute_force")
class BruteForce(ObjectPlanner):
    """The patrol route, every place in order and back to the start (thesis Fig. 5.11)."""

    rank = 0

    Params = NoParams

    def targets(self, ctx):
        yield from patrol_targets(ctx)
        if ctx.home is not None:
            yield (*ctx.home, {"kind": "home"})


@register_planner("last_seen")
class LastSeen(ObjectPlanner):
    """The position of the most recent detection of the class (latest day, then hour)."""

    rank = 1

    Params = NoParams

    def targets(self, ctx):
        dets = ctx.log[ctx.log["class"] == ctx.cls]
        if len(dets):
            last = dets.sort_values(["day", "hour"], kind="stable").iloc[-1]
            yield float(last["x"]), float(last["y"]), {"kind": "last_seen", "day": int(last["day"]), "hour": float(last["hour"])}
