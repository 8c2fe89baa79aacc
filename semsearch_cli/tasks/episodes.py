"""Episodes: the start/goal problems a scenario's runs are made of.

An episode is a goal (a door number, an object request, a chain, an indirect view scale in one
room) and a start pose (x, y in m, heading in degrees, or no heading: drawn at each repeat). A
scenario's runs are episodes x planner variants x repeats (the ``seed`` column); every planner
variant meets the same episodes and, at repeat k, the same random stream, so planners can be
compared episode by episode.

A run's random stream (:func:`episode_seed`) derives from the base seed, the episode's content
(goal, start, room) and the repeat, never from the scenario's name, its path or the episode's
position in the set: a renamed copy of a scenario gives the same rows.

The set comes from the scenario's ``episodes`` section (:class:`~semsearch_cli.config.base.EpisodesSpec`):
drawn (``starts`` per goal, from the reachable free space, seeded), given by hand (``list``), or
read from a CSV (``file``, as written by ``semsearch episodes``). Without the section there is one
episode per goal, from the scenario's ``start`` (the thesis' fixed starts).

Drawing. The candidate cells are those the robot can stand on and reach from the scenario's
start, at least ``clearance`` from walls (0.5 m by default: a robot started within a few
centimetres of its radius from a wall, facing it, sees too little to plan and can end stuck at its
start; one such start in 40 on the hotel did), optionally only corridors or only rooms: a cell is in a room when a disk of diameter
``corridor_width`` fits in the free space around it (a morphological opening of the free map),
in a corridor otherwise. Of those, a cell qualifies when its geodesic distance to the goal (to the
nearest pose that achieves it, as the shortest path column measures it) lies in
[``min_distance``, ``max_distance``]; with ``shared`` it must do so for every goal. The starts
are drawn uniformly among qualifying cells (cell centres, without replacement while there are
enough), each with a heading uniform in [-180, 180) degrees, by a generator seeded by
``episodes.seed`` and the goal's label (or by the seed alone when shared), so adding a goal does
not move the other goals' starts.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..config.base import MAX_EPISODES, EpisodesSpec, label_column, number_text, sign_label
from ..errors import ScenarioError, did_you_mean
from ..files import read_user_text

EPISODE_COLUMNS = ["episode", "goal", "start_x", "start_y", "start_heading", "room", "shortest_m", "hash"]
MAX_HEADING = 3600.0  # degrees either way, as a scenario's start and episodes.list take a heading (config.base.Angle)


@dataclass(frozen=True)
class Episode:
    """One start/goal problem.

    index : int, its position in the scenario's set (the ``episode`` column); goal : the goal as
    the scenario writes it; x, y : float, m; heading : float, degrees, or None (drawn at each
    repeat); room : int or None, the room searched (indirect search); shortest_m : float, the
    ground-truth shortest path from the start to the goal (m).
    """

    index: int
    goal: object
    x: float
    y: float
    heading: float | None = None
    room: int | None = None
    shortest_m: float = math.nan

    @property
    def content(self) -> str:
        """What the episode is, as text: goal, start and room (not its index, not its path length)."""
        h = None if self.heading is None else round(float(self.heading), 3)
        return json.dumps([str(self.goal), round(float(self.x), 4), round(float(self.y), 4), h, self.room])

    @property
    def hash(self) -> str:
        return hashlib.sha256(self.content.encode()).hexdigest()[:16]

    def row(self) -> dict:
        """The episode as a row of ``episodes.csv``."""
        return {"episode": self.index, "goal": self.goal, "start_x": round(self.x, 4), "start_y": round(self.y, 4),
                "start_heading": "" if self.heading is None else round(self.heading, 3),
                "room": "" if self.room is None else self.room, "shortest_m": round(self.shortest_m, 3), "hash": self.hash}


def episode_seed(ep: Episode, repeat: int, base_seed: int, *salt: int) -> np.random.SeedSequence:
    """The seed of repeat ``repeat`` of episode ``ep``: base seed, episode content, repeat (and a
    ``salt`` for a sub-stream, e.g. a chain's stage). Independent of names, paths and order."""
    words = np.frombuffer(hashlib.sha256(ep.content.encode()).digest()[:16], np.uint32)
    return np.random.SeedSequence([int(base_seed), int(repeat), *(int(w) for w in words), *(int(s) for s in salt)])


def set_hash(episodes: list[Episode]) -> str:
    """One hash for a whole set (its episodes' contents, in order)."""
    return hashlib.sha256("\n".join(e.content for e in episodes).encode()).hexdigest()[:16]


def label_words(label) -> list[int]:
    """A goal label as integers for seeding (its text's hash)."""
    return [int(w) for w in np.frombuffer(hashlib.sha256(str(label).encode()).digest()[:8], np.uint32)]


def region_mask(free: np.ndarray, res: float, where: str, corridor_width: float) -> np.ndarray:
    """(H, W) bool: the cells of ``where`` ("anywhere", "rooms": a disk of diameter
    ``corridor_width`` fits in the free space around the cell, "corridors": the other free cells)."""
    if where == "anywhere":
        return np.ones(free.shape, bool)
    k = 2 * int(round(corridor_width / res / 2)) + 1  # odd: a centred disk (an even one shifts the opening)
    disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))
    wide = cv2.morphologyEx(free.astype(np.uint8), cv2.MORPH_OPEN, disk).astype(bool) & free
    return wide if where == "rooms" else free & ~wide


def draw_starts(stand: np.ndarray, fields: list[np.ndarray], to_world, n: int, rng: np.random.Generator,
                lo: float, hi: float | None) -> list[tuple[float, float, float]]:
    """``n`` starts (x, y m, heading deg) among the cells of ``stand`` whose distance in every
    field (m) lies in [lo, hi]; empty when no cell qualifies."""
    ok = stand.copy()
    for f in fields:
        ok &= np.isfinite(f) & (f >= lo) & (f <= (np.inf if hi is None else hi))
    rr, cc = np.nonzero(ok)
    if not len(rr):
        return []
    pick = rng.choice(len(rr), size=n, replace=len(rr) < n)
    heading = rng.uniform(-180.0, 180.0, n)
    xs, ys = to_world(rr[pick], cc[pick])
    return [(round(float(x), 4), round(float(y), 4), round(float(h), 2)) for x, y, h in zip(xs, ys, heading)]


def read_episodes_csv(path: Path, owner: str) -> list[dict]:
    """The rows of an episodes CSV (goal, start_x, start_y, start_heading[, room][, hash]) as
    dicts; a :class:`ScenarioError` naming the file and the line for anything else. At most
    ``MAX_EPISODES`` (100,000) rows, refused before any is measured; the goals are read as labels
    (:func:`~semsearch_cli.config.base.label_column`: a spreadsheet's column ``304.0`` is 304), each
    row keeping its goal as written in ``text`` (an indirect search's room name); a row's
    ``hash``, when given, must be its episode's (:func:`check_hash`)."""
    text = read_user_text(path, "episodes file", owner, "episodes.file")
    reader = csv.DictReader(io.StringIO(text))
    rows = []
    try:
        for r in reader:
            rows.append((reader.line_num, r))
            if len(rows) > MAX_EPISODES:
                raise ScenarioError(str(path), f"line {reader.line_num}", f"more than {MAX_EPISODES:,} episodes, the bound "
                                    "of an episode set (docs/usage.md, Limits); split the set into several scenarios")
    except csv.Error as exc:
        raise ScenarioError(str(path), f"line {reader.line_num}", f"not a CSV file semsearch can read ({exc})") from None
    need = ["goal", "start_x", "start_y"]
    header = list(reader.fieldnames or ())
    missing = [c for c in need if c not in header]
    if not rows or missing:
        # the columns named: a header "Goal" or " start_x" (a space after the comma), a file of
        # semicolons, was "expected a CSV with columns ..." naming none of them
        near = "".join(f"; no column {c}{did_you_mean(c, header)}" for c in missing)
        one = header[0] if len(header) == 1 else ""
        sep = next((ch for ch in ";\t|" if ch in one), None)
        raise ScenarioError(str(path), "", "expected a CSV with columns goal, start_x, start_y[, start_heading] "
                            "(as semsearch episodes writes), with at least one row"
                            + (f"{near}; the header holds {', '.join(repr(h) for h in header[:8])}" if header and missing else "")
                            + (f" (a file separated by {sep!r}? columns are separated by commas)" if sep else ""))
    # a column semsearch episodes does not write is refused, as in runs.csv: a misspelt
    # start_headng was dropped without a word, and every start's heading drawn at random
    for c in header:
        if c not in EPISODE_COLUMNS:
            raise ScenarioError(str(path), c or "line 1", f"a column semsearch episodes does not write{did_you_mean(c, EPISODE_COLUMNS)}"
                                f"; the columns are {', '.join(EPISODE_COLUMNS)} (goal, start_x and start_y needed)")
    if len(set(header)) != len(header):
        twice = next(c for c in header if header.count(c) > 1)
        raise ScenarioError(str(path), twice, f"the column {twice} is given twice in the header (line 1)")
    out = []
    ids: dict[int, int] = {}  # the episode column's numbers -> the line that gives each
    for k, r in rows:
        if None in r:
            raise ScenarioError(str(path), f"line {k}", f"{len(r[None]) + len(reader.fieldnames)} fields where the header "
                                f"has {len(reader.fieldnames)} ({', '.join(reader.fieldnames)})")
        values = {}
        for col in ("start_x", "start_y", "start_heading"):  # each named where it is wrong: line 2 start_heading
            text = (r.get(col) or "").strip()
            if col == "start_heading" and text in ("", "random"):
                values[col] = None
                continue
            try:
                v = number_text(text)
            except (TypeError, ValueError):
                raise ScenarioError(str(path), f"line {k} {col}", f"{col} must be a number, not {text[:40]!r}"
                                    + (" (start_heading may be empty or random: drawn at each repeat)"
                                       if col == "start_heading" else "")) from None
            if not math.isfinite(v):
                raise ScenarioError(str(path), f"line {k} {col}", f"{col} must be finite, not {text[:40]!r}")
            if col == "start_heading" and abs(v) > MAX_HEADING:  # as episodes.list and start.heading bound it
                raise ScenarioError(str(path), f"line {k} {col}", f"start_heading must lie in -{MAX_HEADING:g} to "
                                    f"{MAX_HEADING:g} degrees, not {text[:40]}")
            values[col] = v
        x, y, heading = values["start_x"], values["start_y"], values["start_heading"]
        room = (r.get("room") or "").strip()
        given_id = (r.get("episode") or "").strip()
        if given_id:  # semsearch episodes numbers its rows 0, 1, ...: a number given twice is two rows claiming one episode
            if not re.fullmatch(r"[0-9]{1,9}", given_id, re.ASCII):
                raise ScenarioError(str(path), f"line {k} episode", f"the episode column holds whole numbers (as "
                                    f"semsearch episodes writes: 0, 1, ...), not {given_id[:40]!r}; or leave it empty")
            if int(given_id) in ids:
                raise ScenarioError(str(path), f"line {k} episode", f"episode {int(given_id)} is given twice (lines "
                                    f"{ids[int(given_id)]} and {k}); each row is one episode: renumber them, or clear "
                                    "the column")
            ids[int(given_id)] = k
        out.append({"goal": (r["goal"] or "").strip(), "x": x, "y": y, "heading": heading, "room": room or None,
                    "hash": (r.get("hash") or "").strip() or None, "file": str(path), "field": f"line {k}"})
    for e in out:
        try:
            sign_label(e["goal"])
        except ValueError as exc:
            raise ScenarioError(str(path), f"{e['field']} goal", str(exc)) from None
    # the goals as labels, a spreadsheet's column of floats (304.0) as numbers; room names as written too
    for e, goal in zip(out, label_column([e["goal"] for e in out])):
        e["text"], e["goal"] = e["goal"], goal
    return out


def check_hash(ep: Episode, given: dict) -> None:
    """A :class:`ScenarioError` when an episode read from a file carries a ``hash`` that is not
    its own: the row was edited after ``semsearch episodes`` wrote it (its runs would be matched to
    the old episode's). Remove the hash, or the whole column, to accept an edit."""
    if given.get("hash") and given["hash"] != ep.hash:
        raise ScenarioError(given["file"], f"{given['field']} hash", f"the row's hash {given['hash']} is not its "
                            f"episode's ({ep.hash}): the goal, start or room was edited after semsearch episodes wrote "
                            "it; clear the hash to keep the edit")


def given_episodes(spec: EpisodesSpec, base: Path, file: str) -> list[dict] | None:
    """The episodes a scenario gives by hand or in a file, as dicts (goal, x, y, heading, room,
    file, field: where each came from, for errors); None when they are to be drawn."""
    if spec.given is not None:
        return [{"goal": e.goal, "x": e.x, "y": e.y, "heading": None if e.heading == "random" else float(e.heading),
                 "room": None, "file": file, "field": f"episodes.list[{k}]"} for k, e in enumerate(spec.given)]
    if spec.file is not None:
        return read_episodes_csv(base / spec.file, file)
    return None
