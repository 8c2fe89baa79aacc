"""The numbers do not move: every registered planner's golden rows (tests/golden/), run again, are
the same column by column, wall time and the code and scenario hashes aside. A change meant to move results rewrites
them (``python tests/golden/update.py``) in the same commit, with a line in CHANGELOG.md."""

import pandas as pd

from semsearch_cli.planners import PLANNERS
from tests.golden.cases import FILE, golden_rows


def test_the_golden_rows_are_what_the_code_makes(tmp_path):
    want = pd.read_csv(FILE, dtype=str, keep_default_na=False)
    got = golden_rows(tmp_path)
    assert list(got.columns) == list(want.columns), "the rows' columns changed: update the golden rows"
    assert len(got) == len(want), f"{len(got)} rows where the golden file has {len(want)}"
    moved = [(i, c, want.at[i, c], got.at[i, c]) for c in want.columns for i in range(len(want))
             if want.at[i, c] != got.at[i, c]]
    assert not moved, ("results moved (row, column, golden, now): " + "; ".join(map(str, moved[:10]))
                       + " -- if that is meant, run python tests/golden/update.py and say why in CHANGELOG.md")


def test_every_registered_planner_has_golden_rows():
    rows = pd.read_csv(FILE, dtype=str, keep_default_na=False)
    names = {p.split("[")[0] for p in rows["planner"]}
    builtin = {n for n, c in PLANNERS.items() if c.__module__.startswith("semsearch_cli.") and not c.service}  # llm: tests/test_llm.py
    assert builtin <= names, f"no golden rows for {sorted(builtin - names)}"
    assert set(rows["kind"]) == {"doors", "objects", "chain", "indirect"}
