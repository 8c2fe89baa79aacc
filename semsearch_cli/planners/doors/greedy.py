"""Greedy: the nearest candidate along the skeleton (thesis 4.4.2; phi = phi_c)."""

from __future__ import annotations

import numpy as np

from ..base import Decision, DoorPlanner, register_planner


def nearest_candidate(ctx, cands) -> Decision | None:
    """The candidate nearest to the robot along the skeleton (ties: the run's generator)."""
    if len(cands) == 0:
        return None
    gs = ctx.belief.search(ctx.row, ctx.col, cands.rows, cands.cols, 1)
    d = gs.lengths(cands.rows, cands.cols)
    if not np.isfinite(d).any():
        return None
    best = np.flatnonzero(d == d.min())
    k = int(best[0] if best.size == 1 else ctx.rng.choice(best))
    return Decision(int(cands.rows[k]), int(cands.cols[k]), {"D": float(d[k])})


@register_planner("greedy")
class Greedy(DoorPlanner):
    """The nearest frontier candidate (the thesis' geometric baseline)."""

    rank = 0
    baseline = True

    def choose(self, ctx, cands):
        return nearest_candidate(ctx, cands)
