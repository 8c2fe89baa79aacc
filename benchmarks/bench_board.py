"""The val board of every built-in planner: each planner of a suite's kind on its val split
(doors-v1 under its true and shuffled numberings, and with --ablation all nsos[alpha=0.9] and
greedy under parity-flipped and reversed too; doors-classic-v1, indirect-v1 and objects-v1 true), every
folder verified by replay, and the board written (docs/bench-board.md and its figure). Prints the
wall time of each run and each verification, their ratio, and the predictability per numbering
convention. Folders already complete are resumed (their runs not run again: the time then counts
only what ran).

Usage:
  python benchmarks/bench_board.py [--out results/bench] [--workers 2] [--site docs/bench-board]
                                   [--suites doors-v1,doors-classic-v1,indirect-v1,objects-v1] [--ablation none|baselines|shuffled|all] [--md FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import pandas as pd
from output import emit

from semsearch_cli import api
from semsearch_cli.bench import SUITES, open_split
from semsearch_cli.planners import PLANNERS
from semsearch_cli.runner import BatchOptions

FIRST = {"doors": ["nsos[alpha=0.9]", "greedy"], "objects": ["lsos"]}  # listed first on the board; then the kind's other built-in planners


def planners_of(kind: str) -> list[str]:
    rest = sorted(n for n, c in PLANNERS.items()
                  if c.task == kind and not c.service and n not in {p.split("[")[0] for p in FIRST.get(kind, [])})
    return FIRST.get(kind, []) + rest


def numberings(suite: str, planner: str, ablation: str) -> tuple:
    """The numberings a planner runs under: on doors-v1, ``shuffled`` for every planner (``all``
    and ``shuffled``) or for nsos and greedy alone (``baselines``), and parity-flipped and
    reversed for nsos and greedy (``all``); elsewhere the true numbering."""
    base = planner in ("nsos[alpha=0.9]", "greedy")
    if suite != "doors-v1" or ablation == "none" or (ablation == "baselines" and not base):
        return ("true",)
    if ablation == "all" and base:
        return ("true", "shuffled", "parity-flipped", "reversed")
    return ("true", "shuffled")


def safe(label: str) -> str:
    return label.replace("[", "_").replace("]", "").replace("=", "")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("results/bench"))
    ap.add_argument("--site", type=Path, default=Path("docs/bench-board"))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--suites", default="doors-v1,doors-classic-v1,indirect-v1,objects-v1")
    ap.add_argument("--ablation", default="all", choices=("none", "baselines", "shuffled", "all"))
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    timings, folders = [], []
    for suite in a.suites.split(","):
        for planner in planners_of(SUITES[suite].kind):
            for numbering in numberings(suite, planner, a.ablation):
                out = a.out / suite / f"{safe(planner)}-{numbering}"
                t0 = time.perf_counter()
                res = api.bench_run(suite, [planner], out, numbering=numbering, options=BatchOptions(workers=a.workers))
                t_run = time.perf_counter() - t0
                t0 = time.perf_counter()
                v = api.verify(out, workers=a.workers).verdict
                t_verify = time.perf_counter() - t0
                timings.append({"suite": suite, "planner": planner, "numbering": numbering, "runs": len(res.runs),
                                "run_s": round(t_run, 1), "verify_s": round(t_verify, 1),
                                "run/verify": round(t_run / t_verify, 2), "verified": f"{v.verified}/{v.runs}"})
                print(json.dumps(timings[-1]), flush=True)
                folders.append(out)
    files = api.bench_board(folders, a.site)
    t = pd.DataFrame(timings)
    lines = ["Runs and verification (wall time, --workers %d; a run resumed from earlier rows times only what it ran):" % a.workers, "",
             "| suite | planner | numbering | runs | run s | verify s | run / verify | verified |", "|---|---|---|---|---|---|---|---|"]
    for r in timings:
        lines.append(f"| {r['suite']} | {r['planner']} | {r['numbering']} | {r['runs']} | {r['run_s']} | {r['verify_s']} | "
                     f"{r['run/verify']} | {r['verified']} |")
    for suite, g in t.groupby("suite", sort=False):
        lines.append(f"\n{suite}: all runs {g['run_s'].sum():.0f} s, all verifications {g['verify_s'].sum():.0f} s")
    sp = open_split("doors-v1")
    pred = pd.DataFrame([{"convention": f.recipe["numbering"], **f.recipe["predictability"]} for f in sp.floors])
    lines += ["", "doors-v1 val, predictability per numbering convention (mean over its floors):", "",
              "| convention | floors | order | parity | predictability |", "|---|---|---|---|---|"]
    for c, g in pred.groupby("convention"):
        lines.append(f"| {c} | {len(g)} | {g['order'].mean():.3f} | {g['parity'].mean():.3f} | {g['value'].mean():.3f} |")
    lines += ["", "board: " + ", ".join(str(f) for f in files)]
    board_md = a.site / "board.md"
    if board_md.is_file():  # the docs page: the board, and the figures beside it
        page = Path("docs/bench-board.md")
        if a.site.resolve() == page.with_suffix("").resolve():
            text = board_md.read_text().replace("](gain_vs", "](bench-board/gain_vs")
            page.write_text("<!-- Generated by benchmarks/bench_board.py: run it again to update. -->\n\n"
                            "The sortable page: [bench-board/index.html](bench-board/index.html).\n\n" + text)
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
