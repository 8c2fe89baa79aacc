"""Laser and door cameras over the ground-truth world; the kernels are in raycast.py."""

from __future__ import annotations

import math

import numpy as np

from ..config import DoorCameraSpec, LaserSpec
from ..geometry import wrap_angle
from ..world.ground_truth import World
from ..kernels.raycast import cast_rays, facing_within, line_of_sight


class Laser:
    """180-degree (default) laser ahead of the robot, ray-cast against the ground truth."""

    def __init__(self, world: World, spec: LaserSpec):
        self.world, self.spec = world, spec
        half = np.radians(spec.fov) / 2
        self.offsets = np.linspace(-half, half, spec.beams)
        self.max_cells = spec.range / world.frame.res

    def scan(self, v: float, u: float, heading: float, rng: np.random.Generator):
        """Beam angles (rad), ranges (cells) and hit flags from continuous cell position (v, u)."""
        thetas = heading + self.offsets
        dist, hit = cast_rays(self.world.occ, v, u, thetas, self.max_cells)
        if self.spec.noise_std > 0:
            noise = rng.normal(0.0, self.spec.noise_std / self.world.frame.res, dist.shape)
            dist = np.clip(dist + noise, 0.0, self.max_cells)
        return thetas, dist, hit


class DoorCamera:
    """Left and right side cameras with the recognition step of the seeds' door simulator.

    A sign is visible to a camera when it lies within the camera's field of view (centred on
    +-90 degrees from the heading) and range, in line of sight, and its face points toward the
    robot. Each visible sign is read with probability ``p_read``; with ``p_misread`` one digit of
    a read number is replaced by another (the reported number may then match no sign).
    """

    def __init__(self, world: World, spec: DoorCameraSpec):
        self.world, self.spec = world, spec
        s = world.signs
        self.sx, self.sy = s.x, s.y
        self.fx, self.fy = np.cos(s.facing), np.sin(s.facing)
        self.sv, self.su = world.frame.to_cell(s.x, s.y)
        self.half = np.radians(spec.fov) / 2

    def bearing(self, i: int, x: float, y: float) -> float:
        """The direction (radians, counter-clockwise from +x) from (x, y) to sign ``i``: where in
        its image a camera sees the sign."""
        return math.atan2(self.sy[i] - y, self.sx[i] - x)

    def read(self, x: float, y: float, heading: float, rng: np.random.Generator) -> list[tuple[int, object]]:
        """Signs read from pose (x, y, heading): list of (sign index, label as read)."""
        near = facing_within(self.sx, self.sy, self.fx, self.fy, x, y, self.spec.range**2)
        if near.size == 0:
            return []
        rel = np.abs(np.abs(wrap_angle(np.arctan2(self.sy[near] - y, self.sx[near] - x) - heading)) - np.pi / 2)
        near = near[rel <= self.half]
        out = []
        v, u = self.world.frame.to_cell(x, y)
        for i in near:
            if not line_of_sight(self.world.occ, float(v), float(u), self.sv[i], self.su[i], 0.75):
                continue
            if rng.random() >= self.spec.p_read:
                continue
            label = self.world.signs.number[i]
            if self.spec.p_misread > 0 and isinstance(label, int) and rng.random() < self.spec.p_misread:
                digits = list(str(label))
                k = int(rng.integers(len(digits)))
                digits[k] = str((int(digits[k]) + 1 + int(rng.integers(9))) % 10)
                label = int("".join(digits))
            out.append((int(i), label))
        return out
