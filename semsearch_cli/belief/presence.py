"""Presence estimation from hourly counts per place (thesis 5.3.5, Eq. 5.3; SPEC 6).

The score of a place at request hour rh is the sum over hours h of count(h, place) * W(rh, h),
with W(rh, h) = 1 - dh / 12 and dh the hour difference on the 24-hour clock (23:00 and 01:00 are
2 hours apart), so W is 1 at the same hour and 0 twelve hours away.
"""

from __future__ import annotations

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
    """Hourly counts per place: first column the hour (0-23), one column per place. Rows whose
    first cell is not a number (a "Total" row) are ignored."""
    text = read_user_text(path, "counts file")
    try:
        df = pd.read_csv(io.StringIO(text))
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ScenarioError(str(path), "", f"not a readable CSV: {exc}") from None
    if df.shape[1] < 2:
        raise ScenarioError(str(path), "", "expected a first column with the hour and one column per place")
    hours = pd.to_numeric(df.iloc[:, 0], errors="coerce")
    df = df[hours.notna()].copy()
    df.index = hours[hours.notna()].astype(float)
    first = df.columns[0]
    df = df.iloc[:, 1:]
    if ((df.index < 0) | (df.index >= 24)).any():
        raise ScenarioError(str(path), str(first), "hours must lie in 0-23")
    counts = df.apply(pd.to_numeric, errors="coerce")
    bad = counts.isna().any()
    if bad.any():
        raise ScenarioError(str(path), str(bad[bad].index[0]), "counts must be numbers")
    return counts


def presence_scores(counts: pd.DataFrame, hours) -> pd.DataFrame:
    """Score of every place (columns) at each request hour (rows): sum_h count(h) * W(rh, h)."""
    rows = {float(rh): (counts.mul(hour_weight(rh, counts.index.to_numpy()), axis=0)).sum() for rh in hours}
    return pd.DataFrame(rows).T.rename_axis("request_hour")
