"""The ``llm`` planner in door search: what the model reads at a re-plan, and how its answer
becomes a frontier target.

The model reads the decision as text (the goal, the frame, the robot's pose and distance so far,
the signs read, the frontier targets it may drive to, numbered nearest first along the path; see
:func:`observation`):

- ``mode: actor``: the model answers one target's number (or the last number: look at the
  nearest wall face no camera has read yet, what every door planner does when it returns None);
- ``mode: estimator``: the model answers its probability that the goal lies beyond each target,
  and the planner chooses by expected cost (:mod:`.core`), ``d_i`` the path to target ``i``.

Its fallback, after the re-asks: the nearest target (0).

The targets are the frontier candidates every door planner gets, reachable ones only, at most
``max_targets`` of them, ordered by their path length from the robot (a search to every target).
The first listed is greedy's choice: the nearest by greedy's own search (which stops at the first
target it reaches, and is the one the path then reuses), ties drawn from the run's generator
exactly as greedy draws them. So a model that always answers 0 makes greedy's runs, draw for draw:
the harness adds nothing of its own to a decision.
"""

from __future__ import annotations

import numpy as np

from ..base import Decision, DoorPlanner
from ..doors.greedy import path_order
from ..text import door_fields, door_targets
from .core import LlmCore


def observation(ctx, dist: np.ndarray, order: np.ndarray, cands, mode: str) -> dict:
    """The decision as the model reads it, field by field (:func:`~semsearch_cli.planners.text.door_fields`,
    the text of ``semsearch/DoorSearch-v1`` too): ``order`` the candidates shown (indices into
    ``cands``), ``dist`` their path lengths (m) by candidate."""
    return door_fields(ctx.goal, (ctx.x, ctx.y, ctx.heading), ctx.distance, ctx.belief,
                       door_targets(ctx, dist, order, cands), mode)


class DoorLlm(LlmCore, DoorPlanner):
    """The ``llm`` planner's door search (see the module docstring)."""

    def choose(self, ctx, cands):
        self.begin("doors")
        if len(cands) == 0:
            return None
        shown = path_order(ctx, cands, self._live.max_targets)
        if shown is None:
            return None
        d, order = shown
        fields = observation(ctx, d, order, cands, self._live.mode)
        n = len(order)
        pick, info = self.ask(fields, range(n + 1) if self._live.mode == "actor" else range(n), d[order], 0)
        if pick == n:  # look at a wall
            return None
        i = int(order[pick])
        return Decision(int(cands.rows[i]), int(cands.cols[i]), {"llm": pick, "D": float(d[i]), **info})
