"""Executors: where runs run. Each yields the rows of every run it is given as the runs finish;
the batch appends them to runs.csv. ``serial`` runs in this process, ``processes`` in a pool of
worker processes that each receive the loaded scenario once."""

from __future__ import annotations

import math
import multiprocessing
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Iterator

import numpy as np

from ..tasks import RunResult
from .specs import Loaded, RunSpec
from .store import save_run_files


def execute(loaded: Loaded, spec: RunSpec, trace: bool = False) -> tuple[list[dict], RunResult]:
    """Run one spec; returns (rows, result). A planner that raises gives one row with outcome
    ``error`` and the message, so the rest of the batch goes on."""
    task = loaded.task
    try:
        res = task.run(spec.variant, spec.goal, spec.seed, trace)
    except Exception as exc:  # a user's planner (or a bug): recorded, not fatal to the batch
        where = traceback.extract_tb(exc.__traceback__)[-1]
        msg = f"{type(exc).__name__}: {exc} ({Path(where.filename).name}:{where.lineno})"
        res = RunResult("error", math.nan, 0, 0, 0.0, np.zeros((0, 2), np.float32), message=msg)
    return task.rows(spec.variant, spec.goal, spec.seed, res), res


def _run_and_save(loaded: Loaded, spec: RunSpec, out: Path, trace: bool) -> list[dict]:
    rows, res = execute(loaded, spec, trace)
    if res.outcome != "error":
        save_run_files(out, spec.stem, res)
    return rows


class SerialExecutor:
    """Runs in this process, in order."""

    def __init__(self, workers: int = 1):
        self.workers = 1

    def rows(self, loaded: Loaded, specs: list[RunSpec], out: Path, trace: bool) -> Iterator[list[dict]]:
        for spec in specs:
            yield _run_and_save(loaded, spec, out, trace)


_CACHE: dict = {}  # the batch's Loaded scenario, handed to each worker process once


def _worker_init(loaded: Loaded) -> None:
    _CACHE["loaded"] = loaded


def _worker_run(spec: RunSpec, out: str, trace: bool) -> list[dict]:
    return _run_and_save(_CACHE["loaded"], spec, Path(out), trace)


class ProcessExecutor:
    """A pool of ``workers`` processes; the loaded scenario is sent to each once. ``start_method``
    (``fork``, ``spawn``, ``forkserver``; default: Python's for the platform) is how they start: a
    spawned worker unpickles the scenario in a fresh interpreter, and a planner from the user's
    own file is loaded there again by its path when its variant is built."""

    def __init__(self, workers: int, start_method: str | None = None):
        self.workers = workers
        self.context = multiprocessing.get_context(start_method)

    def rows(self, loaded: Loaded, specs: list[RunSpec], out: Path, trace: bool) -> Iterator[list[dict]]:
        with ProcessPoolExecutor(max_workers=self.workers, mp_context=self.context, initializer=_worker_init,
                                 initargs=(loaded,)) as pool:
            futs = [pool.submit(_worker_run, spec, str(out), trace) for spec in specs]
            try:
                for f in as_completed(futs):
                    yield f.result()
            except BaseException:
                for f in futs:
                    f.cancel()
                raise


def make_executor(workers: int, start_method: str | None = None):
    """The process pool for more than one worker, else the serial executor."""
    return ProcessExecutor(workers, start_method) if workers > 1 else SerialExecutor()
