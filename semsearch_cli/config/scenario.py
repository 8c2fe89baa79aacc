"""The scenario file: one model over the shared sections and each kind's own, YAML loading, and
errors that name the file and the field (SPEC 1). Checks that need the map (start in a wall, goals
reachable) belong to the world and the tasks.

The kind of search is ``kind:`` when given, else the section present: ``objects`` (object search),
``chains`` (chained searches), ``indirect`` (indirect search in rooms), otherwise ``goals`` (door
search). Indirect search brings its own rooms, so it takes no ``map`` or ``start``; the others
need both.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Literal, Union

import yaml
from pydantic import Field, ValidationError, field_validator, model_validator

from ..errors import ScenarioError
from ..files import read_user_text
from .base import (BeliefSpec, DoorCameraSpec, DoorSpec, EpisodesSpec, ExperimentSpec, Label, LaserSpec, MapSpec, NavigationSpec,
                   PlannerSpec, RobotSpec, StartSpec, Strict)
from .chain import ChainSpec
from .indirect import IndirectSpec
from .objects import ObjectsSpec, DetectTable  # noqa: F401  (DetectTable names a union branch in errors)

KINDS = ("doors", "objects", "chain", "indirect")
# the section each kind needs: (field, what to write when it is missing)
NEEDS = {"doors": ("goals", "door numbers under goals"), "objects": ("objects", "an objects section"),
         "chain": ("chains", "a chains section"), "indirect": ("indirect", "an indirect section")}
# the sections a kind takes from others
USES = {"doors": {"goals"}, "objects": {"objects"}, "chain": {"chains", "objects"}, "indirect": {"indirect"}}
ROOMS_OF_THEIR_OWN = {"indirect"}  # kinds that bring their own rooms instead of map and start


class Scenario(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_\-][A-Za-z0-9_.\-]*$", max_length=200,
                      description="letters, digits, _ - . (not first): it names the output folder")
    map: MapSpec | None = None
    start: StartSpec | None = None
    doors: Union[str, list[DoorSpec]] = Field(default_factory=list)
    goals: list[Label] = Field(default_factory=list)
    objects: ObjectsSpec | None = None
    chains: list[ChainSpec] | None = Field(None, description="chained searches (thesis ch. 6)")
    indirect: IndirectSpec | None = Field(None, description="indirect search with secondary objects (Loncomilla et al. 2018)")
    kind: Literal["doors", "objects", "chain", "indirect"] | None = Field(None, description="default: from the sections given")
    duplicates: Literal["error", "keep-first", "any"] = Field(
        "error", description="signs sharing a number: refuse them, keep the first of each, or accept any as the goal")
    planners: list[PlannerSpec] = Field(default_factory=lambda: [PlannerSpec(name="greedy")], min_length=1)
    episodes: EpisodesSpec | None = Field(None, description="start/goal problems (default: one per goal, from start)")
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
        kind = self.search_kind
        field, what = NEEDS[kind]
        if not getattr(self, field):
            raise ValueError(f"give {what} (door search: goals; object search: objects; chains: chains; "
                             "indirect search: indirect)")
        extra = [f for f in ("goals", "objects", "chains", "indirect") if getattr(self, f) and f not in USES[kind]]
        if kind in ROOMS_OF_THEIR_OWN:
            extra += [f for f in ("map", "start") if getattr(self, f) is not None]
        else:
            missing = [f for f in ("map", "start") if getattr(self, f) is None]
            if missing:
                raise ValueError(f"a {kind} scenario needs {' and '.join(missing)}")
        if extra:
            raise ValueError(f"a {kind} scenario does not take {' or '.join(extra)}; remove it")
        return self

    @property
    def search_kind(self) -> str:
        """doors, objects or chain: ``kind`` when given, else the section present."""
        if self.kind is not None:
            return self.kind
        if self.chains:
            return "chain"
        if self.indirect is not None:
            return "indirect"
        return "objects" if self.objects is not None else "doors"


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


def read_yaml(path: str | Path, what: str = "file", owner: str | None = None, field: str = "") -> Any:
    """A YAML file's contents; a file that is missing, not a file, not UTF-8 text (see
    :func:`~semsearch_cli.files.read_user_text`) or not YAML is a :class:`ScenarioError` naming the
    file (or ``owner`` and ``field``, the scenario that named it) and the line. Only plain YAML
    is read (``yaml.safe_load``: a ``!!python`` tag is refused, never executed)."""
    path = Path(path)
    text = read_user_text(path, what, owner, field)
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ScenarioError(str(path), "", f"not valid YAML{where}: {getattr(exc, 'problem', None) or exc}") from None
    except RecursionError:
        raise ScenarioError(str(path), "", "nested too deeply to be a scenario (brackets or indents inside one another "
                            "hundreds of times)") from None


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario YAML file."""
    return parse_scenario(read_yaml(path), path)


def with_param(data: dict, param: str, value: Any, file: str | Path) -> dict:
    """A copy of the scenario document ``data`` with one parameter set, for sweeps.

    ``param`` is a dotted path: a section and its field (``door_camera.p_misread``,
    ``belief.density_delta``, ``experiment.max_distance``), or a planner name and one of its
    parameters (``nsos.alpha``: set on every entry of that planner). The result is validated by
    the caller (:func:`parse_scenario`), so a bad value is reported like one in the file.
    """
    keys = [k for k in param.split(".")]
    if not data or not isinstance(data, dict) or len(keys) < 2 or any(not k for k in keys):
        raise ScenarioError("<command line>", "--param", f"expected SECTION.FIELD=VALUES (e.g. door_camera.p_misread=0,0.05), got {param!r}")
    out = yaml.safe_load(yaml.safe_dump(data))  # a deep copy of plain YAML data
    planners = [p for p in out.get("planners") or [] if isinstance(p, dict) and p.get("name") == keys[0]]
    if planners:
        for p in planners:
            _set(p, keys[1:], value)
        return out
    if keys[0] not in Scenario.model_fields or keys[0] in ("name", "planners"):
        names = sorted({p.get("name") for p in out.get("planners") or [] if isinstance(p, dict)} - {None})
        raise ScenarioError("<command line>", "--param", f"{keys[0]!r} is neither a section of {file} nor one of its planners "
                            f"({', '.join(names)}); sections: {', '.join(k for k in Scenario.model_fields if k not in ('name', 'planners'))}")
    _set(out, keys, value)
    return out


def _set(d: dict, keys: list[str], value: Any) -> None:
    for k in keys[:-1]:
        if not isinstance(d.get(k), dict):
            d[k] = {}
        d = d[k]
    d[keys[-1]] = value
