"""The draft paper's planner (../shared/seeds/draft_semantic_goal_directed_exploration.txt,
Section III-C): ``phi(c) = tau(c) + Omega(c) + alpha Gamma(c)``, the robot going to
argmax phi over the frontier candidates c.

The draft is unfinished; what it defines, and how each gap is filled here:

- **Parity attraction tau** (the draft's Eqs. 5-8 are cut). From the authors' code:
  the belief in a parity is ``bel = min(1, beta * n)``, n the number of signs of that parity in
  the candidate's segment N(c) read more than ``parity_reads`` (5) times there;
  ``diff = min(0, bel_goal - bel_other)``; ``tau = 0.5 + (bel_goal + diff |diff|) / 2``, with
  beta = 0.1. *Gap*: the code names odd and even, not the goal's parity; we read ``bel`` as the
  belief in the goal's parity and ``diff`` as that belief minus the other's, so tau is 1 when the
  segment holds only the goal's parity (10 or more such signs), 0 when only the other, and 0.5
  with no signs. tau is defined for numeric goals only (0.5 otherwise).
- **Growing direction Omega** (Eqs. 9-10, which survive). FF(N(c)) is the direction of the sum of
  the vectors from sign l to sign l' over the pairs l < l' of N(c), and GG its norm divided by
  ``max(w_g, number of vectors)`` (the draft's PARAM). *Gaps*: the draft does not say whether
  the vectors are unit vectors (we sum unit vectors, as NSOS does, so that GG is in [0, 1]) nor
  what RR is (we take the candidate's branch direction theta_f, the only per-candidate angle in
  the draft's set-up). Eq. 9: ``TT = KK(RR, FF)`` if the goal is bigger than every sign of N(c),
  else ``KK(RR, FF - pi)``, KK the absolute angle between two directions (in [0, pi]).
  Eq. 10: ``Omega = 0.5`` when ``SMALLER < g < BIGGER``, else ``0.5 + TT' GG / 2`` with
  ``TT' = 1 - 2 TT / pi``. *Gap*: with the goal smaller than every sign the "otherwise" branch of
  Eq. 9 applies (turn away from the increasing direction); a goal equal to SMALLER or BIGGER
  cannot be in N(c) (it would have been read), so it is treated like the otherwise branch too.
- **Physical distance Gamma** (section 3 is "!!!!" in the draft). We read it as NSOS's closeness:
  ``Gamma = phi_c = 1 - (1 - D_min / D(c))^4``, D the skeleton distance (NSOS paper Eq. 16).
- *Gap*: the draft's "door numbers read" per segment uses the same door lists as NSOS (thesis
  4.2.3), with every read counted (``min_reads`` 1) so that the parity threshold above applies to
  the reads made from the segment.
- *Gap*: its tables show "Ours (10)" and "Ours (20)" without saying what 10 and 20 are; we expose
  ``w_g`` (PARAM), ``beta``, ``parity_reads`` and ``alpha`` and default to w_g = 8 and
  alpha = 1.
- *Gap*: the draft has no rule for ties nor for a robot oscillating between two candidates as
  closeness drifts; the planner keeps NSOS's hysteresis (keep the last target while its phi is
  within ``hysteresis`` of the best and no new sign has been counted) and NSOS's tie-break
  (nearest, then the run's generator).
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...geometry import wrap_angle
from ...world.labels import parse_label
from ..base import Decision, register_planner
from .nsos import KeepTarget, increasing_sum, pick


def parity_attraction(numbers, goal: int, beta: float) -> float:
    """tau: 0.5 + (bel_goal + diff |diff|) / 2 with bel = min(1, beta n) per parity and
    diff = min(0, bel_goal - bel_other); ``numbers`` are the signs that count."""
    numbers = np.asarray(numbers)
    same = int((numbers % 2 == goal % 2).sum())
    bel_goal = min(1.0, beta * same)
    bel_other = min(1.0, beta * (numbers.size - same))
    diff = min(0.0, bel_goal - bel_other)
    return 0.5 + (bel_goal + diff * abs(diff)) / 2.0


def increasing_strength(numbers, xs, ys, w_g: float) -> tuple[float | None, float]:
    """(FF, GG): the direction of the summed unit vectors from each sign to every larger one, and
    their norm over max(w_g, number of vectors); (None, 0) without two distinct numbers."""
    ff, norm, pairs = increasing_sum(np.asarray(numbers), np.asarray(xs, float), np.asarray(ys, float))
    if ff is None:
        return None, 0.0
    return ff, min(1.0, norm / max(w_g, float(pairs)))


def growing_attraction(numbers, xs, ys, goal: int, theta_f: float, w_g: float) -> float:
    """Omega of the draft's Eqs. 9-10 for a candidate whose branch points along ``theta_f``."""
    numbers = np.asarray(numbers)
    if numbers.size and numbers.min() < goal < numbers.max():
        return 0.5
    ff, gg = increasing_strength(numbers, xs, ys, w_g)
    if ff is None:
        return 0.5
    toward = ff if numbers.size and goal > numbers.max() else ff - math.pi
    tt = abs(float(wrap_angle(theta_f - toward)))
    return 0.5 + (1.0 - 2.0 * tt / math.pi) * gg / 2.0


class DraftParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    alpha: float = Field(1.0, ge=0.0, description="weight of the closeness term Gamma")
    beta: float = Field(0.1, gt=0.0, le=1.0, description="parity belief per sign of that parity")
    parity_reads: int = Field(5, ge=0, description="a sign counts for parity when read more than this many times in the segment")
    w_g: float = Field(8.0, gt=0.0, description="the draft's PARAM: vectors needed for full growing-direction strength")
    hysteresis: float = Field(0.01, ge=0.0, description="keep the last target while its phi is within this of the best")


@register_planner("draft")
class Draft(KeepTarget):
    """phi = tau + Omega + alpha Gamma (the draft paper's planner), with NSOS's hysteresis."""

    rank = 3

    Params = DraftParams

    def _decide(self, ctx, cands, keep: int | None = None):
        k = len(cands)
        p, b = self.params, ctx.belief
        dist = self.distances(ctx, cands)
        if dist is None:
            return None
        D, reach, gamma = dist
        tau = np.full(k, 0.5)
        omega = np.full(k, 0.5)
        label = parse_label(ctx.goal)  # the numbers of the signs that share the goal's prefix (world/labels.py)
        goal = None if label is None else label.number
        if goal is not None:
            seg, lists = b.segment_door_lists(cands.seg_rows, cands.seg_cols, 1)
            per_seg = []
            for lst in lists:
                items = [(q.number, cnt, x, y) for lab, (cnt, x, y) in lst.items()
                         if (q := parse_label(lab)) is not None and q.prefix == label.prefix]
                nums = np.array([i[0] for i in items], np.int64)
                cnt = np.array([i[1] for i in items], np.int64)
                per_seg.append((nums, np.array([i[2] for i in items]), np.array([i[3] for i in items]), nums[cnt > p.parity_reads]))
            for i in range(k):
                if seg[i] < 0:
                    continue
                nums, xs, ys, counted = per_seg[seg[i]]
                tau[i] = parity_attraction(counted, goal, p.beta)
                omega[i] = growing_attraction(nums, xs, ys, goal, cands.theta[i], p.w_g)
        phi = tau + omega + p.alpha * gamma
        phi[~reach] = -np.inf
        j = pick(phi, D, keep, p.hysteresis, ctx.rng)
        if not ctx.explain:
            return Decision(int(cands.rows[j]), int(cands.cols[j]), {"chosen": j})
        xs_w, ys_w = b.frame.to_world(cands.rows, cands.cols)
        info = {"chosen": j, "candidates": [
            {"x": round(float(xs_w[i]), 2), "y": round(float(ys_w[i]), 2), "theta_f_deg": round(float(np.degrees(cands.theta[i])), 1),
             "D_m": round(float(D[i]) * b.frame.res, 2) if reach[i] else None, "tau": round(float(tau[i]), 4),
             "Omega": round(float(omega[i]), 4), "Gamma": round(float(gamma[i]), 4),
             "phi": round(float(phi[i]), 4) if reach[i] else None} for i in range(k)]}
        return Decision(int(cands.rows[j]), int(cands.cols[j]), info)
