"""Executors: where runs run. Each yields the rows of every run it is given as the runs finish;
the batch appends them to runs.csv. ``serial`` runs in this process, ``processes`` in a pool of
worker processes that each receive the loaded scenario once."""

from __future__ import annotations

import itertools
import multiprocessing
import os
import shutil
import signal
import tempfile
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Iterable, Iterator

from ..errors import BatchStopped, ScenarioError, did_you_mean
from ..kernels import share_compiling_note
from ..registry import Registry
from .execution import Executor, Watch, run_and_save
from .specs import Loaded, RunSpec


class SerialExecutor(Executor):
    """Runs in this process, in order."""

    def __init__(self, workers: int = 1):
        self.workers = 1

    def rows(self, loaded: Loaded, specs: Iterable[RunSpec], out: Path, watch: Watch) -> Iterator[list[dict]]:
        for spec in specs:
            yield run_and_save(loaded, spec, out, watch)


_CACHE: dict = {}  # the batch's Loaded scenario, handed to each worker process once


def _worker_init(loaded: Loaded, note: str | None = None) -> None:
    share_compiling_note(note)  # the compiling note, once for the whole pool
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


def _worker_run(spec: RunSpec, out: str, watch: Watch) -> list[dict]:
    return run_and_save(_CACHE["loaded"], spec, Path(out), watch)


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

    def rows(self, loaded: Loaded, specs: Iterable[RunSpec], out: Path, watch: Watch) -> Iterator[list[dict]]:
        specs = iter(specs)
        ahead = 2 * self.workers
        note = os.path.join(tempfile.mkdtemp(prefix="semsearch-note-"), "said")
        share_compiling_note(note)
        try:
            pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=self.context, initializer=_worker_init,
                                       initargs=(loaded, note))
            running = {pool.submit(_worker_run, s, str(out), watch) for s in itertools.islice(specs, ahead)}
            try:
                while running:
                    finished, running = wait(running, return_when=FIRST_COMPLETED)
                    broken = [f for f in finished if isinstance(f.exception(), BrokenProcessPool)]
                    for f in finished:  # the runs that did finish are kept, even beside a dead worker
                        if f not in broken:
                            yield f.result()
                    if broken:
                        raise broken[0].exception()
                    running |= {pool.submit(_worker_run, s, str(out), watch) for s in itertools.islice(specs, len(finished))}
            except BrokenProcessPool:
                self._stop(pool, running)
                raise BatchStopped("a worker process died (killed by a signal, or by the system for lack of memory), "
                                   "and the pool cannot go on") from None
            except BaseException:
                self._stop(pool, running)
                raise
            pool.shutdown()
        finally:
            share_compiling_note(None)
            shutil.rmtree(os.path.dirname(note), ignore_errors=True)

    @staticmethod
    def _stop(pool: ProcessPoolExecutor, running) -> None:
        """Stop the workers at once, dropping their unfinished runs (no public call stops a pool's
        processes; 3.14 adds one); joining the manager thread leaves nothing to wake at exit."""
        for f in running:
            f.cancel()
        for proc in list((getattr(pool, "_processes", None) or {}).values()):
            proc.terminate()
        pool.shutdown(wait=True, cancel_futures=True)


# --executor name -> a factory called with (workers, start_method, address, chunk) that returns an Executor
EXECUTORS = Registry("executor")
register_executor = EXECUTORS.register


@register_executor("processes")
def process_executor(workers: int, start_method: str | None, address: str | None, chunk: int) -> Executor:
    """A process pool for more than one worker, else the serial executor."""
    return ProcessExecutor(workers, start_method) if workers > 1 else SerialExecutor()


def check_kind(kind: str) -> None:
    """A :class:`ScenarioError` for ``--executor`` unless ``kind`` is one of :data:`EXECUTORS`."""
    if kind not in EXECUTORS:
        raise ScenarioError("<command line>", "--executor", f"unknown executor {kind!r}{did_you_mean(kind, EXECUTORS)}; valid: {', '.join(EXECUTORS)}")


def make_executor(workers: int, start_method: str | None = None, kind: str = "processes", address: str | None = None,
                  chunk: int = 4) -> Executor:
    """An executor: ``processes`` (the default) is a process pool for more than one worker, else
    the serial executor; ``dask`` (:mod:`.cluster`) runs on the Dask scheduler at ``address``, or
    on a local cluster of ``workers`` processes."""
    check_kind(kind)
    return EXECUTORS[kind](workers, start_method, address, chunk)
