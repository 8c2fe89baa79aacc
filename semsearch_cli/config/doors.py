"""Door search (thesis ch. 4): the robot reads door signs until it reads the goal's number."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator

from .base import Label
from .scenario import OnMap, SignSections, register_kind


@register_kind("doors", default=True)
class DoorScenario(SignSections, OnMap):
    """A door-search scenario: a map, its door signs, a start, and the sign numbers to find."""

    section = "goals"
    needs = "door numbers under goals"

    kind: Literal["doors"] = "doors"
    goals: list[Label] = Field(min_length=1, description="the numbers (or labels, e.g. K202) of the signs to find")

    @field_validator("goals")
    @classmethod
    def _unique_goals(cls, v):
        if len(set(map(str, v))) != len(v):
            raise ValueError("goals must not repeat")
        return v
