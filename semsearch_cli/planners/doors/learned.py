"""``learned``: the door planner whose choice a model makes, and what it reads (docs/learning.md).

At a decision every frontier target gets the features the robot has (:func:`decision_features`:
its path length and rank, the targets, the metres travelled and signs counted, nsos's terms, the
numbering model's probability that the goal lies beyond the target, metres past it and expected
travel, and the path, nsos's phi, SF and phi_g and the expected travel against the decision's
best). Gradient-boosted regression trees predict ``log(1 + regret)`` of each, ``regret`` the
metres the oracle ``d(c) + G(c)`` (the true remaining travel through the target, computed on the
known map) exceeds the decision's best. The planner takes the least prediction (ties: the nearer
target, then the run's generator) and keeps its last target while that target's prediction is
within ``hysteresis`` of the best, as nsos keeps its own (:class:`KeepTarget`).

The trees were fitted with scikit-learn on training floors that are none of the benchmark's
(``scripts/train_learned.py``, one command) and ship as arrays
(``semsearch_cli/data/models/learned-doors-v1.json``), which NumPy evaluates (:class:`Trees`): no
learning library is needed to run the planner. The labelled decisions
(:mod:`semsearch_cli.learn`) are recorded with these very features.
"""

from __future__ import annotations

import dataclasses
import json
import math
from functools import lru_cache
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ..base import Decision, register_planner
from .nsos import NSOS, KeepTarget, NSOSParams, pick
from .numbering import NumberingParams, expected_travel, target_terms

MODELS = Path(__file__).resolve().parents[2] / "data" / "models"
TERMS = ("phi_g", "zeta", "gamma", "phi_p", "phi_o", "phi_r", "phi_c", "SF", "GF", "phi")
NUMBERING = ("P_beyond", "E_beyond", "T_expected")  # the numbering model's (docs/numbering.md), at its defaults
BASE = ("d_m", "d_rank", "n_targets", "travelled_m", "signs", *TERMS, *NUMBERING)  # a target's own
RELATIVE = ("d_over_min", "phi_below_max", "SF_below_max", "phi_g_below_max", "T_over_min")  # against the decision's best
FEATURES = (*BASE, *RELATIVE)
_NUMBERING = NumberingParams()  # the numbering model's terms are read at its defaults


def decision_features(ctx, cands, nsos: NSOS) -> tuple[np.ndarray, np.ndarray]:
    """(X (k, len(FEATURES)), d_m (k,)) at a decision: the features of each target (NaN where
    nsos gives none: an unreachable target), and the path to each (m, inf when unreachable).
    nsos's terms come from ``nsos`` run on a copy of the decision with a generator of its own
    (the run's is not drawn from)."""
    own = dataclasses.replace(ctx, rng=np.random.default_rng(0), explain=True)
    dec = nsos._decide(own, cands)
    k = len(cands)
    terms = dec.info["candidates"] if dec is not None else [{} for _ in range(k)]
    d = np.array([t["D_m"] if t.get("D_m") is not None else math.inf for t in terms], float)
    b = ctx.belief
    signs = sum(1 for n in b.reads.total.values() if n >= b.spec.min_reads)
    X = np.full((k, len(FEATURES)), np.nan)
    X[:, 0] = np.where(np.isfinite(d), d, np.nan)
    X[:, 1] = np.argsort(np.argsort(d, kind="stable"), kind="stable")
    X[:, 2] = k
    X[:, 3] = ctx.distance
    X[:, 4] = signs
    for j, t in enumerate(TERMS):
        X[:, 5 + j] = [np.nan if c.get(t) is None else c[t] for c in terms]
    reach = np.isfinite(d)
    P, E = target_terms(ctx, cands, reach, _NUMBERING)
    T = expected_travel(d, P, E, _NUMBERING.horizon)
    j = 5 + len(TERMS)
    X[:, j : j + 3] = np.column_stack([P, E, T])
    X[~reach, j : j + 3] = np.nan
    return add_relative(X), d


def add_relative(X: np.ndarray) -> np.ndarray:
    """Fill one decision's :data:`RELATIVE` columns from its :data:`BASE` ones (in place; also
    how the training script derives them from recorded rows): the path over the shortest, and
    nsos's phi, SF and phi_g below the decision's highest."""
    col = {f: i for i, f in enumerate(FEATURES)}
    with np.errstate(all="ignore"):
        d = X[:, col["d_m"]]
        X[:, col["d_over_min"]] = d - np.nanmin(d) if np.isfinite(d).any() else np.nan
        for rel, base in (("phi_below_max", "phi"), ("SF_below_max", "SF"), ("phi_g_below_max", "phi_g")):
            v = X[:, col[base]]
            X[:, col[rel]] = np.nanmax(v) - v if np.isfinite(v).any() else np.nan
        T = X[:, col["T_expected"]]
        X[:, col["T_over_min"]] = T - np.nanmin(T) if np.isfinite(T).any() else np.nan
    return X


class Trees:
    """Gradient-boosted regression trees as flat arrays (every tree's nodes one after another):
    ``feature``, ``threshold``, ``left``, ``right`` (absolute node indices), ``leaf``,
    ``value``, ``missing_left`` (where a NaN goes), ``roots`` and ``baseline``; the prediction
    of a row is ``baseline`` plus the value of the leaf it reaches in each tree."""

    def __init__(self, doc: dict):
        t = doc["trees"]
        self.feature = np.asarray(t["feature"], np.int64)
        self.threshold = np.asarray(t["threshold"], float)
        self.left = np.asarray(t["left"], np.int64)
        self.right = np.asarray(t["right"], np.int64)
        self.leaf = np.asarray(t["leaf"], bool)
        self.value = np.asarray(t["value"], float)
        self.missing_left = np.asarray(t["missing_left"], bool)
        self.roots = np.asarray(t["roots"], np.int64)
        self.baseline = float(doc["baseline"])
        self.sign = float(doc.get("sign", 1.0))  # the planner takes the least of sign * prediction
        self.features = tuple(doc["features"])
        self.depth = int(doc.get("max_depth", 64))

    def predict(self, X: np.ndarray) -> np.ndarray:
        """(n,) predictions for the rows of ``X`` (n, features): all trees at once, level by level."""
        X = np.asarray(X, float)
        n = X.shape[0]
        node = np.repeat(self.roots[:, None], n, axis=1)  # (trees, rows)
        rows = np.broadcast_to(np.arange(n), node.shape)
        for _ in range(self.depth + 1):
            inner = ~self.leaf[node]
            if not inner.any():
                break
            x = X[rows, self.feature[node]]
            go_left = np.where(np.isnan(x), self.missing_left[node], x <= self.threshold[node])
            node = np.where(inner, np.where(go_left, self.left[node], self.right[node]), node)
        return self.baseline + self.value[node].sum(axis=0)


@lru_cache(maxsize=4)
def load_model(name: str) -> Trees:
    """A shipped model, ``semsearch_cli/data/models/<name>.json``; its features must be this
    module's :data:`FEATURES`, in order."""
    doc = json.loads((MODELS / f"{name}.json").read_text())
    if tuple(doc["features"]) != FEATURES:
        raise ValueError(f"model {name}: its features {doc['features']} are not this planner's {list(FEATURES)}")
    return Trees(doc)


class LearnedParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    model: Literal["learned-doors-v1"] = Field("learned-doors-v1", description="the shipped model (semsearch_cli/data/models/<model>.json)")
    hysteresis: float = Field(0.05, ge=0.0, description="keep the last target while its predicted log(1 + regret) is within this of the best")


@register_planner("learned")
class Learned(KeepTarget):
    """The frontier target of least predicted regret, by gradient-boosted trees trained on labels
    from the known map on floors none of the benchmark's (docs/learning.md). The trees are
    evaluated with NumPy; no learning library is needed to run it."""

    rank = 6
    tuned_on = "doors-train, salt semsearch-train-v1 (training floors disjoint from the benchmark's)"
    Params = LearnedParams

    def __init__(self, params):
        super().__init__(params)
        self._nsos = NSOS(NSOSParams())
        self._trees = load_model(self.params.model)

    def _decide(self, ctx, cands, keep: int | None = None):
        X, d = decision_features(ctx, cands, self._nsos)
        reach = np.isfinite(d)
        if not reach.any():
            return None
        pred = np.where(reach, self._trees.sign * self._trees.predict(X), np.inf)
        j = pick(-pred, np.where(reach, d, np.inf), keep, self.params.hysteresis, ctx.rng)
        return Decision(int(cands.rows[j]), int(cands.cols[j]), {"chosen": j, "predicted": round(float(pred[j]), 4)})
