"""The Willow-like check of ``import ros --clean``, on a SLAM-like map of our own making.

    python benchmarks/slam_clean.py [--seeds 20] [--workers 2] [--md FILE]

Our demo building saved as ROS's map_saver saves a map (PGM: free 254, occupied 0, unknown 205),
with what SLAM leaves around a building: 18 one-pixel laser rays fanning from the start out through
the walls; every sign's facing given 20 degrees off its wall's normal, as a user's hand-placed
signs are. It is imported twice with ``semsearch import ros`` (goals 304 and 452, the same start),
without and with ``--clean``, and nsos[alpha=0.9] and greedy search both scenarios ``--seeds``
times. Prints the cells ``--clean`` removed, the largest change of a sign's facing between the file
and each import, and per planner and goal the mean distance on each map with the paired
difference (with minus without, 95% bootstrap interval over the repeats, which share their start
heading).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import yaml
from output import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from semsearch_cli.report.document import markdown_table  # noqa: E402
from semsearch_cli.report.stats import mean_ci  # noqa: E402
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch  # noqa: E402

ORIGIN = (-3.0, -2.0)
CLI = [sys.executable, "-c", "from semsearch_cli.cli import main; main()"]


def slam_map(work: Path) -> tuple[np.ndarray, pd.DataFrame, tuple[float, float]]:
    """Write work/lab.pgm, lab.yaml and doors.csv; returns the fans' cells, the signs as given and the start."""
    img = cv2.imread(str(ROOT / "maps/demo/map.png"), cv2.IMREAD_GRAYSCALE)
    pgm = np.where(img >= 200, 254, np.where(img < 100, 0, 205)).astype(np.uint8)
    demo = Loaded.load(ROOT / "configs/demo.yaml")
    r0, c0 = (int(v) for v in demo.world.frame.to_index(*demo.world.start_xy))
    H, W = pgm.shape
    fans = np.zeros_like(pgm)
    for a in np.linspace(0, 2 * np.pi, 18, endpoint=False):
        end = (int(c0 + 2 * W * np.cos(a)), int(r0 - 2 * H * np.sin(a)))
        cv2.line(fans, (c0, r0), end, 1, 1)
    added = (fans > 0) & (pgm != 254)
    pgm[added] = 254
    cv2.imwrite(str(work / "lab.pgm"), pgm)
    (work / "lab.yaml").write_text(f"image: lab.pgm\nresolution: 0.1\norigin: [{ORIGIN[0]}, {ORIGIN[1]}, 0.0]\n"
                                   "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    doors = pd.read_csv(ROOT / "maps/demo/doors.csv")
    doors["x"] += ORIGIN[0]
    doors["y"] += ORIGIN[1]
    doors["facing"] = doors["facing"] + 20.0
    doors.to_csv(work / "doors.csv", index=False)
    start = (demo.world.start_xy[0] + ORIGIN[0], demo.world.start_xy[1] + ORIGIN[1])
    return added, doors, start


def facing_change(given: pd.DataFrame, folder: Path) -> float:
    out = pd.read_csv(folder / "doors.csv").set_index("number")
    d = (out.loc[given["number"], "facing"].to_numpy() - given["facing"].to_numpy() + 180.0) % 360.0 - 180.0
    return float(np.abs(d).max())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--md", type=Path, default=None)
    a = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="slam-"))
    added, doors, start = slam_map(work)
    runs, notes = {}, []
    for name, extra in (("without --clean", []), ("with --clean", ["--clean"])):
        out = work / ("clean" if extra else "raw")
        p = subprocess.run(CLI + ["import", "ros", str(work / "lab.yaml"), str(work / "doors.csv"), "--out", str(out),
                                  "--goals", "304,452", "--start", f"{start[0]},{start[1]}", *extra],
                           capture_output=True, text=True)
        if p.returncode != 0:
            print(p.stdout, p.stderr)
            return 1
        removed = [" ".join(ln.split()) for ln in p.stdout.splitlines() if "cleaned" in ln]
        notes.append(f"{name}: largest change of a sign's facing {facing_change(doors, out):.1f} deg"
                     + (f"; {removed[0]}" if removed else ""))
        data = yaml.safe_load((out / "scenario.yaml").read_text())
        data["planners"] = [{"name": "greedy"}, {"name": "nsos", "alpha": 0.9}]
        L = Loaded.load(out / "scenario.yaml", data)
        runs[name] = run_batch(L, expand(L, a.seeds), out / "runs", BatchOptions(workers=a.workers))
    key = ["planner", "goal", "seed"]
    both = runs["without --clean"].merge(runs["with --clean"], on=key, suffixes=("_raw", "_clean"))
    rows = []
    for (planner, goal), g in both.groupby(["planner", "goal"], sort=True):
        d = (g["distance_m_clean"] - g["distance_m_raw"]).to_numpy()
        m, lo, hi = mean_ci(d, np.arange(len(d)))
        rows.append({"planner": planner, "goal": goal, "repeats": len(d),
                     "without --clean (m)": f"{g['distance_m_raw'].mean():.1f} (sd {g['distance_m_raw'].std():.1f})",
                     "with --clean (m)": f"{g['distance_m_clean'].mean():.1f} (sd {g['distance_m_clean'].std():.1f})",
                     "with - without (m)": f"{m:+.1f} [{lo:+.1f}, {hi:+.1f}]",
                     "found": f"{(g['outcome_raw'] == 'found').mean():.0%}, {(g['outcome_clean'] == 'found').mean():.0%}"})
    text = [f"SLAM-like demo map: {int(added.sum())} ray cells added through the walls", *notes, "",
            markdown_table(pd.DataFrame(rows))]
    return emit("\n".join(text), a.md)


if __name__ == "__main__":
    sys.exit(main())
