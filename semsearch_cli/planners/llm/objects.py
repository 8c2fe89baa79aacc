"""The ``llm`` planner in object search: the model names the next place to drive to and look
around at, reading what the object environment's text observation shows
(:func:`~semsearch_cli.planners.text.object_fields`): the request, the pose, and per place its
distance and bearing, whether the camera has had it in view, and the recorded log's detections of
the class there (in all, and within an hour of the request's hour).

- ``mode: actor``: the model answers a place's number; the place the robot has just looked
  around at is left out of the choices (driving there again would see nothing new);
- ``mode: estimator``: the model answers its probability that the object is at each place, and
  the planner chooses by expected cost (:mod:`.core`), ``d_i`` the straight-line distance to
  place ``i``, as the text shows it.

Its fallback, after the re-asks: the nearest place offered (straight line; ties: the lower
number). The search goes on until the object is found or the run's budget ends it: the model
cannot end it early (every object planner's list of targets may run out; a model is always asked
again).
"""

from __future__ import annotations

import math

import numpy as np

from ..objects import ObjectPlanner
from ..text import object_fields, place_history, spell
from .core import LlmCore


class ObjectLlm(LlmCore, ObjectPlanner):
    """The ``llm`` planner's object search (see the module docstring)."""

    def targets(self, ctx):
        self.begin("objects")
        names = list(ctx.places)
        history = place_history(ctx.log, ctx.cls, ctx.hour, names)
        while True:
            here = names.index(ctx.here) if ctx.here in ctx.places else None
            mask = np.ones(len(names), bool)
            if here is not None:
                mask[here] = False
            allowed = np.flatnonzero(mask)
            if allowed.size == 0:
                return
            fields = object_fields(ctx.cls, ctx.hour, (ctx.x, ctx.y, ctx.heading), ctx.distance, names, ctx.places,
                                   ctx.seen_places, history, here, mask)
            if self._live.mode == "estimator":  # the answer is probabilities, not a number (the re-ask repeats it)
                json_line = (f"Answer with one JSON object mapping place numbers ({spell(range(len(names)))}) to "
                             "probabilities from 0 to 1.")
                fields["observation"] = fields["observation"].removesuffix(fields["answer"]) + json_line
                fields["answer"] = json_line
            dist = np.array([math.hypot(x - ctx.x, y - ctx.y) for x, y in (ctx.places[n] for n in names)])
            nearest = int(allowed[np.argmin(dist[allowed])])
            pick, info = self.ask(fields, allowed, dist, nearest)
            x, y = ctx.places[names[pick]]
            yield float(x), float(y), {"kind": "llm", "place": names[pick], "llm": pick, **info}
