"""Greedy against nsos on many generated buildings, per numbering scheme (random included).

Usage: semsearch generate batch --out results/batch      (60 buildings: 4 layouts x 5 schemes x 3)
       python benchmarks/robustness.py results/batch [--workers 2] [--md FILE]
Each scenario's rows go to <batch>/<scenario>/results/runs.csv (resumable).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import pandas as pd

from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("batch", type=Path)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    frames = []
    t0 = time.perf_counter()
    for line in (a.batch / "index.txt").read_text().split():
        p = a.batch / line
        L = Loaded.load(p)
        runs = run_batch(L, expand(L), p.parent / "results", BatchOptions(workers=a.workers))
        layout, scheme = L.sc.name.split("-", 1)[0], L.sc.name.split("-", 1)[1].rsplit("-", 1)[0]
        frames.append(runs.assign(layout=layout, scheme=scheme))
        print(f"{L.sc.name}: {len(runs)} rows", file=sys.stderr, flush=True)
    df = pd.concat(frames, ignore_index=True)
    wall = time.perf_counter() - t0
    # per building and goal: mean ratio of each planner, then nsos / greedy
    per = df.groupby(["scheme", "scenario", "goal", "planner"])["ratio"].mean().unstack("planner")
    nsos = [c for c in per.columns if c.startswith("nsos")][0]
    per["rel"] = per[nsos] / per["greedy"]
    rows = []
    for scheme, g in per.groupby(level="scheme"):
        sub = df[df.scheme == scheme]
        rows.append({
            "scheme": scheme,
            "buildings": g.index.get_level_values("scenario").nunique(),
            "goals": len(g),
            "greedy mean ratio": round(g["greedy"].mean(), 2),
            f"{nsos} mean ratio": round(g[nsos].mean(), 2),
            "nsos / greedy (median over goals)": round(g["rel"].median(), 2),
            "goals where nsos is shorter": f"{(g['rel'] < 1).mean():.0%}",
            "success greedy": f"{sub[sub.planner == 'greedy']['success'].mean():.0%}",
            "success nsos": f"{sub[sub.planner == nsos]['success'].mean():.0%}",
        })
    table = pd.DataFrame(rows)
    text = "\n".join(["| " + " | ".join(table.columns) + " |", "|" + "---|" * len(table.columns)]
                     + ["| " + " | ".join(str(v) for v in r) + " |" for r in table.itertuples(index=False)])
    print(text)
    print(f"\n{len(df)} runs in {wall:.0f} s")
    if a.md:
        a.md.write_text(text + f"\n\n{len(df)} runs in {wall:.0f} s\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
