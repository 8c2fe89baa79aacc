"""BVP exploration (Prestes et al. 2002; draft paper Section IV-B): frontier exploration by the
harmonic potential with every frontier cell attracting.

The attraction is solved in a square window around the robot (``window`` m half-size); the robot
climbs it to whichever frontier the field leads to. Where the window holds no frontier or the field
is numerically flat at the robot (frontiers far away), the nearest candidate along the skeleton is
taken instead, as greedy would.
"""

from __future__ import annotations

import cv2
import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ..navigation.harmonic import FLAT, ascend, harmonic_field
from .base import Decision, Planner, register_planner
from .greedy import Greedy


class BVPParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    window: float = Field(15.0, gt=1.0, description="m, half-size of the square solved around the robot")


@register_planner("bvp")
class BVP(Planner):
    Params = BVPParams

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
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
            u = harmonic_field(passable, front)
            if u[ctx.row - r0, ctx.col - c0] >= FLAT:
                rows, cols, ok = ascend(u, ctx.row - r0, ctx.col - c0, 8 * m)
                if ok:
                    return Decision(int(rows[-1] + r0), int(cols[-1] + c0), {"u_robot": float(u[ctx.row - r0, ctx.col - c0])})
        d = Greedy(self.params).choose(ctx, cands)
        if d is not None:
            d.info["fallback"] = "nearest"
        return d
