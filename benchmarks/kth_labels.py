"""The label statistics of real floors, measured on the public KTH campus floor plans (Aydemir,
Jensfelt, Folkesson 2012): what doors-v1's mix of numbering conventions is calibrated on.

Each floor plan is imported as `semsearch import kth` does (a sign per door from a room to a
circulation space, on the corridor wall), and its signs' labels are measured: how many carry a
letter suffix (``010a``), a leading zero, a room's second door (``2512/2``); how many numbers are
skipped (within a floor and prefix, 1 - distinct numbers / (max - min + 1)); and the floor's
predictability (semsearch_cli.bench.predictability: order along walls, parity per wall). The
floor plans are read from a folder on this machine (never copied into the repository): the XML
files of the public dataset, e.g. those of github.com/selimon2000/GNN_Semantic_Map_Prediction
(dataset/*/raw/*.xml), or ../shared/reference_maps/kth.

Usage:
  python benchmarks/kth_labels.py FOLDER [--md FILE] [--csv FILE]
  python benchmarks/kth_labels.py --suite doors-v1   # the same statistics of a shipped split's floors, to compare
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
from output import emit

from semsearch_cli.bench import open_split
from semsearch_cli.bench.predictability import predictability
from semsearch_cli.errors import ScenarioError
from semsearch_cli.world.importers.kth import import_kth
from semsearch_cli.world.labels import parse_label


def measure(xml: Path, tmp: Path) -> dict | None:
    try:
        p, _ = import_kth(xml, tmp / xml.stem, duplicates="any")
    except ScenarioError as exc:
        return {"floor": xml.stem, "error": exc.message[:80]}
    return measure_doors(p.parent / "doors.csv", xml.stem)


def measure_doors(doors: Path, name: str) -> dict:
    """The statistics of one floor's doors file."""
    d = pd.read_csv(doors, dtype={"number": str}, keep_default_na=False)
    labels = [str(a) for a in d["number"]]
    first = [a for a in labels if "/" not in a]  # a room's first door
    parsed = [parse_label(a) for a in first]
    nums = [q for q in parsed if q is not None]
    gaps = []
    for pre in {q.prefix for q in nums}:
        v = sorted({q.number for q in nums if q.prefix == pre})
        if len(v) >= 3:
            gaps.append(1.0 - len(v) / (v[-1] - v[0] + 1))
    pr = predictability(labels, d["x"], d["y"], d["facing"], name)
    return {"floor": name, "signs": len(labels), "rooms": len(first),
            "lettered": sum(1 for q in nums if q.suffix and not q.suffix.startswith("/")) / max(1, len(nums)),
            "leading_zero": sum(1 for a in first if re.match(r"^0\d", a)) / max(1, len(first)),
            "second_doors": (len(labels) - len(first)) / max(1, len(labels)),
            "no_number": (len(first) - len(nums)) / max(1, len(first)),
            "skipped": float(np.mean(gaps)) if gaps else np.nan,
            "order": pr.order, "parity": pr.parity, "predictability": pr.value, "walls": pr.walls}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?")
    ap.add_argument("--suite", help="measure a shipped split's floors instead (val)")
    ap.add_argument("--md", type=Path)
    ap.add_argument("--csv", type=Path)
    a = ap.parse_args()
    if a.suite:
        sp = open_split(a.suite)
        df = pd.DataFrame([measure_doors(f.scenario.parent / "doors.csv", f.id) for f in sp.floors])
        return emit(table(df, f"{a.suite} val: {len(df)} floors, {int(df['signs'].sum())} signs"), a.md)
    files = sorted(a.folder.rglob("*.xml"))
    if not files:
        print(f"skipped: no KTH floor-plan XML under {a.folder}")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        rows = [measure(f, Path(tmp)) for f in files]
    df = pd.DataFrame(rows)
    ok = df[df.get("error", pd.Series(np.nan, index=df.index)).isna()] if "error" in df else df
    if a.csv:
        df.to_csv(a.csv, index=False)
    return emit(table(ok, f"KTH floor plans: {len(files)} files, {len(ok)} imported ({len(df) - len(ok)} refused by the "
                          f"importer); {int(ok['signs'].sum())} signs, {int(ok['rooms'].sum())} rooms"), a.md)


def table(ok: pd.DataFrame, title: str) -> str:
    cols = ["lettered", "leading_zero", "second_doors", "no_number", "skipped", "order", "parity", "predictability"]
    q = ok[cols].describe(percentiles=[0.25, 0.5, 0.75]).T[["mean", "25%", "50%", "75%"]]
    lines = [title, "", "| statistic (per floor) | mean | 25% | median | 75% | floors with any |", "|---|---|---|---|---|---|"]
    for c in cols:
        anyf = f"{(ok[c] > 0).mean():.0%}" if c in ("lettered", "leading_zero", "second_doors", "no_number", "skipped") else ""
        lines.append(f"| {c} | {q.loc[c, 'mean']:.3f} | {q.loc[c, '25%']:.3f} | {q.loc[c, '50%']:.3f} | {q.loc[c, '75%']:.3f} | {anyf} |")
    lines.append(f"\nparity statistic >= 0.5 on {(ok['parity'] >= 0.5).mean():.0%} of the floors")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
