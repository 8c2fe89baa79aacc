"""Poses, world <-> cell conversion and angle helpers.

Conventions: world coordinates are metres with x to the right and y up; grids are indexed
``[row, col] = [y, x]`` with row 0 at the top of the image (the largest y). A cell (r, c) covers
``x in [x0 + c*res, x0 + (c+1)*res)`` and ``y in [y_top - (r+1)*res, y_top - r*res)``.
Angles are radians in code and degrees in files.
"""

from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np


def wrap_angle(a):
    """Wrap an angle (radians, scalar or array) to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


@dataclass(frozen=True)
class GridFrame:
    """Placement of an (H, W) grid in the world.

    Parameters
    ----------
    res : float
        Cell size, m/cell.
    origin_x, origin_y : float
        World coordinates (m) of the bottom-left corner of the grid.
    height, width : int
        Grid size in cells.
    """

    res: float
    origin_x: float
    origin_y: float
    height: int
    width: int

    def to_cell(self, x, y):
        """World (m) -> continuous cell coordinates (row, col); cell centres at .5."""
        col = (np.asarray(x, float) - self.origin_x) / self.res
        row = self.height - (np.asarray(y, float) - self.origin_y) / self.res
        return row, col

    def point_to_cell(self, x: float, y: float) -> tuple[float, float, int, int]:
        """:meth:`to_cell` and :meth:`to_index` of one point, in plain floats and ints (the same
        arithmetic, without NumPy's per-call cost): (row, col, integer row, integer col)."""
        col = (float(x) - self.origin_x) / self.res
        row = self.height - (float(y) - self.origin_y) / self.res
        return row, col, math.floor(row), math.floor(col)

    def to_index(self, x, y):
        """World (m) -> integer (row, col) of the containing cell."""
        r, c = self.to_cell(x, y)
        return np.floor(r).astype(np.int64), np.floor(c).astype(np.int64)

    def to_world(self, row, col):
        """Integer cell (row, col) -> world coordinates (m) of its centre."""
        x = self.origin_x + (np.asarray(col, float) + 0.5) * self.res
        y = self.origin_y + (self.height - np.asarray(row, float) - 0.5) * self.res
        return x, y
