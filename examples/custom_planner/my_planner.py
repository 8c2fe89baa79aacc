"""A planner of your own, outside semsearch: keep going straight.

Of the frontier candidates, take the one that costs least in straight-line distance plus
``turn_weight`` metres per radian of turning away from the robot's heading. Register it with
``@register_planner`` and name this file in a scenario: ``{name: straight_on, module: my_planner.py}``.
"""

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from semsearch_cli.planners import Decision, DoorPlanner, register_planner


class StraightOnParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    turn_weight: float = Field(2.0, ge=0.0, description="m of detour worth one radian of turning")


@register_planner("straight_on")
class StraightOn(DoorPlanner):
    Params = StraightOnParams

    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None  # no frontier: the robot goes to look at walls it has not read yet
        x, y = ctx.belief.frame.to_world(cands.rows, cands.cols)
        dist = np.hypot(x - ctx.x, y - ctx.y)
        turn = np.abs((np.arctan2(y - ctx.y, x - ctx.x) - ctx.heading + np.pi) % (2 * np.pi) - np.pi)
        cost = dist + self.params.turn_weight * turn
        k = int(np.argmin(cost))
        return Decision(int(cands.rows[k]), int(cands.cols[k]), {"cost": round(float(cost[k]), 3)})
