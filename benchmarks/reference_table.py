"""Run the door-search planners on the authors' three reference maps (from ../shared, never
copied into the repository) and print per-goal mean +- std and ratio to the shortest path beside
the thesis' Greedy column.

Usage: python benchmarks/reference_table.py [--seeds 10] [--workers 2] [--planners greedy,bvp]
                                            [--out results/reference] [--md FILE]
Rows go to OUT/<map>/runs.csv (resumable), like `semsearch run`.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from thesis import GREEDY, MAPS, SHORTEST  # noqa: E402

from semsearch_cli.experiment import Loaded, expand, run_batch  # noqa: E402
from semsearch_cli.report.tables import summarise  # noqa: E402
from semsearch_cli.world.mobilesim import import_mobilesim  # noqa: E402

REF = Path(__file__).resolve().parents[2] / "shared" / "reference_maps"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--planners", default="greedy,bvp")
    ap.add_argument("--out", type=Path, default=Path("results/reference"))
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    if not REF.is_dir():
        print(f"skipped: the authors' reference maps are not at {REF} (../shared absent)")
        return 0
    planners = a.planners.split(",")
    tmp = Path(tempfile.mkdtemp(prefix="semsearch-ref-"))
    lines = ["| map | goal | shortest (ours / thesis) | " + " | ".join(f"{p} mean +- std (ratio)" for p in planners)
             + " | thesis Greedy mean +- std (ratio) |", "|---" * (4 + len(planners)) + "|"]
    for stem, (name, start, delta) in MAPS.items():
        goals = list(GREEDY[name])
        p = import_mobilesim(REF / f"{stem}.map", REF / f"{stem}.doors", tmp / stem, 0.1, start, goals, delta, f"{name.lower()}-reference")
        L = Loaded.load(p)
        specs = expand(L, a.seeds, planners=planners)
        t0 = time.perf_counter()
        runs = run_batch(L, specs, a.out / name.lower(), a.workers)
        print(f"{name}: {len(specs)} runs in {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
        s = summarise(runs).set_index(["goal", "planner"])
        for g in goals:
            cells = []
            for pl in planners:
                r = s.loc[(g, pl)]
                fail = "" if r["success_rate"] == 1 else f", success {r['success_rate']:.0%}"
                cells.append(f"{r['mean']:.1f} +- {r['std']:.1f} ({r['mean_ratio']:.2f}{fail})")
            tm, ts = GREEDY[name][g]
            sh = SHORTEST[name][g]
            lines.append(f"| {name} | {g} | {L.shortest[g]:.1f} / {sh:.1f} | " + " | ".join(cells) + f" | {tm:.1f} +- {ts:.1f} ({tm / sh:.2f}) |")
    text = "\n".join(lines)
    print(text)
    if a.md:
        a.md.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
