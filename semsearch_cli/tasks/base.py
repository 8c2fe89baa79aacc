"""The Task protocol: what every kind of search provides to the runner, and the robot state that
one episode takes in and gives back.

A task is built from a scenario (world, goals or requests, shortest paths, checked), and runs one
episode of a planner for one goal from a given :class:`RobotState` (pose, belief, clock, distance
so far), returning the outcome and the new state. :meth:`Task.run` is one run from the start of the
scenario; a chain (``tasks/chain.py``) runs several episodes of other tasks from one state.
Every kind registers itself with :func:`register_task`; nothing outside ``tasks/`` asks which kind a
scenario is.
"""

from __future__ import annotations

import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..config import Scenario
from ..errors import ScenarioError
from ..metrics import run_row
from ..planners import Variant, expand_variants
from ..world.scenario import World


def run_seed(scenario: str, goal, seed: int, base_seed: int) -> np.random.SeedSequence:
    """The seed of one run, derived from (scenario, goal, seed) only: every planner variant sees
    the same start heading and sensor draws for seed k, whatever the worker count."""
    return np.random.SeedSequence([base_seed, seed, zlib.crc32(scenario.encode()), zlib.crc32(str(goal).encode())])


@dataclass
class RobotState:
    """The robot between and during episodes.

    x, y : float, m; heading : float, rad; belief : the map and sign reads built so far (door
    search), or None; clock : float, hour of day, or None; distance : float, m travelled so far;
    steps : int; trail : list of (x, y) m, every pose so far; headings : list of rad, the heading
    at every pose (the robot-orientation histogram of nsos); read_signs : indices of the signs
    read at least once.
    """

    x: float
    y: float
    heading: float
    belief: Any = None
    clock: float | None = None
    distance: float = 0.0
    steps: int = 0
    trail: list = field(default_factory=list)
    headings: list = field(default_factory=list)
    read_signs: set = field(default_factory=set)


@dataclass
class Outcome:
    """How one episode ended: ``outcome`` is found, not_found (the planner had nowhere left to
    look), stuck (no path to anywhere new), budget or error; the counts are this episode's."""

    outcome: str
    distance_m: float
    steps: int
    decisions: int
    trace: list = field(default_factory=list)


@dataclass
class RunResult:
    outcome: str  # found | not_found | stuck | budget | error
    distance_m: float
    steps: int
    decisions: int
    wall_s: float
    path: np.ndarray  # (n, 2) float32, m
    read_signs: list = field(default_factory=list)  # sign indices read at least once
    trace: list = field(default_factory=list)  # one dict per decision
    stages: list = field(default_factory=list)  # extra rows of a run (chains: one per stage and mode)
    message: str = ""
    time_s: float = float("nan")  # simulated seconds, for tasks with a clock


TASKS: dict[str, type["Task"]] = {}


def register_task(cls):
    """Class decorator: the task answers scenarios of kind ``cls.kind``."""
    TASKS[cls.kind] = cls
    return cls


class Task:
    """One kind of search over a scenario. Subclasses set ``kind``, ``planner_kind`` (which
    registered planners answer it) and implement :meth:`episode` (and usually :meth:`goals`)."""

    kind: ClassVar[str] = ""
    planner_kind: ClassVar[str] = "doors"

    def __init__(self, sc: Scenario, world: World, path: Path):
        self.sc, self.world, self.path = sc, world, Path(path)
        self.file = str(path)
        self.shortest: dict = {}

    # ---- built from the scenario ------------------------------------------------------
    @property
    def goals(self) -> list:
        """The goal labels of the runs (door numbers, request labels, chain names)."""
        return list(self.sc.goals)

    def variants(self, specs=None) -> list[Variant]:
        """The scenario's planner entries (or ``specs``) as variants, checked for this kind."""
        return expand_variants(self.sc.planners if specs is None else specs, self.file, self.planner_kind, self.path.parent)

    def planner_labels(self, most: int = 12):
        """The variants' labels for `validate`; a long sweep as its count and its first and last."""
        labels = [v.label for v in self.variants()]
        if len(labels) <= most:
            return labels
        return f"{len(labels)} variants: {', '.join(labels[:3])}, ..., {labels[-1]}"

    def goal_value(self, label):
        """The goal as the scenario wrote it (an int door number stays an int)."""
        for g in self.goals:
            if str(g) == str(label):
                return g
        return label

    # ---- running ----------------------------------------------------------------------
    def start_state(self, rng: np.random.Generator) -> RobotState:
        """The robot at the scenario's start (a random heading draws from ``rng``)."""
        w = self.world
        heading = w.start_heading if w.start_heading is not None else float(rng.uniform(-np.pi, np.pi))
        x, y = w.start_xy
        return RobotState(x, y, heading, trail=[(x, y)])

    def episode(self, state: RobotState, planner, goal, rng: np.random.Generator, trace: bool = False,
                recorder=None) -> tuple[Outcome, RobotState]:  # pragma: no cover
        raise NotImplementedError

    def run(self, variant: Variant, goal, seed: int, trace: bool = False, recorder=None) -> RunResult:
        """One run from the start: the start state, then one episode."""
        t0 = time.perf_counter()
        goal = self.goal_value(goal)
        rng = np.random.default_rng(run_seed(self.sc.name, goal, seed, self.sc.experiment.base_seed))
        st = self.start_state(rng)
        out, st = self.episode(st, variant.build(), goal, rng, trace, recorder)
        return RunResult(out.outcome, out.distance_m, out.steps, out.decisions, time.perf_counter() - t0,
                         np.asarray(st.trail, np.float32), sorted(st.read_signs), out.trace)

    def shortest_for(self, goal, seed: int) -> float:
        """The shortest path (m) of run ``seed`` for ``goal`` (the same for every seed unless a
        task varies its world by seed)."""
        return self.shortest.get(self.goal_value(goal), float("nan"))

    def rows(self, variant: Variant, goal, seed: int, res: RunResult) -> list[dict]:
        """The rows of one finished run: its own, then any per-stage rows."""
        row = run_row(self.kind, self.sc.name, variant, goal, seed, res, self.shortest_for(goal, seed),
                      self.sc.navigation.navigator)
        return [row] + [{**row, **s} for s in res.stages]

    def max_steps(self) -> int:
        e = self.sc.experiment
        return e.max_steps or int(np.ceil(e.max_distance / self.sc.robot.step * 1.5)) + 100

    # ---- beside the runs --------------------------------------------------------------
    def write_inputs(self, out: Path) -> None:
        """Write what the runs read besides the scenario (detection logs) into ``out``."""

    def describe(self) -> dict:
        """What ``semsearch validate`` prints."""
        w = self.world
        return {"name": self.sc.name, "kind": self.kind, "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
                "planners": self.planner_labels()}


def build_task(sc: Scenario, world: World, path: Path) -> Task:
    """The task of a scenario's kind, built and checked."""
    kind = sc.search_kind
    if kind not in TASKS:
        raise ScenarioError(str(path), "kind", f"no task of kind {kind!r}; known: {', '.join(sorted(TASKS))}")
    return TASKS[kind].build(sc, world, path)
