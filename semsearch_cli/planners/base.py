"""The planner interface and registry (SPEC 4).

A planner picks the next target from the belief. It sees a :class:`PlanContext` and the frontier
:class:`~semsearch_cli.belief.Candidates`, and returns a :class:`Decision` (a target cell and the
numbers behind the choice, for traces). Adding a planner: subclass :class:`Planner` in a module of
this package, give it a pydantic ``Params`` model, and decorate it with ``@register_planner(name)``;
nothing in the simulator changes.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from ..belief import Belief, Candidates
from ..errors import ScenarioError


class NoParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclass
class PlanContext:
    """What a planner may look at: the belief, the robot pose and history, the goal, the run's RNG."""

    belief: Belief
    row: int
    col: int
    x: float
    y: float
    heading: float
    goal: Any
    rng: np.random.Generator
    headings: list = field(default_factory=list)


@dataclass
class Decision:
    row: int
    col: int
    info: dict = field(default_factory=dict)


class Planner:
    """Base class: ``choose`` returns a :class:`Decision` or None when there is nowhere to go."""

    name: ClassVar[str] = ""
    task: ClassVar[str] = "doors"  # or "objects": which kind of scenario the planner answers
    Params: ClassVar[type[BaseModel]] = NoParams

    def __init__(self, params: BaseModel):
        self.params = params

    def choose(self, ctx: PlanContext, cands: Candidates) -> Decision | None:  # pragma: no cover
        raise NotImplementedError


PLANNERS: dict[str, type[Planner]] = {}


def register_planner(name: str):
    """Class decorator adding a planner to the registry under ``name`` (must be new)."""

    def deco(cls):
        if name in PLANNERS:
            raise ValueError(f"planner {name!r} is already registered by {PLANNERS[name].__module__}")
        cls.name = name
        PLANNERS[name] = cls
        return cls

    return deco


@dataclass(frozen=True)
class Variant:
    """One planner with fixed parameters; ``label`` names it in rows, e.g. ``nsos[alpha=0.9]``."""

    name: str
    params: tuple  # sorted (key, value) pairs as given by the user

    @property
    def label(self) -> str:
        if not self.params:
            return self.name
        return f"{self.name}[" + ",".join(f"{k}={v}" for k, v in self.params) + "]"

    def build(self) -> Planner:
        cls = PLANNERS[self.name]
        return cls(cls.Params(**dict(self.params)))


def expand_variants(specs, file: str = "<scenario>", task: str | None = None) -> list[Variant]:
    """Planner entries -> variants; list-valued parameters expand into one variant per value.
    With ``task`` ("doors" or "objects"), planners for the other kind of search are refused."""
    out: list[Variant] = []
    for i, spec in enumerate(specs):
        name, params = spec.name, spec.params()
        valid = sorted(n for n, c in PLANNERS.items() if task is None or c.task == task)
        if name not in PLANNERS:
            raise ScenarioError(file, f"planners[{i}].name", f"unknown planner {name!r}; valid: {', '.join(valid)}")
        if task is not None and PLANNERS[name].task != task:
            kind = {"doors": "door", "objects": "object"}
            raise ScenarioError(file, f"planners[{i}].name", f"{name!r} is a {kind[PLANNERS[name].task]}-search planner and this is "
                                f"a {kind[task]}-search scenario; valid: {', '.join(valid)}")
        keys = sorted(params)
        values = [v if isinstance(v, list) else [v] for v in (params[k] for k in keys)]
        for combo in itertools.product(*values):
            p = tuple(zip(keys, combo))
            try:
                PLANNERS[name].Params(**dict(p))
            except ValidationError as exc:
                e = exc.errors()[0]
                loc = ".".join(str(x) for x in e["loc"])
                raise ScenarioError(file, f"planners[{i}].{loc}", e["msg"] if e["type"] != "extra_forbidden" else f"unknown parameter for planner {name!r}") from None
            v = Variant(name, p)
            if v not in out:
                out.append(v)
    return out
