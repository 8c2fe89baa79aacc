"""Paths on a known map: the ground truth as a complete recorded map (object search, thesis ch. 5)."""

from __future__ import annotations

import numpy as np

from ..kernels.grid import GridSearch


class KnownMap:
    """Planning on the recorded (complete) map: cells where the robot fits, reachable from the
    start, with a cost that keeps paths off the walls (1 in the open, up to 3 against a wall)."""

    def __init__(self, world):
        self.world = world
        self.passable = world.reach
        clear = np.minimum(world.clearance, 1.0)
        self.cost = (3.0 - 2.0 * clear).astype(np.float32)
        self.search = GridSearch(self.passable.shape)
        self._paths: dict = {}  # (r, c, tr, tc) -> cells: patrol legs repeat across hours and runs

    def snap(self, r: int, c: int) -> tuple[int, int]:
        """The reachable cell nearest to (r, c)."""
        H, W = self.passable.shape
        for R in (4, 16, 64, max(H, W)):
            r0, r1, c0, c1 = max(0, r - R), min(H, r + R + 1), max(0, c - R), min(W, c + R + 1)
            rr, cc = np.nonzero(self.passable[r0:r1, c0:c1])
            if rr.size:
                k = int(np.argmin((rr + r0 - r) ** 2 + (cc + c0 - c) ** 2))
                return int(rr[k] + r0), int(cc[k] + c0)
        raise ValueError("no reachable cell")

    def path(self, r: int, c: int, tr: int, tc: int):
        """Cells from (r, c) to (tr, tc) (both reachable), or None."""
        if not self.passable[r, c]:
            r, c = self.snap(r, c)
        key = (r, c, tr, tc)
        if key not in self._paths:
            if len(self._paths) > 4096:
                self._paths.clear()
            ok = self.search.run(self.passable, self.cost, r, c, np.array([tr]), np.array([tc]), 1) >= 1
            self._paths[key] = self.search.path(tr, tc) if ok else None
        return self._paths[key]

    def path_to(self, x: float, y: float, tx: float, ty: float):
        """Cells from the cell of (x, y) to the reachable cell nearest (tx, ty), or None."""
        fr = self.world.frame
        r, c = (int(v) for v in fr.to_index(x, y))
        tr, tc = self.snap(*(int(v) for v in fr.to_index(tx, ty)))
        return self.path(r, c, tr, tc)
