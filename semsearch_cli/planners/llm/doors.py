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

import math

import numpy as np

from ..base import Decision, DoorPlanner
from ..text import ANGLES_TEXT, answer_line, deg, spell
from .core import LlmCore


def observation(ctx, dist: np.ndarray, order: np.ndarray, cands, mode: str) -> dict:
    """The decision as the model reads it, field by field (:data:`FIELDS`): ``order`` the
    candidates shown (indices into ``cands``), ``dist`` their path lengths (m) by candidate."""
    b = ctx.belief
    label = str(ctx.goal)
    travelled = "" if not math.isfinite(ctx.distance) else f"; travelled {ctx.distance:.1f} m"
    f = {"goal": f"Goal: read the door sign {label}.", "label": label,
         "frame": ("Frame: x points east and y north, in metres; a target's distance is the length of the robot's path "
                   "to it, every other distance a straight line. " + ANGLES_TEXT),
         "pose": f"You are at x {ctx.x:.1f} m, y {ctx.y:.1f} m, heading {deg(ctx.heading)} deg{travelled}."}
    reads = b.reads.lists(np.arange(b.reads.n), b.spec.min_reads)
    signs = sorted(((str(lab), x - ctx.x, y - ctx.y) for lab, (_, x, y) in reads.items()), key=lambda s: s[1] ** 2 + s[2] ** 2)
    f["signs"] = ("Signs read so far, nearest first (where you stood when you read each): " + "; ".join(
        f"{lab} read {math.hypot(dx, dy):.1f} m away, bearing {deg(math.atan2(dy, dx))} deg" for lab, dx, dy in signs) + "."
        if signs else "No sign read yet.")
    xs, ys = b.frame.to_world(cands.rows[order], cands.cols[order])
    lines = [("Targets: frontier points on the edge of the explored area, nearest first along the path, each with the "
              "direction in which unexplored space goes on beyond it" + (", or look at a wall:" if mode == "actor" else ":"))]
    lines += [f"[{k}] {dist[i]:.1f} m along the path, bearing {deg(math.atan2(y - ctx.y, x - ctx.x))} deg, unexplored space "
              f"towards {deg(cands.theta[i])} deg" for k, (i, x, y) in enumerate(zip(order, xs, ys))]
    n = len(order)
    if mode == "actor":
        lines.append(f"[{n}] look at the nearest wall face no camera has read yet")
    f["targets"] = "\n".join(lines)
    f["answer"] = (answer_line(np.ones(n + 1, bool)) if mode == "actor" else
                   f"Answer with one JSON object mapping target numbers ({spell(range(n))}) to probabilities from 0 to 1.")
    f["observation"] = "\n".join(f[k] for k in ("goal", "frame", "pose", "signs", "targets", "answer"))
    return f


class DoorLlm(LlmCore, DoorPlanner):
    """The ``llm`` planner's door search (see the module docstring)."""

    def choose(self, ctx, cands):
        self.begin("doors")
        if len(cands) == 0:
            return None
        b, res = ctx.belief, ctx.belief.frame.res
        d = b.search(ctx.row, ctx.col, cands.rows, cands.cols, 0).lengths(cands.rows, cands.cols) * res  # every target
        # then greedy's own search, last, so that the path to the target reuses it as greedy's does
        near = b.search(ctx.row, ctx.col, cands.rows, cands.cols, 1).lengths(cands.rows, cands.cols)
        if not np.isfinite(near).any():
            return None
        best = np.flatnonzero(near == near.min())
        first = int(best[0] if best.size == 1 else ctx.rng.choice(best))  # greedy's draw, exactly
        if not math.isfinite(d[first]):
            d[first] = near[first] * res
        ok = np.flatnonzero(np.isfinite(d))
        rest = [int(i) for i in ok[np.lexsort((ok, d[ok]))] if i != first]
        order = np.asarray([first, *rest][:self._live.max_targets], np.int64)
        fields = observation(ctx, d, order, cands, self._live.mode)
        n = len(order)
        pick, info = self.ask(fields, range(n + 1) if self._live.mode == "actor" else range(n), d[order], 0)
        if pick == n:  # look at a wall
            return None
        i = int(order[pick])
        return Decision(int(cands.rows[i]), int(cands.cols[i]), {"llm": pick, "D": float(d[i]), **info})
