"""Compare the rows of two results folders (or runs.csv files), all columns they share but wall time.

    python benchmarks/compare_rows.py OLD NEW [--code]

Rows are matched by (planner, goal, seed, stage, map); prints the rows that differ and exits 1
when any does (or when one side has a run the other lacks). Used to check that a change which
should not move numbers does not. The ``code`` column (the hash of the code that made a row)
differs after any change to the simulator's files, so it is left out unless ``--code`` is given.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

KEY = ["planner", "goal", "seed", "stage", "map"]


def load(p: str) -> pd.DataFrame:
    f = Path(p)
    f = f / "runs.csv" if f.is_dir() else f
    df = pd.read_csv(f, dtype=str, keep_default_na=False)
    for k in KEY:
        if k not in df:
            df[k] = ""
    return df.drop(columns=["wall_s"]).set_index(KEY).sort_index()


def main(a: str, b: str, code: bool = False) -> int:
    old, new = load(a), load(b)
    cols = [c for c in old.columns if c in new.columns and (code or c != "code")]
    only_old = old.index.difference(new.index)
    only_new = new.index.difference(old.index)
    both = old.index.intersection(new.index)
    diff = (old.loc[both, cols] != new.loc[both, cols]).any(axis=1)
    print(f"{len(both)} runs in both ({len(cols)} columns compared: {', '.join(cols)}); "
          f"{int(diff.sum())} differ; {len(only_old)} only in {a}; {len(only_new)} only in {b}")
    for k in list(both[diff.to_numpy()])[:20]:
        o, n = old.loc[k, cols], new.loc[k, cols]
        print(k, {c: (o[c], n[c]) for c in cols if o[c] != n[c]})
    return int(bool(diff.any() or len(only_old) or len(only_new)))


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3], code="--code" in sys.argv[3:]))
