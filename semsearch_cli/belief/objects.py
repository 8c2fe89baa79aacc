"""LSOS heat map and goals (thesis 5.2, Eqs. 5.3-5.6). Pure functions of arrays.

Each recorded detection of the target class adds an inverted kernel (Eq. 5.4)
``IK = W(rh, hour) * Q * d / r`` for cells within Manhattan distance ``d <= r`` of the object,
restricted to a sector of half-angle ``sector`` centred on the direction from the object toward
the robot's pose at that detection (the thesis' "acute angle" kernel: the warmest cells are where
the robot stood and will see the object again); Q is 0 on unknown cells. Goals are the maxima of
the heat summed over a circular window (Eqs. 5.5-5.6), visited in order of that sum.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from .presence import hour_weight


def inverted_kernel(shape, obj_rc, robot_rc, radius: float, weight: float, known: np.ndarray | None = None,
                    sector_deg: float = 45.0, inverted: bool = True) -> np.ndarray:
    """IK of Eq. 5.4 for one detection (with ``inverted=False``, K of Eq. 5.1: ``1 - d / r``).

    Parameters
    ----------
    shape : (H, W)
    obj_rc, robot_rc : (row, col) of the object and of the robot at the detection (cells)
    radius : float, cells (r)
    weight : float, W(rh, hour) of Eq. 5.3
    known : (H, W) bool or None, cells that are not unknown (Q = 1); None means all known
    sector_deg : float, half-angle of the sector toward the robot (180 gives the full disk)

    Returns
    -------
    (H, W) float64
    """
    out = np.zeros(shape)
    _add_kernel(out, obj_rc, robot_rc, radius, weight, known, sector_deg, inverted)
    return out


def _add_kernel(h, obj_rc, robot_rc, radius, weight, known, sector_deg, inverted) -> None:
    """Add one kernel to ``h`` in place, computed only over its (2r + 1)-cell window."""
    H, W = h.shape
    R = int(math.floor(radius))
    r0, r1 = max(0, obj_rc[0] - R), min(H, obj_rc[0] + R + 1)
    c0, c1 = max(0, obj_rc[1] - R), min(W, obj_rc[1] + R + 1)
    if r0 >= r1 or c0 >= c1:
        return
    rr, cc = np.mgrid[r0:r1, c0:c1]
    dr, dc = rr - obj_rc[0], cc - obj_rc[1]
    d = np.abs(dr) + np.abs(dc)
    out = np.where(d <= radius, weight * (d / radius if inverted else 1.0 - d / radius), 0.0)
    if sector_deg < 180.0:
        toward = math.atan2(-(robot_rc[0] - obj_rc[0]), robot_rc[1] - obj_rc[1])
        ang = np.arctan2(-dr, dc)
        diff = np.abs((ang - toward + np.pi) % (2 * np.pi) - np.pi)
        out[(diff > math.radians(sector_deg)) & (d > 0)] = 0.0
    if known is not None:
        out[~known[r0:r1, c0:c1]] = 0.0
    h[r0:r1, c0:c1] += out


def heat_map(detections, target: str | None, request_hour: float, frame, radius_m: float = 1.5,
             known: np.ndarray | None = None, sector_deg: float = 45.0, inverted: bool = True) -> np.ndarray:
    """Sum of inverted kernels over the detections of class ``target`` (None: every class, as in
    the thesis' Figure 5.7 before the class filter; ``inverted=False``: the kernel of Eq. 5.1).

    ``detections``: iterable of (class, x, y, hour, robot_x, robot_y) in metres and hours.
    """
    h = np.zeros((frame.height, frame.width))
    r = radius_m / frame.res
    for cls, x, y, hour, rx, ry in detections:
        if target is not None and cls != target:
            continue
        o = frame.to_index(x, y)
        p = frame.to_index(rx, ry)
        _add_kernel(h, (int(o[0]), int(o[1])), (int(p[0]), int(p[1])), r, float(hour_weight(request_hour, hour)),
                    known, sector_deg, inverted)
    return h


def goal_cells(heat: np.ndarray, window_cells: float, max_goals: int = 20) -> list[tuple[int, int, float]]:
    """Goals (row, col, phi) in order of phi (Eq. 5.6: the heat summed over a disk of radius
    ``window_cells``), each the argmax (Eq. 5.5) once the windows of earlier goals are removed.

    A window as wide as the kernel covers a whole kernel from many centres, so the maximum is a
    plateau; among its cells the goal is the warmest one itself, which with the inverted kernel is
    at the kernel's edge toward where the robot stood (the point of Eq. 5.4), then the first in
    row-major order."""
    R = int(math.ceil(window_cells))
    yy, xx = np.mgrid[-R : R + 1, -R : R + 1]
    disk = ((yy * yy + xx * xx) <= window_cells * window_cells).astype(np.float64)
    phi = cv2.filter2D(heat.astype(np.float64), -1, disk, borderType=cv2.BORDER_CONSTANT)
    phi[heat <= 0] = 0.0  # a goal is a warm cell itself
    # windows of equal heat tie exactly in theory; rounding away the summation-order noise makes
    # the choice among them independent of how the sums were taken
    phi = np.round(phi, 9)
    warm = np.round(heat, 12)
    out = []
    for _ in range(max_goals):
        best = phi.max()
        if best <= 1e-12:
            break
        k = int(np.argmax(np.where(phi == best, warm, -np.inf)))
        r, c = divmod(k, phi.shape[1])
        out.append((r, c, float(phi[r, c])))
        sup = 2 * R
        phi[max(0, r - sup) : r + sup + 1, max(0, c - sup) : c + sup + 1] = 0.0
    return out
