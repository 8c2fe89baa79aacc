"""The row store: runs.csv, appended one row at a time as runs finish, read back for resume and
reports; and each run's path (and trace) beside it."""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ScenarioError
from ..metrics import CAUSES, COLUMNS
from ..files import temp_path


def read_runs(path: Path, as_written: bool = False) -> pd.DataFrame:
    """runs.csv as a DataFrame (empty with the columns when absent). A torn last line (a write
    cut by power loss or a full disk, even inside a quoted field) is left out; a file that is not
    a runs.csv written by semsearch is a :class:`ScenarioError`. ``stage`` and ``map`` are read as
    text (empty for a run's own row).

    ``as_written``: a run's key columns (``planner``, ``params``, ``goal``) as the text that was
    written, never a number or a missing value: a goal labelled ``4.50``, ``1e3`` or ``NA`` is that
    label. A batch resumes (and moves rows aside) by these, so no label can make a run count
    twice or be rewritten; without it, pandas reads them as it reads any column (``4.5``, NaN),
    as the rows the API returns always have."""
    if path.is_dir():
        raise ScenarioError(str(path), "", "is a folder, not a runs.csv; move it away or write into another folder with --out")
    if not path.is_file() or path.stat().st_size == 0:
        return pd.DataFrame(columns=COLUMNS)
    data = path.read_bytes()
    data = data[: data.rfind(b"\n") + 1]  # whole lines only
    bad = "not a runs.csv written by semsearch; move it away or write into another folder with --out"
    try:
        text = dict.fromkeys(KEY_TEXT, str) if as_written else {}
        na = dict(keep_default_na=False, na_values={c: MISSING for c in [*COLUMNS, *LATER] if c not in KEY_TEXT}) \
            if as_written else {}
        df = pd.read_csv(io.BytesIO(data), dtype={"stage": str, "map": str, "message": str, "kind": str, "scenario": str,
                                                  "fingerprint": str, "code": str, "room": str, "cause": str, **text},
                         encoding="utf-8", **na)  # a scenario may be named 50045233
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
    for c in NUMBERS:
        if c in df.columns and not pd.api.types.is_numeric_dtype(df[c]):  # a cell that is not a number
            num = pd.to_numeric(df[c], errors="coerce")
            bad = num.isna() & df[c].notna() & (df[c].astype(str).str.strip() != "")
            if bad.any():
                k = int(bad.to_numpy().nonzero()[0][0])
                raise ScenarioError(str(path), c, f"expected numbers, found {df[c].iloc[k]!r} on line {k + 2} "
                                    "(edited by hand?); fix it, or write into another folder with --out")
            df[c] = num
    return df.dropna(subset=["wall_s"])


# columns added after the first release, with what rows written before them stand for
LATER = {"episode": 0, "start_x": float("nan"), "start_y": float("nan"), "start_heading": float("nan"), "room": "",
         "cause": None, "soft_spl": float("nan"), "left_m": float("nan"), "fingerprint": "", "code": ""}
TEXT = ["stage", "map", "message", "room", "cause", "code"]
KEY_TEXT = ("planner", "params", "goal")  # read as written: never a number, never missing
MISSING = ["", "nan", "NaN", "NA", "N/A", "null", "None", "<NA>"]  # what pandas reads as missing in the other columns
NUMBERS = ["episode", "seed", "start_x", "start_y", "start_heading", "success", "distance_m", "shortest_m", "ratio", "spl",
           "soft_spl", "left_m", "time_s", "steps", "decisions", "wall_s"]


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

    def __init__(self, path: Path):
        path.parent.mkdir(parents=True, exist_ok=True)
        if path.is_file():  # drop a last line cut by an interruption
            with open(path, "rb+") as fh:
                fh.truncate(_whole_lines(fh))
        new = not path.is_file() or path.stat().st_size == 0
        fields = COLUMNS
        if not new:  # keep the file's columns
            with open(path, newline="") as fh:
                fields = next(csv.reader(fh))
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
    else its ``repr``."""
    if isinstance(v, dict):
        return {str(k): json_safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple, set, frozenset)):
        return [json_safe(x) for x in v]
    if isinstance(v, np.ndarray):
        return json_safe(v.tolist())
    if isinstance(v, np.generic):
        return json_safe(v.item())
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if v is None or isinstance(v, (bool, int, str)):
        return v
    return repr(v)


def save_run_files(out: Path, stem: str, res) -> None:
    """``paths/<stem>.npz`` (path, signs read) and, for traced runs, ``traces/<stem>.jsonl``
    (one JSON object per decision); each written atomically."""
    paths = out / "paths"
    paths.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(paths / f"{stem}.npz")
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, path=res.path, read_signs=np.asarray(res.read_signs, np.int64))
    os.replace(tmp, paths / f"{stem}.npz")
    if res.trace:
        traces = out / "traces"
        traces.mkdir(parents=True, exist_ok=True)
        tmp = temp_path(traces / f"{stem}.jsonl")
        with open(tmp, "w") as fh:
            for d in res.trace:
                fh.write(json.dumps(json_safe(d), allow_nan=False) + "\n")
        os.replace(tmp, traces / f"{stem}.jsonl")
    if res.frames:
        write_frames(out / "frames" / f"{stem}.npz", res.frames)


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


def read_frames(path: Path) -> list[dict]:
    """The frames :func:`write_frames` wrote, as the replay draws them."""
    with np.load(path) as z:
        frames = [dict() for _ in range(int(z["n"]))]
        for key in z.files:
            if key == "n":
                continue
            i, k = key.split("/", 1)
            frames[int(i)][k] = z[key]
    for f in frames:
        if "seen_names" in f:
            f["seen"] = {str(c): tuple(float(u) for u in xy) for c, xy in zip(f.pop("seen_names"), f.pop("seen_xy"))}
        for k, v in list(f.items()):
            if isinstance(v, np.ndarray) and v.ndim == 0:
                f[k] = v.item()
        if "read" in f:
            f["read"] = [int(i) for i in f["read"]]
        if "target" in f or "goal" in f:
            for k in ("target", "goal"):
                if k in f:
                    f[k] = tuple(float(u) for u in f[k])
    return frames
