"""What every executor shares: running one spec (errors and time limits recorded as rows, never
fatal to the batch), saving its path, and the :class:`Executor` protocol. The executors
themselves are in :mod:`.executors` (serial, processes) and :mod:`.cluster` (Dask)."""

from __future__ import annotations

import math
import signal
import threading
import traceback
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..engine import ENGINE
from ..errors import UNAVAILABLE, MissingExtra, RunTimeout, Unavailable
from ..kernels import announce_compiling
from ..tasks import FrameRecorder, Observers, RunResult, TraceObserver
from ..tasks.decisions import Recording, Seat
from ..tasks.loop import running
from .specs import Loaded, RunSpec
from .store import decisions_digest, save_run_files


@dataclass(frozen=True)
class Watch:
    """What a batch keeps of each run beside its rows: its decisions' ``trace`` (traces/<run>.jsonl),
    its replay's ``frames`` (frames/<run>.npz, which a report replays without re-running) and its
    ``decisions`` (decisions/<run>.json, the choices that replay it without its planner:
    :mod:`semsearch_cli.tasks.decisions`, ``semsearch verify``) and its planner's ``transcripts``
    (transcripts/<run>.jsonl: a language model's prompts and replies, which replay it offline:
    :mod:`semsearch_cli.planners.llm`)."""

    trace: bool = False
    frames: bool = False
    decisions: bool = False
    transcripts: bool = False


def execute(loaded: Loaded, spec: RunSpec, watch: Watch = Watch()) -> tuple[list[dict], RunResult]:
    """Run one spec; returns (rows, result). A planner that raises or exits (``sys.exit``
    included) gives one row with outcome ``error`` and the message; a run past
    ``experiment.run_time_limit`` s of wall-clock time, one with outcome ``timeout``; either
    way the rest of the batch goes on. A run that failed for a cause outside it
    (:class:`~semsearch_cli.errors.Unavailable`: a service that did not answer; a missing package)
    is an ``error`` whose message starts with ``unavailable:``, which a resumed batch runs again."""
    task = loaded.task
    limit = loaded.sc.experiment.run_time_limit
    empty = np.zeros((0, 2), np.float32)
    announce_compiling()
    running(f"{spec.variant.label} goal {spec.episode.goal} episode {spec.episode.index} seed {spec.seed}")
    seat = Recording() if watch.decisions else Seat()
    try:
        with wall_clock_limit(limit):
            tracer = TraceObserver() if watch.trace else None
            recorder = FrameRecorder() if watch.frames else None
            watching = Observers(tracer, recorder) if tracer or recorder else None
            res = task.run(spec.variant, spec.episode, spec.seed, watching, seat=seat)
            if watch.decisions:
                res.decisions_record = {**seat.record(task.kind), **identity(loaded, spec)}
            if not watch.transcripts:
                res.transcripts = []
            if tracer is not None:
                res.trace = tracer.rows
            if recorder is not None:
                res.frames = recorder.frames
    except RunTimeout:
        res = RunResult("timeout", math.nan, 0, 0, limit, empty,
                        message=f"the run took longer than {limit:g} s of wall-clock time (experiment.run_time_limit)")
    except (Unavailable, MissingExtra) as exc:  # a cause outside the run: recorded, and run again by the same command
        res = RunResult("error", math.nan, 0, 0, 0.0, empty, message=f"{UNAVAILABLE}{exc}")
    except (Exception, SystemExit) as exc:  # a user's planner (or a bug): recorded, not fatal to the batch
        where = traceback.extract_tb(exc.__traceback__)[-1]
        msg = f"{type(exc).__name__}: {exc} ({Path(where.filename).name}:{where.lineno})"
        res = RunResult("error", math.nan, 0, 0, 0.0, empty, message=msg)
    finally:
        running(None)
    if res.outcome in ("error", "timeout"):  # what its planner paid for before the run failed is still counted
        res.record = {**seat.costs(), **res.record}
        res.transcripts = seat.transcripts() if watch.transcripts else []
    rows = task.rows(spec.variant, spec.episode, spec.seed, res)
    if res.decisions_record is not None:  # a bench row names its record (metrics.BENCH_COLUMNS); other folders drop it
        digest = decisions_digest(res.decisions_record)
        for r in rows:
            r["decisions_sha256"] = digest
    return rows, res


def identity(loaded: Loaded, spec: RunSpec) -> dict:
    """What names a run in its decisions record: the scenario (name, fingerprint), the simulator
    engine (:data:`semsearch_cli.engine.ENGINE`), the planner
    variant's label, the goal (as written), the episode and the repeat."""
    return {"scenario": loaded.sc.name, "fingerprint": loaded.fingerprint, "engine": ENGINE, "planner": spec.variant.label,
            "goal": str(spec.episode.goal), "episode": int(spec.episode.index), "seed": int(spec.seed)}


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


def run_and_save(loaded: Loaded, spec: RunSpec, out: Path, watch: Watch) -> list[dict]:
    rows, res = execute(loaded, spec, watch)
    save_run_files(out, spec.stem, res)  # a failed run: its transcripts alone
    return rows


class Executor:
    """What every executor gives the runner: ``rows(loaded, specs, out, watch)`` yields each run's
    rows as it finishes. An executor is also a context manager: inside ``with`` it may keep what
    it starts (a cluster) for several batches (a sweep's values); outside, each batch starts and
    stops its own. Nothing to keep here."""

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None
