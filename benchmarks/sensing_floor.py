"""The sensing floor, part by part: what each part of a door-search frame costs against the work
it must do, on the authors' Hotel map (read from ../shared, never copied), over the poses of one
nsos run (alpha 0.9, goal 148, seed 0).

A frame is what every planner pays at every pose, whatever it decides: the laser (ray casting
against the ground truth), its HIMM update of the belief (``fold_scan``: the certainty values of
every cell the beams crossed, then ``free`` where it changed), the door cameras (the signs in
range, a line of sight to each) and the visited kernel (``visit``). Each part is timed alone over
the same poses (median of ``--repeat`` passes), and set against its work: cells crossed by the
beams (Amanatides and Woo visit each cell a beam passes through once: ``|dr| + |dc| + 1`` per
beam), cells whose free state the scan changed, signs tested, cells newly visited. Two floors
put the numbers in scale: the cost of calling a compiled kernel at all (a zero-beam cast), and the
cost per cell of the traversal itself (the laser's ns per cell crossed).

Usage:
  python benchmarks/sensing_floor.py [--repeat 5] [--md FILE]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from output import emit
from refmaps import hotel

from semsearch_cli.belief import DoorBelief
from semsearch_cli.kernels.grid import local_reach
from semsearch_cli.kernels.raycast import cast_rays
from semsearch_cli.planners import Variant
from semsearch_cli.runner import Loaded
from semsearch_cli.sensors.doors import DoorCamera, Laser

PARTS = ("laser", "fold_scan", "cameras", "visit")


def poses(path: np.ndarray) -> list[tuple[float, float, float]]:
    """(x, y, heading) at each pose of a run's path, heading along the last step (as the
    sensing-only baseline of bench_door_search.py)."""
    out, prev = [], path[0]
    for x, y in path[1:]:
        heading = float(np.arctan2(y - prev[1], x - prev[0])) if (x, y) != tuple(prev) else 0.0
        prev = (x, y)
        out.append((float(x), float(y), heading))
    return out


def one_pass(L: Loaded, frames) -> tuple[dict, dict]:
    """Seconds per part over ``frames`` on a fresh belief, and the work each part did."""
    sc, w = L.sc, L.world
    b = DoorBelief(w.frame, sc.belief, sc.robot.radius)
    laser, cam = Laser(w, sc.laser), DoorCamera(w, sc.door_camera)
    rng = np.random.default_rng(0)
    t = dict.fromkeys(PARTS, 0.0)
    work = {"cells crossed": 0, "beams": 0, "free changed": 0, "signs tested": 0, "signs read": 0, "cells visited": 0, "cells reached": 0}
    clock = time.perf_counter
    for x, y, heading in frames:
        v, u = w.frame.to_cell(x, y)
        v, u = float(v), float(u)
        t0 = clock()
        thetas, dist, hit = laser.scan(v, u, heading, rng)
        t1 = clock()
        before = b.free.copy()
        t2 = clock()
        b.fold_scan(v, u, thetas, dist, hit)
        t3 = clock()
        seen = cam.read(x, y, heading, rng)
        t4 = clock()
        nv = b.visited.sum()
        r, c = int(np.floor(v)), int(np.floor(u))
        res = w.frame.res
        reach = len(local_reach(b.free, r, c, sc.belief.visited_radius / res + 1e-6, False)[0])
        t5 = clock()
        b.visit(r, c)
        t6 = clock()
        t["laser"] += t1 - t0
        t["fold_scan"] += t3 - t2
        t["cameras"] += t4 - t3
        t["visit"] += t6 - t5
        # the work, outside the timed spans
        dv, du = -np.sin(thetas), np.cos(thetas)
        end = dist + np.where(hit, 1e-6, 0.0)
        r1, c1 = np.floor(v + end * dv), np.floor(u + end * du)
        work["cells crossed"] += int((np.abs(r1 - np.floor(v)) + np.abs(c1 - np.floor(u)) + 1).sum())
        work["beams"] += len(thetas)
        work["free changed"] += int((b.free != before).sum())
        work["signs tested"] += len(cam.sx)
        work["signs read"] += len(seen)
        new = int(b.visited.sum() - nv)
        work["cells visited"] += new
        # visit's work: the visited kernel's reach, and the density kernel's when a cell was new
        work["cells reached"] += reach + (len(local_reach(b.free, r, c, sc.belief.density_radius / res + 1e-6, True)[0]) if new else 0)
    return t, work


def call_floor(occ: np.ndarray, repeat: int = 20000) -> float:
    """Seconds to call the compiled ray caster with no beam: what any kernel call costs."""
    empty = np.zeros(0)
    cast_rays(occ, 10.0, 10.0, empty, 100.0)
    t0 = time.perf_counter()
    for _ in range(repeat):
        cast_rays(occ, 10.0, 10.0, empty, 100.0)
    return (time.perf_counter() - t0) / repeat


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    L = hotel("semsearch-sensing-")
    if L is None:
        return 0
    res = L.task.run(Variant("nsos", (("alpha", 0.9),)), 148, 0)
    frames = poses(res.path.astype(float))
    one_pass(L, frames)  # warm-up (numba cache)
    passes = [one_pass(L, frames) for _ in range(a.repeat)]
    work = passes[0][1]
    n = len(frames)
    med = {k: statistics.median(p[0][k] for p in passes) for k in PARTS}
    total = sum(med.values())
    call = call_floor(L.world.occ)
    per_cell = med["laser"] / work["cells crossed"]
    lines = [f"# The sensing floor ({time.strftime('%Y-%m-%d %H:%M')}, {sys.platform}, python {sys.version.split()[0]})", "",
             f"nsos alpha 0.9, the authors' Hotel, goal 148, seed 0: {n} frames, {res.distance_m:.1f} m; laser "
             f"{L.sc.laser.beams} beams over {L.sc.laser.fov:g} degrees to {L.sc.laser.range:g} m at {L.world.frame.res:g} m per cell; "
             f"{len(L.world.signs.x)} signs. Medians of {a.repeat} passes.", "",
             "| part | us per frame | share | work per frame | ns per unit of work |", "|---|---|---|---|---|"]
    units = {"laser": ("cells crossed", work["cells crossed"]), "fold_scan": ("cells crossed", work["cells crossed"]),
             "cameras": ("signs tested", work["signs tested"]), "visit": ("cells reached", work["cells reached"])}
    for k in PARTS:
        what, amount = units[k]
        per = f"{med[k] / amount * 1e9:.1f} per {what.replace('cells', 'cell').replace('signs', 'sign')}" if amount else "-"
        lines.append(f"| {k} | {med[k] / n * 1e6:.1f} | {med[k] / total:.0%} | {amount / n:.0f} {what} | {per} |")
    lines.append(f"| all | {total / n * 1e6:.1f} | 100% | | |")
    lines += ["", f"- beams per frame {work['beams'] / n:.0f}; cells crossed per beam {work['cells crossed'] / work['beams']:.1f}; "
              f"free cells changed per frame {work['free changed'] / n:.1f}; signs read per frame {work['signs read'] / n:.2f}; cells newly visited per frame {work['cells visited'] / n:.1f}",
              f"- calling a compiled kernel with no work: {call * 1e6:.2f} us; a frame makes at least 6 such calls "
              f"(cast, HIMM, fold, facing, visit's two reaches): {6 * call / (total / n):.0%} of a frame",
              f"- the laser's traversal: {per_cell * 1e9:.2f} ns per cell crossed; the HIMM update crosses the same cells again "
              f"({med['fold_scan'] / work['cells crossed'] * 1e9:.2f} ns per cell, with a write to two maps)",
              f"- a frame whose laser and HIMM update crossed the cells once, at the laser's cost per cell, would take "
              f"{(total - min(med['laser'], med['fold_scan'])) / n * 1e6:.1f} us: {min(med['laser'], med['fold_scan']) / total:.0%} less"]
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
