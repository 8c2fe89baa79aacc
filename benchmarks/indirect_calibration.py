"""How much indirect search's results rest on what the paper leaves unstated, and on what the
robot is told: the calibration table and the ablation table, from one command each.

``--table calibration`` (the default): for each alternative value of an unstated parameter (speed,
turn rate, camera pitch, object sizes, whether objects block the robot, count-once) and of each
reading we changed (N of Eq. 34, AOSEOOR's random search, Algorithm 4's occlusion, the detection
table and the robot's model of it), UIS, AOSEOOR, ISC-PN-SM and ISCG-PN-SM at view scales 1 m and
2.5 m. No value here is tuned towards the paper's Table 3: the table says how far each choice
moves the results, nothing more.

``--table ablations`` (after cos-pomdp's ablations for correlational search): ISC-PN-SM and
ISCG-PN-SM (``--methods`` for others) under the true relations, relations learned from k = 5, 20
and 100 generated training rooms (``indirect.learned``), wrong relations (``ablation: shuffled``),
a noisy detector (``indirect.noise``: false positives and position error), no secondary objects at
all, and the side-blind table.

Both run on configs/indirect.yaml's rooms from the same drawn starts (``--starts`` per room, one
run each) and print the success rate per method and scale with its 95% interval clustered on rooms
(:func:`semsearch_cli.report.stats.rate_ci`), the default first; then the same for the searches that
found A within ``--within`` seconds (60 by default; the same searches, read at a shorter budget,
where the five minutes leave little room below 100%).

``--table secondaries`` (the red flag: does seeing secondary objects ever hurt?): UIS and four
informed methods, each setting run twice, in the rooms as generated and in the same rooms holding A
alone, from the same starts; printed as the paired difference of success, with against without.

Usage: python benchmarks/indirect_calibration.py [--table calibration|ablations] [--starts 2]
       [--workers 2] [--methods UIS,ISC-PN-SM] [--out results/indirect-calibration]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

from semsearch_cli.config import read_yaml, with_param
from semsearch_cli.report import stats
from semsearch_cli.report.indirect import PAIR_KEYS, paired_success
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch

SCENARIO = Path(__file__).resolve().parents[1] / "configs" / "indirect.yaml"
SCALES = [1.0, 2.5]
SIZES = {"monitor": 0.5, "keyboard": 0.45, "system_unit": 0.45, "router": 0.25}  # the defaults (ours)

# (label, dotted parameter, value): the default first; each other row changes one thing
CALIBRATION = [
    ("default", None, None),
    ("speed 0.15 m/s (default 0.2)", "indirect.robot.speed", 0.15),
    ("speed 0.3 m/s", "indirect.robot.speed", 0.3),
    ("turn rate 30 deg/s (default 40)", "indirect.robot.turn_rate", 30.0),
    ("turn rate 60 deg/s", "indirect.robot.turn_rate", 60.0),
    ("camera pitch 15 deg (default 30)", "indirect.camera.pitch", 15.0),
    ("camera pitch 45 deg", "indirect.camera.pitch", 45.0),
    ("object sizes halved", "indirect.camera.diameters", {k: v / 2 for k, v in SIZES.items()}),
    ("object sizes doubled", "indirect.camera.diameters", {k: v * 2 for k, v in SIZES.items()}),
    ("objects block the robot (default no)", "indirect.objects_block", True),
    ("count_once false (default true)", "indirect.count_once", False),
    ("occlusion by radius (default diameter)", "indirect.camera.occlusion", "radius"),
    ("N = 50 in Eq. 34 (default 3)", "n_poses", 50),
    ("AOSEOOR random walk (default waypoints)", "AOSEOOR.random_search", "walk"),
    ("side-blind table (default every yaw)", "indirect.camera.table", "side_blind"),
    ("model: mean over yaws at every frame (default per yaw)", "indirect.camera.model", "mean"),
]
ABLATIONS = [
    ("true relations", None, None),
    ("learned from 5 rooms", "indirect.learned", {"rooms": 5, "seed": 1000}),
    ("learned from 20 rooms", "indirect.learned", {"rooms": 20, "seed": 1000}),
    ("learned from 100 rooms", "indirect.learned", {"rooms": 100, "seed": 1000}),
    ("wrong relations (shuffled)", "indirect.ablation", "shuffled"),
    ("noisy detector (2% false positives per frame, 0.2 m error)", "indirect.noise",
     {"false_positive": 0.02, "position_sd": 0.2}),
    ("no secondary objects", "indirect.ablation", "no_secondary"),
    ("side-blind table", "indirect.camera.table", "side_blind"),
]
# the red flag: under each setting, every run again in rooms that hold A alone, paired
SECONDARIES = [
    ("default", None, None),
    ("side-blind table", "indirect.camera.table", "side_blind"),
    ("model: mean over yaws", "indirect.camera.model", "mean"),
    ("side-blind table, model: mean over yaws (the earlier setup)", [("indirect.camera.table", "side_blind"),
                                                                     ("indirect.camera.model", "mean")], None),
    ("count_once false", "indirect.count_once", False),
    ("objects do not occlude each other (sizes 1 cm)", "indirect.camera.diameters", {k: 0.01 for k in SIZES}),
]
TABLES = {"calibration": (CALIBRATION, ["UIS", "AOSEOOR", "ISC-PN-SM", "ISCG-PN-SM"]),
          "ablations": (ABLATIONS, ["ISC-PN-SM", "ISCG-PN-SM"]),
          "secondaries": (SECONDARIES, ["UIS", "ISC-OP-SM", "ISC-PN-SM", "ISCG-OP-SM", "ISCG-PN-SM"])}


def variant(data: dict, param, value, file: Path) -> dict:
    if param is None:
        return data
    if isinstance(param, list):  # several changes at once
        for p, v in param:
            data = variant(data, p, v, file)
        return data
    if param == "n_poses":  # every local-search method's N
        out = data
        for m in ("UIS", "ISC-PN-SM"):
            out = with_param(out, f"{m}.n_poses", value, file)
        return out
    return with_param(data, param, value, file)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table", choices=sorted(TABLES), default="calibration")
    ap.add_argument("--starts", type=int, default=2, help="starts drawn per room (20 rooms): trials per cell = 20 x this")
    ap.add_argument("--methods", default="", help="comma-separated methods (default: the table's)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--within", type=float, default=60.0, help="s: also print the success within this time (the "
                    "searches are the same; 5 minutes leave little room below 100%%)")
    ap.add_argument("--out", type=Path, default=None, help="default results/indirect-<table>")
    a = ap.parse_args()
    alternatives, methods = TABLES[a.table]
    methods = [m for m in a.methods.split(",") if m] or methods
    out = a.out or Path(f"results/indirect-{a.table}")
    base = read_yaml(SCENARIO)
    scales = [1.0, 1.75, 2.5] if a.table == "secondaries" else SCALES
    base["indirect"]["view_scales"] = scales
    base["planners"] = [{"name": m} for m in methods]
    base["episodes"] = {"starts": a.starts, "seed": 0}
    base["experiment"] = {"seeds": 1, "base_seed": 0}
    table, paired = [], []
    for k, (label, param, value) in enumerate(alternatives):
        data = variant(base, param, value, SCENARIO)
        t0 = time.perf_counter()
        rows = searches(data, out / f"{k:02d}", a.workers)
        if a.table == "secondaries":
            alone = searches(variant(data, "indirect.ablation", "no_secondary", SCENARIO), out / f"{k:02d}-alone", a.workers)
            paired += with_against_without(label, rows, alone)
        method = rows["planner"].astype(str).str.split("[").str[0]  # UIS[n_poses=50] is UIS
        for (m, sc), g in rows.groupby([method, rows["goal"].astype(float)]):
            units = stats.units(g, cluster="room")
            quick = g["success"].astype(bool) & (g["time_s"].astype(float) <= a.within)
            for budget, hits in (("5 min", g["success"]), (f"{a.within:g} s", quick)):
                rate, lo, hi = stats.rate_ci(hits.astype(int), units)
                table.append({"alternative": label, "budget": budget, "method": m, "scale": sc, "n": len(g),
                              "success": 100 * rate, "lo": 100 * lo, "hi": 100 * hi})
        print(f"{label}: {len(rows)} searches, {time.perf_counter() - t0:.0f} s", flush=True)
    t = pd.DataFrame(table)
    t.to_csv(out / f"{a.table}.csv", index=False)
    t["cell"] = t.apply(lambda r: f"{r.success:.0f} [{r.lo:.0f}-{r.hi:.0f}]", axis=1)
    n = int(t["n"].iloc[0])
    for budget, g in t.groupby("budget", sort=False):
        wide = g.pivot_table(index="alternative", columns=["method", "scale"], values="cell", aggfunc="first", sort=False)
        wide = wide.reindex(index=[x[0] for x in alternatives], columns=[(m, s) for m in methods for s in scales])
        print(f"\nfound within {budget}: success % [95% interval clustered on rooms], {n} trials per cell "
              f"({a.starts} drawn starts in each of 20 rooms)\n")
        print("| alternative | " + " | ".join(f"{m} {s:g} m" for m, s in wide.columns) + " |")
        print("|---|" + "---|" * len(wide.columns))
        for label, r in wide.iterrows():
            print(f"| {label} | " + " | ".join(str(v) for v in r) + " |")
    if paired:
        p = pd.DataFrame(paired)
        p.to_csv(out / "with_against_without.csv", index=False)
        p["cell"] = p.apply(lambda r: f"{r['diff']:+.1f} [{r['lo']:+.1f}, {r['hi']:+.1f}]", axis=1)
        wide = p.pivot_table(index="alternative", columns="method", values="cell", aggfunc="first", sort=False)
        wide = wide.reindex(index=[x[0] for x in alternatives], columns=methods)
        print(f"\nwith secondary objects minus without (rooms holding A alone), success points over the scales "
              f"{', '.join(f'{s:g}' for s in scales)} m, paired on start, room and scale [95% bootstrap over rooms]\n")
        print("| setting | " + " | ".join(wide.columns) + " |")
        print("|---|" + "---|" * len(wide.columns))
        for label, r in wide.iterrows():
            print(f"| {label} | " + " | ".join(str(v) for v in r) + " |")


def searches(data: dict, folder: Path, workers: int) -> pd.DataFrame:
    loaded = Loaded.load(SCENARIO, data)
    rows = run_batch(loaded, expand(loaded), folder, BatchOptions(workers=workers))
    return rows[rows["stage"] == ""]


def with_against_without(label: str, rows: pd.DataFrame, alone: pd.DataFrame) -> list[dict]:
    """Per method, the paired difference of success with secondary objects minus without."""
    out = []
    keys = PAIR_KEYS + ["goal"]
    for m, g in rows.groupby(rows["planner"].astype(str)):
        d, lo, hi, n = paired_success(g, alone[alone["planner"].astype(str) == m], keys)
        out.append({"alternative": label, "method": m, "pairs": n, "diff": 100 * d, "lo": 100 * lo, "hi": 100 * hi})
    return out


if __name__ == "__main__":
    main()
