"""One batch per output folder at a time: an advisory lock (``fcntl.flock``) on
``<out>/.semsearch.lock``, held for the whole command, naming the process that holds it.

The lock is re-entrant within a process (a command that holds it may call :func:`run_batch`,
which takes it too). It is released when the process ends, however it ends: a process forked
while it is held (a pool worker) closes its copy of the lock's file at once, so that a worker that
outlives its parent cannot keep the folder locked.
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
_FILES: dict[str, object] = {}  # folder -> the open lock file


def _drop_inherited() -> None:
    """In a forked child: let go of the inherited lock files without unlocking (the lock is the
    parent's; flock's lock lives as long as any copy of the file stays open). Each descriptor is
    pointed at /dev/null rather than closed, so that the number stays taken while the parent's
    file object, copied into the child, still names it."""
    if _FILES:
        null = os.open(os.devnull, os.O_RDWR)
        for fh in _FILES.values():
            try:
                os.dup2(null, fh.fileno())
            except OSError:
                pass
        os.close(null)
    _FILES.clear()
    _HELD.clear()


os.register_at_fork(after_in_child=_drop_inherited)


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
    _FILES[key] = fh
    try:
        yield
    finally:
        del _HELD[key]
        del _FILES[key]
        fcntl.flock(fh, fcntl.LOCK_UN)
        fh.close()
