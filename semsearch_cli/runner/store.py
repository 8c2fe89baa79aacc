"""The row store: runs.csv, appended one row at a time as runs finish, read back for resume and
reports; and each run's path (and trace) beside it (SPEC 9)."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ScenarioError
from ..metrics import COLUMNS


def read_runs(path: Path) -> pd.DataFrame:
    """runs.csv as a DataFrame (empty with the columns when absent); a torn last line is dropped.
    ``stage`` and ``map`` are read as text (empty for a run's own row)."""
    if not path.is_file() or path.stat().st_size == 0:
        return pd.DataFrame(columns=COLUMNS)
    df = pd.read_csv(path, on_bad_lines="skip", dtype={"stage": str, "map": str, "message": str, "kind": str,
                                                       "scenario": str})  # a scenario may be named 50045233
    if "kind" not in df.columns:
        raise ScenarioError(str(path), "kind", "this runs.csv was written by an older semsearch (no kind column); "
                            "write new runs into another folder with --out")
    df[["stage", "map", "message"]] = df[["stage", "map", "message"]].fillna("")
    return df.dropna(subset=["wall_s"])


def run_rows(df: pd.DataFrame) -> pd.DataFrame:
    """The rows that stand for whole runs (not the per-stage rows of chains)."""
    return df[df["stage"] == ""] if len(df) else df


class RowWriter:
    """Appends rows to runs.csv, flushing each to disk as it arrives."""

    def __init__(self, path: Path):
        path.parent.mkdir(parents=True, exist_ok=True)
        new = not path.is_file() or path.stat().st_size == 0
        fields = COLUMNS
        if not new:  # repair a file cut mid-line by an interruption; keep its columns
            with open(path, "rb+") as fh:
                fh.seek(-1, os.SEEK_END)
                if fh.read(1) != b"\n":
                    fh.write(b"\n")
            with open(path, newline="") as fh:
                fields = next(csv.reader(fh))
        self.fh = open(path, "a", newline="")
        self.w = csv.DictWriter(self.fh, fieldnames=fields, extrasaction="ignore")
        if new:
            self.w.writeheader()
            self.fh.flush()

    def write(self, rows: list[dict]) -> None:
        """Append the rows of one run together."""
        self.w.writerows(rows)
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


def save_run_files(out: Path, stem: str, res) -> None:
    """``paths/<stem>.npz`` (path, signs read) and, for traced runs, ``traces/<stem>.jsonl``
    (one JSON object per decision); each written atomically."""
    paths = out / "paths"
    paths.mkdir(parents=True, exist_ok=True)
    tmp = paths / f".{stem}.tmp.npz"
    with open(tmp, "wb") as fh:
        np.savez_compressed(fh, path=res.path, read_signs=np.asarray(res.read_signs, np.int64))
    os.replace(tmp, paths / f"{stem}.npz")
    if res.trace:
        traces = out / "traces"
        traces.mkdir(parents=True, exist_ok=True)
        tmp = traces / f".{stem}.tmp.jsonl"
        with open(tmp, "w") as fh:
            for d in res.trace:
                fh.write(json.dumps(d) + "\n")
        os.replace(tmp, traces / f"{stem}.jsonl")
