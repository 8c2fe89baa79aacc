"""The options of a batch: which runs (seeds, goals, planners), where they go (the output folder)
and how they run (workers, executor, trace). One frozen object travels from the command line
through :mod:`semsearch_cli.api` to :func:`~semsearch_cli.runner.run_batch`; rows never depend on
how they ran."""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import ScenarioError
from ..planners.base import check_entry
from .cluster import check_address, require_dask
from .executors import check_kind

MAX_WORKERS = 512  # even with --oversubscribe


@dataclass(frozen=True)
class BatchOptions:
    """``seeds``: repeats of each episode per planner variant (None: the scenario's
    ``experiment.seeds``); ``goals``, ``planners``: only these goals, and planners by name or
    label (None: all); ``out``: the output folder (None: ``results/<name>``); ``workers``: worker
    processes (None: the CPU count, at most 4; more than the CPUs only with ``oversubscribe``);
    ``executor``: ``processes`` or ``dask``, on the Dask scheduler at ``scheduler`` or a local
    cluster of ``workers``; ``start_method``: the worker processes' (see
    :class:`~semsearch_cli.runner.ProcessExecutor`); ``trace``: write each run's decisions to
    ``traces/``; ``frames``: write each run's replay frames to ``frames/`` (a report then replays
    any run without re-running it); ``decisions``: write each run's decisions to ``decisions/``
    (``semsearch verify`` replays them without the planner); ``transcripts``: write each run's
    language-model transcript to ``transcripts/`` (the ``llm`` planner replays them offline,
    ``{name: llm, replay: DIR}``); ``force``: start afresh in a folder holding rows of another scenario (the old
    runs.csv is kept as ``runs.<n>.csv.bak``)."""

    seeds: int | None = None
    goals: tuple | list | None = None
    planners: tuple | list | None = None
    out: str | Path | None = None
    workers: int | None = None
    oversubscribe: bool = False
    executor: str = "processes"
    scheduler: str | None = None
    start_method: str | None = None
    trace: bool = False
    frames: bool = False
    decisions: bool = False
    transcripts: bool = False
    force: bool = False

    def replace(self, **changes) -> "BatchOptions":
        return dataclasses.replace(self, **changes)

    def checked(self) -> "BatchOptions":
        """These options with the worker count decided: a :class:`ScenarioError` for an unknown
        executor, a scheduler given to the process pool, more workers than the CPUs without
        ``oversubscribe``, or a planner label whose parameters its planner refuses
        (:func:`~semsearch_cli.planners.base.check_entry`). With a scheduler the cluster's own workers run the batch, and
        ``workers`` is not checked."""
        check_kind(self.executor)
        for entry in self.planners or ():  # a label no variant could have: its parameter named, a key never shown
            check_entry(str(entry))
        if self.executor == "dask":
            require_dask()  # its package, before anything is written
        if self.scheduler is not None and self.executor != "dask":
            raise ScenarioError("<command line>", "--scheduler", "a scheduler address goes with --executor dask")
        if self.scheduler is not None and not self.scheduler.strip():
            raise ScenarioError("<command line>", "--scheduler", "an empty address; give tcp://HOST:PORT")
        if self.scheduler:
            check_address(self.scheduler)  # its form, before the scenario loads
            return self.replace(workers=self.workers or 1)
        return self.replace(workers=workers_for(self.workers, self.oversubscribe))


def workers_for(workers: int | None, oversubscribe: bool = False) -> int:
    """The number of worker processes: by default the CPU count, at most 4; more workers than
    CPUs only slow each run down and multiply memory, so they are refused unless
    ``oversubscribe`` (never more than :data:`MAX_WORKERS`)."""
    cpus = os.cpu_count() or 1
    if workers is None:
        return max(1, min(4, cpus))
    if workers < 1 or workers > MAX_WORKERS or (workers > cpus and not oversubscribe):
        limit = f"at most {cpus} (the CPU count)" + (f", or up to {MAX_WORKERS} with --oversubscribe" if workers <= MAX_WORKERS else "")
        raise ScenarioError("<command line>", "--workers", f"{workers} workers on {cpus} CPUs: {limit}")
    return workers
