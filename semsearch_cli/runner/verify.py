"""Verify a results folder by replaying its runs from their decisions (``semsearch verify``).

Each run's row that has a decisions record (``decisions/<run>.json``, written by ``semsearch run
--decisions``) is run again with the record answering every decision point
(:class:`~semsearch_cli.tasks.decisions.Replay`): no planner is built, so a run of a planner whose
code is not at hand (a learned policy, a language model, a colleague's planner) is checked all
the same. The replay's rows must equal the folder's in outcome, distance and steps (and decisions,
and a chain's stage rows), exactly as written; any other result, or a replay that cannot go on,
names the run.

The folder is checked whole, not only the runs that kept a record: a finished run's row without
its record, a record without its row, a row twice or of no episode of the scenario, a record that
names another run or scenario each fail the verdict (:func:`verify_folder`). A row recorded with
``--decisions`` names its record (``decisions_sha256``, the SHA-256 of its bytes); an error or
timeout row keeps none (the run did not finish) and must claim no result."""

from __future__ import annotations

import hashlib
import math
import multiprocessing as mp
import numbers
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path


from ..engine import ENGINE, engine_of, refusal
from ..errors import PlannerError, ScenarioError
from ..planners import Variant
from ..tasks.decisions import Replay, ReplayError
from .specs import Loaded, file_stem
from .store import read_decisions, read_runs

COMPARED = ("outcome", "distance_m", "steps", "decisions")  # what a replay must give exactly, per row


@dataclass
class Verdict:
    """What :func:`verify_folder` found. ``runs``: the folder's runs (its rows of whole runs);
    ``verified``: runs replayed to their rows; ``failed``: (what, why) of each run, row or record
    that does not hold (a run that does not replay, a row without its record, a record without its
    row, a row twice, a row of no run of the scenario); ``unrecorded``: runs without a record
    that ``allow_unrecorded`` let pass unchecked; ``unfinished``: error and timeout runs, which
    keep no record (a run that did not finish has no decisions to replay) and claim nothing."""

    runs: int = 0
    verified: int = 0
    failed: list = field(default_factory=list)
    unrecorded: int = 0
    unfinished: int = 0


UNFINISHED = ("error", "timeout")  # outcomes of a run that did not finish: no decisions record is written for them


def run_name(planner, goal, episode, seed) -> str:
    return f"{planner} goal {goal} episode {episode} seed {seed}"


def _same(a, b) -> bool:
    """Equal as written: numbers by value (NaN equal to NaN), anything else as text."""
    if isinstance(a, numbers.Number) and isinstance(b, numbers.Number):
        fa, fb = float(a), float(b)
        return fa == fb or (math.isnan(fa) and math.isnan(fb))
    return str(a) == str(b)


def _whole(v) -> int | None:
    """``v`` as a whole number from 0 to 999,999,999 (an episode, a seed), else None."""
    if isinstance(v, bool) or not (isinstance(v, numbers.Integral) or (isinstance(v, float) and v.is_integer())):
        return None
    return int(v) if 0 <= v < 10**9 else None


def _claims_nothing(row: dict) -> bool:
    """An error or timeout row as a run that did not finish writes it: no success, no distance."""
    success, distance = row.get("success"), row.get("distance_m")
    no_distance = distance is None or str(distance) == "" or (isinstance(distance, numbers.Number) and math.isnan(float(distance)))
    return _same(success, 0) and no_distance


def _below_shortest(row: dict, episode) -> str:
    """Why a row that claims success over less than its episode's shortest path is no run, or ""
    (a run no record checks is held to what any run obeys)."""
    try:
        success, distance, shortest = float(row.get("success")), float(row.get("distance_m")), float(episode.shortest_m)
    except (TypeError, ValueError, AttributeError):
        return ""
    if success > 0 and math.isfinite(shortest) and distance < 0.99 * shortest:
        return f"found its goal in {distance:g} m, below its episode's shortest path {shortest:.3f} m: no run travels that"
    return ""


def check_engine(rows, path: Path) -> None:
    """Refuse rows (read by :func:`~semsearch_cli.runner.store.read_runs`) that another simulator
    engine made: a :class:`ScenarioError` naming the release that replays them
    (:func:`semsearch_cli.engine.refusal`). What replays a run (verify, export, a bag's replay)
    checks this first: another engine's run does not replay here, and that is no failure of the run."""
    engines = sorted({int(e) for e in rows["engine"]} - {ENGINE}) if len(rows) else []
    if engines:
        raise ScenarioError(str(path), "engine", refusal(engines[0], f"{'this folder' if path.name == 'runs.csv' else path}"))


def check_folder_engine(folder: Path) -> None:
    """:func:`check_engine` over every runs.csv of a results folder or a bench folder (its
    floors'), before its scenario or suite is looked for: another engine's folder is named with
    the release that replays it, whatever else it lacks here."""
    folder = Path(folder)
    for f in [folder / "runs.csv", *sorted(folder.glob("*/runs.csv"))]:
        if f.is_file():
            check_engine(read_runs(f, as_written=True), f)


def records_in(folder: Path) -> dict[str, Path]:
    """Every entry of ``folder/decisions`` by name (a record is ``<run>.json``; the hidden
    temporary files of a write that was cut short are left out)."""
    d = Path(folder) / "decisions"
    if not d.is_dir():
        return {}
    return {p.name: p for p in d.iterdir() if not (p.name.startswith(".") and ".tmp" in p.name)}


def verify_folder(folder: Path, loaded: Loaded, progress=None, workers: int = 1, allow_unrecorded: bool = False) -> Verdict:
    """Check every run of ``folder/runs.csv`` on ``loaded`` (the scenario the rows were made with:
    their fingerprint must be its own), in ``workers`` processes (the verdict is the same whatever
    their number); ``progress(done, total)`` after each run replayed (the runs not replayed counted done first).

    The folder is checked, not only the runs that kept a record: each row must be a run of the
    scenario (its goal and episode one of the scenario's episodes, from that episode's start), once;
    each finished run must have its record ``decisions/<run>.json`` (a regular file, the one the
    row's ``decisions_sha256`` names when the row names one), which must name the row's run and
    replay to its rows; each record must have its row. An error or timeout row has no record (the
    run did not finish) and must claim nothing (no success, no distance): it is counted as
    ``unfinished``. ``allow_unrecorded``: a folder recorded partly without ``--decisions``; a
    finished run without a record (and naming none) is counted as ``unrecorded``, not failed."""
    folder = Path(folder)
    rows = read_runs(folder / "runs.csv", as_written=True)
    if not len(rows):
        raise ScenarioError(str(folder / "runs.csv"), "", "holds no rows to verify")
    check_engine(rows, folder / "runs.csv")
    own = rows[rows["stage"] == ""]
    fp = loaded.fingerprint
    other = own["fingerprint"].astype(str) != fp
    if other.any():
        raise ScenarioError(str(loaded.path), "fingerprint", f"{int(other.sum())} of the {len(own)} runs were made with another "
                            f"scenario (fingerprint {own.loc[other, 'fingerprint'].iloc[0]}, this one's {fp}): give the "
                            "scenario they were made with (--scenario)")
    verdict = Verdict(runs=len(own))
    records = records_in(folder)
    episodes = {(str(e.goal), e.index): e for e in loaded.task.episodes}
    jobs = []  # (name, decisions file, planner, goal, episode, seed, the run's rows as written)
    named: set[str] = set()  # the records the rows name (by file name)
    times = own.groupby(["planner", "goal", "episode", "seed"], sort=False, dropna=False).size()
    by_run = rows.groupby(["planner", "goal", "episode", "seed"], sort=False, dropna=False)
    for (planner, goal, episode, seed), group in by_run:
        name = run_name(planner, goal, episode, seed)
        runs = group[group["stage"] == ""]
        if not len(runs):
            verdict.failed.append((name, "stage rows without their run's row in runs.csv (a row taken away?)"))
            continue
        ep, sd = _whole(episode), _whole(seed)
        if ep is None or sd is None:
            verdict.failed.append((name, "its episode and seed are not whole numbers from 0 to 999,999,999 (edited by hand?)"))
            continue
        f = folder / "decisions" / f"{file_stem(str(planner), goal, sd, ep)}.json"
        named.add(f.name)
        n = int(times.get((planner, goal, episode, seed), 0))
        if n > 1:
            verdict.failed.append((name, f"appears {n} times in runs.csv: a run has one row (a row added or copied)"))
            continue
        first = runs.iloc[0].to_dict()
        episode_ = episodes.get((str(goal), ep))
        if episode_ is None:
            verdict.failed.append((name, f"is no run of the scenario: it has no episode {ep} of goal {goal} (a row added?)"))
            continue
        try:
            at = (round(float(first["start_x"]), 4), round(float(first["start_y"]), 4))
        except (TypeError, ValueError):
            at = None
        where = (round(episode_.x, 4), round(episode_.y, 4))
        if at != where:
            verdict.failed.append((name, f"starts at {at}, its episode at {where}: not the run of episode {ep} (edited by hand?)"))
            continue
        digest = str(first.get("decisions_sha256") or "")
        if f.exists() and not f.is_file():
            verdict.failed.append((name, f"decisions/{f.name} is not a file (a record replaced by a folder?)"))
            continue
        if not f.is_file():
            if str(first.get("outcome")) in UNFINISHED and not digest:
                if _claims_nothing(first):
                    verdict.unfinished += 1
                else:
                    verdict.failed.append((name, f"an {first.get('outcome')} row that claims a result (success "
                                           f"{first.get('success')}, distance {first.get('distance_m')}): a run that did not "
                                           "finish claims none"))
                continue
            if digest:
                verdict.failed.append((name, f"its record decisions/{f.name}, which the row names (decisions_sha256), is gone"))
            elif allow_unrecorded:
                short = _below_shortest(first, episode_)
                if short:
                    verdict.failed.append((name, short))
                else:
                    verdict.unrecorded += 1
            else:
                verdict.failed.append((name, f"has no decisions record (decisions/{f.name}): a run without its record cannot be "
                                       "checked (a record taken away, or a row added; --allow-unrecorded for a folder "
                                       "recorded partly without --decisions)"))
            continue
        jobs.append((name, f, str(planner), str(goal), ep, sd, group.to_dict("records")))
    for entry in sorted(set(records) - named):
        verdict.failed.append((f"decisions/{entry}", "a record without its row in runs.csv (a row taken away, or a record "
                               "added)" if entry.endswith(".json") else "not a record semsearch writes"))
    done = verdict.runs - len(jobs)
    with _pool(loaded, min(workers, len(jobs))) as pool:
        for (name, *_), why in zip(jobs, pool.map(_job, jobs) if pool is not None else map(_job, jobs)):
            if why:
                verdict.failed.append((name, why))
            else:
                verdict.verified += 1
            done += 1
            if progress:
                progress(done, verdict.runs)
    return verdict


_TASK: list = []  # the task a process replays on: (task, its episodes by (goal, index))


def _seat(loaded: Loaded) -> None:
    task = loaded.task
    _TASK[:] = [(task, {(str(e.goal), e.index): e for e in task.episodes}, loaded.fingerprint)]


@contextmanager
def _pool(loaded: Loaded, workers: int):
    """None (replay here) for one worker, else a process pool whose workers hold ``loaded``."""
    _seat(loaded)
    if workers <= 1:
        yield None
        return
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_seat, initargs=(loaded,)) as pool:
        yield pool


def _job(job) -> str:
    name, f, planner, goal, episode, seed, rows = job
    task, episodes, fingerprint = _TASK[0]
    return replay_run(task, f, planner, goal, episode, seed, rows, episodes, fingerprint=fingerprint)


def replay_run(task, f: Path, planner: str, goal: str, episode: int, seed: int, want: list[dict], episodes: dict,
               observer=None, fingerprint: str | None = None) -> str:
    """Why the run's replay does not give its rows, or "" when it does; ``observer`` sees the
    replay's events (``semsearch export`` writes them to a bag); ``fingerprint``, when given, the
    scenario's, which the record must name."""
    named = str(want[0].get("decisions_sha256") or "")
    if named and hashlib.sha256(f.read_bytes()).hexdigest() != named:
        return f"{f.name} is not the record the row names (its SHA-256 differs from the row's decisions_sha256)"
    try:
        record = read_decisions(f)
    except ScenarioError as exc:
        return exc.message
    named = (str(record.get("planner")), str(record.get("goal")), record.get("episode"), record.get("seed"))
    if named != (planner, goal, episode, seed):
        return f"{f.name} records another run ({run_name(*named)})"
    try:
        engine = engine_of(record.get("engine"))
    except ValueError:
        return f"{f.name} names no simulator engine semsearch writes (engine {record.get('engine')!r}; edited by hand?)"
    if engine != ENGINE:
        return refusal(engine, f.name)
    if fingerprint is not None and record.get("fingerprint") != fingerprint:
        return f"{f.name} was recorded on another scenario (fingerprint {record.get('fingerprint')}, this one's {fingerprint})"
    ep = episodes.get((goal, episode))
    if ep is None:
        return f"the scenario has no episode {episode} of goal {goal}"
    variant = Variant(planner, ())  # the label alone: the replay builds no planner
    try:
        replay = Replay(record)
        res = task.run(variant, ep, seed, observer=observer, seat=replay)
        replay.finish()
    except (ReplayError, PlannerError) as exc:
        return f"the replay stopped: {exc}"
    except Exception as exc:  # noqa: BLE001  a recorded choice the kind's code could not take: named, never a traceback
        return f"the replay stopped: {type(exc).__name__}: {str(exc)[:120]}"
    if res.outcome == "error":  # pragma: no cover - a replay raises rather than records
        return f"the replay ended in an error: {res.message}"
    got = task.rows(variant, ep, seed, res)
    if len(got) != len(want):
        return f"the replay gives {len(got)} rows, the folder holds {len(want)}"
    for g, w in zip(got, want):
        for c in COMPARED:
            if not _same(g[c], w[c]):
                where = f" (stage {w['stage']}, map {w['map']})" if w.get("stage") else ""
                return f"{c}{where}: {w[c]} recorded, {g[c]} replayed"
    return ""
