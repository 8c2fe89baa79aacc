"""The semantic camera of indirect search (Loncomilla et al. 2018, Section 4.2-4.3).

Ground truth (:meth:`SemanticCamera.frame`): an object's centre is taken into the camera frame by
Eq. 37 (robot yaw, then the camera's pitch; ours: ``pitch`` degrees down, since the paper gives
none), and is in view when its distance r_d (Eq. 38) lies in [min_depth, range], its horizontal
angle theta_d (Eq. 39) within hfov / 2 and its vertical angle phi_d (Eq. 40) within vfov / 2, and
no obstacle box stands on the line from the robot to it. Objects in view occlude each other as
spheres (Algorithm 4): when the angular distance of two centres is at most the sum of
``atan2(rho, x_cam)`` over the two, rho the object's diameter, as the paper prints it (by default,
``occlusion: diameter``), the farther one is not detected. ``occlusion: radius`` halves rho (the
sum of angular radii: where two projected discs actually meet; our earlier reading, kept as an
option: the printed test hides more objects). Each object left is then
detected with the probability of the look-up table (Table 1's axes; by default our table that
detects from every yaw, built from Table 1's surviving values: ``config/indirect.py``
``every_yaw_table``): the yaw bin is the direction from the object to the camera relative to the
object's yaw, the nearest of the eight; the distance is interpolated linearly between the table's
columns and clamped at its ends.

The robot's model, per map cell: the probability that an object of a class standing there (at the
objects' height) would be detected from a pose, by the same view test and line of sight on the
obstacle map, without occlusion by other objects. The robot does not know the yaw of an object it
has not seen, and the frames of a search all see one object at one yaw, so the model keeps one
hypothesis per yaw (:class:`YawMemory`, the default ``camera.model: yaws``) and gives, per frame,
the probability of detecting the object given that the frames before missed it: the product of
the paper's per-frame updates is then the exact probability of all the misses, however many frames
looked from one side. ``camera.model: mean`` (our earlier model) takes the table's mean over the
eight yaws at every frame (:meth:`SemanticCamera.detect_image`), which is right for one frame only.
Both serve A's non-detections and the secondary objects'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..config.indirect import LUT_DISTANCES, LUT_YAWS, SemanticCameraSpec
from ..geometry import GridFrame, wrap_angle
from ..kernels.cone import cone_box, cone_image, cone_mass, cone_nondetect
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
        self.tan_h, self.tan_v = math.tan(self.half_h), math.tan(self.half_v)
        self.lut_d = np.asarray(LUT_DISTANCES, float)
        self.pitch = math.radians(spec.pitch)
        self.object_height = object_height
        self._lut: dict[str, np.ndarray] = {}

    # ---- the look-up table ------------------------------------------------------------------
    def table(self, cls: str) -> np.ndarray:
        """(8, 5) detection probabilities (0-1): rows yaw 0..315, columns 0.8..2.5 m."""
        if cls not in self._lut:
            self._lut[cls] = np.asarray(self.spec.lut(cls), float) / 100.0
        return self._lut[cls]

    def probability(self, cls: str, r, seen_yaw_deg):
        """Detection probability of ``cls`` at distance ``r`` (m) seen at yaw ``seen_yaw_deg``
        (scalars, or arrays of one shape): the nearest yaw row, interpolated in distance."""
        row = np.round((np.asarray(seen_yaw_deg, float) % 360.0) / 45.0).astype(np.int64) % len(LUT_YAWS)
        r = np.asarray(r, float)
        table = self.table(cls)
        out = np.zeros(np.broadcast(r, row).shape)
        for b in np.unique(row):
            m = np.broadcast_to(row == b, out.shape)
            out[m] = np.interp(np.broadcast_to(r, out.shape)[m], LUT_DISTANCES, table[b])
        return float(out) if out.ndim == 0 else out

    def mean_table(self, cls: str) -> np.ndarray:
        """The table's mean over the eight yaws, per distance column."""
        key = cls + "/mean"
        if key not in self._lut:
            self._lut[key] = self.table(cls).mean(axis=0)
        return self._lut[key]

    def mean_probability(self, cls: str, r: np.ndarray) -> np.ndarray:
        """The table's mean over the eight yaws, at distances ``r`` (m)."""
        return np.interp(r, LUT_DISTANCES, self.mean_table(cls))

    # ---- geometry ---------------------------------------------------------------------------
    def to_camera(self, dx, dy, dz, heading):
        """Eq. 37: world offsets from the camera (m) -> camera frame (x forward, y right, z up);
        scalars or arrays that broadcast together."""
        c, s = (math.cos(heading), math.sin(heading)) if np.isscalar(heading) else (np.cos(heading), np.sin(heading))
        xr, yr = c * dx + s * dy, -s * dx + c * dy  # robot frame: x forward, y left
        cp, sp = math.cos(self.pitch), math.sin(self.pitch)
        return cp * xr - sp * dz, -yr, sp * xr + cp * dz

    def in_view(self, r, theta, phi, x_cam, max_range):
        """Eqs. 38-40 against the field of view and the depth limits."""
        return ((x_cam > 0) & (r >= self.spec.min_depth) & (r <= max_range)
                & (np.abs(theta) <= self.half_h) & (np.abs(phi) <= self.half_v))

    def sees(self, poses: np.ndarray, xs: np.ndarray, ys: np.ndarray, max_range: float) -> np.ndarray:
        """(n, m) whether each of ``n`` poses (x, y, heading) has each of ``m`` points (at the
        objects' height) in view, ignoring obstacles."""
        poses = np.asarray(poses, float).reshape(-1, 3)
        dx = np.asarray(xs, float)[None, :] - poses[:, :1]
        dy = np.asarray(ys, float)[None, :] - poses[:, 1:2]
        xc, yc, zc = self.to_camera(dx, dy, self.object_height - self.spec.height, poses[:, 2:3])
        r = np.sqrt(xc * xc + yc * yc + zc * zc)
        return self.in_view(r, np.arctan2(yc, xc), np.arctan2(zc, xc), xc, max_range)

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
        scale = 1.0 if self.spec.occlusion == "diameter" else 0.5
        hidden = set()
        for i in range(len(seen)):
            for j in range(i + 1, len(seen)):
                a, b = seen[i], seen[j]
                ang_a = math.atan2(self.spec.diameters.get(a.cls, 0.3) * scale, a.x_cam)
                ang_b = math.atan2(self.spec.diameters.get(b.cls, 0.3) * scale, b.x_cam)
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
                     occ: np.ndarray | None = None, out: np.ndarray | None = None) -> np.ndarray:
        """(H, W) probability that an object of ``cls`` standing in each cell would be detected
        from (x, y, heading); ``occ`` is the obstacle map (True blocks the view). Written into
        ``out`` (zeroed first) when given."""
        if out is None:
            out = np.zeros((frame.height, frame.width))
        else:
            out[:] = 0.0
        table = self.mean_table(cls)
        r0, r1, c0, c1 = cone_image(out, frame.origin_x, frame.origin_y, frame.res, x, y, heading, self.pitch,
                                    self.tan_h, self.tan_v, self.spec.min_depth, max_range,
                                    self.object_height - self.spec.height, self.lut_d, table)
        if occ is not None and r1 > r0 and c1 > c0 and occ[r0:r1, c0:c1].any():
            cx, cy = frame.to_world(np.arange(r0, r1)[:, None], np.arange(c0, c1)[None, :])
            dx, dy = cx - x, cy - y
            win = out[r0:r1, c0:c1]
            win[~self.line_of_sight(frame, x, y, heading, occ, np.hypot(dx, dy), np.arctan2(dy, dx))] = 0.0
        return out

    def not_detected(self, nd: np.ndarray, frame: GridFrame, x: float, y: float, heading: float, cls: str,
                     max_range: float, occ: np.ndarray | None = None) -> tuple[int, int, int, int]:
        """Multiply ``nd`` (8, H, W), per yaw hypothesis of an object of ``cls`` (k: its yaw is 45 k
        degrees) the probability that it stands in each cell undetected so far, by the probability
        of not detecting it from (x, y, heading): under hypothesis k a cell's table row is the
        direction from the cell to the camera relative to 45 k degrees (as :meth:`visible` reads the
        table). Returns the box (r0, r1, c0, c1) of the cells it may have changed."""
        dz = self.object_height - self.spec.height
        hidden, hr0, hc0 = _NONE_HIDDEN, 0, 0
        if occ is not None:
            r0, r1, c0, c1 = cone_box(frame.height, frame.width, frame.origin_x, frame.origin_y, frame.res, x, y,
                                      max_range, dz)
            if r1 > r0 and c1 > c0 and occ[r0:r1, c0:c1].any():
                cx, cy = frame.to_world(np.arange(r0, r1)[:, None], np.arange(c0, c1)[None, :])
                dx, dy = cx - x, cy - y
                hidden = ~self.line_of_sight(frame, x, y, heading, occ, np.hypot(dx, dy), np.arctan2(dy, dx))
                hr0, hc0 = r0, c0
        return cone_nondetect(nd, frame.origin_x, frame.origin_y, frame.res, x, y, heading, self.pitch, self.tan_h,
                              self.tan_v, self.spec.min_depth, max_range, dz, self.lut_d, self.table(cls), hidden, hr0,
                              hc0)

    def line_of_sight(self, frame: GridFrame, x: float, y: float, heading: float, occ: np.ndarray,
                      dist: np.ndarray, bearing: np.ndarray) -> np.ndarray:
        """Cells not hidden by obstacles: rays every half degree over a field wide enough for the
        pitched camera (which sees wider than hfov near its feet); a cell is seen when it is nearer
        than the ray of its bearing."""
        half = min(math.pi, 2 * self.half_h)
        n = int(math.ceil(math.degrees(2 * half) * 2)) + 1
        thetas = heading + np.linspace(-half, half, n)
        v, u = frame.to_cell(x, y)
        free_m = cast_rays(occ, float(v), float(u), thetas, 1e6)[0] * frame.res
        k = np.clip(np.round((wrap_angle(bearing - heading) + half) / (2 * half) * (n - 1)), 0, n - 1)
        return dist <= free_m[k.astype(np.int64)]

    def templates(self, max_range: float, res: float, bins: int = 64) -> "ConeTemplates":
        """The cells in view (Eq. 34's V) from a cell centre, for ``bins`` headings: offsets
        (rows, cols) per heading, for summing a map over the view cones of many poses at once."""
        reach = math.sqrt(max(max_range ** 2 - (self.object_height - self.spec.height) ** 2, 0.0))
        R = int(math.ceil(reach / res)) + 1
        fr = GridFrame(res, -(R + 0.5) * res, -(R + 0.5) * res, 2 * R + 1, 2 * R + 1)
        img = np.zeros((2 * R + 1, 2 * R + 1))
        offs = []
        for b in range(bins):
            img[:] = 0.0
            cone_image(img, fr.origin_x, fr.origin_y, res, 0.0, 0.0, 2 * math.pi * b / bins, self.pitch, self.tan_h,
                       self.tan_v, self.spec.min_depth, max_range, self.object_height - self.spec.height,
                       np.array([0.0, 1.0]), np.array([1.0, 1.0]))
            rr, cc = np.nonzero(img)
            offs.append((rr - R, cc - R))
        L = max(1, max(len(o[0]) for o in offs))
        offs_r = np.zeros((bins, L), np.int64)
        offs_c = np.zeros((bins, L), np.int64)
        counts = np.zeros(bins, np.int64)
        for b, (rr, cc) in enumerate(offs):
            offs_r[b, :len(rr)], offs_c[b, :len(cc)], counts[b] = rr, cc, len(rr)
        return ConeTemplates(R, offs_r, offs_c, counts, bins)


class YawMemory:
    """The robot's model of detecting one class on one grid over a search, correct however many
    frames look from one side.

    The robot does not know the yaw of an object it has not seen, and the table depends on it. One
    frame's detection probability is the table's mean over the eight yaws; but the frames of a
    search are not independent draws of the yaw (the object does not turn), so multiplying
    (1 - that mean) at every frame is wrong: nine looks from a side the detector misses would rule a
    cell out. The memory keeps, per yaw hypothesis, the product of the non-detections so far
    (``nd``, 8 x H x W), and :meth:`look` returns the probability of detecting the object in each
    cell in this frame given that the frames before missed it: 1 - mean_k nd_k(after) / mean_k
    nd_k(before). The product over frames of (1 - that) is mean_k nd_k, the exact probability of no
    detection in all of them, so the paper's per-frame update (Eqs. 6-9) stays as printed."""

    def __init__(self, camera: SemanticCamera, cls: str, frame: GridFrame, occ: np.ndarray | None = None):
        self.camera, self.cls, self.frame, self.occ = camera, cls, frame, occ
        self.nd = np.ones((len(LUT_YAWS), frame.height, frame.width))
        self.mean = np.ones((frame.height, frame.width))
        self.D = np.zeros((frame.height, frame.width))
        self._box = (0, 0, 0, 0)

    def look(self, x: float, y: float, heading: float, max_range: float) -> np.ndarray:
        """(H, W) this frame's detection probability per cell, given the misses before (the array is
        reused at the next call: copy it to keep it)."""
        r0, r1, c0, c1 = self._box
        self.D[r0:r1, c0:c1] = 0.0
        r0, r1, c0, c1 = self._box = self.camera.not_detected(self.nd, self.frame, x, y, heading, self.cls, max_range,
                                                               self.occ)
        if r1 > r0 and c1 > c0:
            new = self.nd[:, r0:r1, c0:c1].mean(axis=0)
            old = self.mean[r0:r1, c0:c1]
            self.D[r0:r1, c0:c1] = np.where(old > 0.0, 1.0 - new / np.where(old > 0.0, old, 1.0), 0.0)
            self.mean[r0:r1, c0:c1] = new
        return self.D


@dataclass(frozen=True)
class ConeTemplates:
    """View-cone offsets per heading bin (see :meth:`SemanticCamera.templates`)."""

    pad: int
    offs_r: np.ndarray
    offs_c: np.ndarray
    counts: np.ndarray
    bins: int

    def mass(self, p: np.ndarray, rows, cols, headings) -> np.ndarray:
        """Sum of ``p`` in the view cone of each pose (cells, heading in radians)."""
        p_pad = np.pad(p, self.pad)
        b = np.round(np.asarray(headings) / (2 * math.pi) * self.bins).astype(np.int64) % self.bins
        return cone_mass(p_pad, self.pad, np.asarray(rows, np.int64), np.asarray(cols, np.int64), b,
                         self.offs_r, self.offs_c, self.counts)


_NONE_HIDDEN = np.zeros((0, 0), np.bool_)


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
