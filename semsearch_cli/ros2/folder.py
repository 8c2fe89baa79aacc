"""A live run's folder (``semsearch ros live --out DIR``): written when the run ends, and checked
by ``semsearch verify DIR`` as a batch run is, from its decisions record alone.

The folder holds ``bag/`` (every message the run took, in the order it took them: what ``semsearch
ros replay`` replays), ``decisions.json`` (the run's decisions record,
:mod:`semsearch_cli.tasks.decisions`: the planner's choices, with the run's identity),
``transcripts.jsonl`` (a language model's prompts and replies, when the planner keeps a
transcript) and ``run.json``: the format, the run's planner, goal and settings (the scenario and
its fingerprint, the margin, the budget), its outcome, distance, poses, the decisions made
[{step, target_cell, target}] and the planner's cost columns (``llm_calls``, ``tokens_in``, ...).

Verifying replays the bag with the record's choices answering each re-plan (no planner built, no
server called) and checks that the re-plans come where they came, choose what the run chose
(step, target cell and target, as written) and that the goal's sign is read, or not, as the run
says; a record that runs out, or is left over, fails.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from ..engine import ENGINE
from ..errors import ScenarioError
from ..files import atomic_text
from ..planners import Variant
from ..runner.store import read_decisions, write_decisions, write_jsonl
from ..runner.verify import Verdict
from ..tasks.decisions import Recording, Replay, ReplayError
from .bag import Messages
from .replay import BagStream, replay_bag

FORMAT = "semsearch-live"
VERSION = 1
MAX_RUN_BYTES = 50_000_000  # a run.json larger than this is not one semsearch wrote


def write_live_folder(folder: Path, res, *, planner: str, goal: str, scenario: Path | None, fingerprint: str | None,
                      margin: float, max_distance: float | None, publish_only: bool) -> Path:
    """Write ``run.json``, ``decisions.json`` and ``transcripts.jsonl`` of a finished live run
    ``res`` (a :class:`~semsearch_cli.ros2.LiveRun`) into ``folder``, beside its ``bag/``;
    each file atomically. Returns ``run.json``'s path."""
    folder = Path(folder)
    # a run that ended before its first map made no decision: its record holds none
    record = dict(res.record) if res.record is not None else {**Recording().record("doors"), "planner": planner,
                                                               "goal": str(goal), "episode": 0, "seed": 0}
    if fingerprint is not None:
        record["fingerprint"] = fingerprint
    record["engine"] = ENGINE
    write_decisions(folder / "decisions.json", record)
    for k, transcript in enumerate(res.transcripts):
        write_jsonl(folder / f"transcripts{f'__stage{k}' if k else ''}.jsonl", transcript)
    run = {"format": FORMAT, "version": VERSION, "engine": ENGINE, "planner": planner, "goal": str(goal),
           "scenario": str(scenario) if scenario is not None else None, "fingerprint": fingerprint, "margin": margin,
           "max_distance": max_distance, "publish_only": publish_only, "outcome": res.outcome, "message": res.message,
           "distance_m": res.distance, "poses": res.poses, "goals": res.goals, "dropped": res.dropped,
           "costs": res.costs, "decisions": res.decisions}
    path = folder / "run.json"
    atomic_text(path, json.dumps(run, allow_nan=False, default=float) + "\n")
    return path


def is_live_folder(folder: Path) -> bool:
    """Whether ``folder`` is a live run's: a ``run.json`` or a ``bag/`` (a run that stopped before
    it ended), and no ``runs.csv`` or ``bench.json`` (a results or bench folder's). A run.json
    that is not one is then named by :func:`check_run`."""
    folder = Path(folder)
    ours = (folder / "run.json").is_file() or (folder / "bag").is_dir()
    return ours and not (folder / "runs.csv").exists() and not (folder / "bench.json").exists()


def read_run(path: Path) -> dict:
    """A live run's ``run.json`` (not yet checked: :func:`check_run`), or a :class:`ScenarioError`
    naming it when it is not JSON."""
    if not path.is_file():
        raise ScenarioError(str(path), "", "is gone: the live run stopped before it ended (its messages are in bag/, which "
                            "`semsearch ros replay` replays), so there is no run to verify")
    try:
        if path.stat().st_size > MAX_RUN_BYTES:
            raise ValueError(f"larger than {MAX_RUN_BYTES:,} bytes")
        run = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise ScenarioError(str(path), "", f"not a live run's run.json ({type(exc).__name__}: {str(exc)[:80]})") from None
    if not isinstance(run, dict):
        raise ScenarioError(str(path), "", "not a live run's run.json (not a JSON object)")
    return run


RUN_KEYS = {"planner": (str,), "goal": (str,), "outcome": (str,), "margin": (int, float), "decisions": (list,),
            "scenario": (str, type(None)), "fingerprint": (str, type(None)), "max_distance": (int, float, type(None))}


def check_run(run: dict, path: Path) -> dict:
    """``run`` (a live run's run.json at ``path``) checked: its format and version, and each of
    :data:`RUN_KEYS` of its type; else a :class:`ScenarioError` naming the file and the field."""
    if run.get("format") != FORMAT:
        raise ScenarioError(str(path), "format", f"is {str(run.get('format'))[:40]!r}: not a live run's run.json "
                            f"(\"format\": \"{FORMAT}\", written by semsearch ros live --out)")
    if run.get("version") != VERSION:
        raise ScenarioError(str(path), "version", f"a live run of version {str(run.get('version'))[:20]!r}; this semsearch "
                            f"reads version {VERSION}")
    for key, kinds in RUN_KEYS.items():
        v = run.get(key)
        if not isinstance(v, kinds) or isinstance(v, bool):
            raise ScenarioError(str(path), key, f"is {str(v)[:40]!r}: not a run.json semsearch wrote")
    if run["fingerprint"] is not None and run["scenario"] is None:
        raise ScenarioError(str(path), "scenario", "names no scenario, and the run was made with one (its fingerprint): "
                            "give it, semsearch verify FOLDER --scenario FILE")
    return run


def verify_live(folder: Path, loaded=None) -> Verdict:
    """Replay a live run's bag from its decisions record (see the module's text): a
    :class:`~semsearch_cli.runner.verify.Verdict` of its one run. ``loaded``: the scenario its
    settings came from (the one ``run.json`` names, loaded by the caller), or None."""
    folder = Path(folder)
    run = check_run(read_run(folder / "run.json"), folder / "run.json")
    if loaded is not None and run["fingerprint"] not in (None, loaded.fingerprint):
        raise ScenarioError(str(folder / "run.json"), "fingerprint", f"the run was made with another scenario (fingerprint "
                            f"{run['fingerprint']}; {loaded.path.name}'s is {loaded.fingerprint})")
    name = f"live run {run['planner']} goal {run['goal']}"
    verdict = Verdict(runs=1)
    bag = folder / "bag"
    if not bag.is_dir():
        raise ScenarioError(str(bag), "", "is gone: a live run's folder keeps the messages it took in bag/")
    record = read_decisions(folder / "decisions.json")
    ids = {"planner": run["planner"], "goal": run["goal"], "fingerprint": run["fingerprint"]}
    other = [k for k, v in ids.items() if v is not None and str(record.get(k)) != v]
    if other:
        verdict.failed.append((name, f"decisions.json records another run (its {', '.join(other)}: "
                               f"{', '.join(str(record.get(k))[:40] for k in other)})"))
        return verdict
    stream = BagStream(bag, Messages())
    try:
        mapped = "/map" in stream.topics
    finally:
        stream.close()
    if not mapped:  # the run ended before its first map: it could choose nothing, and read no sign
        if run["decisions"] or record["decisions"] or run["outcome"] == "found":
            verdict.failed.append((name, f"the bag holds no map, and the run claims {len(run['decisions'])} decisions "
                                   f"({len(record['decisions'])} recorded) and the outcome {run['outcome']}"))
        else:
            verdict.verified = 1
        return verdict
    with tempfile.TemporaryDirectory(prefix="semsearch-verify-live-") as tmp:
        try:
            rep = replay_bag(loaded, bag, Variant(run["planner"], ()), Path(tmp) / "replayed", "mcap", run["goal"],
                             float(run["margin"]), seat=Replay(record), max_distance=run.get("max_distance"))
        except ReplayError as exc:
            verdict.failed.append((name, f"the replay stopped: {exc}"))
            return verdict
    want = run["decisions"]
    got = json.loads(json.dumps(rep.decisions))  # as run.json writes them
    if got != want:
        k = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
        if k >= min(len(got), len(want)):
            why = f"decisions: {len(want)} recorded, {len(got)} replayed"
        else:
            why = f"decision {k + 1}: {json.dumps(want[k])[:80]} recorded, {json.dumps(got[k])[:80]} replayed"
        verdict.failed.append((name, why))
    elif rep.found != (run["outcome"] == "found"):
        verdict.failed.append((name, f"outcome: {run['outcome']} recorded; the replay {'reads' if rep.found else 'never reads'} "
                               "the goal's sign"))
    else:
        verdict.verified = 1
    return verdict
