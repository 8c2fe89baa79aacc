"""A batch: run the specs not yet in ``runs.csv`` on an executor, appending each run's rows as it
finishes, so an interrupted batch keeps every finished run and resumes where it stopped."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import pandas as pd

from .executors import SerialExecutor, make_executor
from .specs import Loaded, RunSpec
from .store import RowWriter, read_runs, run_rows


def run_batch(loaded: Loaded, specs: list[RunSpec], out: Path, workers: int = 1,
              progress: Callable[[dict], None] | None = None, trace: bool = False,
              start_method: str | None = None) -> pd.DataFrame:
    """Run the specs not yet in ``out/runs.csv``; returns all rows of the file afterwards.
    With ``trace``, each run it runs also writes its decision trace to ``out/traces/``;
    ``start_method`` is the worker processes' (see :class:`ProcessExecutor`)."""
    runs_csv = out / "runs.csv"
    done = run_rows(read_runs(runs_csv))
    have = {(str(p), str(g), int(s)) for p, g, s in zip(done["planner"], done["goal"], done["seed"])} if len(done) else set()
    todo = [s for s in specs if s.key not in have]
    executor = make_executor(workers, start_method) if len(todo) > 1 else SerialExecutor()
    writer = RowWriter(runs_csv)
    try:
        for rows in executor.rows(loaded, todo, out, trace):
            writer.write(rows)
            if progress:
                progress(rows[0])
    finally:
        writer.close()
    return read_runs(runs_csv)
