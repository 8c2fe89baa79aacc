"""Privileged reference planners: told something about the episode that a robot is not
(:attr:`~semsearch_cli.planners.base.Planner.privileged`), they bound what reasoning over door
signs can buy. They are references on the board, never competitors (docs/bench.md).

``oracle_goal`` is told where the goal's sign is, not the map. At each re-plan it takes the
frontier candidate ``c`` that minimises

    D(c) + E(c),

``D(c)`` the robot's path to ``c`` along the skeleton of the map built so far (m) and ``E(c)`` the
rest of the way from ``c`` to the nearest sign carrying the goal's label (m): the frontier through
which the goal looks nearest, with what lies past the frontier unknown. ``beyond`` says how that
rest is measured: ``unknown`` (the default), the shortest path through every cell not known to be
a wall (the unknown taken as free, the known walls kept: the goal behind a wall seen already is
not near); ``line``, the straight line (the planner the issue that asked for it measured). It explores as greedy does
(the same candidates, the same navigator, the same completeness sweep when no frontier is left), so
the difference between the two is what knowing the goal's position is worth, and the share of that
difference a planner recovers from the signs it reads is the board's "gap closed".
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...errors import PlannerError
from ...kernels.grid import GridSearch
from ..base import Decision, DoorPlanner, register_planner


class OracleParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    beyond: Literal["unknown", "line"] = Field("unknown", description="the way from a frontier to the goal: unknown: "
                                               "the shortest path through every cell not known to be a wall; line: the "
                                               "straight line")


@register_planner("oracle_goal")
class OracleGoal(DoorPlanner):
    """Privileged: told the goal sign's position, not the map; the frontier minimising the path to
    it plus the straight line from it to the goal (the ceiling on what reading signs can buy)."""

    rank = 90
    privileged = "the goal sign's position (x, y), not the map"
    Params = OracleParams

    def __init__(self, params):
        super().__init__(params)
        self._gs = None  # the search from the goal (beyond: unknown), kept between re-plans
        self._one = None

    def rest(self, b, goals: np.ndarray, rows, cols) -> np.ndarray:
        """The way (m) from each cell (rows, cols) to the nearest goal: the straight line, or the
        shortest path through the cells not known to be walls (``beyond``); inf where none."""
        fr = b.frame
        x, y = fr.to_world(rows, cols)
        if self.params.beyond == "line":
            return np.hypot(x[:, None] - goals[None, :, 0], y[:, None] - goals[None, :, 1]).min(axis=1)
        H, W = b.free.shape
        if self._gs is None or self._gs.shape != (H, W):
            self._gs, self._one = GridSearch((H, W)), np.ones((H, W), np.float32)
        gr, gc = fr.to_index(goals[:, 0], goals[:, 1])
        gr, gc = np.clip(np.atleast_1d(gr), 0, H - 1), np.clip(np.atleast_1d(gc), 0, W - 1)
        open_ = ~(b.seen & ~b.free)  # free or unknown
        open_[gr, gc] = True  # the sign's cell, on its wall
        self._gs.run(open_, self._one, gr, gc, rows, cols, 0)
        return self._gs.lengths(rows, cols) * fr.res

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        if ctx.told is None or not ctx.told.goal_xy:
            raise PlannerError("oracle_goal is privileged and was told no goal position: it runs where the world's "
                               "signs are known (the simulator, a bench run), not on a robot")
        b = ctx.belief
        gs = b.search(ctx.row, ctx.col, cands.rows, cands.cols, len(cands))
        d = gs.lengths(cands.rows, cands.cols) * b.frame.res
        e = self.rest(b, np.asarray(ctx.told.goal_xy, float).reshape(-1, 2), cands.rows, cands.cols)
        score = d + e
        if not np.isfinite(score).any():
            return None
        best = np.flatnonzero(score == score[np.isfinite(score)].min())
        k = int(best[0] if best.size == 1 else ctx.rng.choice(best))
        return Decision(int(cands.rows[k]), int(cands.cols[k]), {"D": float(d[k]), "E": float(e[k])})
