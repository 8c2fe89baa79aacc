"""What moved between two engines: the same runs (the thesis door tables of bench_door_search.py
``--tables thesis --keep DIR``, made by each engine), paired run by run.

    python benchmarks/engine_moves.py OLD_DIR NEW_DIR [--out FILE.md]

OLD_DIR and NEW_DIR hold one folder per config (normal, inverse, hotel_thesis, kth), each with its
runs.csv. Rows pair on (config, planner, params, goal, episode, seed); per planner and goal: each
engine's mean distance, the mean paired difference (new - old) with its 95% interval over the
pairs (semsearch_cli.report.stats.paired: a BCa bootstrap; the unit is the repeat, one episode
per goal), the Wilcoxon p-value, success on each side; then per planner over all its goals.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd
from output import emit

from semsearch_cli.report import stats
from semsearch_cli.runner.store import read_runs


def load(root: Path) -> pd.DataFrame:
    parts = []
    for f in sorted(root.glob("*/runs.csv")):
        df = read_runs(f)
        df["config"] = f.parent.name
        parts.append(df)
    if not parts:
        raise SystemExit(f"no */runs.csv under {root}")
    return pd.concat(parts, ignore_index=True)


def label(row) -> str:
    return row["planner"]  # the label names its parameters (nsos[alpha=0.9])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--out", type=Path)
    a = ap.parse_args()
    old, new = load(a.old), load(a.new)
    engines = (sorted(set(old["engine"])), sorted(set(new["engine"])))
    for df in (old, new):
        df["who"] = df.apply(label, axis=1)
    key = ["config", "who", "goal"]
    lines = [f"engine {engines[0]} ({a.old}) against engine {engines[1]} ({a.new}): {len(old)} and {len(new)} rows", "",
             "| config | planner | goal | pairs | old mean (m) | new mean (m) | new - old (m) [95% CI] | p | found old / new |",
             "|---|---|---|---|---|---|---|---|---|"]
    summary = []
    for (cfg, who, goal), o in old.groupby(key, sort=True):
        n = new[(new["config"] == cfg) & (new["who"] == who) & (new["goal"] == goal)]
        p = stats.paired(n, o)
        summary.append((cfg, who, o, n))
        lines.append(f"| {cfg} | {who} | {goal} | {p['n_pairs']} | {o['distance_m'].mean():.1f} | {n['distance_m'].mean():.1f} | "
                     f"{p['mean_diff']:+.1f} [{p['diff_lo']:+.1f}, {p['diff_hi']:+.1f}] | {p['p_value']:.3g} | "
                     f"{int(o['success'].sum())} / {int(n['success'].sum())} |")
    lines += ["", "Per planner, over its goals (pairs pooled):", "",
              "| config | planner | pairs | old mean (m) | new mean (m) | new - old (m) [95% CI] | p |", "|---|---|---|---|---|---|---|"]
    for (cfg, who), o in old.groupby(["config", "who"], sort=True):
        n = new[(new["config"] == cfg) & (new["who"] == who)]
        # pair on (goal, seed): one unit per run
        o2, n2 = o.assign(episode=o["goal"].astype(str)), n.assign(episode=n["goal"].astype(str))
        p = stats.paired(n2, o2)
        lines.append(f"| {cfg} | {who} | {p['n_pairs']} | {o['distance_m'].mean():.1f} | {n['distance_m'].mean():.1f} | "
                     f"{p['mean_diff']:+.1f} [{p['diff_lo']:+.1f}, {p['diff_hi']:+.1f}] | {p['p_value']:.3g} |")
    emit("\n".join(lines), a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
