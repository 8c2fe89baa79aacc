"""Verify a results folder by replaying its runs from their decisions (``semsearch verify``).

Each run's row that has a decisions record (``decisions/<run>.json``, written by ``semsearch run
--decisions``) is run again with the record answering every decision point
(:class:`~semsearch_cli.tasks.decisions.Replay`): no planner is built, so a run of a planner whose
code is not at hand (a learned policy, a language model, a colleague's planner) is checked all
the same. The replay's rows must equal the folder's in outcome, distance and steps (and decisions,
and a chain's stage rows), exactly as written; any other result, or a replay that cannot go on,
names the run."""

from __future__ import annotations

import hashlib
import math
import multiprocessing as mp
import numbers
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path


from ..errors import PlannerError, ScenarioError
from ..planners import Variant
from ..tasks.decisions import Replay, ReplayError
from .specs import Loaded, file_stem
from .store import read_decisions, read_runs

COMPARED = ("outcome", "distance_m", "steps", "decisions")  # what a replay must give exactly, per row


@dataclass
class Verdict:
    """What :func:`verify_folder` found: ``verified`` runs replayed to their rows; ``failed``:
    (the run, why) of each that did not; ``unrecorded``: runs without a decisions record."""

    runs: int = 0
    verified: int = 0
    failed: list = field(default_factory=list)
    unrecorded: int = 0


def run_name(planner, goal, episode, seed) -> str:
    return f"{planner} goal {goal} episode {episode} seed {seed}"


def _same(a, b) -> bool:
    """Equal as written: numbers by value (NaN equal to NaN), anything else as text."""
    if isinstance(a, numbers.Number) and isinstance(b, numbers.Number):
        fa, fb = float(a), float(b)
        return fa == fb or (math.isnan(fa) and math.isnan(fb))
    return str(a) == str(b)


def verify_folder(folder: Path, loaded: Loaded, progress=None, workers: int = 1) -> Verdict:
    """Replay every run of ``folder/runs.csv`` that has a decisions record, on ``loaded`` (the
    scenario the rows were made with: their fingerprint must be its own), in ``workers``
    processes (the verdict is the same whatever their number); ``progress(done, total)`` after
    each run."""
    rows = read_runs(Path(folder) / "runs.csv", as_written=True)
    if not len(rows):
        raise ScenarioError(str(Path(folder) / "runs.csv"), "", "holds no rows to verify")
    own = rows[rows["stage"] == ""]
    fp = loaded.fingerprint
    other = own["fingerprint"].astype(str) != fp
    if other.any():
        raise ScenarioError(str(loaded.path), "fingerprint", f"{int(other.sum())} of the {len(own)} runs were made with another "
                            f"scenario (fingerprint {own.loc[other, 'fingerprint'].iloc[0]}, this one's {fp}): give the "
                            "scenario they were made with (--scenario)")
    verdict = Verdict(runs=len(own))
    jobs = []  # (name, decisions file, planner, goal, episode, seed, the run's rows as written)
    by_run = rows.groupby(["planner", "goal", "episode", "seed"], sort=False, dropna=False)
    for (planner, goal, episode, seed), group in by_run:
        name = run_name(planner, goal, episode, seed)
        whole = [v for v in (episode, seed) if isinstance(v, numbers.Integral) or (isinstance(v, float) and v.is_integer())]
        if len(whole) < 2 or not all(0 <= v < 10**9 for v in whole):
            verdict.failed.append((name, "its episode and seed are not whole numbers from 0 to 999,999,999 (edited by hand?)"))
            continue
        f = Path(folder) / "decisions" / f"{file_stem(str(planner), goal, int(seed), int(episode))}.json"
        if not f.is_file():
            verdict.unrecorded += 1
            continue
        jobs.append((name, f, str(planner), str(goal), int(episode), int(seed), group.to_dict("records")))
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
    _TASK[:] = [(task, {(str(e.goal), e.index): e for e in task.episodes})]


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
    task, episodes = _TASK[0]
    return replay_run(task, f, planner, goal, episode, seed, rows, episodes)


def replay_run(task, f: Path, planner: str, goal: str, episode: int, seed: int, want: list[dict], episodes: dict,
               observer=None) -> str:
    """Why the run's replay does not give its rows, or "" when it does; ``observer`` sees the
    replay's events (``semsearch export`` writes them to a bag)."""
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
