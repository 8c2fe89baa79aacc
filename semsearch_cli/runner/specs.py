"""A loaded scenario and its runs: goals x planner variants x seeds (SPEC 9).

A run's randomness comes only from its own seed (:func:`semsearch_cli.tasks.run_seed`), so rows
do not depend on the number of workers or the executor.
"""

from __future__ import annotations

import re
import hashlib
import json
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


def expand(loaded: Loaded, seeds: int | None = None, goals=None, planners=None) -> list[RunSpec]:
    """goals x planner variants x seeds, in that nesting order."""
    variants = loaded.task.variants()
    if planners:
        variants = [v for v in variants if v.name in planners or v.label in planners]
    gl = [g for g in loaded.goals if goals is None or str(g) in {str(x) for x in goals}]
    n = seeds or loaded.sc.experiment.seeds
    return [RunSpec(g, v, s) for g in gl for v in variants for s in range(n)]
