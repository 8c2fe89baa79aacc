"""What a learned door planner reads and runs: its trees evaluated with NumPy (exact values on a
hand-made tree, NaN routing included) and its features, the ones its labels are recorded with."""

from __future__ import annotations

import numpy as np
import pytest

from semsearch_cli import api
from semsearch_cli.learn import LabelSeat
from semsearch_cli.planners import Variant
from semsearch_cli.planners.doors.learned import FEATURES, MODELS, Trees, add_relative, decision_features, load_model
from semsearch_cli.planners.doors.nsos import NSOS, NSOSParams
from semsearch_cli.runner import Loaded

from .test_nsos import _junction_context


def test_trees_route_rows_as_the_thresholds_and_missing_values_say():
    # tree 0: x0 <= 1 ? (leaf 1.0) : (x1 <= 5 ? leaf 2.0 : leaf 3.0), NaN in x0 goes right, in x1 left;
    # tree 1: a lone leaf of 0.5; baseline 10
    doc = {"features": ["a", "b"], "baseline": 10.0, "max_depth": 2,
           "trees": {"roots": [0, 5], "feature": [0, 0, 1, 0, 0, 0], "threshold": [1.0, 0, 5.0, 0, 0, 0],
                     "left": [1, 0, 3, 0, 0, 0], "right": [2, 0, 4, 0, 0, 0],
                     "leaf": [False, True, False, True, True, True], "value": [0, 1.0, 0, 2.0, 3.0, 0.5],
                     "missing_left": [False, False, True, False, False, False]}}
    X = np.array([[0.5, 9.0], [1.0, 0.0], [2.0, 5.0], [2.0, 6.0], [np.nan, np.nan], [np.nan, 7.0]])
    assert Trees(doc).predict(X).tolist() == [11.5, 11.5, 12.5, 13.5, 12.5, 13.5]


def test_relative_features_are_against_the_decisions_best():
    X = np.full((3, len(FEATURES)), np.nan)
    col = {f: i for i, f in enumerate(FEATURES)}
    X[:, col["d_m"]] = [4.0, 2.5, np.nan]
    X[:, col["phi"]] = [0.3, 0.5, np.nan]
    X[:, col["SF"]] = [0.25, 0.25, np.nan]
    X[:, col["phi_g"]] = [0.5, 0.75, np.nan]
    X[:, col["T_expected"]] = [30.0, 42.5, np.nan]
    add_relative(X)
    assert X[:, col["T_over_min"]][:2].tolist() == [0.0, 12.5]
    assert X[:, col["d_over_min"]][:2].tolist() == [1.5, 0.0] and np.isnan(X[2, col["d_over_min"]])
    assert X[:, col["phi_below_max"]][:2].tolist() == pytest.approx([0.2, 0.0])
    assert X[:, col["SF_below_max"]][:2].tolist() == [0.0, 0.0] and X[:, col["phi_g_below_max"]][:2].tolist() == [0.25, 0.0]


def test_labels_are_recorded_with_every_feature_a_learned_planner_reads(tmp_path):
    api.init("demo", tmp_path, force=True)
    task = Loaded.load(tmp_path / "demo.yaml").task
    seat = LabelSeat(task)
    task.run(Variant("greedy", ()), task.episodes[0], 0, seat=seat)
    rows = [r for r in seat.rows if r["decision"] == 1]
    assert len(rows) >= 2 and set(FEATURES) <= set(rows[0])
    d = [r["d_m"] for r in rows]
    assert [r["d_over_min"] for r in rows] == pytest.approx([x - min(d) for x in d])
    assert sorted(r["d_rank"] for r in rows) == list(range(len(rows)))


def test_the_shipped_model_reads_this_planners_features():
    trees = load_model("learned-doors-v1")
    assert trees.features == FEATURES
    assert (MODELS / "learned-doors-v1.json").stat().st_size < 1_000_000  # small enough to ship
    # every tree's nodes lie within the arrays, and each inner node's children after it
    inner = ~trees.leaf
    assert (trees.left[inner] > np.flatnonzero(inner)).all() and (trees.right[inner] < trees.leaf.size).all()


def test_the_learned_planner_takes_the_least_predicted_regret():
    b, cands, ctx = _junction_context(goal=21)
    X, d = decision_features(ctx, cands, NSOS(NSOSParams()))
    pred = load_model("learned-doors-v1").predict(X)
    dec = Variant("learned", ()).build().choose(ctx, cands)
    assert dec.info["chosen"] == int(np.argmin(np.where(np.isfinite(d), pred, np.inf)))
    assert dec.info["predicted"] == round(float(pred.min()), 4)


def test_an_unknown_model_is_refused_by_name():
    with pytest.raises(Exception, match="learned-doors-v1"):
        Variant("learned", (("model", "learned-doors-v9"),)).build()
