"""Golden rows: a few seeded runs of every registered planner on small shipped scenarios of every
kind of search, as ``semsearch run`` writes them. ``tests/test_golden.py`` runs them again and
compares every column but the wall time and the hashes of code and scenario; a change that moves a result must
rewrite ``rows.csv`` (``python tests/golden/update.py``) in the same commit, with a line in
CHANGELOG.md saying why."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from semsearch_cli.planners import PLANNERS, Variant
from semsearch_cli.runner import BatchOptions, Loaded, run_batch, RunSpec

ROOT = Path(__file__).resolve().parents[2]
FILE = Path(__file__).with_name("rows.csv")
IGNORED = ("wall_s", "code", "fingerprint")  # how long a run took; the hashes of the code and the scenario (provenance, which a new option moves)
# (config, kind of planners, episodes, repeats): per registered planner of that kind
CASES = [("demo", "doors", (0, 1), (0, 1)),
         ("office", "objects", (0, 1, 2, 3), (0,)),
         ("hospital", "doors", (0, 2), (0,)),
         ("indirect_quick", "indirect", (0, 139), (0,))]
DEFAULTS = {"nsos": (("alpha", 0.9),)}


def planners(kind: str) -> list[Variant]:
    """Every registered built-in planner of ``kind``, with its default parameters (nsos at 0.9); not
    llm, which needs a server (tests/test_llm.py)."""
    return [Variant(n, DEFAULTS.get(n, ())) for n, c in PLANNERS.items()
            if c.task == kind and c.__module__.startswith("semsearch_cli.") and not c.service]


def golden_rows(out: Path) -> pd.DataFrame:
    """Every case run into ``out`` (one folder per config), the rows as text, sorted."""
    frames = []
    for config, kind, episodes, repeats in CASES:
        L = Loaded.load(ROOT / "configs" / f"{config}.yaml")
        specs = [RunSpec(L.task.episodes[k], v, s) for v in planners(kind) for k in episodes for s in repeats]
        run_batch(L, specs, out / config, BatchOptions(workers=1))
        frames.append(pd.read_csv(out / config / "runs.csv", dtype=str, keep_default_na=False))
    rows = pd.concat(frames, ignore_index=True).drop(columns=list(IGNORED)).fillna("")  # a column one folder lacks: empty, as the CSV reads it
    key = ["scenario", "planner", "goal", "episode", "seed", "stage"]
    return rows.sort_values(key, kind="stable").reset_index(drop=True)
