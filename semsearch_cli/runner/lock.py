"""One batch per output folder at a time: an advisory lock (``fcntl.flock``) on
``<out>/.semsearch.lock``, held for the whole command, naming the process that holds it.

The lock is re-entrant within a process (a command that holds it may call :func:`run_batch`,
which takes it too). It is released when the process ends, however it ends.
"""

from __future__ import annotations

import fcntl
import os
import sys
from contextlib import contextmanager
from pathlib import Path

from ..errors import ScenarioError
from ..files import output_folder

LOCK_NAME = ".semsearch.lock"
_HELD: dict[str, int] = {}  # folder -> depth, for the locks this process holds


@contextmanager
def folder_lock(out: Path):
    """Hold the output folder ``out`` (created if needed) for this process; a
    :class:`ScenarioError` naming the holder when another process has it."""
    out = output_folder(out)
    key = str(out.resolve())
    if key in _HELD:
        _HELD[key] += 1
        try:
            yield
        finally:
            _HELD[key] -= 1
        return
    try:
        fh = open(out / LOCK_NAME, "a+")
    except OSError as exc:
        raise ScenarioError(str(out), "--out", f"cannot write into this output folder: {exc.strerror or exc}") from None
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        fh.seek(0)
        who = fh.read().strip() or "another process"
        fh.close()
        raise ScenarioError(str(out), "--out", f"this folder is in use by {who}; wait for it to finish, "
                            "or write into another folder with --out") from None
    fh.seek(0)
    fh.truncate()
    fh.write(f"process {os.getpid()} ({' '.join(os.path.basename(a) if i == 0 else a for i, a in enumerate(sys.argv))})")
    fh.flush()
    _HELD[key] = 1
    try:
        yield
    finally:
        del _HELD[key]
        fcntl.flock(fh, fcntl.LOCK_UN)
        fh.close()
