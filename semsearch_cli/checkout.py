"""The git commit of the checkout a package lives in. Standard library only: setup.py loads this
file by its path at build time (before any dependency is installed) to stamp a wheel with its
commit, and :mod:`semsearch_cli.provenance` uses it at run time."""

from __future__ import annotations

import subprocess
from pathlib import Path


def checkout_commit(package: Path) -> str | None:
    """The commit of the git checkout that holds the folder ``package`` (``+dirty`` when that
    folder's files differ from it), or None outside a checkout or without git."""
    root = package.parent
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--", package.name],
                               capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    if head.returncode != 0:
        return None
    return head.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")
