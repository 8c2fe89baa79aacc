"""What made a result: semsearch's version and the hash of its code, the git commit it was
installed from (when it runs from a checkout), and the versions of what it runs on.

``code_hash()`` hashes the ``.py`` files of the package that a run executes (paths and bytes; not
the report or the command line), so two installs of the same code agree and any edit of the
simulator or a planner, committed or not, changes it; rows carry it through each planner's code
hash (see :func:`semsearch_cli.planners.code_of`)."""

from __future__ import annotations

import functools
import hashlib
import os
import platform
import stat
import sys
from importlib import metadata
from pathlib import Path

from . import __version__
from .checkout import checkout_commit
from .engine import ENGINE

PACKAGE = Path(__file__).resolve().parent
DEPENDENCIES = ("numpy", "scipy", "numba", "pandas", "opencv-python-headless", "matplotlib", "pydantic")


# what a run does not execute: the report, the command line and its API (a typo fixed in a plot
# must not throw every row away)
NOT_RUN = ("report/", "cli.py", "api.py")


def regular_bytes(path: str | Path) -> bytes | None:
    """The bytes of ``path`` when it is a regular file this process can read (a symlink to one
    counts), else None: a folder, a pipe (FIFO), a socket or a device, a dangling or looping
    symlink, a file without read permission. Never waits on a pipe: one is refused by its status
    before it is opened, and the open does not wait (``O_NONBLOCK``) and is checked again through
    its descriptor, so one swapped in between is refused too."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except (OSError, ValueError):  # ValueError: a NUL in the name
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        with os.fdopen(os.dup(fd), "rb") as fh:
            return fh.read()
    except OSError:
        return None
    finally:
        os.close(fd)


def files_hash(root: Path, skip: tuple = (), recursive: bool = True) -> str:
    """sha256 (16 hex digits) of the Python files under ``root`` (in its subfolders too when
    ``recursive``; paths relative to it and bytes, in path order), leaving out those whose
    relative path starts with one of ``skip``.

    Only regular files that can be read count (:func:`regular_bytes`): whatever else is named
    ``*.py`` beside a user's planner file (a folder ``junk.py``, a dangling symlink, a pipe, a
    socket, a file without read permission) is left out, as Python could not import it either;
    a pipe is never read, so it cannot hang a run."""
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py") if recursive else root.glob("*.py")):
        rel = f.relative_to(root).as_posix()
        if rel.startswith(skip) or "/." in "/" + rel:
            continue
        data = regular_bytes(f)
        if data is None:
            continue
        h.update(rel.encode() + b"\0")
        h.update(data)
    return h.hexdigest()[:16]


@functools.cache
def code_hash() -> str:
    """The hash of the code a run executes: every Python file of the package but the report and
    the command line (:data:`NOT_RUN`)."""
    return files_hash(PACKAGE, NOT_RUN)


@functools.cache
def git_commit() -> str | None:
    """The commit of the checkout the package runs from (``+dirty`` when its files differ from
    it); installed from a wheel, the commit the wheel was built from (see setup.py); None when
    neither is known (built from an sdist or a tarball)."""
    if (PACKAGE.parent / ".git").exists():
        return checkout_commit(PACKAGE)
    built = PACKAGE / "data" / "build_commit.txt"  # written by setup.py into a wheel built from a checkout
    return (built.read_text().strip() or None) if built.is_file() else None


def version_line() -> str:
    """``semsearch 0.3.0 (engine 2, code 1a2b..., commit abc...)``: what ``semsearch --version``
    prints (the engine: :mod:`semsearch_cli.engine`)."""
    commit = git_commit()
    return f"semsearch {__version__} (engine {ENGINE}, code {code_hash()}" + (f", commit {commit}" if commit else "") + ")"


def environment() -> dict:
    """Python, the platform and the versions of the libraries the numbers depend on."""
    deps = {}
    for d in DEPENDENCIES:
        try:
            deps[d] = metadata.version(d)
        except metadata.PackageNotFoundError:
            deps[d] = None
    return {"python": sys.version.split()[0], "platform": platform.platform(), "machine": platform.machine(), **deps}


def describe() -> dict:
    """semsearch's version, simulator engine, code hash, commit and environment, for meta.json."""
    return {"version": __version__, "engine": ENGINE, "code": code_hash(), "commit": git_commit(), **environment()}
