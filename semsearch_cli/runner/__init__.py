"""The runner: run specs and seeds, executors, the row store (append, resume)."""

from .batch import Batch, check_folder, run_batch
from .lock import folder_lock
from .options import BatchOptions, workers_for
from .execution import execute
from .executors import EXECUTORS, ProcessExecutor, SerialExecutor, check_kind, make_executor
from .specs import Loaded, RunSpec, expand, file_stem
from . import cluster  # noqa: F401  (registers the dask executor; Dask itself is imported at first use)
from .store import RowWriter, read_runs, run_rows, save_run_files

__all__ = ["Batch", "BatchOptions", "EXECUTORS", "Loaded", "check_folder", "check_kind", "ProcessExecutor", "RowWriter", "RunSpec", "SerialExecutor", "execute", "expand", "file_stem", "folder_lock",
           "make_executor", "read_runs", "run_batch", "run_rows", "save_run_files", "workers_for"]
