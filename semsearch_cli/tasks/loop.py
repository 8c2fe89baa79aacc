"""The one step loop of every episode (STYLE: one fixed, written step order).

Each step: (1) sense, (2) update the belief, (3) stop if the target was seen, (4) re-plan if an
event asks, (5) move one step along the path, (6) check the budget. What sensing, the belief, an
event and a plan mean is the task's (:class:`Search`); the order, the motion and the budget are
the same for every task. The budget is the scenario's ``max_distance`` (and ``max_steps``) over
the robot's whole history, so a chain's stages share one budget.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Generator
from typing import Protocol

from ..errors import BudgetSpent
from ..navigation import advance
from .state import RobotState
from .decisions import DecisionPoint, ask

STALL_STEPS = 50  # steps without moving before a run is stuck
PROGRESS_S = 10.0  # s of wall-clock time between the lines a long run prints about itself
_RUN = {"what": None, "last": 0.0}  # the run under way in this process (set by the runner)


def running(what: str | None) -> None:
    """Name the run this process starts (None when it ends): a run longer than ``PROGRESS_S``
    then prints a line every ``PROGRESS_S`` seconds to stderr (distance so far), so that a long
    run on a huge map shows it is alive, off a terminal too."""
    _RUN["what"], _RUN["last"] = what, time.monotonic()


def _alive(st: RobotState) -> None:
    now = time.monotonic()
    if _RUN["what"] is not None and now - _RUN["last"] >= PROGRESS_S:
        _RUN["last"] = now
        print(f"run {_RUN['what']}: {st.distance:.0f} m so far, {st.steps} steps", file=sys.stderr, flush=True)


class Search(Protocol):
    """The task-specific part of one episode."""

    decisions: int

    def sense(self, st: RobotState) -> tuple[bool, bool]:
        """Read the sensors at the robot's pose; (target seen, an event that asks for a re-plan)."""

    def update(self, st: RobotState) -> None:
        """Fold what was sensed into the belief."""

    def replan_due(self, path_done: bool, since_plan: float, event: bool) -> bool:
        """Whether to re-plan now (the path is used up, ``since_plan`` m travelled since the last
        plan, a sensing event)."""

    def plan(self, st: RobotState):
        """Waypoints ``(xs, ys)`` (m) from the robot's position, or the outcome that ends the
        episode when there is nowhere to go (``found`` when looking around saw the target); as a
        generator, after yielding each :class:`~semsearch_cli.tasks.decisions.DecisionPoint` it
        needs answered (the one place a run stops for a decision)."""


class Stepper:
    """One episode's step loop, stopped at each re-plan so that someone else may make the plan:
    :func:`run_loop` makes it with the task's planner, a Gymnasium environment
    (``semsearch_cli.envs``) with an agent's action. Both run this one loop.

    :meth:`advance` runs steps until the episode ends (returns the outcome) or a re-plan is due
    (returns None); :meth:`follow` then takes the plan (waypoints, or the outcome that ends the
    episode) and finishes the step with the move. ``move(st, px, py, i) -> (i, moved)`` replaces
    the default motion (``step`` metres along the path, the heading following it), e.g. for a
    robot that turns at a finite rate; a step in which the pose does not change at all counts
    towards ``stuck``.
    """

    def __init__(self, search: Search, st: RobotState, step: float, max_distance: float, max_steps: int, move=None):
        self.search, self.st, self.step = search, st, step
        self.max_distance, self.max_steps, self.move = max_distance, max_steps, move
        self.px = self.py = None
        self.i = 0
        self.since_plan = 0.0
        self.stall = 0
        self.outcome: str | None = None
        self._moving = False  # a plan was taken: the step's move comes next

    def advance(self) -> str | None:
        """Steps until an outcome (returned, also kept in ``outcome``) or a due re-plan (None)."""
        search, st = self.search, self.st
        while self.outcome is None:
            if self._moving:
                self._moving = False
                if (out := self._move()) is not None:
                    self.outcome = out
                    break
            found, event = search.sense(st)  # 1. sense
            search.update(st)  # 2. belief
            if found:  # 3. success
                self.outcome = "found"
                break
            if search.replan_due(self.px is None or self.i >= len(self.px), self.since_plan, event):  # 4. re-plan
                return None
            self._moving = True
        return self.outcome

    def follow(self, plan) -> str | None:
        """Take ``plan`` (waypoints ``(xs, ys)`` in m, or an outcome) and go on to the next re-plan
        or the end, as :meth:`advance`."""
        if isinstance(plan, str):
            self.outcome = plan
            return plan
        self.px, self.py = plan
        self.i = 1
        self.since_plan = 0.0
        self._moving = True
        return self.advance()

    def look(self) -> bool:
        """Sense at the pose and fold it into the belief, outside the loop (the start of an
        episode stepped by primitive actions, :meth:`take`): whether the target was seen."""
        found, _ = self.search.sense(self.st)
        self.search.update(self.st)
        if found:
            self.outcome = "found"
        return found

    def take(self, motion) -> str | None:
        """One step of someone else's motion instead of the plan's (a primitive action of an
        environment): ``motion(st)`` moves the pose and returns the metres moved; the step is
        counted (distance, steps, trail), then sensed and folded in (:meth:`look`). Returns
        ``found``, ``budget`` (the distance or step limit reached) or None. No plan and no
        decision point: the agent moves the robot itself."""
        if self.outcome is not None:
            raise RuntimeError(f"the episode has ended ({self.outcome})")
        st = self.st
        moved = float(motion(st))
        st.distance += moved
        st.steps += 1
        st.trail.append((st.x, st.y))
        if self.look():
            return "found"
        if st.distance >= self.max_distance or st.steps >= self.max_steps:
            self.outcome = "budget"
        return self.outcome

    def _move(self) -> str | None:
        st = self.st
        h0 = st.heading
        if self.move is None:  # 5. move
            st.x, st.y, self.i, st.heading, moved = advance(self.px, self.py, self.i, st.x, st.y, st.heading, self.step)
        else:
            self.i, moved = self.move(st, self.px, self.py, self.i)
        st.distance += moved
        self.since_plan += moved
        st.steps += 1
        st.trail.append((st.x, st.y))
        if not st.steps & 63:
            _alive(st)
        self.stall = self.stall + 1 if moved < 1e-9 and st.heading == h0 else 0
        if self.stall >= STALL_STEPS:  # 6. budget
            return "stuck"
        if st.distance >= self.max_distance or st.steps >= self.max_steps:
            return "budget"
        return None


class Session:
    """One episode driven decision by decision: the :class:`Stepper` loop, with the kind's
    re-plan (``Search.plan``: a generator that yields
    :class:`~semsearch_cli.tasks.decisions.DecisionPoint` and is sent the choice, or a function
    that returns the plan outright) suspended at each decision point.

    :meth:`start` and :meth:`answer` run the episode to its next decision point (returned) or to
    its end (the outcome, a string). :func:`run_loop` answers every point with ``decide`` (the
    batch, a recording, a replay); a Gymnasium environment answers with the agent's actions. Both
    are this one loop."""

    def __init__(self, search: Search, st: RobotState, step: float, max_distance: float, max_steps: int, move=None):
        self.search, self.st = search, st
        self.stepper = Stepper(search, st, step, max_distance, max_steps, move)
        self.point: DecisionPoint | None = None  # the decision the episode waits for
        self.outcome: str | None = None
        self._plan = None  # the suspended re-plan

    def start(self):
        """Run to the first decision point (returned) or the end (the outcome)."""
        return self._go(self.stepper.advance())

    def answer(self, choice):
        """Take ``choice`` at the pending decision point; run to the next one or the end."""
        if self._plan is None:
            raise RuntimeError("no decision is pending")
        try:
            self.point = self._plan.send(choice)
            return self.point
        except StopIteration as stop:
            self._plan = None
            return self._go(self.stepper.follow(stop.value))

    def _go(self, out):
        while out is None:
            plan = self.search.plan(self.st)
            if isinstance(plan, Generator):
                try:
                    self.point = next(plan)
                    self._plan = plan
                    return self.point
                except StopIteration as stop:
                    plan = stop.value
            out = self.stepper.follow(plan)
        self.point, self.outcome = None, out
        return out


def drive(search: Search, st: RobotState, step: float, max_distance: float, max_steps: int, move=None):
    """The step loop of one search as a generator (a kind's :meth:`~semsearch_cli.tasks.base.Task.steps`
    runs it with ``yield from``): it yields its :class:`Session` once, first (so that whoever
    drives the run can see the search and take primitive steps, :meth:`Stepper.take`), then each
    :class:`~semsearch_cli.tasks.decisions.DecisionPoint`, and is sent the choice; it returns the
    outcome. A :class:`~semsearch_cli.errors.BudgetSpent` thrown in at a decision point (a
    planner's own budget spent: a language model's calls or tokens) ends the search as ``budget``."""
    session = Session(search, st, step, max_distance, max_steps, move)
    yield session
    point = session.start()
    while isinstance(point, DecisionPoint):
        try:
            choice = yield point
        except BudgetSpent:
            return "budget"
        point = session.answer(choice)
    return point


def answer_all(steps: Generator, decide=ask):
    """Run ``steps`` (a generator of a kind's search: :func:`drive`, a task's ``steps``) to its
    end, each decision point answered by ``decide``, a planner's spent budget
    (:class:`~semsearch_cli.errors.BudgetSpent`) thrown back in; returns what the generator returns."""
    send = spent = None
    while True:
        try:
            item = steps.throw(spent) if spent is not None else steps.send(send)
        except StopIteration as stop:
            return stop.value
        send = spent = None
        if isinstance(item, DecisionPoint):
            try:
                send = decide(item)
            except BudgetSpent as exc:
                spent = exc


def run_loop(search: Search, st: RobotState, step: float, max_distance: float, max_steps: int, move=None,
             decide=ask) -> str:
    """Drive ``st`` (changed in place) until an outcome: found, budget, stuck, or whatever
    :meth:`Search.plan` returns when there is nowhere to go (see :class:`Stepper`), each decision
    point answered by ``decide`` (by default the seated planner). A planner whose own budget is
    spent (:class:`~semsearch_cli.errors.BudgetSpent`) ends the run as ``budget``. The same as
    :func:`drive` answered by :func:`answer_all`."""
    return answer_all(drive(search, st, step, max_distance, max_steps, move), decide)
