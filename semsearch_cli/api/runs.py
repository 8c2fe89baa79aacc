"""``run``, ``sweep_alpha``, ``sweep`` and ``record``: batches of runs into a results folder (and
object search's recording mode), and the first prompt a language model would read."""

from __future__ import annotations

import os
from contextlib import ExitStack, nullcontext
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import yaml

from ..config import PlannerSpec, load_scenario, read_yaml, with_param
from ..config.scenario import load_yaml_text
from ..credentials import WHERE_THE_KEY_GOES, credential_in, redact
from ..errors import ScenarioError, did_you_mean
from ..planners import PLANNERS, expand_variants, planner_class
from ..planners.llm import FirstPrompt
from ..report import build as report_build
from ..report.document import atomic_text, markdown_table
from ..report.figures.distances import plot_alpha_sweep, plot_sweep
from ..report.tables import summarise, sweep_table
from ..runner import Batch, BatchOptions, Loaded, expand, folder_lock, make_executor, run_rows
from ..tasks import TASKS
from ..tasks.decisions import Seat
from ..tasks.objects import write_log
from ..files import check_outputs, inside, output_folder, temp_path
from ..shipped import scenario_file
from .reports import report


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
