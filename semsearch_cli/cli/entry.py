"""The ``semsearch`` entry point: the ``--version`` callback, and :func:`main`, which ends every fault
with one paragraph and a status, never a traceback."""

from __future__ import annotations

import signal
import sys
import warnings
from pathlib import Path

import typer

from ..provenance import version_line
from ..kernels import announce_compiling
from ..errors import DISK_FULL, BatchStopped, Terminated
from .common import CLOSED, _stopped, app, err, out


def _version(value: bool) -> None:
    if value:
        out.print(version_line())
        raise typer.Exit(0)


@app.callback()
def _main(show_version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                            help="Print the version, code hash and git commit, and exit.")):
    """Object-search planners in a fast 2D grid simulator: run scenarios over episodes and seeds,
    write tables and plots."""


def _terminate(signum, frame) -> None:
    raise Terminated()


PACKAGE = str(Path(__file__).resolve().parents[1])  # semsearch's own files: a warning raised in them is shown without its line


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on standard error: its category and message, and where it was raised
    when that is the user's code (a planner file written against an older API), not semsearch's."""
    where = "" if str(Path(filename).resolve()).startswith(PACKAGE) else f"{filename}:{lineno}: "
    err.print(f"{where}{category.__name__}: {message}", highlight=False, soft_wrap=True)


def main() -> None:
    """The command line. Faults end with one paragraph and a status, never a traceback: Ctrl-C
    (130), SIGTERM (143), a batch stopped by a dead worker (1), a full disk (1)."""
    signal.signal(signal.SIGTERM, _terminate)
    announce_compiling()
    # semsearch's own deprecations (a user's planner written against an older API) are shown: the
    # user's code is what must change, and Python hides DeprecationWarning outside __main__
    warnings.filterwarnings("default", category=DeprecationWarning, message=".*deprecated since semsearch")
    warnings.showwarning = _show_warning
    resume = "finished runs are kept in runs.csv; run the same command again to resume"
    resume = {"live": "the goal under way was cancelled, and the messages taken are in the repro bag named above",
              "sim": "the stand-in robot holds nothing to keep", "replay": "no half-written bag is left"}.get(
        sys.argv[2] if sys.argv[1:2] == ["ros"] and len(sys.argv) > 2 else "", resume)
    if "stdout" in CLOSED:
        err.print("error: standard output is closed (>&-); give it a file, or /dev/null to discard what semsearch prints",
                  highlight=False, soft_wrap=True)
        sys.exit(2)
    try:
        app()
    except (KeyboardInterrupt, Terminated, BatchStopped) as exc:
        what, status = _stopped(exc)
        err.print(f"{what}: {resume}", highlight=False, soft_wrap=True)
        sys.exit(status)
    except OSError as exc:
        if exc.errno not in DISK_FULL:
            raise
        err.print(f"stopped: the disk is full ({exc.filename or 'writing an output file'}); nothing written before "
                  f"is lost: free some space and run the same command again ({resume.split('; ')[0]})",
                  highlight=False, soft_wrap=True)
        sys.exit(1)
