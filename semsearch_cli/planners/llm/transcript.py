"""Transcripts: what a language model was asked and answered in one run, enough to replay the run
offline (``{name: llm, replay: DIR}``).

``semsearch run --transcripts`` writes ``transcripts/<run>.jsonl`` (a chain's later stages
``<run>__stage<k>.jsonl``), one JSON object a line, schema ``semsearch-transcript`` version 1:

- the first line, ``{"type": "header", "format": "semsearch-transcript", "version": 1, "engine": 1,
  "kind": "doors", "run": {"scenario", "kind", "planner", "goal", "episode", "seed", "stage"}, "params":
  {...}, "prompt_sha256": "..."}``: the kind of search (doors, objects, indirect), the run, the
  planner's parameters (the key's variable's name, never the key) and the prompt template's hash;
  ``engine``: the simulator engine the run ran on (:mod:`semsearch_cli.engine`; a header without it:
  engine 1). A transcript of another engine does not replay here (its observations were another
  simulator's): reading it names the release that replays it;
- one ``{"type": "call", "decision": k, "attempt": a, "observation": "...", "messages": [...],
  "reply": "..." or null, "error": "", "choice": ..., "valid": true, "reason": "", "tokens_in":
  n, "tokens_out": n, "latency_s": s, "model": "...", "temperature": t, "seed": s or null,
  "reply_format": "text"}`` per call to the model (the last three since 0.4.0): decision ``k``
  (0, 1, ... in the order the run asked), its attempt ``a`` (0, then each re-ask), the
  observation, every message sent, the raw reply (null when there was none, ``error`` saying
  why), the parsed choice (a target's number; the estimator's probabilities by target), whether
  the planner could take it and, if not, why;
- one ``{"type": "fallback", "decision": k, "choice": n, "reason": "..."}`` per decision the
  planner took its kind's stated fallback ``n`` for after the re-asks ran out.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ...engine import ENGINE, engine_of, refusal
from ...errors import PlannerError

FORMAT = "semsearch-transcript"
VERSION = 1
RUN_KEYS = ("scenario", "goal", "episode", "seed", "stage")  # what finds a run's transcript in a replay


def header(kind: str, run: dict, params: dict, prompt_sha256: str) -> dict:
    return {"type": "header", "format": FORMAT, "version": VERSION, "engine": ENGINE, "kind": kind, "run": dict(run), "params": params,
            "prompt_sha256": prompt_sha256}


def run_key(run: dict) -> tuple:
    return tuple(str(run.get(k, "")) for k in RUN_KEYS)


def read(path: Path) -> list[dict]:
    """A transcript's lines; a :class:`PlannerError` naming the file and line when one is not a
    JSON object, or the first is not a header this version reads."""
    out = []
    with open(path, encoding="utf-8") as fh:
        for n, line in enumerate(fh, 1):
            try:
                item = json.loads(line)
            except ValueError:
                raise PlannerError(f"transcript {path}: line {n} is not JSON") from None
            if not isinstance(item, dict):
                raise PlannerError(f"transcript {path}: line {n} is not a JSON object")
            out.append(item)
    if not out or out[0].get("format") != FORMAT or out[0].get("type") != "header":
        raise PlannerError(f"transcript {path}: not a {FORMAT} file (its first line is no header)")
    if out[0].get("version") != VERSION:
        raise PlannerError(f"transcript {path}: version {out[0].get('version')!r}; this semsearch reads version {VERSION}")
    try:
        engine = engine_of(out[0].get("engine"))
    except ValueError:
        raise PlannerError(f"transcript {path}: engine {out[0].get('engine')!r} is no simulator engine (edited by hand?)") from None
    if engine != ENGINE:
        raise PlannerError(refusal(engine, f"transcript {path}"))
    return out


_INDEX: dict = {}  # the last folder's index and what it was read from (a replay reads one folder, run after run)


def files(folder: Path) -> list[Path]:
    """The transcript files under ``folder``: a results folder's ``transcripts/``, a bench
    folder's ``<floor>/transcripts/``, or the files in ``folder`` itself."""
    if (folder / "transcripts").is_dir():
        return sorted((folder / "transcripts").glob("*.jsonl"))
    nested = sorted(folder.glob("*/transcripts/*.jsonl"))
    return nested or sorted(folder.glob("*.jsonl"))


def index(folder: Path) -> dict[tuple, list[tuple[str, Path]]]:
    """The transcripts under ``folder`` (:func:`files`), by run: run key -> [(planner label,
    file)]."""
    paths = files(Path(folder))
    key = (str(Path(folder).resolve()), len(paths), max((p.stat().st_mtime_ns for p in paths), default=0))
    if _INDEX.get("key") != key:  # read again when a transcript was added or rewritten
        _INDEX["key"], _INDEX["params"] = key, {}
        _INDEX["index"] = _index(paths, _INDEX["params"])
    return _INDEX["index"]


def replan_on_signs(folder: Path, planner: str | None = None) -> set:
    """The values of ``replan_on_signs`` the transcripts under ``folder`` were made with (of
    ``planner``'s only, when given): what a replay's environment must re-plan by before its
    first run starts (a :class:`~semsearch_cli.envs.PlannerPolicy`'s ``env_kwargs``)."""
    runs = index(folder)
    paths = {p for found in runs.values() for lab, p in found if planner is None or lab == planner}
    return {bool(v.get("replan_on_signs", False)) for p, v in _INDEX["params"].items() if p in paths}


def _index(paths: list[Path], params: dict) -> dict[tuple, list[tuple[str, Path]]]:
    out: dict[tuple, list[tuple[str, Path]]] = {}
    for path in paths:
        with open(path, encoding="utf-8") as fh:
            first = fh.readline()
        try:
            head = json.loads(first)
        except ValueError:
            continue
        if isinstance(head, dict) and head.get("format") == FORMAT and isinstance(head.get("run"), dict):
            out.setdefault(run_key(head["run"]), []).append((str(head["run"].get("planner", "")), path))
            params[path] = head["params"] if isinstance(head.get("params"), dict) else {}
    return out


def folder_text(folder: Path) -> str:
    """The transcripts under ``folder`` as text to hash (names and bytes, in name order): what a
    replay's rows depend on."""
    return "".join(f"{p.relative_to(folder)}\0{hashlib.sha256(p.read_bytes()).hexdigest()}\0" for p in files(folder))
