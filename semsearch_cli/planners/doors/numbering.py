"""``numbering``: a planner that keeps a posterior over how the corridor beyond each frontier
target is numbered, and chooses the target of least expected travel to the goal under it.

The model (docs/numbering.md writes it out with the reasons for its values). For a frontier target
``c`` with branch direction ``theta_f`` (the way unexplored space goes on beyond it), on the
corridor segment ``S(c)``, take the numbered signs of ``S(c)`` that share the goal's prefix
(``n_i``, read from robot positions ``p_i`` on the corridor's axis) and their coordinates along
the branch, ``t_i = p_i . e_f`` with ``e_f = (cos theta_f, sin theta_f)``.

- **Hypotheses.** ``H_0``, no usable pattern (the numbers are independent, uniform over a range of
  ``R`` numbers), with prior ``pi_0``; and the linear numberings ``H_{s,b}``: the number rises by
  ``b`` per metre in the direction ``s e_f`` (``s = +1`` or ``-1``; ``b`` on a geometric grid
  ``spacings``), each with prior ``(1 - pi_0) / (2 |spacings|)``, with an unknown offset ``a``
  (uniform over the same range) and residuals ``N(0, sigma^2)`` (``sigma`` absorbs odd and even
  numbers on opposite walls and uneven doors).
- **Evidence** of ``k`` signs, the offset integrated out, with ``r_i = n_i - s b t_i`` and
  ``S = sum (r_i - mean r)^2``: ``p(n | H_{s,b}) = R^-1 (2 pi sigma^2)^(-(k-1)/2) k^(-1/2)
  exp(-S / 2 sigma^2)`` and ``p(n | H_0) = R^-k``. The posterior is proportional to prior times
  evidence.
- **Where the goal is.** Under ``H_{s,b}`` the goal ``g`` sits at ``t_g = (g - a*) / (s b)``
  with ``a*`` the offset's posterior mean, ``mean(n_i - s b t_i)``: beyond the target
  when ``t_g > t_c`` (``t_c = c . e_f``), at ``t_g - t_c`` metres past it.
- **Prefix and parity.** A segment whose numbered signs carry other prefixes is likely another
  wing: ``(k_same + 1) / (k + 1)`` multiplies the probability that the goal is beyond the target;
  a corridor whose same-prefix signs are all of the other parity is likely numbered on one wall
  only: ``min(1, (k_parity + 1) / (k_same / 2 + 1))`` multiplies it too. Both are 1 without
  evidence, and the parity factor is 1 for a corridor holding about half of each parity.
- **The choice.** ``P_c``: the posterior probability that the goal is beyond ``c`` (the
  ``H_{s,b}`` with ``t_g > t_c``, plus ``H_0``'s share at ``1/2``), times the two shares; without a
  same-prefix sign on ``S(c)``, ``P_c = 1/2`` times the prefix share. ``E_c``: the expected metres
  past ``c`` to the goal when it is beyond (the ``H_{s,b}``'s ``t_g - t_c`` weighted by their
  posterior, capped at ``horizon``; ``H_0`` and no signs: ``horizon / 2``). With ``d_c`` the path
  to ``c`` (m) and ``d_mean`` the mean over the reachable targets, the expected travel through
  ``c`` is ``d_c + P_c E_c + (1 - P_c) (d_c + d_mean + horizon / 2)``: when the goal is not beyond
  ``c``, about the way back and on to another target. The least wins (ties: the nearer, then the
  run's generator), kept between re-plans as nsos keeps its target (:class:`KeepTarget`).

Every choice of value here (``R``, ``sigma``, ``pi_0``, the grid, ``horizon``) is a parameter,
stated in the docs with its reason, and none was tuned towards a result.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...world.labels import parse_label
from ..base import Decision, register_planner
from .nsos import KeepTarget, pick

SPACINGS = (0.1, 0.15, 0.2, 0.3, 0.45, 0.7, 1.0, 1.5, 2.2, 3.3, 5.0)  # numbers per metre, a geometric grid


def slopes(spacings=SPACINGS) -> np.ndarray:
    """(2, B): ``s b`` of every linear numbering, rising (``s = +1``, row 0) then falling."""
    b = np.asarray(spacings, float)
    return np.stack([b, -b])


class NumberingParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    sigma: float = Field(1.5, gt=0.0, le=100.0, description="numbers: residual of a sign about the corridor's line")
    number_range: float = Field(200.0, gt=1.0, description="R: numbers a floor's signs spread over (the uniform's width)")
    p_none: float = Field(0.2, ge=0.0, le=1.0, description="pi_0: prior share of 'no usable pattern'")
    horizon: float = Field(30.0, gt=0.0, description="m: the farthest the goal is expected past a target")
    min_reads: int | None = Field(None, ge=1, description="reads before a sign counts (default: belief.min_reads)")
    hysteresis: float = Field(0.5, ge=0.0, description="m: keep the last target while its expected travel is within this of the best")


def linear_posterior(numbers, t, sigma: float, R: float, p_none: float, spacings=SPACINGS):
    """The posterior over ``H_0`` and the linear numberings ``H_{s,b}`` given ``k`` signs'
    numbers and coordinates ``t`` (m) along an axis: (``w0``, ``w`` (2, B) over ``s = +1, -1`` by
    ``spacings``, ``a`` (2, B) the offsets' posterior means). With ``k = 0`` the prior."""
    n = np.asarray(numbers, float)
    t = np.asarray(t, float)
    k = n.size
    slope = slopes(spacings)
    log_prior_lin = math.log(max(1.0 - p_none, 1e-300)) - math.log(slope.size)
    log_prior_none = math.log(max(p_none, 1e-300))
    if k == 0:
        logw = np.full(slope.shape, log_prior_lin)
        a = np.zeros(slope.shape)
        log0 = log_prior_none
    else:
        r = n[None, None, :] - slope[..., None] * t[None, None, :]  # (2, B, k)
        a = r.mean(axis=2)
        S = ((r - a[..., None]) ** 2).sum(axis=2)
        loglin = (-math.log(R) - 0.5 * (k - 1) * math.log(2.0 * math.pi * sigma ** 2) - 0.5 * math.log(k)
                  - S / (2.0 * sigma ** 2))
        logw = log_prior_lin + loglin
        log0 = log_prior_none - k * math.log(R)
    m = max(float(logw.max()), log0)
    w = np.exp(logw - m)
    w0 = math.exp(log0 - m) if p_none > 0 else 0.0
    z = w.sum() + w0
    return w0 / z, w / z, a


def beyond(w0: float, w: np.ndarray, a: np.ndarray, goal: float, t_c: float, horizon: float,
           spacings=SPACINGS) -> tuple[float, float]:
    """(P, E): the probability that the goal lies beyond the target at ``t_c`` along the axis,
    and the expected metres past it when it does (see the module docstring)."""
    t_g = (goal - a) / slopes(spacings)
    past = t_g - t_c
    ahead = past > 0
    p_lin = float(w[ahead].sum())
    P = p_lin + 0.5 * w0
    if P <= 0:
        return 0.0, horizon / 2.0
    e_lin = float((w[ahead] * np.minimum(past[ahead], horizon)).sum())
    E = (e_lin + 0.5 * w0 * horizon / 2.0) / P
    return P, E


def shares(numbers_same, k_all: int, goal_number: int) -> tuple[float, float]:
    """(prefix factor, parity factor) of a segment, each 1 without evidence: ``(k_same + 1) / (k +
    1)`` and ``min(1, (k_parity + 1) / (k_same / 2 + 1))`` (a corridor numbered on both walls
    holds about half of each parity, and is not evidence against the goal's)."""
    same = np.asarray(numbers_same, np.int64)
    k_parity = int((same % 2 == goal_number % 2).sum())
    return (same.size + 1) / (k_all + 1), min(1.0, (k_parity + 1) / (same.size / 2 + 1))


def expected_travel(d: np.ndarray, P: np.ndarray, E: np.ndarray, horizon: float) -> np.ndarray:
    """``d_c + P_c E_c + (1 - P_c)(d_c + d_mean + horizon / 2)`` over the reachable targets (m)."""
    ok = np.isfinite(d)
    out = np.full(d.shape, np.inf)
    if not ok.any():
        return out
    dm = float(d[ok].mean())
    out[ok] = d[ok] + P[ok] * E[ok] + (1.0 - P[ok]) * (d[ok] + dm + horizon / 2.0)
    return out


def target_terms(ctx, cands, reach: np.ndarray, params: NumberingParams) -> tuple[np.ndarray, np.ndarray]:
    """(P, E) of every target at a decision (module docstring): the probability that the goal
    lies beyond it, and the expected metres past it when it does. Targets that cannot be reached,
    or whose segment holds no visited cell, keep the prior (1/2, ``horizon / 2``)."""
    b = ctx.belief
    k = len(cands)
    P = np.full(k, 0.5)
    E = np.full(k, params.horizon / 2.0)
    goal = parse_label(ctx.goal)
    if goal is None:
        return P, E
    seg, lists = b.segment_door_lists(cands.seg_rows, cands.seg_cols, params.min_reads)
    parsed = [[(q, x, y) for lab, (_, x, y) in lst.items() if (q := parse_label(lab)) is not None] for lst in lists]
    xs, ys = b.frame.to_world(cands.rows, cands.cols)
    for i in np.flatnonzero(reach & (seg >= 0)):
        signs = parsed[seg[i]]
        same = [(q.number, x, y) for q, x, y in signs if q.prefix == goal.prefix]
        prefix, par = shares([s[0] for s in same], len(signs), goal.number)
        if same:
            e = (math.cos(cands.theta[i]), math.sin(cands.theta[i]))
            t = [x * e[0] + y * e[1] for _, x, y in same]
            w0, w, a = linear_posterior([s[0] for s in same], t, params.sigma, params.number_range, params.p_none)
            P[i], E[i] = beyond(w0, w, a, goal.number, float(xs[i] * e[0] + ys[i] * e[1]), params.horizon)
        P[i] *= prefix * par
    return P, E


@register_planner("numbering")
class Numbering(KeepTarget):
    """A posterior over how the corridor beyond each target is numbered (direction, spacing, a
    share for no pattern; the goal's prefix and parity), and the target of least expected travel
    to the goal under it (docs/numbering.md)."""

    rank = 5
    tuned_on = "doors-v1 val (designed while val was the one split it was measured on)"
    Params = NumberingParams

    def _decide(self, ctx, cands, keep: int | None = None):
        dist = self.distances(ctx, cands)
        if dist is None:
            return None
        D, reach, _ = dist
        d = np.where(reach, D * ctx.belief.frame.res, np.inf)
        P, E = target_terms(ctx, cands, reach, self.params)
        cost = expected_travel(d, P, E, self.params.horizon)
        j = pick(-cost, D, keep, self.params.hysteresis, ctx.rng)
        info = {"chosen": j, "P": round(float(P[j]), 4), "E_m": round(float(E[j]), 2), "cost_m": round(float(cost[j]), 2)}
        return Decision(int(cands.rows[j]), int(cands.cols[j]), info)
