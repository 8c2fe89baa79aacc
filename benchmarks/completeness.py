"""Completeness: does every door planner find every goal that is readable from reachable free space?

Usage:
  semsearch generate batch --out results/batch --seeds 1          (20 buildings)
  semsearch import kth FLOOR.xml --out /tmp/kth-floor             (any KTH floors you have)
  python benchmarks/completeness.py results/batch /tmp/kth-floor/scenario.yaml [--seeds 2]
      [--all-signs] [--workers 2] [--md FILE]

A folder argument is a generated batch (its index.txt lists the scenarios); a file is one
scenario. Every scenario is run with every door planner (greedy, bvp, geometric, nsos at
alpha 0.9, draft); ``--all-signs`` makes every readable sign of each scenario file a goal
(instead of its own goals; a batch's scenarios keep theirs). Rows go to ``<out>/<scenario>/runs.csv`` (resumable). Prints, per source and
planner, the runs and how many ended other than ``found`` (stuck, budget), and lists them.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import pandas as pd

from output import emit

from semsearch_cli.config import PlannerSpec, read_yaml
from semsearch_cli.report.document import markdown_table
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch

PLANNERS = [PlannerSpec(name="greedy"), PlannerSpec(name="bvp"), PlannerSpec(name="geometric"),
            PlannerSpec(name="nsos", alpha=0.9), PlannerSpec(name="draft")]


def scenarios(arg: Path) -> list[Path]:
    if arg.is_dir():
        return [arg / line for line in (arg / "index.txt").read_text().split()]
    return [arg]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("sources", type=Path, nargs="+")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--all-signs", action="store_true", help="every readable sign a goal, for single scenario files")
    ap.add_argument("--out", type=Path, default=Path("results/completeness"))
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    frames = []
    t0 = time.perf_counter()
    for src in a.sources:
        for p in scenarios(src):
            L = Loaded.load(p)
            if a.all_signs and not src.is_dir():
                w = L.world
                data = read_yaml(p)
                data["goals"] = sorted({w.signs.number[i] for i in range(len(w.signs)) if w.readable_mask(i).any()}, key=str)
                L = Loaded.load(p, data)
            L = L.with_planners(PLANNERS)
            runs = run_batch(L, expand(L, a.seeds), a.out / L.sc.name, BatchOptions(workers=a.workers))
            frames.append(runs.assign(source=src.name))
            print(f"{L.sc.name}: {len(runs)} runs, {int((runs.outcome != 'found').sum())} not found", file=sys.stderr, flush=True)
    df = pd.concat(frames, ignore_index=True)
    wall = time.perf_counter() - t0
    df["not_found"] = df["outcome"] != "found"
    table = df.groupby(["source", "planner"], sort=False).agg(scenarios=("scenario", "nunique"), runs=("outcome", "size"),
                                                                not_found=("not_found", "sum")).reset_index()
    total = pd.DataFrame([{"source": "all", "planner": "all", "scenarios": df["scenario"].nunique(), "runs": len(df),
                           "not_found": int(df["not_found"].sum())}])
    table = pd.concat([table, total], ignore_index=True)
    text = markdown_table(table, fmt="{:g}")
    bad = df[df["not_found"]][["scenario", "planner", "goal", "seed", "outcome", "distance_m", "shortest_m"]]
    if len(bad):
        text += "\n\nnot found:\n\n" + markdown_table(bad, fmt="{:g}")
    text += f"\n\n{len(df)} runs in {wall:.0f} s\n"
    return emit(text, a.md)


if __name__ == "__main__":
    sys.exit(main())
