"""The commands as Python functions; the CLI only parses, calls these and prints."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import time
from contextlib import ExitStack, nullcontext
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import yaml

from .config import PlannerSpec, load_scenario, read_yaml, scenario_schema, with_param
from .config.scenario import load_yaml_text
from .config.base import sign_label
from .deprecation import warn
from .credentials import WHERE_THE_KEY_GOES, credential_in, redact, url_credential
from .errors import MissingExtra, ScenarioError, did_you_mean
from .world.ground_truth import DuplicateSigns
from .world.buildings import numbered
from .world.importers import kth, mobilesim, ros
from .world.rooms import generate_rooms as make_rooms, write_rooms
from .belief.presence import presence_scores, read_counts
from .config.indirect import IndirectSpec
from .planners import PLANNERS, expand_variants, load_entry_points, planner_class
from .planners.base import check_params, load_planner_file, parse_entry, path_fields
from .planners.llm import FirstPrompt
from .plugins import load_kinds
from .report import build as report_build
from .report.document import atomic_text, markdown_table
from .report.figures.distances import plot_alpha_sweep, plot_sweep
from .report.tables import summarise, sweep_table
from .runner import Batch, BatchOptions, Loaded, expand, folder_lock, make_executor, run_rows, workers_for
from .runner.store import read_runs
from .runner.verify import UNFINISHED, Verdict, check_folder_engine, records_in, verify_folder
from .tasks import TASKS
from .tasks.decisions import Seat
from .tasks.doors import DoorTask
from .tasks.episodes import EPISODE_COLUMNS, set_hash
from .tasks.objects import write_log
from .files import check_outputs, inside, output_file, output_folder, temp_path
from . import bench, ros2, shipped
from .shipped import scenario_file


@dataclass
class RunOutput:
    out: Path
    runs: pd.DataFrame
    summary: pd.DataFrame


def default_out(loaded: Loaded, out: str | Path | None) -> Path:
    if out is not None:
        return output_folder(out)
    if loaded.sc.experiment.out:
        return (loaded.path.parent / loaded.sc.experiment.out).resolve()
    return Path("results") / loaded.sc.name


RECORDED = ("decisions_sha256",)  # a run recorded with --decisions names its record in its rows (semsearch verify)


def run(scenario: str | Path, options: BatchOptions = BatchOptions(), progress=None, plots: bool = True,
        planner_specs=None) -> RunOutput:
    """Run a scenario's experiment (:class:`~semsearch_cli.runner.BatchOptions` say which runs,
    where and how): rows to runs.csv, then summary.csv and the report's tables and PNG figures
    (``plots``). ``planner_specs`` (a list of :class:`~semsearch_cli.config.PlannerSpec`)
    replaces the scenario's planners. The output folder is locked for the command; rows of
    another (or an edited) scenario in it are refused unless ``options.force`` (see
    :func:`~semsearch_cli.runner.run_batch`). ``progress(row, done, total)`` is called as each run
    finishes.
    """
    options = options.checked()
    goals, planners = options.goals, options.planners
    loaded = Loaded.load(scenario_file(scenario))
    if planner_specs is not None:
        loaded = loaded.with_planners(planner_specs)
    if goals:
        known = {str(g) for g in loaded.goals}
        for g in goals:
            if str(g) not in known:
                raise ScenarioError("<command line>", "--goal", f"goal {g} is not among the scenario's goals {loaded.goals}")
    specs = expand(loaded, options.seeds, goals, planners)
    if not specs:
        raise _no_variant(loaded, planners)
    out_dir = default_out(loaded, options.out)
    with Batch(loaded, specs, out_dir, options, own=RECORDED if options.decisions else ()) as batch:  # held and checked, once
        report_build.write_meta(out_dir, loaded)
        loaded.task.write_inputs(out_dir)
        runs = batch.run(progress)
        summary = write_summary(runs, out_dir)
        if plots:
            report([out_dir], formats=("md", "csv", "png", "html"), replay=False)
    return RunOutput(out_dir, runs, summary)


class _DrySeat(Seat):
    """A dry run's seat: a planner that calls a language model stops at its first call
    (:class:`~semsearch_cli.planners.llm.FirstPrompt`) instead of making it."""

    def planner(self, variant):
        p = variant.build()
        p.dry_run = True
        return self.seat(p)


def first_prompt(scenario: str | Path, options: BatchOptions = BatchOptions()) -> str:
    """The first prompt a run of the scenario would send to a language model (``semsearch run
    --dry-run``): the first planner that calls one (``Planner.service``; among ``options.planners``
    when given) on the first episode (of ``options.goals``) that asks it anything, repeat 0, as the
    messages it would send (``--- system ---``, ``--- user ---``). Nothing is called and nothing
    is written."""
    loaded = Loaded.load(scenario_file(scenario))
    task = loaded.task
    chosen = set(map(str, options.planners or ()))
    variants = [v for v in task.variants() if planner_class(v).service and (not chosen or {v.name, v.label} & chosen)]
    if not variants:
        raise ScenarioError(str(loaded.path), "planners", "no planner of this scenario calls a language model (llm); "
                            "--dry-run prints the first prompt such a planner would send")
    cls = planner_class(variants[0])
    fault = cls.missing(variants[0].resolved(cls))
    if fault:  # what a real batch refuses before its first run, a dry run refuses too (it calls no server)
        raise ScenarioError(str(loaded.path), f"planners.{fault[0]}", f"{variants[0].label}: {fault[1]}")
    goals = set(map(str, options.goals or ()))
    for ep in task.episodes:
        if goals and str(ep.goal) not in goals:
            continue
        try:
            task.run(variants[0], ep, 0, seat=_DrySeat())
        except FirstPrompt as stop:
            return stop.text()
    raise ScenarioError(str(loaded.path), "planners", f"{variants[0].label} was asked nothing on these episodes (each "
                        "found its goal before a decision)")


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


@dataclass
class VerifyOutput:
    folder: Path
    scenario: Path | str  # the scenario replayed on, or a bench's "SUITE SPLIT (hash ...)"
    verdict: Verdict
    what: str = ""  # what ``scenario`` is, as the command line says it: scenario, suite, settings ("": by its type)


def _rows_scenario(folder: Path, scenario: str | Path | None) -> tuple[Path, Loaded]:
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


def export(folder: str | Path, out: str | Path, fmt: str = "mcap", run: str | None = None,
           scenario: str | Path | None = None, kept=None) -> list:
    """Every door-search run of a results folder recorded with ``--decisions`` (or the one named
    ``run``, its record's file stem) as a ROS 2 bag folder ``out/<run>`` (``fmt``: ``mcap`` or
    ``rosbag2``, SQLite 3), replayed from its decisions (:mod:`semsearch_cli.ros2`; the ``ros``
    extra). Runs whose bag exists already are kept (``kept``, when given, is called with each one's
    name). Returns the :class:`~semsearch_cli.ros2.Exported` runs."""
    if fmt not in ros2.FORMATS:
        raise ScenarioError("<command line>", "--format", f"{fmt!r} is not a bag format; use one of {', '.join(ros2.FORMATS)}")
    if not ros2.available():
        raise MissingExtra("semsearch export", "ros")
    folder = Path(folder)
    check_folder_engine(folder)
    _, loaded = _rows_scenario(folder, scenario)
    ros2.exportable(loaded)  # before the output folder is made
    with folder_lock(Path(out)):
        return ros2.export_folder(loaded, folder, Path(out), fmt, run, kept)


def ros_replay(bag: str | Path, planner: str, out: str | Path, scenario: str | Path | None = None, fmt: str = "mcap",
               planner_file: str | Path | None = None, goal: str | None = None, margin: float = 10.0):
    """Run a door planner (``NAME`` or ``NAME[key=value,...]``) over a bag, asked at each of its
    re-plans, and write its decisions as a new bag folder ``out``
    (:func:`~semsearch_cli.ros2.replay_bag`; the ``ros`` extra). A bag ``semsearch export`` wrote
    replays on ``scenario``, the one it was recorded on (default: the shipped scenario the bag
    names); a robot's own bag (a map, a pose, the detections) needs ``goal``, the label to find,
    takes its settings from ``scenario`` when given, and is folded into its first map and ``margin``
    metres around it (as :func:`ros_live` folds a robot's maps). Returns the
    :class:`~semsearch_cli.ros2.Replayed`."""
    _margin(margin)
    goal = _label(goal) if goal is not None else None
    if fmt not in ros2.FORMATS:
        raise ScenarioError("<command line>", "--format", f"{fmt!r} is not a bag format; use one of {', '.join(ros2.FORMATS)}")
    if not ros2.available():
        raise MissingExtra("semsearch ros replay", "ros")
    bag = Path(bag)
    if bag.is_file():
        raise ScenarioError(str(bag), "", f"is a file: give the bag's folder, {bag.parent} (a ROS 2 bag is a folder with "
                            "metadata.yaml)")
    if not bag.is_dir():
        raise ScenarioError(str(bag), "", "no such bag folder (a ROS 2 bag is a folder with metadata.yaml)")
    name = ros2.recorded_scenario(bag)  # None: a robot's own bag
    if scenario is None and name is not None:
        if name not in shipped.names():
            raise ScenarioError(str(bag), "/semsearch/setup", f"names the scenario {name!r}, which is not a shipped one: give "
                                "the scenario the bag was recorded on, --scenario FILE")
        scenario = name
    loaded = Loaded.load(scenario_file(scenario), planners=False) if scenario is not None else None
    return ros2.replay_bag(loaded, bag, _door_variant(planner, planner_file), Path(out), fmt, goal, margin)


def ros_live(rosbridge: str, planner: str, goal: str, scenario: str | Path | None = None, publish_only: bool = False,
             repro: str | Path | None = None, margin: float = 10.0, max_distance: float | None = None,
             planner_file: str | Path | None = None, silence: float = 30.0, log=None, out: str | Path | None = None):
    """Explore with a robot through rosbridge (``ws://HOST:PORT``) until the sign ``goal`` is
    read, door planner ``planner`` choosing where to go (:mod:`semsearch_cli.ros2.live`; the
    ``ros`` extra): the robot's /map, pose and /semsearch/detections in; /explore/frontiers,
    /semsearch/goal and Nav2 ``NavigateToPose`` goals out (none with ``publish_only``). The
    belief's, robot's and navigation's settings come from ``scenario`` when given, and its
    ``experiment.max_distance`` unless ``max_distance`` is; ``margin`` metres of grid surround the
    robot's first map. The planner is seated as in a batch, and the run's folder ``out`` (default
    ``live-DATE-TIME``) gets its bag, decisions record, transcript and ``run.json``
    (:mod:`semsearch_cli.ros2.folder`), which ``semsearch verify`` checks. ``repro`` (deprecated
    since 0.4.0): with no ``out``, only a failed run's bag, there, as before 0.4.0. ``log`` takes a
    line of progress. Returns the :class:`~semsearch_cli.ros2.LiveRun`."""
    if not ros2.available("rosbags", "roslibpy"):  # rosbags: the repro bag
        raise MissingExtra("semsearch ros live", "ros")
    _margin(margin)
    if max_distance is not None and not max_distance > 0:
        raise ScenarioError("<command line>", "--max-distance", f"{max_distance:g} m: give more than 0")
    if not 0 < silence < math.inf:
        raise ScenarioError("<command line>", "--silence", f"{silence:g} s: give a number of seconds over 0")
    goal = _label(goal)
    loaded = Loaded.load(scenario_file(scenario), planners=False) if scenario is not None else None
    if loaded is not None and not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind}: a robot explores with door planners only")
    if max_distance is None and loaded is not None:
        max_distance = loaded.sc.experiment.max_distance
    if repro is not None:
        warn("ros live --repro (a failed run's bag alone)", "give --out DIR: a folder with every run's bag, its decisions "
             "record (semsearch verify DIR checks it) and its planner's transcript", since="0.4.0", until="0.5.0")
    elif out is None:
        out = f"live-{time.strftime('%Y%m%d-%H%M%S')}"
    variant = _door_variant(planner, planner_file)
    live = ros2.Live(rosbridge, variant, goal, loaded.sc if loaded is not None else None,
                     publish_only, repro, margin, max_distance, silence, log, out=out)
    res = live.run()
    if out is not None:
        ros2.write_live_folder(Path(out), res, planner=variant.label, goal=goal,
                               scenario=loaded.path.resolve() if loaded is not None else None,
                               fingerprint=loaded.fingerprint if loaded is not None else None, margin=margin,
                               max_distance=None if max_distance is None or math.isinf(max_distance) else max_distance,
                               publish_only=publish_only)
    return res


def _verify_live(folder: Path, scenario: str | Path | None) -> VerifyOutput:
    """A live run's folder (``ros live --out``), replayed from its record: its scenario the one
    ``run.json`` names (or ``scenario``), none for a run on the defaults."""
    if not ros2.available("rosbags"):
        raise MissingExtra("semsearch verify (a live run's bag)", "ros")
    run = ros2.read_run(folder / "run.json")
    named = scenario if scenario is not None else run.get("scenario")
    loaded = Loaded.load(scenario_file(named), planners=False) if named is not None else None
    return VerifyOutput(folder, loaded.path if loaded is not None else "the robot's defaults", ros2.verify_live(folder, loaded),
                        "settings of")


def ros_sim(scenario: str | Path, goal: str, seed: int = 0, port: int = 9090, period: float = 0.2,
            follow: str | None = None):
    """A robot without ROS to try :func:`ros_live` on: the simulator's robot of ``scenario``
    (goal ``goal``'s first episode, repeat ``seed``) behind a rosbridge server on
    ``ws://127.0.0.1:port`` (:mod:`semsearch_cli.ros2.loopback`), a step every ``period`` seconds
    (0.2: a step of 0.1 m at 0.5 m/s); with ``follow``, it also drives to each PoseStamped a
    client publishes on that topic (``--publish-only``'s goals). Returns the started
    :class:`~semsearch_cli.ros2.loopback.SimRobot`; ``robot.bridge.stop()`` ends it."""
    if not ros2.available("rosbags", "websockets"):  # rosbags: its messages
        raise MissingExtra("semsearch ros sim", "ros")
    if not 0 < period < math.inf:
        raise ScenarioError("<command line>", "--period", f"{period:g} s: give a number of seconds over 0")
    if follow is not None and not follow.startswith("/"):
        raise ScenarioError("<command line>", "--follow", f"{follow!r}: give a topic's absolute name, e.g. /semsearch/goal")
    loaded = Loaded.load(scenario_file(scenario), planners=False)
    if not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind}: the stand-in robot searches for door signs")
    goal = _label(goal)
    if loaded.world.signs.index_of(goal) < 0:
        goals = ", ".join(str(g) for g in loaded.goals)
        raise ScenarioError(str(loaded.path), "--goal", f"no door sign carries {goal!r} in this scenario"
                            f"{did_you_mean(goal, [str(n) for n in loaded.world.signs.number])}; its goals: {goals} "
                            f"(any of its {len(loaded.world.signs.number)} signs may be one)")
    bridge = ros2.Rosbridge(port=port)
    try:
        bridge.start()
    except OSError as exc:
        raise ScenarioError("<command line>", "--port", f"{port}: {exc.strerror or exc}") from None
    return ros2.SimRobot(bridge, loaded, goal, seed, period=period, follow=follow).start()


def _margin(margin: float) -> None:
    if not 0 <= margin <= ros2.MAX_MARGIN:
        raise ScenarioError("<command line>", "--margin", f"{margin:g} m: give 0 to {ros2.MAX_MARGIN:g} metres of grid around "
                            "the first map")


def _label(goal) -> str | int:
    """A goal's label as signs carry it (a whole number is a number), or a ScenarioError."""
    try:
        return sign_label(goal)
    except ValueError as exc:
        raise ScenarioError("<command line>", "--goal", f"{goal!r}: {exc}") from None


def _door_variant(planner: str, planner_file: str | Path | None):
    """The one door-planner variant ``planner`` (NAME or NAME[key=value,...]) names."""
    variants = expand_variants([planner_spec(planner, planner_file)], "<command line>", TASKS["doors"].planner_kind)
    if len(variants) != 1:
        raise ScenarioError("<command line>", "--planner", f"{planner!r} names {len(variants)} variants: give one value per "
                            "parameter")
    return variants[0]


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
    path, loaded = _rows_scenario(folder, scenario)
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


def sweep_alpha(scenario: str | Path, alphas: list[float], options: BatchOptions = BatchOptions(), progress=None) -> RunOutput:
    """The planner that sweeps alpha (:attr:`Planner.swept`: nsos) at each alpha with the baseline
    planner (:attr:`Planner.baseline`: greedy) beside it: the rows and summary of :func:`run`, plus
    ``plots/alpha_sweep.png``. The swept planner is the scenario's first entry of one that sweeps
    alpha (its other parameters kept), else the built-in one of the scenario's kind."""
    scenario = scenario_file(scenario)
    sc = load_scenario(scenario)
    answers = TASKS[sc.kind].planner_kind
    sweeping = {n: c for n, c in PLANNERS.items() if c.swept == "alpha" and c.answers(answers)}
    baseline = next((n for n, c in PLANNERS.items() if c.baseline and c.answers(answers)), None)
    if not sweeping or baseline is None:
        raise ScenarioError(str(scenario), "kind", f"no registered planner for {sc.kind} scenarios sweeps alpha beside a "
                            "baseline; sweep a planner's own parameter with `semsearch sweep --param PLANNER.PARAM=V1,V2`")
    entry = next((p for p in sc.planners if p.name in sweeping), None)
    name = entry.name if entry is not None else next(iter(sweeping))
    base = entry.params() if entry is not None else {}
    base.pop("alpha", None)
    specs = [PlannerSpec(name=baseline), PlannerSpec(name=name, alpha=[float(a) for a in alphas], **base)]
    res = run(scenario, options.replace(planners=None), progress, True, planner_specs=specs)
    labels = {v.label for v in expand_variants(specs, str(scenario))}
    (res.out / "plots").mkdir(parents=True, exist_ok=True)
    plot_alpha_sweep(run_rows(res.runs)[run_rows(res.runs)["planner"].isin(labels)], res.out / "plots" / "alpha_sweep.png")
    return res


@dataclass
class SweepOutput:
    out: Path
    runs: pd.DataFrame  # every run, with the parameter's value in column ``value``
    table: pd.DataFrame


def _typed(param: str, value, loaded: Loaded) -> None:
    """A sweep value is typed by the field it sets: ``true`` or ``false`` sets a yes/no field
    only (pydantic would read it as 1 or 0 in a number field)."""
    if not isinstance(value, bool):
        return
    keys = param.split(".")
    cls = PLANNERS.get(keys[0])
    if cls is not None and len(keys) == 2 and keys[1] in cls.Params.model_fields:
        is_bool = cls.Params.model_fields[keys[1]].annotation is bool
    else:
        got = loaded.sc.model_dump()
        for k in keys:
            got = got.get(k) if isinstance(got, dict) else None
        is_bool = isinstance(got, bool)
    if not is_bool:
        raise ScenarioError("<command line>", "--param", f"{param}={str(value).lower()}: this field holds numbers or text, "
                            "not yes/no; give its values")


def _no_variant(loaded: Loaded, planners) -> ScenarioError:
    """The error of a ``--planner`` list that matches no variant of the scenario: each name with
    the nearest variant names and labels, and those there are."""
    variants = loaded.task.variants()
    valid = sorted({v.name for v in variants} | {v.label for v in variants})
    near = "; ".join(f"{p!r}{did_you_mean(p, valid)}" for p in planners or ())
    return ScenarioError("<command line>", "--planner", f"no planner variant matches {near or planners}; the scenario's "
                         f"variants: {', '.join(valid[:12])}{', ...' if len(valid) > 12 else ''}")


def parse_param(text: str) -> tuple[str, list]:
    """``SECTION.FIELD=V1,V2,...`` -> (dotted name, values read as YAML scalars); an address
    holding a credential is refused, never shown (its value would name a folder)."""
    secret = credential_in(text)
    if secret:
        raise ScenarioError("<command line>", "--param", f"{redact(text)!r} holds {secret}: {WHERE_THE_KEY_GOES}")
    name, eq, vals = text.partition("=")
    items = [v.strip() for v in vals.split(",") if v.strip()]
    if not eq or not name.strip() or not items:
        raise ScenarioError("<command line>", "--param", f"expected SECTION.FIELD=V1,V2,... (e.g. door_camera.p_misread=0,0.05,0.1), got {text!r}")
    values = []
    for v in items:
        # read as a scenario's YAML is (ScenarioLoader): numbers as written, so that 1_5 and 010 are
        # text its field refuses, and 5,000 digits are text too (yaml.safe_load's int() of them raised
        # a ValueError, a traceback)
        try:
            values.append(load_yaml_text(v))
        except (yaml.YAMLError, ValueError, RecursionError):
            raise ScenarioError("<command line>", "--param", f"cannot read the value {v[:40]!r}") from None
    return name.strip(), values


def _load_value(path: Path, data: dict, param: str, value) -> Loaded:
    """The scenario with ``param`` set to ``value``; a value its field refuses is blamed on
    ``--param`` (the file is not at fault)."""
    try:
        return Loaded.load(path, with_param(data, param, value, path))
    except ScenarioError as exc:
        own = exc.field == param or exc.field.startswith(param + ".") or (  # a section's field, or a planner's parameter
            exc.field.startswith("planners[") and exc.field.split(".")[-1] == param.split(".")[-1])
        if exc.file == str(path) and own:
            shown = str(value).lower() if isinstance(value, bool) else redact(value)
            cut = (lambda t: t if len(t) <= 80 else f"{t[:60]}... ({len(t):,} characters)")  # 5,000 digits: not twice in full
            raise ScenarioError("<command line>", "--param", f"{param}={cut(shown)} "
                                f"({exc.field} of the scenario): {exc.message.replace(shown, cut(shown))}") from None
        raise


def sweep(scenario: str | Path, param: str, values: list, options: BatchOptions = BatchOptions(), progress=None) -> SweepOutput:
    """Run a scenario once per value of one parameter (see
    :func:`~semsearch_cli.config.with_param`): each value's rows go to ``out/<param>=<value>/``
    (resumable, as :func:`run`), then ``sweep.csv``, ``sweep.md`` and ``sweep.png`` compare them.
    Every value is checked before anything runs."""
    options = options.checked()
    path = scenario_file(scenario)
    data = read_yaml(path)
    loaded = [_load_value(path, data, param, v) for v in values]
    for v, ld in zip(values, loaded):
        _typed(param, v, ld)
    out_dir = Path(options.out) if options.out else inside(Path("results"), f"{loaded[0].sc.name}-sweep-{param}")
    # one Dask cluster (or client) for every value; the process pool starts per value (a fork costs little)
    shared = (make_executor(options.workers, None, options.executor, options.scheduler) if options.executor != "processes"
              else nullcontext())
    with folder_lock(out_dir), shared as runner, ExitStack() as held:
        check_outputs(out_dir, ("sweep.csv", "sweep.md", "sweep.png"))
        subs = [inside(out_dir, f"{param}={v}") for v in values]
        batches = []
        for ld, sub in zip(loaded, subs):  # every value's folder held and checked (foreign rows refused) before anything runs
            specs = expand(ld, options.seeds, options.goals, options.planners)
            if not specs:
                raise _no_variant(ld, options.planners)
            batches.append(held.enter_context(Batch(ld, specs, sub, options, own=RECORDED if options.decisions else ())))
        frames = []
        for v, ld, sub, batch in zip(values, loaded, subs, batches):
            report_build.write_meta(sub, ld, {"param": param, "value": v})
            ld.task.write_inputs(sub)
            runs = batch.run(progress, runner=runner)
            write_summary(runs, sub)
            frames.append(run_rows(runs).assign(value=v))
        runs = pd.concat(frames, ignore_index=True)
        table = sweep_table(runs, param)
        tmp = temp_path(out_dir / "sweep.csv")
        table.to_csv(tmp, index=False)
        os.replace(tmp, out_dir / "sweep.csv")
        atomic_text(out_dir / "sweep.md", markdown_table(table, fmt="{:g}") + "\n")
        plot_sweep(table, param, out_dir / "sweep.png")
    return SweepOutput(out_dir, runs, table)


def write_summary(runs: pd.DataFrame, out_dir: Path) -> pd.DataFrame:
    """summary.csv: per scenario x goal x planner, the statistics of the runs' distances."""
    summary = summarise(run_rows(runs))
    tmp = temp_path(out_dir / "summary.csv")
    summary.to_csv(tmp, index=False)
    os.replace(tmp, out_dir / "summary.csv")
    return summary


def record(scenario: str | Path, out: str | Path, cases=None) -> list[tuple[Path, int]]:
    """Write each case's detection log (recorded by patrolling, or read from its CSV) to ``out``."""
    loaded = Loaded.load(scenario_file(scenario))
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
        f = inside(Path(out), f"{name}.csv")
        write_log(logs[name], f)
        written.append((f, len(logs[name])))
    return written


def imported(importer, out: str | Path, *args, **kwargs) -> tuple[Path, list[str]]:
    """Run an importer (``import_ros``, ``import_kth``, ``import_mobilesim``: ``importer(*args,
    out=folder, **kwargs)`` -> (scenario path, notes)) into a hidden folder beside ``out``,
    validate what it wrote with the same code as :func:`validate`, and only then move the files
    into ``out``. A scenario that would not validate is a :class:`ScenarioError` (exit 2), and
    ``out`` is left as it was."""
    out = output_folder(out)
    work = out / f".import.{os.getpid()}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir()
    try:
        path, notes = importer(*args, out=work, **kwargs)
        try:
            validate(path)
        except DuplicateSigns as exc:
            raise ScenarioError(str(args[-1] if args else out), "", f"{exc.count} sign number(s) appear more than once: "
                                f"{exc.listed} (positions after snapping onto the walls). Nothing was written: import again with --duplicates keep-first (the "
                                "first sign of each number is kept) or --duplicates any (every sign is kept; the goal is "
                                "found at whichever sign carries it)") from None
        except ScenarioError as exc:
            raise ScenarioError(str(out / path.name), exc.field, f"the imported scenario would not validate, so "
                                f"nothing was written: {exc.message}") from None
        for f in sorted(work.iterdir()):
            os.replace(f, out / f.name)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out / path.name, notes


def schema_text() -> str:
    """The scenario JSON Schema (every kind's model), as ``semsearch schema`` writes it."""
    return json.dumps(scenario_schema(), indent=2) + "\n"


def schema(out: str | Path | None = None) -> Path | None:
    """Write the scenario JSON Schema to ``out`` (.json, atomically); None: return nothing (the
    caller prints :func:`schema_text`). Editors read it through the first line of a scenario,
    ``# yaml-language-server: $schema=PATH``, for completion and checking as you type."""
    if out is None:
        return None
    path = output_file(out, "--out", (".json",))
    atomic_text(path, schema_text())
    return path


def validate(scenario: str | Path) -> dict:
    """Every check of the loader, plus counts, each goal's shortest path from the scenario's start
    and the episode set (no simulation)."""
    task = Loaded.load(scenario_file(scenario)).task
    eps = task.episodes
    sp = [e.shortest_m for e in eps]
    return {**task.describe(), "episodes": f"{len(eps)} over {len({str(e.goal) for e in eps})} goals, shortest paths "
            f"{min(sp):.1f}-{max(sp):.1f} m, set hash {set_hash(eps)} (semsearch episodes writes them)"}


def show(scenario: str | Path, out: str | Path) -> Path:
    """Draw a scenario (map, signs or places, start, goals) to a PNG without simulating."""
    out = output_file(out, "--out", (".png", ".pdf", ".svg"))
    loaded = Loaded.load(scenario_file(scenario))
    return report_build.show(loaded, out)


def episodes(scenario: str | Path, out: str | Path) -> tuple[Path, list, str]:
    """Write a scenario's episode set to the CSV ``out`` (episode, goal, start_x, start_y,
    start_heading, room, shortest_m, hash), atomically; returns (file, episodes, set hash).
    ``episodes: {file: that.csv}`` in a scenario runs exactly that set."""
    loaded = Loaded.load(scenario_file(scenario))
    eps = loaded.task.episodes
    rows = pd.DataFrame([loaded.task.episode_row(e) for e in eps], columns=EPISODE_COLUMNS)
    path = output_file(out, "--out", (".csv",))
    tmp = temp_path(path)
    rows.to_csv(tmp, index=False)
    os.replace(tmp, path)
    return path, eps, set_hash(eps)


_ROLE = re.compile(r":(?:class|func|meth|attr|mod|data|exc|obj):`(~?)([\w.]+)`")


def _plain_doc(text: str) -> str:
    """A docstring's text for a console: Sphinx roles (``:class:`~a.B```) as their plain names
    (``B``), double backquotes as single quotes."""
    text = _ROLE.sub(lambda m: m.group(2).rsplit(".", 1)[-1] if m.group(1) else m.group(2), text)
    return text.replace("``", "'")


def _shown(path: str | Path) -> str:
    """A path as the user would type it: relative to the working folder when it lies inside it."""
    p = Path(path)
    try:
        return p.relative_to(Path.cwd()).as_posix()
    except ValueError:
        return str(p)


def planners(scenario: str | Path | None = None) -> list[dict]:
    """Every planner semsearch can run: built-in, from installed packages (entry points) and,
    with ``scenario``, from the files it names; each with its kind of search (comma-separated
    for one that answers several), where it comes from, its description and its parameters
    (name, type, default, description)."""
    load_kinds()
    load_entry_points()
    own = {}
    if scenario is not None:
        loaded = Loaded.load(scenario_file(scenario))
        own = {v.name: v.module for v in loaded.task.variants() if v.module}
    out = []
    for name, cls in sorted(PLANNERS.items(), key=lambda kv: (kv[1].task, kv[0])):
        mod = cls.__module__
        source = (f"file {_shown(own[name])}" if name in own else "built-in" if mod.startswith("semsearch_cli.")
                  else f"module {mod}")
        if mod.startswith("semsearch_user_planners.") and name not in own:
            continue  # a file some other scenario loaded in this process
        doc = _plain_doc((cls.__doc__ or "").strip().split("\n\n")[0])
        params = [{"name": k, "type": getattr(f.annotation, "__name__", str(f.annotation)),
                   "default": None if f.is_required() else f.default, "description": f.description or ""}
                  for k, f in cls.Params.model_fields.items()]
        out.append({"name": name, "kind": ", ".join(cls.kinds) if cls.kinds else cls.task, "source": source,
                    "description": " ".join(doc.split()), "params": params, "privileged": cls.privileged})
    return out


def scenarios() -> list[dict]:
    """The shipped scenarios (package data): each one's ``name`` (what ``semsearch run NAME``
    takes), ``kind``, ``file`` and ``description`` (:func:`semsearch_cli.shipped.describe`)."""
    out = []
    for name in shipped.names():
        sc = load_scenario(shipped.path(name))
        out.append({"name": name, "kind": sc.kind, "file": shipped.path(name), "description": shipped.describe(name)})
    return out


def init(name: str, folder: str | Path, force: bool = False) -> list[Path]:
    """Copy the shipped scenario ``name`` and the files it names into ``folder``, to edit (see
    :func:`semsearch_cli.shipped.init`); the copy is validated before this returns."""
    written = shipped.init(name, output_folder(folder, "DIR"), force)
    Loaded.load(written[0])
    return written


# ---- hours, buildings, rooms and maps of one's own -------------------------------------------------
LAYOUTS, SCHEMES = numbered.LAYOUTS, numbered.SCHEMES  # generate_building's layouts and numbering schemes
KTH_CORRIDOR_TYPES = kth.CORRIDOR_TYPES  # import_kth's default corridor types


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


def generate_building(layout: str, numbering: str, seed: int, out: str | Path, spacing: float = 2.5, signs: int | None = None,
                      goals: list | None = None, name: str | None = None, scale: float = 1.0, skip: float = 0.0,
                      letters: float = 0.0, extension: bool = False, style: str = "plain", letter_case: str = "lower") -> Path:
    """Write a generated building into ``out`` (map.png, doors.csv and a scenario that runs as it
    is); returns the scenario's path. ``goals``: door numbers (default: four spread by distance).
    ``skip``, ``letters``, ``extension`` and ``style``: what real floors add (numbers skipped,
    lettered doors (``letter_case`` lower or upper), an extension renumbered, wing prefixes or
    floor-dot-room labels; see
    :func:`~semsearch_cli.world.buildings.numbered.generate_building`)."""
    if goals and any(not isinstance(g, int) or isinstance(g, bool) for g in goals):
        raise ScenarioError("<command line>", "--goals", f"expected door numbers, got {','.join(map(str, goals))!r}")
    return numbered.generate_building(layout, numbering, seed, output_folder(out), spacing=spacing, signs=signs, goals=goals,
                                      name=name, scale=scale, skip=skip, letters=letters, extension=extension, style=style,
                                      letter_case=letter_case)


def _among(items, valid: tuple, flag: str) -> tuple:
    """``items`` (None: all of ``valid``), each checked to be one of ``valid``."""
    if items is None:
        return valid
    items = tuple(items)
    bad = [t for t in items if t not in valid]
    if bad or not items:
        raise ScenarioError("<command line>", flag, f"unknown value(s) {bad or list(items)}; valid: {', '.join(valid)}")
    return items


def generate_batch(out: str | Path, seeds: int = 3, runs: int = 3, layouts=None, schemes=None) -> list[Path]:
    """Every layout x numbering scheme x seed (``layouts``, ``schemes``: None for all) into ``out``,
    one sub-folder each and index.txt: a robustness set. Returns the scenarios' paths."""
    return numbered.generate_batch(output_folder(out), seeds=seeds, runs=runs, layouts=_among(layouts, LAYOUTS, "--layouts"),
                                   schemes=_among(schemes, SCHEMES, "--schemes"))


def generate_rooms(n: int, seed: int, out: str | Path, size: tuple[float, float] = (6.0, 6.0),
                   obstacles: int = 0) -> tuple[Path, list]:
    """``n`` rooms for indirect search as the paper's (Loncomilla et al. 2018, Section 4.5) into
    ``out``/rooms.yaml; returns (its path, the rooms)."""
    w, d = size
    if not (1.0 <= w <= 50.0 and 1.0 <= d <= 50.0):
        raise ScenarioError("<command line>", "--size", f"W and D must lie between 1 and 50 m (got {w:g},{d:g})")
    spec = IndirectSpec()
    try:
        rooms = make_rooms(n, seed, spec.relations, spec.masks, spec.target, (w, d), obstacles)
    except ValueError as exc:  # no free place for an object: the boxes took it, or the room is too small for the rings
        raise ScenarioError("<command line>", "--obstacles" if obstacles else "--size",
                            f"{exc}" + ("" if obstacles else f" (a {w:g} x {d:g} m room is too small for the objects' "
                                                             "rings; give a larger --size)")) from None
    return write_rooms(output_folder(out) / "rooms.yaml", rooms), rooms


def import_mobilesim(map_file: str | Path, doors_file: str | Path, out: str | Path, **options) -> tuple[Path, list[str]]:
    """A MobileSim map and door file as a scenario in ``out`` (see
    :func:`~semsearch_cli.world.importers.mobilesim.import_mobilesim` for ``options``), validated
    before it is written (:func:`imported`); returns (the scenario's path, notes)."""
    return imported(mobilesim.import_mobilesim, out, Path(map_file), Path(doors_file), **options)


def import_ros(map_file: str | Path, doors_file: str | Path, out: str | Path, **options) -> tuple[Path, list[str]]:
    """A scenario over a ROS map (map_server YAML) and a doors CSV in ``out`` (see
    :func:`~semsearch_cli.world.importers.ros.import_ros`), validated before it is written."""
    return imported(ros.import_ros, out, Path(map_file), Path(doors_file), **options)


def import_kth(xml_file: str | Path, out: str | Path, **options) -> tuple[Path, list[str]]:
    """A KTH campus floor plan as a scenario in ``out`` (see
    :func:`~semsearch_cli.world.importers.kth.import_kth`), validated before it is written."""
    return imported(kth.import_kth, out, Path(xml_file), **options)


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
    bench.board.write_verdict(folder, split.hash, v.runs, v.verified, len(v.failed), v.unfinished)
    return VerifyOutput(folder, f"{split.suite.name} {split.name}, hash {split.hash[:16]}", v)


def planner_spec(text: str, module: str | Path | None = None) -> PlannerSpec:
    """A planner given on the command line, ``NAME`` or ``NAME[key=value,...]`` (as rows label
    it: ``nsos[alpha=0.9]``), registered by ``module`` (a user's Python file) when given. A
    parameter that names a file (the llm planner's ``prompt``, ``replay``) is taken relative to the
    working folder, and written absolute."""
    name, params = parse_entry(text)  # its form, and no key in an address (refused, never shown)
    m = {"name": name}
    if module is not None:  # the file's planners come from it; a built-in (or installed) planner beside them does not
        mod = Path(module)
        if not mod.is_file():
            raise ScenarioError(str(mod), "", "no such planner file (--planner-file)")
        mine = load_planner_file(mod)
        if m["name"] not in mine and m["name"] not in PLANNERS:
            load_entry_points()  # a planner of an installed package, named beside the file's
        if m["name"] in mine or m["name"] not in PLANNERS:
            params["module"] = str(mod.resolve())
    cls = PLANNERS.get(m["name"])
    if cls is not None:  # a parameter its planner refuses, named: 'nsos[alpha=2]': alpha must be at most 1
        try:
            fault = check_params(cls, name, {k: v for k, v in params.items() if k != "module"})
        except (Exception, SystemExit):  # a user's validator that raises: expand_variants names its line
            fault = None
        if fault:
            raise ScenarioError("<command line>", "--planner", fault[1])
    for k in path_fields(cls.Params) if cls is not None else ():  # a file named here is relative to this folder, not the floor's
        if isinstance(params.get(k), str) and not Path(params[k]).is_absolute():
            params[k] = str(Path(params[k]).resolve())
    return PlannerSpec(name=m["name"], **params)


def bench_run(suite: str, planners: list[str], out: str | Path, split: str = "val", numbering: str = "true",
              options: BatchOptions = BatchOptions(), limit: int | None = None, salt_file: str | Path | None = None,
              planner_file: str | Path | None = None, progress=None) -> bench.BenchOutput:
    """Run planners (``NAME`` or ``NAME[key=value,...]``, :func:`planner_spec`) on a suite's
    split into ``out`` (:func:`~semsearch_cli.bench.run_bench`)."""
    if not planners:
        raise ScenarioError("<command line>", "--planner", "give the planner to run (NAME or NAME[key=value,...])")
    specs = [planner_spec(p, planner_file) for p in planners]
    return bench.run_bench(suite, specs, out, split, numbering, options, limit, salt_file, progress)


def bench_list() -> list[dict]:
    """Every suite's splits: kind, floors, goals, episodes, repeats, hash (shipped splits) and the
    published hash."""
    rows = []
    for s in bench.SUITES.values():
        for split in s.splits:
            row = {"suite": s.name, "split": split, "kind": s.kind, "repeats": s.repeats, "summary": s.summary,
                   "published": bench.PUBLISHED.get((s.name, split))}
            if split in s.hidden:
                row.update(floors=None, goals=None, episodes=None, hash=None, hidden=True)
            elif s.fetched and not bench.real.is_fetched(s):
                row.update(floors=None, goals=None, episodes=None, hash=None, hidden=False, fetch=True,
                           sources=len(bench.real.read_sources(s.name)["floors"]))
            else:
                sp = bench.open_split(s.name, split)
                eps = [pd.read_csv(f.scenario.parent / "episodes.csv", dtype=str, keep_default_na=False) for f in sp.floors]
                rooms = sum(e["room"].nunique() for e in eps if (e["room"] != "").all())  # indirect search: rooms, not floors
                row.update(floors=f"{rooms} rooms" if rooms else len(sp.floors), goals=sum(e["goal"].nunique() for e in eps),
                           episodes=sum(len(e) for e in eps), hash=sp.hash, hidden=False)
            rows.append(row)
    return rows


def bench_board(folders, out: str | Path) -> list[Path]:
    """The results page of bench folders into ``out`` (index.html, board.md, the figure and the
    per-floor table): :mod:`semsearch_cli.bench.board`."""
    if not folders:
        raise ScenarioError("<command line>", "FOLDERS", "give one or more bench results folders")
    return bench.board.board([Path(f) for f in folders], out)


def bench_fetch(suite: str, from_dirs=(), mirror: str | None = None, partial: bool = False, progress=None):
    """Fetch a track of floors that may not be shipped (:mod:`semsearch_cli.bench.real`) and
    build its split in the cache; returns (the split, the floors left out with why)."""
    s = bench.suite_named(suite)
    if not s.fetched:
        raise ScenarioError("<command line>", "SUITE", f"{suite} is shipped with semsearch: nothing to fetch (the tracks to "
                            f"fetch: {', '.join(n for n, x in bench.SUITES.items() if x.fetched)})")
    for d in from_dirs:
        if not Path(d).is_dir():
            raise ScenarioError(str(d), "--from", "no such folder")
    secret = url_credential(mirror)
    if secret:  # a fetch's messages name the address it fetched
        raise ScenarioError("<command line>", "--mirror", f"{redact(mirror)!r} holds {secret}: a mirror is fetched without "
                            "credentials; serve it where none is needed, or copy the files and give --from DIR")
    return bench.real.fetch(s, [Path(d) for d in from_dirs], mirror, partial, progress)


def bench_hash(suite: str, split: str = "val", salt_file: str | Path | None = None) -> bench.Split:
    """A split, built (a hidden one from ``salt_file``) and hashed: its ``hash`` and whether it is
    the published one (``official``)."""
    return bench.open_split(suite, split, salt_file)
