"""The commands as Python functions; the CLI only parses, calls these and prints."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .config import PlannerSpec, load_scenario
from .errors import ScenarioError
from .planners import expand_variants
from .report import build as report_build
from .report.plots import plot_alpha_sweep
from .report.tables import summarise
from .runner import Loaded, expand, run_batch, run_rows
from .tasks.objects import write_log


@dataclass
class RunOutput:
    out: Path
    runs: pd.DataFrame
    summary: pd.DataFrame


def default_out(loaded: Loaded, out: str | Path | None) -> Path:
    if out:
        return Path(out)
    if loaded.sc.experiment.out:
        return (loaded.path.parent / loaded.sc.experiment.out).resolve()
    return Path("results") / loaded.sc.name


def default_workers() -> int:
    return max(1, min(4, os.cpu_count() or 1))


def run(scenario: str | Path, seeds: int | None = None, workers: int | None = None, goals=None,
        planners=None, out: str | Path | None = None, progress=None, plots: bool = True,
        trace: bool = False, planner_specs=None) -> RunOutput:
    """Run a scenario's experiment: rows to runs.csv, then summary.csv and plots/.

    ``planner_specs`` (a list of :class:`~semsearch_cli.config.PlannerSpec`) replaces the
    scenario's planners; ``trace`` writes each run's decisions to traces/<run>.jsonl.
    """
    loaded = Loaded.load(Path(scenario))
    if planner_specs is not None:
        loaded = loaded.with_planners(planner_specs)
    if goals:
        known = {str(g) for g in loaded.goals}
        for g in goals:
            if str(g) not in known:
                raise ScenarioError("<command line>", "--goal", f"goal {g} is not among the scenario's goals {loaded.goals}")
    specs = expand(loaded, seeds, goals, planners)
    if not specs:
        raise ScenarioError("<command line>", "--planner", f"no planner variant matches {planners}")
    out_dir = default_out(loaded, out)
    report_build.write_meta(out_dir, loaded.path)
    loaded.task.write_inputs(out_dir)
    runs = run_batch(loaded, specs, out_dir, workers or default_workers(), progress, trace)
    summary = write_summary(runs, out_dir)
    if plots:
        report([out_dir], formats=("md", "csv", "png", "html"), replay=False)
    return RunOutput(out_dir, runs, summary)


def report(folders, out: str | Path | None = None, formats=("md", "csv", "png", "html"), replay: bool = True) -> list[Path]:
    """Rebuild every table and figure of one or several results folders from their runs.csv."""
    bad = [f for f in formats if f not in report_build.ALL_FORMATS]
    if bad:
        raise ScenarioError("<command line>", "--format", f"unknown format(s) {bad}; valid: {', '.join(report_build.ALL_FORMATS)}")
    for f in folders:
        if not (Path(f) / "runs.csv").is_file():
            raise ScenarioError(str(f), "", "no runs.csv here: give a folder written by `semsearch run`")
    return report_build.build_report([Path(f) for f in folders], Path(out) if out else None, formats, replay)


def sweep_alpha(scenario: str | Path, alphas: list[float], seeds: int | None = None, workers: int | None = None,
                goals=None, out: str | Path | None = None, progress=None, trace: bool = False) -> RunOutput:
    """nsos at each alpha with greedy beside it: the rows and summary of :func:`run`, plus
    ``plots/alpha_sweep.png``. Other nsos parameters come from the scenario's first nsos entry."""
    sc = load_scenario(scenario)
    base = next((p.params() for p in sc.planners if p.name == "nsos"), {})
    base.pop("alpha", None)
    specs = [PlannerSpec(name="greedy"), PlannerSpec(name="nsos", alpha=[float(a) for a in alphas], **base)]
    res = run(scenario, seeds, workers, goals, None, out, progress, True, trace, planner_specs=specs)
    labels = {v.label for v in expand_variants(specs, str(scenario))}
    (res.out / "plots").mkdir(parents=True, exist_ok=True)
    plot_alpha_sweep(run_rows(res.runs)[run_rows(res.runs)["planner"].isin(labels)], res.out / "plots" / "alpha_sweep.png")
    return res


def write_summary(runs: pd.DataFrame, out_dir: Path) -> pd.DataFrame:
    """summary.csv: per scenario x goal x planner, the statistics of the runs' distances."""
    summary = summarise(run_rows(runs))
    tmp = out_dir / ".summary.csv.tmp"
    summary.to_csv(tmp, index=False)
    os.replace(tmp, out_dir / "summary.csv")
    return summary


def record(scenario: str | Path, out: str | Path, cases=None) -> list[tuple[Path, int]]:
    """Write each case's detection log (recorded by patrolling, or read from its CSV) to ``out``."""
    loaded = Loaded.load(Path(scenario))
    logs = getattr(loaded.task, "logs", None)
    if not logs:
        raise ScenarioError(str(scenario), "objects", "recording needs a scenario with object cases (an objects section)")
    names = list(logs)
    for c in cases or []:
        if str(c) not in names:
            raise ScenarioError("<command line>", "--case", f"no case {c!r}; cases are {', '.join(names)}")
    written = []
    for name in names:
        if cases and name not in {str(c) for c in cases}:
            continue
        f = Path(out) / f"{name}.csv"
        write_log(logs[name], f)
        written.append((f, len(logs[name])))
    return written


def validate(scenario: str | Path) -> dict:
    """Every check of the loader, plus counts and each goal's shortest path (no simulation)."""
    return Loaded.load(Path(scenario)).task.describe()


def show(scenario: str | Path, out: str | Path) -> Path:
    """Draw a scenario (map, signs or places, start, goals) to a PNG without simulating."""
    loaded = Loaded.load(Path(scenario))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    return report_build.show(loaded, out)
