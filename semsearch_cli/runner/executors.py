"""Executors: where runs run. Each yields the rows of every run it is given as the runs finish;
the batch appends them to runs.csv. ``serial`` runs in this process, ``processes`` in a pool of
worker processes that each receive the loaded scenario once."""

from __future__ import annotations

import importlib
import importlib.util
import itertools
import math
import multiprocessing
import os
import signal
import threading
import time
import traceback
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np

from ..errors import BatchStopped, RunTimeout, ScenarioError
from ..tasks import RunResult
from ..tasks.loop import running
from .specs import Loaded, RunSpec
from .store import save_run_files


def execute(loaded: Loaded, spec: RunSpec, trace: bool = False) -> tuple[list[dict], RunResult]:
    """Run one spec; returns (rows, result). A planner that raises or exits (``sys.exit``
    included) gives one row with outcome ``error`` and the message; a run past
    ``experiment.run_time_limit`` s of wall-clock time, one with outcome ``timeout``; either
    way the rest of the batch goes on."""
    task = loaded.task
    limit = loaded.sc.experiment.run_time_limit
    empty = np.zeros((0, 2), np.float32)
    running(f"{spec.variant.label} goal {spec.episode.goal} episode {spec.episode.index} seed {spec.seed}")
    try:
        with wall_clock_limit(limit):
            res = task.run(spec.variant, spec.episode, spec.seed, trace)
    except RunTimeout:
        res = RunResult("timeout", math.nan, 0, 0, limit, empty,
                        message=f"the run took longer than {limit:g} s of wall-clock time (experiment.run_time_limit)")
    except (Exception, SystemExit) as exc:  # a user's planner (or a bug): recorded, not fatal to the batch
        where = traceback.extract_tb(exc.__traceback__)[-1]
        msg = f"{type(exc).__name__}: {exc} ({Path(where.filename).name}:{where.lineno})"
        res = RunResult("error", math.nan, 0, 0, 0.0, empty, message=msg)
    finally:
        running(None)
    return task.rows(spec.variant, spec.episode, spec.seed, res), res


@contextmanager
def wall_clock_limit(seconds: float):
    """Raise :class:`RunTimeout` in the block after ``seconds`` of wall-clock time (SIGALRM;
    only in a process's main thread, where signals arrive: not on Dask's worker threads)."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        yield
        return

    def alarm(signum, frame):
        raise RunTimeout()

    before = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, before)


NO_PATH = ("error", "timeout")  # outcomes of runs that leave no path to save


def _run_and_save(loaded: Loaded, spec: RunSpec, out: Path, trace: bool) -> list[dict]:
    rows, res = execute(loaded, spec, trace)
    if res.outcome not in NO_PATH:
        save_run_files(out, spec.stem, res)
    return rows


class Executor:
    """What every executor gives the runner: ``rows(loaded, specs, out, trace)`` yields each run's
    rows as it finishes. An executor is also a context manager: inside ``with`` it may keep what
    it starts (a cluster) for several batches (a sweep's values); outside, each batch starts and
    stops its own. Nothing to keep here."""

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None


class SerialExecutor(Executor):
    """Runs in this process, in order."""

    def __init__(self, workers: int = 1):
        self.workers = 1

    def rows(self, loaded: Loaded, specs: Iterable[RunSpec], out: Path, trace: bool) -> Iterator[list[dict]]:
        for spec in specs:
            yield _run_and_save(loaded, spec, out, trace)


_CACHE: dict = {}  # the batch's Loaded scenario, handed to each worker process once


def _worker_init(loaded: Loaded) -> None:
    # Ctrl-C reaches every process of the terminal's group: the batch (the parent) handles it and
    # stops the workers, which would otherwise each print a KeyboardInterrupt traceback
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the parent's handler is not the worker's
    _CACHE["loaded"] = loaded
    threading.Thread(target=_die_with, args=(os.getppid(),), daemon=True, name="semsearch-parent-watch").start()


def _die_with(parent: int) -> None:
    """A worker's watch: when its parent is gone (killed, even by SIGKILL, which no handler sees),
    the worker is re-parented, and it exits at once rather than run on, orphaned."""
    while os.getppid() == parent:
        time.sleep(WATCH_S)
    os._exit(1)


WATCH_S = 0.5  # s between a worker's looks at its parent


def _worker_run(spec: RunSpec, out: str, trace: bool) -> list[dict]:
    return _run_and_save(_CACHE["loaded"], spec, Path(out), trace)


class ProcessExecutor(Executor):
    """A pool of ``workers`` processes; the loaded scenario is sent to each once. ``start_method``
    (``fork``, ``spawn``, ``forkserver``; default: Python's for the platform) is how they start: a
    spawned worker unpickles the scenario in a fresh interpreter, and a planner from the user's
    own file is loaded there again by its path when its variant is built.

    Runs are handed out as workers free up, a few per worker ahead, so the list of runs is
    streamed, never held whole. When the batch stops early (Ctrl-C, an error in the parent), the
    workers are stopped at once and their unfinished runs dropped."""

    def __init__(self, workers: int, start_method: str | None = None):
        self.workers = workers
        self.context = multiprocessing.get_context(start_method)

    def rows(self, loaded: Loaded, specs: Iterable[RunSpec], out: Path, trace: bool) -> Iterator[list[dict]]:
        specs = iter(specs)
        ahead = 2 * self.workers
        pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=self.context, initializer=_worker_init,
                                   initargs=(loaded,))
        running = {pool.submit(_worker_run, s, str(out), trace) for s in itertools.islice(specs, ahead)}
        try:
            while running:
                finished, running = wait(running, return_when=FIRST_COMPLETED)
                broken = [f for f in finished if isinstance(f.exception(), BrokenProcessPool)]
                for f in finished:  # the runs that did finish are kept, even beside a dead worker
                    if f not in broken:
                        yield f.result()
                if broken:
                    raise broken[0].exception()
                running |= {pool.submit(_worker_run, s, str(out), trace) for s in itertools.islice(specs, len(finished))}
        except BrokenProcessPool:
            self._stop(pool, running)
            raise BatchStopped("a worker process died (killed by a signal, or by the system for lack of memory), "
                               "and the pool cannot go on") from None
        except BaseException:
            self._stop(pool, running)
            raise
        pool.shutdown()

    @staticmethod
    def _stop(pool: ProcessPoolExecutor, running) -> None:
        """Stop the workers at once, dropping their unfinished runs (no public call stops a pool's
        processes; 3.14 adds one); joining the manager thread leaves nothing to wake at exit."""
        for f in running:
            f.cancel()
        for proc in list((getattr(pool, "_processes", None) or {}).values()):
            proc.terminate()
        pool.shutdown(wait=True, cancel_futures=True)


EXECUTORS = ("processes", "dask")
# executors on optional dependencies, by name: the module holding each (imported on demand, so
# that a command that does not use Dask does not pay for importing it) and its class
OPTIONAL = {"dask": ("semsearch_cli.runner.cluster", "DaskExecutor", "distributed", "dask")}


def check_kind(kind: str) -> None:
    """A :class:`ScenarioError` for ``--executor`` unless ``kind`` is one of :data:`EXECUTORS`."""
    if kind not in EXECUTORS:
        raise ScenarioError("<command line>", "--executor", f"unknown executor {kind!r}; valid: {', '.join(EXECUTORS)}")


def make_executor(workers: int, start_method: str | None = None, kind: str = "processes", address: str | None = None,
                  chunk: int = 4):
    """An executor: ``processes`` (the default) is a process pool for more than one worker, else
    the serial executor; ``dask`` runs on the Dask scheduler at ``address``, or on a local
    cluster of ``workers`` processes (see :class:`~semsearch_cli.runner.cluster.DaskExecutor`)."""
    check_kind(kind)
    if kind in OPTIONAL:
        module, cls, package, extra = OPTIONAL[kind]
        if importlib.util.find_spec(package) is None:
            raise ScenarioError("<command line>", "--executor", f"{kind} needs the {package} package: "
                                f"pip install 'semsearch[{extra}]'")
        return getattr(importlib.import_module(module), cls)(workers, address, chunk)
    return ProcessExecutor(workers, start_method) if workers > 1 else SerialExecutor()
