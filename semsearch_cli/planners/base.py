"""The planner interface and registry.

A planner picks the next target from the belief. It sees a :class:`DoorContext` and the frontier
:class:`~semsearch_cli.belief.Candidates`, and returns a :class:`Decision` (a target cell and the
numbers behind the choice, for traces). Adding a planner: subclass :class:`Planner`, give it a
pydantic ``Params`` model, and decorate it with ``@register_planner(name)``; nothing in the
simulator changes. The class may live in this package, in a file of the user's named by a
scenario (``{name: mine, module: my_planner.py}``), or in an installed package that declares it
under the entry-point group ``semsearch.planners``.

``decisions`` in the rows counts new targets, for every planner alike: a re-plan that returns
the cell the robot is already heading for is not a decision, whether the planner chose it again
or marked it ``info["kept"] = True``.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import itertools
import math
import re
import sys
import traceback
from dataclasses import dataclass, field
from importlib.metadata import entry_points, packages_distributions, version
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from ..belief import DoorBelief, Candidates
from .. import __version__, deprecation
from ..errors import ScenarioError, did_you_mean
from ..files import user_file
from ..provenance import code_hash, files_hash
from ..registry import Registry


class NoParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclass
class DoorContext:
    """What a door planner may look at at a re-plan: the belief, the robot's pose and history,
    the goal and the run's random generator.

    Cells are (row, col) indices of the belief's grid: row 0 is the map's top, so row grows as y
    falls; ``belief.frame`` converts (``to_world(row, col)`` -> (x, y) m of the cell centre,
    ``to_index(x, y)`` -> cell, ``res`` m per cell).

    - ``belief``: the map built so far (:class:`~semsearch_cli.belief.DoorBelief`): ``free``,
      ``seen``, ``visited``, ``passable`` (free and the robot fits), ``skeleton`` and
      ``clearance`` (m) as (H, W) arrays; ``search(row, col, rows, cols, n)`` skeleton distances
      (cells) to target cells; ``reads`` every sign read (``reads.total``: label -> count) and
      ``segment_door_lists`` the signs read per corridor segment.
    - ``row``, ``col``: the robot's cell; ``x``, ``y``: its position (m); ``heading``: radians,
      counter-clockwise from +x.
    - ``goal``: the label to find as written in the scenario (an int such as 148, or text such as
      ``K202``).
    - ``rng``: the run's NumPy generator: draw from it (never from a global one), so that a run
      repeats exactly.
    - ``headings``: the robot's heading (radians) at every pose so far.
    - ``explain``: whether the caller keeps the numbers behind each choice (``Decision.info``,
      for traces and recordings); a planner may skip tabulating them when it is False.
    """

    belief: DoorBelief
    row: int
    col: int
    x: float
    y: float
    heading: float
    goal: Any
    rng: np.random.Generator
    headings: list = field(default_factory=list)
    explain: bool = True


@dataclass
class Decision:
    """A door planner's choice: the target cell (``row``, ``col``, a free cell of the belief's
    grid) and ``info``, the numbers behind it for traces (any JSON-able values; ``"kept": True``
    marks a re-plan that keeps the previous target, which is not counted as a decision)."""

    row: int
    col: int
    info: dict = field(default_factory=dict)


class Planner:
    """What every planner is, whatever it searches for; each kind has its own protocol on top:
    :class:`DoorPlanner`, :class:`~semsearch_cli.planners.ObjectPlanner` and
    :class:`~semsearch_cli.planners.IndirectPlanner`, which set ``task``.

    Class attributes: ``Params`` (a pydantic model of the planner's parameters, checked when the
    scenario is loaded), ``task`` (the kind of search it answers), ``rank``, ``baseline``,
    ``swept`` and ``replay`` (how reports order, compare and replay it; see the attributes below).
    """

    name: ClassVar[str] = ""
    task: ClassVar[str] = ""  # which kind of scenario the planner answers (a task's planner_kind)
    Params: ClassVar[type[BaseModel]] = NoParams
    rank: ClassVar[int] = 100  # where reports list it among its kind's planners (lower first; then by name)
    baseline: ClassVar[bool] = False  # reports compare the other planners with this one, paired
    swept: ClassVar[str | None] = None  # the parameter `semsearch sweep-alpha` sweeps (and reports plot against)
    replay: ClassVar[bool] = False  # the planner a report replays by default (else the last in report order)

    def __init__(self, params: BaseModel):
        self.params = params


class DoorPlanner(Planner):
    """A door-search planner: ``choose(ctx, cands)`` gets a :class:`DoorContext` and the
    frontier :class:`~semsearch_cli.belief.Candidates` and returns a :class:`Decision`, or None
    when no candidate suits (the robot then looks at the walls it has not read yet)."""

    task: ClassVar[str] = "doors"

    def choose(self, ctx: DoorContext, cands: Candidates) -> Decision | None:  # pragma: no cover
        raise NotImplementedError


PLANNERS = Registry("planner", Planner, names=True)  # name -> class
MAX_NAME = 64  # characters in a planner's name (it names files: paths/, traces/, frames/)
PLANNER_NAME = re.compile(rf"[A-Za-z0-9][A-Za-z0-9_.+\-]{{0,{MAX_NAME - 1}}}")


def register_planner(name: str):
    """Class decorator adding a planner to the registry under ``name`` (must be new); the class
    subclasses one kind's protocol (:class:`DoorPlanner`, ``ObjectPlanner``, ``IndirectPlanner``)."""

    if not isinstance(name, str) or not PLANNER_NAME.fullmatch(name):
        raise TypeError(f"planner name {str(name)[:80]!r}: a name holds only letters, digits and . _ + - (at most "
                        f"{MAX_NAME} characters, starting with a letter or digit); [ ] = , would read as a variant's "
                        "label, such as nsos[alpha=0.9]")

    def deco(cls):
        if isinstance(cls, type) and issubclass(cls, Planner) and not cls.task:
            if not callable(getattr(cls, "choose", None)):
                raise TypeError(f"planner {name!r}: {cls.__name__} answers no kind of search; subclass DoorPlanner (door "
                                "search), ObjectPlanner or IndirectPlanner (from semsearch_cli.planners)")
            cls = _as_door_planner(cls)
        return PLANNERS.add(name, cls)

    return deco


def _as_door_planner(cls: type[Planner]) -> type[DoorPlanner]:
    """A ``Planner`` subclass with ``choose(ctx, cands)``, written against the API before 0.2.0
    (when ``Planner`` was the door planner's protocol), as a :class:`DoorPlanner`: the same class
    with DoorPlanner among its bases, under the same name and module, with a DeprecationWarning.
    Deprecated in 0.2.0; refused from 0.3.0."""
    deprecation.warn(f"a door planner that subclasses Planner ({cls.__qualname__})",
                     "subclass DoorPlanner (from semsearch_cli.planners import DoorPlanner); Planner is the base of "
                     "every kind of planner", stacklevel=4)
    return type(cls.__name__, (cls, DoorPlanner), {"__module__": cls.__module__, "__qualname__": cls.__qualname__,
                                                  "__doc__": cls.__doc__})


ENTRY_POINT_GROUP = "semsearch.planners"
_LOADED_FILES: dict[str, list[str]] = {}  # resolved path -> planner names it registered
_ENTRY_POINTS_LOADED = False


def load_entry_points() -> None:
    """Import every module registered under the entry-point group ``semsearch.planners`` (once
    per process); each registers its planners with :func:`register_planner`."""
    global _ENTRY_POINTS_LOADED
    if _ENTRY_POINTS_LOADED:
        return
    _ENTRY_POINTS_LOADED = True
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            ep.load()
        except Exception as exc:
            raise ScenarioError(f"entry point {ep.name} = {ep.value}", ENTRY_POINT_GROUP,
                                f"the planner package failed to load: {type(exc).__name__}: {exc}") from None


def load_planner_file(path: str | Path) -> list[str]:
    """Import a user's planner file (once per process) and return the planner names it
    registered. A broken file (it raises, it registers nothing, it reuses a registered name)
    is a :class:`ScenarioError` naming the file."""
    path = Path(path).resolve()
    key = str(path)
    if key in _LOADED_FILES:
        return _LOADED_FILES[key]
    user_file(path, "planner file")
    mod_name = f"semsearch_user_planners.{path.stem}_{hashlib.sha1(key.encode()).hexdigest()[:8]}"
    spec = importlib.util.spec_from_file_location(mod_name, path)
    module = importlib.util.module_from_spec(spec)
    before = set(PLANNERS)
    sys.modules[mod_name] = module
    try:
        spec.loader.exec_module(module)
    except SyntaxError as exc:
        del sys.modules[mod_name]
        raise ScenarioError(key, f"line {exc.lineno}", f"not valid Python: {exc.msg}") from None
    except (Exception, SystemExit) as exc:  # sys.exit() at import too: exit 2, naming the file
        del sys.modules[mod_name]
        line = traceback.extract_tb(exc.__traceback__)[-1].lineno
        raise ScenarioError(key, f"line {line}", f"the planner file raised {type(exc).__name__}: {exc}") from None
    names = [n for n in PLANNERS if n not in before]
    if not names:
        raise ScenarioError(key, "", "registers no planner: decorate a Planner subclass with "
                            "@register_planner(\"name\") (from semsearch_cli.planners)")
    _LOADED_FILES[key] = names
    return names


@dataclass(frozen=True)
class Variant:
    """One planner with fixed parameters; ``label`` names it in rows, e.g. ``nsos[alpha=0.9]``.
    ``module``: the user's file that registers the planner (absolute path), loaded on demand in
    whichever process builds the planner."""

    name: str
    params: tuple  # sorted (key, value) pairs as given by the user
    module: str | None = None

    @property
    def label(self) -> str:
        if not self.params:
            return self.name
        return f"{self.name}[" + ",".join(f"{k}={v}" for k, v in self.params) + "]"

    def build(self) -> Planner:
        cls = planner_class(self)
        return cls(cls.Params(**dict(self.params)))


def planner_named(label: str) -> type[Planner] | None:
    """The registered class of a row's planner label (``nsos[alpha=0.9]`` -> nsos), or None when
    this process has not registered it (a user's planner, outside its run)."""
    return PLANNERS.get(str(label).split("[", 1)[0])


def swept_value(label: str) -> float | None:
    """The value of its planner's swept parameter in a row's planner label (``nsos[alpha=0.8]``
    -> 0.8), the parameter's default when the label does not set it; None without one."""
    cls = planner_named(label)
    if cls is None or cls.swept is None:
        return None
    m = re.search(rf"[\[,]{re.escape(cls.swept)}=([-+0-9.eE]+)", str(label))
    return float(m.group(1)) if m else float(cls.Params.model_fields[cls.swept].default)


def planner_order(labels) -> list[str]:
    """Row planner labels in report order: by :attr:`Planner.rank`, name, then the swept
    parameter's value (unknown planners last, by name)."""

    def key(lab):
        cls = planner_named(lab)
        v = swept_value(lab)
        return (cls.rank if cls is not None else Planner.rank, str(lab).split("[", 1)[0], v if v is not None else 0.0, lab)

    return sorted(set(labels), key=key)


def baseline_of(labels) -> str:
    """The label the others are compared with: a baseline planner's (the first in report order),
    else the first label in report order."""
    order = planner_order(labels)
    return next((lab for lab in order if (c := planner_named(lab)) is not None and c.baseline), order[0])


def expand_variants(specs, file: str = "<scenario>", task: str | None = None, base: Path | None = None) -> list[Variant]:
    """Planner entries -> variants; list-valued parameters expand into one variant per value.
    With ``task`` (a task's ``planner_kind``), planners that answer another kind are refused.
    An entry with ``module`` first loads that file (relative to ``base``, the scenario's folder);
    a name nothing registered is looked for among the installed entry points."""
    out: list[Variant] = []
    seen: set[tuple] = set()
    for i, spec in enumerate(specs):
        name, params = spec.name, spec.params()
        module = None
        if spec.module is not None:
            module = str(((base or Path(".")) / spec.module).resolve())
            names = load_planner_file(module)
            if name not in names:
                raise ScenarioError(file, f"planners[{i}].name", f"{module} registers {', '.join(names)}, not {name!r}")
        elif name not in PLANNERS:
            load_entry_points()
        valid = sorted(n for n, c in PLANNERS.items() if task is None or c.task == task)
        if name not in PLANNERS:
            raise ScenarioError(file, f"planners[{i}].name", f"unknown planner {name!r}{did_you_mean(name, valid)}; valid: "
                                f"{', '.join(valid)} (semsearch planners lists them with their parameters)")
        if task is not None and PLANNERS[name].task != task:
            raise ScenarioError(file, f"planners[{i}].name", f"{name!r} answers {PLANNERS[name].task} scenarios, not {task} "
                                f"ones; valid: {', '.join(valid)}")
        keys = sorted(params)
        values = [v if isinstance(v, list) else [v] for v in (params[k] for k in keys)]
        for k, vs in zip(keys, values):
            if not vs:
                raise ScenarioError(file, f"planners[{i}].{k}", "an empty list: give one value, or a list of values to "
                                    "sweep")
            bad = [v for v in vs if isinstance(v, float) and not math.isfinite(v)]
            if bad:
                raise ScenarioError(file, f"planners[{i}].{k}", f"expected a finite number, got {bad[0]!r}")
        for combo in itertools.product(*values):
            p = tuple(zip(keys, combo))
            try:
                PLANNERS[name].Params(**dict(p))
            except ValidationError as exc:
                e = exc.errors()[0]
                loc = ".".join(str(x) for x in e["loc"])
                if e["type"] == "extra_forbidden":
                    raise ScenarioError(file, f"planners[{i}].{loc}", f"{name!r} has no parameter {loc!r}"
                                        f"{did_you_mean(loc, PLANNERS[name].Params.model_fields)}; "
                                        f"{_parameters(PLANNERS[name])}") from None
                raise ScenarioError(file, f"planners[{i}].{loc}", e["msg"]) from None
            v = Variant(name, p, module)
            key = (v.label, module)  # rows name a variant by its label; a set keeps a big sweep linear
            if key not in seen:
                seen.add(key)
                out.append(v)
    return out


def _parameters(cls: type[Planner]) -> str:
    """A planner's parameters as an error lists them: ``its parameters: alpha = 0.9 (...), ...``."""
    fields = cls.Params.model_fields
    if not fields:
        return "it takes no parameters"
    return "its parameters: " + ", ".join(f"{k} = {f.default!r}" + (f" ({f.description})" if f.description else "")
                                          for k, f in fields.items())


def planner_class(variant: Variant) -> type[Planner]:
    """The registered class of a variant's planner (its file or entry point loaded first)."""
    if variant.module is not None:
        load_planner_file(variant.module)
    elif variant.name not in PLANNERS:
        load_entry_points()
    return PLANNERS[variant.name]


def code_of(variant: Variant) -> dict:
    """What a variant's results depend on besides the scenario: semsearch's own code (version and
    :func:`~semsearch_cli.provenance.code_hash`) and the planner's: a user's file by its bytes and
    those of the other Python files beside it (modules it may import); a planner from an
    installed package by that distribution's name and version and the hash of its package's
    Python files (an editable install changes with its files). ``hash`` (16 hex digits) combines
    them; rows carry it in their ``code`` column."""
    cls = planner_class(variant)
    out = {"planner": variant.label, "semsearch": __version__, "semsearch_code": code_hash()}
    mod = cls.__module__
    own = ""
    if variant.module is not None:
        path = Path(variant.module)
        out["source"] = "file"
        out["file"] = variant.module
        out["file_sha256"] = hashlib.sha256(path.read_bytes()).hexdigest()
        own = out["file_sha256"] + files_hash(path.parent, recursive=False)
    elif mod == "semsearch_cli" or mod.startswith("semsearch_cli."):
        out["source"] = "built-in"
    else:
        top = mod.split(".", 1)[0]
        dists = packages_distributions().get(top, [])
        out["source"] = "entry point"
        out["distribution"] = ", ".join(f"{d} {version(d)}" for d in dists) or f"module {mod} (no distribution found)"
        src = inspect.getsourcefile(sys.modules[top]) if top in sys.modules else None
        if src:
            root = Path(src).parent if Path(src).name == "__init__.py" else None
            out["package_code"] = files_hash(root) if root else hashlib.sha256(Path(src).read_bytes()).hexdigest()[:16]
        own = out["distribution"] + out.get("package_code", "")
    parts = [out["semsearch"], out["semsearch_code"], own]
    out["hash"] = hashlib.sha256("\0".join(parts).encode()).hexdigest()[:16]
    return out


DEPRECATED = {"PlanContext": ("semsearch_cli.planners.DoorContext", DoorContext)}  # 0.2.0 -> removed in 0.3.0


def __getattr__(name: str):
    return deprecation.alias(__name__, name, DEPRECATED)
