"""The runner: run specs and seeds, executors, the row store (append, resume)."""

from .batch import run_batch
from .executors import ProcessExecutor, SerialExecutor, execute, make_executor
from .specs import Loaded, RunSpec, expand, file_stem
from .store import RowWriter, read_runs, run_rows, save_run_files

__all__ = ["Loaded", "ProcessExecutor", "RowWriter", "RunSpec", "SerialExecutor", "execute", "expand", "file_stem",
           "make_executor", "read_runs", "run_batch", "run_rows", "save_run_files"]
