"""Engine 2's skeleton against engine 1's, on the changes of a real run: the belief's free map at
every refresh of an nsos run on the authors' Hotel map (read from ../shared, never copied), goal
148, seed 0, replayed into (a) scikit-image's thinning of the changed box and 4 m around it (what
engine 1 does at each refresh) and (b) the kept thinning of the whole map (semsearch_cli.kernels.
skeleton), timed in the same run (median over repeats of the per-refresh mean), and (b) checked
against the thinning of the whole last map from scratch.

Usage:
  python benchmarks/skeleton.py [--repeats 5] [--md FILE]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from output import emit
from refmaps import hotel
from skimage.morphology import skeletonize

from semsearch_cli.belief import doors as belief_doors
from semsearch_cli.kernels.skeleton import Skeleton, deletion_table
from semsearch_cli.planners import Variant
from semsearch_cli.runner import Loaded

ENGINE1_MARGIN_M = 4.0  # engine 1 thinned the changed box and this much around it (semsearch 0.2)


def record(loaded: Loaded, variant: Variant, goal: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(dirty box, free map) at every refresh of the belief's derived maps in one run."""
    out = []
    refresh = belief_doors.DoorBelief.refresh_derived

    def spy(self):
        if self.dirty[1] >= self.dirty[0]:
            out.append((self.dirty.copy(), self.free.copy()))
        return refresh(self)

    belief_doors.DoorBelief.refresh_derived = spy
    try:
        loaded.task.run(variant, goal, 0)
    finally:
        belief_doors.DoorBelief.refresh_derived = refresh
    return out


def thin_whole(free: np.ndarray) -> np.ndarray:
    """Zhang and Suen's thinning of the whole map from scratch (the tables of the kernel)."""
    tables = [deletion_table(False), deletion_table(True)]
    img = np.pad(free.astype(np.uint8), 1)
    weights = [(-1, 0), (-1, 1), (0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1)]
    s, quiet = 0, 0
    while quiet < 2:
        code = np.zeros(free.shape, np.int64)
        for k, (dr, dc) in enumerate(weights):
            code |= img[1 + dr:img.shape[0] - 1 + dr, 1 + dc:img.shape[1] - 1 + dc].astype(np.int64) << k
        m = (img[1:-1, 1:-1] == 1) & (tables[s % 2][code] == 1)
        img[1:-1, 1:-1][m] = 0
        s += 1
        quiet = quiet + 1 if not m.any() else 0
    return img[1:-1, 1:-1].astype(bool)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    loaded = hotel("semsearch-skeleton-")
    if loaded is None:
        return 0
    rec = record(loaded, Variant("nsos", (("alpha", 0.9),)), 148)
    H, W = rec[0][1].shape
    m = int(np.ceil(ENGINE1_MARGIN_M / loaded.world.frame.res))
    t_win, t_ours, per = [], [], []
    for _ in range(a.repeats + 1):  # the first: numba's compile and the pages' first touch, not counted
        t = time.perf_counter()
        for d, free in rec:
            skeletonize(free[max(0, d[0] - m):min(H, d[1] + m + 1), max(0, d[2] - m):min(W, d[3] + m + 1)])
        t_win.append((time.perf_counter() - t) / len(rec))
        sk = Skeleton((H, W))
        times = []
        t = time.perf_counter()
        for d, free in rec:
            t1 = time.perf_counter()
            sk.update(free, d)
            times.append(time.perf_counter() - t1)
        t_ours.append((time.perf_counter() - t) / len(rec))
        per = times
    t_win, t_ours = np.median(t_win[1:]), np.median(t_ours[1:])
    exact = np.array_equal(sk.skeleton, thin_whole(rec[-1][1]))
    per = np.array(per) * 1e3
    lines = [f"nsos[alpha=0.9], Hotel goal 148, seed 0: {len(rec)} refreshes of the derived maps; median of {a.repeats} repeats",
             "", "| skeleton | ms per refresh | ratio |", "|---|---|---|",
             f"| engine 1: scikit-image's thinning of the changed box and {ENGINE1_MARGIN_M:g} m around it | "
             f"{t_win * 1e3:.3f} | 1 |",
             f"| engine 2: the kept thinning of the whole map | {t_ours * 1e3:.3f} | {t_ours / t_win:.2f} |", "",
             f"engine 2 per refresh (last repeat): median {np.median(per):.3f} ms, 90th percentile {np.percentile(per, 90):.3f}, "
             f"max {per.max():.2f}; its skeleton equals the thinning of the whole last map from scratch: {exact}"]
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
