"""The row store: runs.csv, appended one row at a time as runs finish, read back for resume and
reports; and each run's path (and trace) beside it."""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import re
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ScenarioError, did_you_mean
from ..metrics import BENCH_COLUMNS, CAUSES, COLUMNS, COST_COLUMNS, PRIVILEGED, columns_for
from ..planners.base import MAX_INFO_DEPTH
from ..plugins import load_kinds
from ..tasks import TASKS
from ..tasks.decisions import ReplayError, check_record
from ..files import temp_path


def read_runs(path: Path, as_written: bool = False) -> pd.DataFrame:
    """runs.csv as a DataFrame (empty with the columns when absent). A torn last line (a write
    cut by power loss or a full disk, even inside a quoted field) is left out; a file that is not
    a runs.csv written by semsearch is a :class:`ScenarioError`. ``stage`` and ``map`` are read as
    text (empty for a run's own row).

    A run's key columns (``planner``, ``params``, ``goal``) are never read as a missing value, and
    as numbers only when every entry reads back as it was written (goals ``304``: int64; view
    scales ``1.5``: float64): a goal labelled ``4.50``, ``1e3`` or ``NA`` is that label, in the
    rows, the summary and the report. ``as_written``: those columns as text, always (a batch
    resumes, and moves rows aside, by them, so no label can make a run count twice or be
    rewritten)."""
    if path.is_dir():
        raise ScenarioError(str(path), "", "is a folder, not a runs.csv; move it away or write into another folder with --out")
    if not path.is_file() or path.stat().st_size == 0:
        return pd.DataFrame(columns=COLUMNS)
    data = path.read_bytes()
    data = data[: data.rfind(b"\n") + 1]  # whole lines only
    bad = "not a runs.csv written by semsearch; move it away or write into another folder with --out"
    try:
        df = pd.read_csv(io.BytesIO(data), dtype={"stage": str, "map": str, "message": str, "kind": str, "scenario": str,
                                                  "fingerprint": str, "code": str, "room": str, "cause": str,
                                                  **dict.fromkeys(BENCH_COLUMNS, str), PRIVILEGED: str,
                                                  **dict.fromkeys(KEY_TEXT, str)},
                         encoding="utf-8", keep_default_na=False,
                         na_values={c: MISSING for c in [*COLUMNS, *LATER] if c not in KEY_TEXT})  # a scenario may be named 50045233
    except (ValueError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ScenarioError(str(path), "", f"{bad} ({type(exc).__name__})") from None
    if "kind" not in df.columns and "wall_s" in df.columns:
        raise ScenarioError(str(path), "kind", "this runs.csv was written by an older semsearch (no kind column); "
                            "write new runs into another folder with --out")
    missing = [c for c in COLUMNS if c not in df.columns and c not in LATER]
    if missing:
        raise ScenarioError(str(path), "", f"{bad} (no column {', '.join(missing[:3])})")
    for c, default in LATER.items():  # rows of an earlier semsearch: one episode, no cause, no code
        if c not in df.columns:
            df[c] = df["outcome"].map(CAUSES) if c == "cause" else default
    df[TEXT] = df[TEXT].fillna("")
    if PRIVILEGED in df.columns:
        df[PRIVILEGED] = df[PRIVILEGED].fillna("")
    if not as_written:
        for c in KEY_TEXT:
            if c in df.columns:
                df[c] = _lossless(df[c])
    load_kinds()
    known = columns_for([*(c for t in TASKS.values() for c in t.columns), *COST_COLUMNS, *BENCH_COLUMNS, PRIVILEGED])  # every kind's, costs, a bench's
    extra = [c for c in df.columns if c not in known]
    if extra:
        raise ScenarioError(str(path), extra[0], f"a column semsearch does not write{did_you_mean(str(extra[0]), known)} "
                            "(edited by hand?); remove it, or write into another folder with --out")
    for c in NUMBERS:
        if c in df.columns and not pd.api.types.is_numeric_dtype(df[c]):  # a cell that is not a number
            num = pd.to_numeric(df[c], errors="coerce")
            bad = num.isna() & df[c].notna() & (df[c].astype(str).str.strip() != "")
            if bad.any():
                k = int(bad.to_numpy().nonzero()[0][0])
                raise ScenarioError(str(path), c, f"expected numbers, found {df[c].iloc[k]!r} on line {k + 2} "
                                    "(edited by hand?); fix it, or write into another folder with --out")
            df[c] = num
    df = df.dropna(subset=["wall_s"])
    failed = df["outcome"].isin(["error", "timeout"]).to_numpy()  # a run that failed has no distance
    for c in NUMBERS:  # every number a run writes is finite; a few are never missing
        if c not in df.columns:  # a column only some folders have (a language model's costs)
            continue
        v = df[c].to_numpy(float)
        inf = np.isneginf(v) if c in UNREACHABLE else np.isinf(v)  # a goal nothing reaches: an infinite shortest path
        bad = inf | (np.isnan(v) & ~failed if c == "distance_m" else False) | (v < 0 if c in MEASURED else False)
        if bad.any():
            k = int(bad.nonzero()[0][0])
            want = "a finite number >= 0" if c in MEASURED else "a number, or inf" if c in UNREACHABLE else "a finite number"
            raise ScenarioError(str(path), c, f"expected {want}"
                                f", found {df[c].iloc[k]} on line {df.index[k] + 2} (edited by hand?); fix it, or write "
                                "into another folder with --out")
    engine = df["engine"].to_numpy(float)  # empty: a row widened from a runs.csv written before the column (engine 1)
    bad = ~np.isnan(engine) & ((engine < 1) | (engine != np.floor(engine)))
    if bad.any():
        k = int(bad.nonzero()[0][0])
        raise ScenarioError(str(path), "engine", f"expected a simulator engine (a whole number >= 1), found {df['engine'].iloc[k]} "
                            f"on line {df.index[k] + 2} (edited by hand?); fix it, or write into another folder with --out")
    df["engine"] = np.where(np.isnan(engine), 1, engine).astype(np.int64)
    return df


def _lossless(col: pd.Series) -> pd.Series:
    """A key column as numbers when every entry reads back as written (``304``, ``-2``: int64;
    ``1.5``, ``2.0``: float64), else its text (``4.50``, ``1e3``, ``NA``, ``K202``)."""
    text = col.astype(str)
    if len(text) and text.str.fullmatch(r"-?[0-9]{1,18}").all():
        return text.astype(np.int64)
    num = pd.to_numeric(text, errors="coerce")
    if len(text) and num.notna().all() and (num.map(lambda v: repr(float(v))) == text).all():
        return num.astype(float)
    return text


# columns added after the first release, with what rows written before them stand for
LATER = {"episode": 0, "start_x": float("nan"), "start_y": float("nan"), "start_heading": float("nan"), "room": "",
         "cause": None, "soft_spl": float("nan"), "left_m": float("nan"), "fingerprint": "", "code": "", "engine": 1}
TEXT = ["stage", "map", "message", "room", "cause", "code"]
KEY_TEXT = ("planner", "params", "goal")  # read as written: never a number, never missing
MISSING = ["", "nan", "NaN", "NA", "N/A", "null", "None", "<NA>"]  # what pandas reads as missing in the other columns
UNREACHABLE = ("shortest_m", "left_m", "ratio")  # +inf where nothing achieves the goal (an absent object)
MEASURED = ("episode", "seed", "distance_m", "wall_s")  # never negative; a distance missing only in a failed run's row
NUMBERS = ["episode", "seed", "start_x", "start_y", "start_heading", "success", "distance_m", "shortest_m", "ratio", "spl",
           "soft_spl", "left_m", "time_s", "steps", "decisions", "wall_s", "engine", *COST_COLUMNS]


def _whole_lines(fh) -> int:
    """The length of an open binary file up to and including its last newline (0 without one)."""
    end = fh.seek(0, os.SEEK_END)
    pos = end
    while pos > 0:
        step = min(65536, pos)
        fh.seek(pos - step)
        k = fh.read(step).rfind(b"\n")
        if k >= 0:
            return pos - step + k + 1
        pos -= step
    return 0


def run_rows(df: pd.DataFrame) -> pd.DataFrame:
    """The rows that stand for whole runs (not the per-stage rows of chains)."""
    return df[df["stage"] == ""] if len(df) else df


class RowWriter:
    """Appends rows to runs.csv, flushing each to disk as it arrives."""

    def __init__(self, path: Path, columns: list[str] | None = None):
        """``columns``: a new file's (default :data:`~semsearch_cli.metrics.COLUMNS`; a batch
        gives :func:`~semsearch_cli.metrics.columns_for` its kind, its planners' cost columns, ...).
        A file that exists keeps its own columns, widened by those of ``columns`` it lacks (a
        planner with cost columns run into a folder whose first planners had none): the file is
        rewritten once, atomically, its rows empty in the new columns, so that no column of a new
        row is dropped."""
        path.parent.mkdir(parents=True, exist_ok=True)
        if path.is_file():  # drop a last line cut by an interruption
            with open(path, "rb+") as fh:
                fh.truncate(_whole_lines(fh))
        new = not path.is_file() or path.stat().st_size == 0
        fields = list(columns or COLUMNS)
        if not new:  # keep the file's columns
            with open(path, newline="") as fh:
                fields = next(csv.reader(fh))
            if columns and any(c not in fields for c in columns):
                fields = _widen(path, fields, list(columns))
        self.fh = open(path, "a", newline="")
        self.w = csv.DictWriter(self.fh, fieldnames=fields, extrasaction="ignore")
        if new:
            self.w.writeheader()
            self.fh.flush()

    def write(self, rows: list[dict]) -> None:
        """Append the rows of one run together, all or none: when the write fails (a full disk),
        the file is cut back to where it was, so a run is never half recorded."""
        buf = io.StringIO()
        csv.DictWriter(buf, fieldnames=self.w.fieldnames, extrasaction="ignore").writerows(rows)
        self.fh.flush()
        start = self.fh.tell()
        try:
            self.fh.write(buf.getvalue())
            self.fh.flush()
            os.fsync(self.fh.fileno())
        except OSError:
            self.fh = _cut_back(self.fh, start)
            raise

    def close(self) -> None:
        self.fh.close()


def widened(have: list[str], want: list[str]) -> list[str]:
    """``have`` (a file's columns, in its order) with each column of ``want`` it lacks inserted
    after the column that comes before it in ``want`` (first when none does)."""
    out = list(have)
    for i, c in enumerate(want):
        if c not in out:
            before = next((w for w in reversed(want[:i]) if w in out), None)
            out.insert(out.index(before) + 1 if before is not None else 0, c)
    return out


def _widen(path: Path, have: list[str], want: list[str]) -> list[str]:
    """Rewrite runs.csv ``path`` with the columns of ``want`` it lacks (:func:`widened`), its
    rows as they were and empty in those; atomically (a temporary file beside it, synced, then
    renamed over it): an interruption leaves the old file or the new one, never part of either."""
    fields = widened(have, want)
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    tmp = temp_path(path)
    try:
        with open(tmp, "w", newline="") as out:
            w = csv.DictWriter(out, fieldnames=fields, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
            out.flush()
            os.fsync(out.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return fields


def _cut_back(fh, size: int):
    """``fh``'s file cut back to ``size`` bytes and reopened for appending: what a failed write
    left after it (part of a run's rows) is dropped."""
    path = fh.name
    try:
        fh.close()  # flushing what is still buffered may fail again
    except OSError:
        pass
    os.truncate(path, size)
    return open(path, "a", newline="")




def json_safe(v):
    """``v`` as strict JSON can hold it, whatever a planner put in ``Decision.info``: NaN and
    infinities become null, NumPy numbers and arrays plain numbers and lists, keys text, anything
    else its ``repr``; a container that holds itself ``"<cycle>"``."""
    return _json_safe(v, ())


def _json_safe(v, outer: tuple):
    if isinstance(v, (dict, list, tuple, set, frozenset)):
        if any(v is o for o in outer) or len(outer) >= MAX_INFO_DEPTH:  # a container that holds itself
            return "<cycle>" if any(v is o for o in outer) else "<nested too deeply>"
        inner = (*outer, v)
        if isinstance(v, dict):
            return {str(k): _json_safe(x, inner) for k, x in v.items()}
        return [_json_safe(x, inner) for x in v]
    if isinstance(v, np.ndarray):
        return _json_safe(v.tolist(), outer)
    if isinstance(v, np.generic):
        return _json_safe(v.item(), outer)
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if v is None or isinstance(v, (bool, int, str)):
        return v
    return repr(v)


def save_run_files(out: Path, stem: str, res) -> None:
    """``paths/<stem>.npz`` (path, signs read) and, for traced runs, ``traces/<stem>.jsonl``
    (one JSON object per decision); its frames, decisions and transcripts when kept; each written
    atomically. A run that failed (error, timeout) leaves no path: only its transcripts, what its
    planner paid for, are written."""
    for k, transcript in enumerate(res.transcripts):  # a language model's: transcripts/<run>.jsonl (a chain's later stages __stage<k>)
        write_jsonl(out / "transcripts" / f"{stem}{f'__stage{k}' if k else ''}.jsonl", transcript)
    if res.outcome in ("error", "timeout"):
        return
    paths = out / "paths"
    paths.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(paths / f"{stem}.npz")
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, path=res.path, read_signs=np.asarray(res.read_signs, np.int64))
    os.replace(tmp, paths / f"{stem}.npz")
    if res.trace:
        write_jsonl(out / "traces" / f"{stem}.jsonl", res.trace)
    if res.frames:
        write_frames(out / "frames" / f"{stem}.npz", res.frames)
    if res.decisions_record is not None:
        write_decisions(out / "decisions" / f"{stem}.json", res.decisions_record)


def write_jsonl(path: Path, items: list) -> None:
    """JSON objects, one a line, atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(path)
    with open(tmp, "w", encoding="utf-8") as fh:
        for d in items:
            fh.write(json.dumps(json_safe(d), allow_nan=False) + "\n")
    os.replace(tmp, path)


def decisions_text(record: dict) -> str:
    """A run's decisions record as the file holds it (compact JSON, one line)."""
    return json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n"


def decisions_digest(record: dict) -> str:
    """The SHA-256 (hex) of a decisions file's bytes: what a bench row names its record by."""
    return hashlib.sha256(decisions_text(record).encode("utf-8")).hexdigest()


def write_decisions(path: Path, record: dict) -> None:
    """A run's decisions record (:mod:`semsearch_cli.tasks.decisions`) as compact JSON, atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(path)
    with open(tmp, "w", encoding="utf-8") as fh:
        fh.write(decisions_text(record))
    os.replace(tmp, path)


MAX_DECISIONS_BYTES = 50_000_000  # a decisions file larger than this is not one semsearch wrote (a run's: kilobytes)


def read_decisions(path: Path) -> dict:
    """A decisions record written by :func:`write_decisions`; a :class:`ScenarioError` naming the
    file when it is not one (too large, not JSON, not a record this version reads)."""
    from_file = "not a decisions file semsearch wrote"
    try:
        if path.stat().st_size > MAX_DECISIONS_BYTES:
            raise ScenarioError(str(path), "", f"{from_file} (larger than {MAX_DECISIONS_BYTES:,} bytes)")
        record = json.loads(path.read_text(encoding="utf-8"))
        check_record(record)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise ScenarioError(str(path), "", f"{from_file} ({type(exc).__name__}: {str(exc)[:80]})") from None
    except ReplayError as exc:
        raise ScenarioError(str(path), "", f"{from_file}: {exc}") from None
    return record


def write_frames(path: Path, frames: list[dict]) -> None:
    """A replay's frames (dicts of arrays, numbers, lists and, for ``seen``, a mapping of class to
    (x, y)) to one compressed file, atomically; :func:`read_frames` reads them back."""
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {}
    for i, f in enumerate(frames):
        for k, v in f.items():
            if k == "seen":
                arrays[f"{i}/seen_names"] = np.array(list(v), dtype=str)
                arrays[f"{i}/seen_xy"] = np.array(list(v.values()), float).reshape(-1, 2)
            else:
                arrays[f"{i}/{k}"] = np.asarray(v)
    tmp = temp_path(path)
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, n=np.int64(len(frames)), **arrays)
    os.replace(tmp, path)


MAX_FRAMES = 10_000  # frames in one replay file (a recorder keeps at most 121)
MAX_STORED = 25_000_000  # elements of one stored array: the map size limit (docs/usage.md, Limits)
_KEY = re.compile(r"(0|[1-9][0-9]{0,5})/([a-z_][a-z0-9_]{0,31})", re.ASCII)
_PAIRS = {"path", "trail", "cands", "seen_xy"}  # (k, 2) arrays of (x, y) m
_POINTS = {"target", "goal"}  # one (x, y) m
# what a frame holds (tasks' Event.frame), name -> dimensions: a door search's, an indirect search's
FRAME_KINDS = ({"map": 2, "path": 2, "distance": 0, "cands": 2, "target": 1, "read": 1},
               {"p": 2, "p0": 0, "trail": 2, "t": 0, "goal": 1, "seen_names": 1, "seen_xy": 2})
FRAME_KIND_NAMES = ("doors", "indirect")  # FRAME_KINDS' searches, in order (a message says "a door search's")
_ARTICLE = {"doors": "a door", "indirect": "an indirect"}


def _frame_value_fault(name: str, v: np.ndarray, signs: int | None, map_shape: tuple | None) -> str | None:
    """What is wrong with the values of a frame's array ``name`` (:func:`read_frames`), or None."""
    if v.dtype.kind == "f" and not np.isfinite(v).all():
        return "a value that is not a finite number (NaN or infinity)"
    if name in ("path", "trail") and v.shape[0] == 0:
        return f"a {name} of no pose (it holds the robot's poses so far, the first at its start)"
    if name in ("distance", "t") and float(v) < 0:
        return f"{name} {float(v):g} below 0"
    if name in ("p", "p0") and v.size and not (0.0 <= float(v.min()) and float(v.max()) <= 1.0):
        return "a probability outside [0, 1]"
    if name == "map":
        if v.dtype.kind not in "iu" or (v.size and not (0 <= int(v.min()) and int(v.max()) <= 2)):
            return "a map holds whole numbers 0 (occupied), 1 (unknown) and 2 (free)"
        if map_shape is not None and tuple(v.shape) != tuple(map_shape):
            return (f"a map of {v.shape[0]} x {v.shape[1]} cells, not the run's {map_shape[0]} x {map_shape[1]} (its grid, "
                    "every second cell): the frames of another scenario")
    if name == "read" and v.size:
        if v.dtype.kind not in "iu":
            return f"the signs read are indices, whole numbers, not {v.dtype}"
        top = signs - 1 if signs is not None else None
        if int(v.min()) < 0 or (top is not None and int(v.max()) > top):
            return (f"a sign index {int(v.min()) if int(v.min()) < 0 else int(v.max())} outside 0 to {top} (the scenario's "
                    f"{signs} signs)" if top is not None else f"a sign index {int(v.min())} below 0")
    return None


def read_npz(path: Path, what: str) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` file semsearch wrote, each checked from its header before its
    data is read: numbers or text only (no pickled objects), at most :data:`MAX_STORED` elements.
    A file that is not such an archive (empty, cut short, another format) is a
    :class:`ScenarioError` naming it, never a traceback or an allocation of the header's size."""
    def damaged(field: str, why: str) -> ScenarioError:
        return ScenarioError(str(path), field, f"not a {what} semsearch wrote ({why}); delete it (a report then "
                             "re-simulates the run) or run the batch again")
    out = {}
    try:
        with zipfile.ZipFile(path) as zf:
            for info in zf.infolist():
                name = info.filename.removesuffix(".npy")
                with zf.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                    shape, _, dtype = read(fh)
                    if dtype.hasobject or dtype.kind not in "biufU":
                        raise damaged(name, f"{name} holds {dtype} values, not numbers or text")
                    if math.prod(shape) > MAX_STORED:
                        raise damaged(name, f"{name} claims {' x '.join(map(str, shape))} values, more than {MAX_STORED:,}")
                with zf.open(info) as fh:
                    out[name] = np.lib.format.read_array(fh, allow_pickle=False)
    except ScenarioError:
        raise
    except (OSError, EOFError, ValueError, zipfile.BadZipFile, zlib.error, NotImplementedError, RuntimeError) as exc:
        raise damaged("", f"{type(exc).__name__}: {exc}") from None
    return out


def read_frames(path: Path, kind: str | None = None, signs: int | None = None, map_shape: tuple | None = None) -> list[dict]:
    """The frames :func:`write_frames` wrote, as the replay draws them, read by :func:`read_npz`
    and checked: a frame count ``n`` of at most :data:`MAX_FRAMES`, keys ``<frame>/<name>`` of a
    frame below ``n``, (x, y) arrays of two columns, finite numbers, a path (a trail) of one pose
    at least, a distance and a time of at least 0, a map of 0, 1 and 2 and probabilities in
    [0, 1]; with ``kind`` (``"doors"`` or ``"indirect"``, :data:`FRAME_KIND_NAMES`) every frame
    of that kind's, with ``signs`` the signs read (``read``) whole numbers from 0 to
    ``signs`` - 1 (indices into the world's signs), with ``map_shape`` each map of that shape (the
    run's grid, every second cell). A :class:`ScenarioError` naming the file and the key
    otherwise: a replay drew a damaged file's values (an index past the signs, an empty path)
    into a traceback, or a run of another kind or scenario without a word."""
    arrays = read_npz(path, "replay frames file")

    def bad(field: str, why: str) -> ScenarioError:
        return ScenarioError(str(path), field, f"not a replay frames file semsearch wrote ({why}); delete it (a report then "
                             "re-simulates the run) or run the batch again with --frames")
    n = arrays.pop("n", None)
    if n is None or n.shape != () or n.dtype.kind not in "iu" or not 0 <= int(n) <= MAX_FRAMES:
        raise bad("n", f"the frame count must be a whole number from 0 to {MAX_FRAMES:,}, got "
                  f"{'nothing' if n is None else n.ravel()[:3].tolist()}")
    if kind is not None and kind not in FRAME_KIND_NAMES:
        raise ValueError(f"kind must be one of {', '.join(FRAME_KIND_NAMES)}, not {kind!r}")
    kind_name, want = kind, None if kind is None else FRAME_KINDS[FRAME_KIND_NAMES.index(kind)]
    frames = [dict() for _ in range(int(n))]
    for key, v in arrays.items():
        m = _KEY.fullmatch(key)
        if m is None or int(m[1]) >= len(frames):
            raise bad(key, f"a key of frame index below {len(frames)} and a name, like 0/path, expected")
        name = m[2]
        if name != "seen_names" and v.dtype.kind == "U":
            raise bad(key, "text where numbers belong")
        if (name in _PAIRS and v.size and (v.ndim != 2 or v.shape[1] != 2)) or (name in _POINTS and v.shape != (2,)):
            raise bad(key, f"(x, y) values expected, got an array of shape {v.shape}")
        frames[int(m[1])][name] = v
    for k, f in enumerate(frames):
        kind = next((d for d in FRAME_KINDS if set(f) == set(d) - ({"seen_names", "seen_xy"} - set(f))), None)
        if kind is None:
            raise bad(f"{k}/", f"frame {k} holds {', '.join(sorted(f)) or 'nothing'}; a frame holds "
                      + " or ".join(", ".join(d) for d in FRAME_KINDS))
        if want is not None and kind is not want:
            raise bad(f"{k}/", f"frame {k} is {_ARTICLE[FRAME_KIND_NAMES[FRAME_KINDS.index(kind)]]} search's "
                      f"({', '.join(sorted(f))}), not {_ARTICLE[kind_name]} search's ({', '.join(want)}): the frames of "
                      "another run")
        for name, v in f.items():
            if v.ndim != kind[name] and v.size:
                raise bad(f"{k}/{name}", f"{kind[name]} dimension(s) expected, got an array of shape {v.shape}")
            fault = _frame_value_fault(name, v, signs, map_shape)
            if fault:
                raise bad(f"{k}/{name}", fault)
    for f in frames:
        if "seen_names" in f:
            f["seen"] = {str(c): tuple(float(u) for u in xy) for c, xy in zip(f.pop("seen_names"), f.pop("seen_xy", ()))}
        for k, v in list(f.items()):
            if isinstance(v, np.ndarray) and v.ndim == 0:
                f[k] = v.item()
        if "read" in f:
            f["read"] = [int(i) for i in np.ravel(f["read"])]
        for k in ("target", "goal"):
            if k in f:
                f[k] = tuple(float(u) for u in f[k])
    return frames
