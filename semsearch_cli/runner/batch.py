"""A batch: run the specs not yet in ``runs.csv`` on an executor, appending each run's rows as it
finishes, so an interrupted batch keeps every finished run and resumes where it stopped."""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Sequence

import pandas as pd

from ..errors import ScenarioError
from .executors import Executor, SerialExecutor, make_executor
from .lock import folder_lock
from .specs import Loaded, RunSpec
from .store import RowWriter, read_runs, run_rows


def check_folder(loaded: Loaded, out: Path, force: bool = False) -> pd.DataFrame:
    """The rows of ``out/runs.csv`` that a batch of ``loaded`` may resume (see :func:`run_batch`);
    a :class:`ScenarioError` when they were made with another scenario, unless ``force``."""
    runs_csv = out / "runs.csv"
    done = run_rows(read_runs(runs_csv))
    fp = loaded.fingerprint
    foreign = len(done) and ("fingerprint" not in done.columns or (done["fingerprint"].astype(str) != fp).any())
    if foreign and not force:
        raise ScenarioError(str(runs_csv), "fingerprint", f"these rows were made with another scenario, with {loaded.path} before it was edited, "
                            "or by an older semsearch, so they cannot be resumed; write into a fresh folder with --out, "
                            "or re-run everything here with --force (the old runs.csv is kept as runs.<n>.csv.bak)")
    if foreign:
        n = 1
        while (out / f"runs.{n}.csv.bak").exists():
            n += 1
        runs_csv.rename(out / f"runs.{n}.csv.bak")
        done = run_rows(read_runs(runs_csv))
    return done


def run_batch(loaded: Loaded, specs: Sequence[RunSpec], out: Path, workers: int = 1,
              progress: Callable[[dict, int, int], None] | None = None, trace: bool = False,
              start_method: str | None = None, force: bool = False, executor: str = "processes",
              scheduler: str | None = None, runner: Executor | None = None) -> pd.DataFrame:
    """Run the specs not yet in ``out/runs.csv``; returns all rows of the file afterwards.
    With ``trace``, each run it runs also writes its decision trace to ``out/traces/``;
    ``start_method`` is the worker processes' (see :class:`ProcessExecutor`); ``executor`` is
    ``processes`` or ``dask`` (on the scheduler at ``scheduler``, or a local cluster of
    ``workers``), see :func:`make_executor`: rows do not depend on it, and a batch started on one
    resumes on another; ``runner``, an executor the caller made (and entered), e.g. one Dask
    cluster for every value of a sweep, replaces both. ``progress(row, done, total)`` is called as
    each run finishes, with the runs finished so far and the runs this batch has to do. The specs
    are streamed to the executor, never listed whole (a
    :class:`~semsearch_cli.runner.specs.RunList` of any length costs no memory).

    The folder is locked for the batch (see :func:`folder_lock`). Rows carry the scenario's
    fingerprint (:attr:`Loaded.fingerprint`); rows of another scenario (or an edited one) in the
    folder are refused, unless ``force``, which moves that runs.csv aside (kept as
    ``runs.<n>.csv.bak``) and starts afresh."""
    runs_csv = out / "runs.csv"
    fp = loaded.fingerprint
    with folder_lock(out):
        done = check_folder(loaded, out, force)
        have = {(str(p), str(g), int(s)) for p, g, s in zip(done["planner"], done["goal"], done["seed"])} if len(done) else set()
        has = getattr(specs, "has_key", None) or {s.key for s in specs}.__contains__
        total = len(specs) - sum(1 for k in have if has(k))
        todo = (s for s in specs if s.key not in have)
        if runner is None:
            serial = total == 0 or (executor == "processes" and total == 1)
            runner = SerialExecutor() if serial else make_executor(max(1, min(workers, total)), start_method, executor, scheduler)
        writer = RowWriter(runs_csv)
        n = 0
        try:
            for rows in runner.rows(loaded, todo, out, trace):
                for r in rows:
                    r["fingerprint"] = fp
                writer.write(rows)
                n += 1
                if progress:
                    progress(rows[0], n, total)
        finally:
            writer.close()
        return read_runs(runs_csv)
