"""The ``semsearch`` command line (typer): parse, call :mod:`semsearch_cli.api`, print."""

from __future__ import annotations

import math
import os
import shlex
import re
import signal
import sys
import time
import warnings
from pathlib import Path
from typing import List, Optional

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text

from . import api
from .provenance import version_line
from .runner import BatchOptions
from .config.base import MAX_SEEDS, label_column, number_text, sign_label
from .kernels import announce_compiling
from .errors import DISK_FULL, BatchStopped, ScenarioError, Terminated, did_you_mean
from .metrics import FALLBACK_FLAG, fallback_shares, outside_the_run
from .report.build import console_tables
from .files import output_folder

app = typer.Typer(add_completion=False, no_args_is_help=True)
import_app = typer.Typer(no_args_is_help=True, help="Convert maps from other tools into scenarios.")
app.add_typer(import_app, name="import")
# a standard stream the shell closed (``>&-``) is None here: given /dev/null so that nothing fails on
# it, and a closed standard output is refused by main() (the command's output would be lost)
CLOSED = [name for name in ("stdout", "stderr") if getattr(sys, name) is None]
for _name in CLOSED:
    setattr(sys, _name, open(os.devnull, "w"))
# markup off: file names, planner names and goals are printed as they are, never read as [style] tags
out = Console(markup=False) if sys.stdout.isatty() else Console(markup=False, width=200)
err = Console(stderr=True, markup=False) if sys.stderr.isatty() else Console(stderr=True, markup=False, width=200)


def _fail(exc: ScenarioError) -> None:
    err.print(Text.assemble(("error:", "bold red"), " " + str(exc)), highlight=False, soft_wrap=True)
    raise typer.Exit(2)


def _path(value: Optional[str]) -> Optional[Path]:
    """An --out value as a Path; an empty one is refused (Path("") would be the working folder)."""
    if value is None:
        return None
    if not value.strip():
        raise typer.BadParameter("an empty path; give a folder or file name")
    return Path(value)


def _finite(value: Optional[float]) -> Optional[float]:
    """A number option: NaN and infinity are refused (click's ranges let NaN through)."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"expected a finite number, got {value}")
    return value


def _split(values: Optional[List[str]], flag: str, labels: bool = True) -> Optional[list]:
    """Repeated or comma-separated values of ``flag``, None when not given: sign labels in their
    canonical form (:func:`~semsearch_cli.config.base.sign_label`: ``148`` and ``148.0`` are the
    number 148) when ``labels``, else text (planner labels, case names). A comma inside brackets
    separates a label's parameters, not two values (``nsos[alpha=0.9,w_g=4]`` is one label)."""
    if values is None or values == []:
        return None
    items = [v.strip() for s in values for v in re.split(r",(?![^\[]*\])", s) if v.strip()]
    if not items:
        raise ScenarioError("<command line>", flag, f"no values in {' '.join(map(repr, values))}; give one or more, comma-separated")
    if not labels:
        return items
    try:  # as a CSV's column of labels is read: --goal 304.0 is the goal 304, as goals: [304.0] is
        return label_column(items)
    except ValueError as exc:
        raise ScenarioError("<command line>", flag, str(exc)) from None


SCENARIO = typer.Argument(..., help="Scenario YAML file, or a shipped scenario's name (semsearch scenarios lists them).")
# the batch options of run, sweep-alpha and sweep, declared once (see runner.BatchOptions)
SEEDS = typer.Option(None, "--seeds", min=1, max=MAX_SEEDS, help="Repeats of each episode per planner variant (default: the scenario's experiment.seeds).")
WORKERS = typer.Option(None, "--workers", min=1, help="Parallel processes (default: CPU count, at most 4; more than the CPU count needs --oversubscribe).")
GOALS = typer.Option(None, "--goal", help="Only these goals (repeat or comma-separate).")
PLANNERS = typer.Option(None, "--planner", help="Only these planners, by name or label (repeat or comma-separate).")
TRACE = typer.Option(False, "--trace", help="Also write each run's decisions (pose, candidates, factors, choice) to traces/<run>.jsonl.")
FRAMES = typer.Option(False, "--frames", help="Also write each run's replay frames to frames/<run>.npz: the report then replays any run from them, without re-running it.")
TRANSCRIPTS = typer.Option(False, "--transcripts", help="Also write each run's language-model transcript to transcripts/<run>.jsonl (the llm planner): {name: llm, replay: DIR} replays the runs from them, offline.")
DECISIONS = typer.Option(False, "--decisions", help="Also write each run's decisions to decisions/<run>.json (a few bytes each): `semsearch verify` then replays every run from them, without its planner.")
FORCE = typer.Option(False, "--force", help="Re-run everything when the folder holds rows of another (or an edited) scenario; the old runs.csv is kept as runs.<n>.csv.bak, its runs' paths, traces and frames in runs.<n>.bak/.")
OVERSUBSCRIBE = typer.Option(False, "--oversubscribe", help="Allow more workers than CPUs (slower runs, more memory; e.g. a planner that waits on I/O).")
EXECUTOR = typer.Option("processes", "--executor", help="processes (a pool on this machine) or dask (a Dask cluster: --scheduler, or a local one of --workers).")
SCHEDULER = typer.Option(None, "--scheduler", help="A Dask scheduler's address, tcp://HOST:PORT (with --executor dask).")


def _options(seeds, workers, goal, planner, out_dir, trace, force, oversubscribe, executor, scheduler, frames=False,
             decisions=False, transcripts=False) -> BatchOptions:
    """The batch options of the command line (a bad --goal or --planner list exits with status 2)."""
    try:
        goals, planners = _split(goal, "--goal"), _split(planner, "--planner", labels=False)
    except ScenarioError as exc:
        _fail(exc)
    return BatchOptions(seeds=seeds, goals=goals, planners=planners, out=out_dir, workers=workers,
                        oversubscribe=oversubscribe, executor=executor, scheduler=scheduler, trace=trace, force=force,
                        frames=frames, decisions=decisions, transcripts=transcripts)


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


def _run_name(row: dict) -> str:
    """A finished run as progress lines name it: planner, goal, episode and seed (as the lines a
    long run prints about itself, and the rows' columns)."""
    return f"{row['planner']} goal {row['goal']} episode {row['episode']} seed {row['seed']}"


class _Lines:
    """Progress off a terminal (CI logs, nohup, SLURM): one line on stderr every ``every`` s or
    every tenth of the batch, whichever comes first, and a last line with the count."""

    def __init__(self, every: float = 30.0):
        self.every, self.t0, self.last, self.step = every, time.monotonic(), time.monotonic(), 1

    def __call__(self, row: dict, done: int, total: int) -> None:
        now = time.monotonic()
        if done == 1:
            self.step = max(1, total // 10)
        if done == total or done % self.step == 0 or now - self.last >= self.every:
            self.last = now
            err.print(f"runs: {done} of {total} done, {now - self.t0:.0f} s; last {_run_name(row)}: {row['outcome']} "
                      f"{row['distance_m']:.0f} m", highlight=False, soft_wrap=True)


def _with_progress(call):
    """Call ``call(tick)`` with a progress display (a bar on a terminal, else lines every 30 s);
    bad input exits with status 2; Ctrl-C stops the batch, keeping its finished runs, and says
    how to resume (status 130)."""
    done = 0
    try:
        if not err.is_terminal:
            lines = _Lines()

            def tick(row, n, total):
                nonlocal done
                done += 1
                lines(row, n, total)

            return call(tick)
        with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                      TimeRemainingColumn(), console=err, transient=False) as prog:
            task = None

            def tick(row, n, total):
                nonlocal task, done
                done += 1
                if task is None or n == 1:  # a sweep runs one batch per value
                    task = prog.add_task("runs", total=total)
                prog.update(task, completed=n, description=escape(
                    f"{_run_name(row)}: {row['outcome']} {row['distance_m']:.0f} m"))

            return call(tick)
    except ScenarioError as exc:
        _fail(exc)
    except (KeyboardInterrupt, Terminated, BatchStopped) as exc:
        what, status = _stopped(exc)
        err.print(f"{what}: the {done} run(s) finished are kept in runs.csv; run the same command again to resume "
                  "(runs already in runs.csv are not run again)", highlight=False, soft_wrap=True)
        raise typer.Exit(status) from None


def _warn_errors(runs) -> None:
    errors = runs[runs["outcome"] == "error"]
    if len(errors):
        err.print(f"warning: {len(errors)} run(s) raised an error (outcome error in runs.csv), e.g. "
                         f"{errors['planner'].iloc[0]}: {errors['message'].iloc[0]}", highlight=False)


def _fallback_lines(runs) -> None:
    """The batch's last lines: per planner that has a fallback (a language model's), the share of
    its decisions that fell back (docs/llm.md); then, when runs could not run for a cause outside
    them (a model that did not answer, a missing package), how many, and status 1: they are no
    result, and the same command runs them again (docs/usage.md)."""
    for label, n, asked in fallback_shares(runs):
        share = n / asked if asked else 0.0
        flag = f" (more than {FALLBACK_FLAG:.0%}: the bench board marks it)" if share > FALLBACK_FLAG else ""
        out.print(f"fell back: {label}: {n} of {asked} decisions ({share:.1%}){flag}", highlight=False, soft_wrap=True)
    outside = runs[outside_the_run(runs)]
    if len(outside):
        err.print(f"{len(outside)} run(s) could not run, for a cause outside them (e.g. {outside['planner'].iloc[0]}: "
                  f"{outside['message'].iloc[0]}): they are not results; once the cause is fixed, the same command runs "
                  "them again", highlight=False, soft_wrap=True)
        raise typer.Exit(1)


def _batch(call):
    """Run a batch with a progress bar, print its summary; bad input exits with status 2."""
    res = _with_progress(call)
    for title, df in console_tables(res.runs):
        _print_table(title, df)
    _warn_errors(res.runs)
    out.print(f"rows: {res.out / 'runs.csv'}  summary: {res.out / 'summary.csv'}  figures: {res.out / 'figures'}  "
                     f"report: {res.out / 'report.md'}")
    _fallback_lines(res.runs)
    return res


def _print_table(title: str, df) -> None:
    """A DataFrame as a console table; text columns left-aligned, numbers right."""
    t = Table(title=title)
    for col in df.columns:
        t.add_column(str(col), justify="left" if df[col].dtype == object else "right")
    for r in df.itertuples(index=False):  # not iterrows: it upcasts a row of ints and floats to floats
        t.add_row(*[str(v) for v in r])
    out.print(t)


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
    out.print(f"{folder}: {v.verified} of {v.runs} runs replayed from their decisions to the outcome, distance, steps and "
              f"decisions recorded{more} ({res.what or ('suite' if isinstance(res.scenario, str) else 'scenario')} {res.scenario})",
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


ros_app = typer.Typer(no_args_is_help=True, help="Door planners over ROS 2 bags and on robots through rosbridge (the ros extra; "
                      "docs/robot.md).")
app.add_typer(ros_app, name="ros")


@ros_app.command("replay")
def ros_replay(
    bag: Path = typer.Argument(..., help="A ROS 2 bag folder: one `semsearch export` wrote, or a robot's own (/map, a pose, "
                               "/semsearch/detections; give --goal)."),
    planner: str = typer.Option(..., "--planner", help="The door planner to ask: NAME or NAME\\[key=value,...], e.g. nsos\\[alpha=0.9]."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="The new bag folder for its decisions (must not exist)."),
    scenario: Optional[Path] = typer.Option(None, "--scenario", help="The scenario the bag was recorded on (default: the "
                                            "shipped scenario the bag names); for a robot's bag, where its settings come from."),
    fmt: str = typer.Option("mcap", "--format", help="mcap or rosbag2 (SQLite 3), for the new bag."),
    planner_file: Optional[Path] = typer.Option(None, "--planner-file", help="A Python file that registers the planner."),
    goal: Optional[str] = typer.Option(None, "--goal", help="The label to find, for a robot's own bag (a bag of `semsearch "
                                       "export` names its goal)."),
    margin: float = typer.Option(10.0, "--margin", help="For a robot's own bag: metres of grid around its first map (as "
                                 "`ros live --margin`)."),
):
    """Ask a door planner where it would go at each re-plan of a bag.

    The robot moves as it moved; the planner's answers (/semsearch/goal, /explore/frontiers, /semsearch/decision) to a new
    bag. Over a bag of `semsearch export`, the run's own planner makes the run's decisions, decision
    for decision; a robot's own bag (/map, a pose, /semsearch/detections) needs --goal."""

    try:
        res = api.ros_replay(bag, planner, out_dir, scenario, fmt, planner_file, goal, margin)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"{res.folder}: {len(res.decisions)} decisions of {planner} over {bag} "
              f"({'the goal was read in the bag' if res.found else 'the goal was never read in the bag'})")
    if res.dropped:
        out.print(f"not taken from the bag: {res.dropped}")


@ros_app.command("live")
def ros_live(
    rosbridge: str = typer.Option(..., "--rosbridge", help="The robot's rosbridge_server: ws://HOST:PORT (it listens on 9090)."),
    planner: str = typer.Option(..., "--planner", help="The door planner: NAME or NAME\\[key=value,...], e.g. nsos\\[alpha=0.9]."),
    goal: str = typer.Option(..., "--goal", help="The label to find (a door's number)."),
    scenario: Optional[Path] = typer.Option(None, "--scenario", help="Where the belief's, robot's and navigation's settings "
                                            "come from, and the distance budget (default: their defaults, no budget)."),
    publish_only: bool = typer.Option(False, "--publish-only", help="Drive nothing: publish each goal on /semsearch/goal "
                                      "(PoseStamped) instead of sending Nav2 NavigateToPose goals."),
    out_dir: Optional[str] = typer.Option(None, "--out", callback=_path, help="The run's folder: the bag of the messages it "
                                          "took, its decisions record (semsearch verify checks it), its planner's transcript "
                                          "and run.json (default: live-DATE-TIME)."),
    repro: Optional[str] = typer.Option(None, "--repro", callback=_path, help="Deprecated since 0.4.0 (use --out): without "
                                        "--out, only a run that does not find the goal leaves its bag, here."),
    margin: float = typer.Option(10.0, "--margin", help="Metres of grid around the robot's first map, for the map to grow into."),
    max_distance: Optional[float] = typer.Option(None, "--max-distance", help="Stop after this many metres (default: the "
                                                 "scenario's experiment.max_distance, else none)."),
    planner_file: Optional[Path] = typer.Option(None, "--planner-file", help="A Python file that registers the planner."),
    silence: float = typer.Option(30.0, "--silence", help="Give up when the robot has sent nothing for this many seconds."),
):
    """Explore with a robot through rosbridge until the goal's sign is read.

    In the place of explore_lite: the robot's /map, pose and /semsearch/detections in; /explore/frontiers,
    /semsearch/goal and Nav2 NavigateToPose goals out; /explore/resume pauses and resumes. A run
    that does not find the goal leaves a repro bag for `semsearch ros replay`. Exit status 0 when
    the goal was found, 1 otherwise."""

    try:
        res = api.ros_live(rosbridge, planner, goal, scenario, publish_only, repro, margin, max_distance, planner_file,
                           silence, log=lambda text: err.print(text), out=out_dir)
    except ScenarioError as exc:
        _fail(exc)
    n = len(res.decisions)
    sent = "targets published on /semsearch/goal" if publish_only else f"{res.goals} goals sent to Nav2 (one a re-plan)"
    out.print(f"{res.outcome}: {res.message}; {res.distance:.1f} m along {res.poses} poses, {n} decision{'s' * (n != 1)}, "
              f"{sent}")
    if res.costs:
        out.print("planner's costs: " + ", ".join(f"{k} {v:g}" for k, v in res.costs.items()), highlight=False)
    if res.dropped:
        out.print(f"not taken from the robot: {res.dropped}")
    if res.bag is not None:
        folder = res.bag.parent
        out.print(f"run folder: {folder} (bag, decisions record{', transcript' if res.transcripts else ''}, run.json; "
                  f"check it: semsearch verify {shlex.quote(str(folder))})", highlight=False, soft_wrap=True)
    if res.repro is not None:
        size = sum(p.stat().st_size for p in res.repro.rglob("*") if p.is_file())
        if res.poses == 0:
            out.print(f"repro bag: {res.repro} ({size / 1e6:.2f} MB; no pose came, so there is nothing to replay)")
        else:
            again = f" --margin {margin:g}" + (f" --scenario {shlex.quote(str(scenario))}" if scenario is not None else "")
            out.print(f"repro bag: {res.repro} ({size / 1e6:.2f} MB; replay it: semsearch ros replay {shlex.quote(str(res.repro))}"
                      f" --goal {shlex.quote(goal)} --planner {shlex.quote(planner)}{again} --out "
                      f"{shlex.quote(str(res.repro) + '-replayed')})")
    raise typer.Exit(0 if res.outcome == "found" else 1)


@ros_app.command("sim")
def ros_sim(
    scenario: Path = SCENARIO,
    goal: str = typer.Option(..., "--goal", help="The goal whose first episode the robot starts from (its start, its seed)."),
    seed: int = typer.Option(0, "--seed", min=0, help="The repeat (the generator `semsearch run` gives that episode and seed)."),
    port: int = typer.Option(9090, "--port", min=0, max=65535, help="The port on 127.0.0.1 (rosbridge_server's is 9090)."),
    period: float = typer.Option(0.2, "--period", help="Seconds between the robot's steps."),
    follow: Optional[str] = typer.Option(None, "--follow", help="Also drive to each PoseStamped published on this topic (for "
                                         "`ros live --publish-only`: /semsearch/goal)."),
):
    """A robot without ROS, to try `semsearch ros live` on.

    The scenario's simulated robot (one episode: the goal's first, and one seed) behind a rosbridge
    server on 127.0.0.1, publishing /map, /semsearch/pose and /semsearch/detections and taking Nav2
    NavigateToPose goals on /navigate_to_pose. Runs until Ctrl-C; start it again for another run."""

    try:
        bot = api.ros_sim(scenario, goal, seed, port, period, follow)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"rosbridge on {bot.bridge.url}: the robot of {scenario} at ({bot.st.x:g}, {bot.st.y:g}), waiting for goals "
              "(Ctrl-C stops it)")
    told = False

    def tell():  # once, when the robot's cameras have read the goal's sign
        nonlocal told
        if bot.found_at is not None and not told:
            told = True
            out.print(f"read the sign {goal} after {bot.found_at:.2f} m, {len(bot.goals)} goals so far")
    try:
        while True:
            time.sleep(0.2)
            tell()
    except KeyboardInterrupt:
        pass
    finally:  # Ctrl-C, or SIGTERM (which goes on to exit 143)
        bot.bridge.stop()
        tell()
        out.print(f"stopped after {bot.distance:.2f} m, {bot.st.steps} steps, {len(bot.goals)} goals")


@app.command()
def validate(scenario: Path = SCENARIO):
    """Check a scenario without simulating: every loader check, sign counts, shortest paths."""

    try:
        info = api.validate(scenario)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"{scenario}: ok")
    for k, v in info.items():
        out.print(f"  {k}: {v}")


@app.command()
def scenarios():
    """List the shipped scenarios: `semsearch run NAME` runs one from any folder, and `semsearch
    init NAME DIR` copies one (with its map) to edit."""

    t = Table(title="shipped scenarios (semsearch run NAME; semsearch init NAME DIR to edit a copy)")
    for col in ("name", "kind", "description"):
        t.add_column(col, overflow="fold")
    for s in api.scenarios():
        t.add_row(s["name"], s["kind"], s["description"])
    out.print(t)


@app.command()
def init(
    name: str = typer.Argument(..., help="A shipped scenario's name (semsearch scenarios)."),
    folder: str = typer.Argument(..., callback=_path, help="Folder to copy it into (created if needed)."),
    force: bool = typer.Option(False, "--force", help="Overwrite files of the same names in the folder."),
):
    """Copy a shipped scenario and the files it names (map, signs, the JSON Schema) into a folder
    of yours, with its paths rewritten to the copies, to edit and run."""

    try:
        written = api.init(name, folder, force)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {written[0]} and {len(written) - 1} file(s) it names; run it with: semsearch run {written[0]}")


@app.command()
def schema(out_file: Optional[str] = typer.Option(None, "--out", callback=_path, help="JSON file to write (default: print it).")):
    """The scenario format as a JSON Schema: every field of every kind of search, with its type,
    default, bounds and description. Point an editor at it with a scenario's first line,
    `# yaml-language-server: $schema=scenario.schema.json`, for completion and checking."""

    try:
        path = api.schema(out_file)
    except ScenarioError as exc:
        _fail(exc)
    if path is None:
        sys.stdout.write(api.schema_text())
    else:
        out.print(f"wrote {path}")


@app.command()
def show(
    scenario: Path = SCENARIO,
    out_file: str = typer.Option("map.png", "--out", callback=_path, help="Image to write: .png, .pdf or .svg."),
):
    """Draw a scenario: the map with every sign and its number, the start and the goals."""

    try:
        path = api.show(scenario, out_file)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {path}")


bench_app = typer.Typer(no_args_is_help=True, help="semsearch-bench: frozen suites, runs that verify by replay (docs/bench.md).")
app.add_typer(bench_app, name="bench")


@bench_app.command("list")
def bench_list():
    """Every suite and split: its kind, floors (or rooms), goals, episodes, repeats and hash."""
    try:
        rows = api.bench_list()
    except ScenarioError as exc:
        _fail(exc)
    t = Table(title="semsearch-bench suites (semsearch bench run SUITE --planner NAME --out DIR)")
    for col in ("suite", "split", "kind", "floors", "goals", "episodes", "repeats", "hash", "published"):
        t.add_column(col, overflow="fold", justify="right" if col in ("floors", "goals", "episodes", "repeats") else "left")
    for r in rows:
        if r.get("fetch"):
            t.add_row(r["suite"], r["split"], r["kind"], f"{r['sources']} to fetch", "", "", str(r["repeats"]),
                      f"(semsearch bench fetch {r['suite']})", str(r["published"] or "")[:16])
        elif r["hidden"]:
            pub = r["published"][:16] if r["published"] else "none yet (a maintainer's)"
            t.add_row(r["suite"], r["split"], r["kind"], "hidden", "", "", str(r["repeats"]), "(salt held by the maintainers)", pub)
        else:
            mark = "= published" if r["hash"] == r["published"] else "DIFFERS from " + str(r["published"])[:16]
            t.add_row(r["suite"], r["split"], r["kind"], str(r["floors"]), str(r["goals"]), str(r["episodes"]), str(r["repeats"]),
                      r["hash"][:16], mark)
    out.print(t)


@bench_app.command("run")
def bench_run(
    suite: str = typer.Argument(..., help="A suite's name (semsearch bench list)."),
    planner: List[str] = typer.Option(..., "--planner", help="NAME or NAME\\[key=value,...], e.g. nsos\\[alpha=0.9] (repeatable)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="The results folder (bench.json, one folder per floor)."),
    split: str = typer.Option("val", "--split", help="val (shipped) or test (hidden: --salt-file)."),
    numbering: str = typer.Option("true", "--numbering", help="true, shuffled, parity-flipped or reversed: the floors' labels permuted."),
    limit: Optional[int] = typer.Option(None, "--limit", min=1, help="Only the first N episodes of the split (a first look)."),
    planner_file: Optional[Path] = typer.Option(None, "--planner-file", help="A Python file that registers the planner(s)."),
    salt_file: Optional[Path] = typer.Option(None, "--salt-file", help="The salt of a hidden split (maintainers)."),
    transcripts: bool = TRANSCRIPTS,
    workers: Optional[int] = WORKERS,
    oversubscribe: bool = OVERSUBSCRIBE,
    executor: str = EXECUTOR,
    scheduler: Optional[str] = SCHEDULER,
):
    """Run planners on a suite's split: every run recorded with its decisions (semsearch verify
    DIR replays them), every row with the suite's hash; resumable."""
    opts = BatchOptions(workers=workers, oversubscribe=oversubscribe, executor=executor, scheduler=scheduler,
                        transcripts=transcripts)
    res = _with_progress(lambda tick: api.bench_run(suite, planner, out_dir, split, numbering, opts, limit, salt_file,
                                                    planner_file, progress=tick))
    runs = res.runs[res.runs["stage"] == ""]
    t = Table(title=f"{res.split.suite.name} {res.split.name}, numbering {res.numbering} ({len(res.floors)} floors; "
                    f"hash {res.split.hash[:16]}{', official' if res.split.official and not res.partial else ''}"
                    f"{'; partial: not every run of the split is in the folder, never official' if res.partial else ''})")
    for col in ("planner", "runs", "success", "SPL", "mean distance m"):
        t.add_column(col, justify="left" if col == "planner" else "right")
    for label, g in runs.groupby("planner", sort=False):
        t.add_row(str(label), str(len(g)), f"{g['success'].mean():.3f}", f"{g['spl'].mean():.3f}", f"{g['distance_m'].mean():.1f}")
    out.print(t)
    _warn_errors(runs)
    out.print(f"results: {res.out} (verify: semsearch verify {res.out})")
    _fallback_lines(runs)


@bench_app.command("board")
def bench_board(
    folders: List[Path] = typer.Argument(..., help="Bench results folders (semsearch bench run --out)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for index.html, board.md and the figure."),
):
    """The results page of bench folders: per suite and split, each planner's success, SPL, SoftSPL
    and distance with 95% intervals over episodes, the paired difference to nsos[alpha=0.9], the
    semantic gain (true minus shuffled numbering), verified or not, official or not."""
    try:
        files = api.bench_board(folders, out_dir)
    except ScenarioError as exc:
        _fail(exc)
    for f in files:
        out.print(f"wrote {f}")


@bench_app.command("fetch")
def bench_fetch(
    suite: str = typer.Argument(..., help="A track of floors that may not be shipped (semsearch bench list)."),
    from_dir: Optional[List[Path]] = typer.Option(None, "--from", help="A folder holding copies of the source files "
                                                  "(found by name and SHA-256; repeatable)."),
    mirror: Optional[str] = typer.Option(None, "--mirror", help="A URL standing for the sources' host (http://HOST:PORT)."),
    partial: bool = typer.Option(False, "--partial", help="Build the split from the floors whose files were found (not official)."),
):
    """Fetch a track's source files (each checked by its SHA-256), import its floors and draw their
    episodes, into the cache: then semsearch bench run SUITE runs it."""
    try:
        sp, missing = api.bench_fetch(suite, from_dir or [], mirror, partial)
    except ScenarioError as exc:
        _fail(exc)
    for m in missing:
        err.print(f"left out: {m}", highlight=False, soft_wrap=True)
    out.print(f"{suite}: {len(sp.floors)} floors in {sp.folder}; hash {sp.hash[:16]} "
              + ("(the published hash: official)" if sp.official else "(not the published hash: not official)"))


@bench_app.command("hash")
def bench_hash(
    suite: str = typer.Argument(..., help="A suite's name (semsearch bench list)."),
    split: str = typer.Option("val", "--split", help="The split."),
    salt_file: Optional[Path] = typer.Option(None, "--salt-file", help="The salt of a hidden split (maintainers)."),
):
    """Print a split's hash (a hidden split built from its salt) and whether it is the published one."""
    try:
        sp = api.bench_hash(suite, split, salt_file)
    except ScenarioError as exc:
        _fail(exc)
    out.print(sp.hash)
    pub = sp.published
    err.print(f"{suite} {split}: {len(sp.floors)} floors; " + ("the published hash" if sp.official else
              "no published hash yet (docs/bench.md: a maintainer fills it in)" if pub is None else
              f"NOT the published hash {pub[:16]}: not official"), highlight=False, soft_wrap=True)


generate_app = typer.Typer(no_args_is_help=True, help="Generate numbered buildings, and rooms for indirect search, of your own.")
app.add_typer(generate_app, name="generate")


@generate_app.command("building")
def generate_building(
    layout: str = typer.Option(..., "--layout", help="grid, wings, angled, single or hall."),
    numbering: str = typer.Option(..., "--numbering", help=", ".join(api.SCHEMES) + "."),
    seed: int = typer.Option(0, "--seed", min=0, max=2**32 - 1, help="Seed of the layout's variations (and of random numbering)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.png, doors.csv and scenario.yaml."),
    spacing: float = typer.Option(2.5, "--spacing", callback=_finite, min=0.5, max=50.0, help="m between door slots along a wall."),
    signs: Optional[int] = typer.Option(None, "--signs", min=1, help="Keep exactly this many signs (doors trimmed at random, numbers kept)."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance)."),
    name: Optional[str] = typer.Option(None, "--name", help="Scenario name (default LAYOUT-NUMBERING-SEED)."),
    scale: float = typer.Option(1.0, "--scale", callback=_finite, min=0.5, max=4.0,
                                help="Stretch the layout this many times in x and y (scale^2 the area), corridors as wide."),
    skip: float = typer.Option(0.0, "--skip", callback=_finite, min=0.0, max=0.95,
                               help="Share of each prefix's number range left without a door (numbers skipped, as real floors do)."),
    letters: float = typer.Option(0.0, "--letters", callback=_finite, min=0.0, max=0.9,
                                  help="Share of doors that share a room's number with a letter suffix (24a, 24b)."),
    extension: bool = typer.Option(False, "--extension", help="Renumber the last corridor in a hundred-block of its own."),
    style: str = typer.Option("plain", "--style", help="plain (214), wing (K214: a wing letter per corridor) or dot (2.14)."),
    letter_case: str = typer.Option("lower", "--letter-case", help="lower (24a) or upper (24A): the lettered doors' suffixes."),
):
    """Write a generated building: map PNG, doors CSV and a scenario YAML that runs as it is."""
    try:
        wanted = _split([goals], "--goals") if goals is not None else None
        path = api.generate_building(layout, numbering, seed, out_dir, spacing=spacing, signs=signs, goals=wanted, name=name,
                                     scale=scale, skip=skip, letters=letters, extension=extension, style=style,
                                     letter_case=letter_case)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.png'}, {out_dir / 'doors.csv'}, {path}")


MAX_BATCH_SEEDS = 100  # generate batch: 2,800 buildings at most


def _items(text: Optional[str]) -> Optional[list]:
    """Comma-separated values, None when not given."""
    return None if text is None else [t.strip() for t in text.split(",") if t.strip()]


@generate_app.command("batch")
def generate_batch(
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for the buildings (one sub-folder each) and index.txt."),
    seeds: int = typer.Option(3, "--seeds", min=1, max=MAX_BATCH_SEEDS, help="Buildings per layout and numbering scheme "
                              f"(at most {MAX_BATCH_SEEDS}: 4 x 7 x {MAX_BATCH_SEEDS} buildings)."),
    runs: int = typer.Option(3, "--runs", min=1, help="Runs per goal and planner in each scenario."),
    layouts: Optional[str] = typer.Option(None, "--layouts", help="Comma-separated layouts (default: all)."),
    schemes: Optional[str] = typer.Option(None, "--schemes", help="Comma-separated numbering schemes (default: all)."),
):
    """Every layout x numbering scheme x seed: a robustness set (4 x 7 x 3 = 84 buildings by default)."""
    try:
        paths = api.generate_batch(out_dir, seeds=seeds, runs=runs, layouts=_items(layouts), schemes=_items(schemes))
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {len(paths)} scenarios under {out_dir} (listed in {out_dir / 'index.txt'})")


@generate_app.command("rooms")
def generate_rooms(
    n: int = typer.Option(20, "--n", min=1, max=10000, help="How many rooms."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed (room k is the same whatever --n)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for rooms.yaml."),
    size: str = typer.Option("6,6", "--size", help="W,D: the room's width and depth in metres."),
    obstacles: int = typer.Option(0, "--obstacles", min=0, max=20, help="Boxes per room (the paper's rooms have none)."),
):
    """Rooms for indirect search as the paper's (Loncomilla et al. 2018, Section 4.5): the monitor
    uniform, each secondary object in a ring drawn from its co-occurrences (Table 2)."""
    try:
        w, d = _xy(size, "--size", "W,D in metres")
        path, rooms = api.generate_rooms(n, seed, out_dir, (w, d), obstacles)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {len(rooms)} rooms of {w:g} x {d:g} m to {path}")


DUPLICATES_POLICIES = ("error", "keep-first", "any")


def _duplicates(value: str) -> str:
    if value not in DUPLICATES_POLICIES:
        raise typer.BadParameter(f"{value!r} is not one of {', '.join(DUPLICATES_POLICIES)}{did_you_mean(value, DUPLICATES_POLICIES)}")
    return value


DUPLICATES = typer.Option("error", "--duplicates", callback=_duplicates,
                          help="Signs that share a number: error (refuse), keep-first (the first sign of each number) or "
                               "any (keep every one; the goal is found at whichever carries it). Written into the scenario.")


@import_app.command("mobilesim")
def import_mobilesim(
    map_file: Path = typer.Argument(..., help="MobileSim .map file (walls in mm)."),
    doors_file: Path = typer.Argument(..., help=".doors file: x y number facing (m, degrees)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.png, doors.csv and scenario.yaml."),
    resolution: float = typer.Option(0.1, "--resolution", callback=_finite, min=0.01, max=1.0, help="m per cell."),
    start: Optional[str] = typer.Option(None, "--start", help="X,Y in metres (default: the widest free cell)."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance)."),
    density_delta: float = typer.Option(2.5, "--density-delta", callback=_finite, min=0.01, max=1e4, help="m^2, segmentation delta (Eq. 4.4)."),
    duplicates: str = DUPLICATES,
):
    """Convert a MobileSim map and door file into a scenario that runs as it is."""
    try:
        path, notes = api.import_mobilesim(map_file, doors_file, out_dir, res=resolution, start=_xy(start, "--start"),
                                   goals=_split([goals], "--goals") if goals is not None else None, density_delta=density_delta,
                                   duplicates=duplicates)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.png'}, {out_dir / 'doors.csv'}, {path}\n" + "\n".join(notes))


def _xy(value: str | None, flag: str, what: str = "X,Y in metres") -> tuple[float, float] | None:
    """Two finite numbers ``A,B`` from the command line, or None."""
    if not value:
        return None
    try:
        xs, ys = value.split(",")
        x, y = float(xs), float(ys)
    except ValueError:
        x = y = math.nan
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ScenarioError("<command line>", flag, f"expected {what}, got {value!r}")
    return x, y


@import_app.command("ros")
def import_ros(
    map_file: Path = typer.Argument(..., help="ROS map YAML (map_server / map_saver: a PGM or PNG beside it)."),
    doors_file: Path = typer.Argument(..., help="Door signs: CSV with columns number,x,y,facing (m, degrees) in the map's frame."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.yaml (and its image), doors.csv and scenario.yaml."),
    start: Optional[str] = typer.Option(None, "--start", help="X,Y in metres (default: the widest free cell)."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance)."),
    density_delta: float = typer.Option(2.5, "--density-delta", callback=_finite, min=0.01, max=1e4, help="m^2, segmentation delta (Eq. 4.4)."),
    clean: bool = typer.Option(False, "--clean", help="Clean a SLAM map: free space not reachable from the start, and laser fans narrower than the robot, become outside (map.clean)."),
    duplicates: str = DUPLICATES,
):
    """Make a scenario over a ROS map (the format of every ROS user's SLAM maps), keeping the map as it is."""
    try:
        path, notes = api.import_ros(map_file, doors_file, out_dir, start=_xy(start, "--start"),
                                   goals=_split([goals], "--goals") if goals is not None else None, density_delta=density_delta,
                                   clean=clean, duplicates=duplicates)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.yaml'}, {out_dir / 'doors.csv'}, {path}\n" + "\n".join(notes))


@import_app.command("kth")
def import_kth(
    xml_file: Path = typer.Argument(..., help="KTH campus floor-plan XML file."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.png, doors.csv and scenario.yaml."),
    resolution: float = typer.Option(0.1, "--resolution", callback=_finite, min=0.01, max=1.0, help="m per cell."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance, among readable signs)."),
    corridor_types: str = typer.Option(",".join(api.KTH_CORRIDOR_TYPES), "--corridor-types",
                                       help="Comma-separated space types the robot drives in (untyped spaces joined to several others count too)."),
    duplicates: str = DUPLICATES,
):
    """Convert a KTH floor plan: circulation spaces become free space, each room-to-corridor portal a sign."""
    try:
        types = tuple(t.strip().upper() for t in corridor_types.split(",") if t.strip())
        path, notes = api.import_kth(xml_file, out_dir, res=resolution,
                                   goals=_split([goals], "--goals") if goals is not None else None, corridor_types=types,
                                   duplicates=duplicates)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.png'}, {out_dir / 'doors.csv'}, {path}\n" + "\n".join(notes))


@app.command()
def version():
    """Print the semsearch version, the hash of its code and the git commit it runs from."""
    out.print(version_line())


def _version(value: bool) -> None:
    if value:
        out.print(version_line())
        raise typer.Exit(0)


@app.callback()
def _main(show_version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                            help="Print the version, code hash and git commit, and exit.")):
    """Object-search planners in a fast 2D grid simulator: run scenarios over episodes and seeds,
    write tables and plots."""


@app.command()
def episodes(
    scenario: Path = SCENARIO,
    out_file: str = typer.Option("episodes.csv", "--out", callback=_path, help="CSV to write."),
):
    """Write a scenario's episode set (each start and goal, its shortest path and a content hash)
    to a CSV, to freeze, share or name it: `episodes: {file: episodes.csv}` in a scenario runs it."""

    try:
        path, eps, h = api.episodes(scenario, out_file)
    except ScenarioError as exc:
        _fail(exc)
    goals = len({str(e.goal) for e in eps})
    out.print(f"wrote {path}: {len(eps)} episodes over {goals} goals, set hash {h}")


@app.command("planners")
def planners_cmd(scenario: Optional[Path] = typer.Argument(None, help="Also list the planners this scenario's files register.")):
    """List every planner (built-in, from installed packages, and a scenario's own files) with its
    kind of search, where it comes from, its parameters, their defaults and descriptions."""

    try:
        found = api.planners(scenario)
    except ScenarioError as exc:
        _fail(exc)
    t = Table(title="planners (parameters: name = default, description)")
    widest = max((len(p["source"]) for p in found), default=0)
    for col in ("name", "kind", "source", "description", "parameters"):
        # a planner file's path is printed whole where it fits (a folded path cannot be copied)
        t.add_column(col, overflow="fold", min_width=min(widest, 80) if col == "source" else None)
    for p in found:
        params = "\n".join(f"{q['name']} = {q['default']!r}" + (f": {q['description']}" if q["description"] else "")
                           for q in p["params"]) or "none"
        kind = p["kind"] + (f"\nprivileged: told {p['privileged']}" if p["privileged"] else "")  # a reference, not a competitor
        t.add_row(p["name"], kind, p["source"], p["description"], params)
    out.print(t)


def _terminate(signum, frame) -> None:
    raise Terminated()


def _stopped(exc: BaseException) -> tuple[str, int]:
    """(how a command stopped, its exit status) for Ctrl-C, SIGTERM and a batch stopped by a fault."""
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted", 130
    if isinstance(exc, Terminated):
        return "stopped (SIGTERM)", 143
    return f"stopped: {exc}", getattr(exc, "status", 1)


PACKAGE = str(Path(__file__).resolve().parent)  # semsearch's own files: a warning raised in them is shown without its line


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on standard error: its category and message, and where it was raised
    when that is the user's code (a planner file written against an older API), not semsearch's."""
    where = "" if str(Path(filename).resolve()).startswith(PACKAGE) else f"{filename}:{lineno}: "
    err.print(f"{where}{category.__name__}: {message}", highlight=False, soft_wrap=True)


def main() -> None:
    """The command line. Faults end with one paragraph and a status, never a traceback: Ctrl-C
    (130), SIGTERM (143), a batch stopped by a dead worker (1), a full disk (1)."""
    signal.signal(signal.SIGTERM, _terminate)
    announce_compiling()
    # semsearch's own deprecations (a user's planner written against an older API) are shown: the
    # user's code is what must change, and Python hides DeprecationWarning outside __main__
    warnings.filterwarnings("default", category=DeprecationWarning, message=".*deprecated since semsearch")
    warnings.showwarning = _show_warning
    resume = "finished runs are kept in runs.csv; run the same command again to resume"
    resume = {"live": "the goal under way was cancelled, and the messages taken are in the repro bag named above",
              "sim": "the stand-in robot holds nothing to keep", "replay": "no half-written bag is left"}.get(
        sys.argv[2] if sys.argv[1:2] == ["ros"] and len(sys.argv) > 2 else "", resume)
    if "stdout" in CLOSED:
        err.print("error: standard output is closed (>&-); give it a file, or /dev/null to discard what semsearch prints",
                  highlight=False, soft_wrap=True)
        sys.exit(2)
    try:
        app()
    except (KeyboardInterrupt, Terminated, BatchStopped) as exc:
        what, status = _stopped(exc)
        err.print(f"{what}: {resume}", highlight=False, soft_wrap=True)
        sys.exit(status)
    except OSError as exc:
        if exc.errno not in DISK_FULL:
            raise
        err.print(f"stopped: the disk is full ({exc.filename or 'writing an output file'}); nothing written before "
                  f"is lost: free some space and run the same command again ({resume.split('; ')[0]})",
                  highlight=False, soft_wrap=True)
        sys.exit(1)
