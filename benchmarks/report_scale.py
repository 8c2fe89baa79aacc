"""Report at scale: the peak resident memory and wall time of `semsearch report` over a runs.csv
of N rows (issue 35: 20,000 rows ended in a MemoryError; 100,000 rows should report within 2 GB).

Usage:
  python benchmarks/report_scale.py [--rows 1000 20000 100000] [--repeat 3] [--md FILE]

The rows are real ones replicated: one `semsearch run demo` (2 goals x 2 planners x 10 seeds, one
episode per goal) into a temporary folder, whose 40 rows are repeated under new seeds until there
are N, each copy's distance scaled by a factor drawn once per row (seeded), so that no two units
are alike and ratio, SPL and soft SPL follow. With one episode per goal the unit of every interval
is the repeat (report/stats.py), so each of the 4 goal x planner groups holds N / 4 units: the
bootstrap's worst case. Each report runs in a fresh process (``semsearch report FOLDER
--no-replay``: the replay re-simulates one run whatever N is), timed from outside, its peak
resident memory read from ``os.wait4``; ``--repeat`` times for N up to 20,000 (the median is
shown), once above. The path files of the copies do not exist: the path figures draw the runs
that have them, as for a folder whose paths were deleted.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from output import emit

REPO = Path(__file__).resolve().parents[1]
SEMSEARCH = [sys.executable, "-c", "import sys; from semsearch_cli.cli import main; sys.exit(main())"]


def base_folder(tmp: Path) -> Path:
    """A real results folder: `semsearch run demo` (40 rows)."""
    out = tmp / "demo"
    subprocess.run([*SEMSEARCH, "run", "demo", "--out", str(out)], check=True, capture_output=True, cwd=tmp)
    return out


def scaled(base: Path, n: int, out: Path, seed: int = 0) -> Path:
    """``base`` with its runs.csv replicated to ``n`` rows under new seeds (see the module's text)."""
    shutil.copytree(base, out, ignore=shutil.ignore_patterns("runs.csv", "report.*", "summary.csv", "tables", "figures"))
    rows = pd.read_csv(base / "runs.csv", dtype=str, keep_default_na=False)
    k = -(-n // len(rows))
    big = pd.concat([rows] * k, ignore_index=True).iloc[:n].copy()
    copy = np.arange(n) // len(rows)
    big["seed"] = (rows["seed"].astype(int).to_numpy()[np.arange(n) % len(rows)] + 10 * copy).astype(str)
    f = np.where(copy == 0, 1.0, np.random.default_rng(seed).uniform(0.8, 1.25, n))
    d = big["distance_m"].astype(float).to_numpy() * f
    short = big["shortest_m"].astype(float).to_numpy()
    ok = big["success"].astype(int).to_numpy() == 1
    big["distance_m"] = np.round(d, 2).astype(str)
    big["ratio"] = np.round(d / short, 4).astype(str)
    spl = np.where(ok, short / np.maximum(d, short), 0.0)
    big["spl"] = big["soft_spl"] = np.round(spl, 4).astype(str)
    big.to_csv(out / "runs.csv", index=False)
    return out


def report_once(folder: Path) -> tuple[float, float]:
    """(peak resident memory in MB, wall time in s) of one `semsearch report FOLDER --no-replay`."""
    t0 = time.perf_counter()
    p = subprocess.Popen([*SEMSEARCH, "report", str(folder), "--no-replay"], stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE)
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode:
        tail = err.decode(errors="replace").strip().splitlines()[-1:] or ["?"]
        raise SystemExit(f"semsearch report failed on {folder} (exit {p.returncode}): {tail[0]}")
    return usage.ru_maxrss / 1024, wall


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rows", type=int, nargs="+", default=[1000, 20000, 100000])
    ap.add_argument("--repeat", type=int, default=3, help="reports per N up to 20,000 rows (once above)")
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    lines = ["| rows | units per group | reports | peak RSS (MB) | wall (s) |", "|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        base = base_folder(Path(tmp))
        groups = pd.read_csv(base / "runs.csv").groupby(["goal", "planner"]).ngroups
        for n in a.rows:
            folder = scaled(base, n, Path(tmp) / f"rows{n}")
            reps = a.repeat if n <= 20000 else 1
            res = [report_once(folder) for _ in range(reps)]
            mb, wall = statistics.median(r[0] for r in res), statistics.median(r[1] for r in res)
            lines.append(f"| {n:,} | {n // groups:,} | {reps} | {mb:.0f} | {wall:.1f} |")
            shutil.rmtree(folder)
    head = (f"`semsearch report --no-replay` over a replicated `semsearch run demo` ({groups} goal x planner groups, "
            f"repeats as units); median of the reports shown")
    return emit("\n".join([head, ""] + lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
