"""What every benchmark script does with its result: print it, and write it to --md if given."""

from __future__ import annotations

from pathlib import Path


def emit(text: str, md: Path | None) -> int:
    """Print ``text``; also write it to ``md`` when given. Returns the exit status 0."""
    print(text)
    if md:
        md.write_text(text if text.endswith("\n") else text + "\n")
    return 0
