"""A loaded scenario and its runs: goals x planner variants x seeds (SPEC 9).

A run's randomness comes only from its own seed (:func:`semsearch_cli.tasks.run_seed`), so rows
do not depend on the number of workers or the executor.
"""

from __future__ import annotations

import re
import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..config import Scenario, load_scenario, parse_scenario
from ..planners import Variant
from ..tasks import Task, build_task
from ..world.scenario import World, build_world


@dataclass(frozen=True)
class RunSpec:
    goal: object
    variant: Variant
    seed: int

    @property
    def key(self) -> tuple:
        return (self.variant.label, str(self.goal), int(self.seed))

    @property
    def stem(self) -> str:
        return file_stem(self.variant.label, self.goal, self.seed)


def file_stem(label: str, goal, seed=None) -> str:
    """File-name stem of a run (or, without seed, of a goal x variant): one path component
    whatever the planner label or goal holds (a KTH room's second door is the goal ``2512/2``)."""
    safe = label.replace("[", "_").replace("]", "").replace("=", "").replace(",", "_")
    stem = f"{safe}__goal{goal}" + (f"__seed{seed}" if seed is not None else "")
    return _UNSAFE.sub("_", stem)


_UNSAFE = re.compile(r"[^A-Za-z0-9._+\-]")


@dataclass
class Loaded:
    """A scenario with its task (world, goals, shortest paths, logs), built once per process."""

    path: Path
    sc: Scenario
    task: Task
    _fingerprint: str | None = field(default=None, repr=False, compare=False)

    @classmethod
    def load(cls, path: str | Path, data: dict | None = None) -> "Loaded":
        """Load the scenario file ``path``, or the document ``data`` in its place (a sweep's
        variation of it: paths in it are relative to ``path``'s folder)."""
        path = Path(path)
        sc = load_scenario(path) if data is None else parse_scenario(data, path)
        world = build_world(sc, path.parent, str(path))
        return cls(path, sc, build_task(sc, world, path))

    @property
    def world(self) -> World:
        return self.task.world

    @property
    def kind(self) -> str:
        return self.task.kind

    @property
    def goals(self) -> list:
        return self.task.goals

    @property
    def shortest(self) -> dict:
        return self.task.shortest

    @property
    def fingerprint(self) -> str:
        """A hash of what decides a run's outcome: the resolved scenario without the run list
        (planners, goals, seeds, output folder), with every file it names (map image, doors,
        logs, ...) standing for its bytes, not its path (a scenario moved with its files keeps
        its fingerprint). Rows carry it, and a batch resumes only rows that match."""
        if self._fingerprint is None:
            d = self.sc.model_dump(mode="json")
            for key in ("planners", "goals"):
                d.pop(key, None)
            for key in ("seeds", "out"):
                d["experiment"].pop(key, None)
            d = _files_by_content(d, self.path.parent)
            h = hashlib.sha256(json.dumps(d, sort_keys=True).encode())
            self._fingerprint = h.hexdigest()[:16]
        return self._fingerprint

    def with_planners(self, specs) -> "Loaded":
        """The same scenario with other planner entries (checked for this kind of search)."""
        sc = self.sc.model_copy(update={"planners": specs})
        self.task.variants(specs)
        self.task.sc = sc
        return Loaded(self.path, sc, self.task)


def _files_by_content(d, base: Path):
    """The scenario document ``d`` with each string that names an existing file (relative to
    ``base``) replaced by a hash of the file's bytes."""
    if isinstance(d, dict):
        return {k: _files_by_content(v, base) for k, v in d.items()}
    if isinstance(d, list):
        return [_files_by_content(v, base) for v in d]
    if isinstance(d, str) and ("." in d or "/" in d) and len(d) < 4096:
        try:
            p = base / d
            if p.is_file():
                return "file:" + hashlib.sha256(p.read_bytes()).hexdigest()
        except OSError:
            pass
    return d


class RunList(Sequence):
    """goals x planner variants x seeds, in that nesting order, as a sequence computed on demand:
    its length and any item come from arithmetic, so a list of a billion runs costs no memory
    (a batch streams it to the workers)."""

    def __init__(self, goals: list, variants: list[Variant], seeds: int):
        self.goals, self.variants, self.seeds = list(goals), list(variants), int(seeds)
        self._labels = {v.label for v in self.variants}
        self._goal_keys = {str(g) for g in self.goals}

    def __len__(self) -> int:
        return len(self.goals) * len(self.variants) * self.seeds

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        n = len(self)
        if not -n <= i < n:
            raise IndexError(i)
        i %= n
        per_goal = len(self.variants) * self.seeds
        return RunSpec(self.goals[i // per_goal], self.variants[(i // self.seeds) % len(self.variants)], i % self.seeds)

    def __iter__(self):
        for g in self.goals:
            for v in self.variants:
                for s in range(self.seeds):
                    yield RunSpec(g, v, s)

    def has_key(self, key: tuple) -> bool:
        """Whether the run ``(label, goal, seed)`` (:attr:`RunSpec.key`) is in the list."""
        label, goal, seed = key
        return label in self._labels and str(goal) in self._goal_keys and 0 <= int(seed) < self.seeds


def expand(loaded: Loaded, seeds: int | None = None, goals=None, planners=None) -> RunList:
    """goals x planner variants x seeds, in that nesting order (a :class:`RunList`)."""
    variants = loaded.task.variants()
    if planners:
        variants = [v for v in variants if v.name in planners or v.label in planners]
    gl = [g for g in loaded.goals if goals is None or str(g) in {str(x) for x in goals}]
    return RunList(gl, variants, seeds or loaded.sc.experiment.seeds)
