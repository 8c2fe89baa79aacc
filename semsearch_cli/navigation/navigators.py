"""Navigators: from the robot cell to a chosen target cell, a path of cells.

``geodesic`` (default): the cheapest path under the belief's skeleton-following cost.
``harmonic``: gradient ascent of the harmonic attraction (the thesis' BVP) solved in a window around
the robot. The attraction decays exponentially along corridors (by about exp(-pi d / w) over a
distance d in a corridor of width w), so beyond ~20 m in a 2 m corridor it falls below double
precision; like the seeds' local BVP, the navigator therefore aims at the target when it is within
``LOOKAHEAD_M`` along the geodesic path, and otherwise at the point of that path ``LOOKAHEAD_M``
ahead (the robot re-plans long before it gets there). Where the ascent still stalls it follows the
geodesic path and counts a fallback.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from ..kernels.harmonic import ascend, harmonic_field
from ..registry import Registry

HARMONIC_MARGIN_M = 3.0
LOOKAHEAD_M = 8.0


class Navigator:
    """Base class: :meth:`plan` drives from the robot cell to a target cell."""

    name: ClassVar[str] = ""

    def plan(self, belief, r: int, c: int, tr: int, tc: int):  # pragma: no cover
        """Cells (rows, cols) from (r, c) to (tr, tc), or None when unreachable."""
        raise NotImplementedError


NAVIGATORS = Registry("navigator", Navigator, names=True)


def register_navigator(name: str):
    """Class decorator adding a :class:`Navigator` subclass under ``name`` (once per name)."""
    return NAVIGATORS.register(name)


@register_navigator("geodesic")
class GeodesicNavigator(Navigator):
    def plan(self, belief, r: int, c: int, tr: int, tc: int):
        """Cells (rows, cols) from (r, c) to (tr, tc), or None when unreachable."""
        return belief.path(r, c, tr, tc)


@register_navigator("harmonic")
class HarmonicNavigator(Navigator):

    def __init__(self):
        self.fallbacks = 0

    def plan(self, belief, r: int, c: int, tr: int, tc: int):
        geo = belief.path(r, c, tr, tc)
        if geo is None:
            return None
        gr, gc = geo
        along = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(gr), np.diff(gc)))]) * belief.frame.res
        k = int(np.searchsorted(along, LOOKAHEAD_M))
        if k < len(gr):
            tr, tc = int(gr[k]), int(gc[k])
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
            return geo
        return rows + r0, cols + c0
