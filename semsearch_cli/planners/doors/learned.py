"""What a learned door planner reads and how it evaluates its model (docs/learning.md): the
features of each frontier target at a decision (:func:`decision_features`: its path length and
rank, the targets, the metres travelled and signs counted, nsos's terms, and the path and nsos's
phi, SF and phi_g against the decision's best), and gradient-boosted regression trees evaluated
with NumPy (:class:`Trees`; ``scripts/train_learned.py`` fits them with scikit-learn and writes
them as arrays). The labelled decisions (:mod:`semsearch_cli.learn`) are recorded with these very
features.

No learned planner is registered yet: the first models, trained on up to 57 training floors,
picked targets no better than greedy's (docs/learning.md has the numbers); one will be, with its
model shipped beside it, when it does better on floors it never saw.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from .nsos import NSOS

MODELS = Path(__file__).resolve().parents[2] / "data" / "models"
TERMS = ("phi_g", "zeta", "gamma", "phi_p", "phi_o", "phi_r", "phi_c", "SF", "GF", "phi")
BASE = ("d_m", "d_rank", "n_targets", "travelled_m", "signs", *TERMS)  # a target's own
RELATIVE = ("d_over_min", "phi_below_max", "SF_below_max", "phi_g_below_max")  # against the decision's best
FEATURES = (*BASE, *RELATIVE)


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
