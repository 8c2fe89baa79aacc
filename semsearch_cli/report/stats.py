"""Statistics at the level of the episode .

Runs of one episode (one start pose and goal) repeated over seeds are not independent: they share
the start, the map and the goal, and differ only in the random stream. The unit of every interval
and test here is therefore the *episode*, or, when a goal has a single episode (the thesis'
configurations: one fixed start per goal), the repeat of that episode; then an interval speaks for
that start only. Indirect search clusters on the room layout instead (trials in one room
are not independent).

Failures count in the mean distance at the distance they travelled before the search ended
(budget, stuck, explored everything, error), as in the thesis' Tables 4.2-4.10; whether a run
failed is reported beside it by the success rate and its interval, and how far it still was from
the goal by ``left_m``. A planner that gives up early can therefore look short on distance alone:
read the two together.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import ndtr, ndtri
from scipy.stats import mannwhitneyu, norm, rankdata, wilcoxon

NAN = float("nan")
RESAMPLE_BLOCK = 1 << 20  # resampled values held at once by the bootstrap (8 MiB of them, as much of indices)


def episodes(df: pd.DataFrame) -> pd.Series:
    """The ``episode`` column as int64, 0 where it is missing (folders written before episodes)."""
    if "episode" not in df.columns:
        return pd.Series(0, index=df.index, dtype="int64", name="episode")
    return pd.to_numeric(df["episode"], errors="coerce").fillna(0).astype("int64")


def _has_cluster(df: pd.DataFrame, cluster: str | None) -> bool:
    return cluster is not None and cluster in df.columns and bool(len(df)) and \
        not df[cluster].isna().any() and bool((df[cluster].astype(str) != "").all())


def unit_kind(df: pd.DataFrame, cluster: str | None = None) -> str:
    """What :func:`units` takes as the unit of ``df``: ``"rooms"`` (or the plural of any other
    ``cluster`` column), ``"episodes"`` or ``"repeats"`` (of one episode). Words for captions."""
    if _has_cluster(df, cluster):
        return f"{cluster}s"
    many = _many_episodes(df)
    return "episodes" if many.all() else "repeats" if not many.any() else "episodes (repeats where a goal has one)"


def _many_episodes(df: pd.DataFrame) -> pd.Series:
    """Per row, whether its goal spans more than one episode in ``df`` (all rows are one goal
    when there is no ``goal`` column)."""
    ep = episodes(df)
    goal = df["goal"].astype(str) if "goal" in df.columns else pd.Series("", index=df.index)
    return ep.groupby(goal).transform("nunique") > 1


def units(df: pd.DataFrame, cluster: str | None = None) -> pd.Series:
    """The independent unit of each row, as text labels aligned with ``df.index``.

    Parameters
    ----------
    df : DataFrame
        Rows of one comparison (one scenario x goal x planner, or the planners being paired), with
        ``episode`` (int; missing is read as 0) and ``seed`` (int).
    cluster : str, optional
        A column to cluster on instead (``"room"`` for indirect search). When the column is
        missing or empty in any row (folders written before it), the default units are used;
        :func:`unit_kind` says which.

    Returns
    -------
    Series of str, named ``unit``: ``"e3"`` (the episode) for the rows of a goal that spans more
    than one episode, else ``"e0/s2"`` (episode and seed: the repeats of a goal's one episode are
    its units), or the cluster's value. Decided goal by goal, so that goals with one episode each
    (the thesis configs) are never taken for one episode set.
    """
    if _has_cluster(df, cluster):
        return df[cluster].astype(str).rename("unit")
    ep = episodes(df)
    seed = pd.to_numeric(df["seed"], errors="coerce").fillna(-1).astype("int64")
    by_episode = "e" + ep.astype(str)
    return by_episode.where(_many_episodes(df), by_episode + "/s" + seed.astype(str)).rename("unit")


def _unit_means(values, unit_labels) -> pd.Series:
    """Per-unit means of ``values`` (NaN values left out), sorted by unit."""
    v = pd.Series(np.asarray(values, dtype=float))
    return v.groupby(np.asarray(unit_labels), sort=True).mean().dropna()


def _resample_means(x: np.ndarray, n_resamples: int, rng: np.random.Generator) -> np.ndarray:
    """Means of ``n_resamples`` bootstrap resamples of ``x`` ((n,) float): (n_resamples,) float.

    The resamples are drawn ``RESAMPLE_BLOCK // n`` at a time (at least one), each block by one
    ``rng.integers(0, n, (rows, n))``: the same draws, in the same order, as the single
    ``(n_resamples, n)`` draw of ``scipy.stats.bootstrap``, so the same seed gives the same means,
    while at most ``max(RESAMPLE_BLOCK, n)`` resampled values are held at once, whatever
    ``n_resamples`` (issue 35: 9999 x 20,000 at once ran out of memory)."""
    n = len(x)
    rows = max(1, RESAMPLE_BLOCK // n)
    out = np.empty(n_resamples)
    for k in range(0, n_resamples, rows):
        b = min(rows, n_resamples - k)
        out[k:k + b] = x[rng.integers(0, n, (b, n))].mean(axis=-1)
    return out


def _boot(samples: tuple, point: float, confidence: float, n_resamples: int, seed: int) -> tuple[float, float, float]:
    """BCa bootstrap interval (Efron & Tibshirani 1993, *An Introduction to the Bootstrap*, sec.
    14.3) of the mean of ``samples[0]``, or, given two samples, of the difference
    of their means: what ``scipy.stats.bootstrap(samples, statistic, method="BCa",
    rng=np.random.default_rng(seed))`` returns for ``np.mean`` and the mean difference, computed in
    memory bounded independently of the sample sizes' product.

    The bootstrap distribution is drawn as SciPy draws it (each sample's resamples in turn, from
    one generator; :func:`_resample_means`). The acceleration ``a`` comes from the jackknife,
    written out for a mean: the leave-one-out means' ``(n - 1)(mean_(.) - mean_(-i))`` is
    ``x_i - mean(x)`` (negated for the subtracted sample), so ``a = sum_j sum_i U_ji^3 / n_j^3 /
    (6 (sum_j sum_i U_ji^2 / n_j^2)^(3/2))`` takes O(n) instead of SciPy's n x (n - 1) leave-one-out
    resamples. The interval's ends are the linear-interpolation quantiles of the distribution at
    the BCa levels; NaN where a level is not a number (where SciPy warns that the BCa interval
    cannot be calculated: every resampled statistic on one side of ``point``).

    Parameters
    ----------
    samples : tuple of one or two (n_j,) float arrays
        Per-unit values (at least two each), the second subtracted.
    point : float
        The statistic on the data (the mean, or the difference of the means).

    Returns
    -------
    (point, lo, hi) : float
    """
    rng = np.random.default_rng(seed)
    xs = [np.asarray(x, dtype=float) for x in samples]
    dist = _resample_means(xs[0], n_resamples, rng)
    for y in xs[1:]:
        dist -= _resample_means(y, n_resamples, rng)
    theta = xs[0].mean() - sum(y.mean() for y in xs[1:])
    z0 = ndtri((np.count_nonzero(dist < theta) + np.count_nonzero(dist <= theta)) / (2.0 * n_resamples))
    u = [x - x.mean() for x in xs]  # the jackknife's U_i; its sign does not matter for U^2 and flips U^3
    num = sum((1 if j == 0 else -1) * np.sum(ui**3) / len(ui) ** 3 for j, ui in enumerate(u))
    den = sum(np.sum(ui**2) / len(ui) ** 2 for ui in u)
    a = num / (6.0 * den**1.5)
    z = ndtri((1.0 - confidence) / 2.0)
    levels = [ndtr(z0 + (z0 + zz) / (1.0 - a * (z0 + zz))) for zz in (z, -z)]
    if not all(0.0 <= q <= 1.0 for q in levels):  # NaN: a degenerate distribution
        return point, NAN, NAN
    lo, hi = np.quantile(dist, levels)
    return point, float(lo), float(hi)


def mean_ci(values, units, confidence: float = 0.95, n_resamples: int = 9999, seed: int = 0) -> tuple[float, float, float]:
    """Mean over units of the per-unit means, with a bootstrap confidence interval over units.

    Parameters
    ----------
    values : (n,) float
        One value per run (e.g. distance_m, m); NaN values are left out.
    units : (n,)
        The unit of each run (:func:`units`).
    confidence : float
        Two-sided level of the interval.
    n_resamples, seed : int
        Bootstrap resamples and the seed of its ``numpy.random.Generator`` (fixed: the same rows
        give the same interval).

    Returns
    -------
    (mean, lo, hi) : float
        ``mean`` is the unweighted mean of the per-unit means (the mean of all runs when every unit
        has as many runs). The interval is the BCa bootstrap over the per-unit means
        (:func:`_boot`: ``scipy.stats.bootstrap``'s, in memory bounded whatever the number of
        units); ``(m, m, m)`` when all unit means are equal, ``(m, nan, nan)`` with fewer than two
        units or an infinite unit mean (``(nan, nan, nan)`` with none).
    """
    um = _unit_means(values, units).to_numpy()
    if len(um) == 0:
        return NAN, NAN, NAN
    m = float(um.mean())
    if len(um) < 2 or not np.isfinite(um).all():
        return m, NAN, NAN
    if np.ptp(um) == 0:
        return m, m, m
    return _boot((um,), m, confidence, n_resamples, seed)


def ratio_ci(num, den, confidence: float = 0.95, n_resamples: int = 9999, seed: int = 0) -> tuple[float, float, float]:
    """``mean(num) / mean(den)`` over paired units (``num[i]`` and ``den[i]`` are one unit's), with
    a BCa bootstrap interval over units, the pairs resampled together: the share of a gap a
    planner closes (``num``: its gain over the baseline per episode; ``den``: the ceiling's).

    The acceleration comes from the jackknife of the ratio, written out: leaving unit ``i`` out
    gives ``(S_num - num_i) / (S_den - den_i)``, O(n). NaN bounds with fewer than two units, a
    ``den`` whose mean is 0, or a degenerate bootstrap distribution (as :func:`_boot`); ``(r, r,
    r)`` when every unit's ratio is the same."""
    a, b = np.asarray(num, float), np.asarray(den, float)
    keep = np.isfinite(a) & np.isfinite(b)
    a, b = a[keep], b[keep]
    n = len(a)
    if n == 0 or b.sum() == 0:
        return NAN, NAN, NAN
    point = float(a.sum() / b.sum())
    if n < 2:
        return point, NAN, NAN
    if np.all(a * b.sum() == b * a.sum()):  # every pair on the line through 0 of slope point: no spread
        return point, point, point
    rng = np.random.default_rng(seed)
    rows = max(1, RESAMPLE_BLOCK // n)
    dist = np.empty(n_resamples)
    for k in range(0, n_resamples, rows):
        m = min(rows, n_resamples - k)
        idx = rng.integers(0, n, (m, n))
        with np.errstate(divide="ignore", invalid="ignore"):
            dist[k:k + m] = a[idx].sum(axis=-1) / b[idx].sum(axis=-1)
    dist = dist[np.isfinite(dist)]
    if len(dist) < n_resamples // 2:
        return point, NAN, NAN
    with np.errstate(divide="ignore", invalid="ignore"):
        jack = (a.sum() - a) / (b.sum() - b)
    if not np.isfinite(jack).all():
        return point, NAN, NAN
    z0 = ndtri((np.count_nonzero(dist < point) + np.count_nonzero(dist <= point)) / (2.0 * len(dist)))
    u = jack.mean() - jack
    den3 = np.sum(u**2) ** 1.5
    acc = np.sum(u**3) / (6.0 * den3) if den3 > 0 else 0.0
    z = ndtri((1.0 - confidence) / 2.0)
    levels = [ndtr(z0 + (z0 + zz) / (1.0 - acc * (z0 + zz))) for zz in (z, -z)]
    if not all(0.0 <= q <= 1.0 for q in levels):
        return point, NAN, NAN
    lo, hi = np.quantile(dist, levels)
    return point, float(lo), float(hi)


def _wilson(p, n, confidence: float):
    """:func:`wilson` over arrays: ``p``, ``n`` broadcast; returns (lo, hi) arrays."""
    z = float(norm.ppf(0.5 + confidence / 2.0))
    d = 1.0 + z * z / n
    centre = (p + z * z / (2.0 * n)) / d
    half = z * np.sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / d
    return np.maximum(0.0, centre - half), np.minimum(1.0, centre + half)


def wilson(p: float, n: float, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a proportion ``p`` observed over ``n`` (may be fractional) trials."""
    lo, hi = _wilson(np.float64(p), np.float64(n), confidence)
    return float(lo), float(hi)


def rate_ci(successes, units, confidence: float = 0.95) -> tuple[float, float, float]:
    """Success rate with a Wilson interval widened for clustered runs.

    The rate is ``p = sum y / n`` over all ``n`` runs. The runs of one unit are correlated, so the
    interval is the Wilson score interval at the effective sample size ``n_eff = n / deff``, with
    Kish's design effect (Kish 1965, *Survey Sampling*, sec. 5.4) estimated from the data::

        deff = max(1, Var_clustered / (p (1 - p) / n))
        Var_clustered = sum_i (y_i - p m_i)^2 / n^2

    for units ``i`` with ``y_i`` successes in ``m_i`` runs: the linearised variance of the ratio
    estimator ``p``, i.e. the between-unit variance of the unit rates weighted by unit size,
    divided by the number of units. It is taken without the small-sample factor k / (k - 1), so
    that units of one run each give ``deff = 1`` and the plain Wilson interval exactly; with few
    units it is slightly optimistic. ``deff`` is floored at 1 (clustering is not credited with
    making runs *more* informative) and is 1 when ``p`` is 0 or 1 (no variance to estimate).

    Parameters
    ----------
    successes : (n,) 0/1
        One value per run; NaN left out.
    units : (n,)
        The unit of each run (:func:`units`).

    Returns
    -------
    (rate, lo, hi) : float
        ``(p, nan, nan)`` when the runs fall in one unit holding more than one run (no
        between-unit variance to estimate); ``(nan, nan, nan)`` without runs.
    """
    y = pd.Series(np.asarray(successes, dtype=float))
    u = pd.Series(np.asarray(units))
    keep = y.notna().to_numpy()
    y, u = y[keep], u[keep]
    n = len(y)
    if n == 0:
        return NAN, NAN, NAN
    p = float(y.mean())
    per = y.groupby(u.to_numpy()).agg(["sum", "size"])
    if len(per) < 2 and n > 1:
        return p, NAN, NAN
    deff = 1.0
    if 0.0 < p < 1.0:
        var = float(((per["sum"] - p * per["size"]) ** 2).sum()) / n**2
        deff = max(1.0, var / (p * (1.0 - p) / n))
    lo, hi = wilson(p, n / deff, confidence)
    return p, lo, hi


def rate_ci_by_budget(found, distance, units, budgets, confidence: float = 0.95) -> dict:
    """:func:`rate_ci` of the runs that found the goal within each budget, all budgets at once.

    At budget ``b`` a run counts as a success when ``found`` and ``distance <= b``; the result at
    each ``b`` is what ``rate_ci(found & (distance <= b), units)`` returns, but computed from one
    sort of the successful runs by distance instead of one pass over the runs per budget
    (issue 35: a budget curve over every distinct distance of 20,000 runs took minutes). Kish's
    variance needs, per budget, ``S1 = sum_i y_i``, ``S2 = sum_i y_i^2`` and ``S3 = sum_i y_i m_i``
    over units ``i`` (``y_i`` successes of ``m_i`` runs): ``n^2 Var = S2 - 2 p S3 + p^2 sum_i
    m_i^2``. Taking the successes in order of distance, the k-th success of a unit raises ``S1``
    by 1, ``S2`` by ``2 k + 1`` (k counted from 0) and ``S3`` by ``m_i``; cumulative sums read at
    ``searchsorted(b)`` give them at every budget.

    Parameters
    ----------
    found : (n,) 0/1
        Whether each run found the goal.
    distance : (n,) float, m
        How far each run travelled (NaN: never within a budget).
    units : (n,)
        The unit of each run (:func:`units`).
    budgets : (k,) float, m

    Returns
    -------
    dict of (k,) arrays: ``successes`` (int), ``rate``, ``lo``, ``hi`` (float; NaN as :func:`rate_ci`).
    """
    ok = np.asarray(found, dtype=float) == 1
    dist = np.asarray(distance, dtype=float)
    b = np.asarray(budgets, dtype=float)
    n = len(dist)
    if n == 0:
        nan = np.full(len(b), NAN)
        return {"successes": np.zeros(len(b), np.int64), "rate": nan, "lo": nan.copy(), "hi": nan.copy()}
    _, code, size = np.unique(np.asarray(units).astype(str), return_inverse=True, return_counts=True)
    code = code.ravel()
    ev = np.flatnonzero(ok & ~np.isnan(dist))
    ev = ev[np.argsort(dist[ev], kind="stable")]
    d_sorted, c = dist[ev], code[ev]
    by_unit = np.argsort(c, kind="stable")  # the successes grouped by unit, in distance order within each
    first = np.r_[0, np.cumsum(np.bincount(c, minlength=len(size)))[:-1]]
    rank = np.empty(len(c), np.int64)
    rank[by_unit] = np.arange(len(c)) - first[c[by_unit]]
    s2 = np.r_[0.0, np.cumsum(2.0 * rank + 1.0)]
    s3 = np.r_[0.0, np.cumsum(size[c].astype(float))]
    k = np.where(np.isnan(b), 0, np.searchsorted(d_sorted, b, side="right"))
    p = k / n
    var = (s2[k] - 2.0 * p * s3[k] + p * p * float(np.sum(size.astype(float) ** 2))) / n**2
    inside = (p > 0.0) & (p < 1.0)
    deff = np.ones(len(b))
    deff[inside] = np.maximum(1.0, var[inside] / (p[inside] * (1.0 - p[inside]) / n))
    lo, hi = _wilson(p, n / deff, confidence)
    if len(size) < 2 and n > 1:
        lo, hi = np.full(len(b), NAN), np.full(len(b), NAN)
    return {"successes": k.astype(np.int64), "rate": p, "lo": lo, "hi": hi}


def paired(a: pd.DataFrame, b: pd.DataFrame, value: str = "distance_m", confidence: float = 0.95) -> dict:
    """Planners A and B on the same episodes, compared unit by unit.

    Repeats are averaged per unit (:func:`units` of both tables together: the episode, or the
    (episode, seed) when there is one episode), the two sides joined on the unit, and the
    difference ``d = a - b`` taken per unit. Units found on one side only are dropped and counted.

    Returns
    -------
    dict
        ``unit`` (``"episodes"`` or ``"repeats"``), ``n_pairs``, ``unpaired``, ``n_nonzero`` (the
        differences that are not zero, which the signed-rank test ranks); ``mean_diff``
        (mean of d, in the unit of ``value``) with ``diff_lo``, ``diff_hi`` from :func:`mean_ci`
        over the pairs; ``p_value`` of the two-sided Wilcoxon signed-rank test
        (``scipy.stats.wilcoxon``, zero differences dropped): 1.0 when every difference is zero,
        NaN with fewer than two nonzero differences; ``effect_r``, the matched-pairs rank-biserial
        correlation ``(R+ - R-) / (R+ + R-)`` over the ranks of the nonzero ``|d|`` (positive
        when A has the larger ``value``, e.g. travels more; 0 when every difference is zero).
    """
    both = pd.concat([a, b], ignore_index=True)
    lab = units(both).to_numpy()
    side = np.r_[np.zeros(len(a), bool), np.ones(len(b), bool)]
    ma = _unit_means(both[value].to_numpy()[~side], lab[~side])
    mb = _unit_means(both[value].to_numpy()[side], lab[side])
    common = ma.index.intersection(mb.index).sort_values()
    d = (ma[common] - mb[common]).to_numpy()
    out = {"unit": unit_kind(both), "n_pairs": len(d), "unpaired": len(ma) + len(mb) - 2 * len(common)}
    out["mean_diff"], out["diff_lo"], out["diff_hi"] = mean_ci(d, np.arange(len(d)), confidence)
    nz = d[d != 0]
    out["n_nonzero"] = len(nz)
    if len(d) == 0:
        p, r = NAN, NAN
    elif len(nz) == 0:
        p, r = 1.0, 0.0
    else:
        p = float(wilcoxon(d, alternative="two-sided").pvalue) if len(nz) >= 2 else NAN
        ranks = rankdata(np.abs(nz))
        r = float((ranks[nz > 0].sum() - ranks[nz < 0].sum()) / ranks.sum())
    out["p_value"], out["effect_r"] = p, r
    return out


def unpaired(a: pd.DataFrame, b: pd.DataFrame, value: str = "distance_m", confidence: float = 0.95) -> dict:
    """Planners A and B on different episodes: each side's per-unit means (:func:`units` of each
    side alone), compared by a two-sided Mann-Whitney U test (SciPy).

    Returns
    -------
    dict
        ``n_a``, ``n_b`` (units); ``mean_diff`` (mean of A's unit means minus B's) with ``diff_lo``,
        ``diff_hi`` from a two-sample BCa bootstrap (``(d, nan, nan)`` when a side has fewer than
        two units or an infinite unit mean, ``(d, d, d)`` when both sides are constant); ``U`` (A's statistic), ``p_value``
        and ``effect_r = 2U / (n_a n_b) - 1``, the rank-biserial correlation (positive when A has
        the larger ``value``, as :func:`paired`).
    """
    x = _unit_means(a[value], units(a)).to_numpy()
    y = _unit_means(b[value], units(b)).to_numpy()
    out = {"n_a": len(x), "n_b": len(y)}
    if not (len(x) and len(y)):
        return out | {"mean_diff": NAN, "diff_lo": NAN, "diff_hi": NAN, "U": NAN, "p_value": NAN, "effect_r": NAN}
    d = float(x.mean() - y.mean())
    if min(len(x), len(y)) < 2 or not (np.isfinite(x).all() and np.isfinite(y).all()):
        ci = (d, NAN, NAN)
    elif np.ptp(x) == 0 and np.ptp(y) == 0:
        ci = (d, d, d)
    else:
        ci = _boot((x, y), d, confidence, 9999, 0)
    u, p = mannwhitneyu(x, y, alternative="two-sided")
    return out | {"mean_diff": ci[0], "diff_lo": ci[1], "diff_hi": ci[2], "U": float(u), "p_value": float(p),
                  "effect_r": 2.0 * float(u) / (len(x) * len(y)) - 1.0}
