"""Pure array kernels (numba / numpy / SciPy): grid searches and flood fills, ray casting and
HIMM, the harmonic potential. They know nothing of robots, tasks or plots.

The numba kernels are compiled on their first call and cached on disk (``cache=True``: beside
their modules, or in numba's user-wide cache when the install is read-only), so compiling is paid
once per install, not once per process; :func:`announce_compiling` says so while it happens."""

from __future__ import annotations

import os
import sys

from numba.core import event

COMPILING = ("compiling the simulator's numba kernels, once per install (a few seconds: 6 s on a 2-core "
             "machine); later runs load them from numba's cache")


class _FirstCompile(event.Listener):
    """Prints :data:`COMPILING` to stderr when this process first compiles a kernel (a kernel
    loaded from the cache is not compiled, so nothing is printed once the cache is warm). With a
    ``once`` file shared by the processes of a batch, only the first of them to compile prints."""

    def __init__(self, label: str):
        self.label, self.said, self.once = label, False, None

    def on_start(self, ev: event.Event) -> None:
        if self.said:
            return
        self.said = True
        if self.once is not None:
            try:
                os.close(os.open(self.once, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:  # another process of the batch said it
                return
            except OSError:  # a folder that went away: say it rather than not
                pass
        print(f"{self.label}{COMPILING}", file=sys.stderr, flush=True)

    def on_end(self, ev: event.Event) -> None:
        pass


_LISTENING: list[_FirstCompile] = []


def announce_compiling(label: str = "note: ") -> None:
    """Say once, on stderr, when this process starts compiling numba kernels (call it before a
    run; calling it again does nothing)."""
    if not _LISTENING:
        _LISTENING.append(_FirstCompile(label))
        event.register("numba:compile", _LISTENING[0])


def share_compiling_note(once: str | None) -> None:
    """The processes of one batch (a worker pool's parent and its workers) share the file ``once``,
    so that the compiling note is said once per batch, not once per worker (None: each process for
    itself again). A process that said it already marks it said there."""
    announce_compiling()
    listener = _LISTENING[0]
    listener.once = once
    if once is not None and listener.said:
        try:
            os.close(os.open(once, os.O_CREAT | os.O_WRONLY))
        except OSError:
            pass
