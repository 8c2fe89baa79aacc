"""Our Normal, Inverse and Hotel with greedy, nsos at the thesis' alphas and the draft paper's
planner: mean +- std (m) per goal, and whether nsos (at its best alpha per goal) beats greedy with
a smaller spread, the shape of the thesis' Tables 4.2-4.4.

Usage: python benchmarks/door_tables.py [--configs normal,inverse,hotel_thesis] [--seeds 10] [--workers 2]
           [--out results/door_tables] [--md FILE]
Rows go to OUT/<config>/runs.csv (resumable).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import pandas as pd

from output import emit

from semsearch_cli.config import PlannerSpec
from semsearch_cli.report.document import markdown_table
from semsearch_cli.report.tables import goal_key
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch

ROOT = Path(__file__).resolve().parents[1]
PLANNERS = [PlannerSpec(name="greedy"), PlannerSpec(name="nsos", alpha=[0.8, 0.9, 1.0]), PlannerSpec(name="draft")]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", default="normal,inverse,hotel_thesis")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("results/door_tables"))
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    parts, shape = [], []
    t0 = time.perf_counter()
    for name in a.configs.split(","):
        L = Loaded.load(ROOT / "configs" / f"{name}.yaml").with_planners(PLANNERS)
        runs = run_batch(L, expand(L, a.seeds), a.out / name, BatchOptions(workers=a.workers))
        g = runs.groupby(["goal", "planner"])["distance_m"].agg(["mean", "std"])
        cell = (g["mean"].round(1).astype(str) + " +- " + g["std"].round(1).astype(str)).unstack("planner")
        cell.index = [f"{name} {goal}" for goal in cell.index]
        parts.append(cell.reindex(sorted(cell.index, key=lambda s: goal_key(s.split()[1]))))
        wins = spread = 0
        for goal in sorted(runs["goal"].unique(), key=goal_key):
            nsos = g.loc[goal][g.loc[goal].index.str.startswith("nsos")]
            best = nsos["mean"].idxmin()
            wins += nsos.loc[best, "mean"] < g.loc[(goal, "greedy"), "mean"]
            spread += nsos.loc[best, "std"] < g.loc[(goal, "greedy"), "std"]
        ngoals = runs["goal"].nunique()
        shape.append({"config": name, "goals": ngoals, "nsos (best alpha) shorter than greedy": f"{wins} of {ngoals}",
                      "nsos (best alpha) smaller spread": f"{spread} of {ngoals}"})
        print(f"{name}: {len(runs)} runs", file=sys.stderr, flush=True)
    table = pd.concat(parts)
    table.index.name = "map goal"
    text = (markdown_table(table) + "\n\n" + markdown_table(pd.DataFrame(shape), fmt="{:g}") +
            f"\n\n{a.seeds} seeds; {time.perf_counter() - t0:.0f} s\n")
    return emit(text, a.md)


if __name__ == "__main__":
    sys.exit(main())
