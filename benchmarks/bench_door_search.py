"""Door-search benchmark on the authors' Hotel map (read from ../shared, never copied).

Measures (medians of repeated runs, with ratios against baselines timed in the same process):
  1. one run each of greedy and nsos (alpha 0.9), Hotel goal 148, seed 0, under each re-planning
     policy (``--replan periodic,events``, navigation.replan): wall time and seconds
     per 300 m travelled; the baseline is the sensing-only loop (laser + HIMM + door cameras +
     visited kernel) over the same poses, i.e. the floor any planner pays, and what a decision
     costs beyond it (the run's median less the baseline's, over the decisions: belief upkeep,
     candidates, the planner, the path and the loop between two decisions);
  2. whole Hotel tables with 2 workers: 4 goals x greedy and bvp x 10 seeds, and 4 goals x
     greedy and nsos at alpha 0.8, 0.9, 1.0 x 10 seeds;
  3. navigators: path lengths of the geodesic and the harmonic navigator between random pairs of
     cells on the fully known Hotel map, and greedy runs with either navigator;
  4. with ``--tables thesis``: every door table of the thesis on our own buildings (configs
     normal, inverse, hotel and kth: 13 goals x greedy and nsos at alpha 0.8, 0.9, 1.0 x 10
     seeds = 520 runs), 2 workers, rows kept in a temporary folder (``--keep DIR`` to compare them
     with benchmarks/compare_rows.py). This part does not need ../shared.

Usage: python benchmarks/bench_door_search.py [--repeat 5] [--replan periodic,events] [--tables bvp,nsos,thesis] [--keep DIR] [--out FILE.md]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from semsearch_cli.belief import DoorBelief
from semsearch_cli.config import NavigationSpec, PlannerSpec
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch
from semsearch_cli.tasks import build_task
from semsearch_cli.navigation import GeodesicNavigator, HarmonicNavigator
from semsearch_cli.planners import Variant
from semsearch_cli.sensors.doors import DoorCamera, Laser
from semsearch_cli.world.importers.mobilesim import import_mobilesim

REF = Path(__file__).resolve().parents[2] / "shared" / "reference_maps"


def sensing_only(L: Loaded, path: np.ndarray) -> float:
    """Seconds to sense and update the belief at each pose of ``path`` (no planning, no motion)."""
    sc, w = L.sc, L.world
    b = DoorBelief(w.frame, sc.belief, sc.robot.radius)
    laser, cam = Laser(w, sc.laser), DoorCamera(w, sc.door_camera)
    rng = np.random.default_rng(0)
    t0 = time.perf_counter()
    prev = path[0]
    for x, y in path[1:]:
        heading = float(np.arctan2(y - prev[1], x - prev[0])) if (x, y) != tuple(prev) else 0.0
        prev = (x, y)
        v, u = w.frame.to_cell(x, y)
        b.fold_scan(float(v), float(u), *laser.scan(float(v), float(u), heading, rng))
        cam.read(float(x), float(y), heading, rng)
        b.visit(int(np.floor(v)), int(np.floor(u)))
    return time.perf_counter() - t0


def thesis_tables(say, out: Path) -> None:
    """Every door table of the thesis on our own buildings, greedy and nsos, 2 workers."""
    repo = Path(__file__).resolve().parents[1]
    say("## 4. every door table of the thesis (configs normal, inverse, hotel, kth; greedy and nsos x 10 seeds), 2 workers")
    say("| config | runs | wall (s) | sum of run times (s) | km travelled |")
    say("|---|---|---|---|---|")
    n_all = wall_all = 0.0
    for name in ("normal", "inverse", "hotel_thesis", "kth"):
        t0 = time.perf_counter()
        L = Loaded.load(repo / "configs" / f"{name}.yaml")
        specs = expand(L, 10, planners=["greedy", "nsos"])
        runs = run_batch(L, specs, out / name, BatchOptions(workers=2))
        wall = time.perf_counter() - t0
        n_all += len(runs)
        wall_all += wall
        say(f"| {name} | {len(runs)} | {wall:.1f} | {runs['wall_s'].sum():.1f} | {runs['distance_m'].sum() / 1000:.1f} |")
    say(f"| all | {n_all:.0f} | {wall_all:.1f} | | |")
    say()


def known_belief(L: Loaded) -> DoorBelief:
    w = L.world
    b = DoorBelief(w.frame, L.sc.belief, L.sc.robot.radius)
    b.seen[:] = True
    b.cv[w.occ] = 15
    b.refresh_free(np.array([0, w.frame.height - 1, 0, w.frame.width - 1]))
    b.refresh_derived()
    return b


def drive(nav, b: DoorBelief, r: int, c: int, tr: int, tc: int, replan_cells: float) -> float | None:
    """Length (cells) a robot travels from (r, c) to (tr, tc), re-planning every ``replan_cells``."""
    total = 0.0
    for _ in range(10_000):
        if (r, c) == (tr, tc):
            return total
        p = nav.plan(b, r, c, tr, tc)
        if p is None or len(p[0]) < 2:
            return None
        rows, cols = p
        seg = np.hypot(np.diff(rows), np.diff(cols))
        k = max(1, int(np.searchsorted(np.cumsum(seg), replan_cells)) + 1)
        k = min(k, len(rows) - 1)
        total += float(seg[:k].sum())
        r, c = int(rows[k]), int(cols[k])
    return None


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--pairs", type=int, default=40)
    ap.add_argument("--replan", default="periodic,events", help="re-planning policies to time in part 1 (navigation.replan)")
    ap.add_argument("--tables", default="bvp,nsos", help="which whole tables to time: bvp, nsos, thesis, several or none")
    ap.add_argument("--keep", type=Path, help="folder for the thesis tables' rows (default: a temporary one)")
    ap.add_argument("--out", type=Path)
    a = ap.parse_args()
    lines = []

    def say(s=""):
        print(s, flush=True)
        lines.append(s)

    tmp = Path(tempfile.mkdtemp(prefix="semsearch-bench-"))
    if "thesis" in a.tables.split(","):
        thesis_tables(say, a.keep or tmp / "thesis")
    if not REF.is_dir():
        print(f"skipped: the authors' reference maps are not at {REF} (../shared absent)")
        return 0
    p, _ = import_mobilesim(REF / "hotel2.map", REF / "hotel2.doors", tmp / "hotel", 0.1, (46.0, 64.0), [76, 135, 148, 185], 2.5, "hotel-reference")
    L = Loaded.load(p)
    say(f"# semsearch door-search benchmark ({time.strftime('%Y-%m-%d %H:%M')}, {sys.platform}, python {sys.version.split()[0]})")
    say()
    # 1. one run per planner, under each re-planning policy
    for replan in a.replan.split(","):
        sc_r = L.sc.model_copy(update={"navigation": L.sc.navigation.model_copy(update={"replan": replan})})
        task = build_task(sc_r, L.world, L.path)
        for variant in (Variant("greedy", ()), Variant("nsos", (("alpha", 0.9),))):
            task.run(variant, 148, 0)  # warm-up (numba cache, imports)
            walls, base = [], []
            for _ in range(a.repeat):
                res = task.run(variant, 148, 0)
                walls.append(res.wall_s)
                base.append(sensing_only(L, res.path.astype(float)))
            med, bmed = statistics.median(walls), statistics.median(base)
            say(f"## 1. {variant.label}, Hotel goal 148, seed 0, navigation.replan: {replan} ({a.repeat} repeats)")
            say(f"distance {res.distance_m:.1f} m, {res.steps} steps, {res.decisions} decisions, outcome {res.outcome}")
            say(f"median wall {med:.3f} s (min {min(walls):.3f}, max {max(walls):.3f}) = {med / res.distance_m * 300:.2f} s per 300 m (target <= 1.5)")
            say(f"sensing-only baseline over the same poses: median {bmed:.3f} s; run / baseline = {med / bmed:.2f} (target <= 1.5)")
            say(f"a decision beyond sensing, (run - baseline) / decisions: {(med - bmed) / res.decisions * 1000:.2f} ms")
            say()
    # 2. navigators
    b = known_belief(L)
    rng = np.random.default_rng(7)
    rr, cc = np.nonzero(L.world.reach & b.passable)
    geo, har = GeodesicNavigator(), HarmonicNavigator()
    rel, tg, th = [], [], []
    while len(rel) < a.pairs:
        i, j = rng.integers(len(rr), size=2)
        d = np.hypot(rr[i] - rr[j], cc[i] - cc[j]) * L.world.frame.res
        if not 5.0 <= d <= 30.0:
            continue
        args = (b, int(rr[i]), int(cc[i]), int(rr[j]), int(cc[j]), L.sc.navigation.replan_every / L.world.frame.res)
        t0 = time.perf_counter()
        lg = drive(geo, *args)
        t1 = time.perf_counter()
        lh = drive(har, *args)
        t2 = time.perf_counter()
        if lg is None or lh is None:
            continue
        rel.append(lh / lg - 1.0)
        tg.append(t1 - t0)
        th.append(t2 - t1)
    rel = np.array(rel)
    say(f"## 2. navigators on the fully known Hotel map ({a.pairs} random pairs 5-30 m apart, re-planning every {L.sc.navigation.replan_every} m)")
    say(f"harmonic path length vs geodesic: mean {rel.mean() * 100:+.1f}%, median {np.median(rel) * 100:+.1f}%, "
        f"range {rel.min() * 100:+.1f}% .. {rel.max() * 100:+.1f}%; harmonic fell back to geodesic {har.fallbacks} times")
    say(f"time to drive one pair: geodesic median {statistics.median(tg) * 1000:.0f} ms, harmonic median {statistics.median(th) * 1000:.0f} ms")
    sc_h = L.sc.model_copy(update={"navigation": NavigationSpec(navigator="harmonic")})
    task_h = build_task(sc_h, L.world, L.path)
    dg, dh = [], []
    for s in range(3):
        dg.append(L.task.run(Variant("greedy", ()), 148, s).distance_m)
        dh.append(task_h.run(Variant("greedy", ()), 148, s).distance_m)
    say("greedy runs, goal 148, seeds 0-2: geodesic " + ", ".join(f"{d:.1f}" for d in dg)
        + " m; harmonic " + ", ".join(f"{d:.1f}" for d in dh) + " m")
    say()
    # 3. whole tables

    tables = {"bvp": [PlannerSpec(name="greedy"), PlannerSpec(name="bvp")],
              "nsos": [PlannerSpec(name="greedy"), PlannerSpec(name="nsos", alpha=[0.8, 0.9, 1.0])]}
    for key in [t for t in a.tables.split(",") if t in tables]:
        L = L.with_planners(tables[key])  # the task's own planners (setting L.sc alone left them as they were)
        specs = expand(L, 10)
        t0 = time.perf_counter()
        runs = run_batch(L, specs, tmp / f"table-{key}", BatchOptions(workers=2))
        wall = time.perf_counter() - t0
        labels = sorted(runs["planner"].unique())
        say(f"## 3. whole Hotel table: 4 goals x {', '.join(labels)} x 10 seeds = {len(specs)} runs, 2 workers")
        say(f"wall {wall:.1f} s; sum of run times {runs['wall_s'].sum():.1f} s; travelled {runs['distance_m'].sum() / 1000:.1f} km; "
            f"{runs['wall_s'].sum() / runs['distance_m'].sum() * 300:.2f} s per 300 m over all runs")
        say(runs.groupby("planner")["wall_s"].describe().round(2).to_string())
        say()
    if a.out:
        a.out.write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
