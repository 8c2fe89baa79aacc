"""``semsearch run``, ``sweep-alpha`` and ``sweep``: batches of runs into a results folder."""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from .. import api
from ..config.base import number_text
from ..errors import ScenarioError
from .common import DECISIONS, EXECUTOR, FORCE, FRAMES, GOALS, OVERSUBSCRIBE, PLANNERS, SCENARIO, SCHEDULER, SEEDS, TRACE, TRANSCRIPTS, WORKERS, _batch, _fail, _fallback_lines, _options, _path, _print_table, _warn_errors, _with_progress, app, out


@app.command()
def run(
    scenario: Path = SCENARIO,
    seeds: Optional[int] = SEEDS,
    workers: Optional[int] = WORKERS,
    goal: Optional[List[str]] = GOALS,
    planner: Optional[List[str]] = PLANNERS,
    out_dir: Optional[str] = typer.Option(None, "--out", callback=_path, help="Output folder (default results/<name>)."),
    trace: bool = TRACE,
    frames: bool = FRAMES,
    decisions: bool = DECISIONS,
    transcripts: bool = TRANSCRIPTS,
    dry_run: bool = typer.Option(False, "--dry-run", help="Print the first prompt a language-model planner (llm) of the scenario would send, and stop: nothing is called or written."),
    force: bool = FORCE,
    oversubscribe: bool = OVERSUBSCRIBE,
    executor: str = EXECUTOR,
    scheduler: Optional[str] = SCHEDULER,
):
    """Run a scenario's experiment: episodes x planner variants x repeats; rows are appended to
    runs.csv as runs finish (an interrupted batch resumes), then summary.csv and plots/ are written."""

    opts = _options(seeds, workers, goal, planner, out_dir, trace, force, oversubscribe, executor, scheduler, frames,
                    decisions, transcripts)
    if dry_run:
        try:
            typer.echo(api.first_prompt(scenario, opts))
        except ScenarioError as exc:
            _fail(exc)
        return
    _batch(lambda tick: api.run(scenario, opts, progress=tick))


@app.command("sweep-alpha")
def sweep_alpha(
    scenario: Path = SCENARIO,
    alphas: str = typer.Option("0,0.5,0.8,0.9,1.0", "--alphas", help="Comma-separated alpha values for nsos."),
    seeds: Optional[int] = SEEDS,
    workers: Optional[int] = WORKERS,
    goal: Optional[List[str]] = GOALS,
    out_dir: Optional[str] = typer.Option(None, "--out", callback=_path, help="Output folder (default results/<name>)."),
    trace: bool = TRACE,
    decisions: bool = DECISIONS,
    force: bool = FORCE,
    oversubscribe: bool = OVERSUBSCRIBE,
    executor: str = EXECUTOR,
    scheduler: Optional[str] = SCHEDULER,
):
    """nsos at each alpha with greedy beside it: the rows and summary of `run`, plus
    plots/alpha_sweep.png (mean ratio to the shortest path against alpha, per goal)."""

    try:  # read as a person writes numbers (number_text): float() read ٠.٥ as 0.5 and 0_5 as 5
        values = [number_text(a) for a in alphas.split(",") if a.strip()]
    except ValueError:
        _fail(ScenarioError("<command line>", "--alphas", f"expected comma-separated numbers, got {alphas!r}"))
    if not values or any(not 0.0 <= a <= 1.0 for a in values):
        _fail(ScenarioError("<command line>", "--alphas", f"alphas must lie in [0, 1], got {alphas!r}"))
    opts = _options(seeds, workers, goal, None, out_dir, trace, force, oversubscribe, executor, scheduler, decisions=decisions)
    res = _batch(lambda tick: api.sweep_alpha(scenario, values, opts, progress=tick))
    out.print(f"alpha plot: {res.out / 'plots' / 'alpha_sweep.png'}")


@app.command()
def sweep(
    scenario: Path = SCENARIO,
    param: str = typer.Option(..., "--param", help="SECTION.FIELD=V1,V2,... e.g. door_camera.p_misread=0,0.02,0.05,0.1, "
                              "or PLANNER.PARAM=... e.g. nsos.alpha=0.8,0.9,1.0."),
    seeds: Optional[int] = SEEDS,
    workers: Optional[int] = WORKERS,
    goal: Optional[List[str]] = GOALS,
    planner: Optional[List[str]] = PLANNERS,
    out_dir: Optional[str] = typer.Option(None, "--out", callback=_path, help="Output folder (default results/<name>-sweep-<param>)."),
    trace: bool = TRACE,
    decisions: bool = DECISIONS,
    force: bool = FORCE,
    oversubscribe: bool = OVERSUBSCRIBE,
    executor: str = EXECUTOR,
    scheduler: Optional[str] = SCHEDULER,
):
    """Run a scenario once per value of one parameter: each value's rows in <out>/<param>=<value>/
    (resumable), then sweep.csv, sweep.md and sweep.png (mean ratio to the shortest path and success
    rate against the value, per goal and planner)."""

    try:
        name, values = api.parse_param(param)
    except ScenarioError as exc:
        _fail(exc)
    opts = _options(seeds, workers, goal, planner, out_dir, trace, force, oversubscribe, executor, scheduler,
                    decisions=decisions)
    res = _with_progress(lambda tick: api.sweep(scenario, name, values, opts, progress=tick))
    _print_table(f"sweep of {name}: ratio to the shortest path", res.table)
    _warn_errors(res.runs)
    out.print(f"table: {res.out / 'sweep.csv'}  plot: {res.out / 'sweep.png'}  rows: {res.out}/{name}=*/runs.csv")
    _fallback_lines(res.runs)
