"""``semsearch report``, ``presence`` and ``record``: tables, figures and scores from rows, and object
search's recording mode (its detection logs)."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer
from rich.table import Table

from .. import api
from ..errors import ScenarioError
from ..files import output_folder
from .common import _fail, _path, _split, app, out


@app.command()
def report(
    folders: List[Path] = typer.Argument(..., help="Results folders (each with a runs.csv)."),
    out_dir: Optional[str] = typer.Option(None, "--out", callback=_path, help="Where to write (default: into each results folder)."),
    fmt: str = typer.Option("md,csv,png,html", "--format",
                            help="Comma-separated, any of md, csv, png, pdf, svg, html: every figure in each image format "
                                 "chosen (PNG also whenever md or html is: the documents embed it)."),
    replay: Optional[str] = typer.Option(None, "--replay", metavar="PLANNER,GOAL,EPISODE,SEED",
                                         help="The run to re-simulate into an animated GIF (default: the median run "
                                              "of the last planner for the first goal)."),
    no_replay: bool = typer.Option(False, "--no-replay", help="Re-simulate no run."),
):
    """Rebuild the thesis' tables, significance tests and figures from runs.csv alone, plus one
    self-contained report.md / report.html per results folder."""

    try:
        if replay is not None and no_replay:
            raise ScenarioError("<command line>", "--replay", "given with --no-replay; give one of them")
        files = api.report(folders, out_dir, [f.strip() for f in fmt.split(",") if f.strip()],
                           False if no_replay else replay if replay is not None else True)
    except ScenarioError as exc:
        _fail(exc)
    for f in files:
        out.print(f"wrote {f}")


@app.command()
def presence(
    counts_file: Path = typer.Argument(..., help="CSV: first column the hour (0-23), one column per place."),
    hours: str = typer.Option(..., "--hours", help="Comma-separated request hours, e.g. 1,10,16,18,22."),
    out_file: Optional[str] = typer.Option(None, "--out", callback=_path, help="Also write the scores to this CSV."),
):
    """Score every place at each request hour from hourly counts (thesis 5.3.5, Eq. 5.3); the
    highest of each hour is marked."""
    try:
        try:
            hs = [float(h) for h in hours.split(",") if h.strip()]
        except ValueError:
            raise ScenarioError("<command line>", "--hours", f"expected comma-separated hours, got {hours!r}") from None
        scores = api.presence(counts_file, hs, out_file)
    except ScenarioError as exc:
        _fail(exc)
    t = Table(title="presence score per place (sum of counts x W, Eq. 5.3), * = highest")
    t.add_column("hour", justify="right")
    for c in scores.columns:
        t.add_column(str(c), justify="right")
    for rh, row in scores.iterrows():
        best = row.idxmax()
        t.add_row(f"{rh:g}", *[f"{v:.2f}" + ("*" if c == best else "") for c, v in row.items()])
    out.print(t)
    if out_file:
        out.print(f"wrote {out_file}")


@app.command()
def record(
    scenario: Path = typer.Argument(..., help="Object-search scenario YAML file, or a shipped scenario's name (semsearch scenarios)."),
    out_dir: str = typer.Option("logs", "--out", callback=_path, help="Folder for the detection logs (one CSV per case)."),
    cases: Optional[List[str]] = typer.Option(None, "--case", help="Only these cases (repeat or comma-separate)."),
):
    """Recording mode: patrol the route at each recording hour and write the detection log of
    every case (day, hour, class, x, y, robot_x, robot_y, place). A scenario can replay a log
    with `record: path/to/log.csv` in its case."""

    try:
        written = api.record(scenario, output_folder(out_dir), _split(cases, "--case", labels=False))
    except ScenarioError as exc:
        _fail(exc)
    for f, n in written:
        out.print(f"wrote {f} ({n} detections)")
