"""Tables rebuilt from rows alone."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd

from ..metrics import CAUSES as OUTCOME_CAUSES, COST_COLUMNS
from ..planners.base import baseline_of, planner_order  # noqa: F401  (planner_order: the report order, used across report/)
from . import stats as S

KEYS = ["scenario", "goal", "planner"]
# the one definition every table and figure that shows a ratio to the shortest path uses (docs/reports.md)
RATIO = ("the mean ratio to the shortest path: the mean over runs of each run's distance over its own episode's shortest "
         "path (failed runs at the distance they travelled)")


def intervals(g: pd.DataFrame, value: str = "distance_m") -> dict:
    """Episode-level statistics of one group of runs (:mod:`.stats`): the distinct ``episodes``,
    the ``unit`` of the intervals (``episodes``, or ``repeats`` of the one episode) and their
    number ``n_units``, the bootstrap interval of the mean of ``value`` (``mean_lo``, ``mean_hi``)
    and the clustered Wilson interval of the success rate (``success_lo``, ``success_hi``)."""
    u = S.units(g)
    _, lo, hi = S.mean_ci(g[value], u)
    _, slo, shi = S.rate_ci(g["success"], u)
    return {"episodes": int(S.episodes(g).nunique()), "unit": S.unit_kind(g), "n_units": int(u.nunique()),
            "mean_lo": lo, "mean_hi": hi, "success_lo": slo, "success_hi": shi}


def per_group(runs: pd.DataFrame, keys: list, fn, columns: list) -> pd.DataFrame:
    """One row per group of ``runs`` by ``keys`` (sorted; a missing key is a group of its own,
    last): the keys and the dict ``fn(group)``. The keys keep the dtypes of ``runs``' columns,
    also when there is no group, so that the result merges back on them."""
    rows = [dict(zip(keys, k)) | fn(d) for k, d in runs.groupby(keys, sort=True, dropna=False)]
    out = pd.DataFrame(rows, columns=keys + columns)
    return in_goal_order(out) if len(out) else out.astype({k: runs[k].dtype for k in keys})


def in_goal_order(df: pd.DataFrame) -> pd.DataFrame:
    """``df``'s rows in the report's goal order: by scenario, then goal (:func:`goal_key`: ``4.50``
    before ``1e3`` before ``NA``, whether the goals were read as numbers or as text), the rest in
    the order they had (a stable sort). ``goal`` (and ``scenario``) are columns or index levels."""
    flat = df.reset_index() if "goal" in (df.index.names or []) else df
    if "goal" not in flat.columns:
        return df
    scen = flat["scenario"].astype(str).tolist() if "scenario" in flat.columns else [""] * len(flat)
    order = sorted(range(len(flat)), key=lambda i: (scen[i], goal_key(flat["goal"].iat[i])))
    return df.iloc[order]


def _finite(v: pd.Series) -> pd.Series:
    v = pd.to_numeric(v, errors="coerce")
    return v[np.isfinite(v)]


INTERVALS = ["episodes", "unit", "n_units", "mean_lo", "mean_hi", "success_lo", "success_hi"]


def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario x goal x planner variant: n runs, distinct ``episodes``, success rate with its
    interval (``success_lo``, ``success_hi``), median, mean (``mean_lo``, ``mean_hi``: its
    interval), std (ddof=1, as the thesis' tables), min and max of distance_m, the shortest path
    (the mean over episodes of each episode's), the mean ratio, the mean ``soft_spl`` and the mean
    distance still to go over the failed runs (``left_m``, m; over those with a finite distance
    left, NaN when none failed) when runs.csv has those columns, and the ``unit`` of the intervals with their number ``n_units``.

    Distances are over every run, failures included at the distance they travelled (the thesis'
    convention; see :mod:`.stats`). ``mean`` is the mean of all runs, as the thesis; the
    interval is that of the mean of per-unit means (:func:`.stats.mean_ci`), the same number when
    every unit has as many runs. Intervals are 95%: a bootstrap over units for the mean, the
    clustered Wilson interval (:func:`.stats.rate_ci`) for the rate.

    The keys are taken as they come: rows read with ``read_runs(path, as_written=True)`` keep each
    goal and planner as the text it was written with, so a goal ``NA``, ``4.50`` or ``1e3`` is
    summarised under that label (``4.50`` apart from ``4.5``). A missing key (rows read without
    it, where pandas reads ``NA`` as NaN) is a group of its own, never dropped. Rows are ordered by
    scenario, goal (:func:`goal_key`: numbers by value, whether read as numbers or as text) and
    planner."""
    g = runs.groupby(KEYS, sort=True, dropna=False)
    out = g.agg(
        n=("distance_m", "size"),
        success_rate=("success", "mean"),
        median=("distance_m", "median"),
        mean=("distance_m", "mean"),
        std=("distance_m", "std"),
        min=("distance_m", "min"),
        max=("distance_m", "max"),
        mean_ratio=("ratio", "mean"),
    ).reset_index()
    extra = {"shortest_m": lambda d: float(d.groupby(S.episodes(d))["shortest_m"].first().mean())}
    if "soft_spl" in runs.columns:
        extra["soft_spl"] = lambda d: float(d["soft_spl"].mean())
    if "left_m" in runs.columns:
        extra["left_m"] = lambda d: float(_finite(d.loc[d["success"] == 0, "left_m"]).mean())
    # the same groups in the same order as ``out`` (no merge on the keys: a NaN key, or keys of
    # mixed types, must not decide which rows meet)
    more = pd.DataFrame([intervals(d) | {k: f(d) for k, f in extra.items()} for _, d in g], columns=INTERVALS + list(extra))
    out = pd.concat([out, more], axis=1)
    out = in_goal_order(out).reset_index(drop=True)  # the groups come sorted by planner within a goal
    cols = KEYS + ["n", "episodes", "success_rate", "success_lo", "success_hi", "median", "mean", "mean_lo", "mean_hi",
                   "std", "min", "max", "shortest_m", "mean_ratio"] + [c for c in extra if c != "shortest_m"] + ["unit", "n_units"]
    return out[cols].round(3)


def span(v: pd.Series) -> str:
    """``"6"`` or ``"4-6"``: the range of the counts in ``v`` (NaN left out), for captions."""
    v = pd.to_numeric(pd.Series(v), errors="coerce").dropna()
    if v.empty:
        return "0"
    lo, hi = int(v.min()), int(v.max())
    return f"{lo}" if lo == hi else f"{lo}-{hi}"


def interval_caption(summary: pd.DataFrame) -> str:
    """What the intervals of ``summary`` (:func:`summarise`) are over, and how many, in words."""
    parts = []
    ep, rep = summary[summary["unit"] == "episodes"], summary[summary["unit"] == "repeats"]
    if len(ep):
        parts.append(f"over episodes (n = {span(ep['n_units'])} per goal and planner; the repeats of an episode averaged first)")
    if len(rep):
        parts.append(f"over the repeats of the one episode of {'each' if not len(ep) else 'the other'} goal "
                     f"(n = {span(rep['n_units'])}; they speak for that start only)")
    return "95% intervals " + ", and ".join(parts) if parts else "no runs"


# ---- the thesis' tables and what it lacked (issue: reports) -------------------------------------
FIVE = ["median", "mean", "std", "min", "max"]


def goal_key(g):
    """Sort goals numerically when they are numbers (``54``, ``54.0``, ``4.50``, ``1e3``: by
    value, then as text), then the rest as text (``NA``, ``kitchen``, a missing goal)."""
    s = str(g)
    if re.fullmatch(r"-?[0-9]{1,18}", s, re.ASCII):  # ASCII digits only: 30² is text
        return (0, int(s), s)
    try:
        v = float(s) if s.isascii() and "_" not in s else math.nan
    except ValueError:
        return (1, 0, s)
    return (0, v, s) if np.isfinite(v) else (1, 0, s)


def five_statistics(runs: pd.DataFrame, summary: pd.DataFrame | None = None) -> pd.DataFrame:
    """Tables 4.2-4.5: rows (scenario, goal, statistic) for the five statistics of distance_m,
    one column per planner variant (``summary``: :func:`summarise` of ``runs``, if at hand)."""
    s = summarise(runs) if summary is None else summary
    long = s.melt(id_vars=["scenario", "goal", "planner"], value_vars=FIVE, var_name="statistic")
    t = long.pivot_table(index=["scenario", "goal", "statistic"], columns="planner", values="value", sort=False)
    t = t.reindex(columns=planner_order(t.columns))
    order = {k: i for i, k in enumerate(FIVE)}
    return in_goal_order(t.sort_index(level=[0, 1, 2], key=lambda idx: idx.map(order) if idx.name == "statistic" else idx))


def _wide(s: pd.DataFrame, cell) -> pd.DataFrame:
    s = s.assign(cell=s.apply(cell, axis=1))
    t = s.pivot_table(index=["scenario", "goal"], columns="planner", values="cell", aggfunc="first")
    t = t.reindex(columns=planner_order(t.columns))
    t["shortest_m"] = s.groupby(["scenario", "goal"])["shortest_m"].first()
    return in_goal_order(t)


def mean_std(runs: pd.DataFrame, summary: pd.DataFrame | None = None) -> pd.DataFrame:
    """Tables 4.6-4.9: ``mean +- std`` per goal and variant beside the shortest path (m), as the
    thesis prints them (std over runs, ddof=1: the spread of runs, not the uncertainty of the mean;
    see :func:`mean_ci`)."""
    s = summarise(runs) if summary is None else summary
    return _wide(s, lambda r: f"{r['mean']:.2f} ± {0.0 if pd.isna(r['std']) else r['std']:.2f}")


def mean_ci(runs: pd.DataFrame, summary: pd.DataFrame | None = None) -> pd.DataFrame:
    """Beside Tables 4.6-4.9: ``mean [lo, hi] (n)`` per goal and variant, the 95% interval of the
    mean distance (m) by a bootstrap over ``n`` units (episodes, or the repeats of a goal's one
    episode: :func:`summarise`), beside the shortest path (m)."""
    s = summarise(runs) if summary is None else summary

    def cell(r):
        ci = "[-]" if pd.isna(r["mean_lo"]) else f"[{r['mean_lo']:.2f}, {r['mean_hi']:.2f}]"
        return f"{r['mean']:.2f} {ci} ({r['n_units']})"

    return _wide(s, cell)


def percent_of_optimal(runs: pd.DataFrame, summary: pd.DataFrame | None = None) -> pd.DataFrame:
    """Table 4.10: the mean ratio to the shortest path, in percent: 100 x the mean over runs of each
    run's ``ratio`` (its distance over its own episode's shortest path; docs/reports.md, "The ratio
    to the shortest path"). From the thesis' single start this is its mean distance over the
    shortest path; from drawn starts each run is measured against its own start's shortest path
    (not the mean distance over the mean shortest path, which weighs long episodes more).

    ``summary`` is no longer read (kept for the signature): the percentages come from the rows' own
    ratios (4 decimals), not from a summary's mean_ratio (rounded to 3)."""
    s = runs.assign(pct=100.0 * pd.to_numeric(runs["ratio"], errors="coerce"))
    t = s.pivot_table(index=["scenario", "goal"], columns="planner", values="pct", aggfunc="mean").round(2)
    return in_goal_order(t.reindex(columns=planner_order(t.columns)))


CAUSES = ("budget", "stuck", "explored", "error", "timeout")


def causes(runs: pd.DataFrame) -> pd.Series:
    """Why each run ended without finding its goal: the ``cause`` column, or where it is missing
    or empty (older folders) the outcome (``not_found``: nowhere left to look, i.e. explored)."""
    fallback = runs["outcome"].map(OUTCOME_CAUSES).fillna("").astype(str)
    if "cause" not in runs.columns:
        return fallback
    c = runs["cause"].fillna("").astype(str)
    return c.where(c != "", fallback)


def success_and_spl(runs: pd.DataFrame) -> pd.DataFrame:
    """Per goal and variant: runs, distinct episodes, success rate with its 95% interval
    clustered on units (:func:`.stats.rate_ci`; ``unit``, ``n_units``), mean SPL (Anderson et al.
    2018), mean soft SPL when runs.csv has it, and the failed runs by cause (:data:`CAUSES`)."""
    df = runs.assign(_cause=causes(runs).where(runs["success"] == 0, ""))

    def row(d):
        u = S.units(d)
        p, lo, hi = S.rate_ci(d["success"], u)
        out = {"n": len(d), "episodes": int(S.episodes(d).nunique()), "success_rate": p, "success_lo": lo,
               "success_hi": hi, "spl": float(d["spl"].mean())}
        if "soft_spl" in d.columns:
            out["soft_spl"] = float(d["soft_spl"].mean())
        return out | {c: int((d["_cause"] == c).sum()) for c in CAUSES} | {"unit": S.unit_kind(d), "n_units": int(u.nunique())}

    cols = ["n", "episodes", "success_rate", "success_lo", "success_hi", "spl"] + (["soft_spl"] if "soft_spl" in runs.columns else [])
    return per_group(df, KEYS, row, cols + list(CAUSES) + ["unit", "n_units"]).round(3)


MIN_N = 5
SIGNIFICANCE = ["scenario", "goal", "baseline", "planner", "test", "n_pairs", "n_baseline", "n", "mean_diff", "diff_lo",
                "diff_hi", "p_value", "effect_r", "note"]


def _trials(d: pd.DataFrame) -> set:
    return set(zip(S.episodes(d), pd.to_numeric(d["seed"], errors="coerce")))


def _blanks(r: dict) -> list[str]:
    """Why a comparison (:func:`.stats.paired` or :func:`.stats.unpaired`) leaves its p-value or
    its interval blank, or sets p by convention, in words for the ``note`` column."""
    out = []
    if "n_pairs" in r:  # paired
        if r["n_pairs"] == 0:
            return ["no shared units: no test, no interval"]
        if r.get("n_nonzero", 0) == 0:
            out.append("every paired difference is 0: p = 1 by convention (nothing to rank)")
        elif pd.isna(r["p_value"]):
            out.append(f"fewer than 2 non-zero paired differences ({r['n_nonzero']}): no test")
        few = r["n_pairs"] < 2
    else:
        if min(r["n_a"], r["n_b"]) == 0:
            return ["no units on one side: no test, no interval"]
        if pd.isna(r["p_value"]):
            out.append("no test")
        few = min(r["n_a"], r["n_b"]) < 2
    if pd.isna(r["diff_lo"]):
        out.append(("1 pair" if "n_pairs" in r else "1 unit on a side") + ": no interval" if few else
                   "no interval (the bootstrap is degenerate)")
    return out


def significance(runs: pd.DataFrame, baseline: str | None = None, value: str = "distance_m") -> pd.DataFrame:
    """Per goal, each planner variant against a baseline on ``value`` (m).

    The baseline is ``baseline`` when given and present, else the first planner whose class says
    it is one (:attr:`~semsearch_cli.planners.Planner.baseline`, greedy), else the first planner of
    :func:`planner_order`. When the variant and the baseline ran the same set of
    (episode, seed) for the goal (they share episodes and random streams), the comparison is
    paired (:func:`.stats.paired`): per-unit differences, the Wilcoxon signed-rank test and the
    matched-pairs rank-biserial r. Otherwise it falls back to the unpaired Mann-Whitney U test over
    each side's unit means (:func:`.stats.unpaired`). Either way ``mean_diff`` = variant -
    baseline with its 95% bootstrap interval (negative: the variant travels less) and ``effect_r``
    is positive when the variant travels more. ``n_baseline`` and ``n`` count units; ``note``
    says why a p-value or an interval is blank (fewer than 2 non-zero paired differences: the
    signed-rank test has nothing to rank; one pair or unit: no interval; no shared units), that p
    is 1 by convention when every paired difference is 0, and flags fewer than ``MIN_N`` units
    (pairs), too few for the test to mean much."""
    rows = []
    for (scen, goal), g in runs.groupby(["scenario", "goal"], dropna=False):  # a missing goal is compared too
        order = planner_order(g["planner"])
        base = baseline if baseline in order else baseline_of(order)
        b = g[g["planner"] == base]
        for lab in order:
            if lab == base:
                continue
            x = g[g["planner"] == lab]
            row = {"scenario": scen, "goal": goal, "baseline": base, "planner": lab}
            if _trials(x) == _trials(b):
                r = S.paired(x, b, value)
                row |= {"test": f"wilcoxon signed-rank, paired on {r['unit']}", "n_pairs": r["n_pairs"],
                        "n_baseline": r["n_pairs"], "n": r["n_pairs"]}
                small = r["n_pairs"]
            else:
                r = S.unpaired(x, b, value)
                row |= {"test": "mann-whitney, unpaired", "n_pairs": np.nan, "n_baseline": r["n_b"], "n": r["n_a"]}
                small = min(r["n_a"], r["n_b"])
            row |= {k: r[k] for k in ("mean_diff", "diff_lo", "diff_hi", "p_value", "effect_r")}
            row["note"] = "; ".join(_blanks(r) + ([f"n < {MIN_N}: too few units to judge"] if 0 < small < MIN_N else []))
            rows.append(row)
    out = in_goal_order(pd.DataFrame(rows, columns=SIGNIFICANCE)).reset_index(drop=True)
    return out.round({"mean_diff": 3, "diff_lo": 3, "diff_hi": 3, "effect_r": 3})


def cells(df: pd.DataFrame, mark_rows: bool = False, fmt: str = "{:.2f}") -> tuple[list[str], list[list[tuple]]]:
    """A DataFrame as text cells: (header, rows of (text, mark)); index levels become leading
    columns. With ``mark_rows`` the smallest value of each row is marked ``best`` and the largest
    ``worst`` (the thesis' green and red cells); other marks are None."""
    idx_names = [str(n or "") for n in (df.index.names if df.index.nlevels > 1 or df.index.name else [])]
    head = idx_names + [str(c) for c in df.columns]
    rows = []
    for key, row in df.iterrows():
        keys = list(key) if isinstance(key, tuple) else ([key] if idx_names else [])
        vals = row.to_numpy()
        num = pd.to_numeric(pd.Series(vals), errors="coerce")
        lo, hi = (num.min(), num.max()) if mark_rows and num.notna().sum() > 1 else (None, None)
        out = [(str(k), None) for k in keys]
        for v, nv in zip(vals, num):
            if isinstance(v, float) and pd.isna(v):
                out.append(("", None))
                continue
            if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
                text = str(v)  # a count: no decimals
            else:
                text = fmt.format(v) if isinstance(v, float) else str(v)
            mark = "best" if lo is not None and nv == lo else "worst" if hi is not None and nv == hi and hi != lo else None
            out.append((text, mark))
        rows.append(out)
    return head, rows


def sweep_table(runs: pd.DataFrame, param: str) -> pd.DataFrame:
    """One row per value of a swept parameter x goal x planner variant: runs, success rate
    (found within the budget), mean and std of the ratio to the shortest path and the median
    distance (m), over every run, failures included at the distance they travelled."""
    g = runs.groupby(["value", "goal", "planner"], sort=False)
    out = g.agg(n=("distance_m", "size"), success_rate=("success", "mean"), mean_ratio=("ratio", "mean"),
                std_ratio=("ratio", "std"), median_m=("distance_m", "median")).reset_index()
    out = out.rename(columns={"value": param})
    return out.round(3)


def cost_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario and planner that reports what its decisions cost (a language model:
    :data:`~semsearch_cli.metrics.COST_COLUMNS`), the runs, each cost summed over them, and calls
    and tokens per run; empty when no row holds a cost."""
    have = [c for c in COST_COLUMNS if c in runs.columns]
    if not have:
        return pd.DataFrame()
    costs = runs[have].apply(pd.to_numeric, errors="coerce")
    rows = runs.loc[costs.notna().any(axis=1)]
    if rows.empty:
        return pd.DataFrame()
    out = []
    for (scenario, planner), g in rows.groupby(["scenario", "planner"], sort=False):
        c = costs.loc[g.index]
        row = {"scenario": scenario, "planner": planner, "runs": len(g)}
        row |= {k: round(float(c[k].sum()), 3) if k == "llm_s" else int(c[k].sum()) for k in have}
        if "llm_calls" in have:
            row["calls per run"] = round(float(c["llm_calls"].mean()), 1)
        if {"tokens_in", "tokens_out"} <= set(have):
            row["tokens per run"] = round(float((c["tokens_in"] + c["tokens_out"]).mean()), 1)
        out.append(row)
    return pd.DataFrame(out)
