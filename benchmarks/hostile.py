"""Hostile inputs, as a user would meet them: every case of a catalogue run as a real ``semsearch``
process with a time limit and a cap on its memory, classified, and tabulated by category. The
catalogues: ``issue14`` (``tests/hostile_inputs.py``, the first reviews), ``release`` (``tests/
hostile_release.py``, the surfaces the release before added, issue 35: its categories are labels,
episodes, output, frames, planners, commands), ``surfaces`` (``tests/hostile_surfaces.py``, issue
52: the robot, bench and llm surfaces, categories shown as ``robot: live``) or ``all`` (every one;
the release's categories are then shown as ``release: <category>``, apart from the first
catalogue's of the same name).

Usage:
  python benchmarks/hostile.py [--catalogue {issue14,release,surfaces,all}] [--timeout 120] [--jobs 2]
                               [--memory 4] [--only CATEGORY] [--md FILE] [--csv FILE]

Outcomes: ``refused`` (exit 2, no traceback), ``accepted`` (exit 0), ``failed`` (exit 1 of a case
that expects it: a verify that finds a falsified folder), ``traceback`` (a Python
traceback on stderr, whatever the status), ``other`` (another status) and ``hang`` (killed at the
time limit); ``warnings`` counts cases that printed a numpy, OpenCV or libpng warning (a defect:
the user should see one paragraph). A case accepted where it should be refused is ``garbage accepted``; one refused
where it should be accepted is ``wrongly refused``. A case whose output lacks a text of its
``says`` (the field, flag or file it must name) is a defect too; its message then begins
``does not say '...'``. Exits 1 when any case is a defect.

Each case's process may take at most ``--memory`` GB of address space (a damaged file that asks
for 10**9 frames ends in a MemoryError, a defect, not in the machine's memory), and sees a
console 200 columns wide (as the tests do: paths and fields are not broken across lines).
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
from tests import hostile_inputs, hostile_release, hostile_surfaces  # noqa: E402

from semsearch_cli.report.document import markdown_table  # noqa: E402

CATALOGUES = {"issue14": hostile_inputs.build_cases, "release": hostile_release.build_cases,
              "surfaces": hostile_surfaces.build_cases}


def cli(memory_gb: float) -> list[str]:
    """The command line, in a process whose address space is capped at ``memory_gb`` GB."""
    cap = int(memory_gb * 2**30)
    return [sys.executable, "-c", f"import resource; resource.setrlimit(resource.RLIMIT_AS, ({cap}, {cap})); "
            "from semsearch_cli.cli import main; main()"]


def run_case(case, timeout: float, cwd: Path, memory_gb: float = 4.0, category: str | None = None) -> dict:
    t0 = time.perf_counter()
    # a session of its own, so that a hang is killed with every process it started
    p = subprocess.Popen(cli(memory_gb) + case.args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd,
                         errors="replace", start_new_session=True, env={**os.environ, "COLUMNS": "200"})
    out = ""
    try:
        out, err = p.communicate(timeout=timeout)
        status = p.returncode
        outcome = ("traceback" if "Traceback (most recent call last)" in err else
                   "refused" if status == 2 else "accepted" if status == 0 else
                   "failed" if status == 1 and case.expect == "fail" else "other")
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        status, err, outcome = None, "", "hang"
    defect = outcome in ("traceback", "other", "hang") or (case.expect == "refuse" and outcome == "accepted") \
        or (case.expect == "accept" and outcome == "refused") or (case.expect == "fail" and outcome != "failed")
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    warned = any(w in ln for ln in lines for w in ("Warning:", "[ WARN", "libpng", "RuntimeWarning"))
    said = " ".join((out + " " + err).split())  # the console wraps long lines
    unsaid = [s for s in case.says if s not in said] if outcome in ("refused", "accepted", "failed") else []
    seconds = time.perf_counter() - t0
    within = getattr(case, "within", None)  # a refusal that must come before any work (a release case)
    slow = within is not None and seconds > within
    defect = defect or warned or bool(unsaid) or slow
    message = " ".join(" ".join(lines[-3:]).split())
    if unsaid:
        message = f"does not say {', '.join(map(repr, unsaid))}: {message}"
    if slow:
        message = f"took {seconds:.1f} s, more than {within:g} s: {message}"
    return {"garbage": case.expect == "refuse" and outcome == "accepted", "wrong_refusal": case.expect == "accept" and outcome == "refused",
            "category": category or case.category, "case": case.name, "expect": case.expect, "outcome": outcome, "status": status,
            "defect": defect, "warned": warned, "issue_14": case.issue, "seconds": round(seconds, 2),
            "message": message[:300]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--catalogue", choices=["issue14", "release", "surfaces", "all"], default="all",
                    help="tests/hostile_inputs.py (issue14), tests/hostile_release.py (release), tests/hostile_surfaces.py "
                    "(surfaces: the robot, bench and llm surfaces of issue 52) or all three")
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--memory", type=float, default=4.0, help="GB of address space each case's process may take")
    ap.add_argument("--only", default=None, help="one category (as the table shows it, or as its catalogue names it)")
    ap.add_argument("--md", type=Path)
    ap.add_argument("--csv", type=Path)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cases = []  # (case, the category the table shows)
        for name, build in CATALOGUES.items():
            if a.catalogue in (name, "all"):
                shown = (lambda c: f"release: {c.category}") if a.catalogue == "all" and name == "release" else (lambda c: c.category)
                cases += [(c, shown(c)) for c in build(root / "cases" / name) if a.only in (None, c.category, shown(c))]
        work = root / "cwd"  # the working folder: nothing may be written here but results/
        work.mkdir()
        t0 = time.perf_counter()
        with ThreadPoolExecutor(a.jobs) as pool:
            rows = list(pool.map(lambda cc: run_case(cc[0], a.timeout, work, a.memory, cc[1]), cases))
        stray = sorted(p.name for p in work.iterdir() if p.name != "results")
        wall = time.perf_counter() - t0
    df = pd.DataFrame(rows)
    if a.csv:
        df.to_csv(a.csv, index=False)
    table = df.groupby("category", sort=False).agg(
        tried=("case", "size"), refused=("outcome", lambda s: int((s == "refused").sum())),
        accepted=("outcome", lambda s: int((s == "accepted").sum())),
        failed=("outcome", lambda s: int((s == "failed").sum())),
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
