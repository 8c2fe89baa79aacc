"""The ``chains`` section: chained searches (thesis ch. 6). A chain is an ordered list of
stages; each stage finds a door sign and, when it names an object class and an hour, then finds
that object in the room behind the door."""

from __future__ import annotations

from typing import Literal, Union

from pydantic import Field, model_validator

from .base import Label, Strict
from .objects import ObjectsSpec
from .scenario import OnMap, SignSections, register_kind

NAME = r"^[A-Za-z0-9_\-]+$"


class StageSpec(Strict):
    door: Label = Field(description="number of the door sign to find")
    object: str | None = Field(None, pattern=NAME, description="object class to find in the room behind the door")
    hour: float | None = Field(None, ge=0.0, lt=24.0, description="hour of the object request")

    @model_validator(mode="after")
    def _object_hour(self):
        if (self.object is None) != (self.hour is None):
            raise ValueError("an object stage gives both object and hour")
        return self


class ChainSpec(Strict):
    name: str = Field(pattern=NAME)
    stages: list[StageSpec] = Field(min_length=1)
    record: Union[str, list[str], None] = Field(None, description="timelines recorded for the object stages' log "
                                                                  "(one day each), or a detection-log CSV")
    truth: str | None = Field(None, description="timeline giving where the objects are at the stages' hours")
    object_planner: str = Field("lsos", pattern=NAME, description="how an object stage searches its room: a registered "
                                "object-search planner (lsos, brute_force, last_seen)")


@register_kind("chain")
class ChainScenario(SignSections, OnMap):
    """Chained searches (thesis ch. 6): door signs, then objects in the rooms behind them."""

    section = "chains"
    needs = "a chains section"

    kind: Literal["chain"] = "chain"
    chains: list[ChainSpec] = Field(min_length=1, description="chained searches (thesis ch. 6)")
    objects: ObjectsSpec | None = Field(None, description="the places and timelines of the object stages")
