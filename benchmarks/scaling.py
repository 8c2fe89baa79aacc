"""Scaling: runs per second of one batch with 1 and 2 workers in the process pool and on a
2-worker local Dask cluster, with the parallel efficiency (rate / (workers x the 1-worker rate)).

Usage:
  python benchmarks/scaling.py [SCENARIO] [--seeds 5] [--planner greedy] [--repeat 2] [--md FILE]

Default: configs/hotel.yaml, greedy, 4 goals x 5 seeds = 20 runs. Each configuration runs the
whole batch into a fresh folder (so nothing resumes), ``--repeat`` times; the median wall time is
shown, start-up included (the pool's fork, the local cluster's start and the scenario's scatter).
The rows of every configuration are checked to be identical (wall time aside).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from output import emit

from semsearch_cli import api
from semsearch_cli.runner import BatchOptions
from semsearch_cli.report.document import markdown_table

REPO = Path(__file__).resolve().parents[1]
SAME = ["planner", "goal", "seed", "outcome", "distance_m", "steps", "decisions"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", nargs="?", type=Path, default=REPO / "configs" / "hotel.yaml")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--planner", default="greedy")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    configs = [("process pool", "processes", 1), ("process pool", "processes", 2), ("local Dask cluster", "dask", 2)]
    rows, reference = [], None
    with tempfile.TemporaryDirectory() as tmp:
        for name, executor, workers in configs:
            times = []
            for k in range(a.repeat):
                out = Path(tmp) / f"{executor}-{workers}-{k}"
                t0 = time.perf_counter()
                res = api.run(a.scenario, BatchOptions(seeds=a.seeds, workers=workers, planners=[a.planner], out=out, executor=executor), plots=False)
                times.append(time.perf_counter() - t0)
                got = res.runs[SAME].sort_values(["planner", "goal", "seed"]).reset_index(drop=True)
                if reference is None:
                    reference = got
                elif not got.equals(reference):
                    raise SystemExit(f"rows differ on {name} with {workers} workers")
            n = len(res.runs)
            rows.append({"executor": name, "workers": workers, "runs": n, "wall_s": statistics.median(times),
                         "runs_per_s": n / statistics.median(times)})
    base = rows[0]["runs_per_s"]
    for r in rows:
        r["efficiency"] = r["runs_per_s"] / (r["workers"] * base)
    df = pd.DataFrame(rows)
    text = (f"{a.scenario.name}, {a.planner}, {rows[0]['runs']} runs per batch, median of {a.repeat} (rows identical in all)\n\n"
            + markdown_table(df.round({"wall_s": 1, "runs_per_s": 3, "efficiency": 2}), fmt="{:g}"))
    return emit(text, a.md)


if __name__ == "__main__":
    sys.exit(main())
