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

import functools
import hashlib
import importlib.util
import inspect
import itertools
import math
import numbers
import re
import sys
import traceback
import types
import typing
from dataclasses import dataclass, field
from importlib.metadata import entry_points, packages_distributions, version
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from ..belief import DoorBelief, Candidates
from .. import __version__
from ..credentials import WHERE_THE_KEY_GOES, credential_in, looks_like_key, redact, url_credential
from ..errors import PlannerError, ScenarioError, did_you_mean
from ..files import user_file
from ..provenance import code_hash, files_hash
from ..registry import Registry


# the row columns of what a planner's decisions cost (``Planner.cost_columns``; the llm planner:
# its calls to the model, their prompt and reply tokens, the replies it could not take, the
# decisions it fell back on the nearest target for, and the seconds spent waiting for replies)
COST_COLUMNS = ("llm_calls", "tokens_in", "tokens_out", "invalid_replies", "fallbacks", "llm_s")


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
    - ``distance``: the metres travelled so far in the run (NaN when the caller does not say).
    - ``told``: what a privileged planner (:attr:`Planner.privileged`) is told about the episode
      that a robot is not (:class:`Told`); None for every other planner.
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
    distance: float = float("nan")  # m travelled so far in the run (NaN: not known)
    told: "Told | None" = None


@dataclass(frozen=True)
class Told:
    """What a privileged planner is told about its episode that a robot is not, from the world's
    ground truth (never the map): ``goal_xy``, the position (x, y m) of each sign that carries the
    goal's label (one; more under ``duplicates: any``), under the numbering the run has (a bench run
    of shuffled labels tells where the shuffled goal's sign is); ``walls``, every sign as (label,
    x m, y m, wall), ``wall`` its stretch of wall (:meth:`~semsearch_cli.world.Signs.walls`)."""

    goal_xy: tuple  # ((x, y), ...) m
    walls: tuple = ()  # ((label, x, y, wall), ...)


@dataclass
class Decision:
    """A door planner's choice: the target cell (``row``, ``col``, a free cell of the belief's
    grid) and ``info``, the numbers behind it for traces (any JSON-able values; ``"kept": True``
    marks a re-plan that keeps the previous target, which is not counted as a decision).

    ``info`` is checked when the decision is made: a dict, holding no container that holds
    itself (``info["me"] = info``) and nested at most :data:`MAX_INFO_DEPTH` deep; else a
    :class:`~semsearch_cli.errors.PlannerError` (the run's ``error``), as no trace could hold it."""

    row: int
    col: int
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        fault = info_fault(self.info)
        if fault:
            raise PlannerError(f"Decision.info {fault}; info is a dict of JSON-able values (numbers, text, lists, "
                               "dicts) for traces")


MAX_INFO_DEPTH = 100  # levels of nesting a decision's info may have (a trace writes it recursively)
_CONTAINERS = (dict, list, tuple, set, frozenset)


def info_fault(info) -> str | None:
    """What makes ``info`` (a decision's numbers behind it) impossible to write to a trace, in
    words (``"holds itself: info['me'] is info"``), or None: not a dict, a container that holds
    itself (anywhere below), or nesting deeper than :data:`MAX_INFO_DEPTH`. A value shared by two
    keys is fine; the walk is iterative, so a deep ``info`` cannot overflow the stack here."""
    if not isinstance(info, dict):
        return f"is {type(info).__name__} {_short(info)}, not a dict"
    on_path = {id(info): "info"}  # the containers from info down to the one being walked
    stack = [(info, "info", iter(info.items()))]
    while stack:
        obj, where, items = stack[-1]
        nxt = next(items, None)
        if nxt is None:
            on_path.pop(id(obj), None)
            stack.pop()
            continue
        key, child = nxt
        if not isinstance(child, _CONTAINERS):
            continue
        here = f"{where}[{_short(key)}]"
        if id(child) in on_path:
            return f"holds itself: {here} is {on_path[id(child)]}"
        if len(stack) >= MAX_INFO_DEPTH:
            return f"is nested deeper than {MAX_INFO_DEPTH} levels (at {here})"
        on_path[id(child)] = here
        stack.append((child, here, iter(child.items() if isinstance(child, dict) else enumerate(child))))
    return None


def _short(v, n: int = 40) -> str:
    """``v`` as a message shows it: its repr cut to ``n`` characters (a class by its name, a
    container by its type and length, so that one holding itself prints)."""
    if isinstance(v, type):
        r = v.__qualname__
    elif isinstance(v, _CONTAINERS):
        r = f"<{type(v).__name__} of {len(v)}>"
    else:
        try:
            r = repr(v)
        except Exception:
            r = f"<{type(v).__name__}>"
    return r if len(r) <= n else r[: n - 3] + "..."


class Planner:
    """What every planner is, whatever it searches for; each kind has its own protocol on top:
    :class:`DoorPlanner`, :class:`~semsearch_cli.planners.ObjectPlanner` and
    :class:`~semsearch_cli.planners.IndirectPlanner`, which set ``task``.

    Class attributes: ``Params`` (a pydantic model of the planner's parameters, checked when the
    scenario is loaded), ``task`` (the kind of search it answers), ``rank``, ``baseline``,
    ``swept`` and ``replay`` (how reports order, compare and replay it; see the attributes below).
    :func:`register_planner` checks them, and those a kind's protocol adds, when the class
    registers (:func:`check_planner_class`).
    """

    name: ClassVar[str] = ""
    task: ClassVar[str] = ""  # which kind of scenario the planner answers (a task's planner_kind)
    kinds: ClassVar[tuple] = ()  # every kind it answers, when more than its task (llm answers all three)
    Params: ClassVar[type[BaseModel]] = NoParams
    rank: ClassVar[float] = 100  # where reports list it among its kind's planners (lower first; then by name)
    baseline: ClassVar[bool] = False  # reports compare the other planners with this one, paired
    swept: ClassVar[str | None] = None  # the parameter `semsearch sweep-alpha` sweeps (and reports plot against)
    replay: ClassVar[bool] = False  # the planner a report replays by default (else the last in report order)
    # the attributes that shape a run besides the planner's choices: a run's decisions record
    # keeps them, and its replay seats a stand-in that has them (semsearch_cli.tasks.decisions)
    run_attributes: ClassVar[tuple] = ()
    # the row columns of what the planner's decisions cost (metrics.COST_COLUMNS: a language
    # model's calls and tokens), filled from its ``costs()`` after each run and summed by reports
    cost_columns: ClassVar[tuple] = ()
    # answers through a service outside semsearch (a language model's endpoint) and needs its
    # parameters to run: what takes every built-in planner with its defaults (the bench board,
    # the golden runs) leaves it out
    service: ClassVar[bool] = False
    # what the planner is told about the episode that a robot is not, in words ("" for every
    # planner that sees only what the robot senses): a privileged planner is a reference (a
    # ceiling, a bound), never a competitor. Door planners that set it get ``DoorContext.told``;
    # the planner list and the bench board mark it, and the board never ranks it with the others.
    privileged: ClassVar[str] = ""
    # the floors its parameters (or model) were chosen or trained on, in words: "" for none (no
    # parameter, or values set before any run), else a suite and split ("doors-v1 val") or a
    # salt ("doors-train, salt semsearch-train-v1"). The bench board gives it beside each row and
    # flags a row of the split it was tuned on: a result there is not held out.
    tuned_on: ClassVar[str] = ""

    def __init__(self, params: BaseModel):
        self.params = params

    @classmethod
    def answers(cls, kind: str) -> bool:
        """Whether the planner answers scenarios of ``kind`` (its ``task``, or one of its ``kinds``)."""
        return kind == cls.task or kind in cls.kinds

    @classmethod
    def fault(cls, params: BaseModel, kind: str | None = None) -> tuple[str, str] | None:
        """What is wrong with parameters that are each valid but do not go together, or do not
        suit a scenario of ``kind`` (the field to name, the message), checked when the scenario
        loads (the files they name already found to exist); None when nothing is. The defaults may
        be faulty this way (the llm planner needs a model named)."""
        return None

    @classmethod
    def inputs(cls, params: BaseModel) -> str:
        """What the planner's results depend on besides its code and its parameters' values, as
        text that :func:`code_of` hashes: the bytes of the files its parameters name (the llm
        planner's prompt and transcripts). Nothing by default."""
        return ""

    @classmethod
    def missing(cls, params: BaseModel) -> tuple[str, str] | None:
        """A package the planner needs that is not installed (the field to name, the message), or
        None (the default). A dry run looks at this alone (it calls no service);
        :meth:`preflight` looks at it first."""
        return None

    @classmethod
    def preflight(cls, params: BaseModel) -> tuple[str, str] | None:
        """What stops the planner from running at all (the field to name, the message), looked
        at once per batch, before its first run, in the process that starts the batch: a package
        it needs, a service it answers through that does not answer (the llm planner's endpoint,
        docs/llm.md). None when nothing does; the default looks at :meth:`missing` alone. A batch
        refuses to start rather than record runs that could not be the planner's."""
        return cls.missing(params)


class DoorPlanner(Planner):
    """A door-search planner: ``choose(ctx, cands)`` gets a :class:`DoorContext` and the
    frontier :class:`~semsearch_cli.belief.Candidates` and returns a :class:`Decision`, or None
    when no candidate suits (the robot then looks at the walls it has not read yet)."""

    task: ClassVar[str] = "doors"
    replan_on_signs: ClassVar[bool] = False  # re-plan also when a sign reaches belief.min_reads reads
    run_attributes: ClassVar[tuple] = ("replan_on_signs",)  # what shapes a run besides the choices (a replay keeps them)

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
            old = (" (a Planner with choose(ctx, cands) was the door planner's API through 0.1.x, ran with a warning in "
                   "0.2.x, removed in 0.3.0)") if callable(getattr(cls, "choose", None)) else ""
            raise TypeError(f"planner {name!r}: {cls.__name__} answers no kind of search{old}; subclass DoorPlanner (door "
                            "search), ObjectPlanner or IndirectPlanner (from semsearch_cli.planners)")
        if isinstance(cls, type) and issubclass(cls, Planner):
            check_planner_class(cls)
        return PLANNERS.add(name, cls)

    return deco


def check_planner_class(cls: type[Planner]) -> None:
    """Refuse, when it registers, a planner class whose class attributes the simulator, the
    planner list or a report would trip over later (after a whole batch, for a report): a
    :class:`ScenarioError` naming the class's file, ``Class.attribute`` and the line that sets it.

    - ``Params``: a pydantic model (a subclass of ``pydantic.BaseModel``) that builds from its
      defaults when every parameter has one (a validator that raises is caught here);
    - every class attribute a kind's protocol declares (``ClassVar`` annotations of
      :class:`Planner`, :class:`DoorPlanner`, ``ObjectPlanner``, ``IndirectPlanner``) of the type
      it declares: ``task`` text, ``rank`` a finite number, ``baseline`` and ``replay`` True or
      False, ``masks`` text or None, ...;
    - ``swept``: None or the name of a parameter whose default is a finite number (reports plot
      against it, and read it from a label that does not set it);
    - ``__doc__`` (the planner list's description): None or text.
    """
    params = cls.Params
    if not (isinstance(params, type) and issubclass(params, BaseModel)):
        _refuse(cls, "Params", f"Params = {_short(params)}: give a pydantic model of the planner's parameters (class "
                "Params(BaseModel) with one annotated field per parameter, or leave it out for none)")
    for attr, hint in _declared(cls).items():
        value = getattr(cls, attr)
        expected = _type_fault(value, hint)
        if expected:
            _refuse(cls, attr, f"{attr} = {_short(value)}: expected {expected}")
    doc = cls.__doc__
    if doc is not None and not isinstance(doc, str):
        _refuse(cls, "__doc__", f"__doc__ = {_short(doc)}: a planner's description (what `semsearch planners` lists) is "
                "text (its docstring) or None")
    columns = getattr(cls, "cost_columns", ())
    if isinstance(columns, (tuple, list)):
        for c in columns:  # a row column of another name: the batch wrote it, then refused its own runs.csv
            if c not in COST_COLUMNS:
                _refuse(cls, "cost_columns", f"cost_columns holds {_short(c)}, not a cost column of the rows"
                        f"{did_you_mean(c, COST_COLUMNS) if isinstance(c, str) else ''} (they are {', '.join(COST_COLUMNS)})")
    fields = params.model_fields
    if all(not f.is_required() for f in fields.values()):
        # the defaults, validated (pydantic takes a default as it is: a run would use one that
        # breaks its own field's bounds, and a validator that raises, unseen until a scenario sets it),
        # a default_factory's too (it was left out: Field(default_factory=lambda: -5, ge=0) ran with -5)
        try:
            defaults = {f.alias or k: f.get_default(call_default_factory=True) for k, f in fields.items()}
            for k, v in defaults.items():
                if isinstance(v, float) and not math.isfinite(v):  # as a scenario's value is refused (check_params)
                    _refuse(cls, "Params", f"its parameters' defaults are not valid ({k}: {v!r}, not a finite number)")
            params.model_validate(defaults)
        except ValidationError as exc:
            e = exc.errors()[0]
            _refuse(cls, "Params", f"its parameters' defaults are not valid ({'.'.join(map(str, e['loc']))}: {e['msg']})")
        except (Exception, SystemExit) as exc:
            file, _ = _source(cls)
            line = _user_line(exc, file)
            _refuse(cls, "Params", f"building its parameters from their defaults raised {type(exc).__name__}: {exc}",
                    line)
    if cls.swept is not None:
        numeric = [k for k, f in fields.items() if _finite_number(f.default)]
        if cls.swept not in fields:
            _refuse(cls, "swept", f"swept = {cls.swept!r} names no parameter of the planner{did_you_mean(cls.swept, numeric)}; "
                    + (f"give one whose default is a number ({', '.join(numeric)}) or None" if numeric else
                       "none has a number as its default: leave swept None"))
        if not _finite_number(fields[cls.swept].default):
            _refuse(cls, "swept", f"swept = {cls.swept!r}, whose default is {fields[cls.swept].default!r}: the swept "
                    "parameter needs a default that is a finite number (reports place a label that does not set it "
                    "at that value)")


def _finite_number(v) -> bool:
    """A real number a float holds (an int of 10**400 is not one: math.isfinite overflowed on it)."""
    if not isinstance(v, numbers.Real) or isinstance(v, bool):
        return False
    try:
        return math.isfinite(float(v))
    except OverflowError:
        return False


def _type_fault(value, hint) -> str | None:
    """What ``value`` should have been, in words, when it is not of type ``hint`` (a class
    attribute's declared type: bool, int, float, str, None, a Literal, or a union of them);
    None when it is, or when ``hint`` is a type not checked here."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        faults = [_type_fault(value, a) for a in args]
        if any(f is None for f in faults):
            return None
        return " or ".join(faults)
    if origin is Literal:
        return None if value in args else "one of " + ", ".join(repr(a) for a in args)
    if hint is type(None):
        return None if value is None else "None"
    if hint is bool:
        return None if isinstance(value, (bool, np.bool_)) else "True or False"
    if hint in (int, float):
        return None if _finite_number(value) and (hint is float or isinstance(value, numbers.Integral)
                                                  or float(value).is_integer()) else (
            "a finite number" if hint is float else "a whole number")
    if hint is str:
        return None if isinstance(value, str) else "text"
    return None


@functools.cache
def _protocol_hints(base: type) -> dict:
    """The class attributes ``base`` (one of semsearch's planner classes) declares, with types."""
    try:
        hints = typing.get_type_hints(base)
    except Exception:  # an annotation that does not resolve: nothing to check against
        return {}
    return {k: typing.get_args(h)[0] for k, h in hints.items() if typing.get_origin(h) is ClassVar and typing.get_args(h)}


def _declared(cls: type) -> dict:
    """attribute -> declared type, over the semsearch planner classes ``cls`` derives from
    (``Params`` and ``name`` are checked apart: a model, and the name the registry sets)."""
    out: dict = {}
    for base in reversed(cls.__mro__):
        if issubclass(base, Planner) and base.__module__.startswith("semsearch_cli."):
            out.update(_protocol_hints(base))
    out.pop("Params", None)
    out.pop("name", None)
    return out


def _source(cls: type) -> tuple[str, int | None]:
    """(the file that defines ``cls``, the line of its ``class`` statement), the line None when
    the source cannot be found (a class made by ``type()``, or in an interactive session)."""
    module = sys.modules.get(cls.__module__)
    file = getattr(module, "__file__", None) or f"module {cls.__module__}"
    try:
        lines, start = inspect.getsourcelines(cls)
    except (OSError, TypeError):
        return file, None
    head = re.compile(rf"\s*class\s+{re.escape(cls.__name__)}\b")
    return file, next((start + i for i, text in enumerate(lines) if head.match(text)), start)


def _attribute_line(cls: type, attr: str) -> int | None:
    """The line that sets ``attr`` in ``cls``'s own body (``attr = ...``, ``class attr``, ``def
    attr``), else the line of the class statement (an attribute it inherits)."""
    _, line = _source(cls)
    if line is None or attr not in vars(cls):
        return line
    lines, start = inspect.getsourcelines(cls)
    sets = re.compile(rf"\s+(?:(?:class|def)\s+{re.escape(attr)}\b|{re.escape(attr)}\s*(?::[^=]*)?=(?!=))")
    return next((start + i for i, text in enumerate(lines) if start + i > line and sets.match(text)), line)


def _refuse(cls: type, attr: str, message: str, line: int | None = None) -> None:
    """Raise the :class:`ScenarioError` of a planner class's bad attribute: its file, the field
    ``Class.attr``, and ``line N of FILE`` (``line``, else the line that sets it)."""
    file, _ = _source(cls)
    line = line if line is not None else _attribute_line(cls, attr)
    where = f"line {line} of {Path(file).name}, " if line is not None else ""
    raise ScenarioError(file, f"{cls.__name__}.{attr}", f"{where}planner class {cls.__name__}: {message}")


def _same_file(a: str, b: str) -> bool:
    if a == b:
        return True
    try:
        return Path(a).resolve() == Path(b).resolve()
    except (OSError, RuntimeError, ValueError):
        return False


def _user_line(exc: BaseException, file: str) -> int | None:
    """The line of ``file`` (a user's planner file) in ``exc``'s traceback nearest to where it
    was raised: the last frame in that file, not one of semsearch's own code or a library's."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if _same_file(f.filename, file)]
    return frames[-1].lineno if frames else None


def _raised_in(exc: BaseException, file: str) -> str:
    """`` (raised at line N of OTHER)`` when ``exc`` was raised in a file other than ``file``
    that is the user's too (a module the planner file imports), not semsearch's, Python's or an
    installed library's; else ``""``."""
    frames = traceback.extract_tb(exc.__traceback__)
    if not frames:
        return ""
    last = frames[-1]
    not_users = (str(Path(__file__).resolve().parents[1]), sys.prefix, sys.base_prefix, sys.exec_prefix, "<")
    if _same_file(last.filename, file) or last.filename.startswith(not_users):
        return ""
    return f" (raised at line {last.lineno} of {last.filename})"


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
        except ScenarioError:  # a planner class refused when it registered: names its file and line
            raise
        except Exception as exc:
            raise ScenarioError(f"entry point {ep.name} = {ep.value}", ENTRY_POINT_GROUP,
                                f"the planner package failed to load: {type(exc).__name__}: {exc}") from None


def load_planner_file(path: str | Path) -> list[str]:
    """Import a user's planner file (once per process) and return the planner names it
    registered. A broken file (it raises, it registers nothing, it reuses a registered name, a
    class it registers is refused by :func:`check_planner_class`) is a :class:`ScenarioError`
    naming the file and the line of it where things went wrong (the last line of the file in
    the traceback, not a line of semsearch's own code); the planners it registered before are
    forgotten, so that loading it again says the same."""
    path = Path(path).resolve()
    key = str(path)
    if key in _LOADED_FILES:
        return _LOADED_FILES[key]
    user_file(path, "planner file")
    if path.suffix != ".py":  # a planner file is Python source, wherever it lies (docs/usage.md, Paths)
        raise ScenarioError(key, "", "not a planner file: give a Python file whose name ends in .py")
    mod_name = f"semsearch_user_planners.{path.stem}_{hashlib.sha1(key.encode()).hexdigest()[:8]}"
    spec = importlib.util.spec_from_file_location(mod_name, path)
    module = importlib.util.module_from_spec(spec)
    before = set(PLANNERS)
    sys.modules[mod_name] = module

    def forget():
        sys.modules.pop(mod_name, None)
        for n in set(PLANNERS) - before:
            del PLANNERS[n]

    try:
        spec.loader.exec_module(module)
    except ScenarioError:  # a class refused when it registered: the error names its file and line
        forget()
        raise
    except SyntaxError as exc:
        forget()
        if exc.filename is None or _same_file(exc.filename, key):  # no line for a file holding a NUL byte ('line None')
            raise ScenarioError(key, f"line {exc.lineno}" if exc.lineno else "", f"not valid Python: {exc.msg}") from None
        line = _user_line(exc, key)  # a module the file imports
        raise ScenarioError(key, f"line {line}" if line is not None else "", f"imports a file that is not valid "
                            f"Python: {exc.msg} (line {exc.lineno} of {exc.filename})") from None
    except (Exception, SystemExit) as exc:  # sys.exit() at import too: exit 2, naming the file
        forget()
        line = _user_line(exc, key)
        raise ScenarioError(key, f"line {line}" if line is not None else "",
                            f"the planner file raised {type(exc).__name__}: {exc}{_raised_in(exc, key)}") from None
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
    base: str | None = None  # the scenario's folder (absolute), for a planner whose parameters name files (path_fields)

    @property
    def label(self) -> str:
        """``name[key=value,...]``; a credential in a value (an address's ``user:key@``, a key such
        as ``sk-...``; :mod:`~semsearch_cli.credentials`) shows masked. Such a value is refused
        where it is given (:func:`expand_variants`, the planner's own checks); this is the last
        guard, for a variant built by hand, since rows, reports and file names carry the label."""
        if not self.params:
            return self.name
        return f"{self.name}[" + ",".join(f"{k}={shown(v)}" for k, v in self.params) + "]"

    def build(self) -> Planner:
        cls = planner_class(self)
        return cls(self.resolved(cls))

    def resolved(self, cls: type[Planner] | None = None) -> BaseModel:
        """The variant's parameters as its planner takes them: the files they name (its
        :func:`path_fields`) relative to the scenario's folder, as written in the label."""
        cls = cls or planner_class(self)
        params = dict(self.params)
        for k in path_fields(cls.Params):
            if params.get(k) is not None and self.base is not None:
                params[k] = str(Path(self.base) / str(params[k]))
        return cls.Params(**params)


def shown(value) -> str:
    """A parameter's value as a label writes it: ``str(value)``, with a credential in it masked."""
    return redact(value) if url_credential(value) or looks_like_key(value) else str(value)


def param_entry(name: str, key: str, value) -> str:
    """The planner entry an error about parameter ``key`` names: ``'nsos[alpha=2]'`` (that
    parameter alone, as a label writes it; a parameter whose name says it holds a key shows
    ``***``)."""
    secretish = any(w in key.lower() for w in ("key", "token", "secret", "password"))
    return repr(f"{name}[{key}={'***' if secretish else shown(value)}]")


def _bound(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def param_message(name: str, error: dict, params: dict) -> tuple[str, str]:
    """(the parameter, a sentence naming the entry and the parameter) of one pydantic error of a
    planner's ``Params``: ``'nsos[alpha=2]': alpha must be at most 1``. The parameter is ``""``
    for an error of the parameters together (a model validator)."""
    loc = ".".join(str(x) for x in error.get("loc", ()))
    key = str(error["loc"][0]) if error.get("loc") else ""
    ctx, kind = error.get("ctx") or {}, error.get("type", "")
    if not key:
        entry = repr(f"{name}[" + ",".join(f"{k}={shown(v)}" for k, v in sorted(params.items())) + "]") if params else repr(name)
        return "", f"{entry}: {error['msg'].removeprefix('Value error, ')}"
    value = params.get(key, error.get("input"))
    what = {
        "greater_than": lambda: f"must be more than {_bound(ctx['gt'])}",
        "greater_than_equal": lambda: f"must be at least {_bound(ctx['ge'])}",
        "less_than": lambda: f"must be less than {_bound(ctx['lt'])}",
        "less_than_equal": lambda: f"must be at most {_bound(ctx['le'])}",
        "finite_number": lambda: "must be a finite number",
        "float_parsing": lambda: "must be a number",
        "float_type": lambda: "must be a number",
        "int_parsing": lambda: "must be a whole number",
        "int_type": lambda: "must be a whole number",
        "int_from_float": lambda: "must be a whole number",
        "int_parsing_size": lambda: "must be a whole number of at most 4,300 digits",
        "bool_parsing": lambda: "must be true or false",
        "bool_type": lambda: "must be true or false",
        "string_type": lambda: "must be text",
        "literal_error": lambda: f"must be one of {ctx.get('expected', '')}",
        "enum": lambda: f"must be one of {ctx.get('expected', '')}",
        "missing": lambda: "is required",
    }.get(kind)
    if what is None:
        msg = error["msg"].removeprefix("Value error, ")
        text = msg if msg.startswith(loc + " ") else f"{loc}: {msg}"
    else:
        text = f"{loc} {what()}"
        if kind in ("float_type", "int_type", "bool_type", "string_type") and value is None:
            text += " (it is empty)"
    return key, f"{param_entry(name, key, value)}: {text}"


def check_params(cls: type[Planner], name: str, params: dict) -> tuple[str, str] | None:
    """What is wrong with ``params`` as planner ``name``'s (:class:`Planner` ``cls``) takes them,
    checked one way for a scenario's entry, ``--planner`` and ``sweep --param``: (the parameter,
    a sentence naming the entry and the parameter, :func:`param_message`), or None.

    - a text value that is an address holding a credential (:func:`~semsearch_cli.credentials.url_credential`,
      any planner: the label would carry it), before anything else, the key never shown;
    - a parameter the planner does not take, with the nearest valid name;
    - what its ``Params`` model refuses (out of range, the wrong type, not one of its choices);
    - a number that is not finite (NaN, inf, also written as text: ``inf``, ``1e999``), which a
      model's float field would otherwise take; true or false for a number (read as 1 or 0)."""
    for k, v in params.items():
        secret = url_credential(v)
        if secret:
            return k, f"{param_entry(name, k, v)}: {k} holds {secret}: {WHERE_THE_KEY_GOES}"
    fields = cls.Params.model_fields
    if cls.Params.model_config.get("extra") != "allow":
        # a key the model does not take: a model that forbids extras says so below, but pydantic's
        # default ignores them, so that a user's planner ran with its default for a misspelt key
        known = set(fields) | {f.alias for f in fields.values() if f.alias}
        for k in params:
            if k not in known:
                return k, (f"{param_entry(name, k, params.get(k))}: {name!r} has no parameter {k!r}"
                           f"{did_you_mean(k, fields)}; {_parameters(cls)}")
    for k, v in params.items():
        if (isinstance(v, float) or (isinstance(v, str) and k in fields and _takes_number(fields[k].annotation))) \
                and not _finite_text(v):
            return k, f"{param_entry(name, k, v)}: {k} must be a finite number"
        if isinstance(v, bool) and k in fields and not _takes_bool(fields[k].annotation):
            return k, f"{param_entry(name, k, v)}: {k} must be a number, not true or false"
    try:
        model = cls.Params(**params)
    except ValidationError as exc:
        e = exc.errors()[0]
        if e["type"] == "extra_forbidden":
            k = str(e["loc"][0])
            return k, (f"{param_entry(name, k, params.get(k))}: {name!r} has no parameter {k!r}"
                       f"{did_you_mean(k, cls.Params.model_fields)}; {_parameters(cls)}")
        return param_message(name, e, params)
    for k in params:
        v = getattr(model, k, None)
        if isinstance(v, float) and not math.isfinite(v):
            return k, f"{param_entry(name, k, params[k])}: {k} must be a finite number"
    return None


def _takes_number(annotation) -> bool:
    """Whether a field of this annotation takes a number (``float``, ``int``, or either or None)."""
    return annotation in (float, int) or bool({float, int} & set(typing.get_args(annotation)))


def _finite_text(v) -> bool:
    """False for a number, or text a number field reads as one, that is not finite (``nan``,
    ``inf``, ``-Infinity``, ``1e999``); True for anything else (a wrong type is the model's to say)."""
    try:
        return math.isfinite(float(v))
    except (TypeError, ValueError, OverflowError):
        return True


def _takes_bool(annotation) -> bool:
    """Whether a field of this annotation takes True or False as such (pydantic would read them
    as 1 and 0 in a number field)."""
    return annotation is bool or bool in typing.get_args(annotation) or annotation in (typing.Any, object)


ENTRY = re.compile(r"(?P<name>[A-Za-z0-9_][\w.+-]*)(?:\[(?P<params>[^\[\]]*)\])?")  # NAME or NAME[key=value,...]


def parse_entry(text: str, flag: str = "--planner") -> tuple[str, dict]:
    """(name, parameters) of a planner given on the command line as a label writes it,
    ``NAME`` or ``NAME[key=value,...]``, each value read as a YAML scalar (``0.9``, ``true``,
    ``text``); a :class:`ScenarioError` naming ``flag`` for any other form, a parameter given
    twice or with no value, and for an address holding a credential (the key never shown)."""
    secret = credential_in(text)
    if secret:
        raise ScenarioError("<command line>", flag, f"{redact(text.strip())!r} holds {secret}: {WHERE_THE_KEY_GOES}")
    m = ENTRY.fullmatch(text.strip())
    if m is None:
        raise ScenarioError("<command line>", flag, f"{_short(text.strip(), 120)}: give NAME or NAME[key=value,...], e.g. "
                            "nsos[alpha=0.9]")
    params: dict = {}
    for item in filter(None, (p.strip() for p in (m["params"] or "").split(","))):
        key, eq, value = (x.strip() for x in item.partition("="))
        if not eq or not key:
            raise ScenarioError("<command line>", flag, f"{text.strip()!r}: {item!r} is not key=value")
        if key in params:
            raise ScenarioError("<command line>", flag, f"{text.strip()!r}: {key} is given twice; give each parameter once")
        if not value:
            raise ScenarioError("<command line>", flag, f"{text.strip()!r}: {key} has no value; give one ({key}=VALUE), or "
                                "leave the parameter out for its default")
        try:
            params[key] = yaml.safe_load(value)
        except yaml.YAMLError:
            raise ScenarioError("<command line>", flag, f"{text.strip()!r}: cannot read the value of {key}, {value!r} (a "
                                "number, true or false, or text)") from None
    return m["name"], params


def check_entry(text: str, flag: str = "--planner") -> None:
    """Refuse, naming ``flag``, a planner given on the command line whose parameters its planner
    would refuse (:func:`check_params`: ``'nsos[alpha=2]': alpha must be at most 1``); a name
    this process has not registered is left to the caller (it may be a user's planner)."""
    name, params = parse_entry(text, flag)
    cls = PLANNERS.get(name)
    if cls is None or not params:
        return
    try:
        fault = check_params(cls, name, {k: v for k, v in params.items() if k != "module"})
    except (Exception, SystemExit):  # a user's validator that raises: expand_variants names its line
        return
    if fault:
        raise ScenarioError("<command line>", flag, fault[1])


def path_fields(params: type[BaseModel]) -> tuple[str, ...]:
    """The parameters of a planner that name a file or folder (relative to the scenario's
    folder): fields declared with ``Field(json_schema_extra={"path": True})``."""
    return tuple(k for k, f in params.model_fields.items() if isinstance(f.json_schema_extra, dict) and f.json_schema_extra.get("path"))


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
            if not module.endswith(".py"):
                raise ScenarioError(file, f"planners[{i}].module", f"{spec.module} is not a planner file: give a Python file "
                                    "whose name ends in .py (relative to the scenario's folder)")
            names = load_planner_file(module)
            if name not in names:
                raise ScenarioError(file, f"planners[{i}].name", f"{module} registers {', '.join(names)}, not {name!r}")
        elif name not in PLANNERS:
            load_entry_points()
        valid = sorted(n for n, c in PLANNERS.items() if task is None or c.answers(task))
        if name not in PLANNERS:
            raise ScenarioError(file, f"planners[{i}].name", f"unknown planner {name!r}{did_you_mean(name, valid)}; valid: "
                                f"{', '.join(valid)} (semsearch planners lists them with their parameters)")
        if task is not None and not PLANNERS[name].answers(task):
            raise ScenarioError(file, f"planners[{i}].name", f"{name!r} answers "
                                f"{', '.join(PLANNERS[name].kinds or (PLANNERS[name].task,))} scenarios, not {task} "
                                f"ones; valid: {', '.join(valid)}")
        keys = sorted(params)
        values = [v if isinstance(v, list) else [v] for v in (params[k] for k in keys)]
        for k, vs in zip(keys, values):
            if not vs:
                raise ScenarioError(file, f"planners[{i}].{k}", f"{name}'s {k} is an empty list: give one value, or a list "
                                    "of values to sweep")
        for combo in itertools.product(*values):
            p = tuple(zip(keys, combo))
            try:
                fault = check_params(PLANNERS[name], name, dict(p))
            except (Exception, SystemExit) as exc:  # a validator of the planner's that raises something else
                src, _ = _source(PLANNERS[name])
                line = _user_line(exc, src)
                at = f" (line {line} of {src})" if line is not None else ""
                raise ScenarioError(file, f"planners[{i}]", f"planner {name!r} with "
                                    f"{', '.join(f'{k}={v!r}' for k, v in p) or 'its defaults'}: its Params raised "
                                    f"{type(exc).__name__}: {exc}{at}") from None
            if fault:
                raise ScenarioError(file, f"planners[{i}].{fault[0]}" if fault[0] else f"planners[{i}]", fault[1])
            paths = path_fields(PLANNERS[name].Params)
            for k, value in p:
                if k in paths and value is not None and not ((base or Path(".")) / str(value)).exists():
                    raise ScenarioError(file, f"planners[{i}].{k}", f"{value} does not exist (a path relative to the "
                                        "scenario's folder)")
            v = Variant(name, p, module, str((base or Path(".")).resolve()) if paths else None)
            try:
                fault = PLANNERS[name].fault(v.resolved(PLANNERS[name]), task)
            except (Exception, SystemExit) as exc:  # a user's fault() that raises
                raise ScenarioError(file, f"planners[{i}]", f"planner {name!r}: its fault() raised {type(exc).__name__}: "
                                    f"{exc}") from None
            if fault:
                raise ScenarioError(file, f"planners[{i}].{fault[0]}", fault[1])
            key = (v.label, module)  # rows name a variant by its label; a set keeps a big sweep linear
            if key not in seen:
                seen.add(key)
                out.append(v)
    return out


def has_preflight(cls: type[Planner]) -> bool:
    """Whether a planner class looks before it runs (overrides :meth:`Planner.preflight` or
    :meth:`Planner.missing`)."""
    return any(getattr(getattr(cls, m), "__func__", None) is not getattr(Planner, m).__func__ for m in ("preflight", "missing"))


def preflight(variants, file: str, field: str | None = None) -> None:
    """Refuse (a :class:`ScenarioError` naming ``file``, the planner and the field, or ``field``
    when given: ``--planner`` for a planner the command line named) the first of ``variants``
    whose planner's :meth:`Planner.preflight` finds it cannot run; each distinct planner and
    parameters is looked at once."""
    seen = set()
    for v in variants:
        cls = planner_class(v)
        if not has_preflight(cls) or (v.name, v.params) in seen:
            continue
        seen.add((v.name, v.params))
        fault = cls.preflight(v.resolved(cls))
        if fault:
            raise ScenarioError(file, field or f"planners.{fault[0]}", f"{v.label}: {fault[1]}")


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
    Python files (an editable install changes with its files); and the files its parameters name
    (:meth:`Planner.inputs`: the llm planner's prompt and transcripts). ``hash`` (16 hex digits)
    combines them; rows carry it in their ``code`` column, and a batch sets aside rows whose hash
    is not the variant's."""
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
    inputs = cls.inputs(variant.resolved(cls))
    if inputs:  # the files its parameters name (a prompt, transcripts): rows made from others are not reused
        out["inputs_sha256"] = hashlib.sha256(inputs.encode()).hexdigest()
        own += out["inputs_sha256"]
    parts = [out["semsearch"], out["semsearch_code"], own]
    out["hash"] = hashlib.sha256("\0".join(parts).encode()).hexdigest()[:16]
    return out

