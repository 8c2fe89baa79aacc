"""Motion: perfect odometry; the robot advances a fixed step along its path."""

from __future__ import annotations

import numpy as np


def advance(px, py, i: int, x: float, y: float, heading: float, step: float):
    """Move up to ``step`` metres from (x, y) along the waypoints ``px, py`` starting at index
    ``i``; the heading follows the segment being travelled. Returns (x, y, i, heading, moved)."""
    remaining = step
    moved = 0.0
    while remaining > 1e-12 and i < len(px):
        dx, dy = px[i] - x, py[i] - y
        d = float(np.hypot(dx, dy))
        if d <= remaining:
            x, y = float(px[i]), float(py[i])
            i += 1
            remaining -= d
            moved += d
        else:
            x += dx / d * remaining
            y += dy / d * remaining
            moved += remaining
            remaining = 0.0
        if d > 1e-9:
            heading = float(np.arctan2(dy, dx))
    return x, y, i, heading, moved
