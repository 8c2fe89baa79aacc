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
from pathlib import Path

from output import emit
from refmaps import hotel

from semsearch_cli.planners import Variant

# (phase, (file under semsearch_cli/, function) whose cumulative time is that phase's; a file
# ending in / stands for every file under that folder; several pairs add up). A re-plan is the
# door search's plan(), a generator (belief upkeep, candidates, the path; cProfile counts each
# resume as a call), which stops at a decision point that run_loop has the planner answer
# (decisions.ask): the two add up.
PHASES = [("sensing (laser, HIMM, door cameras, visited kernel)", ("tasks/doors.py", "sense")),
          ("re-planning in all (the rows below)", (("tasks/doors.py", "plan"), ("tasks/decisions.py", "ask"))),
          ("  belief upkeep (skeleton, segments)", ("belief/doors.py", "refresh_derived")),
          ("  frontier candidates", ("belief/doors.py", "candidates")),
          ("  planner decision", ("planners/", "choose")),
          ("  path to the target (navigator)", ("navigation/navigators.py", "plan"))]
PACKAGE = "semsearch_cli"


def phase_time(by_name: dict, key: tuple) -> float:
    """The cumulative seconds of a phase's function (:data:`PHASES`), 0 when it was not called."""
    if isinstance(key[0], tuple):
        return sum(phase_time(by_name, k) for k in key)
    file, name = key
    if file.endswith("/"):
        return sum(t for (f, n), t in by_name.items() if n == name and f.startswith(file))
    return by_name.get(key, 0.0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--planner", default="nsos")
    ap.add_argument("--alpha", type=float, default=0.9)
    ap.add_argument("--goal", type=int, default=148)
    ap.add_argument("--top", type=int, default=20)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    L = hotel("semsearch-profile-")
    if L is None:
        return 0
    v = Variant(a.planner, (("alpha", a.alpha),) if a.planner == "nsos" else ())
    L.task.run(v, a.goal, 0)  # warm-up: numba's cache, imports
    prof = cProfile.Profile()
    res = prof.runcall(L.task.run, v, a.goal, 0)
    st = pstats.Stats(prof)
    total = max(t[3] for t in st.stats.values())
    by_name: dict[tuple, float] = {}
    for (file, _, name), (_, _, _, cum, _) in st.stats.items():
        parts = Path(file).parts
        if PACKAGE in parts:
            key = ("/".join(parts[len(parts) - parts[::-1].index(PACKAGE):]), name)  # the path under the package
            by_name[key] = by_name.get(key, 0.0) + cum
    lines = [f"{v.label}, goal {a.goal}, seed 0: {res.distance_m:.1f} m, {res.steps} steps, {res.decisions} decisions; "
             f"{total:.2f} s under the profiler", "",
             "| phase | cumulative s | share |", "|---|---|---|"]
    missing = [key for _, key in PHASES if phase_time(by_name, key) == 0.0]
    if missing:  # a phase's function renamed or moved: say so, rather than print 0% for it
        raise SystemExit(f"profile_door.py: no time under {', '.join(map(str, missing))}; update PHASES")
    for phase, key in PHASES:
        t = phase_time(by_name, key)
        lines.append(f"| {phase} | {t:.3f} | {t / total:.0%} |")
    out = io.StringIO()
    pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(a.top)
    body = [ln for ln in out.getvalue().splitlines() if ln.strip()][-a.top - 1:]
    lines += ["", f"top {a.top} functions by own time:", "", "```", *body, "```"]
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
