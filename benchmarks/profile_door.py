"""Where a door-search run spends its time: cProfile of one run on the authors' Hotel map (read
from ../shared, never copied), goal 148, seed 0, after a warm-up run, grouped into the phases of
the loop (sensing, belief upkeep, candidates, planner, navigation).

Usage:
  python benchmarks/profile_door.py [--planner nsos] [--alpha 0.9] [--goal 148] [--top 20] [--md FILE]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import sys
import tempfile
from pathlib import Path

from output import emit

from semsearch_cli.planners import Variant
from semsearch_cli.runner import Loaded
from semsearch_cli.world.importers.mobilesim import import_mobilesim

REF = Path(__file__).resolve().parents[2] / "shared" / "reference_maps"
# (phase, (file, function) whose cumulative time is that phase's)
PHASES = [("sensing (laser, HIMM, door cameras, visited kernel)", ("doors.py", "sense")),
          ("re-planning in all (the rows below)", ("doors.py", "plan")),
          ("  belief upkeep (skeleton, segments)", ("belief.py", "refresh_derived")),
          ("  frontier candidates", ("belief.py", "candidates")),
          ("  planner decision", ("*", "choose")),
          ("  path to the target (navigator)", ("navigators.py", "plan"))]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--planner", default="nsos")
    ap.add_argument("--alpha", type=float, default=0.9)
    ap.add_argument("--goal", type=int, default=148)
    ap.add_argument("--top", type=int, default=20)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    if not REF.is_dir():
        print(f"skipped: the authors' reference maps are not at {REF} (../shared absent)")
        return 0
    tmp = Path(tempfile.mkdtemp(prefix="semsearch-profile-"))
    p, _ = import_mobilesim(REF / "hotel2.map", REF / "hotel2.doors", tmp / "hotel", 0.1, (46.0, 64.0), [76, 135, 148, 185], 2.5,
                            "hotel-reference")
    L = Loaded.load(p)
    v = Variant(a.planner, (("alpha", a.alpha),) if a.planner == "nsos" else ())
    L.task.run(v, a.goal, 0)  # warm-up: numba's cache, imports
    prof = cProfile.Profile()
    res = prof.runcall(L.task.run, v, a.goal, 0)
    st = pstats.Stats(prof)
    total = max(t[3] for t in st.stats.values())
    by_name: dict[tuple, float] = {}
    for (file, _, name), (_, _, _, cum, _) in st.stats.items():
        if "semsearch_cli" in file:
            key = (Path(file).name, name)
            by_name[key] = by_name.get(key, 0.0) + cum
    lines = [f"{v.label}, goal {a.goal}, seed 0: {res.distance_m:.1f} m, {res.steps} steps, {res.decisions} decisions; "
             f"{total:.2f} s under the profiler", "",
             "| phase | cumulative s | share |", "|---|---|---|"]
    for phase, key in PHASES:
        t = sum(v for (f, n), v in by_name.items() if n == key[1]) if key[0] == "*" else by_name.get(key, 0.0)
        lines.append(f"| {phase} | {t:.3f} | {t / total:.0%} |")
    out = io.StringIO()
    pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(a.top)
    body = [ln for ln in out.getvalue().splitlines() if ln.strip()][-a.top - 1:]
    lines += ["", f"top {a.top} functions by own time:", "", "```", *body, "```"]
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
