"""semsearch-bench: frozen suites, runs that carry their decisions, verification by replay, and
the numbering ablation (docs/bench.md)."""

from __future__ import annotations

import json

from . import board, real
from .make import SUITE_CLASSIC, SUITE_DOORS, SUITE_INDIRECT, SUITE_OBJECTS, SUITE_REAL
from .numbering import NUMBERINGS, relabel
from .run import BENCH_FILE, BenchOutput, is_bench, materialise, read_bench, run_bench, verify_bench
from .suites import DATA, PUBLISHED, SUITES, Floor, Split, Suite, open_split, register, split_hash, suite_named

# the published hashes, one file the maintainers edit (a hidden split's stays null until a
# maintainer who holds its salt fills it in: semsearch bench hash SUITE --split test --salt-file F)
_HASHES = json.loads((DATA / "published.json").read_text()) if (DATA / "published.json").is_file() else {}
for _suite in (SUITE_DOORS, SUITE_CLASSIC, SUITE_INDIRECT, SUITE_OBJECTS, SUITE_REAL):
    register(_suite, _HASHES.get(_suite.name, {}))

__all__ = ["board", "real", "BENCH_FILE", "BenchOutput", "DATA", "Floor", "NUMBERINGS", "PUBLISHED", "SUITES", "Split", "Suite", "is_bench",
           "materialise", "open_split", "read_bench", "register", "relabel", "run_bench", "split_hash", "suite_named",
           "verify_bench"]
