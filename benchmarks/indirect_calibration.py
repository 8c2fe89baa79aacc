"""How much indirect search's results rest on the values the paper leaves unstated.

For each alternative value of an unstated parameter (speed, turn rate, camera pitch, object sizes,
count-once) and of each reading we changed (N of Eq. 34, AOSEOOR's random search, Algorithm 4's
occlusion), run UIS, AOSEOOR, ISC-PN-SM and ISCG-PN-SM at view scales 1 m and 2.5 m on
configs/indirect.yaml's rooms, from the same drawn starts (``--starts`` per room, one run each),
and print the success rate per method and scale with its 95% interval clustered on rooms
(:func:`semsearch_cli.report.stats.rate_ci`), the default first. No value here is tuned towards the
paper's Table 3: the table says how far each choice moves the results, nothing more.

Usage: python benchmarks/indirect_calibration.py [--starts 2] [--workers 2] [--out results/indirect-calibration]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

from semsearch_cli.config import read_yaml, with_param
from semsearch_cli.report import stats
from semsearch_cli.runner import Loaded, expand, run_batch

SCENARIO = Path(__file__).resolve().parents[1] / "configs" / "indirect.yaml"
METHODS = ["UIS", "AOSEOOR", "ISC-PN-SM", "ISCG-PN-SM"]
SCALES = [1.0, 2.5]
SIZES = {"monitor": 0.5, "keyboard": 0.45, "system_unit": 0.45, "router": 0.25}  # the defaults (ours)

# (label, dotted parameter, value): the default first; each other row changes one thing
ALTERNATIVES = [
    ("default", None, None),
    ("speed 0.3 m/s (default 0.15)", "indirect.robot.speed", 0.3),
    ("turn rate 60 deg/s (default 30)", "indirect.robot.turn_rate", 60.0),
    ("camera pitch 15 deg (default 30)", "indirect.camera.pitch", 15.0),
    ("camera pitch 45 deg", "indirect.camera.pitch", 45.0),
    ("object sizes halved", "indirect.camera.diameters", {k: v / 2 for k, v in SIZES.items()}),
    ("object sizes doubled", "indirect.camera.diameters", {k: v * 2 for k, v in SIZES.items()}),
    ("count_once false (default true)", "indirect.count_once", False),
    ("occlusion by radius (default diameter)", "indirect.camera.occlusion", "radius"),
    ("N = 50 in Eq. 34 (default 3)", "n_poses", 50),
    ("AOSEOOR random walk (default waypoints)", "AOSEOOR.random_search", "walk"),
]


def variant(data: dict, param: str | None, value, file: Path) -> dict:
    if param is None:
        return data
    if param == "n_poses":  # every local-search method's N
        out = data
        for m in ("UIS", "ISC-PN-SM"):
            out = with_param(out, f"{m}.n_poses", value, file)
        return out
    return with_param(data, param, value, file)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, default=2, help="starts drawn per room (20 rooms): trials per cell = 20 x this")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("results/indirect-calibration"))
    a = ap.parse_args()
    base = read_yaml(SCENARIO)
    base["indirect"]["view_scales"] = SCALES
    base["planners"] = [{"name": m} for m in METHODS]
    base["episodes"] = {"starts": a.starts, "seed": 0}
    base["experiment"] = {"seeds": 1, "base_seed": 0}
    table = []
    for k, (label, param, value) in enumerate(ALTERNATIVES):
        data = variant(base, param, value, SCENARIO)
        loaded = Loaded.load(SCENARIO, data)
        t0 = time.perf_counter()
        rows = run_batch(loaded, expand(loaded), a.out / f"{k:02d}", workers=a.workers)
        rows = rows[rows["stage"] == ""]
        method = rows["planner"].astype(str).str.split("[").str[0]  # UIS[n_poses=50] is UIS
        for (m, s), g in rows.groupby([method, rows["goal"].astype(float)]):
            rate, lo, hi = stats.rate_ci(g["success"], stats.units(g, cluster="room"))
            table.append({"alternative": label, "method": m, "scale": s, "n": len(g), "success": 100 * rate,
                          "lo": 100 * lo, "hi": 100 * hi})
        print(f"{label}: {len(rows)} searches, {time.perf_counter() - t0:.0f} s", flush=True)
    t = pd.DataFrame(table)
    t.to_csv(a.out / "calibration.csv", index=False)
    t["cell"] = t.apply(lambda r: f"{r.success:.0f} [{r.lo:.0f}-{r.hi:.0f}]", axis=1)
    wide = t.pivot_table(index="alternative", columns=["method", "scale"], values="cell", aggfunc="first", sort=False)
    wide = wide.reindex(index=[x[0] for x in ALTERNATIVES], columns=[(m, s) for m in METHODS for s in SCALES])
    n = int(t["n"].iloc[0])
    print(f"\nsuccess % [95% interval clustered on rooms], {n} trials per cell ({a.starts} drawn starts in each of 20 rooms)\n")
    print("| alternative | " + " | ".join(f"{m} {s:g} m" for m, s in wide.columns) + " |")
    print("|---|" + "---|" * len(wide.columns))
    for label, r in wide.iterrows():
        print(f"| {label} | " + " | ".join(str(v) for v in r) + " |")


if __name__ == "__main__":
    main()
