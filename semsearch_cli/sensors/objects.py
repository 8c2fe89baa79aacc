"""The object camera: a forward camera with a field of view and range per object class,
line of sight against walls, and a detection probability per frame that is a constant or a table
by distance and view angle (Loncomilla et al. 2018, Table 1)."""

from __future__ import annotations

import numpy as np

from ..config import ObjectCameraSpec
from ..geometry import wrap_angle
from ..kernels.raycast import line_of_sight


def detect_probability(p, distance: float, view_deg: float) -> float:
    """p_detect of the camera spec: a constant, or a :class:`~semsearch_cli.config.DetectTable`
    read at ``distance`` (m, linear, clamped) and ``view_deg`` (nearest tabulated angle)."""
    if isinstance(p, (int, float)):
        return float(p)
    row = 0
    if p.angles:
        a = np.asarray(p.angles, float)
        diff = np.abs((a - view_deg + 180.0) % 360.0 - 180.0)
        row = int(np.argmin(diff))
    return float(np.interp(distance, p.distances, p.p[row]))


class ObjectCamera:
    """Forward camera over fixed points: those within ``range`` (m) and ``fov`` (degrees) around
    the heading, in line of sight."""

    def __init__(self, world, fov: float, range_m: float, xs, ys):
        self.world, self.range = world, range_m
        self.x, self.y = np.asarray(xs, float), np.asarray(ys, float)
        self.v, self.u = world.frame.to_cell(self.x, self.y)
        self.half = np.radians(fov) / 2

    def visible(self, x: float, y: float, heading: float) -> np.ndarray:
        """Indices of the points in view from pose (x, y, heading)."""
        if self.x.size == 0:
            return np.zeros(0, np.int64)
        dx, dy = self.x - x, self.y - y
        near = np.flatnonzero(dx * dx + dy * dy <= self.range**2)
        if near.size and self.half < np.pi:
            rel = np.abs(wrap_angle(np.arctan2(dy[near], dx[near]) - heading))
            near = near[rel <= self.half]
        v, u = self.world.frame.to_cell(x, y)
        occ = self.world.occ
        return np.array([i for i in near if line_of_sight(occ, float(v), float(u), self.v[i], self.u[i], 0.5)], np.int64)


class PlaceCamera:
    """The object camera watching the places where objects stand.

    The camera looks at the places with the widest field of view and longest range of any class;
    each object instance standing at a place in view is then checked against its own class's
    field of view and range, and detected with its class's probability. ``look`` returns the
    places in view (whether or not anything stood there) and the instances detected.
    """

    def __init__(self, world, spec: ObjectCameraSpec, places: dict, facing: dict, instances):
        """``places`` name -> (x, y) m; ``facing`` name -> radians; ``instances`` [(class, place)]."""
        self.names = list(places)
        self.places, self.facing = places, facing
        self.camera = ObjectCamera(world, spec.max_fov, spec.max_range, [places[n][0] for n in self.names],
                                   [places[n][1] for n in self.names])
        self.at_place = [[i for i, (_, p) in enumerate(instances) if p == n] for n in self.names]
        self.cam = [spec.for_class(cls) for cls, _ in instances]  # (fov, range, p_detect) per instance
        self.uniform = all(c == (spec.max_fov, spec.max_range, spec.p_detect) and isinstance(c[2], float) for c in self.cam)

    def look(self, x: float, y: float, heading: float, rng: np.random.Generator) -> tuple[list[str], list[int]]:
        """(names of the places in view, indices of the instances detected) from one frame."""
        seen, detected = [], []
        for k in self.camera.visible(x, y, heading):
            name = self.names[k]
            seen.append(name)
            for i in self.at_place[k]:
                fov, rng_m, p = self.cam[i]
                if not self.uniform:
                    px, py = self.places[name]
                    d = float(np.hypot(px - x, py - y))
                    bearing = float(np.arctan2(py - y, px - x))
                    if d > rng_m or abs(float(wrap_angle(bearing - heading))) > np.radians(fov) / 2:
                        continue
                    view = float(np.degrees(bearing + np.pi - self.facing[name])) % 360.0
                    p = detect_probability(p, d, view)
                if rng.random() < p:
                    detected.append(i)
        return seen, detected
