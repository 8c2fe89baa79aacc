"""The view cone of a pitched camera on a grid (numba): the robot's model of the semantic camera
(see :mod:`semsearch_cli.sensors.indirect` for the geometry, Eqs. 37-40)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def cone_box(H, W, ox, oy, res, x, y, max_range, dz):
    """The bounding box (r0, r1, c0, c1), half-open, of the cells :func:`cone_image` visits."""
    reach = math.sqrt(max(max_range * max_range - dz * dz, 0.0))
    c0 = max(0, int(math.floor((x - reach - ox) / res)))
    c1 = min(W, int(math.ceil((x + reach - ox) / res)) + 1)
    r0 = max(0, int(math.floor(H - (y + reach - oy) / res)))
    r1 = min(H, int(math.ceil(H - (y - reach - oy) / res)) + 1)
    return r0, r1, c0, c1


@njit(cache=True)
def _view_distance(cx, cy, ch, sh, cp, sp, dz, tan_h, tan_v, min_depth, max_range):
    """The camera-to-point distance of the offset (cx, cy) (m, at height offset dz) when the point
    is in view (x_cam > 0, |y_cam| <= tan_h x_cam, |z_cam| <= tan_v x_cam, min_depth <= r <=
    max_range), else -1."""
    xr = ch * cx + sh * cy
    yr = -sh * cx + ch * cy
    xc = cp * xr - sp * dz
    if xc <= 0.0:
        return -1.0
    zc = sp * xr + cp * dz
    if abs(yr) > tan_h * xc or abs(zc) > tan_v * xc:
        return -1.0
    d = math.sqrt(xc * xc + yr * yr + zc * zc)
    if d < min_depth or d > max_range:
        return -1.0
    return d


@njit(cache=True)
def _bracket(lut_d, d):
    """(k, t): ``d`` lies at fraction t between lut_d[k - 1] and lut_d[k], clamped at the ends."""
    n = lut_d.shape[0]
    if d <= lut_d[0]:
        return 1, 0.0
    if d >= lut_d[n - 1]:
        return n - 1, 1.0
    k = 1
    while lut_d[k] < d:
        k += 1
    return k, (d - lut_d[k - 1]) / (lut_d[k] - lut_d[k - 1])


@njit(cache=True)
def _lerp(lo, hi, t):
    return hi if t == 1.0 else lo + t * (hi - lo)


@njit(cache=True)
def cone_image(out, ox, oy, res, x, y, heading, pitch, tan_h, tan_v, min_depth, max_range, dz, lut_d, lut_p):
    """Write into ``out`` (H, W), for every cell whose centre (at height offset ``dz`` from the
    camera) is in view from (x, y, heading), the detection probability interpolated in
    (``lut_d``, ``lut_p``) at its distance; cells out of view are left as they are. In view:
    x_cam > 0, |y_cam| <= tan_h x_cam, |z_cam| <= tan_v x_cam, min_depth <= r <= max_range.
    ``ox, oy`` is the grid's bottom-left corner (m), row 0 at the top. Returns the bounding box
    (r0, r1, c0, c1) of the cells visited (half-open)."""
    H, W = out.shape
    r0, r1, c0, c1 = cone_box(H, W, ox, oy, res, x, y, max_range, dz)
    ch, sh = math.cos(heading), math.sin(heading)
    cp, sp = math.cos(pitch), math.sin(pitch)
    for r in range(r0, r1):
        cy = oy + (H - r - 0.5) * res - y
        for c in range(c0, c1):
            d = _view_distance(ox + (c + 0.5) * res - x, cy, ch, sh, cp, sp, dz, tan_h, tan_v, min_depth, max_range)
            if d < 0.0:
                continue
            k, t = _bracket(lut_d, d)
            out[r, c] = _lerp(lut_p[k - 1], lut_p[k], t)
    return r0, r1, c0, c1


@njit(cache=True)
def cone_mass(p_pad, pad, rows, cols, bins, offs_r, offs_c, counts):
    """Sum of ``p_pad`` over a view-cone template at each pose: pose k at cell (rows[k], cols[k])
    with heading bin bins[k]; the template of bin b is the first counts[b] offsets of
    offs_r[b], offs_c[b]; ``p_pad`` is the map padded by ``pad`` zero cells on each side."""
    n = rows.shape[0]
    out = np.zeros(n)
    for k in range(n):
        b = bins[k]
        r = rows[k] + pad
        c = cols[k] + pad
        s = 0.0
        for j in range(counts[b]):
            s += p_pad[r + offs_r[b, j], c + offs_c[b, j]]
        out[k] = s
    return out


@njit(cache=True)
def cone_nondetect(nd, ox, oy, res, x, y, heading, pitch, tan_h, tan_v, min_depth, max_range, dz, lut_d, lut_p,
                   hidden, hr0, hc0):
    """Multiply ``nd`` (K, H, W), the probability under each of K yaw hypotheses that an object in
    each cell has not been detected yet, by the probability of not detecting it from (x, y,
    heading), for the cells in view (as :func:`cone_image`). Hypothesis k: the object's yaw is
    360 k / K degrees; the table row is the direction from the cell to the camera relative to that
    yaw, the nearest of ``lut_p``'s K rows (each interpolated in ``lut_d``). ``hidden`` (h, w):
    cells (offset by hr0, hc0) the camera cannot see for obstacles; an empty array for none."""
    K, H, W = nd.shape
    r0, r1, c0, c1 = cone_box(H, W, ox, oy, res, x, y, max_range, dz)
    ch, sh = math.cos(heading), math.sin(heading)
    cp, sp = math.cos(pitch), math.sin(pitch)
    step = 2.0 * math.pi / K
    check = hidden.shape[0] > 0
    for r in range(r0, r1):
        cy = oy + (H - r - 0.5) * res - y
        for c in range(c0, c1):
            cx = ox + (c + 0.5) * res - x
            d = _view_distance(cx, cy, ch, sh, cp, sp, dz, tan_h, tan_v, min_depth, max_range)
            if d < 0.0 or (check and hidden[r - hr0, c - hc0]):
                continue
            k, t = _bracket(lut_d, d)
            b = int(math.floor(math.atan2(-cy, -cx) / step + 0.5))  # the bearing from the cell to the camera
            for h in range(K):
                row = (b - h) % K
                nd[h, r, c] *= 1.0 - _lerp(lut_p[row, k - 1], lut_p[row, k], t)
    return r0, r1, c0, c1
