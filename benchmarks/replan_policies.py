"""The two door re-planning policies (navigation.replan: periodic, events) on the 520 thesis door
runs, paired run for run.

    python benchmarks/replan_policies.py [--workers 2] [--keep DIR] [--md FILE]

Runs configs normal, inverse, hotel_thesis and kth (13 goals x greedy and nsos at alpha 0.8, 0.9,
1.0 x 10 seeds = 520 runs) under each policy; the runs of the two policies share episode and seed,
so each run is a pair. Prints, per planner, the mean distance under each policy, the mean of the
per-run difference (events - periodic) with its 95% bootstrap interval over the runs and that
interval as a share of the periodic mean, the Wilcoxon p, and the wall time of each policy; then,
per policy, nsos against greedy on the same goals and seeds (per-run differences, 95% bootstrap
interval over the runs, Wilcoxon p).
The events policy may become the default only if every planner's interval lies inside +-5% of its
mean and nsos still beats greedy (the rule for making it the default); the script says whether it does.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from output import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from semsearch_cli.report.document import markdown_table  # noqa: E402
from semsearch_cli.report.stats import mean_ci  # noqa: E402
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch  # noqa: E402
from scipy.stats import wilcoxon  # noqa: E402

CONFIGS = ("normal", "inverse", "hotel_thesis", "kth")


def run_policy(replan: str, out: Path, workers: int) -> tuple[pd.DataFrame, float]:
    t0 = time.perf_counter()
    frames = []
    for name in CONFIGS:
        path = ROOT / "configs" / f"{name}.yaml"
        data = yaml.safe_load(path.read_text())
        data.setdefault("navigation", {})["replan"] = replan
        L = Loaded.load(path, data)
        runs = run_batch(L, expand(L, 10, planners=["greedy", "nsos"]), out / replan / name, BatchOptions(workers=workers))
        frames.append(runs.assign(config=name))
    return pd.concat(frames, ignore_index=True), time.perf_counter() - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", type=Path, default=None, help="folder for the rows (a temporary one by default)")
    ap.add_argument("--md", type=Path, default=None)
    a = ap.parse_args()
    out = a.keep or Path(tempfile.mkdtemp(prefix="replan-"))
    per, wall = {}, {}
    for replan in ("periodic", "events"):
        per[replan], wall[replan] = run_policy(replan, out, a.workers)
    key = ["config", "planner", "goal", "episode", "seed"]
    both = per["periodic"].merge(per["events"], on=key, suffixes=("_p", "_e"))
    rows, ok = [], True
    for planner, g in both.groupby("planner", sort=False):
        d = (g["distance_m_e"] - g["distance_m_p"]).to_numpy()
        mean_p = float(g["distance_m_p"].mean())
        m, lo, hi = mean_ci(d, np.arange(len(d)))
        inside = -0.05 * mean_p <= lo and hi <= 0.05 * mean_p
        ok &= inside
        p = float(wilcoxon(d).pvalue) if np.any(d != 0) else 1.0
        rows.append({"planner": planner, "runs": len(d), "periodic mean (m)": round(mean_p, 1),
                     "events mean (m)": round(float(g["distance_m_e"].mean()), 1),
                     "events - periodic (m)": f"{m:+.1f} [{lo:+.1f}, {hi:+.1f}]",
                     "interval / periodic mean": f"[{lo / mean_p:+.1%}, {hi / mean_p:+.1%}]",
                     "inside +-5%": "yes" if inside else "no", "p": round(p, 3),
                     "found (periodic, events)": f"{(g['outcome_p'] == 'found').mean():.0%}, {(g['outcome_e'] == 'found').mean():.0%}"})
    text = [f"## the 520 thesis door runs under each policy (wall: periodic {wall['periodic']:.0f} s, events {wall['events']:.0f} s, "
            f"{a.workers} workers)", "", markdown_table(pd.DataFrame(rows)), ""]
    beats = {}
    for replan, df in per.items():
        g = df[df["planner"] == "greedy"]
        lines = []
        for label in sorted(l for l in df["planner"].unique() if l.startswith("nsos")):
            m = df[df["planner"] == label].merge(g, on=["config", "goal", "episode", "seed"], suffixes=("", "_g"))
            d = (m["distance_m"] - m["distance_m_g"]).to_numpy()
            mean, lo, hi = mean_ci(d, np.arange(len(d)))
            beats[(replan, label)] = mean < 0
            lines.append({"policy": replan, "nsos": label, "pairs (runs)": len(d),
                          "nsos - greedy (m)": f"{mean:+.1f} [{lo:+.1f}, {hi:+.1f}]",
                          "p": round(float(wilcoxon(d).pvalue), 4) if np.any(d != 0) else 1.0})
        text += [markdown_table(pd.DataFrame(lines)), ""]
    still = all(v for (r, _), v in beats.items() if r == "events") or \
        all(beats[("events", k[1])] == beats[("periodic", k[1])] for k in beats if k[0] == "periodic")
    verdict = ok and still
    text.append(f"events as the default: {'yes' if verdict else 'no'} (every interval inside +-5%: {'yes' if ok else 'no'}; "
                f"nsos against greedy keeps its sign: {'yes' if still else 'no'})")
    return emit("\n".join(text), a.md)


if __name__ == "__main__":
    sys.exit(main())
