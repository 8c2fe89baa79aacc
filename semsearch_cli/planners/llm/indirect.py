"""The ``llm`` planner in indirect search: the model names the next pose, reading what the
indirect environment's text observation shows
(:func:`~semsearch_cli.planners.text.indirect_fields`): the goal and the time used, the pose,
the other objects detected, the five likeliest cells of the target on the robot's map, and the
choices, the poses of a lattice every ``lattice`` m over the room with 8 headings (answer ``8 k +
h``); the lattice points the robot cannot stand on are left out.

The robot's map of the target is built as ISC-PN-SM builds its (soft masks; the secondary
objects' detections and non-detections), as the environment's is by default, and the model is
asked again every ``indirect.replan_every`` seconds, on arrival, and when an object is detected.
Only ``mode: actor``: a pose is not a place a probability can be put on.

Its fallback, after the re-asks: the lattice point the robot can stand on nearest the likeliest
cell of the map, facing the heading (of the 8) nearest the bearing from the robot to that cell.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from ..indirect import Goal, IndirectPlanner, Lattice
from ..text import indirect_fields, lattice_choices
from .core import LlmCore


class IndirectLlm(LlmCore, IndirectPlanner):
    """The ``llm`` planner's indirect search (see the module docstring)."""

    masks: ClassVar[str | None] = "soft"
    negative: ClassVar[bool] = True
    uses_map: ClassVar[bool] = True
    replan_on_detection: ClassVar[bool] = True

    def plan(self, ctx):
        self.begin("indirect")
        lat = Lattice.over(ctx.frame, ctx.stand, ctx.room_size, self._live.lattice)
        p = ctx.belief.inside()  # as the environment shows it
        mask = lat.mask()
        fields = indirect_fields(ctx.target, ctx.room, ctx.view_scale, ctx.t, ctx.time_limit, (ctx.x, ctx.y, ctx.heading),
                                 ctx.seen, p, ctx.frame, lattice_choices(len(lat.xs), len(lat.ys), lat.step, ctx.horizon),
                                 mask)
        pick, info = self.ask(fields, np.flatnonzero(mask), None, fallback(lat, p, ctx))
        x, y, heading = lat.pose(pick)
        return Goal(x, y, heading, {"llm": pick, **info})


def fallback(lat: Lattice, p: np.ndarray, ctx) -> int:
    """The fallback pose (see the module docstring), as an action ``8 k + h``."""
    if not lat.standable.any():
        return 0
    r, c = np.unravel_index(int(np.argmax(p)), p.shape)
    cx, cy = ctx.frame.to_world(r, c)
    d = np.hypot(lat.points[:, 0] - cx, lat.points[:, 1] - cy)
    d[~lat.standable] = np.inf
    k = int(np.argmin(d))
    h = int(round(math.degrees(math.atan2(float(cy) - ctx.y, float(cx) - ctx.x)) / 45.0)) % 8
    return 8 * k + h
