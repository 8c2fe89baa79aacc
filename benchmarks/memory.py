"""Memory per worker: the peak resident memory of a fresh process that imports semsearch, loads a
scenario (what `validate` does) and then runs one search (what each worker does per run).

Usage:
  python benchmarks/memory.py [SCENARIO ...] [--runs 3] [--md FILE]

Without scenarios: configs/hotel.yaml (1327 x 700 cells) and the same building on a 2000 x 2000
map (the hotel's image in the bottom-left corner of a 2000 x 2000 canvas of "outside" gray, 0.1 m
per cell: every grid the simulator keeps is the canvas' size). Each stage is measured in its own process, ``--runs`` times (the median is shown): the
imports alone, imports + load, imports + load + one run (the first goal, the first planner
variant, seed 0). A worker of ``--workers N`` holds one loaded scenario and one run at a time,
so the last column is the memory each worker needs (a forked worker shares the parent's loaded
pages until it writes to them, so this is an upper bound).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import yaml

from output import emit

REPO = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, resource, sys
stage = sys.argv[1]
from semsearch_cli.runner import Loaded, expand
from semsearch_cli.runner.execution import execute
out = {"import_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}
if stage != "import":
    L = Loaded.load(sys.argv[2])
    out["cells"] = int(L.world.free.size)
    if stage == "run":
        rows, res = execute(L, expand(L, 1)[0])
        out["outcome"], out["distance_m"] = res.outcome, res.distance_m
out["peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(out))
"""


def big_hotel(folder: Path) -> Path:
    """configs/hotel.yaml on a 2000 x 2000 map: its image in the canvas' bottom-left corner."""
    doc = yaml.safe_load((REPO / "configs" / "hotel.yaml").read_text())
    img = cv2.imread(str(REPO / "maps" / "hotel" / "map.png"), cv2.IMREAD_GRAYSCALE)
    H, W = img.shape
    out = np.full((2000, 2000), 160, np.uint8)
    out[2000 - H:, :W] = img  # the bottom-left corner stays at the origin
    cv2.imwrite(str(folder / "map.png"), out)
    doc["name"] = "hotel-2000"
    doc["map"] = {"image": str(folder / "map.png"), "resolution": doc["map"]["resolution"]}
    doc["doors"] = str(REPO / "maps" / "hotel" / "doors.csv")
    path = folder / "hotel-2000.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


def measure(stage: str, scenario: Path) -> dict:
    p = subprocess.run([sys.executable, "-c", CHILD, stage, str(scenario)], capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenarios", nargs="*", type=Path)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        scenarios = a.scenarios or [REPO / "configs" / "hotel.yaml", big_hotel(Path(tmp))]
        lines = ["| scenario | cells | imports (MB) | + load (MB) | + one run (MB) | run outcome |", "|---|---|---|---|---|---|"]
        for sc in scenarios:
            m = {st: [measure(st, sc) for _ in range(a.runs)] for st in ("import", "load", "run")}
            med = {st: statistics.median(r["peak_mb"] for r in rs) for st, rs in m.items()}
            run = m["run"][0]
            lines.append(f"| {sc.name} | {run['cells']:,} | {med['import']:.0f} | {med['load']:.0f} | {med['run']:.0f} | "
                         f"{run['outcome']} {run['distance_m']:.0f} m |")
    return emit("\n".join([f"peak resident memory of one process, median of {a.runs}", ""] + lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
