"""Harmonic potential (boundary value problem, thesis Eqs. 2.7-2.9; Prestes et al. 2002).

We solve for the *attraction* ``u = 1 - p``: ``u = 1`` on goal cells, ``u = 0`` on walls, unknown
cells and the window border, and the discrete Laplace equation (each free cell the mean of its four
neighbours) elsewhere, with one sparse direct solve (SciPy SuperLU). Working with ``u`` rather than
the potential ``p`` keeps the tiny values far from the goals representable; where even ``u`` falls
below ~1e-13 of the goal value the gradient is numerical noise and callers fall back to geodesic
distance (the thesis' implementation has the same limit and relaxes over local windows).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.sparse import csr_matrix
from scipy.sparse.linalg import spsolve

FLAT = 1e-13


def harmonic_field(passable: np.ndarray, goals: np.ndarray) -> np.ndarray:
    """Solve the Laplace equation on ``passable`` with ``u = 1`` on ``goals``.

    Parameters
    ----------
    passable : (h, w) bool
        Cells where the potential is free to vary (goal cells may or may not be included).
    goals : (h, w) bool
        Attracting cells (u = 1).

    Returns
    -------
    u : (h, w) float64
        1 on goals, 0 on non-passable cells, harmonic in between.
    """
    h, w = passable.shape
    inner = passable & ~goals
    inner[0, :] = inner[-1, :] = False
    inner[:, 0] = inner[:, -1] = False
    u = np.zeros((h, w))
    u[goals] = 1.0
    n = int(inner.sum())
    if n == 0:
        return u
    idx = np.full((h, w), -1, np.int64)
    rr, cc = np.nonzero(inner)
    idx[rr, cc] = np.arange(n)
    rows, cols, vals = [np.arange(n)], [np.arange(n)], [np.full(n, 4.0)]
    b = np.zeros(n)
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        nr, nc = rr + dr, cc + dc
        j = idx[nr, nc]
        m = j >= 0
        rows.append(np.nonzero(m)[0])
        cols.append(j[m])
        vals.append(np.full(int(m.sum()), -1.0))
        b += goals[nr, nc]
    A = csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    u[rr, cc] = np.maximum(spsolve(A, b), 0.0)
    return u


@njit(cache=True)
def ascend(u, r, c, max_steps):
    """Steepest ascent of ``u`` over 8-neighbours from (r, c) until a cell with u >= 1.

    Returns the visited cells (rows, cols); ``ok`` is False when the ascent stalls (flat or noisy
    field) before reaching a goal.
    """
    h, w = u.shape
    rows = np.empty(max_steps + 1, np.int64)
    cols = np.empty(max_steps + 1, np.int64)
    rows[0] = r
    cols[0] = c
    n = 1
    while n <= max_steps:
        if u[r, c] >= 1.0:
            return rows[:n], cols[:n], True
        best = u[r, c]
        br = -1
        bc = -1
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                if dr == 0 and dc == 0:
                    continue
                nr = r + dr
                nc = c + dc
                if nr < 0 or nr >= h or nc < 0 or nc >= w:
                    continue
                if dr != 0 and dc != 0 and (u[r, nc] <= 0.0 or u[nr, c] <= 0.0):
                    continue
                if u[nr, nc] > best:
                    best = u[nr, nc]
                    br = nr
                    bc = nc
        if br < 0 or best < FLAT:
            return rows[:n], cols[:n], False
        r = br
        c = bc
        rows[n] = r
        cols[n] = c
        n += 1
    return rows[:n], cols[:n], False
