"""Object-search benchmark on our office (configs/office.yaml).

Measures (medians of repeated runs, in one process):
  1. loading the scenario: the map checks, recording every case (11 patrols of 10 hours) and the
     shortest paths; the baseline is loading without recording (the checks alone);
  2. one run of each planner on the moved-mug request (lsos tries A, then finds the mug at H) and
     brute force on Static at midnight (the whole route to H), with seconds per 100 m;
  3. the whole office experiment (13 requests x 3 planners x 10 seeds) with 2 workers, without
     the report.

Usage: python benchmarks/bench_object_search.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from semsearch_cli.config import load_scenario
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch
from semsearch_cli.tasks.objects import ObjectTask
from semsearch_cli.planners import Variant
from semsearch_cli.world.ground_truth import build_world

OFFICE = Path(__file__).resolve().parents[1] / "configs" / "office.yaml"


def median_time(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    Loaded.load(OFFICE)  # compile the numba kernels once

    def checks_only():
        sc = load_scenario(OFFICE)
        return ObjectTask(sc, build_world(sc, OFFICE.parent, str(OFFICE)), OFFICE)

    t_checks, _ = median_time(checks_only, args.repeat)
    t_load, L = median_time(lambda: Loaded.load(OFFICE), args.repeat)
    print("| what | median | note |\n|---|---|---|")
    print(f"| load office.yaml with recording | {t_load:.2f} s | checks alone {t_checks:.2f} s "
          f"(recording = {t_load / t_checks:.1f}x the checks) |")
    for label, planner in (("Moved-mug.mug@0", "lsos"), ("Moved-mug.mug@0", "brute_force"),
                           ("Moved-mug.mug@0", "last_seen"), ("Static.mug@0", "brute_force")):
        t, res = median_time(lambda label=label, planner=planner: L.task.run(Variant(planner, ()), label, 0), args.repeat)
        print(f"| {planner}, {label}, seed 0 | {t * 1000:.0f} ms | {res.distance_m:.1f} m, {res.outcome}, "
              f"{t / max(res.distance_m, 1e-9) * 100 * 1000:.0f} ms per 100 m |")
    with tempfile.TemporaryDirectory() as d:
        specs = expand(L)
        t = time.perf_counter()
        rows = run_batch(L, specs, Path(d), BatchOptions(workers=2))
        wall = time.perf_counter() - t
    print(f"| whole office experiment, {len(rows)} runs, 2 workers | {wall:.1f} s | "
          f"{rows['distance_m'].sum() / 1000:.1f} km travelled |")


if __name__ == "__main__":
    main()
