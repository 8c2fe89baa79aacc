"""Tables rebuilt from rows alone (SPEC 9)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import mannwhitneyu

from ..runner import file_stem

def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario x goal x planner variant: n, success rate, median, mean, std (ddof=1, as the
    thesis' tables), min and max of distance_m, the shortest path and the mean ratio."""
    g = runs.groupby(["scenario", "goal", "planner"], sort=True)
    out = g.agg(
        n=("distance_m", "size"),
        success_rate=("success", "mean"),
        median=("distance_m", "median"),
        mean=("distance_m", "mean"),
        std=("distance_m", "std"),
        min=("distance_m", "min"),
        max=("distance_m", "max"),
        shortest_m=("shortest_m", "first"),
        mean_ratio=("ratio", "mean"),
    ).reset_index()
    return out.round(3)


def median_paths(folder: Path, med: pd.DataFrame, goal, order: list) -> dict:
    """Planner label -> (path (n, 2) m, its row) of the median run of each planner for ``goal``
    (``med`` from :func:`median_run`), in ``order``, for the runs whose path file is in
    ``folder/paths``."""
    out = {}
    for r in med[med["goal"].astype(str) == str(goal)].itertuples(index=False):
        p = folder / "paths" / f"{file_stem(r.planner, goal, int(r.seed))}.npz"
        if p.is_file():
            out[r.planner] = (np.load(p)["path"], r)
    return {k: out[k] for k in order if k in out}


def median_run(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario x goal x planner: the row of the run whose distance is the (lower) median."""
    def pick(df):
        df = df.sort_values(["distance_m", "seed"])
        return df.iloc[(len(df) - 1) // 2]

    return runs.groupby(["scenario", "goal", "planner"], sort=True)[runs.columns.tolist()].apply(pick).reset_index(drop=True)


# ---- the thesis' tables and what it lacked (issue: reports) -------------------------------------
FIVE = ["median", "mean", "std", "min", "max"]


def goal_key(g):
    """Sort goals numerically when they are numbers, then as text."""
    s = str(g)
    return (0, int(s), "") if s.lstrip("-").isdigit() else (1, 0, s)


def planner_order(labels) -> list[str]:
    """greedy, bvp, geometric, other planners, then nsos variants by alpha."""

    def key(lab):
        name = lab.split("[", 1)[0]
        rank = {"greedy": 0, "bvp": 1, "geometric": 2, "nsos": 4}.get(name, 3)
        m = re.search(r"alpha=([0-9.]+)", lab)
        return (rank, name, float(m.group(1)) if m else 0.0, lab)

    return sorted(set(labels), key=key)


def five_statistics(runs: pd.DataFrame) -> pd.DataFrame:
    """Tables 4.2-4.5: rows (scenario, goal, statistic) for the five statistics of distance_m,
    one column per planner variant."""
    s = summarise(runs)
    long = s.melt(id_vars=["scenario", "goal", "planner"], value_vars=FIVE, var_name="statistic")
    t = long.pivot_table(index=["scenario", "goal", "statistic"], columns="planner", values="value", sort=False)
    t = t.reindex(columns=planner_order(t.columns))
    order = {k: i for i, k in enumerate(FIVE)}
    return t.sort_index(level=[0, 1, 2], key=lambda idx: idx.map(order) if idx.name == "statistic" else idx)


def mean_std(runs: pd.DataFrame) -> pd.DataFrame:
    """Tables 4.6-4.9: ``mean +- std`` per goal and variant beside the shortest path (m)."""
    s = summarise(runs)
    s["cell"] = s.apply(lambda r: f"{r['mean']:.2f} ± {0.0 if pd.isna(r['std']) else r['std']:.2f}", axis=1)
    t = s.pivot_table(index=["scenario", "goal"], columns="planner", values="cell", aggfunc="first")
    t = t.reindex(columns=planner_order(t.columns))
    t["shortest_m"] = s.groupby(["scenario", "goal"])["shortest_m"].first()
    return t


def percent_of_optimal(runs: pd.DataFrame) -> pd.DataFrame:
    """Table 4.10: mean distance as a percentage of the shortest path."""
    s = summarise(runs)
    s["pct"] = (100.0 * s["mean"] / s["shortest_m"]).round(2)
    t = s.pivot_table(index=["scenario", "goal"], columns="planner", values="pct")
    return t.reindex(columns=planner_order(t.columns))


def success_and_spl(runs: pd.DataFrame) -> pd.DataFrame:
    """Success rate and mean SPL (Anderson et al. 2018) per goal and variant."""
    g = runs.groupby(["scenario", "goal", "planner"])
    return g.agg(n=("success", "size"), success_rate=("success", "mean"), spl=("spl", "mean"),
                 budget=("outcome", lambda o: int((o == "budget").sum())),
                 stuck=("outcome", lambda o: int((o == "stuck").sum()))).round(3).reset_index()


MIN_N = 5


def significance(runs: pd.DataFrame, baseline: str = "greedy") -> pd.DataFrame:
    """Per goal, a two-sided Mann-Whitney U test (SciPy) of distance_m between ``baseline`` and
    each other variant, with the rank-biserial effect size r = 1 - 2U / (n1 n2) (positive when
    the variant travels less than the baseline) and a note when either sample has fewer than
    ``MIN_N`` runs (too few for the test to mean much)."""
    rows = []
    for (scen, goal), g in runs.groupby(["scenario", "goal"]):
        base = g[g["planner"] == baseline]["distance_m"].to_numpy()
        for lab in planner_order(g["planner"]):
            if lab == baseline:
                continue
            x = g[g["planner"] == lab]["distance_m"].to_numpy()
            row = {"scenario": scen, "goal": goal, "baseline": baseline, "planner": lab, "n_baseline": len(base), "n": len(x)}
            if len(base) and len(x):
                u, p = mannwhitneyu(x, base, alternative="two-sided")
                row.update(U=float(u), p_value=float(p), effect_r=round(1.0 - 2.0 * float(u) / (len(x) * len(base)), 3))
            else:
                row.update(U=float("nan"), p_value=float("nan"), effect_r=float("nan"))
            row["note"] = f"n < {MIN_N}: too few runs to judge" if min(len(base), len(x)) < MIN_N else ""
            rows.append(row)
    return pd.DataFrame(rows, columns=["scenario", "goal", "baseline", "planner", "n_baseline", "n", "U", "p_value", "effect_r", "note"])


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
            text = fmt.format(v) if isinstance(v, (float, int)) and not isinstance(v, bool) else str(v)
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
