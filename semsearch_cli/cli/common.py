"""What the commands share: the typer app, the consoles (markup off: names print as they are), the one-
paragraph refusal, the options of the batch commands, and a batch's progress and closing lines."""

from __future__ import annotations

import math
import os
import re
import sys
import time
from pathlib import Path
from typing import List, Optional

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text

from ..runner import BatchOptions
from ..config.base import MAX_SEEDS, label_column
from ..errors import BatchStopped, ScenarioError, Terminated
from ..metrics import FALLBACK_FLAG, fallback_shares, outside_the_run
from ..report.build import console_tables


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


def _stopped(exc: BaseException) -> tuple[str, int]:
    """(how a command stopped, its exit status) for Ctrl-C, SIGTERM and a batch stopped by a fault."""
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted", 130
    if isinstance(exc, Terminated):
        return "stopped (SIGTERM)", 143
    return f"stopped: {exc}", getattr(exc, "status", 1)
