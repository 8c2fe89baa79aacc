"""Import a MobileSim line map (.map) and door file (.doors) into a semsearch scenario.

``.map``: after the ``LINES`` line, one wall segment per line ``x1 y1 x2 y2`` in millimetres, until
``DATA``. ``.doors``: one sign per line ``x y number facing`` (metres, degrees). The importer
rasterises the walls, keeps as free the space 4-connected to the start (everything else becomes
"outside"), and snaps each sign onto the nearest wall face of that free space, facing into it
(the authors' signs sit 0.3-1 m behind the corridor walls, on the room side).
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
from scipy import ndimage

from ...config.base import number_text, sign_label
from ...errors import ScenarioError
from ...files import read_user_text
from ...geometry import GridFrame
from ...kernels.grid import dijkstra
from ..scenario_folder import map_image, scenario_dict, write_building
from ..labels import parse_label

MARGIN_M = 1.0


def read_mobilesim_lines(path: Path) -> np.ndarray:
    """(n, 4) float64 wall segments in metres."""
    segs, inside = [], False
    for k, line in enumerate(read_user_text(path, "MobileSim map").splitlines()):
        s = line.strip()
        if s == "LINES":
            inside = True
            continue
        if s == "DATA":
            break
        if inside and s:
            parts = s.split()
            try:
                segs.append([number_text(p) / 1000.0 for p in parts[:4]])
            except ValueError:
                raise ScenarioError(str(path), f"line {k + 1}", f"expected 'x1 y1 x2 y2' in millimetres, got {s!r}") from None
    if not segs:
        raise ScenarioError(str(path), "LINES", "no wall segments found (is this a MobileSim .map file?)")
    return np.array(segs)


def read_mobilesim_doors(path: Path) -> list[tuple]:
    """Signs ``(label, x, y, facing_deg)`` from a ``.doors`` file."""
    out = []
    for k, line in enumerate(read_user_text(path, "door file").splitlines()):
        parts = line.split()
        if not parts:
            continue
        try:
            x, y, num, facing = number_text(parts[0]), number_text(parts[1]), parts[2], number_text(parts[3])
        except (ValueError, IndexError):
            raise ScenarioError(str(path), f"line {k + 1}", f"expected 'x y number facing', got {line!r}") from None
        try:
            label = sign_label(num)
        except ValueError as exc:
            raise ScenarioError(str(path), f"line {k + 1}", f"the sign's number: {exc}") from None
        out.append((label, x, y, facing))
    return out


def rasterise(segs: np.ndarray, res: float) -> tuple[np.ndarray, GridFrame]:
    """Walls as a (H, W) bool grid with a margin, and its frame."""
    x0 = segs[:, [0, 2]].min() - MARGIN_M
    y0 = segs[:, [1, 3]].min() - MARGIN_M
    x1 = segs[:, [0, 2]].max() + MARGIN_M
    y1 = segs[:, [1, 3]].max() + MARGIN_M
    W = int(np.ceil((x1 - x0) / res))
    H = int(np.ceil((y1 - y0) / res))
    frame = GridFrame(res, float(x0), float(y0), H, W)
    img = np.zeros((H, W), np.uint8)
    r1, c1 = frame.to_index(segs[:, 0], segs[:, 1])
    r2, c2 = frame.to_index(segs[:, 2], segs[:, 3])
    for a, b, c, d in zip(c1, r1, c2, r2):
        cv2.line(img, (int(a), int(b)), (int(c), int(d)), 1, 1, cv2.LINE_8)
    return img.astype(bool), frame


MAX_SNAP_M = 2.0  # a sign farther than this from the free space is dropped: no pose there could read it


def snap_report(signs: list[tuple], snapped: list[tuple], frame: GridFrame) -> tuple[list[tuple], list[str]]:
    """Drop the signs that :func:`snap_signs` had to move more than ``MAX_SNAP_M``, and say what
    happened: a summary (how many signs were moved onto the walls, by more than a cell, and how
    far; how many re-faced; how many dropped, and why), then one line per sign moved, re-faced or
    dropped. Returns (the signs kept, the lines of the report)."""
    moved = [float(np.hypot(a[1] - b[1], a[2] - b[2])) for a, b in zip(signs, snapped)]
    turned = [a[3] is not None and abs((b[3] - a[3] + 180.0) % 360.0 - 180.0) > 0.01 for a, b in zip(signs, snapped)]
    kept = [b for b, m in zip(snapped, moved) if m <= MAX_SNAP_M]
    lines = []
    far = [k for k, m in enumerate(moved) if m > MAX_SNAP_M]
    near = [m for m in moved if frame.res < m <= MAX_SNAP_M]
    if near:
        lines.append(f"snapped {len(near)} of {len(signs)} signs onto the walls of the free space (moved {min(near):.2f}-"
                     f"{max(near):.2f} m), each keeping its facing: they stood off the walls the robot drives along")
    if any(t for t, m in zip(turned, moved) if m <= MAX_SNAP_M):
        lines.append(f"re-faced {sum(t for t, m in zip(turned, moved) if m <= MAX_SNAP_M)} signs whose facing pointed "
                     "into the wall they stand on: they now face the free space, square to the wall")
    if far:
        lines.append(f"dropped {len(far)} signs more than {MAX_SNAP_M:g} m from the free space the robot can reach "
                     f"(no pose could read them)")
    if not lines:
        lines.append(f"kept all {len(signs)} signs where they stood (within a cell of the walls), with their facings")
    for a, b, m, t in zip(signs, snapped, moved, turned):
        if m > MAX_SNAP_M:
            lines.append(f"  sign {a[0]}: dropped, {m:.1f} m from the free space")
        elif m > frame.res or t:
            what = [f"moved {m:.2f} m"] if m > frame.res else []
            if a[3] is None:
                what.append(f"facing {b[3]:g} degrees (the file gives none: square to the wall)")
            else:
                what.append(f"facing {a[3]:g} -> {b[3]:g} degrees (pointed into the wall)" if t else f"facing {a[3]:g} kept")
            lines.append(f"  sign {a[0]}: " + ", ".join(what))
    return kept, lines


def snap_signs(free: np.ndarray, frame: GridFrame, signs: list[tuple]) -> list[tuple]:
    """Move each sign onto the nearest wall face of ``free``. A sign keeps its facing (the
    direction it faces, degrees) unless that points into the wall it now stands on (no reader
    could stand there), or is None (the file gives none, as KTH's); it then faces the free cell,
    square to the wall."""
    _, (ir, ic) = ndimage.distance_transform_edt(~free, return_indices=True)
    H, W = free.shape
    out = []
    for label, x, y, facing in signs:
        r, c = frame.to_index(x, y)
        r = int(np.clip(r, 0, H - 1))
        c = int(np.clip(c, 0, W - 1))
        fr, fc = int(ir[r, c]), int(ic[r, c])
        fx, fy = frame.to_world(fr, fc)
        best, bdir = -np.inf, (0.0, 0.0)
        for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
            nr, nc = fr + dr, fc + dc
            if 0 <= nr < H and 0 <= nc < W and free[nr, nc]:
                continue
            ux, uy = dc, -dr
            score = (x - fx) * ux + (y - fy) * uy
            if score > best:
                best, bdir = score, (ux, uy)
        if best == -np.inf:  # free on all four sides: face toward the original position
            v = np.array([x - fx, y - fy])
            v = v / (np.linalg.norm(v) or 1.0)
            bdir = (float(v[0]), float(v[1]))
        sx = fx + 0.5 * frame.res * bdir[0]
        sy = fy + 0.5 * frame.res * bdir[1]
        if facing is None or np.cos(np.radians(float(facing))) * -bdir[0] + np.sin(np.radians(float(facing))) * -bdir[1] <= 0.0:
            # no facing given, or one toward the wall (no reader can stand there): square to the wall
            facing = float(np.degrees(np.arctan2(-bdir[1], -bdir[0])))
        out.append((label, round(float(sx), 4), round(float(sy), 4), round(float(facing), 2)))
    return out


def import_mobilesim(map_path: Path, doors_path: Path, out: Path, res: float = 0.1,
                     start: tuple[float, float] | None = None, goals: list | None = None,
                     density_delta: float = 2.5, name: str | None = None, duplicates: str = "error") -> tuple[Path, list[str]]:
    """Write ``out/map.png``, ``out/doors.csv`` and ``out/scenario.yaml``; returns the YAML path
    and what happened to the signs (see :func:`snap_report`; also in the YAML's header).
    ``duplicates`` is the scenario's policy for signs that share a number (``error``,
    ``keep-first``, ``any``)."""
    segs = read_mobilesim_lines(map_path)
    signs = read_mobilesim_doors(doors_path)
    walls, frame = rasterise(segs, res)
    space = ~walls
    n, lab = cv2.connectedComponents(space.astype(np.uint8), connectivity=4)
    if start is None:  # the free cell farthest from walls inside the building (not the margin)
        border = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
        inner = space & ~np.isin(lab, border)
        d = cv2.distanceTransform(inner.astype(np.uint8), cv2.DIST_L2, 5)
        r, c = np.unravel_index(int(np.argmax(d)), d.shape)
        sx, sy = frame.to_world(r, c)
        start = (round(float(sx), 2), round(float(sy), 2))
    r, c = frame.to_index(*start)
    if not (0 <= r < frame.height and 0 <= c < frame.width) or not space[r, c]:
        raise ScenarioError("<command line>", "--start", f"start {start} m is not in free space of {map_path}")
    free = lab == lab[r, c]
    snapped, report = snap_report(signs, snap_signs(free, frame, signs), frame)
    if not snapped:
        raise ScenarioError(str(doors_path), "", f"none of its {len(signs)} signs lies within {MAX_SNAP_M:g} m of the free "
                            f"space the robot can reach from the start {start} m: there is no sign to read and no goal "
                            "to seek; are the signs in the map's frame (millimetres)?")
    if not goals:
        goals = spread_goals(free, frame, snapped, start)
    scen = scenario_dict(name or map_path.stem, res, start, goals, [{"name": "greedy"}, {"name": "bvp"}],
                         density_delta, (frame.origin_x, frame.origin_y), duplicates)
    header = f"imported from {map_path.name} and {doors_path.name} by `semsearch import mobilesim`\n# " + "\n# ".join(report)
    return write_building(out, map_image(free, walls), snapped, scen, header), report


def spread_goals(free, frame, signs, start, k=4):
    """k signs with a number (world/labels.py) at evenly spread quantiles of distance from the
    start (a default only)."""
    r, c = frame.to_index(*start)
    _, length, _ = dijkstra(free, np.ones((1, 1), np.float32), np.array([r]), np.array([c]),
                            np.zeros(free.shape, bool), 0, np.inf)
    cand = []
    for label, x, y, _ in signs:
        if parse_label(label) is not None:
            sr, sc = frame.to_index(x, y)
            win = length[max(sr - 2, 0): sr + 3, max(sc - 2, 0): sc + 3]
            d = win[np.isfinite(win)]
            if d.size:
                cand.append((float(d.min()), label))
    def order(label):  # numbers first by value (labels mix 1513 and K202)
        return parse_label(label).number, str(label)

    cand.sort(key=lambda dc: (dc[0], *order(dc[1])))
    if not cand:
        return [signs[0][0]]
    idx = np.linspace(0.2, 0.8, k) * (len(cand) - 1)
    return sorted({cand[int(round(i))][1] for i in idx}, key=order)
