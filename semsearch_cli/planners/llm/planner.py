"""``llm``: a language model as a planner, on any OpenAI-compatible endpoint, in every kind of
search: door search (:mod:`.doors`), object search (:mod:`.objects`) and indirect search
(:mod:`.indirect`), on the kind-neutral core (:mod:`.core`)."""

from __future__ import annotations

from ..base import register_planner
from .doors import DoorLlm
from .indirect import IndirectLlm
from .objects import ObjectLlm

RUN_ATTRIBUTES = {"doors": ("replan_on_signs",), "objects": (),
                  "indirect": ("masks", "negative", "uses_map", "replan_on_detection")}


@register_planner("llm")
class LlmPlanner(DoorLlm, ObjectLlm, IndirectLlm):
    """A language model on an OpenAI-compatible endpoint chooses where to search next (actor), or
    estimates where the goal lies and the planner chooses by expected cost (estimator); door,
    object and indirect search."""

    task = "doors"
    kinds = ("doors", "objects", "indirect")
    rank = 60
    run_attributes = RUN_ATTRIBUTES["doors"]

    def begin(self, kind: str) -> None:
        super().begin(kind)
        self.run_attributes = RUN_ATTRIBUTES[kind]  # what shapes this kind's runs besides the choices

    def start_run(self, run: dict) -> None:
        super().start_run(run)
        if self.kind:
            self.run_attributes = RUN_ATTRIBUTES[self.kind]
