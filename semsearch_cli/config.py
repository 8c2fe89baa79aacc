"""Scenario files: pydantic models, YAML loading and friendly errors (SPEC 1).

A scenario file describes the world (map, start, door signs), the task (goals), the planners and
the experiment. Paths inside it are relative to the file. Lengths are metres, angles degrees.
Every structural problem becomes a :class:`~semsearch_cli.errors.ScenarioError` naming the file
and the field; checks that need the map (start in a wall, goals reachable) live in
:mod:`semsearch_cli.world.scenario`.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from .errors import ScenarioError


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class MapSpec(Strict):
    image: str = Field(description="PNG: dark (<100) wall, light (>=200) free, gray between = outside")
    resolution: float = Field(0.1, gt=0.0, le=1.0, description="m/cell")
    origin: tuple[float, float] = Field((0.0, 0.0), description="world (x, y) m of the image's bottom-left corner")


class StartSpec(Strict):
    x: float
    y: float
    heading: Union[float, Literal["random"]] = Field("random", description="degrees, or random")


class DoorSpec(Strict):
    number: Union[int, str]
    x: float
    y: float
    facing: float = Field(description="degrees, the direction the sign faces")


class PlannerSpec(BaseModel):
    """``{name: ..., <parameter>: value | [values]}``; parameters are checked by the planner."""

    model_config = ConfigDict(extra="allow", frozen=True)
    name: str

    def params(self) -> dict[str, Any]:
        return dict(self.model_extra or {})


class RobotSpec(Strict):
    radius: float = Field(0.25, gt=0.0, description="m, disk robot")
    step: float = Field(0.1, gt=0.0, le=1.0, description="m travelled per simulation step")


class LaserSpec(Strict):
    fov: float = Field(180.0, gt=0.0, le=360.0, description="degrees")
    beams: int = Field(181, ge=2, le=2000)
    range: float = Field(10.0, gt=0.0, description="m")
    noise_std: float = Field(0.0, ge=0.0, description="m, Gaussian range noise")


class DoorCameraSpec(Strict):
    fov: float = Field(60.0, gt=0.0, le=180.0, description="degrees, each of the left and right cameras")
    range: float = Field(3.0, gt=0.0, description="m")
    p_read: float = Field(0.95, ge=0.0, le=1.0, description="probability a visible sign is read")
    p_misread: float = Field(0.0, ge=0.0, le=1.0, description="probability a read replaces one digit")


class BeliefSpec(Strict):
    visited_radius: float = Field(1.2, gt=0.0, description="m, kernel of the visited region")
    density_radius: float = Field(2.4, gt=0.0, description="m, uniform kernel radius r of Eq. 4.2 (Manhattan)")
    density_delta: float = Field(2.5, gt=0.0, description="m^2, delta of Eq. 4.4")
    min_reads: int = Field(3, ge=1, description="reads before a sign feeds the planner's factors")
    himm_inc: int = Field(3, ge=1, le=15)
    himm_dec: int = Field(1, ge=1, le=15)
    himm_max: int = Field(15, ge=1, le=255)
    occupied_threshold: int = Field(3, ge=1, description="certainty at or above which a seen cell is occupied")


class NavigationSpec(Strict):
    navigator: Literal["geodesic", "harmonic"] = "geodesic"
    replan_every: float = Field(1.0, gt=0.0, description="m travelled between periodic re-plans")


class ExperimentSpec(Strict):
    seeds: int = Field(10, ge=1)
    base_seed: int = Field(0, ge=0)
    max_distance: float = Field(2000.0, gt=0.0, description="m, budget per run")
    max_steps: int | None = Field(None, ge=1)
    out: str | None = Field(None, description="output folder (default results/<name>)")


NAME = r"^[A-Za-z0-9_\-]+$"


class PlaceSpec(Strict):
    name: str = Field(pattern=NAME, description="a place where objects stand, e.g. A")
    x: float
    y: float
    facing: float = Field(0.0, description="degrees, the direction the objects there face (for angle tables)")


class DetectTable(Strict):
    """Detection probability by camera-object distance and view angle (Loncomilla et al. 2018,
    Table 1): ``p[a][d]`` at ``angles[a]`` and ``distances[d]``. Distances interpolate linearly
    (clamped at the ends); the view angle (the object's facing against the direction from the object
    to the camera, 0 = seen from the front) takes the nearest tabulated angle. Without ``angles``,
    ``p`` is one row."""

    distances: list[float] = Field(min_length=1, description="m, increasing")
    angles: list[float] | None = Field(None, description="degrees")
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
    range: float | None = Field(None, gt=0.0)
    p_detect: Union[Probability, DetectTable, None] = None


class ObjectCameraSpec(Strict):
    """Forward object camera (SPEC 2): field of view and range, detection probability constant or
    a :class:`DetectTable`, with per-class overrides under ``classes``."""

    fov: float = Field(60.0, gt=0.0, le=360.0, description="degrees, centred on the heading")
    range: float = Field(3.0, gt=0.0, description="m")
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
    hour: float = Field(ge=0.0, lt=24.0)
    at: list[str] | None = Field(None, description="places holding the class at the request (ground truth); "
                                                   "default: the case's truth timeline at that hour")


class CaseSpec(Strict):
    name: str = Field(pattern=NAME)
    record: Union[str, list[str]] = Field(description="timeline names to record (one day each, in order), "
                                                      "or a detection-log CSV path")
    truth: str | None = Field(None, description="timeline giving the ground truth at request hours")
    requests: list[RequestSpec] | None = Field(None, description="default: objects.requests")


Timeline = dict[str, dict[float, Union[str, list[str], None]]]


class ObjectsSpec(Strict):
    """Object search over time (thesis ch. 5, SPEC 6)."""

    places: list[PlaceSpec] = Field(min_length=1)
    fixed: dict[str, Union[str, list[str]]] = Field(default_factory=dict, description="place -> class(es) standing there all day")
    route: list[str] | None = Field(None, description="patrol order of the places (default: as listed)")
    timelines: dict[str, Timeline] = Field(default_factory=dict,
                                           description="pattern -> class -> {hour: place(s) from that hour on}")
    recording_hours: list[float] = Field(default_factory=lambda: [3, 5, 7, 9, 11, 15, 17, 19, 21, 23])
    requests: list[RequestSpec] = Field(default_factory=list)
    cases: list[CaseSpec] | None = Field(None, description="default: one case per timeline, recorded from it")
    camera: ObjectCameraSpec = ObjectCameraSpec()


class Scenario(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_.\-]+$")
    map: MapSpec
    start: StartSpec
    doors: Union[str, list[DoorSpec]] = Field(default_factory=list)
    goals: list[Union[int, str]] = Field(default_factory=list)
    objects: ObjectsSpec | None = None
    planners: list[PlannerSpec] = Field(default_factory=lambda: [PlannerSpec(name="greedy")], min_length=1)
    experiment: ExperimentSpec = ExperimentSpec()
    robot: RobotSpec = RobotSpec()
    laser: LaserSpec = LaserSpec()
    door_camera: DoorCameraSpec = DoorCameraSpec()
    belief: BeliefSpec = BeliefSpec()
    navigation: NavigationSpec = NavigationSpec()

    @field_validator("goals")
    @classmethod
    def _unique_goals(cls, v):
        if len(set(map(str, v))) != len(v):
            raise ValueError("goals must not repeat")
        return v

    @model_validator(mode="after")
    def _task(self):
        if self.objects is None and not self.goals:
            raise ValueError("give door numbers under goals (door search) or an objects section (object search)")
        if self.objects is not None and self.goals:
            raise ValueError("an object-search scenario takes its goals from objects.requests; remove goals")
        return self

    @property
    def is_objects(self) -> bool:
        return self.objects is not None


_TYPE_PART = re.compile(r"^(int|str|float|bool|none|constrained-\w+|list\[.*\]|dict\[.*\]|literal\[.*\]|function-.*|[A-Z]\w*Spec|DetectTable)$")


def _loc(loc: tuple) -> str:
    """pydantic's error location as a dotted field path, without the union-branch type names."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif _TYPE_PART.match(str(part)):
            continue
        else:
            out += ("." if out else "") + str(part)
    return out


def parse_scenario(data: Any, file: str | Path) -> Scenario:
    """Validate a parsed YAML document; raise :class:`ScenarioError` on the first problem."""
    if not isinstance(data, dict):
        raise ScenarioError(str(file), "", "expected a YAML mapping (key: value) at the top level")
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        errs = exc.errors()
        err = errs[0]
        # a value matching no branch of a union gets one error per branch: report the deepest one
        # under the same field (the branch the input was meant for, e.g. a table given as a mapping)
        same = [e for e in errs if _loc(e["loc"]).startswith(_loc(err["loc"]))]
        err = max(same, key=lambda e: (len(e["loc"]), not e["type"].endswith("_type")))
        field = _loc(err["loc"])
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown key (check its spelling; `semsearch validate --help` lists the scenario format)"
        elif err["type"] == "missing":
            msg = "required field is missing"
        got = err.get("input")
        if err["type"] not in ("extra_forbidden", "missing") and not isinstance(got, (dict, list)):
            msg += f" (got {got!r})"
        raise ScenarioError(str(file), field, msg) from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario YAML file."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(str(path), "", "file not found")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ScenarioError(str(path), "", f"not valid YAML{where}: {getattr(exc, 'problem', exc)}") from None
    return parse_scenario(data, path)
