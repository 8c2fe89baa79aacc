"""Runs picked from rows, and their files. A run's path file, found from its row: ``paths/<stem>.npz`` beside runs.csv, with the stem of
:func:`~semsearch_cli.runner.file_stem`. Folders written since episodes name the episode in the
stem (``..__goal{g}__ep{e}__seed{s}``); older ones do not (and their rows have no ``episode``
column: episode 0). The new stem is tried first, then the old one."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ScenarioError
from ..files import safe_chars
from ..planners import Variant
from ..planners.base import planner_named
from ..runner import file_stem
from ..runner.store import read_frames, read_npz
from ..tasks import FrameRecorder
from .stats import episodes


def stems(planner: str, goal, seed: int, episode: int = 0) -> list[str]:
    """The stems a run's files may have, newest naming first."""
    try:
        new = file_stem(planner, goal, seed, episode=episode)
    except TypeError:  # a runner from before episodes: its stems have no episode
        new = None
    old = file_stem(planner, goal, seed)
    return [s for s in (new, old) if s] if new != old else [old]


def same_goal(a, b) -> bool:
    """Goals as written on the command line and as read from runs.csv (1.5 and 1.50 are one view
    scale; 304.0 is the goal 304), as ``--replay`` is checked and as its section finds the run."""
    if str(a) == str(b):
        return True
    try:
        return float(a) == float(b)
    except (TypeError, ValueError, OverflowError):
        return False


def path_file(folder: Path, planner: str, goal, seed: int, episode: int = 0) -> Path | None:
    """The path file of one run, or None when there is none."""
    for stem in stems(planner, goal, seed, episode):
        f = Path(folder) / "paths" / f"{stem}.npz"
        if f.is_file():
            return f
    return None


def load_paths(folder: Path, rows: pd.DataFrame) -> list[tuple[int, np.ndarray]]:
    """(row label in ``rows``, path (n, 2) float, m) of every row whose path file exists, in row order."""
    ep = episodes(rows)
    out = []
    for i, r in rows.iterrows():
        f = path_file(folder, str(r["planner"]), r["goal"], int(r["seed"]), int(ep[i]))
        if f is not None:
            path = read_npz(f, "path file").get("path")
            if path is None or path.dtype.kind not in "iuf" or (path.size and (path.ndim != 2 or path.shape[1] != 2)):
                raise ScenarioError(str(f), "path", "not a path file semsearch wrote (no (x, y) array 'path'); delete it "
                                    "or run the batch again")
            out.append((i, path))
    return out


def safe_name(goal) -> str:
    """A goal as one file-name component (a KTH room's second door is ``2512/2``)."""
    return safe_chars(goal)


def median_label(rows: pd.DataFrame):
    """The row label of the run drawn as a group's median: the median run by distance when their
    count is odd; when it is even there is no median run (the median is the mean of the two middle
    distances, both equally near it) and it is the shorter of the two middle runs. Ties by seed,
    then episode."""
    s = rows.assign(_ep=episodes(rows)).sort_values(["distance_m", "seed", "_ep"], kind="stable")
    return s.index[(len(s) - 1) // 2]


def metres(x: float) -> str:
    """A distance as the report's tables print it (two decimals), trailing zeros dropped:
    ``226.5``, ``339.85``, ``137``."""
    return f"{float(x):.2f}".rstrip("0").rstrip(".")


def median_panel(rows: pd.DataFrame, found: list, count: str) -> tuple[list, int, str]:
    """One panel of :func:`~semsearch_cli.report.plots.plot_path_panels` for a group of runs:
    (their paths, the index among them of the run drawn bold (:func:`median_label`; -1 when its
    path file is missing), the title's note). The note gives the median distance as the tables
    print it, then ``count`` (``"n=10"``); when the run drawn is not at the median (an even
    number of runs: the median is the mean of the two middle distances) a second line says which
    run it is and its distance, ``"bold: lower middle run, 137 m"``.

    rows : the group's rows; found : [(row label, path)] (:func:`load_paths` of ``rows``)."""
    label = median_label(rows)
    idx = [i for i, _ in found]
    k = idx.index(label) if label in idx else -1
    d = pd.to_numeric(rows["distance_m"], errors="coerce")
    med, run = metres(d.median()), metres(d[label])
    note = f"median {med} m, {count}"
    if k >= 0 and run != med:
        note += f"\nbold: lower middle run, {run} m"
    return [p for _, p in found], k, note


def start_points(rows: pd.DataFrame, world) -> list[tuple[float, float]]:
    """The distinct starts of ``rows`` (columns start_x, start_y), else the scenario's start."""
    if {"start_x", "start_y"} <= set(rows.columns):
        xy = rows[["start_x", "start_y"]].apply(pd.to_numeric, errors="coerce").dropna().round(3).drop_duplicates()
        if len(xy):
            return [tuple(map(float, r)) for r in xy.to_numpy()]
    return [tuple(map(float, world.start_xy))]


REPLAY_FRAMES = 60  # at most this many frames in a replay


def replay_frames(folder: Path, planner: str, goal, seed: int, episode: int, rerun, failed: bool = False,
                  expect: dict | None = None) -> tuple[list[dict], str]:
    """A run's replay frames (at most :data:`REPLAY_FRAMES`, evenly spaced): read from
    ``frames/<run>.npz`` when ``semsearch run --frames`` recorded them, else by ``rerun(observer)``
    (re-simulating the run, which is deterministic, with a :class:`FrameRecorder` watching).
    Returns (frames, "recorded" or "re-simulated"); a run whose planner raised (``failed``: its row's
    outcome is ``error``) is re-simulated up to the error, which ``how`` names. A run of a planner
    that answers through a service (a language model: ``Planner.service``) is never re-simulated,
    which would call the model: without recorded frames, no frames. ``expect``: what recorded
    frames must agree with, :func:`~semsearch_cli.runner.store.read_frames`' ``kind``, ``signs``
    and ``map_shape`` (the run's search, its scenario's signs and grid)."""
    for stem in stems(planner, goal, seed, episode):
        f = Path(folder) / "frames" / f"{stem}.npz"
        if f.is_file():
            frames, how = read_frames(f, **(expect or {})), "recorded"
            break
    else:
        cls = planner_named(planner)
        if cls is not None and cls.service:
            return [], "not re-simulated (it would call the planner's service; semsearch run --frames records the frames)"
        recorder = FrameRecorder()
        how = "re-simulated"
        try:
            rerun(recorder)
        except Exception as exc:  # noqa: BLE001  a user's planner raised, as it did in the batch (an error row)
            if not failed:
                raise
            how = f"re-simulated up to the planner's error, {type(exc).__name__}: {str(exc)[:80]}"
        frames = recorder.frames
    step = max(1, -(-len(frames) // REPLAY_FRAMES))
    return frames[::step], how


def row_variant(loaded, row) -> Variant | None:
    """The planner variant that made a row: one of the scenario's, else a registered planner with
    the row's parameters (``sweep-alpha`` and ``--param`` sweeps run variants the scenario does
    not list); None when neither gives the row's label."""
    label = str(row["planner"])
    found = next((v for v in loaded.task.variants() if v.label == label), None)
    if found is not None:
        return found
    cls = planner_named(label)
    if cls is None:
        return None
    params = json.loads(str(row.get("params") or "{}") or "{}")
    v = Variant(cls.name, tuple(sorted(params.items())))
    return v if v.label == label else None
