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
from typing import Protocol

from ..navigation import advance
from .base import RobotState

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
    trace: list

    def sense(self, st: RobotState) -> tuple[bool, bool]:
        """Read the sensors at the robot's pose; (target seen, an event that asks for a re-plan)."""

    def update(self, st: RobotState) -> None:
        """Fold what was sensed into the belief."""

    def replan_due(self, path_done: bool, since_plan: float, event: bool) -> bool:
        """Whether to re-plan now (the path is used up, ``since_plan`` m travelled since the last
        plan, a sensing event)."""

    def plan(self, st: RobotState):
        """Waypoints ``(xs, ys)`` (m) from the robot's position, or the outcome that ends the
        episode when there is nowhere to go (``found`` when looking around saw the target)."""


def run_loop(search: Search, st: RobotState, step: float, max_distance: float, max_steps: int, move=None) -> str:
    """Drive ``st`` (changed in place) until an outcome: found, budget, stuck, or whatever
    :meth:`Search.plan` returns when there is nowhere to go. ``move(st, px, py, i) -> (i, moved)``
    replaces the default motion (``step`` metres along the path, the heading following it), e.g.
    for a robot that turns at a finite rate; a step in which the pose does not change at all
    counts towards ``stuck``."""
    px = py = None
    i = 0
    since_plan = 0.0
    stall = 0
    while True:
        found, event = search.sense(st)  # 1. sense
        search.update(st)  # 2. belief
        if found:  # 3. success
            return "found"
        if search.replan_due(px is None or i >= len(px), since_plan, event):  # 4. re-plan on events
            plan = search.plan(st)
            if isinstance(plan, str):
                return plan
            px, py = plan
            i = 1
            since_plan = 0.0
        h0 = st.heading
        if move is None:  # 5. move
            st.x, st.y, i, st.heading, moved = advance(px, py, i, st.x, st.y, st.heading, step)
        else:
            i, moved = move(st, px, py, i)
        st.distance += moved
        since_plan += moved
        st.steps += 1
        st.trail.append((st.x, st.y))
        if not st.steps & 63:
            _alive(st)
        stall = stall + 1 if moved < 1e-9 and st.heading == h0 else 0
        if stall >= STALL_STEPS:  # 6. budget
            return "stuck"
        if st.distance >= max_distance or st.steps >= max_steps:
            return "budget"
