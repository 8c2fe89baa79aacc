"""Pure ray-casting kernels on occupancy grids (numba).

Coordinates are continuous cell coordinates ``(v, u) = (row, col)``: cell (r, c) covers
``[r, r+1) x [c, c+1)``, so a cell centre is at (r + .5, c + .5). A direction ``theta`` (radians,
world frame, x right, y up) moves by ``(dv, du) = (-sin theta, cos theta)``. Distances are in cells.
Traversal is exact (Amanatides and Woo 1987): every cell the ray passes through is visited once.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_INF = 1e30


@njit(cache=True, inline="always")
def _setup(v0, u0, dv, du):
    r = int(math.floor(v0))
    c = int(math.floor(u0))
    if dv > 0:
        sr, tmr, tdr = 1, (r + 1 - v0) / dv, 1.0 / dv
    elif dv < 0:
        sr, tmr, tdr = -1, (r - v0) / dv, -1.0 / dv
    else:
        sr, tmr, tdr = 0, _INF, _INF
    if du > 0:
        sc, tmc, tdc = 1, (c + 1 - u0) / du, 1.0 / du
    elif du < 0:
        sc, tmc, tdc = -1, (c - u0) / du, -1.0 / du
    else:
        sc, tmc, tdc = 0, _INF, _INF
    return r, c, sr, sc, tmr, tmc, tdr, tdc


@njit(cache=True)
def cast_ray(occ, v0, u0, theta, max_cells):
    """Distance (cells) from (v0, u0) along ``theta`` to the first occupied cell.

    Parameters
    ----------
    occ : (H, W) bool
        True where a cell blocks the beam. Leaving the grid counts as a miss.
    v0, u0 : float
        Start, continuous cell coordinates (row, col).
    theta : float
        Beam direction, radians, world frame.
    max_cells : float
        Maximum range, cells.

    Returns
    -------
    dist : float
        Distance to the entry point of the first occupied cell, or ``max_cells`` on a miss.
    hit : bool
        Whether an occupied cell was met within range.
    """
    H, W = occ.shape
    dv = -math.sin(theta)
    du = math.cos(theta)
    r, c, sr, sc, tmr, tmc, tdr, tdc = _setup(v0, u0, dv, du)
    t = 0.0
    while t <= max_cells:
        if r < 0 or r >= H or c < 0 or c >= W:
            return max_cells, False
        if occ[r, c]:
            return t, True
        if tmr < tmc:
            t = tmr
            tmr += tdr
            r += sr
        else:
            t = tmc
            tmc += tdc
            c += sc
    return max_cells, False


@njit(cache=True)
def cast_rays(occ, v0, u0, thetas, max_cells):
    """:func:`cast_ray` for each beam angle; returns (dist (n,) float64, hit (n,) bool)."""
    n = thetas.shape[0]
    dist = np.empty(n)
    hit = np.zeros(n, np.bool_)
    for i in range(n):
        dist[i], hit[i] = cast_ray(occ, v0, u0, thetas[i], max_cells)
    return dist, hit


@njit(cache=True)
def himm_update(cv, seen, v0, u0, thetas, dist, hit, inc, dec, cv_max, free, occupied, touched):
    """Histogramic in-motion mapping update (Borenstein and Koren 1991) for one scan.

    Cells a beam passes through before its end lose ``dec`` certainty (not below 0); the cell at
    the end of a beam that hit something gains ``inc`` (not above ``cv_max``). Every touched cell
    becomes ``seen``. The growth-rate operator of the original paper is not applied (the seeds'
    simulations have noise-free odometry, where it only thickens walls).

    Parameters
    ----------
    cv : (H, W) uint8
        Certainty values, modified in place.
    seen : (H, W) bool
        Cells observed at least once, modified in place.
    v0, u0 : float
        Sensor position, continuous cell coordinates.
    thetas, dist, hit : (n,) float64, (n,) float64, (n,) bool
        Beam angles (radians), measured ranges (cells), hit flags.
    inc, dec, cv_max : int
        HIMM increment, decrement and cap.
    free : (H, W) bool, occupied : int
        The free map (``seen & (cv < occupied)``, read only here; see :func:`fold_free`).
    touched : (m,) int64
        Receives the flat index ``r * W + c`` of each touched cell whose free state differs from
        ``free`` just after the touch (a cell may appear more than once); every cell whose free
        state differs from ``free`` after the scan is among them.

    Returns
    -------
    int
        How many such touches there were; when more than ``m``, only the first ``m`` were
        written (the caller then refreshes ``free`` over the scan's whole box instead).
    """
    H, W = cv.shape
    n = 0
    m = touched.shape[0]
    for i in range(thetas.shape[0]):
        dv = -math.sin(thetas[i])
        du = math.cos(thetas[i])
        R = dist[i]
        hr = -1
        hc = -1
        if hit[i]:
            hr = int(math.floor(v0 + (R + 1e-6) * dv))
            hc = int(math.floor(u0 + (R + 1e-6) * du))
        r, c, sr, sc, tmr, tmc, tdr, tdc = _setup(v0, u0, dv, du)
        t = 0.0
        while t < R - 1e-9:
            if r < 0 or r >= H or c < 0 or c >= W:
                break
            if not (r == hr and c == hc):
                x = int(cv[r, c]) - dec
                cv[r, c] = 0 if x < 0 else x
                seen[r, c] = True
                if (cv[r, c] < occupied) != free[r, c]:
                    if n < m:
                        touched[n] = r * W + c
                    n += 1
            if tmr < tmc:
                t = tmr
                tmr += tdr
                r += sr
            else:
                t = tmc
                tmc += tdc
                c += sc
        if hr >= 0 and hr < H and hc >= 0 and hc < W:
            x = int(cv[hr, hc]) + inc
            cv[hr, hc] = cv_max if x > cv_max else x
            seen[hr, hc] = True
            if (cv[hr, hc] < occupied) != free[hr, hc]:
                if n < m:
                    touched[n] = hr * W + hc
                n += 1
    return n


@njit(cache=True)
def fold_free(free, seen, cv, occupied, cells, n, dirty):
    """Re-derive ``free = seen & (cv < occupied)`` at the first ``n`` flat indices of ``cells``
    and grow ``dirty`` ``[rmin, rmax, cmin, cmax]`` (in place) by the cells whose state changed.
    Returns how many cells stopped being free."""
    W = free.shape[1]
    ff = free.ravel()
    sf = seen.ravel()
    cf = cv.ravel()
    lost = 0
    for k in range(n):
        q = cells[k]
        new = sf[q] and cf[q] < occupied
        if new != ff[q]:
            lost += ff[q]
            ff[q] = new
            r = q // W
            c = q - r * W
            if r < dirty[0]:
                dirty[0] = r
            if r > dirty[1]:
                dirty[1] = r
            if c < dirty[2]:
                dirty[2] = c
            if c > dirty[3]:
                dirty[3] = c
    return lost


@njit(cache=True)
def facing_within(sx, sy, fx, fy, x, y, range2):
    """Indices (ascending) of the signs at (sx, sy), facing along the unit vectors (fx, fy), that
    lie within ``sqrt(range2)`` of (x, y) (all in m) and face it (the point lies on the side the
    sign's face points to)."""
    out = np.empty(sx.shape[0], np.int64)
    n = 0
    for i in range(sx.shape[0]):
        dx = sx[i] - x
        dy = sy[i] - y
        if dx * dx + dy * dy <= range2 and dx * fx[i] + dy * fy[i] < 0:
            out[n] = i
            n += 1
    return out[:n]


@njit(cache=True)
def line_of_sight(occ, v0, u0, v1, u1, stop_short):
    """True when no occupied cell lies on the segment (v0, u0) -> (v1, u1).

    The last ``stop_short`` cells of length are not checked, so a target lying on a wall face
    (a door sign) is visible from the free side.
    """
    dv = v1 - v0
    du = u1 - u0
    L = math.sqrt(dv * dv + du * du)
    if L <= stop_short:
        return True
    theta = math.atan2(-dv, du)
    d, h = cast_ray(occ, v0, u0, theta, L - stop_short)
    return not h


@njit(cache=True)
def mark_viewed(free, viewed, stamp, first, views, half_fov, max_cells):
    """Count, for each view, the last free cell before the first cell that is not free along
    every ray of two side cameras: ``viewed`` (H, W) uint8 (saturating) is incremented in place,
    once per view and cell (``stamp`` (H, W) int64 holds the last view that counted, views being
    numbered from ``first``). A row of ``views`` stands for ``times`` views from one pose, one after
    the other: each cell it sees is incremented ``times`` (saturating), as that many rows would.

    Parameters
    ----------
    free : (H, W) bool
        Cells the camera sees through (a ray stops at the first other cell or at the grid's edge).
    views : (n, 4) float64
        Camera poses ``(v, u, heading, times)``: continuous cell coordinates, radians and how many
        views in a row were taken from that pose; the cameras look along ``heading +- pi/2``, each
        over ``+-half_fov``.
    max_cells : float
        Camera range, cells. Rays are spaced so that neighbouring rays are at most half a cell
        apart at that range.
    """
    H, W = free.shape
    n_side = int(math.ceil(2.0 * half_fov * max_cells / 0.5)) + 1
    step = 2.0 * half_fov / max(1, n_side - 1)
    vid = first - 1
    for k in range(views.shape[0]):
        v0, u0, heading, times = views[k, 0], views[k, 1], views[k, 2], int(views[k, 3])
        vid += times  # the last of the row's views: a number no other row has
        for side in (-1.0, 1.0):
            centre = heading + side * 0.5 * math.pi
            for j in range(n_side):
                theta = centre - half_fov + j * step
                dv = -math.sin(theta)
                du = math.cos(theta)
                r, c, sr, sc, tmr, tmc, tdr, tdc = _setup(v0, u0, dv, du)
                pr, pc = r, c
                t = 0.0
                while t <= max_cells:
                    if r < 0 or r >= H or c < 0 or c >= W:
                        break
                    if not free[r, c]:
                        if t > 0.0 and stamp[pr, pc] != vid:
                            stamp[pr, pc] = vid
                            viewed[pr, pc] = min(255, int(viewed[pr, pc]) + times)
                        break
                    pr, pc = r, c
                    if tmr < tmc:
                        t = tmr
                        tmr += tdr
                        r += sr
                    else:
                        t = tmc
                        tmc += tdc
                        c += sc
