"""``report`` and ``presence``: tables, figures and scores from rows."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..errors import ScenarioError
from ..belief.presence import presence_scores, read_counts
from ..report import build as report_build
from ..report.document import atomic_text
from ..files import output_file, output_folder


def report(folders, out: str | Path | None = None, formats=("md", "csv", "png", "html"), replay: bool | str = True) -> list[Path]:
    """Rebuild every table and figure of one or several results folders from their runs.csv.

    ``formats``: any of md, csv, png, pdf, svg, html (figures in each image format chosen, and in
    PNG whenever md or html is). ``replay``: False, True (the default run) or
    ``"PLANNER,GOAL,EPISODE,SEED"``, the run to re-simulate into a GIF."""
    formats = list(formats)
    bad = [f for f in formats if f not in report_build.ALL_FORMATS]
    if bad or not formats:
        what = f"unknown format(s) {', '.join(map(repr, bad))}" if bad else "no format given"
        raise ScenarioError("<command line>", "--format", f"{what}; give a comma-separated subset of "
                            f"{', '.join(report_build.ALL_FORMATS)}")
    if isinstance(replay, str):
        replay = report_build.parse_replay(replay)
    for f in folders:
        if not (Path(f) / "runs.csv").is_file():
            raise ScenarioError(str(f), "", "no runs.csv here: give a folder written by `semsearch run`")
    return report_build.build_report([Path(f) for f in folders], output_folder(out) if out is not None else None, formats, replay)


def presence(counts: str | Path, hours, out: str | Path | None = None) -> pd.DataFrame:
    """Every place's presence score at each request hour from hourly counts (thesis 5.3.5,
    Eq. 5.3): a DataFrame, one row per hour, one column per place; with ``out``, also written as
    CSV (atomically) with the highest place of each hour."""
    hours = list(hours)
    if not hours or any(not 0 <= h < 24 for h in hours):
        raise ScenarioError("<command line>", "--hours", f"hours must lie in 0-23, got {','.join(f'{h:g}' for h in hours)!r}")
    path = output_file(out, "--out", (".csv",)) if out is not None else None
    scores = presence_scores(read_counts(Path(counts)), hours)
    if path is not None:
        atomic_text(path, scores.assign(highest=scores.idxmax(axis=1)).round(3).to_csv())
    return scores
