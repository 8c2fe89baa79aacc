"""``wall_numbers``: a planner that reads the numbers along each wall, predicts where the goal's
number falls, and takes the frontier through which the predicted goal is nearest.

Numbers on a floor run along walls: whatever the convention (rising along one wall and back the
other, odd and even on opposite walls, a hundred-block per corridor, rising from the middle
outward), two neighbouring doors on one wall differ by a few numbers, and a stretch of a wall
keeps its direction. The model uses only that (docs/numbering.md, "wall_numbers").

- **Walls.** Each sign read with the goal's prefix gives a number ``n``, its wall face (where the
  rays of its reads, robot position and bearing, leave the known free space:
  :meth:`~semsearch_cli.belief.DoorBelief.sign_faces`) and the axis of the cameras that read it,
  the unit vector ``v`` toward its wall. Two signs are on one wall when their ``v`` agree within 20 degrees and their faces lie
  within ``wall_gap`` m of one line across ``v``; along a wall (the coordinate ``t``, m) a gap of
  more than ``max_gap`` m between neighbours starts a new stretch.
- **Predictions.** On a stretch sorted by ``t``, with numbers merged where they repeat (a room's
  lettered doors):

  * a *bracket*: two neighbours ``(t_i, n_i)``, ``(t_j, n_j)`` whose numbers change by at most
    ``max_slope`` per metre and hold the goal number ``g`` strictly between them put the goal at
    ``t_i + (g - n_i)(t_j - t_i) / (n_j - n_i)``, weight 1;
  * an *extrapolation*: at each end of a stretch, the last (up to) three signs, strictly monotone,
    each step within ``max_slope`` per metre and the least-squares slope ``b`` at least
    ``min_slope``, that run toward ``g`` past the end put it at ``t_end + (g - n_end) / b``, weight
    ``exp(-|g - n_end| / tau)``: the more numbers lie between the last sign and the goal, the less
    a straight wall can be trusted to carry them;

  a prediction within ``passed`` m of a cell the robot has visited is weighed down 20 times (the
  robot passed it and did not read the goal there). A random numbering gives neighbours tens of
  numbers apart, past ``max_slope``: no prediction, and the planner is nearest-frontier.
- **The choice.** With ``w_j`` the predictions' weights and ``prior`` the weight of "none of them",
  ``pi_j = w_j / (prior + sum w)``; the frontier target ``c`` of least

      d(c) + sum_j pi_j |c - q_j|

  wins, ``d(c)`` the path to it along the skeleton (m) and ``|c - q_j|`` the straight line from it to
  prediction ``q_j``: ``oracle_goal``'s rule (``beyond=line``) over the predicted goal, weighed by
  belief, and nearest-frontier's where nothing is predicted. The last target is kept while its
  cost is within ``hysteresis`` m of the best (:class:`~.nsos.KeepTarget`).

It needs the bearing of each read: the simulator, ``semsearch verify`` and bags that
``semsearch export`` writes carry it; a robot's own detections do not yet, and there it is
nearest-frontier. Its values were chosen from the model's meaning and set on training floors only
(salt ``semsearch-train-v1``, docs/bench.md "Which floors to tune on").
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ...world.labels import parse_label
from ...errors import PlannerError
from ..base import Decision, DoorPlanner, register_planner
from .greedy import nearest_candidate

SAME_WALL_COS = math.cos(math.radians(20.0))


class WallParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    max_slope: float = Field(2.0, gt=0.0, le=100.0, description="numbers per metre: the most two neighbouring signs "
                             "on a wall may differ by and still be read as one numbering")
    min_slope: float = Field(0.1, ge=0.0, description="numbers per metre: the least slope an extrapolation takes")
    near: float = Field(5.0, ge=0.0, description="numbers: an extrapolation over at most this many numbers past a "
                        "wall's last sign weighs w_near")
    far: float = Field(10.0, ge=0.0, description="numbers: one over more than near and at most this many weighs w_far; "
                       "farther, none is made")
    w_near: float = Field(0.95, ge=0.0, le=1.0, description="the weight of a near extrapolation (and of a bracket)")
    w_far: float = Field(0.15, ge=0.0, le=1.0, description="the weight of a far extrapolation")
    supported: float = Field(0.5, ge=0.0, le=1.0, description="share of the wall line from the last sign to the "
                             "prediction that the map knows as wall, above which an extrapolation of any length weighs "
                             "w_wall")
    w_wall: float = Field(0.75, ge=0.0, le=1.0, description="the weight of an extrapolation along a wall the map shows")
    prior: float = Field(0.05, gt=0.0, description="the weight of 'no prediction holds'")
    wall_gap: float = Field(0.75, gt=0.0, description="m: faces within this of one line share a wall")
    max_gap: float = Field(12.0, gt=0.0, description="m: a gap along a wall longer than this starts a new stretch")
    passed: float = Field(3.0, ge=0.0, description="m: a prediction this near a visited cell is weighed down 20 times")
    reach: float = Field(10.0, gt=0.0, description="m: the farthest a sign's wall face is looked for from the robot")
    min_reads: int | None = Field(None, ge=1, description="reads before a sign counts (default: belief.min_reads)")


def walls(t_face: np.ndarray, o: np.ndarray, v: np.ndarray, wall_gap: float, max_gap: float) -> list[np.ndarray]:
    """Stretches of wall: index arrays into the signs, each sorted by ``t_face`` (coordinates
    along the wall in the frame of each sign's own ``v``: compared within a wall, whose ``v``
    agree)."""
    k = len(o)
    if k == 0:
        return []
    cos = v @ v.T
    across = np.abs(o[None, :] - o[:, None])
    same = (cos > SAME_WALL_COS) & (across < wall_gap)
    i, j = np.nonzero(same)
    n, lab = connected_components(coo_matrix((np.ones(len(i)), (i, j)), shape=(k, k)), directed=False)
    out = []
    for w in range(n):
        idx = np.flatnonzero(lab == w)
        idx = idx[np.argsort(t_face[idx], kind="stable")]
        cut = np.flatnonzero(np.diff(t_face[idx]) > max_gap) + 1
        out += [s for s in np.split(idx, cut) if len(s) >= 2]
    return out


def stretch_predictions(t: np.ndarray, n: np.ndarray, g: float, p: WallParams) -> list[tuple[float, float, float, float]]:
    """[(t of the goal along the stretch, weight, numbers from the nearest sign (0 for a bracket),
    t of the sign it is extrapolated from (a bracket: the goal's own t))] from one stretch's signs
    (``t`` sorted)."""
    # merge repeated numbers (a room's lettered doors): their mean position
    un, inv = np.unique(n, return_inverse=True)
    if len(un) < len(n):
        tt = np.bincount(inv, t) / np.bincount(inv)
        order = np.argsort(tt, kind="stable")
        t, n = tt[order], un[order]
    if len(t) < 2:
        return []
    out = []
    dt, dn = np.diff(t), np.diff(n)
    ok = (dt > 0.3) & (dn != 0) & (np.abs(dn) <= p.max_slope * np.maximum(dt, 0.3))
    for j in np.flatnonzero(ok & (np.minimum(n[:-1], n[1:]) < g) & (g < np.maximum(n[:-1], n[1:]))):
        tg = float(t[j] + (g - n[j]) * dt[j] / dn[j])
        out.append((tg, p.w_near, 0.0, tg))
    for end in (1, -1):  # the high-t end, then the low-t end
        m = min(3, len(t))
        sl = slice(len(t) - m, None) if end == 1 else slice(0, m)
        te, ne = t[sl], n[sl]
        steps_ok = ok[len(t) - m:] if end == 1 else ok[: m - 1]
        if not steps_ok.all() or not (np.all(np.diff(ne) > 0) or np.all(np.diff(ne) < 0)):
            continue
        slope = float(np.polyfit(te, ne, 1)[0])
        if abs(slope) < p.min_slope:
            continue
        t_end, n_end = (te[-1], ne[-1]) if end == 1 else (te[0], ne[0])
        tg = t_end + (g - n_end) / slope
        gap = abs(g - n_end)
        if (tg - t_end) * end > 0:
            out.append((float(tg), p.w_near if gap <= p.near else p.w_far, float(gap), float(t_end)))
    return out


def wall_support(b, p0: np.ndarray, p1: np.ndarray, v: np.ndarray) -> float:
    """The share of the wall line from ``p0`` to ``p1`` (faces, m) that the map knows as wall:
    points every half cell, a quarter cell beyond the face along ``v`` (the face is where a ray
    first met a cell that is not free, at most half a cell into it: still inside a one-cell wall)."""
    fr = b.frame
    n = max(2, int(np.hypot(*(p1 - p0)) / (fr.res / 2)))
    pts = p0[None, :] + (p1 - p0)[None, :] * np.linspace(0.0, 1.0, n)[:, None] + v[None, :] * (fr.res * 0.25)
    r, c = fr.to_index(pts[:, 0], pts[:, 1])
    H, W = b.free.shape
    ok = (r >= 0) & (r < H) & (c >= 0) & (c < W)
    r, c = np.clip(r, 0, H - 1), np.clip(c, 0, W - 1)
    return float((ok & b.seen[r, c] & ~b.free[r, c]).mean())


def predictions(ctx, p: WallParams) -> tuple[np.ndarray, np.ndarray]:
    """(q (m, 2) predicted positions of the goal's sign, m; w (m,) their weights) at a decision."""
    none = (np.zeros((0, 2)), np.zeros(0))
    goal = parse_label(ctx.goal)
    if goal is None:
        return none
    b = ctx.belief
    labels, face, v = b.sign_faces(p.min_reads, p.reach)
    if not labels:
        return none
    parsed = [parse_label(lab) for lab in labels]
    keep = np.array([q is not None and q.prefix == goal.prefix for q in parsed], bool)
    if keep.sum() < 2:
        return none
    face, v = face[keep], v[keep]
    n = np.array([q.number for q, k in zip(parsed, keep) if k], float)
    u = np.column_stack([-v[:, 1], v[:, 0]])  # along the wall
    o = (face * v).sum(axis=1)  # the wall line's offset, each in its own v
    t = (face * u).sum(axis=1)
    qs, ws, gaps, support = [], [], [], []
    for s in walls(t, o, v, p.wall_gap, p.max_gap):
        vv, uu = v[s[0]], u[s[0]]
        ts = face[s] @ uu  # along the first sign's frame
        oo = float(np.median(face[s] @ vv))
        order = np.argsort(ts, kind="stable")
        for tg, w, gap_, te in stretch_predictions(ts[order], n[s][order], float(goal.number), p):
            qs.append(uu * tg + vv * (oo - 0.5))  # half a metre off the wall, into the corridor
            ws.append(w)
            gaps.append(gap_)
            support.append(wall_support(b, uu * te + vv * oo, uu * tg + vv * oo, vv))
    if not qs:
        return none
    q, w, gaps, support = np.array(qs), np.array(ws), np.array(gaps), np.array(support)
    w = np.where((gaps > p.near) & (support > p.supported), p.w_wall, w)  # the map shows the wall running on to it
    keep = (gaps <= p.far) | (support > p.supported)
    if not keep.any():
        return none
    q, w = q[keep], w[keep]
    if p.passed > 0:
        fr = b.frame
        k = int(math.ceil(p.passed / fr.res))
        r, c = fr.to_index(q[:, 0], q[:, 1])
        H, W = b.visited.shape
        for i in range(len(q)):
            r0, r1, c0, c1 = max(0, r[i] - k), min(H, r[i] + k + 1), max(0, c[i] - k), min(W, c[i] + k + 1)
            if r0 < r1 and c0 < c1 and b.visited[r0:r1, c0:c1].any():
                w[i] /= 20.0
    return q, w


@register_planner("wall_numbers")
class WallNumbers(DoorPlanner):
    """The numbers along each wall read for where the goal's number falls (between two neighbours,
    or past a wall's last signs), and the frontier through which that prediction is nearest,
    weighed by belief; nearest-frontier where nothing is predicted (docs/numbering.md)."""

    rank = 4
    tuned_on = "doors-train, salt semsearch-train-v1 (training floors disjoint from the benchmark's)"
    Params = WallParams

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        q, w = predictions(ctx, self.params)
        if not len(q):
            return nearest_candidate(ctx, cands)
        b = ctx.belief
        gs = b.search(ctx.row, ctx.col, cands.rows, cands.cols, len(cands))
        d = gs.lengths(cands.rows, cands.cols) * b.frame.res
        if not np.isfinite(d).any():
            return None
        pi = w / (self.params.prior + w.sum())
        x, y = b.frame.to_world(cands.rows, cands.cols)
        cost = d + np.hypot(x[:, None] - q[None, :, 0], y[:, None] - q[None, :, 1]) @ pi
        best = np.flatnonzero(cost == cost[np.isfinite(cost)].min())
        k = int(best[0] if best.size == 1 else ctx.rng.choice(best))
        return Decision(int(cands.rows[k]), int(cands.cols[k]), {"D": float(d[k]), "cost_m": float(cost[k]),
                                                               "predictions": int(len(q)), "belief": float(pi.sum())})


@register_planner("wall_rule")
class WallRule(WallNumbers):
    """Privileged: ``wall_numbers`` told, for every stretch of wall it has read a sign on, the
    rest of that stretch's numbers (the rule of the walls it saw, not the map); where the goal's
    sign is on one of them, it goes for it as ``oracle_goal`` does (beyond: line). The bound between
    inferring a wall's numbering from the signs read and knowing it (docs/bench.md)."""

    rank = 91
    privileged = "every sign's position on each stretch of wall it has read a sign on (the walls' numbering), not the map"
    tuned_on = WallNumbers.tuned_on

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        told = ctx.told
        if told is None or not told.walls:
            raise PlannerError("wall_rule is privileged and was told no walls: it runs where the world's signs are known "
                               "(the simulator, a bench run), not on a robot")
        b = ctx.belief
        read = {lab for lab, n in b.reads.total.items() if n >= (self.params.min_reads or b.spec.min_reads)}
        seen = {w for lab, _, _, w in told.walls if lab in read}
        goal = [(x, y) for lab, x, y, w in told.walls if w in seen and str(lab) == str(ctx.goal)]
        if not goal:
            return super().choose(ctx, cands)
        gs = b.search(ctx.row, ctx.col, cands.rows, cands.cols, len(cands))
        d = gs.lengths(cands.rows, cands.cols) * b.frame.res
        if not np.isfinite(d).any():
            return None
        x, y = b.frame.to_world(cands.rows, cands.cols)
        g = np.asarray(goal, float)
        cost = d + np.hypot(x[:, None] - g[None, :, 0], y[:, None] - g[None, :, 1]).min(axis=1)
        best = np.flatnonzero(cost == cost[np.isfinite(cost)].min())
        k = int(best[0] if best.size == 1 else ctx.rng.choice(best))
        return Decision(int(cands.rows[k]), int(cands.cols[k]), {"D": float(d[k]), "cost_m": float(cost[k]), "told": True})
