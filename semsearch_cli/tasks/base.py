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

import copy
import dataclasses
import inspect
import math
import time
from collections.abc import Generator
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from ..config import Scenario
from ..deprecation import warn
from ..kernels.grid import dijkstra
from ..errors import BudgetSpent, PlannerError, ScenarioError
from ..metrics import run_row
from ..registry import Registry
from ..navigation import NAVIGATORS
from ..planners import Variant, expand_variants
from ..world.ground_truth import World, build_world
from .decisions import DecisionPoint, Seat, ask
from .loop import Session, answer_all
from .state import RobotState
from .episodes import Episode, check_hash, draw_starts, episode_seed, given_episodes, label_words, region_mask


@dataclass
class Outcome:
    """How one episode ended: ``outcome`` is found, not_found (the planner had nowhere left to
    look), stuck (no path to anywhere new), budget or error; the counts are this episode's.
    What a kind adds to its run's result: ``left_m`` (None: the task's :meth:`Task.distance_left`
    from where the run ended), ``time_s`` (simulated), ``message``, ``stages`` (a chain's rows)."""

    outcome: str
    distance_m: float
    steps: int
    decisions: int
    left_m: float | None = None
    time_s: float = float("nan")
    message: str = ""
    stages: list = field(default_factory=list)
    record: dict = field(default_factory=dict)  # the kind's own columns of the run's row (Task.columns)


@dataclass(frozen=True, kw_only=True)
class Event:
    """What a search decided at a re-plan, as its observers see it. Each kind defines its own
    (``DoorDecision``, ``ObjectTarget``, ``IndirectGoal``, in its task module) with
    :meth:`trace_row`, the JSON-able row ``--trace`` writes; ``stage`` is a chain's stage (1, 2,
    ...), None outside chains; ``traced``: whether the trace keeps it (a new target)."""

    stage: int | None = None

    @property
    def traced(self) -> bool:
        return True

    def row(self) -> dict:  # pragma: no cover
        raise NotImplementedError

    def frame(self) -> dict | None:
        """What a replay draws of this moment (arrays and numbers; None: nothing to draw)."""
        return None

    def trace_row(self) -> dict:
        row = self.row()
        return row if self.stage is None else {**row, "stage": self.stage}


class Observer:
    """Sees every :class:`Event` of a run (``Task.run(..., observer)``): the trace of
    ``semsearch run --trace`` (:class:`TraceObserver`), a report's replay, a notebook's plot.
    Observing changes nothing in the run; a planner may tabulate more for an observed run
    (``DoorContext.explain``). An observer with ``steps`` true also sees every sensing frame,
    step and re-plan of a door search (``DoorFrame``, ``DoorStep``, ``DoorPlan``), for an export
    that needs the whole run (``semsearch export``)."""

    steps = False

    def see(self, event: Event) -> None:  # pragma: no cover
        raise NotImplementedError


class TraceObserver(Observer):
    """Keeps the trace row of each event the trace keeps: ``rows``, what traces/<run>.jsonl holds."""

    def __init__(self):
        self.rows: list[dict] = []

    def see(self, event: Event) -> None:
        if event.traced:
            self.rows.append(event.trace_row())


class FrameRecorder(Observer):
    """Keeps the frames of a run's replay (:meth:`Event.frame`), evenly spaced: every ``step``-th
    event, ``step`` doubling (and every other frame kept dropped) whenever more than ``limit``
    are kept, so a long run costs at most ``limit`` frames."""

    def __init__(self, limit: int = 120):
        self.limit, self.step, self.count = limit, 1, 0
        self.frames: list[dict] = []

    def see(self, event: Event) -> None:
        self.count += 1
        if (self.count - 1) % self.step:
            return
        frame = event.frame()
        if frame is None:
            return
        self.frames.append(frame)
        if len(self.frames) > self.limit:
            self.frames = self.frames[::2]
            self.step *= 2


class Observers(Observer):
    """Several observers of one run."""

    def __init__(self, *observers: Observer):
        self.observers = [o for o in observers if o is not None]

    def see(self, event: Event) -> None:
        for o in self.observers:
            o.see(event)


class StageObserver(Observer):
    """Passes a chain stage's events on to ``inner``, marked with the stage's number."""

    def __init__(self, inner: Observer, stage: int):
        self.inner, self.stage = inner, stage

    def see(self, event: Event) -> None:
        self.inner.see(dataclasses.replace(event, stage=self.stage))


@dataclass
class RunResult:
    outcome: str  # found | not_found | stuck | budget | error | timeout
    distance_m: float
    steps: int
    decisions: int
    wall_s: float
    path: np.ndarray  # (n, 2) float32, m
    read_signs: list = field(default_factory=list)  # sign indices read at least once
    trace: list = field(default_factory=list)  # one dict per decision, when traced (runner.execute)
    frames: list = field(default_factory=list)  # a replay's frames, when recorded (runner.execute)
    stages: list = field(default_factory=list)  # extra rows of a run (chains: one per stage and mode)
    message: str = ""
    time_s: float = float("nan")  # simulated seconds, for tasks with a clock
    left_m: float = float("nan")  # geodesic distance left to the goal where the run ended (0 when found)
    start_heading: float = float("nan")  # rad, the heading the run started with
    decisions_record: dict | None = None  # the run's decisions, when recorded (runner.execute; tasks.decisions)
    record: dict = field(default_factory=dict)  # the kind's own columns of the run's row (Outcome.record), and its planners' costs
    transcripts: list = field(default_factory=list)  # its planners' transcripts (language models: one list of JSON objects each)


def checked_cell(planner: str, row, col, free: np.ndarray) -> tuple[int, int]:
    """A planner's target cell after the checks every decision gets: whole numbers, on the map,
    a free cell of the belief; else a :class:`~semsearch_cli.errors.PlannerError` naming the
    planner and the value (the run is recorded as ``error``)."""
    H, W = free.shape
    try:
        r, c = int(row), int(col)
        if (r, c) != (row, col):
            raise ValueError
    except (TypeError, ValueError, OverflowError):
        raise PlannerError(f"planner {planner!r} chose the cell ({row!r}, {col!r}): not a pair of whole numbers") from None
    if not (0 <= r < H and 0 <= c < W):
        raise PlannerError(f"planner {planner!r} chose the cell ({r}, {c}), off the map ({H} x {W} cells)")
    if not free[r, c]:
        raise PlannerError(f"planner {planner!r} chose the cell ({r}, {c}), which the belief does not hold free")
    return r, c


def checked_point(planner: str, x, y, frame, heading=None) -> tuple[float, float]:
    """A planner's target point (m) after the checks every decision gets: finite numbers, on the
    map, and a finite ``heading`` when one is given; else a
    :class:`~semsearch_cli.errors.PlannerError` naming the planner and the value."""
    if heading is not None and not (isinstance(heading, (int, float, np.number)) and math.isfinite(heading)):
        raise PlannerError(f"planner {planner!r} chose the heading {heading!r}: not a finite number")
    try:
        fx, fy = float(x), float(y)
    except (TypeError, ValueError):
        raise PlannerError(f"planner {planner!r} chose the point ({x!r}, {y!r}): not numbers") from None
    if not (math.isfinite(fx) and math.isfinite(fy)):
        raise PlannerError(f"planner {planner!r} chose the point ({fx}, {fy}): not finite")
    r, c = frame.to_index(fx, fy)
    if not (0 <= r < frame.height and 0 <= c < frame.width):
        raise PlannerError(f"planner {planner!r} chose the point ({fx:.2f}, {fy:.2f}) m, off the map")
    return fx, fy


class OpenEpisode:
    """One run of one episode, opened (:meth:`Task.open`) and stepped decision by decision: the
    handle every driver holds, whoever answers the decisions.

    :meth:`start` runs the episode to its first decision point (returned: a
    :class:`~semsearch_cli.tasks.decisions.DecisionPoint`, with the kind's ``observation``, its
    ``choices`` and the legal-choice ``mask``) or to its end (the outcome, a string);
    :meth:`answer` takes a choice from outside (an agent, a user) and runs to the next point or
    the end; :meth:`ask` has the seat answer instead (the planner, a recording, a replay), and
    :meth:`play` lets it answer every point. :meth:`take` steps the robot by a motion of the
    agent's own (primitive actions) instead of by decisions. When the episode has ended,
    ``outcome`` is set and :meth:`result` and :meth:`rows` give what the batch writes.

    ``state`` (the :class:`RobotState`, changed as the run goes), ``rng`` (the run's generator),
    ``episode``, ``seed``, ``variant`` and ``seat`` are the run's; ``point`` is the decision the
    run waits at (None when it does not), ``session`` the loop of the search under way
    (:class:`~semsearch_cli.tasks.loop.Session`: its ``search`` and ``stepper``)."""

    def __init__(self, task: "Task", variant: Variant | None, ep, seed: int, seat: Seat | None,
                 observer: Observer | None):
        self.t0 = time.perf_counter()
        self.task, self.observer = task, observer
        self.episode = ep = task.as_episode(ep)
        self.seed = int(seed)
        self.seat = Seat() if seat is None else seat
        self.variant = Variant(getattr(self.seat, "name", "agent"), ()) if variant is None else variant
        self.rng = np.random.default_rng(episode_seed(ep, seed, task.sc.experiment.base_seed))
        self.state = task.start_state(ep, self.rng)
        self.start_heading = self.state.heading
        self.seat.run = {"scenario": task.sc.name, "kind": task.planner_kind, "planner": self.variant.label,
                         "goal": str(ep.goal), "episode": int(ep.index), "seed": self.seed}
        steps = task.search(self.variant, ep, self.seed, self.state, self.rng, self.seat, observer)
        # a kind's search of before 0.4.0 returns its Outcome, having run whole (the seat answered)
        self._steps = steps if isinstance(steps, Generator) else _ran(steps)
        self.session: Session | None = None
        self.point: DecisionPoint | None = None
        self.outcome: str | None = None
        self._started = False
        self._result: RunResult | None = None

    # ---- what the driver reads ------------------------------------------------------------
    @property
    def observation(self):
        """What a planner of the kind reads at the pending decision (None when none is pending)."""
        return None if self.point is None else self.point.observation

    @property
    def mask(self) -> np.ndarray | None:
        """The legal choices of the pending decision (None when none is pending)."""
        return None if self.point is None else self.point.mask

    @property
    def search(self):
        """The kind's search under way (its ``Search``; None before :meth:`start`)."""
        return None if self.session is None else self.session.search

    # ---- stepping -------------------------------------------------------------------------
    def start(self, primitive: bool = False):
        """Run to the first decision point (returned) or the end (the outcome). With
        ``primitive``: only set the search up and sense at the start pose; the agent then moves
        the robot itself (:meth:`take`), and no decision is asked. Returns the outcome (found:
        the target is in view from the start) or None."""
        if self._started:
            raise RuntimeError("the episode has started already")
        self._started = True
        if not primitive:
            return self._advance()
        try:
            item = self._steps.send(None)  # a search shows its loop first (tasks.loop.drive)
        except StopIteration:
            item = None
        if not isinstance(item, Session):
            raise RuntimeError(f"a {self.task.kind} search has no step loop to take primitive steps in")
        self.session = item
        return self._primitive_end() if item.stepper.look() else None

    def answer(self, choice):
        """Take ``choice`` at the pending decision point; run to the next one (returned) or the end
        (the outcome)."""
        self._pending()
        self.point = None
        return self._advance(choice)

    def ask(self):
        """Have the seat answer the pending decision point (the planner's answer, or a record's);
        run to the next one or the end, as :meth:`answer`. A planner whose own budget is spent
        (:class:`~semsearch_cli.errors.BudgetSpent`) ends the search as ``budget``."""
        point = self._pending()
        try:
            choice = self.seat.decide(point)
        except BudgetSpent as exc:
            self.point = None
            return self._advance(spent=exc)
        self.point = None
        return self._advance(choice)

    def play(self) -> RunResult:
        """Let the seat answer every decision to the end (started if it was not); the result."""
        item = self.start() if not self._started else self.point if self.point is not None else self.outcome
        while isinstance(item, DecisionPoint):
            item = self.ask()
        return self.result()

    def take(self, motion) -> str | None:
        """One primitive step (after ``start(primitive=True)``): ``motion(st)`` moves the pose and
        returns the metres moved (:meth:`~semsearch_cli.tasks.loop.Stepper.take`); returns the
        outcome (found, budget) or None."""
        if self.session is None or self.point is not None or self._result is not None:
            raise RuntimeError("take() steps an episode started with start(primitive=True) that has not ended")
        return self._primitive_end() if self.session.stepper.take(motion) is not None else None

    # ---- the end ----------------------------------------------------------------------------
    def result(self) -> RunResult:
        """The run's result, once it has ended."""
        if self._result is None:
            raise RuntimeError("the episode has not ended")
        return self._result

    def rows(self) -> list[dict]:
        """The rows the batch writes of this run (its own, then a chain's stage rows)."""
        return self.task.rows(self.variant, self.episode, self.seed, self.result())

    def _pending(self) -> DecisionPoint:
        if self.point is None:
            raise RuntimeError("no decision is pending" + (f": the episode has ended ({self.outcome})" if self.outcome else ""))
        return self.point

    def _advance(self, send=None, spent: BaseException | None = None):
        while True:
            try:
                item = self._steps.throw(spent) if spent is not None else self._steps.send(send)
            except StopIteration as stop:
                return self._end(stop.value)
            send = spent = None
            if isinstance(item, Session):
                self.session = item
                continue
            self.point = item
            return item

    def _primitive_end(self) -> str:
        st = self.state
        self._steps.close()
        return self._end(Outcome(self.session.stepper.outcome, st.distance, st.steps, 0))

    def _end(self, out: Outcome) -> str:
        seat, st, ep = self.seat, self.state, self.episode
        seat.finish()
        left = out.left_m if out.left_m is not None else 0.0 if out.outcome == "found" else self.task.distance_left(ep.goal, st.x, st.y)
        message = out.message or (seat.notes() if out.outcome == "budget" else "")
        self._result = RunResult(out.outcome, out.distance_m, out.steps, out.decisions, time.perf_counter() - self.t0,
                                 np.asarray(st.trail, np.float32), sorted(st.read_signs), stages=out.stages,
                                 message=message, time_s=out.time_s, left_m=left, start_heading=self.start_heading,
                                 record={**out.record, **seat.costs()}, transcripts=seat.transcripts())
        self.outcome = out.outcome
        return out.outcome


class Task:
    """One kind of search over a scenario, whatever its world. Subclasses set ``kind``,
    ``planner_kind`` (which registered planners answer it), ``columns`` (its own row columns
    beyond every kind's, filled by :meth:`record`) and ``records`` (the columns it fills on every
    row), and implement :meth:`build_world`, :meth:`build`,
    :meth:`build_episodes` and :meth:`episode` (and usually :attr:`goals`); a kind on a map
    subclasses :class:`OnMapTask`, which does the world and the episodes."""

    kind: ClassVar[str] = ""
    planner_kind: ClassVar[str] = ""  # the kind the registered planners that answer it answer (Planner.answers)
    noun: ClassVar[str] = ""  # what the kind searches for, in a sentence ("door signs")
    records: ClassVar[tuple[str, ...]] = ()  # the row columns this kind fills with a value on every row
    columns: ClassVar[tuple[str, ...]] = ()  # the kind's own row columns, beyond every kind's (metrics.SHARED)

    def episode_row(self, ep: Episode) -> dict:
        """An episode as a row of ``semsearch episodes``' CSV."""
        return ep.row()

    @classmethod
    def example(cls, folder: Path, planner: str) -> Path:
        """Write a small scenario of this kind run by ``planner`` (with the files it names) into
        ``folder`` and return its YAML file: seconds to run, for the tests every kind shares."""
        raise NotImplementedError

    def __init__(self, sc: Scenario, world, path: Path):
        """``world``: what :meth:`build_world` built (a kind's own type)."""
        self.sc, self.world, self.path = sc, world, Path(path)
        self.file = str(path)
        self.shortest: dict = {}  # goal -> shortest path (m) from the scenario's start, set by each kind's build
        self._episodes: list[Episode] | None = None
        self._variants: tuple | None = None  # (the planner entries, their variants)

    # ---- built from the scenario ------------------------------------------------------
    @property
    def goals(self) -> list:
        """The goal labels of the runs (door numbers, request labels, chain names)."""
        return list(self.sc.goals)

    def variants(self, specs=None) -> list[Variant]:
        """The scenario's planner entries (or ``specs``) as variants, checked for this kind; the
        scenario's own expanded once (their files loaded once), then kept."""
        if specs is not None:
            return expand_variants(specs, self.file, self.planner_kind, self.path.parent)
        entries = self.sc.planners
        if self._variants is None or self._variants[0] is not entries:  # sc replaced (Loaded.with_planners): expand again
            self._variants = (entries, expand_variants(entries, self.file, self.planner_kind, self.path.parent))
        return list(self._variants[1])

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

    # ---- episodes ---------------------------------------------------------------------
    @property
    def episodes(self) -> list[Episode]:
        """The scenario's episode set (see :mod:`.episodes`), built on first use."""
        if self._episodes is None:
            self._episodes = self.build_episodes()
        return self._episodes

    # ---- the kind's world and episodes ---------------------------------------------------
    @classmethod
    def build_world(cls, sc: Scenario, base: Path, file: str):  # pragma: no cover
        """The world a scenario of this kind is searched in, built from it (paths relative to
        ``base``) and checked: each kind builds its own (:class:`OnMapTask`: a map, its signs and
        a start; indirect search: its rooms)."""
        raise NotImplementedError

    def build_episodes(self) -> list[Episode]:  # pragma: no cover
        """The scenario's episode set (a kind defines it; see :mod:`.episodes`)."""
        raise NotImplementedError

    def as_episode(self, ep) -> Episode:
        """``ep`` itself when it is an :class:`Episode`, else a goal's first episode, or the one
        :meth:`from_start` gives for a goal the set lacks (a convenience for scripts and tests:
        ``task.run(variant, 148, 0)``)."""
        if isinstance(ep, Episode):
            return ep
        for e in self.episodes:
            if str(e.goal) == str(ep) or (isinstance(ep, float) and str(e.goal) == f"{ep:g}"):
                return e
        return self.from_start(ep)

    def from_start(self, goal) -> Episode:
        """The episode of a goal the episode set lacks (a kind on a map starts it at the
        scenario's start); here: a :class:`ScenarioError`."""
        raise ScenarioError(self.file, "goals", f"no episode of goal {goal}")

    def distance_left(self, goal, x: float, y: float) -> float:
        """The distance (m) from (x, y) to ``goal``, where a run that did not find it ended:
        NaN (unknown) unless the kind measures it."""
        return math.nan

    def memory_per_run(self) -> int:
        """Bytes one run of this scenario holds at its peak, about (0: not known; the batch checks
        the workers' memory against it)."""
        return 0

    # ---- running ----------------------------------------------------------------------
    def start_state(self, ep: Episode, rng: np.random.Generator) -> RobotState:
        """The robot at the episode's start (a heading left to each repeat draws from ``rng``)."""
        heading = math.radians(ep.heading) if ep.heading is not None else float(rng.uniform(-np.pi, np.pi))
        return RobotState(ep.x, ep.y, heading, trail=[(ep.x, ep.y)])

    def steps(self, state: RobotState, planner, goal, rng: np.random.Generator, observer: Observer | None = None):  # pragma: no cover
        """One search for ``goal`` by ``planner`` from ``state``, as a generator: it runs the step
        loop with ``yield from`` :func:`~semsearch_cli.tasks.loop.drive` (or several, one after
        another), so that it yields each decision point and is sent the choice, and returns
        ``(Outcome, state)``. Whoever drives the run answers (:meth:`open`)."""
        raise NotImplementedError

    def episode(self, state: RobotState, planner, goal, rng: np.random.Generator,
                observer: Observer | None = None, decide=ask, **options) -> tuple[Outcome, RobotState]:
        """One search for ``goal`` by ``planner`` from ``state``, its decisions answered by
        ``decide`` (by default the planner's; :mod:`.decisions`): :meth:`steps` run to its end
        (``options``: the kind's own, e.g. door search's ``reuse_reads``, indirect search's ``room``)."""
        return answer_all(self.steps(state, planner, goal, rng, observer, **options), decide)

    def open(self, variant: Variant | None, ep, seed: int, *, seat: Seat | None = None,
             observer: Observer | None = None) -> "OpenEpisode":
        """Repeat ``seed`` of episode ``ep`` (or of a goal's first episode), opened: the start
        state drawn and the search set up, nothing run yet; step it with
        :meth:`OpenEpisode.start` and :meth:`OpenEpisode.answer`, or let the seat answer every
        decision (:meth:`OpenEpisode.play`). ``seat`` says who sits in the planner's seat
        (default: the variant's planner, :class:`~semsearch_cli.tasks.decisions.Seat`; an
        :class:`~semsearch_cli.tasks.decisions.Agent` for choices from outside, with ``variant``
        None); ``observer`` sees the run's events. The one way every driver runs an episode: the
        batch, ``semsearch verify``, the Gymnasium environments and the robot bridge."""
        return OpenEpisode(self, variant, ep, seed, seat, observer)

    def run(self, variant: Variant, ep: Episode, seed: int, observer: Observer | None = None,
            seat: Seat | None = None) -> RunResult:
        """Repeat ``seed`` of episode ``ep`` (or of a goal's first episode), every decision answered
        by ``seat`` (default: the variant's planner; a
        :class:`~semsearch_cli.tasks.decisions.Recording` keeps them, a
        :class:`~semsearch_cli.tasks.decisions.Replay` answers from a record): :meth:`open`, then
        :meth:`OpenEpisode.play`. Every kind's run."""
        return self.open(variant, ep, seed, seat=seat, observer=observer).play()

    def search(self, variant: Variant, ep: Episode, seed: int, st: RobotState, rng: np.random.Generator, seat: Seat,
               observer: Observer | None):
        """One run's search from ``st`` (changed in place), as a generator of its decision points
        that returns the :class:`Outcome`: by default one :meth:`steps` of the variant's planner
        (as ``seat`` seats it) for the episode's goal."""
        if answers_itself(type(self)):  # a kind of before 0.4.0: its episode() answers its own decisions
            out, _ = self.episode(st, seat.planner(variant), ep.goal, rng, observer, decide=seat.decide)
            return out
        out, _ = yield from self.steps(st, seat.planner(variant), ep.goal, rng, observer)
        return out

    def with_budget(self, max_distance: float) -> "Task":
        """This task with ``experiment.max_distance`` replaced (and the step limit that follows from
        it), sharing its world and episodes: an environment's shorter training episodes."""
        task = copy.copy(self)
        e = self.sc.experiment
        task.sc = self.sc.model_copy(update={"experiment": e.model_copy(update={"max_distance": float(max_distance)})})
        task._variants = None
        return task

    def rows(self, variant: Variant, ep: Episode, seed: int, res: RunResult) -> list[dict]:
        """The rows of one finished run: its own, then any per-stage rows."""
        row = run_row(self.kind, self.sc.name, variant, ep, seed, res, self.navigator) | self.record(ep, res)
        return [row] + [{**row, **s} for s in res.stages]

    def record(self, ep: Episode, res: RunResult) -> dict:
        """The kind's own columns of a run's row (:attr:`columns`), beside every kind's
        (:func:`~semsearch_cli.metrics.run_row`): by default what its search put in
        :attr:`Outcome.record`."""
        return dict(res.record)

    @property
    def navigator(self) -> str:
        """The navigator the rows name: ``navigation.navigator`` for a kind that takes the
        navigation section; else ``geodesic``, as 0.2.0 wrote it (object search drives geodesic
        paths on the recorded map, indirect search any-angle paths over its room's cells)."""
        nav = getattr(self.sc, "navigation", None)
        return nav.navigator if nav is not None else "geodesic"

    # ---- beside the runs --------------------------------------------------------------
    def write_inputs(self, out: Path) -> None:
        """Write what the runs read besides the scenario (detection logs) into ``out``."""

    def describe(self) -> dict:
        """What ``semsearch validate`` prints."""
        return {"name": self.sc.name, "kind": self.kind, "planners": self.planner_labels()}

class OnMapTask(Task):
    """A kind searched on a map of the scenario's own (door search, object search, chains): the
    world is the map with its signs and start (:func:`~semsearch_cli.world.ground_truth.build_world`);
    a goal's shortest path and the distance left are geodesics on it; episodes start from the
    scenario's start, or are drawn or given on the map (:mod:`.episodes`)."""

    def __init__(self, sc: Scenario, world: World, path: Path):
        super().__init__(sc, world, path)
        self._fields: dict[str, np.ndarray] = {}  # goal -> distance field, only while episodes are drawn

    @classmethod
    def build_world(cls, sc: Scenario, base: Path, file: str) -> World:
        return build_world(sc, base, file)

    def goal_field(self, goal) -> np.ndarray:
        """(H, W) float, m: the ground-truth geodesic distance from every cell to ``goal`` (to the
        nearest pose that achieves it), inf where unreachable; kept while the episodes are drawn
        (one map-sized array per goal), then dropped."""
        key = str(goal)
        if key not in self._fields:
            w = self.world
            rr, cc = np.nonzero(self.goal_cells(goal))
            if not len(rr):
                self._fields[key] = np.full(w.reach.shape, np.inf)
            else:
                _, length, _ = dijkstra(w.reach, np.ones((1, 1), np.float32), rr, cc, np.zeros_like(w.reach), 0, np.inf)
                self._fields[key] = length * w.frame.res
        return self._fields[key]

    def goal_cells(self, goal) -> np.ndarray:  # pragma: no cover
        """(H, W) bool: the reachable poses that achieve ``goal`` (a kind defines it)."""
        raise NotImplementedError

    def distance_left(self, goal, x: float, y: float) -> float:
        """Geodesic distance (m) from (x, y) to ``goal``; inf when unreachable."""
        w = self.world
        r, c = w.frame.to_index(x, y)
        if str(goal) in self._fields:
            f = self._fields[str(goal)]
            return float(f[r, c]) if 0 <= r < f.shape[0] and 0 <= c < f.shape[1] else math.inf
        if not (0 <= r < w.reach.shape[0] and 0 <= c < w.reach.shape[1] and w.reach[r, c]):
            return math.inf
        return w.geodesic((int(r), int(c)), self.goal_cells(goal))[0]

    def shortest_from(self, goal, x: float, y: float) -> float:
        """The shortest path (m) of ``goal`` from a start at (x, y)."""
        return self.distance_left(goal, x, y)

    def build_episodes(self) -> list[Episode]:
        """The episodes of the scenario's ``episodes`` section, or one per goal from its start."""
        try:
            return self._build_episodes()
        finally:
            self._fields.clear()

    def _build_episodes(self) -> list[Episode]:
        spec, w = self.sc.episodes, self.world
        if spec is None:
            eps = [self.start_episode(g) for g in self.goals]
        else:
            eps = given_episodes(spec, self.path.parent, self.file)
            if eps is None:
                eps = self.draw_episodes(spec)
        goals = [self.check_episode_goal(e) for e in eps]
        for e in eps:
            if e.get("room") is not None:  # an indirect search's column: here it was dropped without a word
                raise ScenarioError(e["file"], f"{e['field']} room", f"a {self.sc.kind} scenario's episodes have no room "
                                    f"(the column is an indirect search's), got {str(e['room'])[:40]!r}; leave it empty")
            r, c = w.frame.to_index(e["x"], e["y"])
            if not (0 <= r < w.reach.shape[0] and 0 <= c < w.reach.shape[1] and w.reach[r, c]):
                raise ScenarioError(e["file"], e["field"], f"the start ({e['x']:g}, {e['y']:g}) m is not free space "
                                    "reachable from the scenario's start (or lies closer than the robot radius to a wall)")
        # a drawn or default episode brings its shortest path (inf only for a goal nothing achieves:
        # an object absent at its hour); a given one is measured here, one path search per goal
        # (its distance field) when the goal has several starts, one per start otherwise
        shortest = {k: e["shortest"] for k, e in enumerate(eps) if "shortest" in e}
        by_goal: dict[str, list[int]] = {}
        for k, goal in enumerate(goals):
            if k not in shortest:
                by_goal.setdefault(str(goal), []).append(k)
        for key, ks in by_goal.items():
            if len(ks) > 1 and type(self).shortest_from is OnMapTask.shortest_from:  # a kind measuring its own way skips it
                self.goal_field(goals[ks[0]])
            for k in ks:
                shortest[k] = self.shortest_from(goals[k], eps[k]["x"], eps[k]["y"])
            self._fields.pop(key, None)
        out = [Episode(k, goal, float(e["x"]), float(e["y"]), e["heading"], None, shortest[k])
               for k, (goal, e) in enumerate(zip(goals, eps))]
        for ep, e in zip(out, eps):
            check_hash(ep, e)
        return out

    def start_episode(self, goal) -> dict:
        """The episode of ``goal`` from the scenario's start (its heading, or None: per repeat), with
        the shortest path the kind's build measured from there."""
        w = self.world
        h = None if w.start_heading is None else float(np.degrees(w.start_heading))
        e = dict(goal=goal, x=w.start_xy[0], y=w.start_xy[1], heading=h, file=self.file, field="start")
        if goal in self.shortest:
            e["shortest"] = self.shortest[goal]
        return e

    def check_episode_goal(self, e: dict):
        """The goal an episode names, as the scenario writes it; a :class:`ScenarioError` when it
        is not one of the scenario's goals."""
        for g in self.goals:
            if str(g) == str(e["goal"]):
                return g
        raise ScenarioError(e["file"], e["field"], f"goal {e['goal']} is not one of the scenario's goals "
                            f"({', '.join(map(str, self.goals))})")

    def forget_field(self, goal) -> None:
        """Drop ``goal``'s distance field (:meth:`goal_field` holds it only while episodes are drawn)."""
        self._fields.pop(str(goal), None)

    def start_cells(self, spec) -> np.ndarray:
        """(H, W) bool: the cells a start of the episode set ``spec`` may be drawn on: reachable,
        ``spec.clearance`` m or more from walls, in ``spec.where``."""
        w = self.world
        return w.reach & (w.clearance >= spec.clearance) & region_mask(w.free, w.frame.res, spec.where, spec.corridor_width)

    def draw_episodes(self, spec) -> list[dict]:
        """``spec.starts`` drawn starts per goal (or shared by every goal), as in :mod:`.episodes`."""
        w = self.world
        stand = self.start_cells(spec)
        where = "" if spec.where == "anywhere" else f" in {spec.where}"
        band = f"between {spec.min_distance:g} and {spec.max_distance:g} m" if spec.max_distance else f"at least {spec.min_distance:g} m"
        out = []
        groups = [(list(self.goals), [spec.seed])] if spec.shared else [([g], [spec.seed, *label_words(g)]) for g in self.goals]
        for goals, seed in groups:
            fields = [f for f in (self.goal_field(g) for g in goals) if np.isfinite(f).any()]
            starts = draw_starts(stand, fields, w.frame.to_world, spec.starts,
                                 np.random.default_rng(seed), spec.min_distance, spec.max_distance)
            if not starts:
                raise ScenarioError(self.file, "episodes", f"no reachable free cell{where}, {spec.clearance:g} m or more from "
                                    f"walls, lies {band} from goal"
                                    f"{'s' if len(goals) > 1 else ''} {', '.join(map(str, goals))}; widen the distances "
                                    "or the region")
            for g in goals:
                out += [dict(goal=g, x=x, y=y, heading=h, file=self.file, field="episodes", shortest=self.shortest_from(g, x, y))
                        for x, y, h in starts]
                if not spec.shared:
                    self.forget_field(g)
        if spec.shared:  # goal by goal, as when drawn per goal
            out.sort(key=lambda e: [str(g) for g in self.goals].index(str(e["goal"])))
        return out

    def from_start(self, goal) -> Episode:
        """The episode of ``goal`` from the scenario's start (for a goal the episode set lacks)."""
        e = self.start_episode(goal)
        return Episode(-1, goal, e["x"], e["y"], e["heading"], None, e.get("shortest", self.shortest_from(goal, e["x"], e["y"])))

    def max_steps(self, max_distance: float | None = None) -> int:
        """The step limit: ``experiment.max_steps``, else 1.5 times the steps that
        ``max_distance`` (default: ``experiment.max_distance``) takes, and 100 more."""
        e = self.sc.experiment
        budget = e.max_distance if max_distance is None else max_distance
        return e.max_steps or int(np.ceil(budget / self.sc.robot.step * 1.5)) + 100

    BYTES_PER_CELL: ClassVar[int] = 110  # measured: one run on a 25-million-cell map took 2.6 GB

    def memory_per_run(self) -> int:
        """Bytes one run of this scenario holds at its peak, about: the map's cells times what a
        run keeps per cell (the belief's layers, the searches' state)."""
        f = self.world.frame
        return int(f.height * f.width * self.BYTES_PER_CELL)

    def describe(self) -> dict:
        """What ``semsearch validate`` prints."""
        w = self.world
        return {"name": self.sc.name, "kind": self.kind, "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
                "planners": self.planner_labels()}


TASKS = Registry("task", Task)  # kind -> its Task subclass


def _ran(out: Outcome):
    """A search that has run whole (a kind's ``search`` of before 0.4.0): no decision left, its outcome."""
    return out
    yield  # a generator, which returns at once


def answers_itself(cls) -> bool:
    """Whether kind ``cls`` is written as before 0.4.0: an ``episode(..., decide)`` of its own that
    is newer (in its class hierarchy) than the ``steps`` it has, so that the batch must call it."""
    mro = cls.__mro__
    ep = next(k for k in mro if "episode" in vars(k))
    st = next(k for k in mro if "steps" in vars(k))
    return ep is not Task and mro.index(ep) < mro.index(st)


def register_task(cls):
    """Class decorator: the task answers scenarios of kind ``cls.kind`` (a :class:`Task` subclass,
    one per kind). A kind that defines ``episode(..., decide)`` answering its own decisions, and
    no :meth:`Task.steps`, runs with a warning: it cannot be opened decision by decision."""
    if isinstance(cls, type) and issubclass(cls, Task) and answers_itself(cls):
        warn(f"a kind whose episode(..., decide) answers its own decisions (kind {getattr(cls, 'kind', '')!r}, "
             f"{cls.__module__}.{cls.__qualname__})", "write its steps(state, planner, goal, rng, observer) as a generator "
             "over tasks.loop.drive (yield from drive(search, ...)) and drop episode(); Task.episode answers it",
             since="0.4.0", until="0.5.0")
    if isinstance(cls, type) and issubclass(cls, Task) and not inspect.isgeneratorfunction(cls.search):
        warn(f"a kind whose search() runs whole and returns its Outcome (kind {getattr(cls, 'kind', '')!r}, "
             f"{cls.__module__}.{cls.__qualname__})", "write search as a generator that yields from steps() "
             "(out, _ = yield from self.steps(...)) and returns the Outcome", since="0.4.0", until="0.5.0")
    return TASKS.add(getattr(cls, "kind", ""), cls)


def build_task(sc: Scenario, world, path: Path) -> Task:
    """The task of a scenario's kind, built and checked, in ``world`` (None: the world the kind
    builds from the scenario, :meth:`Task.build_world`)."""
    kind = sc.kind
    if kind not in TASKS:
        raise ScenarioError(str(path), "kind", f"no task of kind {kind!r}; known: {', '.join(sorted(TASKS))}")
    nav = getattr(sc, "navigation", None)
    if nav is not None and nav.navigator not in NAVIGATORS:
        raise ScenarioError(str(path), "navigation.navigator", f"unknown navigator {nav.navigator!r}; valid: "
                            f"{', '.join(NAVIGATORS)}")
    cls = TASKS[kind]
    if world is None:
        world = cls.build_world(sc, Path(path).parent, str(path))
    task = cls.build(sc, world, path)
    task.episodes  # built and checked now: a bad episode is an error of the scenario's
    return task
