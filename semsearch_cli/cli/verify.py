"""``semsearch verify`` (a results, bench or live run's folder replayed from its decisions) and
``export`` (runs as ROS 2 bags)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .. import api
from ..errors import ScenarioError
from .common import _fail, _path, app, out


@app.command()
def verify(
    folder: Path = typer.Argument(..., help="A results folder (runs.csv, and decisions/ from `semsearch run --decisions`)."),
    scenario: Optional[Path] = typer.Option(None, "--scenario", help="The scenario the rows were made with (default: the one "
                                            "meta.json names)."),
    workers: Optional[int] = typer.Option(None, "--workers", min=1, help="Replaying processes (default: the CPU count, at "
                                          "most 4; at most the CPU count). The verdict does not depend on it."),
    salt_file: Optional[Path] = typer.Option(None, "--salt-file", help="A bench folder of a hidden split: the file holding "
                                             "its salt (maintainers)."),
    allow_unrecorded: bool = typer.Option(False, "--allow-unrecorded", help="A folder recorded partly without --decisions: "
                                          "its runs without a record are counted, not failed (never for a bench folder)."),
):
    """Check a results folder recorded with `semsearch run --decisions`: replay each run from its
    decisions, without its planner, to its outcome, distance, steps and decisions exactly, and
    check the folder whole: a row without its record, a record without its row, a row added or
    twice, a record of another run. Each is named, and the status is 1."""

    try:
        res = api.verify(folder, scenario, workers=workers, salt_file=salt_file, allow_unrecorded=allow_unrecorded)
    except ScenarioError as exc:
        _fail(exc)
    v = res.verdict
    for name, why in v.failed:
        out.print(f"does not replay: {name}: {why}", highlight=False, soft_wrap=True)
    notes = []
    if v.unrecorded:
        notes.append(f"{v.unrecorded} without decisions not checked (--allow-unrecorded)")
    if v.unfinished:
        notes.append(f"{v.unfinished} error or timeout run(s) not replayed (a run that did not finish keeps no record; "
                     "they claim no result)")
    more = "".join(f"; {n}" for n in notes)
    checked = ("the re-plans (step, target) and the outcome recorded, over the run's bag" if res.what == "settings of"
               else "the outcome, distance, steps and decisions recorded")
    out.print(f"{folder}: {v.verified} of {v.runs} runs replayed from their decisions to {checked}{more} "
              f"({res.what or ('suite' if isinstance(res.scenario, str) else 'scenario')} {res.scenario})",
              highlight=False, soft_wrap=True)
    if v.failed:
        out.print(f"{len(v.failed)} problem(s): the folder does not verify", highlight=False, soft_wrap=True)
        raise typer.Exit(1)


@app.command()
def export(
    folder: Path = typer.Argument(..., help="A results folder with decisions/ (`semsearch run --decisions`)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for the bags: one ROS 2 bag folder per run."),
    fmt: str = typer.Option("mcap", "--format", help="mcap (one .mcap file, opens in Foxglove) or rosbag2 (SQLite 3)."),
    run_id: Optional[str] = typer.Option(None, "--run", help="Only this run: its decisions file's name without .json "
                                         "(e.g. greedy__goal304__ep0__seed0)."),
    scenario: Optional[Path] = typer.Option(None, "--scenario", help="The scenario the rows were made with (default: the one "
                                            "meta.json names)."),
):
    """Write recorded door-search runs as ROS 2 bags (the ros extra): the belief map, pose and /tf,
    laser, path, signs read, frontier candidates and each decision's target, on the topics of
    docs/robot.md. Each run is replayed from its decisions; a bag already written is kept."""

    kept: list[str] = []
    try:
        done = api.export(folder, out_dir, fmt, run_id, scenario, kept=kept.append)
    except ScenarioError as exc:
        _fail(exc)
    for d in done:
        out.print(f"{d.folder}: {d.outcome}, {d.distance_m:.1f} m, {d.decisions} decisions, {d.messages} messages, "
                  f"{d.size / 1e6:.2f} MB")
    there = f"; {len(kept)} kept as they were (their bags were there already)" if kept else ""
    out.print(f"{len(done)} bag(s) written to {out_dir} ({fmt}){there}")
