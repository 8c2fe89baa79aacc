"""Labelled decisions for a learned door planner: draw training floors (semsearch_cli/learn/floors.py:
doors-v1's mix from a salt of their own, no benchmark floor), run a behaviour planner over their
episodes, and write one row per frontier target of every decision with the features the robot
has and the oracle's label (semsearch_cli/learn/labels.py). Run from the checkout:

    python scripts/make_labels.py --floors 120 --out results/labels/greedy [--planner greedy] [--seeds 1] [--first 0]

Rows are appended to OUT/labels.csv floor by floor; a floor already in it is skipped, so an
interrupted run resumes. OUT/floors/ keeps the floors (their scenarios run as they are)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import pandas as pd

from semsearch_cli.learn import collect, training_floor


def make(floors: int, out: Path, planner: str = "greedy", seeds: int = 1, first: int = 0) -> Path:
    """Label training floors ``first .. first + floors - 1`` into ``out/labels.csv`` (a floor
    already there is skipped); returns the CSV's path."""
    csv = out / "labels.csv"
    done = set(pd.read_csv(csv, usecols=["scenario"])["scenario"]) if csv.is_file() else set()
    t0 = time.perf_counter()
    for i in range(first, first + floors):
        path, recipe = training_floor(i, out / "floors")
        name = path.parent.name
        scenario = f"doors-train-{name}"
        if scenario in done:
            continue
        df = collect(path, planner, seeds=seeds)
        df.insert(1, "layout", recipe["layout"])
        df.insert(2, "numbering", recipe["numbering"])
        df.to_csv(csv, mode="a", header=not csv.is_file(), index=False, lineterminator="\n")
        runs = df.groupby(["goal", "episode", "seed"]).ngroups
        print(f"{name} {recipe['layout']}/{recipe['numbering']}: {runs} runs, {df['decision'].groupby([df['goal'], df['episode'], df['seed']]).nunique().sum()} "
              f"decisions, {len(df)} targets; {time.perf_counter() - t0:.0f} s", flush=True)
    return csv


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--floors", type=int, default=20)
    ap.add_argument("--first", type=int, default=0, help="the first training floor's index")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--planner", default="greedy", help="the behaviour policy whose decisions are labelled")
    ap.add_argument("--seeds", type=int, default=1)
    a = ap.parse_args()
    make(a.floors, a.out, a.planner, a.seeds, a.first)
    return 0


if __name__ == "__main__":
    sys.exit(main())
