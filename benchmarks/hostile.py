"""Hostile inputs, as a user would meet them: every case of ``tests/hostile_inputs.py`` run as a
real ``semsearch`` process with a time limit, classified, and tabulated by category.

Usage:
  python benchmarks/hostile.py [--timeout 120] [--jobs 2] [--only CATEGORY] [--md FILE] [--csv FILE]

Outcomes: ``refused`` (exit 2, no traceback), ``accepted`` (exit 0), ``traceback`` (a Python
traceback on stderr, whatever the status), ``other`` (another status) and ``hang`` (killed at the
time limit); ``warnings`` counts cases that printed a numpy, OpenCV or libpng warning (a defect:
the user should see one paragraph). A case accepted where it should be refused is ``garbage accepted``; one refused
where it should be accepted is ``wrongly refused``. Exits 1 when any case is a defect.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pandas as pd

from output import emit

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.hostile_inputs import build_cases  # noqa: E402

from semsearch_cli.report.document import markdown_table  # noqa: E402

CLI = [sys.executable, "-c", "from semsearch_cli.cli import main; main()"]


def run_case(case, timeout: float, cwd: Path) -> dict:
    t0 = time.perf_counter()
    # a session of its own, so that a hang is killed with every process it started
    p = subprocess.Popen(CLI + case.args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd, errors="replace",
                         start_new_session=True)
    try:
        _, err = p.communicate(timeout=timeout)
        status = p.returncode
        outcome = ("traceback" if "Traceback (most recent call last)" in err else
                   "refused" if status == 2 else "accepted" if status == 0 else "other")
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        status, err, outcome = None, "", "hang"
    defect = outcome in ("traceback", "other", "hang") or (case.expect == "refuse" and outcome == "accepted") \
        or (case.expect == "accept" and outcome == "refused")
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    warned = any(w in ln for ln in lines for w in ("Warning:", "[ WARN", "libpng", "RuntimeWarning"))
    defect = defect or warned
    return {"garbage": case.expect == "refuse" and outcome == "accepted", "wrong_refusal": case.expect == "accept" and outcome == "refused","category": case.category, "case": case.name, "expect": case.expect, "outcome": outcome, "status": status,
            "defect": defect, "warned": warned, "issue_14": case.issue, "seconds": round(time.perf_counter() - t0, 2),
            "message": " ".join(" ".join(lines[-3:]).split())[:300]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default=None, help="one category")
    ap.add_argument("--md", type=Path)
    ap.add_argument("--csv", type=Path)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cases = [c for c in build_cases(root / "cases") if a.only in (None, c.category)]
        work = root / "cwd"  # the working folder: nothing may be written here but results/
        work.mkdir()
        t0 = time.perf_counter()
        with ThreadPoolExecutor(a.jobs) as pool:
            rows = list(pool.map(lambda c: run_case(c, a.timeout, work), cases))
        stray = sorted(p.name for p in work.iterdir() if p.name != "results")
        wall = time.perf_counter() - t0
    df = pd.DataFrame(rows)
    if a.csv:
        df.to_csv(a.csv, index=False)
    table = df.groupby("category", sort=False).agg(
        tried=("case", "size"), refused=("outcome", lambda s: int((s == "refused").sum())),
        accepted=("outcome", lambda s: int((s == "accepted").sum())),
        traceback=("outcome", lambda s: int((s == "traceback").sum())),
        hang=("outcome", lambda s: int((s == "hang").sum())), other=("outcome", lambda s: int((s == "other").sum())),
        warnings=("warned", "sum"),
        garbage_accepted=("garbage", "sum"), wrongly_refused=("wrong_refusal", "sum")).reset_index()
    counts = table.columns.drop("category")
    table[counts] = table[counts].astype(int)
    total = pd.DataFrame([{"category": "all", **{c: int(table[c].sum()) for c in counts}}])
    table = pd.concat([table, total], ignore_index=True)
    bad = df[df["defect"]]
    text = [f"{len(df)} hostile inputs in {wall:.0f} s ({a.jobs} at a time, time limit {a.timeout:g} s each)", "",
            markdown_table(table, fmt="{:g}"), ""]
    if len(bad):
        text += ["Defects:", "", markdown_table(bad[["category", "case", "expect", "outcome", "message"]]), ""]
    if stray:
        text += [f"Written into the working folder: {', '.join(stray)}", ""]
    text.append(f"slowest: {df.sort_values('seconds').iloc[-1]['case']} ({df['seconds'].max():.1f} s)")
    emit("\n".join(text), a.md)
    return 1 if len(bad) or stray else 0


if __name__ == "__main__":
    sys.exit(main())
