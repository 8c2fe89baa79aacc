"""Train the learned door planner (``learned``, docs/learning.md) from nothing, in one command, and
write its model as arrays into the package (semsearch_cli/data/models/<name>.json). Run from the
checkout, with the ``train`` extra installed (``pip install -e '.[train]'``):

    python scripts/train_learned.py --out results/labels --floors 120 --dagger 60     # the shipped model
    python scripts/train_learned.py --labels results/labels/greedy/labels.csv ...    # fit labels already made

With ``--out``: label ``--floors`` training floors under greedy (scripts/make_labels.py; floors
already labelled are skipped, so an interrupted run resumes), fit, and with ``--dagger N`` label N
more floors under the fitted model's own planner and fit again on all of them (one round of
DAgger: the planner learns from the states it visits itself).

The model: scikit-learn's gradient-boosted trees (fixed seed) on the features of
semsearch_cli/planners/doors/learned.py, either regressing ``log(1 + regret)`` of each reachable
target, ``regret`` the metres its oracle (``d(c) + G(c)``) exceeds the decision's best (a planner
takes the least), or classifying whether it is the best (the highest log-odds). Decisions with
fewer than two labelled targets teach nothing and are left out. One floor in five (by the floor's
name) is held out; the script prints, on those floors, the mean regret of the target the model
picks against greedy's (the nearest), nsos's (the highest phi) and the numbering model's (the
least expected travel), and checks that the exported arrays predict what scikit-learn predicts."""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.ensemble import HistGradientBoostingClassifier, HistGradientBoostingRegressor

from make_labels import make  # scripts/, beside this one
from semsearch_cli.planners.doors.learned import FEATURES, MODELS, Trees, load_model

DECISION = ["scenario", "goal", "episode", "seed", "decision"]


def prepare(df: pd.DataFrame) -> pd.DataFrame:
    """The labelled rows of reachable targets in decisions with a choice, and the target."""
    df = df.replace([np.inf, -np.inf], np.nan)
    df = df[df["oracle_m"].notna() & df["d_m"].notna()].copy()
    g = df.groupby(DECISION, sort=False)
    df = df[g["target"].transform("size") >= 2].copy()
    g = df.groupby(DECISION, sort=False)
    df["regret"] = df["oracle_m"] - g["oracle_m"].transform("min")
    df["y"] = np.log1p(df["regret"])
    return df


def picked_regret(df: pd.DataFrame, score: np.ndarray) -> float:
    """The mean over decisions of the regret of the target of least ``score``."""
    d = df.assign(_s=score)
    idx = d.groupby(DECISION, sort=False)["_s"].idxmin()
    return float(d.loc[idx, "regret"].mean())


def export(model: HistGradientBoostingRegressor) -> dict:
    """The trees as flat arrays (:class:`~semsearch_cli.planners.doors.learned.Trees`)."""
    out = {k: [] for k in ("feature", "threshold", "left", "right", "leaf", "value", "missing_left", "roots")}
    depth = 0
    for (tree,) in model._predictors:
        nodes = tree.nodes
        base = len(out["feature"])
        out["roots"].append(base)
        out["feature"] += nodes["feature_idx"].astype(int).tolist()
        out["threshold"] += nodes["num_threshold"].astype(float).tolist()
        out["left"] += (nodes["left"].astype(int) + base).tolist()
        out["right"] += (nodes["right"].astype(int) + base).tolist()
        out["leaf"] += nodes["is_leaf"].astype(bool).tolist()
        out["value"] += nodes["value"].astype(float).tolist()
        out["missing_left"] += nodes["missing_go_to_left"].astype(bool).tolist()
        depth = max(depth, int(nodes["depth"].max()))
    return {"trees": out, "baseline": float(np.ravel(model._baseline_prediction)[0]), "max_depth": depth}


def fit(raw: pd.DataFrame, a, sources: list[str]) -> dict:
    """Fit the model to labelled rows, check its export and measure it on the held-out floors:
    the model's document (its trees, and how it was trained)."""
    df = prepare(raw)
    held = df["scenario"].map(lambda s: int(hashlib.sha256(str(s).encode()).hexdigest(), 16) % 5 == 0)
    train, val = df[~held], df[held]
    kw = dict(max_iter=a.iterations, max_leaf_nodes=a.leaves, learning_rate=0.1, min_samples_leaf=50, early_stopping=False,
              random_state=0)
    t1 = time.perf_counter()
    if a.objective == "regret":  # predict log(1 + regret): the least is chosen
        model = HistGradientBoostingRegressor(**kw).fit(train[list(FEATURES)].to_numpy(float), train["y"].to_numpy(float))
    else:  # predict the log-odds that a target is the decision's best: the highest is chosen (its negation the least)
        model = HistGradientBoostingClassifier(**kw).fit(train[list(FEATURES)].to_numpy(float), train["best"].to_numpy(bool))
    fit_s = time.perf_counter() - t1
    doc = {"name": a.name, "features": list(FEATURES), "objective": a.objective, "sign": 1.0 if a.objective == "regret" else -1.0,
           **export(model),
           "training": {"labels": sources, "floors": int(df["scenario"].nunique()),
                        "held_out_floors": int(val["scenario"].nunique()), "rows": int(len(train)),
                        "decisions": int(train.groupby(DECISION).ngroups), "fit_s": round(fit_s, 1),
                        "iterations": a.iterations, "leaves": a.leaves, "learning_rate": 0.1, "min_samples_leaf": 50,
                        "random_state": 0, "sklearn": __import__("sklearn").__version__}}
    trees = Trees(doc)
    Xv = val[list(FEATURES)].to_numpy(float)
    ours = trees.predict(Xv)
    theirs = model.predict(Xv) if a.objective == "regret" else model.decision_function(Xv)
    gap = float(np.abs(ours - theirs).max()) if len(Xv) else 0.0
    if gap > 1e-9:
        raise SystemExit(f"the exported trees predict {gap} away from scikit-learn's")
    res = {"model": picked_regret(val, doc["sign"] * ours), "greedy (nearest)": picked_regret(val, val["d_m"].to_numpy()),
           "nsos (highest phi)": picked_regret(val, -val["phi"].fillna(-np.inf).to_numpy()),
           "numbering (least expected travel)": picked_regret(val, val["T_expected"].fillna(np.inf).to_numpy()),
           "oracle": 0.0}
    doc["training"]["held_out_regret_m"] = {k: round(v, 3) for k, v in res.items()}
    print(f"{len(raw)} labelled targets -> {len(df)} in decisions with a choice; {df['scenario'].nunique()} floors "
          f"({val['scenario'].nunique()} held out); fit {fit_s:.1f} s; exported == scikit-learn's predictions "
          f"(max gap {gap:.1e})", flush=True)
    print("held-out mean regret of the target picked (m): " + ", ".join(f"{k} {v:.2f}" for k, v in res.items()), flush=True)
    return doc


def named(csvs) -> list[str]:
    """The label files as the model records them: folder and name, not this machine's path."""
    return [f"{Path(c).parent.name}/{Path(c).name}" for c in csvs]


def write(doc: dict) -> Path:
    MODELS.mkdir(parents=True, exist_ok=True)
    path = MODELS / f"{doc['name']}.json"
    tmp = path.with_suffix(".part")
    tmp.write_text(json.dumps(doc, separators=(",", ":")) + "\n")
    tmp.replace(path)
    load_model.cache_clear()
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB)", flush=True)
    return path


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--labels", type=Path, nargs="*", default=[], help="labelled CSVs to fit (instead of --out's)")
    ap.add_argument("--out", type=Path, help="label training floors into OUT/greedy (and OUT/dagger) first, then fit")
    ap.add_argument("--floors", type=int, default=120, help="with --out: training floors labelled under greedy")
    ap.add_argument("--dagger", type=int, default=0,
                    help="with --out: then this many more floors labelled under the first model's own planner, and fit again on all")
    ap.add_argument("--name", default="learned-doors-v1")
    ap.add_argument("--iterations", type=int, default=200)
    ap.add_argument("--leaves", type=int, default=15)
    ap.add_argument("--objective", choices=("regret", "best"), default="regret",
                    help="regret: regress log(1 + regret); best: classify the decision's best target")
    a = ap.parse_args()
    t0 = time.perf_counter()
    csvs = list(a.labels)
    if a.out is not None:
        if a.name != "learned-doors-v1" and a.dagger:
            raise SystemExit("--dagger runs the registered planner, which reads learned-doors-v1: keep --name")
        csvs = [make(a.floors, a.out / "greedy", "greedy")]
        print(f"labels under greedy: {time.perf_counter() - t0:.0f} s", flush=True)
        if a.dagger:
            write(fit(pd.concat([pd.read_csv(c, dtype={"goal": str}) for c in csvs]), a, named(csvs)))
            csvs.append(make(a.dagger, a.out / "dagger", "learned", first=a.floors))
            print(f"labels under the first model: {time.perf_counter() - t0:.0f} s", flush=True)
    if not csvs:
        raise SystemExit("give --labels CSV... or --out DIR")
    raw = pd.concat([pd.read_csv(c, dtype={"goal": str}) for c in csvs], ignore_index=True)
    write(fit(raw, a, named(csvs)))
    print(f"all {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
