"""BVP exploration (Prestes et al. 2002; draft paper Section IV-B): frontier exploration by the
harmonic potential with every frontier cell attracting.

The attraction is solved in a square window around the robot (``window`` m half-size), on cells
``coarsen`` times the map's (a coarse cell is passable when all its fine cells are, and attracts
when any of them is a frontier cell), which keeps each solve to a few milliseconds; the robot
climbs the field to whichever frontier it leads to, and the target is the frontier cell in that
coarse cell nearest to the robot. The robot keeps that target until it is reached or stops being a
frontier cell (visited, or no longer passable): re-solving every metre and switching between the
field and the nearest-candidate fallback can otherwise trap it in a back-and-forth between two
poses where the field is near the limit of double precision. Where the window holds no frontier or the field
is numerically flat at the robot (frontiers far away), the nearest candidate along the skeleton is
taken instead, as greedy would.
"""

from __future__ import annotations

import cv2
import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...kernels.harmonic import FLAT, ascend, harmonic_field
from ..base import Decision, DoorPlanner, register_planner
from .greedy import nearest_candidate


class BVPParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    window: float = Field(15.0, gt=1.0, le=100.0, description="m, half-size of the square solved around the robot")
    coarsen: int = Field(2, ge=1, le=8, description="cells of the map per cell of the potential's grid")


@register_planner("bvp")
class BVP(DoorPlanner):
    """Frontier exploration by the harmonic potential (Prestes et al. 2002), solved in a window
    around the robot, every frontier cell attracting; the target is kept until reached or no
    longer a frontier."""

    rank = 1

    Params = BVPParams

    def __init__(self, params):
        super().__init__(params)
        self.target: tuple[int, int] | None = None

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        b = ctx.belief
        if self.target is not None:
            tr, tc = self.target
            if (tr, tc) != (ctx.row, ctx.col) and b.passable[tr, tc] and not b.visited[tr, tc]:
                return Decision(tr, tc, {"kept": True})
        d = self._choose(ctx, cands)
        self.target = None if d is None else (d.row, d.col)
        return d

    def _choose(self, ctx, cands):
        b = ctx.belief
        H, W = b.free.shape
        m = int(self.params.window / b.frame.res)
        r0, r1, c0, c1 = max(0, ctx.row - m), min(H, ctx.row + m + 1), max(0, ctx.col - m), min(W, ctx.col + m + 1)
        vis = b.visited[r0:r1, c0:c1]
        grown = cv2.dilate(vis.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
        passable = b.passable[r0:r1, c0:c1].copy()
        passable[ctx.row - r0, ctx.col - c0] = True
        front = grown & ~vis & passable
        if front.any():
            k = self.params.coarsen
            pc, fc = _pool(passable, k, np.all), _pool(front, k, np.any)
            pc |= fc
            rr, rc = (ctx.row - r0) // k, (ctx.col - c0) // k
            pc[rr, rc] = True
            u = harmonic_field(pc, fc)
            if u[rr, rc] >= FLAT:
                rows, cols, ok = ascend(u, rr, rc, 8 * m)
                if ok:
                    br, bc = int(rows[-1]) * k, int(cols[-1]) * k
                    fr, fcol = np.nonzero(front[br : br + k, bc : bc + k])
                    j = int(np.argmin((fr + br - (ctx.row - r0)) ** 2 + (fcol + bc - (ctx.col - c0)) ** 2))
                    return Decision(int(fr[j] + br + r0), int(fcol[j] + bc + c0), {"u_robot": float(u[rr, rc])})
        d = nearest_candidate(ctx, cands)
        if d is not None:
            d.info["fallback"] = "nearest"
        return d


def _pool(a: np.ndarray, k: int, how) -> np.ndarray:
    """Pool a bool grid by k x k blocks (padding with False) using ``how`` (np.all or np.any)."""
    if k == 1:
        return a.copy()
    h, w = a.shape
    p = np.zeros((-(-h // k) * k, -(-w // k) * k), bool)
    p[:h, :w] = a
    return how(p.reshape(p.shape[0] // k, k, p.shape[1] // k, k), axis=(1, 3))
