"""Rewrite tests/golden/rows.csv from the code as it is: only when a change is meant to move
results, in the same commit, with a line in CHANGELOG.md saying why.

    python tests/golden/update.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from tests.golden.cases import FILE, golden_rows  # noqa: E402

if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        rows = golden_rows(Path(tmp))
    rows.to_csv(FILE, index=False)
    print(f"wrote {len(rows)} rows to {FILE}; say why in CHANGELOG.md")
