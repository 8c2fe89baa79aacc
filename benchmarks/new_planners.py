"""The comparison that counts (issue 39, docs/learning.md): the numbering model and the learned
planner against nsos[alpha=0.9] and greedy, paired over episodes, on semsearch-bench doors-v1 val
(its true numbering and the shuffled-labels ablation) and on the thesis' floors
(doors-classic-v1), none of which they were trained or tuned on.

Per suite and numbering: each planner's success (Wilson's interval widened for clustered runs) and
mean distance (BCa over episodes), and its paired difference in distance against nsos and against
greedy: metres and per cent of the baseline's mean, with the 95% BCa interval over episodes (an
episode is a floor's start/goal problem, its repeats averaged). Then the same differences per
numbering convention, and by the floor's predictability (below and above the split's median).
Folders already complete are resumed.

Usage:
  python benchmarks/new_planners.py [--out results/new-planners] [--workers 2] [--md FILE]
                                    [--planners 'nsos[alpha=0.9],greedy,numbering,learned'] [--limit N]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from output import emit

from semsearch_cli import api
from semsearch_cli.bench.board import load, paired_diff
from semsearch_cli.report.stats import mean_ci, rate_ci
from semsearch_cli.runner import BatchOptions

BASELINES = ("nsos[alpha=0.9]", "greedy")
RUNS = (("doors-v1", "true"), ("doors-v1", "shuffled"), ("doors-classic-v1", "true"))


def safe(label: str) -> str:
    return label.replace("[", "_").replace("]", "").replace("=", "")


def diff_cell(a: pd.DataFrame, b: pd.DataFrame) -> str:
    """``+x.x m (+y%) [lo, hi]``: a minus b in mean distance over shared episodes, the per cent of
    b's mean over those episodes, and the 95% interval in metres."""
    if not len(a) or not len(b):
        return ""
    m, lo, hi, n = paired_diff(a, b, "distance_m")
    if not n:
        return ""
    base = b[b["unit"].isin(a["unit"])].groupby("unit")["distance_m"].mean().mean()
    return f"{m:+.1f} m ({100 * m / base:+.1f}%) [{lo:+.1f}, {hi:+.1f}]"


def table(rows: pd.DataFrame, planners: list[str], by: str | None) -> list[str]:
    head = ["| " + (by + " | " if by else "") + "planner | runs | found | mean distance (m) | vs nsos[alpha=0.9] | vs greedy |",
            "|" + "---|" * (6 + bool(by))]
    groups = rows.groupby(by, sort=True) if by else [(None, rows)]
    for key, g in groups:
        for p in planners:
            a = g[g["planner"] == p]
            if not len(a):
                continue
            u = a["unit"].to_numpy()
            found, f_lo, f_hi = rate_ci((a["outcome"] == "found").to_numpy(float), u)
            m, lo, hi = mean_ci(a["distance_m"].to_numpy(float), u)
            cells = [f"{100 * found:.1f}% [{100 * f_lo:.1f}, {100 * f_hi:.1f}]", f"{m:.1f} [{lo:.1f}, {hi:.1f}]"]
            cells += ["" if p == base else diff_cell(a, g[g["planner"] == base]) for base in BASELINES]
            head.append("| " + (f"{key} | " if by else "") + f"{p} | {len(a)} | " + " | ".join(cells) + " |")
    return head


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("results/new-planners"))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--planners", default="nsos[alpha=0.9],greedy,numbering,learned")
    ap.add_argument("--limit", type=int, help="the first N episodes of each split (a quick look; not the comparison)")
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    planners = a.planners.split(",")
    lines, frames = [], []
    for suite, numbering in RUNS:
        folders = []
        for planner in planners:
            out = a.out / suite / f"{safe(planner)}-{numbering}"
            t0 = time.perf_counter()
            res = api.bench_run(suite, [planner], out, numbering=numbering, options=BatchOptions(workers=a.workers), limit=a.limit)
            print(json.dumps({"suite": suite, "numbering": numbering, "planner": planner, "runs": len(res.runs),
                              "run_s": round(time.perf_counter() - t0, 1)}), flush=True)
            folders.append(out)
        rows = load(folders)
        frames.append(rows)
        lines += [f"## {suite} val, {numbering} numbering", "",
                  f"{rows['unit'].nunique()} episodes on {rows['floor'].nunique()} floors; differences paired over episodes, "
                  "95% BCa intervals.", ""]
        lines += table(rows, planners, None) + [""]
        if suite == "doors-v1":
            lines += [f"Per numbering convention ({numbering} labels):", ""] + table(rows, planners, "convention") + [""]
            median = float(np.nanmedian(rows.drop_duplicates("floor")["predictability"]))
            rows = rows.assign(predictable=np.where(rows["predictability"] > median, f"above {median:.3f}",
                                                    f"at most {median:.3f}"))
            lines += ["By the floor's predictability (the split's median):", ""] + table(rows, planners, "predictable") + [""]
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
