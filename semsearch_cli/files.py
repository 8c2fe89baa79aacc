"""Writing files atomically: every write goes to a temporary file beside its target, unique to the
writing process, and is then renamed over it, so a reader never sees half a file and two
processes writing the same file never share a temporary name."""

from __future__ import annotations

import os
from pathlib import Path


def temp_path(path: Path) -> Path:
    """A temporary path beside ``path`` for an atomic write: hidden, unique to this process, and
    with the same suffix (libraries that pick a format from it still do)."""
    path = Path(path)
    return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
