"""Run door-search planners on the authors' three reference maps (from ../shared, never copied
into the repository) and print, per goal and planner, mean +- std and the ratio to the shortest
path beside the thesis' Tables 4.2-4.4 and 4.6-4.8.

Usage: python benchmarks/reference_table.py [--seeds 10] [--workers 2] [--planners greedy,nsos]
           [--alphas 0.8,0.9,1.0] [--heading random|DEG] [--out results/reference] [--md FILE]
Rows go to OUT/<map>/runs.csv (resumable), like `semsearch run`.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from thesis import GREEDY, MAPS, NSOS, SHORTEST  # noqa: E402

from semsearch_cli.config import PlannerSpec  # noqa: E402
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch  # noqa: E402
from semsearch_cli.planners import expand_variants  # noqa: E402
from semsearch_cli.report.build import write_meta  # noqa: E402
from semsearch_cli.report.tables import summarise  # noqa: E402
from semsearch_cli.world.importers.mobilesim import import_mobilesim  # noqa: E402

REF = Path(__file__).resolve().parents[2] / "shared" / "reference_maps"


def thesis_value(name, goal, variant):
    if variant.name == "greedy":
        return GREEDY[name][goal]
    if variant.name == "nsos":
        return NSOS[name][goal].get(dict(variant.params).get("alpha"))
    return None


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--planners", default="greedy,nsos")
    ap.add_argument("--alphas", default="0.8,0.9,1.0")
    ap.add_argument("--out", type=Path, default=Path("results/reference"))
    ap.add_argument("--md", type=Path)
    ap.add_argument("--heading", default="random", help="start heading in degrees, or random (the importer's default)")
    a = ap.parse_args()
    if not REF.is_dir():
        print(f"skipped: the authors' reference maps are not at {REF} (../shared absent)")
        return 0
    specs = [PlannerSpec(name="nsos", alpha=[float(x) for x in a.alphas.split(",")]) if p == "nsos" else PlannerSpec(name=p)
             for p in a.planners.split(",")]
    variants = expand_variants(specs)
    tmp = Path(tempfile.mkdtemp(prefix="semsearch-ref-"))
    lines = ["| map | goal | shortest ours / thesis (m) | planner | ours: mean +- std (m) | ratio | success | thesis: mean +- std (m) | thesis ratio |",
             "|---|---|---|---|---|---|---|---|---|"]
    for stem, (name, start, delta) in MAPS.items():
        goals = list(GREEDY[name])
        p, _ = import_mobilesim(REF / f"{stem}.map", REF / f"{stem}.doors", tmp / stem, 0.1, start, goals, delta, f"{name.lower()}-reference")
        if a.heading != "random":  # the scenario's start heading, written into the imported file
            d = yaml.safe_load(p.read_text())
            d["start"]["heading"] = float(a.heading)
            p.write_text(yaml.safe_dump(d, sort_keys=False))
        L = Loaded.load(p).with_planners(specs)
        todo = expand(L, a.seeds)
        t0 = time.perf_counter()
        write_meta(a.out / name.lower(), L)
        runs = run_batch(L, todo, a.out / name.lower(), BatchOptions(workers=a.workers))
        print(f"{name}: {len(todo)} runs in {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
        s = summarise(runs).set_index(["goal", "planner"])
        for g in goals:
            sh = SHORTEST[name][g]
            for v in variants:
                r = s.loc[(g, v.label)]
                t = thesis_value(name, g, v)
                ts = f"{t[0]:.1f} +- {t[1]:.1f} | {t[0] / sh:.2f}" if t else "- | -"
                lines.append(f"| {name} | {g} | {L.shortest[g]:.1f} / {sh:.1f} | {v.label} | {r['mean']:.1f} +- {r['std']:.1f} | "
                             f"{r['mean_ratio']:.2f} | {r['success_rate']:.0%} | {ts} |")
    text = "\n".join(lines)
    print(text)
    if a.md:
        a.md.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
