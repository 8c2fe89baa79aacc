"""Distance Advantage (Ericson, Pedro and Jensfelt 2025, "Information Gain Is Not All You Need",
arXiv:2504.01980): a geometric frontier planner that reads no sign.

Nearest-frontier takes the candidate of least path length from the robot, ``d(r, a)``. Distance
Advantage takes the candidate of most *advantage*: how much nearer it is to the robot now than it
is, on average, to the places the robot may be later,

    A(a) = mean_{v in S} d(v, a) - d(r, a),

``S`` the known free space around the robot. A frontier close to the robot but far from the rest
(a dead end, a side room) has a large advantage: visit it now, while it is cheap, or pay a detour
back to it later. A frontier in the middle of open space can wait.

Our reading, stated: ``S`` is the known skeleton cells of the belief (the corridor axes, where the
robot drives), every one of them by default, or those within ``window`` m of the robot (a square;
the authors' default is 61 cells of their 4.5-cell-per-metre grid, about 13.6 m), at most
``sources`` of them taken evenly in scan order. A window moves with the robot, and that makes the
choice indifferent to the robot's own motion: a step toward ``a`` shortens ``d(r, a)`` and, by
moving ``S`` toward ``a``, the mean too. On the training floors (salt ``semsearch-train-v1``, floors
0-11, 3 episodes each) a 13.5 m window spent the whole 2000 m budget turning between two targets
on 4 of the 36 episodes, the whole skeleton on none (mean 375.4 m and 190.5 m; greedy 158.4 m): the
default is the whole skeleton;
``d`` is the path length along the skeleton (:meth:`~semsearch_cli.belief.DoorBelief.search`),
as greedy's; the candidates are the frontier candidates every door planner gets. The authors also
filter the frontiers by information gain and use a map prediction in one variant; we use neither
(the variant without predictions).

As the robot moves, every candidate's advantage drifts, and a plain argmax taken afresh at each
re-plan can turn back and forth between two targets until the budget is spent (seen on doors-v1
val f000: 2000 m, 1,804 decisions): the planner keeps its last
target while it is still a candidate and its advantage is within ``hysteresis`` m of the best
(:class:`~.nsos.KeepTarget`, as nsos and learned keep theirs). 1 m is our choice, about a re-plan's
travel, not tuned.
"""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ..base import Decision, register_planner
from .nsos import KeepTarget, pick


class AdvantageParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    window: float | None = Field(None, gt=0, le=10_000, description="m, half-size of the square around the robot whose "
                                 "known skeleton cells are the places it may be later (None: every known skeleton cell)")
    sources: int = Field(200, ge=1, le=100_000, description="at most this many of those cells, taken evenly")
    hysteresis: float = Field(1.0, ge=0.0, description="m: keep the last target while its advantage is within this of "
                              "the best")


@register_planner("distance_advantage")
class DistanceAdvantage(KeepTarget):
    """Distance Advantage (Ericson, Pedro and Jensfelt 2025): the frontier candidate nearest to the
    robot relative to its mean distance from the known space around it; reads no sign."""

    rank = 1
    Params = AdvantageParams
    replan_on_signs = False  # it reads no sign

    def _decide(self, ctx, cands, keep):
        b, p = ctx.belief, self.params
        res = b.frame.res
        near = b.search(ctx.row, ctx.col, cands.rows, cands.cols, 0).lengths(cands.rows, cands.cols) * res
        reach = np.flatnonzero(np.isfinite(near))
        if not len(reach):
            return None
        H, W = b.free.shape
        k = int(np.ceil(p.window / res)) if p.window is not None else max(H, W)
        r0, r1, c0, c1 = max(0, ctx.row - k), min(H, ctx.row + k + 1), max(0, ctx.col - k), min(W, ctx.col + k + 1)
        rr, cc = np.nonzero(b.skeleton[r0:r1, c0:c1] & b.passable[r0:r1, c0:c1])
        rr, cc = rr + r0, cc + c0
        if len(rr) > p.sources:
            even = np.linspace(0, len(rr) - 1, p.sources).round().astype(np.int64)
            rr, cc = rr[even], cc[even]
        mean = np.full(len(cands), np.nan)
        for i in reach:
            d = b.search(int(cands.rows[i]), int(cands.cols[i]), rr, cc, 0).lengths(rr, cc) * res
            d = d[np.isfinite(d)]
            mean[i] = d.mean() if len(d) else 0.0
        adv = np.where(np.isfinite(mean), mean - near, -np.inf)
        i = pick(adv, np.where(np.isfinite(near), near, np.inf), keep, p.hysteresis, ctx.rng)
        return Decision(int(cands.rows[i]), int(cands.cols[i]), {"D": float(near[i]), "mean_from_S": float(mean[i]),
                                                               "advantage": float(adv[i]), "S": int(len(rr))})
