"""Fit a learned door planner's model from labelled decisions (scripts/make_labels.py) and write
it as arrays (semsearch_cli/data/models/<name>.json, the package data a learned planner will read;
none is registered yet, docs/learning.md). Run from the checkout, with the ``train`` extra
installed (``pip install -e '.[train]'``):

    python scripts/train_learned.py --labels results/labels/labels.csv [--name learned-doors-v1] [--objective regret|best]

The model: scikit-learn's gradient-boosted trees (fixed seed) on the features of
semsearch_cli/planners/doors/learned.py, either regressing ``log(1 + regret)`` of each reachable
target, ``regret`` the metres its oracle (``d(c) + G(c)``) exceeds the decision's best (a planner
takes the least), or classifying whether it is the best (the highest log-odds). Decisions with fewer than two labelled targets teach nothing and are left out.
One floor in five (by the floor's name) is held out; the script prints, on those floors, the mean
regret of the target the model picks against greedy's (the nearest) and nsos's (the highest phi),
and checks that the exported arrays predict what scikit-learn predicts."""

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

from semsearch_cli.planners.doors.learned import FEATURES, MODELS, Trees

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


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--labels", type=Path, required=True)
    ap.add_argument("--name", default="learned-doors-v1")
    ap.add_argument("--iterations", type=int, default=200)
    ap.add_argument("--leaves", type=int, default=15)
    ap.add_argument("--objective", choices=("regret", "best"), default="regret",
                    help="regret: regress log(1 + regret); best: classify the decision's best target")
    a = ap.parse_args()
    t0 = time.perf_counter()
    raw = pd.read_csv(a.labels, dtype={"goal": str})
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
           "training": {"labels": str(a.labels.name), "floors": int(df["scenario"].nunique()),
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
           "oracle": 0.0}
    doc["training"]["held_out_regret_m"] = {k: round(v, 3) for k, v in res.items()}
    MODELS.mkdir(parents=True, exist_ok=True)
    path = MODELS / f"{a.name}.json"
    path.write_text(json.dumps(doc, separators=(",", ":")) + "\n")
    print(f"{len(raw)} labelled targets -> {len(df)} in decisions with a choice; {df['scenario'].nunique()} floors "
          f"({val['scenario'].nunique()} held out); fit {fit_s:.1f} s; all {time.perf_counter() - t0:.1f} s")
    print("held-out mean regret of the target picked (m): " + ", ".join(f"{k} {v:.2f}" for k, v in res.items()))
    print(f"exported == scikit-learn's predictions (max gap {gap:.1e}); {path} ({path.stat().st_size / 1e3:.0f} kB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
