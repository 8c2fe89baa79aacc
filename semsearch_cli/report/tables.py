"""Tables rebuilt from rows alone (SPEC 9)."""

from __future__ import annotations

import pandas as pd

STATS = ["n", "success_rate", "median", "mean", "std", "min", "max", "shortest_m", "mean_ratio"]


def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario x goal x planner variant: n, success rate, median, mean, std (ddof=1, as the
    thesis' tables), min and max of distance_m, the shortest path and the mean ratio."""
    g = runs.groupby(["scenario", "goal", "planner"], sort=True)
    out = g.agg(
        n=("distance_m", "size"),
        success_rate=("success", "mean"),
        median=("distance_m", "median"),
        mean=("distance_m", "mean"),
        std=("distance_m", "std"),
        min=("distance_m", "min"),
        max=("distance_m", "max"),
        shortest_m=("shortest_m", "first"),
        mean_ratio=("ratio", "mean"),
    ).reset_index()
    return out.round(3)


def median_run(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario x goal x planner: the row of the run whose distance is the (lower) median."""
    def pick(df):
        df = df.sort_values(["distance_m", "seed"])
        return df.iloc[(len(df) - 1) // 2]

    return runs.groupby(["scenario", "goal", "planner"], sort=True)[runs.columns.tolist()].apply(pick).reset_index(drop=True)
