"""NSOS semantic planner (thesis 4.3; paper Section 4) and the ``geometric`` planner.

For each frontier candidate c (segment S(c), branch direction theta_f(c)):

- growing direction (Eqs. 4.9-4.11): ``phi_g = (zeta * gamma + 1) / 2`` with
  ``zeta = (n_smaller - n_bigger) / max(n_smaller + n_bigger, w_g)`` over the numbered signs of S
  (Eq. 4.9 as written: +1 when all signs are smaller than the goal, so the goal lies in the
  increasing direction) and ``gamma = 1 - 2 |wrap(theta_f - theta_inc)| / pi``, where theta_inc is
  the direction of the sum of the unit vectors from sign l to sign l' over all pairs l < l'
  (positions: the mean robot position at the sign's reads); gamma = 0 with fewer than two distinct
  numbers (or when the vectors cancel);
- parity (Eq. 4.12): ``phi_p = 0.5 + 0.5 (n_same - n_diff) / max(n_same + n_diff, w_p)``;
- door orientation (Eq. 4.13): ``phi_o = H_d[theta_f]``, H_d the normalised histogram of the
  robot's heading modulo 180 degrees at its last ``lambda_d`` sign reads, ``door_bins`` bins
  centred on 0, 45, 90, 135 degrees (for 4 bins);
- robot orientation (Eq. 4.14): ``phi_r = H_r[theta_f]``, H_r the normalised histogram of the
  robot's heading over its last ``lambda_r`` poses, ``robot_bins`` bins over 360 degrees centred
  on 0, 20, 40, ... degrees (for 18 bins; the seeds do not say where the bins start, so both
  histograms are centred alike);
- closeness (paper Eq. 16): ``phi_c = 1 - (1 - D_min / D(c))^4``, D the path length along the
  skeleton (see :meth:`semsearch_cli.belief.DoorBelief.search`).

``SF = phi_g phi_p`` (Eq. 4.5), ``GF = ((phi_o + phi_r) phi_c + phi_c) / 3`` (Eq. 4.6),
``phi = alpha SF + (1 - alpha) GF`` (Eq. 4.7); the robot goes to argmax phi (Eq. 4.8). Ties go to
the nearest candidate, then to the run's generator: at alpha = 1, before any sign counts, every
candidate scores 0.25, and a random pick at each re-plan would send the robot back and forth. Text labels (e.g. "B12") are ignored by the number-based factors.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...geometry import wrap_angle
from ...world.labels import SignLabel, parse_label
from ..base import Decision, DoorPlanner, register_planner


# ---- the five factors, as pure functions ------------------------------------------------------
def increasing_sum(numbers: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> tuple[float | None, float, int]:
    """(theta_inc, norm, pairs): the direction (radians) and norm of the sum of unit vectors
    from each sign to every larger one, and the number of such pairs; theta_inc is None with
    fewer than two distinct numbers or when the vectors cancel."""
    numbers = np.asarray(numbers)
    if np.unique(numbers).size < 2:
        return None, 0.0, 0
    i, j = np.nonzero(numbers[:, None] < numbers[None, :])
    dx, dy = xs[j] - xs[i], ys[j] - ys[i]
    n = np.hypot(dx, dy)
    ok = n > 1e-9
    sx, sy = (dx[ok] / n[ok]).sum(), (dy[ok] / n[ok]).sum()
    norm = math.hypot(sx, sy)
    return (None if norm < 1e-9 else math.atan2(sy, sx)), norm, int(i.size)


def increasing_direction(numbers: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> float | None:
    """theta_inc (radians) of :func:`increasing_sum`."""
    return increasing_sum(numbers, xs, ys)[0]


def growing_direction(numbers, xs, ys, goal: int, theta_f: float, w_g: float) -> tuple[float, float, float]:
    """(phi_g, zeta, gamma) of Eqs. 4.9-4.11 for one candidate."""
    return growing_along(*segment_growth(numbers, xs, ys, goal, w_g), theta_f)


def segment_growth(numbers, xs, ys, goal: int, w_g: float) -> tuple[float, float | None]:
    """(zeta, theta_inc) of a segment's door list: the parts of Eqs. 4.9-4.10 that do not depend
    on the candidate."""
    numbers = np.asarray(numbers)
    smaller = int((numbers < goal).sum())
    bigger = int((numbers > goal).sum())
    zeta = (smaller - bigger) / max(smaller + bigger, w_g)
    return zeta, increasing_direction(numbers, np.asarray(xs, float), np.asarray(ys, float))


def growing_along(zeta: float, th: float | None, theta_f: float) -> tuple[float, float, float]:
    """(phi_g, zeta, gamma) of Eq. 4.11 for a candidate whose branch points along ``theta_f``."""
    gamma = 0.0 if th is None else 1.0 - 2.0 * abs(float(wrap_angle(theta_f - th))) / math.pi
    return (zeta * gamma + 1.0) / 2.0, zeta, gamma


def parity(numbers, goal: int, w_p: float) -> float:
    """phi_p of Eq. 4.12."""
    numbers = np.asarray(numbers)
    same = int((numbers % 2 == goal % 2).sum())
    diff = numbers.size - same
    return 0.5 + 0.5 * (same - diff) / max(same + diff, w_p)


def heading_histogram(headings, bins: int, fold: bool) -> np.ndarray:
    """Normalised histogram of headings (radians): ``bins`` bins centred on multiples of
    180/bins degrees over [0, 180) when ``fold`` (headings modulo 180), else of 360/bins over
    [0, 360). All zeros when there are no headings."""
    h = np.asarray(headings, float)
    if h.size == 0:
        return np.zeros(bins)
    idx = _bin(h, bins, fold)
    return np.bincount(idx, minlength=bins) / h.size


def histogram_lookup(hist: np.ndarray, theta, fold: bool):
    """H[theta]: the value of the bin holding ``theta`` (radians)."""
    return hist[_bin(np.asarray(theta, float), hist.shape[0], fold)]


def _bin(theta, bins, fold):
    span = math.pi if fold else 2.0 * math.pi
    return np.floor(np.mod(theta, span) / (span / bins) + 0.5).astype(np.int64) % bins


class RollingHistogram:
    """:func:`heading_histogram` of the last ``window`` items of a growing list, kept up to date
    by consuming only the items appended since the last call (O(new items), not O(history))."""

    def __init__(self, bins: int, fold: bool, window: int):
        self.bins, self.fold, self.window = bins, fold, window
        self.counts = np.zeros(bins, np.int64)
        self.seen = 0  # items of the list consumed so far

    def update(self, items: list) -> np.ndarray:
        n = len(items)
        if n > self.seen:
            self.counts += np.bincount(_bin(np.asarray(items[self.seen :], float), self.bins, self.fold), minlength=self.bins)
            lo_old, lo_new = max(0, self.seen - self.window), max(0, n - self.window)
            if lo_new > lo_old:  # items that left the window
                self.counts -= np.bincount(_bin(np.asarray(items[lo_old:lo_new], float), self.bins, self.fold), minlength=self.bins)
            self.seen = n
        total = min(n, self.window)
        return self.counts / total if total else np.zeros(self.bins)


def closeness(D: np.ndarray) -> np.ndarray:
    """phi_c of paper Eq. 16 from skeleton distances D (cells, >= 0); inf D gives 0."""
    D = np.maximum(np.asarray(D, float), 1.0)
    return 1.0 - (1.0 - D.min() / D) ** 4


# ---- the planner ------------------------------------------------------------------------------
MAX_BINS = 3600  # bins of a heading histogram (0.1 degrees each over 360): a histogram of 10**9 bins would take 8 GB


class NSOSParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    alpha: float = Field(0.9, ge=0.0, le=1.0, description="weight of the semantic factor, Eq. 4.7")
    w_g: float = Field(8.0, gt=0.0, description="signs needed for full growing-direction confidence, Eq. 4.9")
    w_p: float = Field(8.0, gt=0.0, description="signs needed for full parity confidence, Eq. 4.12")
    door_bins: int = Field(4, ge=1, le=MAX_BINS, description="bins of H_d over 180 degrees")
    robot_bins: int = Field(18, ge=1, le=MAX_BINS, description="bins of H_r over 360 degrees")
    lambda_d: int = Field(6000, ge=1, description="sign reads kept for H_d")
    lambda_r: int = Field(600000, ge=1, description="poses kept for H_r")
    min_reads: int | None = Field(None, ge=1, description="reads before a sign counts (default: belief.min_reads)")
    hysteresis: float = Field(0.01, ge=0.0, description="keep the last target while its phi is within this of the best")


def pick(phi: np.ndarray, D: np.ndarray, keep: int | None, hysteresis: float, rng) -> int:
    """argmax phi, keeping candidate ``keep`` while its phi is within ``hysteresis`` of the best;
    ties go to the nearest (smallest D), then to ``rng``."""
    if keep is not None and phi[keep] >= phi.max() - hysteresis:
        return keep
    best = np.flatnonzero(phi >= phi.max() - 1e-12)
    if best.size > 1:  # ties (common at alpha = 1 before any sign counts): nearest, then random
        best = best[D[best] <= D[best].min() + 1e-9]
    return int(best[0] if best.size == 1 else rng.choice(best))


class KeepTarget(DoorPlanner):
    """A scoring planner with hysteresis between re-plans: subclasses give ``_decide(ctx, cands,
    keep)``, ``keep`` the index of the last target among ``cands`` when it may be kept.

    Closeness is relative to the nearest candidate, so as the robot moves every candidate's phi
    drifts; with the argmax taken afresh at each re-plan, a robot travelling toward a far
    candidate past a near, unpromising one sees the other candidates' closeness shrink, turns
    back, and repeats for ever (seen on Inverse goal 124: 2000 m between two poses 1.1 m apart).
    So the planner keeps its last target while it is still a candidate and its phi is within
    ``hysteresis`` of the best; it chooses afresh whenever a sign reaches ``min_reads`` (new
    semantic evidence) or the target is gone. ``hysteresis = 0`` is the plain argmax.
    """

    replan_on_signs = True

    def __init__(self, params):
        super().__init__(params)
        self._last = None  # (target cell, counted signs) of the last decision

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        b = ctx.belief
        min_reads = getattr(self.params, "min_reads", None) or b.spec.min_reads
        counted = sum(1 for n in b.reads.total.values() if n >= min_reads)
        keep = None
        if self._last is not None and self._last[1] == counted and self.params.hysteresis > 0:
            hit = np.flatnonzero((cands.rows == self._last[0][0]) & (cands.cols == self._last[0][1]))
            keep = int(hit[0]) if hit.size else None
        d = self._decide(ctx, cands, keep)
        self._last = None if d is None else ((d.row, d.col), counted)
        return d

    def _decide(self, ctx, cands, keep: int | None) -> Decision | None:
        raise NotImplementedError

    @staticmethod
    def distances(ctx, cands):
        """(D, reach, phi_c): skeleton distances to the candidates (cells), which are reachable,
        and their closeness (0 where unreachable); None when none is reachable."""
        gs = ctx.belief.search(ctx.row, ctx.col, cands.rows, cands.cols, len(cands))
        D = gs.lengths(cands.rows, cands.cols)
        reach = np.isfinite(D)
        if not reach.any():
            return None
        phi_c = np.zeros(len(cands))
        phi_c[reach] = closeness(D[reach])
        return D, reach, phi_c


@register_planner("nsos")
class NSOS(KeepTarget):
    """The semantic planner (Eqs. 4.5-4.8), with :class:`KeepTarget`'s hysteresis."""

    rank = 4
    tuned_on = "the thesis' floors (its published parameters)"
    swept = "alpha"

    Params = NSOSParams
    use_semantics = True

    def __init__(self, params):
        super().__init__(params)
        self._h_d = RollingHistogram(self.params.door_bins, True, self.params.lambda_d)
        self._h_r = RollingHistogram(self.params.robot_bins, False, self.params.lambda_r)
        self._terms: dict = {}  # (goal, door list) -> (zeta, theta_inc, phi_p), see _segment_terms

    def _segment_terms(self, door_list: dict, goal: SignLabel) -> tuple:
        """(zeta, theta_inc, phi_p) of a segment's numbered signs that share the goal's prefix
        (world/labels.py: ``K202`` counts as 202 among the K signs, ``24D`` as 24). A segment's
        door list changes only when one of its signs is read again, so the terms are kept by the
        list's contents (the same numbers, in the same order, as computing them afresh)."""
        items = [(p.number, x, y) for lab, (_, x, y) in door_list.items()
                 if (p := parse_label(lab)) is not None and p.prefix == goal.prefix]
        key = (goal, tuple(items))
        terms = self._terms.get(key)
        if terms is None:
            if len(self._terms) >= 1024:
                self._terms.clear()
            nums = np.array([i[0] for i in items], np.int64)
            p = self.params
            terms = self._terms[key] = (*segment_growth(nums, [i[1] for i in items], [i[2] for i in items], goal.number,
                                                        p.w_g), parity(nums, goal.number, p.w_p))
        return terms

    def _decide(self, ctx, cands, keep: int | None = None):
        k = len(cands)
        p, b = self.params, ctx.belief
        alpha = p.alpha if self.use_semantics else 0.0
        dist = self.distances(ctx, cands)
        if dist is None:
            return None
        D, reach, phi_c = dist
        h_d = self._h_d.update(b.reads.headings)
        h_r = self._h_r.update(ctx.headings)
        phi_o = histogram_lookup(h_d, cands.theta, fold=True)
        phi_r = histogram_lookup(h_r, cands.theta, fold=False)
        GF = ((phi_o + phi_r) * phi_c + phi_c) / 3.0
        phi_g = np.full(k, 0.5)
        phi_p = np.full(k, 0.5)
        zeta = np.zeros(k)
        gamma = np.zeros(k)
        seg = np.full(k, -1)
        goal = parse_label(ctx.goal)
        if alpha > 0 and goal is not None:
            seg, lists = b.segment_door_lists(cands.seg_rows, cands.seg_cols, p.min_reads)
            per_seg = [self._segment_terms(lst, goal) for lst in lists]
            for i in range(k):
                if seg[i] < 0:
                    continue
                z, th, phi_p[i] = per_seg[seg[i]]
                phi_g[i], zeta[i], gamma[i] = growing_along(z, th, cands.theta[i])
        SF = phi_g * phi_p
        phi = alpha * SF + (1.0 - alpha) * GF
        phi[~reach] = -np.inf
        j = pick(phi, D, keep, p.hysteresis, ctx.rng)
        if not ctx.explain:
            return Decision(int(cands.rows[j]), int(cands.cols[j]), {"chosen": j})
        info = {"chosen": j, "candidates": [
            {"x": round(float(x), 2), "y": round(float(y), 2), "theta_f_deg": round(float(np.degrees(t)), 1),
             "segment": int(seg[i]), "D_m": round(float(D[i]) * b.frame.res, 2) if reach[i] else None,
             "phi_g": round(float(phi_g[i]), 4), "zeta": round(float(zeta[i]), 4), "gamma": round(float(gamma[i]), 4),
             "phi_p": round(float(phi_p[i]), 4), "phi_o": round(float(phi_o[i]), 4), "phi_r": round(float(phi_r[i]), 4),
             "phi_c": round(float(phi_c[i]), 4), "SF": round(float(SF[i]), 4), "GF": round(float(GF[i]), 4),
             "phi": round(float(phi[i]), 4) if reach[i] else None}
            for i, (x, y, t) in enumerate(zip(*b.frame.to_world(cands.rows, cands.cols), cands.theta))]}
        return Decision(int(cands.rows[j]), int(cands.cols[j]), info)


class GeometricParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    door_bins: int = Field(4, ge=1, le=MAX_BINS)
    robot_bins: int = Field(18, ge=1, le=MAX_BINS)
    lambda_d: int = Field(6000, ge=1)
    lambda_r: int = Field(600000, ge=1)
    hysteresis: float = Field(0.01, ge=0.0)


@register_planner("geometric")
class Geometric(NSOS):
    """Eq. 4.6 alone: NSOS with alpha = 0, keeping the two orientation factors."""

    rank = 2
    swept = None

    Params = GeometricParams
    replan_on_signs = False
    use_semantics = False

    def __init__(self, params):
        super().__init__(NSOSParams(alpha=0.0, **params.model_dump()))
