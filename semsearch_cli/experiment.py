"""Expand a scenario into runs, run them in parallel processes, append rows, resume (SPEC 9).

Each finished run is appended to ``runs.csv`` at once (and its path to ``paths/``), so an
interrupted batch keeps every finished run; a rerun skips the (planner, goal, seed) rows already
there. Rows do not depend on the number of workers: a run's randomness comes only from its own
seed (:func:`semsearch_cli.episode.run_seed`).
"""

from __future__ import annotations

import csv
import json
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .config import Scenario, load_scenario
from .episode import Episode
from .metrics import COLUMNS, run_row
from .planners import Variant, expand_variants
from .world.scenario import World, build_world, check_goals_reachable


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
    """File-name stem of a run (or, without seed, of a goal x variant)."""
    safe = label.replace("[", "_").replace("]", "").replace("=", "").replace(",", "_")
    return f"{safe}__goal{goal}" + (f"__seed{seed}" if seed is not None else "")


@dataclass
class Loaded:
    """A scenario with its world and the shortest path of each goal, built once per process.

    For object search, ``task`` holds the places, cases and requests, ``logs`` each case's
    detection log (recorded once, here), and the goals are the request labels (``Static.mug@12``).
    """

    path: Path
    sc: Scenario
    world: World
    shortest: dict
    task: object = None
    logs: dict | None = None

    @property
    def goals(self) -> list:
        return [r.label for r in self.task.requests] if self.task is not None else list(self.sc.goals)

    @classmethod
    def load(cls, path: Path) -> "Loaded":
        sc = load_scenario(path)
        world = build_world(sc, path.parent, str(path))
        if sc.is_objects:
            from .objects.task import ObjectTask

            task = ObjectTask(sc, world, path.parent, str(path))
            logs = {c.name: task.log(c) for c in task.cases}
            shortest = {r.label: task.shortest(r) for r in task.requests}
            loaded = cls(path, sc, world, shortest, task, logs)
        else:
            loaded = cls(path, sc, world, check_goals_reachable(world, sc.goals, str(path)))
        loaded.check_planners()
        return loaded

    @property
    def kind(self) -> str:
        return "objects" if self.sc.is_objects else "doors"

    def check_planners(self) -> None:
        """Every planner entry must name a planner for this kind of search, with valid parameters."""
        expand_variants(self.sc.planners, str(self.path), self.kind)


_CACHE: dict = {}  # the batch's Loaded scenario, handed to each worker process once


def _worker_init(loaded: Loaded) -> None:
    _CACHE["loaded"] = loaded


def execute(loaded: Loaded, spec: RunSpec, trace: bool = False):
    """Run one spec; returns (row, result)."""
    if loaded.task is not None:
        from .objects.search import ObjectEpisode

        req = loaded.task.request(spec.goal)
        res = ObjectEpisode(loaded.task, spec.variant, req, loaded.logs[req.case], spec.seed, trace).run()
    else:
        res = Episode(loaded.world, loaded.sc, spec.variant, spec.goal, spec.seed, trace=trace).run()
    row = run_row(loaded.sc.name, spec.variant, spec.goal, spec.seed, res, loaded.shortest[spec.goal], loaded.sc.navigation.navigator)
    return row, res


def _worker_run(spec: RunSpec, out: str, trace: bool):
    row, res = execute(_CACHE["loaded"], spec, trace)
    save_run_files(Path(out), spec, res)
    return row


def save_run_files(out: Path, spec: RunSpec, res) -> None:
    """``paths/<stem>.npz`` (path, signs read) and, for traced runs, ``traces/<stem>.jsonl``
    (one JSON object per decision); each written atomically."""
    paths = out / "paths"
    paths.mkdir(parents=True, exist_ok=True)
    tmp = paths / f".{spec.stem}.tmp.npz"
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, path=res.path, read_signs=np.asarray(res.read_signs, np.int64))
    os.replace(tmp, paths / f"{spec.stem}.npz")
    if res.trace:
        traces = out / "traces"
        traces.mkdir(parents=True, exist_ok=True)
        tmp = traces / f".{spec.stem}.tmp.jsonl"
        with open(tmp, "w") as fh:
            for d in res.trace:
                fh.write(json.dumps(d) + "\n")
        os.replace(tmp, traces / f"{spec.stem}.jsonl")


def expand(loaded: Loaded, seeds: int | None = None, goals=None, planners=None) -> list[RunSpec]:
    """goals x planner variants x seeds, in that nesting order."""
    sc = loaded.sc
    variants = expand_variants(sc.planners, str(loaded.path), loaded.kind)
    if planners:
        variants = [v for v in variants if v.name in planners or v.label in planners]
    gl = [g for g in loaded.goals if goals is None or str(g) in {str(x) for x in goals}]
    n = seeds or sc.experiment.seeds
    return [RunSpec(g, v, s) for g in gl for v in variants for s in range(n)]


def read_runs(path: Path) -> pd.DataFrame:
    """runs.csv as a DataFrame (empty with the columns when absent); a torn last line is dropped."""
    if not path.is_file() or path.stat().st_size == 0:
        return pd.DataFrame(columns=COLUMNS)
    df = pd.read_csv(path, on_bad_lines="skip")
    return df.dropna(subset=["wall_s"])


class RowWriter:
    """Appends rows to runs.csv, flushing each to disk as it arrives."""

    def __init__(self, path: Path):
        path.parent.mkdir(parents=True, exist_ok=True)
        new = not path.is_file() or path.stat().st_size == 0
        if not new:  # repair a file cut mid-line by an interruption
            with open(path, "rb+") as fh:
                fh.seek(-1, os.SEEK_END)
                if fh.read(1) != b"\n":
                    fh.write(b"\n")
        self.fh = open(path, "a", newline="")
        self.w = csv.DictWriter(self.fh, fieldnames=COLUMNS)
        if new:
            self.w.writeheader()
            self.fh.flush()

    def write(self, row: dict) -> None:
        self.w.writerow(row)
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


def run_batch(loaded: Loaded, specs: list[RunSpec], out: Path, workers: int = 1,
              progress: Callable[[dict], None] | None = None, trace: bool = False) -> pd.DataFrame:
    """Run the specs not yet in ``out/runs.csv``; returns all rows of the file afterwards.
    With ``trace``, each run it runs also writes its decision trace to ``out/traces/``."""
    runs_csv = out / "runs.csv"
    done = read_runs(runs_csv)
    have = {(str(p), str(g), int(s)) for p, g, s in zip(done["planner"], done["goal"], done["seed"])} if len(done) else set()
    todo = [s for s in specs if s.key not in have]
    writer = RowWriter(runs_csv)
    try:
        if workers <= 1 or len(todo) <= 1:
            for spec in todo:
                row, res = execute(loaded, spec, trace)
                save_run_files(out, spec, res)
                writer.write(row)
                if progress:
                    progress(row)
        else:
            with ProcessPoolExecutor(max_workers=workers, initializer=_worker_init, initargs=(loaded,)) as pool:
                futs = [pool.submit(_worker_run, spec, str(out), trace) for spec in todo]
                try:
                    for f in as_completed(futs):
                        row = f.result()
                        writer.write(row)
                        if progress:
                            progress(row)
                except BaseException:
                    for f in futs:
                        f.cancel()
                    raise
    finally:
        writer.close()
    return read_runs(runs_csv)
