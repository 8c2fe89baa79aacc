"""How predictable a floor's numbers are from where its signs are: the per-floor statistic the
numbering ablation is read against (docs/bench.md, "Predictability").

Signs are grouped into **walls**: signs that face the same way (within ``FACING_TOL`` degrees)
and lie on one line (their offsets along the facing direction within ``LINE_TOL`` m), ordered
along it. Only labels with a number count, and only signs of one prefix (a wing, a floor) are
compared with each other.

- **order** (``P_order``): along each wall, an interior sign's number is predicted by the mean of
  its two neighbours' numbers; ``P_order = 1 - E_true / E_shuffled``, where ``E`` is the mean
  absolute error of that prediction over every interior sign of the floor, on the floor's labels
  (true) and on its labels shuffled among its signs (the mean over ``SHUFFLES`` seeded
  shuffles). 1: every number lies midway between its neighbours' (numbers rise or fall steadily
  along each wall); 0: the neighbours predict it no better than chance; below 0, worse.
- **parity** (``P_parity``): the share of each wall's signs that carry its majority parity,
  averaged over the walls (weighted by their signs), rescaled so that the shuffled floor's share
  is 0 and one parity per wall is 1: ``(m_true - m_shuffled) / (1 - m_shuffled)``.
- **predictability**: the mean of the two.

A wall's neighbours may straddle a junction or a numbering seam; the statistic counts that error
like any other, as a planner that reasons along the wall would meet it.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from ..world.labels import parse_label

FACING_TOL = 10.0  # degrees
LINE_TOL = 0.5  # m
SHUFFLES = 50


@dataclass(frozen=True)
class Predictability:
    order: float
    parity: float
    walls: int  # walls with at least two numbered signs
    signs: int  # numbered signs on them

    @property
    def value(self) -> float:
        return 0.5 * (self.order + self.parity)


def walls(x, y, facing) -> list[np.ndarray]:
    """The walls (see the module docstring) as arrays of sign indices, each ordered along its line."""
    x, y, f = (np.asarray(v, float) for v in (x, y, facing))
    out = []
    left = np.ones(len(x), bool)
    while left.any():
        i = int(np.flatnonzero(left)[0])
        d = np.abs((f - f[i] + 180.0) % 360.0 - 180.0)
        t = np.radians(f[i])
        u = np.array([np.cos(t), np.sin(t)])  # the facing direction: the wall's normal
        off = (x - x[i]) * u[0] + (y - y[i]) * u[1]
        mine = left & (d <= FACING_TOL) & (np.abs(off) <= LINE_TOL)
        idx = np.flatnonzero(mine)
        along = -x[idx] * u[1] + y[idx] * u[0]
        out.append(idx[np.argsort(along, kind="stable")])
        left &= ~mine
    return out


def _errors(numbers: np.ndarray, prefixes: np.ndarray, lines: list[np.ndarray]) -> tuple[float, float, int]:
    """(mean interpolation error, mean majority-parity share, interior signs) of one labelling."""
    err, n_err, share, n_share = 0.0, 0, 0.0, 0
    for w in lines:
        for grp in np.unique(prefixes[w]):
            s = w[prefixes[w] == grp]
            if len(s) < 2:
                continue
            v = numbers[s]
            odd = int((v % 2).sum())
            share += max(odd, len(v) - odd)
            n_share += len(v)
            if len(v) >= 3:
                e = np.abs(v[1:-1] - 0.5 * (v[:-2] + v[2:]))
                err += float(e.sum())
                n_err += len(e)
    return (err / n_err if n_err else np.nan), (share / n_share if n_share else np.nan), n_err


def _mean(values) -> float:
    """The mean of the finite values, NaN when there is none."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return float(v.mean()) if len(v) else np.nan


def predictability(labels, x, y, facing, seed: str = "") -> Predictability:
    """The statistic of one floor: its signs' ``labels`` at (``x``, ``y``) m facing ``facing``
    degrees (as a doors file gives them); ``seed`` (text) seeds the shuffles."""
    parsed = [parse_label(a) for a in labels]
    keep = np.array([p is not None for p in parsed])
    idx = np.flatnonzero(keep)
    numbers = np.array([parsed[i].number for i in idx], float)
    prefixes = np.array([parsed[i].prefix for i in idx], object)
    lines = [w for w in walls(np.asarray(x, float)[idx], np.asarray(y, float)[idx], np.asarray(facing, float)[idx])]
    e_true, m_true, _ = _errors(numbers, prefixes, lines)
    words = np.frombuffer(hashlib.sha256(f"predictability/{seed}".encode()).digest()[:16], "<u4")
    rng = np.random.default_rng([int(w) for w in words])
    es, ms = [], []
    for _ in range(SHUFFLES):
        k = rng.permutation(len(numbers))
        e, m, _ = _errors(numbers[k], prefixes[k], lines)
        es.append(e)
        ms.append(m)
    e_sh, m_sh = _mean(es), _mean(ms)
    order = 1.0 - e_true / e_sh if e_sh and np.isfinite(e_sh) and e_sh > 0 else np.nan
    parity = (m_true - m_sh) / (1.0 - m_sh) if np.isfinite(m_sh) and m_sh < 1.0 else np.nan
    counted = [w for w in lines if len(w) >= 2]
    return Predictability(float(order), float(parity), len(counted), int(sum(len(w) for w in counted)))
