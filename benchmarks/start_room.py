"""Why nsos lost goal 135 of the authors' Hotel on engine 2: what the skeleton shows in the start
room, and which way the robot turns at the first junction.

The thesis start (46, 64) m lies in a room about 5 m wide whose only way out is its south end, at
a T junction with the main corridor (46.4, 49.5) m: straight on leads south down a dead-end wing,
east leads to room 135. For each seed this runs nsos on the authors' Hotel map (read from
../shared, never copied) and prints, from the planner's own inputs at each decision:

- ``side``: decisions with a candidate against the start room's side walls (x < 45.5 or > 47.5 m,
  y > 52.5 m), where a branch of the skeleton ends at unknown cells beside the robot;
- ``ends`` / ``fresh``: the median over those decisions' belief maps of the skeleton's branch ends in
  the start room, as the belief keeps it, and in scikit-image's thinning of the same free map from
  scratch (so a spur the kept skeleton holds and the map does not shows as ends > fresh);
- ``junction``: the way the robot leaves the junction (where it first is 4 m from it: south, east
  or west), and the candidates' geometric factors GF at the first decision there, best first
  (Eq. 4.8's heading and closeness terms; no sign counts there yet, so the semantic factor is 0.25
  for all and GF decides).

It runs on either engine: from this checkout for engine 2, and with an engine-1 release
(``pip install 'semsearch==0.2.*'``, or a checkout of it) for engine 1, the script passed by path.

Usage: python benchmarks/start_room.py [--goal 135] [--alpha 0.8] [--seeds 0,1,2] [--md FILE]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.ndimage import convolve
from skimage.morphology import skeletonize

sys.path.insert(0, str(Path(__file__).resolve().parent))

from output import emit  # noqa: E402

import semsearch_cli  # noqa: E402
from semsearch_cli.engine import ENGINE  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.planners.doors import nsos as nsos_module  # noqa: E402
from semsearch_cli.runner import Loaded  # noqa: E402
from semsearch_cli.world.importers.mobilesim import import_mobilesim  # noqa: E402

REF = Path(__file__).resolve().parents[2] / "shared" / "reference_maps"
ROOM = (43.5, 50.0, 52.5, 69.0)  # the start room of the authors' Hotel, x0, x1, y0, y1 (m)
JUNCTION = (46.4, 49.5)  # where the start room meets the main corridor (m)
NEIGHBOURS = np.ones((3, 3), int)
NEIGHBOURS[1, 1] = 0


def branch_ends(skeleton: np.ndarray, box: tuple[int, int, int, int]) -> int:
    r0, r1, c0, c1 = box
    n = convolve(skeleton.astype(int), NEIGHBOURS, mode="constant")
    return int((skeleton & (n == 1))[r0:r1, c0:c1].sum())


def one_run(loaded: Loaded, alpha: float, goal: int, seed: int) -> dict:
    f = loaded.world.frame
    (r0, c0), (r1, c1) = f.to_cell(ROOM[0], ROOM[3]), f.to_cell(ROOM[1], ROOM[2])
    box = (int(r0), int(r1), int(c0), int(c1))
    seen = {"side": 0, "decisions": 0, "ends": [], "fresh": [], "gf": None, "way": None}
    decide = nsos_module.NSOS._decide

    def spy(self, ctx, cands, keep=None):
        object.__setattr__(ctx, "explain", True)  # the candidates' factors, as `semsearch explain` shows them
        d = decide(self, ctx, cands, keep)
        seen["decisions"] += 1
        x, y = f.to_world(ctx.row, ctx.col)
        cs = (d.info or {}).get("candidates", []) if d is not None else []
        if any(c["y"] > ROOM[2] and ROOM[0] < c["x"] < ROOM[1] and not 45.5 <= c["x"] <= 47.5 for c in cs):
            seen["side"] += 1
            seen["ends"].append(branch_ends(ctx.belief.skeleton, box))
            seen["fresh"].append(branch_ends(skeletonize(ctx.belief.free), box))
        if seen["gf"] is None and y < 51.0 and cs:  # the first decision at the junction
            seen["gf"] = ", ".join(f"{c['GF']:.3f}" for c in sorted(cs, key=lambda c: -c["GF"]))
        if seen["gf"] is not None and seen["way"] is None and np.hypot(x - JUNCTION[0], y - JUNCTION[1]) > 4.0:
            seen["way"] = "south" if y < JUNCTION[1] - 3.0 else "east" if x > JUNCTION[0] else "west"
        return d

    nsos_module.NSOS._decide = spy
    try:
        r = loaded.task.run(Variant("nsos", (("alpha", alpha),)), goal, seed)
    finally:
        nsos_module.NSOS._decide = decide
    med = (lambda v: f"{np.median(v):.0f}" if v else "-")
    return {"seed": seed, "distance": r.distance_m, "decisions": seen["decisions"], "side": seen["side"],
            "ends": med(seen["ends"]), "fresh": med(seen["fresh"]), "junction": f"{seen['way'] or '-'} (GF {seen['gf'] or '-'})"}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--goal", type=int, default=135)
    ap.add_argument("--alpha", type=float, default=0.8)
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    if not REF.is_dir():
        print(f"skipped: the authors' reference maps are not at {REF} (../shared absent)")
        return 0
    tmp = Path(tempfile.mkdtemp(prefix="semsearch-start-room-"))
    p, _ = import_mobilesim(REF / "hotel2.map", REF / "hotel2.doors", tmp / "hotel", 0.1, (46.0, 64.0),
                            [76, 135, 148, 185], 2.5, "hotel-reference")
    loaded = Loaded.load(p)
    lines = [f"semsearch {semsearch_cli.__version__}, engine {ENGINE}: nsos[alpha={a.alpha}], authors' Hotel, goal {a.goal}",
             "", "| seed | distance (m) | decisions | side | ends | fresh | junction |", "|---|---|---|---|---|---|---|"]
    for s in (int(x) for x in a.seeds.split(",")):
        o = one_run(loaded, a.alpha, a.goal, s)
        lines.append(f"| {o['seed']} | {o['distance']:.1f} | {o['decisions']} | {o['side']} | {o['ends']} | {o['fresh']} | {o['junction']} |")
    emit("\n".join(lines), a.md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
