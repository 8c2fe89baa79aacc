"""The scenario file: the sections every kind of search shares, the registry of kinds, YAML
loading, and errors that name the file and the field. Checks that need the map (start in a wall,
goals reachable) belong to the world and the tasks.

Each kind of search declares its scenario model in its own module of this package, a subclass of
:class:`Scenario` (or :class:`OnMap`) registered with :func:`register_kind`, which names the
section that makes a document that kind. A document is of the kind ``kind:`` names, else of the
kind whose section it has (a kind whose model also takes the other sections present wins, as
chains do with ``objects``), else of the default kind. The scenario format is the union of the
registered models, discriminated on ``kind`` (:func:`scenario_schema`).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal, Union, get_args

import yaml
from pydantic import BaseModel, Field, PrivateAttr, Tag, TypeAdapter, ValidationError

from .. import deprecation
from ..errors import ScenarioError, did_you_mean
from ..files import read_user_text
from ..plugins import load_kinds
from ..registry import Registry
from .base import (BeliefSpec, DoorCameraSpec, DoorSpec, EpisodesSpec, ExperimentSpec, LaserSpec, MapSpec, NavigationSpec,
                   PlannerSpec, RobotSpec, StartSpec, Strict)

class Scenario(Strict):
    """The sections every kind of search takes: ``kind``, ``name``, ``planners``, ``episodes``
    and ``experiment``. A kind's model adds its own section (named by ``section``), the shared
    sections it takes (:class:`OnMap`: ``map``, ``start``, ``robot``; :class:`SignSections`: the
    door signs, their sensors, belief and navigation), and sets ``kind`` to a one-value Literal
    with that value as its default. A section the kind does not take is refused, naming it.

    ``retired``: sections the kind's model took in 0.2.0 without using them; given, each is
    ignored with a DeprecationWarning (refused from 0.4.0), and counted in the fingerprint as 0.2.0
    counted it (a results folder of 0.2.0 resumes)."""

    section: ClassVar[str] = ""  # the field whose presence makes a document this kind
    needs: ClassVar[str] = ""  # what to write when that section is missing, e.g. "door numbers under goals"
    retired: ClassVar[tuple[str, ...]] = ()

    kind: str
    name: str = Field(pattern=r"^[A-Za-z0-9_\-][A-Za-z0-9_.\-]*$", max_length=200,
                      description="letters, digits, _ - . (not first): it names the output folder")
    planners: list[PlannerSpec] = Field(default_factory=lambda: [PlannerSpec(name="greedy")], min_length=1)
    episodes: EpisodesSpec | None = Field(None, description="start/goal problems (default: one per goal, from start)")
    experiment: ExperimentSpec = ExperimentSpec()
    _retired: dict = PrivateAttr(default_factory=dict)  # the retired sections as 0.2.0 read them (the fingerprint's)


class OnMap(Scenario):
    """A kind searched on a map of the scenario's own, from a start pose, by a robot of a radius
    that moves a step at a time."""

    map: MapSpec = Field(description="the occupancy map: an image with its resolution and origin, or a ROS map_server YAML")
    start: StartSpec = Field(description="where the robot starts (m, degrees)")
    robot: RobotSpec = RobotSpec()


class SignSections(Strict):
    """The sections of a kind that reads door signs: the signs, the laser and door cameras that
    build its map, the belief and the navigation (door search and chains)."""

    doors: Union[str, list[DoorSpec]] = Field(default_factory=list, description="the door signs: a CSV file (number, x, y, facing) or a list")
    duplicates: Literal["error", "keep-first", "any"] = Field(
        "error", description="signs sharing a number: refuse them, keep the first of each, or accept any as the goal")
    laser: LaserSpec = LaserSpec()
    door_camera: DoorCameraSpec = DoorCameraSpec()
    belief: BeliefSpec = BeliefSpec()
    navigation: NavigationSpec = NavigationSpec()


class _Retired(Strict):
    """Every section some kind has retired, as 0.2.0's common model read it."""

    doors: Union[str, list[DoorSpec]] = Field(default_factory=list)
    duplicates: Literal["error", "keep-first", "any"] = "error"
    robot: RobotSpec = RobotSpec()
    laser: LaserSpec = LaserSpec()
    door_camera: DoorCameraSpec = DoorCameraSpec()
    belief: BeliefSpec = BeliefSpec()
    navigation: NavigationSpec = NavigationSpec()


SIGN_SECTIONS = tuple(SignSections.model_fields)  # retired by the kinds that read no signs


def _retire(model: type[Scenario], data: dict, file) -> tuple[dict, dict]:
    """``data`` without the sections ``model`` has retired (each given one warned about), and
    those sections as 0.2.0 read them (defaults for the ones not given)."""
    names = [k for k in model.retired if k not in model.model_fields]
    given = {k: data[k] for k in names if k in data}
    if not names:
        return data, {}
    for k in given:
        deprecation.warn(f"the {k} section of a scenario of kind {model.model_fields['kind'].default} ({file}), which that "
                         "kind never used,", "remove it (it is ignored)", since="0.3.0", until="0.4.0", stacklevel=5)
    try:
        old = _Retired.model_validate(given).model_dump(mode="json")
    except ValidationError:  # a value 0.2.0 would have refused: the section is ignored all the same
        old = _Retired().model_dump(mode="json") | {k: None for k in given}
    return {k: v for k, v in data.items() if k not in given}, {k: old[k] for k in names}


KINDS = Registry("scenario kind", Scenario)  # kind -> its scenario model, in registration order
_DEFAULT: list[str] = []


def register_kind(kind: str, default: bool = False):
    """Class decorator: ``cls`` (a :class:`Scenario` subclass whose ``kind`` is ``Literal[kind]``)
    is the scenario model of ``kind``; with ``default``, documents that name no kind and have no
    kind's section are of this kind. A kind is registered once."""

    def deco(cls):
        if isinstance(cls, type) and issubclass(cls, Scenario) and (not cls.section or cls.section not in cls.model_fields):
            raise TypeError(f"scenario kind {kind!r}: {cls.__name__}.section must name one of its fields")
        KINDS.add(kind, cls)
        if default:
            _DEFAULT[:] = [kind]
        global _ADAPTER
        _ADAPTER = None
        return cls

    return deco


def _sections() -> dict[str, str]:
    return {cls.section: kind for kind, cls in KINDS.items()}


def kind_of(data: dict) -> str | None:
    """The kind a scenario document is of (see the module's docstring); None for ``kind:`` naming
    no registered kind. The kinds of installed packages are registered first (:mod:`~semsearch_cli.plugins`)."""
    load_kinds()
    given = data.get("kind")
    if given is not None:
        return given if isinstance(given, str) and given in KINDS else None
    present = [k for s, k in _sections().items() if data.get(s) not in (None, [], {})]
    if not present:
        return _DEFAULT[0] if _DEFAULT else next(iter(KINDS))
    taken = [k for k in present if all(KINDS[o].section in KINDS[k].model_fields for o in present)]
    return (taken or present)[0]


def all_fields(built_in: bool = False) -> set[str]:
    """Every top-level field of every kind's model (``built_in``: of semsearch's own kinds only)."""
    return {f for cls in KINDS.values() if not built_in or cls.__module__.startswith("semsearch_cli.") for f in cls.model_fields}


_ADAPTER: TypeAdapter | None = None


def scenario_schema() -> dict:
    """The JSON Schema of a scenario file: one branch per kind, each with ``kind`` a constant."""
    global _ADAPTER
    if _ADAPTER is None:
        union = Union[tuple(Annotated[cls, Tag(k)] for k, cls in KINDS.items())]  # noqa: UP007
        _ADAPTER = TypeAdapter(union)
    schema = _ADAPTER.json_schema()
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": "semsearch scenario",
            "description": "A scenario file: one kind of search (" + ", ".join(KINDS) + "), named by kind or by its section.",
            **schema}


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


def _keys_at(model: type[BaseModel], loc: tuple) -> list[str]:
    """The keys a model takes at pydantic's error location ``loc`` (the mapping that holds the
    unknown key), following nested models through lists and optional or union fields; ``[]``
    where the walk cannot tell."""
    here: Any = model
    for part in loc:
        if isinstance(part, int) or _TYPE_PART.match(str(part)):
            continue
        fields = getattr(here, "model_fields", None)
        if not fields or part not in fields:
            return []
        here = _model_in(fields[part].annotation)
        if here is None:
            return []
    fields = getattr(here, "model_fields", None)
    return sorted(f.alias or k for k, f in fields.items()) if fields else []


def _model_in(annotation) -> type[BaseModel] | None:
    """The pydantic model an annotation holds (``X``, ``X | None``, ``list[X]``), or None."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    models = [m for a in get_args(annotation) if (m := _model_in(a)) is not None]
    return models[0] if len(models) == 1 else None


def parse_scenario(data: Any, file: str | Path) -> Scenario:
    """Validate a parsed YAML document; raise :class:`ScenarioError` on the first problem."""
    if not isinstance(data, dict):
        raise ScenarioError(str(file), "", "expected a YAML mapping (key: value) at the top level")
    kind = kind_of(data)
    if kind is None:
        raise ScenarioError(str(file), "kind", f"unknown kind {data.get('kind')!r}; known: {', '.join(KINDS)}")
    model = KINDS[kind]
    data, retired = _retire(model, data, file)
    try:
        sc = model.model_validate(data)
        sc._retired = retired
        return sc
    except ValidationError as exc:
        errs = exc.errors()
        err = errs[0]
        # a value matching no branch of a union gets one error per branch: report the deepest one
        # under the same field (the branch the input was meant for, e.g. a table given as a mapping)
        same = [e for e in errs if _loc(e["loc"]).startswith(_loc(err["loc"]))]
        err = max(same, key=lambda e: (len(e["loc"]), not e["type"].endswith("_type")))
        field = _loc(err["loc"])
        msg = err["msg"].removeprefix("Value error, ")
        if err["type"] == "extra_forbidden" and len(err["loc"]) == 1 and field in all_fields():
            raise ScenarioError(str(file), field, f"a {kind} scenario does not take {field}; remove it") from None
        if err["type"] == "missing" and field == model.section:
            raise ScenarioError(str(file), field, f"give {model.needs} ("
                                + "; ".join(f"{k}: {c.section}" for k, c in KINDS.items()) + ")") from None
        if err["type"] == "extra_forbidden":
            valid = _keys_at(model, err["loc"][:-1])
            bad = str(err["loc"][-1])
            msg = (f"unknown key {bad!r}{did_you_mean(bad, valid)}" + (f"; valid keys here: {', '.join(valid)}" if valid else "")
                   + " (`semsearch schema` writes the scenario format)")
        elif err["type"] == "missing":
            msg = "required field is missing"
        got = err.get("input")
        if err["type"] not in ("extra_forbidden", "missing") and not isinstance(got, (dict, list)):
            msg += f" (got {got!r})"
        raise ScenarioError(str(file), field, msg) from None


class ScenarioLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` whose plain numbers are the ones a reader sees: YAML 1.1's decimal
    integers and floats (``1.5``, ``1.0e+3``, ``.5``; ``1e3`` stays text, as before), ``0x``
    integers and ``.inf``/``.nan`` (refused by the models). Its other numbers are text: ``1_5``
    (15 with the underscore dropped), ``1:30`` (sexagesimal 90), ``010`` (octal 8) and ``0b11``, so
    a mistyped number is an error naming its field, never another number. Everything else
    ``yaml.safe_dump`` writes reads back as it was."""


ScenarioLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag not in ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
ScenarioLoader.add_implicit_resolver(
    "tag:yaml.org,2002:int", re.compile(r"^(?:[-+]?(?:0|[1-9][0-9]*)|[-+]?0x[0-9a-fA-F]+)$"), list("-+0123456789"))
ScenarioLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^(?:(?:[-+]?[0-9]+\.[0-9]*|\.[0-9]+)(?:[eE][-+][0-9]+)?|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
    list("-+0123456789."))


def _construct_int(loader, node):
    text = loader.construct_scalar(node)
    if len(text) > 64:  # no number of a scenario has so many digits: text, which its field refuses naming its bound
        return text
    return int(text, 16) if "x" in text else int(text)


ScenarioLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)


def load_yaml_text(text: str) -> Any:
    """Plain YAML data of ``text`` (:class:`ScenarioLoader`: numbers as written, no Python tags)."""
    return yaml.load(text, Loader=ScenarioLoader)  # noqa: S506 (a SafeLoader subclass)


def read_yaml(path: str | Path, what: str = "file", owner: str | None = None, field: str = "") -> Any:
    """A YAML file's contents; a file that is missing, not a file, not UTF-8 text (see
    :func:`~semsearch_cli.files.read_user_text`) or not YAML is a :class:`ScenarioError` naming the
    file (or ``owner`` and ``field``, the scenario that named it) and the line. Only plain YAML
    is read (:class:`ScenarioLoader`, a ``yaml.SafeLoader``: a ``!!python`` tag is refused, never
    executed; ``1_5`` is text, not 15)."""
    path = Path(path)
    text = read_user_text(path, what, owner, field)
    try:
        return load_yaml_text(text)
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
    fields = KINDS[kind_of(out) or next(iter(KINDS))].model_fields
    if keys[0] not in fields or keys[0] in ("name", "planners", "kind"):
        names = sorted({p.get("name") for p in out.get("planners") or [] if isinstance(p, dict)} - {None})
        raise ScenarioError("<command line>", "--param", f"{keys[0]!r} is neither a section of {file} nor one of its planners "
                            f"({', '.join(names)}); sections: {', '.join(k for k in fields if k not in ('name', 'planners', 'kind'))}")
    _set(out, keys, value)
    return out


def _set(d: dict, keys: list[str], value: Any) -> None:
    for k in keys[:-1]:
        if not isinstance(d.get(k), dict):
            d[k] = {}
        d = d[k]
    d[keys[-1]] = value
