"""A loaded scenario and its runs: goals x planner variants x seeds.

A run's randomness comes only from its episode and repeat (:func:`semsearch_cli.tasks.episode_seed`), so rows
do not depend on the number of workers or the executor.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..config import Scenario, all_fields, load_scenario, parse_scenario
from ..config.fingerprint import FINGERPRINTED, drop_new_defaults
from ..engine import ENGINE
from ..errors import ScenarioError
from ..files import safe_chars
from ..planners import Variant
from ..tasks import Task, build_task
from ..tasks.episodes import Episode
from ..world.ground_truth import World


@dataclass(frozen=True)
class RunSpec:
    """One run: repeat ``seed`` of episode ``episode`` by planner variant ``variant``."""

    episode: Episode
    variant: Variant
    seed: int

    @property
    def goal(self):
        return self.episode.goal

    @property
    def key(self) -> tuple:
        return (self.variant.label, str(self.goal), int(self.episode.index), int(self.seed))

    @property
    def stem(self) -> str:
        return file_stem(self.variant.label, self.goal, self.seed, self.episode.index)


def file_stem(label: str, goal, seed=None, episode=None) -> str:
    """File-name stem of a run (or, without seed, of a goal x variant): one path component
    whatever the planner label or goal holds (a KTH room's second door is the goal ``2512/2``)."""
    safe = label.replace("[", "_").replace("]", "").replace("=", "").replace(",", "_")
    stem = f"{safe}__goal{goal}" + (f"__ep{episode}" if episode is not None else "") + (f"__seed{seed}" if seed is not None else "")
    return safe_chars(stem)


def check_file_stems(task: Task, file: str) -> None:
    """Refuse a scenario two of whose planner variants, or two of whose goals, would share the
    files of a run (paths/, traces/, frames/ name them by :func:`file_stem`): a planner of one's
    own named ``nsos_alpha0.9`` beside nsos at alpha 0.9, goals ``2512/2`` and ``2512_2``."""
    for field, items, stem in (("planners", [v.label for v in task.variants()], lambda x: file_stem(x, "")),
                               ("goals", [str(g) for g in task.goals], lambda x: file_stem("", x))):
        seen: dict[str, str] = {}
        for item in items:
            other = seen.setdefault(stem(item), item)
            if other != item:
                raise ScenarioError(file, field, f"{other!r} and {item!r} would write their runs' files under one name "
                                    f"({stem(item)}); rename one of them")


@dataclass
class Loaded:
    """A scenario with its task (world, goals, shortest paths, logs), built once per process."""

    path: Path
    sc: Scenario
    task: Task
    _fingerprint: str | None = field(default=None, repr=False, compare=False)

    @classmethod
    def load(cls, path: str | Path, data: dict | None = None, planners: bool = True) -> "Loaded":
        """Load the scenario file ``path``, or the document ``data`` in its place (a sweep's
        variation of it: paths in it are relative to ``path``'s folder). Without ``planners`` its
        planner entries are left out (their files are not loaded): what a replay from decisions
        needs (the fingerprint does not depend on them)."""
        path = Path(path)
        sc = load_scenario(path) if data is None else parse_scenario(data, path)
        if not planners:
            sc = sc.model_copy(update={"planners": []})
        task = build_task(sc, None, path)  # in the world its kind builds
        check_file_stems(task, str(path))
        return cls(path, sc, task)

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
        its fingerprint), and the simulator engine (:mod:`semsearch_cli.engine`) from engine 2 on.
        A field added after 0.3.0 enters only when the scenario sets it away from its default
        (:mod:`semsearch_cli.config.fingerprint`), so a new field orphans no results folder. Rows
        carry it, and a batch resumes only rows that match."""
        if self._fingerprint is None:
            h = hashlib.sha256(json.dumps(self.canonical(), sort_keys=True).encode())
            self._fingerprint = h.hexdigest()[:16]
        return self._fingerprint

    def canonical(self, known: frozenset = FINGERPRINTED) -> dict:
        """What the fingerprint hashes (``known``: the fields that enter even at their defaults)."""
        # one canonical form whatever the kind's model: every kind's sections (null where this
        # kind has none), and ``kind`` only as written (null when the sections said it)
        # (semsearch's own kinds' fields: a kind another package adds moves no other kind's fingerprint)
        d = dict.fromkeys(all_fields(built_in=True)) | self.sc._retired | self.sc.model_dump(mode="json")
        d = drop_new_defaults(d, self.sc.model_dump(mode="json", exclude_defaults=True), known)
        if "kind" not in self.sc.model_fields_set:
            d["kind"] = None
        for key in ("planners", "goals"):  # the name stays: rows of a renamed copy are not resumed under the old name
            d.pop(key, None)
        for key in ("seeds", "out", "run_time_limit"):
            d["experiment"].pop(key, None)
        d = files_by_content(d, self.path.parent)
        if ENGINE > 1:  # engine 1's fingerprints are as they always were; a later engine's differ from them
            d["engine"] = ENGINE
        return d

    def with_planners(self, specs) -> "Loaded":
        """The same scenario with other planner entries (checked for this kind of search)."""
        sc = self.sc.model_copy(update={"planners": specs})
        self.task.variants(specs)
        self.task.sc = sc
        return Loaded(self.path, sc, self.task)


def files_by_content(d, base: Path):
    """The scenario document ``d`` with each string that names an existing file (relative to
    ``base``) replaced by a hash of the file's bytes."""
    if isinstance(d, dict):
        return {k: files_by_content(v, base) for k, v in d.items()}
    if isinstance(d, list):
        return [files_by_content(v, base) for v in d]
    if isinstance(d, str) and ("." in d or "/" in d) and len(d) < 4096:
        try:
            p = base / d
            if p.is_file():
                return "file:" + hashlib.sha256(p.read_bytes()).hexdigest()
        except OSError:
            pass
    return d


class RunList(Sequence):
    """episodes x planner variants x repeats, in that nesting order, as a sequence computed on
    demand: its length and any item come from arithmetic, so a list of a billion runs costs no
    memory (a batch streams it to the workers)."""

    def __init__(self, episodes: list[Episode], variants: list[Variant], seeds: int):
        self.episodes, self.variants, self.seeds = list(episodes), list(variants), int(seeds)
        self._labels = {v.label for v in self.variants}
        self._episode_keys = {(str(e.goal), e.index) for e in self.episodes}

    @property
    def goals(self) -> list:
        return list(dict.fromkeys(e.goal for e in self.episodes))

    def __len__(self) -> int:
        return len(self.episodes) * len(self.variants) * self.seeds

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        n = len(self)
        if not -n <= i < n:
            raise IndexError(i)
        i %= n
        per_episode = len(self.variants) * self.seeds
        return RunSpec(self.episodes[i // per_episode], self.variants[(i // self.seeds) % len(self.variants)], i % self.seeds)

    def __iter__(self):
        for e in self.episodes:
            for v in self.variants:
                for s in range(self.seeds):
                    yield RunSpec(e, v, s)

    def has_key(self, key: tuple) -> bool:
        """Whether the run ``(label, goal, episode, seed)`` (:attr:`RunSpec.key`) is in the list."""
        label, goal, episode, seed = key
        return label in self._labels and (str(goal), int(episode)) in self._episode_keys and 0 <= int(seed) < self.seeds


def expand(loaded: Loaded, seeds: int | None = None, goals=None, planners=None) -> RunList:
    """episodes x planner variants x repeats, in that nesting order (a :class:`RunList`);
    ``goals`` keeps the episodes of those goals, ``planners`` the variants of those names."""
    variants = loaded.task.variants()
    if planners:
        variants = [v for v in variants if v.name in planners or v.label in planners]
    keep = None if goals is None else {str(x) for x in goals}
    eps = [e for e in loaded.task.episodes if keep is None or str(e.goal) in keep]
    return RunList(eps, variants, seeds or loaded.sc.experiment.seeds)
