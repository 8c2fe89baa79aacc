"""Greedy: the nearest candidate along the skeleton (thesis 4.4.2; phi = phi_c)."""

from __future__ import annotations

import numpy as np

from ..base import Decision, DoorPlanner, register_planner


def greedy_draw(ctx, cands) -> tuple[np.ndarray, int] | None:
    """Greedy's search over the candidates (path lengths in cells, inf where there is none) and
    the candidate it takes: the nearest, ties drawn from the run's generator; None when none is
    reachable (nothing drawn)."""
    d = ctx.belief.search(ctx.row, ctx.col, cands.rows, cands.cols, 1).lengths(cands.rows, cands.cols)
    if not np.isfinite(d).any():
        return None
    best = np.flatnonzero(d == d.min())
    return d, int(best[0] if best.size == 1 else ctx.rng.choice(best))


def nearest_candidate(ctx, cands) -> Decision | None:
    """The candidate nearest to the robot along the skeleton (ties: the run's generator)."""
    if len(cands) == 0:
        return None
    drawn = greedy_draw(ctx, cands)
    if drawn is None:
        return None
    d, k = drawn
    return Decision(int(cands.rows[k]), int(cands.cols[k]), {"D": float(d[k])})


def path_order(ctx, cands, limit: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The frontier targets as the llm planner and ``semsearch/DoorSearch-v1`` show them: the
    reachable candidates ordered by their path length from the robot, greedy's choice first
    (:func:`nearest_candidate`'s search and its tie drawn from the run's generator, exactly as
    greedy draws it), at most ``limit`` of them. Returns ``(d, order)``: ``d`` (m) the path length
    to every candidate (inf where there is none), ``order`` the candidates shown (indices into
    ``cands``); None when no candidate is reachable (nothing drawn). Greedy's search runs last, so
    that the path to the target chosen reuses it as greedy's does."""
    b, res = ctx.belief, ctx.belief.frame.res
    d = b.search(ctx.row, ctx.col, cands.rows, cands.cols, 0).lengths(cands.rows, cands.cols) * res  # every target
    drawn = greedy_draw(ctx, cands)  # greedy's own search and draw, exactly
    if drawn is None:
        return None
    near, first = drawn
    if not np.isfinite(d[first]):
        d[first] = near[first] * res
    ok = np.flatnonzero(np.isfinite(d))
    rest = [int(i) for i in ok[np.lexsort((ok, d[ok]))] if i != first]
    return d, np.asarray([first, *rest][:limit], np.int64)


@register_planner("greedy")
class Greedy(DoorPlanner):
    """The nearest frontier candidate (the thesis' geometric baseline)."""

    rank = 0
    baseline = True

    def choose(self, ctx, cands):
        return nearest_candidate(ctx, cands)
