"""Navigators (SPEC 5): from the robot cell to a chosen target cell, a path of cells.

``geodesic`` (default): the cheapest path under the belief's skeleton-following cost.
``harmonic``: gradient ascent of the harmonic attraction toward the target, solved in a window
around robot and target; falls back to the geodesic path where the field is numerically flat.
"""

from __future__ import annotations

import numpy as np

from .harmonic import ascend, harmonic_field

HARMONIC_MARGIN_M = 5.0


class GeodesicNavigator:
    name = "geodesic"

    def plan(self, belief, r: int, c: int, tr: int, tc: int):
        """Cells (rows, cols) from (r, c) to (tr, tc), or None when unreachable."""
        return belief.path(r, c, tr, tc)


class HarmonicNavigator:
    name = "harmonic"

    def __init__(self):
        self.fallback = GeodesicNavigator()
        self.fallbacks = 0

    def plan(self, belief, r: int, c: int, tr: int, tc: int):
        H, W = belief.free.shape
        m = int(HARMONIC_MARGIN_M / belief.frame.res)
        r0, r1 = max(0, min(r, tr) - m), min(H, max(r, tr) + m + 1)
        c0, c1 = max(0, min(c, tc) - m), min(W, max(c, tc) + m + 1)
        passable = belief.passable[r0:r1, c0:c1].copy()
        passable[r - r0, c - c0] = True
        goals = np.zeros_like(passable)
        goals[tr - r0, tc - c0] = True
        u = harmonic_field(passable, goals)
        rows, cols, ok = ascend(u, r - r0, c - c0, 4 * (r1 - r0 + c1 - c0))
        if not ok:
            self.fallbacks += 1
            return self.fallback.plan(belief, r, c, tr, tc)
        return rows + r0, cols + c0


NAVIGATORS = {"geodesic": GeodesicNavigator, "harmonic": HarmonicNavigator}
