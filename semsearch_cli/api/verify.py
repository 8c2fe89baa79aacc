"""``verify``: a results folder, a bench folder or a live run's folder replayed from its decisions,
checked whole."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..config import read_yaml, with_param
from ..errors import MissingExtra, ScenarioError
from ..report import build as report_build
from ..runner import Loaded, workers_for
from ..runner.store import read_runs
from ..runner.verify import UNFINISHED, Verdict, check_folder_engine, records_in, verify_folder
from .. import bench, ros2
from ..shipped import scenario_file


@dataclass
class VerifyOutput:
    folder: Path
    scenario: Path | str  # the scenario replayed on, or a bench's "SUITE SPLIT (hash ...)"
    verdict: Verdict
    what: str = ""  # what ``scenario`` is, as the command line says it: scenario, suite, settings ("": by its type)


def rows_scenario(folder: Path, scenario: str | Path | None) -> tuple[Path, Loaded]:
    """The scenario a results folder's rows were made with, loaded without planners: ``scenario``
    when given, else the one meta.json names, with the parameter a sweep set in that folder."""
    if not (folder / "runs.csv").is_file():
        raise ScenarioError(str(folder), "", "no runs.csv here: give a folder written by `semsearch run`")
    meta = report_build.read_meta(folder)
    if scenario is None:
        path = report_build.scenario_of(folder, meta)
        path = path.resolve() if path is not None else None
        if path is None:
            raise ScenarioError(str(folder / "meta.json"), "scenario", "names no scenario file that exists; give the "
                                "scenario the rows were made with, --scenario FILE")
    else:
        path = scenario_file(scenario)
    varied = meta.get("varied")  # a sweep's value: its parameter set as the sweep set it
    if isinstance(varied, dict) and isinstance(varied.get("param"), str):
        return path, Loaded.load(path, with_param(read_yaml(path), varied["param"], varied.get("value"), path), planners=False)
    return path, Loaded.load(path, planners=False)


def _verify_live(folder: Path, scenario: str | Path | None) -> VerifyOutput:
    """A live run's folder (``ros live --out``), replayed from its record: its scenario the one
    ``run.json`` names (or ``scenario``), none for a run on the defaults."""
    if not ros2.available("rosbags"):
        raise MissingExtra("semsearch verify (a live run's bag)", "ros")
    run = ros2.check_run(ros2.read_run(folder / "run.json"), folder / "run.json")
    named = scenario if scenario is not None else run["scenario"]
    loaded = Loaded.load(scenario_file(named), planners=False) if named is not None else None
    return VerifyOutput(folder, loaded.path if loaded is not None else "the robot's defaults", ros2.verify_live(folder, loaded),
                        "settings of")


def verify(folder: str | Path, scenario: str | Path | None = None, progress=None, workers: int | None = None,
           salt_file: str | Path | None = None, allow_unrecorded: bool = False) -> VerifyOutput:
    """Check a results folder recorded with ``run --decisions``: replay each of its runs from its
    decisions alone, no planner built, against its rows (outcome, distance, steps, decisions), and
    check the folder whole (:func:`~semsearch_cli.runner.verify.verify_folder`): a row without its
    record, a record without its row, a row twice or of no run of the scenario, a record of
    another run each fail the verdict. ``scenario``: the scenario the rows were made with
    (default: the one meta.json names, with the parameter a sweep set in that folder); its
    planners' files are not needed. ``workers``: replaying processes (None: the CPU count, at
    most 4; the verdict does not depend on it). ``allow_unrecorded``: a folder recorded partly
    without ``--decisions``: its runs without a record (naming none) are counted, not failed. A
    bench folder (``semsearch bench run``) is verified floor by floor on the suite's own floors
    (:func:`~semsearch_cli.bench.verify_bench`; ``salt_file`` for a hidden split), every run
    recorded."""
    folder = Path(folder)
    cpus = os.cpu_count() or 1
    if workers is not None and workers > cpus:
        raise ScenarioError("<command line>", "--workers", f"{workers} replaying processes on {cpus} CPUs: at most {cpus}")
    if ros2.is_live_folder(folder):  # a robot's run (ros live --out): its bag replayed from its record
        return _verify_live(folder, scenario)
    check_folder_engine(folder)  # another engine's runs replay with the release that made them
    if bench.is_bench(folder):
        if scenario is not None:
            raise ScenarioError("<command line>", "--scenario", f"{folder} is a bench folder: its floors are the suite's "
                                "(bench.json); give --salt-file for a hidden split, never a scenario")
        if allow_unrecorded:
            raise ScenarioError("<command line>", "--allow-unrecorded", f"{folder} is a bench folder: a bench run records "
                                "every run, so each must have its record")
        return _verify_bench(folder, salt_file, progress, workers)
    if salt_file is not None:
        raise ScenarioError("<command line>", "--salt-file", f"{folder} is not a bench folder (no bench.json)")
    path, loaded = rows_scenario(folder, scenario)
    rows = read_runs(folder / "runs.csv", as_written=True)
    digests = rows["decisions_sha256"].astype(str).str.len().gt(0).any() if "decisions_sha256" in rows.columns else False
    if not records_in(folder) and not digests:  # never recorded (a row naming its record says it was)
        own = rows[rows["stage"] == ""]
        if len(own) and own["outcome"].astype(str).isin(UNFINISHED).all():
            raise ScenarioError(str(folder / "runs.csv"), "", f"all {len(own)} runs ended in an error or a timeout, which keep "
                                "no decisions record: nothing to replay")
        raise ScenarioError(str(folder / "decisions"), "", f"none of the {len(own)} runs has a decisions "
                            "record: run the batch with --decisions (the runs already done are not recorded again; run them "
                            "into a fresh folder)")
    verdict = verify_folder(folder, loaded, progress, workers_for(workers), allow_unrecorded)
    return VerifyOutput(folder, path, verdict)


def _verify_bench(folder: Path, salt_file=None, progress=None, workers: int | None = None) -> VerifyOutput:
    """:func:`verify` of a bench folder: the floors' verdicts as one, each run named with its floor."""
    split, verdicts = bench.verify_bench(folder, salt_file, workers_for(workers), progress)
    v = Verdict()
    for fid, fv in verdicts.items():
        v.runs += fv.runs
        v.verified += fv.verified
        v.unrecorded += fv.unrecorded
        v.unfinished += fv.unfinished
        v.failed += [(f"{'the bench folder' if fid == '(top)' else f'floor {fid}'}: {name}", why) for name, why in fv.failed]
    if not v.runs:
        raise ScenarioError(str(folder), "", "holds no floor with rows to verify")
    bench.board.write_verdict(folder, v.runs, v.verified, len(v.failed), v.unfinished)
    return VerifyOutput(folder, f"{split.suite.name} {split.name}, hash {split.hash[:16]}", v)
