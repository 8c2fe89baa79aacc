"""Presence estimation from hourly counts per place (thesis 5.3.5, Eq. 5.3).

The score of a place at request hour rh is the sum over hours h of count(h, place) * W(rh, h),
with W(rh, h) = 1 - dh / 12 and dh the hour difference on the 24-hour clock (23:00 and 01:00 are
2 hours apart), so W is 1 at the same hour and 0 twelve hours away.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ScenarioError
from ..files import read_user_text


def hour_difference(a, b):
    """Hours between a and b on the 24-hour clock, in [0, 12] (fractions allowed)."""
    d = np.abs(np.asarray(a, float) - np.asarray(b, float)) % 24.0
    return np.minimum(d, 24.0 - d)


def hour_weight(rh, h):
    """W of Eq. 5.3 on the 24-hour clock: 1 - dh / 12."""
    return 1.0 - hour_difference(rh, h) / 12.0


def read_counts(path: Path) -> pd.DataFrame:
    """Hourly counts per place: first column the hour (0-23), one column per place, every row as
    long as the header; counts finite and not negative. Rows whose first cell is not a number (a
    "Total" row) are ignored; a file with no hour row is refused."""
    text = read_user_text(path, "counts file")
    try:
        rows = list(csv.reader(io.StringIO(text)))
    except csv.Error as exc:
        raise ScenarioError(str(path), "", f"not a readable CSV: {exc}") from None
    rows = [r for r in rows if any(c.strip() for c in r)]
    if not rows or len(rows[0]) < 2:
        raise ScenarioError(str(path), "", "expected a first column with the hour and one column per place")
    for k, r in enumerate(rows[1:], start=2):
        if len(r) != len(rows[0]):
            raise ScenarioError(str(path), f"line {k}", f"{len(r)} cells where the header has {len(rows[0])}")
    df = pd.DataFrame(rows[1:], columns=rows[0])
    hours = pd.to_numeric(df.iloc[:, 0], errors="coerce")
    df = df[hours.notna()].copy()
    df.index = hours[hours.notna()].astype(float)
    first = df.columns[0]
    df = df.iloc[:, 1:]
    if ((df.index < 0) | (df.index >= 24)).any():
        raise ScenarioError(str(path), str(first), "hours must lie in 0-23")
    if df.empty:
        raise ScenarioError(str(path), str(first), "no row with an hour: give one row per hour (0-23)")
    counts = df.apply(pd.to_numeric, errors="coerce")
    bad = (counts.isna() | ~np.isfinite(counts) | (counts < 0)).any()
    if bad.any():
        raise ScenarioError(str(path), str(bad[bad].index[0]), "counts must be finite numbers, 0 or more")
    return counts


def presence_scores(counts: pd.DataFrame, hours) -> pd.DataFrame:
    """Score of every place (columns) at each request hour (rows): sum_h count(h) * W(rh, h)."""
    rows = {float(rh): (counts.mul(hour_weight(rh, counts.index.to_numpy()), axis=0)).sum() for rh in hours}
    return pd.DataFrame(rows).T.rename_axis("request_hour")
