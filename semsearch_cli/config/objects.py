"""The ``objects`` section: places, timelines, cases and requests of object search over time
(thesis ch. 5), and the object camera."""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import ConfigDict, Field, model_validator

from .base import Label, MAX_RANGE, Angle, Coord, Strict
from .scenario import SIGN_SECTIONS, OnMap, register_kind

NAME = r"^[A-Za-z0-9_\-]+$"
Hour = Annotated[float, Field(ge=0.0, lt=24.0, description="hour of the day, 0 <= h < 24")]


class PlaceSpec(Strict):
    name: str = Field(pattern=NAME, description="a place where objects stand, e.g. A")
    x: Coord
    y: Coord
    facing: Angle = Field(0.0, description="degrees, the direction the objects there face (for angle tables)")
    room: Label | None = Field(None, description="number of the door sign of the room holding the place (chains)")


class DetectTable(Strict):
    """Detection probability by camera-object distance and view angle (Loncomilla et al. 2018,
    Table 1): ``p[a][d]`` at ``angles[a]`` and ``distances[d]``. Distances interpolate linearly
    (clamped at the ends); the view angle (the object's facing against the direction from the object
    to the camera, 0 = seen from the front) takes the nearest tabulated angle. Without ``angles``,
    ``p`` is one row."""

    distances: list[Annotated[float, Field(ge=0.0, le=MAX_RANGE)]] = Field(min_length=1, description="m, increasing")
    angles: list[Angle] | None = Field(None, description="degrees")
    p: list[list[float]] = Field(min_length=1)

    @model_validator(mode="after")
    def _shape(self):
        if any(b <= a for a, b in zip(self.distances, self.distances[1:])):
            raise ValueError("distances must increase")
        rows = len(self.angles) if self.angles else 1
        if len(self.p) != rows or any(len(r) != len(self.distances) for r in self.p):
            raise ValueError(f"p must have {rows} row(s) (one per angle) of {len(self.distances)} values (one per distance)")
        if any(not 0.0 <= v <= 1.0 for r in self.p for v in r):
            raise ValueError("probabilities must lie in [0, 1]")
        return self


Probability = Annotated[float, Field(ge=0.0, le=1.0)]


class ClassCameraSpec(Strict):
    fov: float | None = Field(None, gt=0.0, le=360.0)
    range: float | None = Field(None, gt=0.0, le=MAX_RANGE)
    p_detect: Union[Probability, DetectTable, None] = None


class ObjectCameraSpec(Strict):
    """Forward object camera: field of view and range, detection probability constant or
    a :class:`DetectTable`, with per-class overrides under ``classes``."""

    fov: float = Field(60.0, gt=0.0, le=360.0, description="degrees, centred on the heading")
    range: float = Field(3.0, gt=0.0, le=MAX_RANGE, description="m")
    p_detect: Union[Probability, DetectTable] = Field(0.9, description="probability a visible object is detected in one frame")
    classes: dict[str, ClassCameraSpec] = Field(default_factory=dict, description="class -> fov / range / p_detect")

    def for_class(self, cls: str) -> tuple[float, float, Union[float, DetectTable]]:
        """(fov, range, p_detect) for a class."""
        c = self.classes.get(cls)
        if c is None:
            return self.fov, self.range, self.p_detect
        return (c.fov if c.fov is not None else self.fov, c.range if c.range is not None else self.range,
                c.p_detect if c.p_detect is not None else self.p_detect)

    @property
    def max_range(self) -> float:
        return max([self.range] + [c.range for c in self.classes.values() if c.range is not None])

    @property
    def max_fov(self) -> float:
        return max([self.fov] + [c.fov for c in self.classes.values() if c.fov is not None])


class RequestSpec(Strict):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)
    cls: str = Field(alias="class", pattern=NAME, description="object class to find")
    hour: Hour
    at: list[str] | None = Field(None, description="places holding the class at the request (ground truth); "
                                                   "default: the case's truth timeline at that hour")


class CaseSpec(Strict):
    name: str = Field(pattern=NAME)
    record: Union[str, list[str]] = Field(description="timeline names to record (one day each, in order), "
                                                      "or a detection-log CSV path")
    truth: str | None = Field(None, description="timeline giving the ground truth at request hours")
    requests: list[RequestSpec] | None = Field(None, description="default: objects.requests")


Timeline = dict[str, dict[Hour, Union[str, list[str], None]]]


class ObjectsSpec(Strict):
    """Object search over time (thesis ch. 5)."""

    places: list[PlaceSpec] = Field(min_length=1)
    fixed: dict[str, Union[str, list[str]]] = Field(default_factory=dict, description="place -> class(es) standing there all day")
    route: list[str] | None = Field(None, min_length=1, description="patrol order of the places (default: as listed)")
    timelines: dict[str, Timeline] = Field(default_factory=dict,
                                           description="pattern -> class -> {hour: place(s) from that hour on}")
    recording_hours: list[Hour] = Field(default_factory=lambda: [3, 5, 7, 9, 11, 15, 17, 19, 21, 23])
    requests: list[RequestSpec] = Field(default_factory=list)
    cases: list[CaseSpec] | None = Field(None, description="default: one case per timeline, recorded from it")
    camera: ObjectCameraSpec = ObjectCameraSpec()




@register_kind("objects")
class ObjectScenario(OnMap):
    """An object-search scenario: places on a map, where objects stand over the day, and the
    requests (a class at an hour) to answer."""

    section = "objects"
    needs = "an objects section"
    retired = SIGN_SECTIONS  # the robot drives the recorded map with its object camera: no signs, laser or belief

    kind: Literal["objects"] = "objects"
    objects: ObjectsSpec = Field(description="places, timelines, requests and the object camera")
