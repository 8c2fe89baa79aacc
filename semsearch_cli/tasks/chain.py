"""Chained searches (thesis ch. 6): "disinfect room 12, then room 15"; "the computer in
room 12 at 11:00".

A chain is a list of stages. A stage finds a door sign (door search with the scenario's door
planner) and, when it names an object class and an hour, then finds that object in the room
behind the door: the places whose ``room`` is the door's number, searched by ``lsos`` on the
chain's recorded log (only the detections at that room's places) or by ``brute_force`` over the
room's places, on the recorded map as in object search. The robot keeps its pose, its map and its
sign reads from stage to stage; a stage whose sign it has already read goes there by path planning
on the map built so far. The budget (``max_distance``) is the whole chain's.

Each run also runs every stage *from scratch*: from the pose where that stage began in the chain,
with an empty map and no sign reads, and the same seed as the stage in the chain (so a first
stage is the same run both ways); so per planner the report compares each
stage with the map kept against the same stage without it. A run's rows: one for the chain (goal =
the chain's name, distance in total, shortest = the sum of the shortest legs in order), one per
stage with the map kept (``map = kept``) and one per stage from scratch (``map = scratch``);
``stage`` is ``k:door`` or ``k:door/class@hour``. A chain stops at the first stage that fails.

Shortest legs: leg 1 runs from the start to the nearest pose that reads the first door; each
later leg from the end pose of the previous leg to the nearest pose that reads its door; an object
leg from there to the nearest pose that sees an instance of the class in its room.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd
import yaml

from ..errors import ScenarioError
from ..metrics import result_columns
from ..planners import PLANNERS, Variant
from ..world.buildings.demo import write_demo
from .base import Observer, Outcome, RobotState, StageObserver, OnMapTask, register_task
from .decisions import Seat
from .episodes import Episode, episode_seed
from .doors import DoorTask
from .objects import Case, ObjectTask


@dataclass(frozen=True)
class Stage:
    door: object
    cls: str | None = None
    hour: float | None = None

    @property
    def label(self) -> str:
        return f"{self.door}" + (f"/{self.cls}@{self.hour:g}" if self.cls is not None else "")


@register_task
class ChainTask(OnMapTask):
    kind = "chain"
    planner_kind = "doors"
    noun = "door signs one after another, and objects in the rooms behind them, from one robot state"
    records = ("map",)
    columns = ("stage", "map")

    @classmethod
    def example(cls, folder, planner):
        """The demo building: doors 452, 304 and 452 again (the last one read on the map built so
        far), one seed, a 600 m budget."""
        path = write_demo(folder, planners=[{"name": planner}], seeds=1)
        d = yaml.safe_load(path.read_text())
        del d["goals"]
        d["chains"] = [{"name": "two", "stages": [{"door": 452}, {"door": 304}, {"door": 452}]}]
        d["experiment"]["max_distance"] = 600.0
        path.write_text(yaml.safe_dump(d, sort_keys=False))
        return path

    def __init__(self, sc, world, path):
        super().__init__(sc, world, path)
        self.doors = DoorTask(sc, world, path)
        self.objects = ObjectTask(sc, world, path) if sc.objects is not None else None
        self.chains = {c.name: c for c in sc.chains}
        if len(self.chains) != len(sc.chains):
            raise ScenarioError(self.file, "chains", "chain names must be unique")
        self.stages: dict[str, list[Stage]] = {}
        self.logs: dict[str, pd.DataFrame] = {}
        self.legs: dict[tuple, list[float]] = {}  # (chain, start x, start y) -> its shortest legs

    @classmethod
    def build(cls, sc, world, path):
        if len(world.signs) == 0:
            raise ScenarioError(str(path), "doors", "no door signs given")
        task = cls(sc, world, path)
        for k, ch in enumerate(sc.chains):
            field = f"chains[{k}]"
            stages = [Stage(s.door, s.object, s.hour) for s in ch.stages]
            task.doors.check_goals([s.door for s in stages], f"{field}.stages")
            if any(s.cls is not None for s in stages):
                task._check_object_stages(ch, stages, field)
                # a chain names its object planner alone, with its defaults: one that needs parameters to run (llm) cannot
                answers = sorted(n for n, c in PLANNERS.items() if c.answers(ObjectTask.planner_kind) and not c.service)
                if ch.object_planner in PLANNERS and PLANNERS[ch.object_planner].service:
                    raise ScenarioError(task.file, f"{field}.object_planner", f"{ch.object_planner!r} needs parameters to "
                                        f"run (a model to call), and a chain runs its object planner with its defaults; "
                                        f"valid: {', '.join(answers)}")
                if ch.object_planner not in answers:
                    raise ScenarioError(task.file, f"{field}.object_planner", f"unknown object-search planner "
                                        f"{ch.object_planner!r}; valid: {', '.join(answers)}")
            task.stages[ch.name] = stages
            legs = task._shortest_legs(ch, stages, field, world.start_cell)
            task.legs[(ch.name, *world.start_xy)] = legs
            task.shortest[ch.name] = float(sum(legs))
        task.variants()
        return task

    def _check_object_stages(self, ch, stages, field) -> None:
        ot = self.objects
        if ot is None:
            raise ScenarioError(self.file, field, "an object stage needs an objects section (places with their room)")
        if ch.record is None or ch.truth is None:
            raise ScenarioError(self.file, field, "a chain with object stages gives record (timelines or a log) and truth")
        if ch.truth not in ot.spec.timelines:
            raise ScenarioError(self.file, f"{field}.truth", f"unknown timeline {ch.truth!r}")
        rec, log_file = ot.record_source(ch.record, f"{field}.record")
        self.logs[ch.name] = ot.log(Case(ch.name, rec, log_file, ch.truth, ()))
        for j, s in enumerate(stages):
            if s.cls is not None and not self.room_places(s.door):
                raise ScenarioError(self.file, f"{field}.stages[{j}]", f"no place has room: {s.door}; give the places "
                                    "in that room a room field")

    def room_places(self, door) -> list[str]:
        """The places of the room behind door ``door``, in route order."""
        ot = self.objects
        room = {p.name for p in ot.spec.places if p.room is not None and str(p.room) == str(door)}
        return [n for n in ot.route if n in room] + sorted(room - set(ot.route))

    def _instances(self, ch, s: Stage) -> list[tuple[str, str]]:
        return self.objects.instances(ch.truth, s.hour)

    def _shortest_legs(self, ch, stages, field, cell) -> list[float]:
        """The shortest legs of chain ``ch`` from ``cell``: to each door's nearest reading pose
        and, for an object stage, on from there to the nearest pose that sees the object."""
        w = self.world
        legs = []
        for j, s in enumerate(stages):
            d, end = w.geodesic(cell, w.reading_cells(s.door))
            if end is None:
                raise ScenarioError(self.file, f"{field}.stages[{j}].door", f"sign {s.door} cannot be read from any pose "
                                    "reachable from the start")
            legs.append(d)
            cell = end
            if s.cls is not None:
                d, end = w.geodesic(cell, self._object_target(ch, s))
                if end is None:
                    raise ScenarioError(self.file, f"{field}.stages[{j}]", f"at {s.hour:g}:00 no {s.cls} stands in the room "
                                        f"behind door {s.door} (timeline {ch.truth}) where the camera could see it")
                legs.append(d)
                cell = end
        return legs

    def _object_target(self, ch, s: Stage) -> np.ndarray:
        """(H, W) bool: the reachable poses that see an instance of stage ``s``'s class in the room
        behind its door, at its hour."""
        ot = self.objects
        rng = ot.spec.camera.for_class(s.cls)[1]
        target = np.zeros_like(self.world.reach)
        room = set(self.room_places(s.door))
        for cl, p in self._instances(ch, s):
            if cl == s.cls and p in room:
                target |= ot.view_mask(*ot.places[p], rng)
        return target

    @property
    def goals(self) -> list:
        return list(self.chains)

    def goal_cells(self, goal) -> np.ndarray:
        """The poses that read the chain's first door (drawn starts keep their distance to it)."""
        return self.world.reading_cells(self.stages[str(goal)][0].door)

    def shortest_from(self, goal, x: float, y: float) -> float:
        return float(sum(self.legs_from(self.chains[str(goal)], x, y)))

    def legs_from(self, ch, x: float, y: float) -> list[float]:
        """The shortest legs of chain ``ch`` from a start at (x, y), computed once per start."""
        key = (ch.name, x, y)
        if key not in self.legs:
            r, c = self.world.frame.to_index(x, y)
            self.legs[key] = self._shortest_legs(ch, self.stages[ch.name], "episodes", (int(r), int(c)))
        return self.legs[key]

    # ---- running ----------------------------------------------------------------------
    def _stage(self, ch, s: Stage, st: RobotState, variant: Variant, rng, reuse: bool, observer: Observer | None,
               seat: Seat):
        """One stage from ``st`` (a generator of its decision points): (outcome, decisions)."""
        out, st = yield from self.doors.steps(st, seat.planner(variant), s.door, rng, observer, reuse_reads=reuse)
        decisions = out.decisions
        if out.outcome != "found" or s.cls is None:
            return out.outcome, decisions
        room = self.room_places(s.door)
        log = self.logs[ch.name]
        near = _nearest_place(log, self.objects.places)
        planner = seat.planner(Variant(ch.object_planner, ()))
        out, st = yield from self.objects.search_steps(st, planner, s.cls, s.hour, self._instances(ch, s), log[near.isin(room)],
                                                       room, None, rng, observer)
        return out.outcome, decisions + out.decisions

    def search(self, variant: Variant, ep: Episode, seed: int, st: RobotState, rng, seat: Seat,
               observer: Observer | None) -> Outcome:
        """A chain's stages from one robot state (the map and the signs read kept); each stage
        again from scratch beside it, unobserved. ``observer`` sees the kept stages' events,
        marked with their stage; ``seat`` answers every stage's decisions, kept and from scratch,
        in the order they are met."""
        ch = self.chains[str(ep.goal)]
        base = self.sc.experiment.base_seed
        st.belief = self.doors.new_belief()
        stages, decisions = [], 0
        outcome = "found"
        legs = self.legs_from(ch, ep.x, ep.y)
        leg = iter(legs)
        used = 0
        left = 0.0
        for k, s in enumerate(self.stages[ch.name], 1):
            pose = (st.x, st.y, st.heading)
            d0, s0, t_stage = st.distance, st.steps, time.perf_counter()
            stage_seed = episode_seed(ep, seed, base, k)  # the same draws kept and from scratch
            outcome, dec = yield from self._stage(ch, s, st, variant, np.random.default_rng(stage_seed), True,
                                       StageObserver(observer, k) if observer is not None else None, seat)
            n_legs = 2 if s.cls is not None else 1
            shortest = sum(next(leg) for _ in range(n_legs))
            used += n_legs
            decisions += dec
            stages.append(_stage_row(k, s, "kept", outcome, st.distance - d0, st.steps - s0, shortest, dec, time.perf_counter() - t_stage))
            # the same stage from scratch: same pose, empty map, same seed
            fresh = RobotState(*pose, trail=[pose[:2]])
            t_s = time.perf_counter()
            o2, d2 = yield from self._stage(ch, s, fresh, variant, np.random.default_rng(stage_seed), False, None, seat)
            stages.append(_stage_row(k, s, "scratch", o2, fresh.distance, fresh.steps, shortest, d2, time.perf_counter() - t_s))
            if outcome != "found":
                # left: to this stage's door and on to its object (when its door was not read), or
                # to its object (the door read, the search in the room failed); then the legs after it
                rest = float(sum(legs[used:]))
                if st.read_signs.keys().isdisjoint(self.world.signs.indices_of(s.door)):
                    left = self.doors.distance_left(s.door, st.x, st.y) + (legs[used - 1] if s.cls is not None else 0.0)
                else:
                    r, c = self.world.frame.to_index(st.x, st.y)
                    left = self.world.geodesic((int(r), int(c)), self._object_target(ch, s))[0]
                left += rest
                break
        return Outcome(outcome, st.distance, st.steps, decisions, left_m=left, stages=stages)

    def rows(self, variant, ep, seed, res):
        rows = super().rows(variant, ep, seed, res)
        rows[0]["map"] = "kept"
        return rows

    def describe(self):
        w = self.world
        return {"name": self.sc.name, "kind": self.kind, "signs": len(w.signs),
                "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
                "planners": self.planner_labels(),
                "chains (shortest m)": {n: f"{' -> '.join(s.label for s in st)}: {self.shortest[n]:.2f}"
                                        for n, st in self.stages.items()}}


def _stage_row(k: int, s: Stage, mode: str, outcome: str, distance: float, steps: int, shortest: float, decisions: int,
               wall: float) -> dict:
    """The columns of a stage row that differ from its chain's row (SoftSPL and the distance left
    are the chain's alone: empty here)."""
    return {"stage": f"{k}:{s.label}", "map": mode, **result_columns(outcome, distance, shortest, steps, decisions, wall),
            "soft_spl": "", "left_m": ""}


def _nearest_place(log: pd.DataFrame, places: dict) -> pd.Series:
    """The place nearest each detection of a log (its ``place`` column may be empty)."""
    if log.empty:
        return pd.Series([], dtype=object)
    names = list(places)
    xy = np.array([places[n] for n in names])
    d = np.hypot(log["x"].to_numpy(float)[:, None] - xy[:, 0], log["y"].to_numpy(float)[:, None] - xy[:, 1])
    return pd.Series([names[i] for i in d.argmin(axis=1)], index=log.index)
