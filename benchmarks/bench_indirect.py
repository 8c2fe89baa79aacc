"""Indirect-search benchmark: the whole Table 3 experiment (configs/indirect.yaml: 11 methods x 7
view scales x 200 trials = 15,400 searches of up to 5 simulated minutes) with 2 workers.

Prints the wall time of the whole experiment against the target (30 minutes), and per method the
cost of one camera frame (wall time / frames, medians over its searches) as a ratio to UIS's in
the same run, the baseline: UIS updates the map with A's non-detections only, so the ratio is what
each method's secondary objects and planning add.

Usage: python benchmarks/bench_indirect.py [--starts 10] [--workers 2] [--out results/indirect]
       (trials per method and scale: --starts drawn in each of the 20 rooms, one run each;
       --starts 1 is a tenth of the experiment, a couple of minutes); then
       semsearch report results/indirect  for the tables, figures and the replay
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from semsearch_cli.report.build import write_meta
from semsearch_cli.config import read_yaml
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch

SCENARIO = Path(__file__).resolve().parents[1] / "configs" / "indirect.yaml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, default=None, help="starts drawn per room (default: the scenario's)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("results/indirect"))
    ap.add_argument("--scenario", type=Path, default=SCENARIO)
    args = ap.parse_args()
    data = read_yaml(args.scenario)
    if args.starts is not None:
        data["episodes"] = {**(data.get("episodes") or {}), "starts": args.starts}
    loaded = Loaded.load(args.scenario, data)
    specs = expand(loaded)
    trials = len(specs) // max(1, len(loaded.task.variants()) * len(loaded.goals))
    runs_csv = args.out / "runs.csv"
    if runs_csv.is_file():
        raise SystemExit(f"{runs_csv} exists: the benchmark times a fresh run; give another --out")
    write_meta(args.out, loaded)  # so that `semsearch report OUT` can replay a search
    t0 = time.perf_counter()
    rows = run_batch(loaded, specs, args.out, BatchOptions(workers=args.workers))
    wall = time.perf_counter() - t0
    print(f"{len(rows)} searches ({len(loaded.task.variants())} methods x {len(loaded.goals)} view scales x {trials} "
          f"trials), {args.workers} workers: {wall:.1f} s = {wall / 60:.1f} min (target for 15,400: 30 min); "
          f"{rows['steps'].sum() / 1e6:.2f} M frames, {rows['time_s'].astype(float).sum() / 3600:.0f} h simulated")
    rows = rows.assign(ms_per_frame=1000 * rows["wall_s"] / rows["steps"].clip(lower=1))
    per = rows.groupby("planner").agg(searches=("steps", "size"), frames=("steps", "sum"),
                                      ms_per_frame=("ms_per_frame", "median"), wall_s=("wall_s", "sum"))
    base = per.loc["UIS", "ms_per_frame"] if "UIS" in per.index else float("nan")
    per["ratio_to_UIS"] = per["ms_per_frame"] / base
    print("| method | searches | frames | ms per frame (median) | ratio to UIS | wall s (sum) |")
    print("|---|---|---|---|---|---|")
    for name, r in per.sort_values("ms_per_frame").iterrows():
        print(f"| {name} | {r.searches:.0f} | {r.frames:.0f} | {r.ms_per_frame:.3f} | {r.ratio_to_UIS:.1f} | {r.wall_s:.0f} |")


if __name__ == "__main__":
    main()
