"""The commands as Python functions; the CLI only parses, calls these and prints."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import ScenarioError
from .experiment import Loaded, expand, file_stem, run_batch


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
        loaded.sc = loaded.sc.model_copy(update={"planners": planner_specs})
    if goals:
        known = {str(g) for g in loaded.goals}
        for g in goals:
            if str(g) not in known:
                raise ScenarioError("<command line>", "--goal", f"goal {g} is not among the scenario's goals {loaded.goals}")
    specs = expand(loaded, seeds, goals, planners)
    if not specs:
        raise ScenarioError("<command line>", "--planner", f"no planner variant matches {planners}")
    out_dir = default_out(loaded, out)
    from .report.build import write_meta

    write_meta(out_dir, loaded.path)
    if loaded.task is not None:
        from .objects.task import write_log

        for case, log in loaded.logs.items():
            write_log(log, out_dir / "logs" / f"{case}.csv")
    runs = run_batch(loaded, specs, out_dir, workers or default_workers(), progress, trace)
    wanted = {s.key for s in specs}
    mine = runs[[(str(p), str(g), int(s)) in wanted for p, g, s in zip(runs["planner"], runs["goal"], runs["seed"])]]
    summary = write_summary(runs, out_dir)
    if plots:
        if loaded.task is None:  # object-search paths are drawn by the report, beside the heat maps
            write_path_plots(loaded, mine, out_dir)
        report([out_dir], formats=("md", "csv", "png", "html"), replay=False)
    return RunOutput(out_dir, runs, summary)


def report(folders, out: str | Path | None = None, formats=("md", "csv", "png", "html"), replay: bool = True) -> list[Path]:
    """Rebuild every table and figure of one or several results folders from their runs.csv."""
    from .errors import ScenarioError
    from .report.build import ALL_FORMATS, build_report

    bad = [f for f in formats if f not in ALL_FORMATS]
    if bad:
        raise ScenarioError("<command line>", "--format", f"unknown format(s) {bad}; valid: {', '.join(ALL_FORMATS)}")
    for f in folders:
        if not (Path(f) / "runs.csv").is_file():
            raise ScenarioError(str(f), "", "no runs.csv here: give a folder written by `semsearch run`")
    return build_report([Path(f) for f in folders], Path(out) if out else None, formats, replay)


def sweep_alpha(scenario: str | Path, alphas: list[float], seeds: int | None = None, workers: int | None = None,
                goals=None, out: str | Path | None = None, progress=None, trace: bool = False) -> RunOutput:
    """nsos at each alpha with greedy beside it: the rows and summary of :func:`run`, plus
    ``plots/alpha_sweep.png``. Other nsos parameters come from the scenario's first nsos entry."""
    from .config import PlannerSpec, load_scenario

    sc = load_scenario(scenario)
    if sc.is_objects:
        raise ScenarioError(str(scenario), "objects", "sweep-alpha varies the door-search planner nsos; this is an "
                            "object-search scenario (use `semsearch run`, with list-valued lsos parameters to sweep them)")
    base = next((p.params() for p in sc.planners if p.name == "nsos"), {})
    base.pop("alpha", None)
    specs = [PlannerSpec(name="greedy"), PlannerSpec(name="nsos", alpha=[float(a) for a in alphas], **base)]
    res = run(scenario, seeds, workers, goals, None, out, progress, True, trace, planner_specs=specs)
    from .planners import expand_variants
    from .report.plots import plot_alpha_sweep

    labels = {v.label for v in expand_variants(specs, str(scenario))}
    plot_alpha_sweep(res.runs[res.runs["planner"].isin(labels)], res.out / "plots" / "alpha_sweep.png")
    return res


def write_summary(runs: pd.DataFrame, out_dir: Path) -> pd.DataFrame:
    from .report.tables import summarise

    summary = summarise(runs)
    tmp = out_dir / ".summary.csv.tmp"
    summary.to_csv(tmp, index=False)
    os.replace(tmp, out_dir / "summary.csv")
    return summary


def write_path_plots(loaded: Loaded, runs: pd.DataFrame, out_dir: Path) -> list[Path]:
    """One PNG per goal x planner variant: the median run's path over the map."""
    from .report.plots import plot_path
    from .report.tables import median_run

    if runs.empty:
        return []
    plots = out_dir / "plots"
    plots.mkdir(parents=True, exist_ok=True)
    written = []
    for _, row in median_run(runs).iterrows():
        goal = _goal_value(loaded, row["goal"])
        f = out_dir / "paths" / f"{file_stem(row['planner'], goal, int(row['seed']))}.npz"
        if not f.is_file():
            continue
        data = np.load(f)
        title = (f"{loaded.sc.name}: goal {goal}, {row['planner']}, median run (seed {int(row['seed'])}): "
                 f"{row['distance_m']:.1f} m, {row['outcome']}, shortest {row['shortest_m']:.1f} m")
        png = plots / f"{file_stem(row['planner'], goal, None)}.png"
        plot_path(loaded.world, data["path"], data["read_signs"], goal, title, png)
        written.append(png)
    return written


def _goal_value(loaded: Loaded, g):
    for x in loaded.sc.goals:
        if str(x) == str(g):
            return x
    return g


def record(scenario: str | Path, out: str | Path, cases=None) -> list[tuple[Path, int]]:
    """Write each case's detection log (recorded by patrolling, or read from its CSV) to ``out``."""
    from .objects.task import write_log

    loaded = Loaded.load(Path(scenario))
    if loaded.task is None:
        raise ScenarioError(str(scenario), "objects", "recording needs an object-search scenario (an objects section)")
    names = [c.name for c in loaded.task.cases]
    for c in cases or []:
        if str(c) not in names:
            raise ScenarioError("<command line>", "--case", f"no case {c!r}; cases are {', '.join(names)}")
    written = []
    for name in names:
        if cases and name not in {str(c) for c in cases}:
            continue
        f = Path(out) / f"{name}.csv"
        write_log(loaded.logs[name], f)
        written.append((f, len(loaded.logs[name])))
    return written


def validate(scenario: str | Path) -> dict:
    """Every check of the loader, plus counts and each goal's shortest path (no simulation)."""
    loaded = Loaded.load(Path(scenario))
    w = loaded.world
    from .planners import expand_variants

    variants = expand_variants(loaded.sc.planners, str(loaded.path), loaded.kind)
    if loaded.task is not None:
        t = loaded.task
        return {"name": loaded.sc.name, "places": len(t.places), "route": " ".join(t.route),
                "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
                "cases": {c.name: f"{len(loaded.logs[c.name])} detections recorded" for c in t.cases},
                "planners": [v.label for v in variants],
                "requests (ground truth: shortest m)": {r.label: f"{','.join(r.truth) or 'absent'}: {loaded.shortest[r.label]:.2f}"
                                                        for r in t.requests}}
    readable = 0
    for i in range(len(w.signs)):
        if w.readable_mask(i).any():
            readable += 1
    return {"name": loaded.sc.name, "signs": len(w.signs), "readable_signs": readable,
            "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
            "planners": [v.label for v in variants], "shortest_m": {str(k): round(v, 2) for k, v in loaded.shortest.items()}}


def show(scenario: str | Path, out: str | Path) -> Path:
    """Draw a scenario (map, signs with numbers, start, goals) to a PNG without simulating."""
    from .config import load_scenario
    from .report.plots import plot_scenario
    from .world.scenario import build_world

    path = Path(scenario)
    sc = load_scenario(path)
    world = build_world(sc, path.parent, str(path))
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    if sc.is_objects:
        from .objects.task import ObjectTask
        from .report.plots import plot_object_paths

        from .objects.search import Drive

        task = ObjectTask(sc, world, path.parent, str(path))
        drive = Drive(task, [], np.random.default_rng(0), world.start_heading or 0.0)
        for n in task.route:
            drive.go(*task.places[n], look=False)
        drive.go(*world.start_xy, look=False)
        plot_object_paths(world, {}, task.places, (), f"{sc.name}: places {' '.join(task.places)}; patrol route "
                          f"{drive.distance:.1f} m (dotted)", out, route=np.asarray(drive.trail))
        return out
    plot_scenario(world, sc.goals, f"{sc.name}: {len(world.signs)} signs, goals {', '.join(map(str, sc.goals))}", out)
    return out
