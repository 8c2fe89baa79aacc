"""Privileged reference planners: told something about the episode that a robot is not
(:attr:`~semsearch_cli.planners.base.Planner.privileged`), they bound what reasoning over door
signs can buy. They are references on the board, never competitors (docs/bench.md).

``oracle_goal`` is told where the goal's sign is, not the map. At each re-plan it takes the
frontier candidate ``c`` that minimises

    D(c) + E(c),

``D(c)`` the robot's path to ``c`` along the skeleton of the map built so far (m) and ``E(c)`` the
straight line from ``c`` to the nearest sign carrying the goal's label (m): the frontier through
which the goal looks nearest, with what lies past the frontier unknown. It explores as greedy does
(the same candidates, the same navigator, the same completeness sweep when no frontier is left), so
the difference between the two is what knowing the goal's position is worth, and the share of that
difference a planner recovers from the signs it reads is the board's "gap closed".
"""

from __future__ import annotations

import numpy as np

from ...errors import PlannerError
from ..base import Decision, DoorPlanner, register_planner


@register_planner("oracle_goal")
class OracleGoal(DoorPlanner):
    """Privileged: told the goal sign's position, not the map; the frontier minimising the path to
    it plus the straight line from it to the goal (the ceiling on what reading signs can buy)."""

    rank = 90
    privileged = "the goal sign's position (x, y), not the map"

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        if ctx.told is None or not ctx.told.goal_xy:
            raise PlannerError("oracle_goal is privileged and was told no goal position: it runs where the world's "
                               "signs are known (the simulator, a bench run), not on a robot")
        b = ctx.belief
        gs = b.search(ctx.row, ctx.col, cands.rows, cands.cols, len(cands))
        d = gs.lengths(cands.rows, cands.cols) * b.frame.res
        x, y = b.frame.to_world(cands.rows, cands.cols)
        goals = np.asarray(ctx.told.goal_xy, float)
        e = np.hypot(x[:, None] - goals[None, :, 0], y[:, None] - goals[None, :, 1]).min(axis=1)
        score = d + e
        if not np.isfinite(score).any():
            return None
        best = np.flatnonzero(score == score[np.isfinite(score)].min())
        k = int(best[0] if best.size == 1 else ctx.rng.choice(best))
        return Decision(int(cands.rows[k]), int(cands.cols[k]), {"D": float(d[k]), "E": float(e[k])})
