"""The semantic camera of indirect search (Loncomilla et al. 2018, Section 4.2-4.3; SPEC 7).

Ground truth (:meth:`SemanticCamera.frame`): an object's centre is taken into the camera frame by
Eq. 37 (robot yaw, then the camera's pitch; ours: ``pitch`` degrees down, since the paper gives
none), and is in view when its distance r_d (Eq. 38) lies in [min_depth, range], its horizontal
angle theta_d (Eq. 39) within hfov / 2 and its vertical angle phi_d (Eq. 40) within vfov / 2, and
no obstacle box stands on the line from the robot to it. Objects in view occlude each other as
spheres (Algorithm 4): when the angular distance of two centres is at most the sum of their
angular radii ``atan2(rho / 2, x_cam)``, the farther one is not detected. (Algorithm 4 prints
``atan2(rho, x)`` with rho the diameter, which is the angular diameter; two projected discs meet
when the centres are nearer than the sum of the radii, so we halve it.) Each object left is then
detected with the probability of the look-up table (Table 1's axes; ours unless the scenario gives
its own): the yaw bin is the direction from the object to the camera relative to the object's
yaw, the nearest of the eight; the distance is interpolated linearly between the table's columns
and clamped at its ends.

The robot's model (:meth:`SemanticCamera.detect_image`): per map cell, the probability that an
object of a class standing there (at the objects' height) would be detected from a pose: the same
view test, line of sight on the obstacle map, and the table's mean over the eight yaws (the robot
does not know the yaw of an object it has not seen), without occlusion by other objects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config.indirect import LUT_DISTANCES, LUT_YAWS, SemanticCameraSpec
from ..geometry import GridFrame, wrap_angle
from ..kernels.raycast import cast_rays


@dataclass(frozen=True)
class Seen:
    """One object in view at one frame: its class, camera-frame angles (rad), distance (m) and
    its detection probability."""

    cls: str
    r: float
    theta: float
    phi: float
    x_cam: float
    p: float


class SemanticCamera:
    def __init__(self, spec: SemanticCameraSpec, object_height: float = 0.5):
        self.spec = spec
        self.half_h = math.radians(spec.hfov) / 2
        self.half_v = math.radians(spec.vfov) / 2
        self.pitch = math.radians(spec.pitch)
        self.object_height = object_height
        self._lut: dict[str, np.ndarray] = {}

    # ---- the look-up table ------------------------------------------------------------------
    def table(self, cls: str) -> np.ndarray:
        """(8, 5) detection probabilities (0-1): rows yaw 0..315, columns 0.8..2.5 m."""
        if cls not in self._lut:
            self._lut[cls] = np.asarray(self.spec.lut(cls), float) / 100.0
        return self._lut[cls]

    def probability(self, cls: str, r: float, seen_yaw_deg: float) -> float:
        """Detection probability of ``cls`` at distance ``r`` (m) seen at yaw ``seen_yaw_deg``."""
        row = int(round((seen_yaw_deg % 360.0) / 45.0)) % len(LUT_YAWS)
        return float(np.interp(r, LUT_DISTANCES, self.table(cls)[row]))

    def mean_probability(self, cls: str, r: np.ndarray) -> np.ndarray:
        """The table's mean over the eight yaws, at distances ``r`` (m)."""
        return np.interp(r, LUT_DISTANCES, self.table(cls).mean(axis=0))

    # ---- geometry ---------------------------------------------------------------------------
    def to_camera(self, dx, dy, dz, heading: float):
        """Eq. 37: world offsets from the camera (m) -> camera frame (x forward, y right, z up)."""
        c, s = math.cos(heading), math.sin(heading)
        xr, yr = c * dx + s * dy, -s * dx + c * dy  # robot frame: x forward, y left
        cp, sp = math.cos(self.pitch), math.sin(self.pitch)
        return cp * xr - sp * dz, -yr, sp * xr + cp * dz

    def in_view(self, r, theta, phi, x_cam, max_range):
        """Eqs. 38-40 against the field of view and the depth limits."""
        return ((x_cam > 0) & (r >= self.spec.min_depth) & (r <= max_range)
                & (np.abs(theta) <= self.half_h) & (np.abs(phi) <= self.half_v))

    # ---- ground truth -----------------------------------------------------------------------
    def visible(self, room, x: float, y: float, heading: float, ranges: dict[str, float]) -> list[Seen]:
        """The objects in view from pose (x, y, heading), after obstacles and occlusion
        (Algorithm 4), each with its detection probability."""
        z = self.spec.height
        seen = []
        for cls, t in room.objects.items():
            xc, yc, zc = self.to_camera(t.x - x, t.y - y, t.height - z, heading)
            r = math.sqrt(xc * xc + yc * yc + zc * zc)
            theta, phi = math.atan2(yc, xc), math.atan2(zc, xc)
            if not self.in_view(r, theta, phi, xc, ranges.get(cls, self.spec.secondary_range)):
                continue
            if room.obstacles and _segment_blocked(room.obstacles, x, y, t.x, t.y):
                continue
            seen_yaw = math.degrees(math.atan2(y - t.y, x - t.x)) - t.yaw
            seen.append(Seen(cls, r, theta, phi, xc, self.probability(cls, r, seen_yaw)))
        return self.occlude(seen)

    def occlude(self, seen: list[Seen]) -> list[Seen]:
        """Algorithm 4: of two objects whose projected spheres overlap, the farther is hidden."""
        hidden = set()
        for i in range(len(seen)):
            for j in range(i + 1, len(seen)):
                a, b = seen[i], seen[j]
                ang_a = math.atan2(self.spec.diameters.get(a.cls, 0.3) / 2, a.x_cam)
                ang_b = math.atan2(self.spec.diameters.get(b.cls, 0.3) / 2, b.x_cam)
                if math.hypot(b.theta - a.theta, a.phi - b.phi) <= ang_a + ang_b:
                    hidden.add(j if b.r > a.r else i)
        return [s for k, s in enumerate(seen) if k not in hidden]

    def frame(self, room, x: float, y: float, heading: float, ranges: dict[str, float],
              rng: np.random.Generator) -> set[str]:
        """One camera frame: the classes detected. One uniform draw per object of the room, in the
        room's order, whether it is in view or not, so that the draws of a run do not depend on
        what happens to be in view."""
        u = rng.random(len(room.objects))
        p = {s.cls: s.p for s in self.visible(room, x, y, heading, ranges)}
        return {cls for k, cls in enumerate(room.objects) if u[k] < p.get(cls, 0.0)}

    # ---- the robot's model ------------------------------------------------------------------
    def detect_image(self, frame: GridFrame, x: float, y: float, heading: float, cls: str, max_range: float,
                     cx: np.ndarray, cy: np.ndarray, occ: np.ndarray | None = None) -> np.ndarray:
        """(H, W) probability that an object of ``cls`` standing in each cell would be detected
        from (x, y, heading); ``cx``, ``cy`` are the cells' centres (m), ``occ`` the obstacle map."""
        dz = self.object_height - self.spec.height
        dx, dy = cx - x, cy - y
        xc, yc, zc = self.to_camera(dx, dy, dz, heading)
        r = np.sqrt(xc * xc + yc * yc + zc * zc)
        ok = self.in_view(r, np.arctan2(yc, xc), np.arctan2(zc, xc), xc, max_range)
        if occ is not None and occ.any():
            ok &= self.line_of_sight(frame, x, y, heading, occ, np.hypot(dx, dy), np.arctan2(dy, dx))
        out = np.zeros(cx.shape)
        out[ok] = self.mean_probability(cls, r[ok])
        return out

    def line_of_sight(self, frame: GridFrame, x: float, y: float, heading: float, occ: np.ndarray,
                      dist: np.ndarray, bearing: np.ndarray) -> np.ndarray:
        """Cells not hidden by obstacles: rays every half degree across the field of view; a cell
        is seen when it is nearer than the ray of its bearing."""
        n = int(math.ceil(math.degrees(2 * self.half_h) * 2)) + 1
        thetas = heading + np.linspace(-self.half_h, self.half_h, n)
        v, u = frame.to_cell(x, y)
        free_m = cast_rays(occ, float(v), float(u), thetas, 1e6)[0] * frame.res
        k = np.clip(np.round((wrap_angle(bearing - heading) + self.half_h) / (2 * self.half_h) * (n - 1)), 0, n - 1)
        return dist <= free_m[k.astype(np.int64)]


def _segment_blocked(boxes, x0: float, y0: float, x1: float, y1: float) -> bool:
    """Whether the segment crosses one of the boxes (slab test)."""
    dx, dy = x1 - x0, y1 - y0
    for bx0, by0, bx1, by1 in boxes:
        t0, t1 = 0.0, 1.0
        ok = True
        for p, d, lo, hi in ((x0, dx, bx0, bx1), (y0, dy, by0, by1)):
            if abs(d) < 1e-12:
                if p < lo or p > hi:
                    ok = False
                    break
            else:
                a, b = (lo - p) / d, (hi - p) / d
                t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
                if t0 > t1:
                    ok = False
                    break
        if ok:
            return True
    return False
