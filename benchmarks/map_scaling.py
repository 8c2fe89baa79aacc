"""Cost grows with the work, not the map: seconds per 300 m travelled on configs/hotel.yaml and on
the same layout generated at twice the scale (4x the area, corridors as wide), for greedy and nsos.

Usage:
  python benchmarks/map_scaling.py [--seeds 3] [--scale 2] [--md FILE]

Both buildings come from `semsearch generate building --layout wings --numbering odd-even-out
--seed 0 --spacing 3.0` (the hotel keeps 124 signs, as configs/hotel.yaml); each runs its own
four goals x ``--seeds`` seeds in one process (after a warm-up run), and the table gives the
total wall time over the total distance travelled, and the ratio of the large building's to the
hotel's (same process, same day). Memory: ``python benchmarks/memory.py SCENARIO``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from output import emit

from semsearch_cli.planners import Variant
from semsearch_cli.runner import Loaded
from semsearch_cli.world.buildings.numbered import generate_building

VARIANTS = [Variant("greedy", ()), Variant("nsos", (("alpha", 0.9),))]


def cost(L: Loaded, variant: Variant, seeds: int) -> tuple[float, float, int]:
    """(wall s, metres, runs) over every goal x seed."""
    wall = dist = 0.0
    n = 0
    for g in L.goals:
        for s in range(seeds):
            res = L.task.run(variant, g, s)
            wall, dist, n = wall + res.wall_s, dist + res.distance_m, n + 1
    return wall, dist, n


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--scale", type=float, default=2.0)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="semsearch-scale-"))
    small = Loaded.load(generate_building("wings", "odd-even-out", 0, tmp / "x1", spacing=3.0, signs=124))
    large = Loaded.load(generate_building("wings", "odd-even-out", 0, tmp / f"x{a.scale:g}", spacing=3.0, scale=a.scale))
    lines = ["| building | cells | signs | planner | runs | km | s per 300 m | ratio to x1 |", "|---|---|---|---|---|---|---|---|"]
    for v in VARIANTS:
        small.task.run(v, small.goals[0], 0)  # warm-up
        base = None
        for tag, L in (("x1", small), (f"x{a.scale:g} (4x area)" if a.scale == 2 else f"x{a.scale:g}", large)):
            wall, dist, n = cost(L, v, a.seeds)
            per = wall / dist * 300
            base = base or per
            lines.append(f"| {tag} | {L.world.free.size:,} | {len(L.world.signs)} | {v.label} | {n} | {dist / 1000:.1f} | {per:.3f} | "
                         f"{per / base:.2f} |")
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
