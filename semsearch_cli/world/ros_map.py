"""ROS maps: the map_server / map_saver format (a YAML file naming a PGM or PNG image).

The YAML gives ``image`` (relative to the YAML), ``resolution`` (m/cell), ``origin`` ([x, y, yaw]:
the pose of the image's lower-left pixel; yaw must be 0 here), ``negate``, ``occupied_thresh``,
``free_thresh`` and ``mode`` (trinary, the default, scale or raw). As map_server reads it: in
trinary and scale modes a pixel's occupancy is ``p = (255 - v) / 255`` (``v / 255`` when negated);
``p > occupied_thresh`` is a wall, ``p < free_thresh`` free, anything between unknown. In raw mode
the pixel is the occupancy in percent (0-100), and other values are unknown. The map becomes
semsearch's grey levels: wall 0, unknown 128 ("outside"), free 255.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import yaml

from ..config import read_yaml
from ..errors import ScenarioError
from .images import read_gray

WALL, UNKNOWN, FREE = 0, 128, 255


def read_ros_yaml(path: Path, owner: str | None = None) -> dict:
    """The map's YAML, checked; errors name the file and the key."""
    path = Path(path)
    d = read_yaml(path, "ROS map file", owner, "map.ros" if owner else "")
    if not isinstance(d, dict):
        raise ScenarioError(str(path), "", "expected the map_server keys (image, resolution, origin, ...)")
    for key in ("image", "resolution", "origin"):
        if key not in d:
            raise ScenarioError(str(path), key, "required by the map_server format")
    res = _number(path, d, "resolution", "m per cell")
    if not 0.005 <= res <= 1.0:
        raise ScenarioError(str(path), "resolution", f"expected 0.005 to 1 m per cell (got {res})")
    origin = d["origin"]
    if not isinstance(origin, (list, tuple)) or len(origin) != 3 or any(isinstance(v, (bool, str)) for v in origin):
        raise ScenarioError(str(path), "origin", f"expected [x, y, yaw], three numbers (got {origin!r})")
    try:
        ox, oy, yaw = (float(v) for v in origin)
    except (TypeError, ValueError):
        raise ScenarioError(str(path), "origin", f"expected [x, y, yaw], three numbers (got {origin!r})") from None
    if not (np.isfinite([ox, oy, yaw]).all() and max(abs(ox), abs(oy)) <= 1e6):
        raise ScenarioError(str(path), "origin", f"expected finite numbers within 1e6 m (got {origin!r})")
    if abs(yaw) > 1e-9:
        raise ScenarioError(str(path), "origin", f"a rotated map (yaw {yaw}) is not supported; save it with yaw 0")
    occupied = _number(path, d, "occupied_thresh", "a probability", 0.65)
    free = _number(path, d, "free_thresh", "a probability", 0.196)
    for key, v in (("occupied_thresh", occupied), ("free_thresh", free)):
        if not 0.0 <= v <= 1.0:
            raise ScenarioError(str(path), key, f"expected a probability, 0 to 1 (got {v})")
    if free > occupied:
        raise ScenarioError(str(path), "free_thresh", f"{free} lies above occupied_thresh {occupied}: a cell cannot be "
                            "both free and occupied")
    negate = d.get("negate", 0)
    if negate not in (0, 1) or isinstance(negate, float):  # map_server reads an integer (True and False are 1 and 0)
        raise ScenarioError(str(path), "negate", f"expected 0 or 1 (got {negate!r})")
    mode = d.get("mode", "trinary")
    if mode not in ("trinary", "scale", "raw"):
        raise ScenarioError(str(path), "mode", f"trinary, scale or raw (got {mode!r})")
    return {"image": str(d["image"]), "resolution": res, "origin": (ox, oy), "negate": bool(negate),
            "occupied_thresh": occupied, "free_thresh": free,
            "mode": mode}


def _number(path: Path, d: dict, key: str, what: str, default: float | None = None) -> float:
    """``d[key]`` as a finite number (YAML booleans and text are not numbers); errors name the key."""
    v = d.get(key, default)
    if isinstance(v, (bool, str)) or v is None:
        raise ScenarioError(str(path), key, f"expected {what}, a number (got {v!r})")
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise ScenarioError(str(path), key, f"expected {what}, a number (got {v!r})") from None
    if not np.isfinite(x):
        raise ScenarioError(str(path), key, f"expected {what}, a finite number (got {v!r})")
    return x


def read_ros_map(path: Path, owner: str | None = None) -> tuple[np.ndarray, float, tuple[float, float]]:
    """(grey image in semsearch's levels, resolution m/cell, origin (x, y) m of the lower-left
    corner) of a ROS map YAML."""
    path = Path(path)
    meta = read_ros_yaml(path, owner)
    img_path = (path.parent / meta["image"])
    raw = read_gray(img_path, "map image", str(path), "image")
    v = raw.astype(np.float64)
    out = np.full(raw.shape, UNKNOWN, np.uint8)
    if meta["mode"] == "raw":
        known = v <= 100
        occ = v / 100.0
    else:
        known = np.ones(raw.shape, bool)
        occ = v / 255.0 if meta["negate"] else (255.0 - v) / 255.0
    out[known & (occ > meta["occupied_thresh"])] = WALL
    out[known & (occ < meta["free_thresh"])] = FREE
    return out, meta["resolution"], meta["origin"]


def copy_ros_map(path: Path, out: Path) -> Path:
    """Copy a ROS map (YAML and image) into ``out``; returns the copied YAML's path."""
    path = Path(path)
    meta = read_ros_yaml(path)
    out.mkdir(parents=True, exist_ok=True)
    img = path.parent / meta["image"]
    if img.resolve() != (out / img.name).resolve():
        shutil.copyfile(img, out / img.name)
    text = yaml.safe_load(path.read_text())
    text["image"] = img.name
    dest = out / "map.yaml"
    dest.write_text(yaml.safe_dump(text, sort_keys=False))
    return dest


def clean_free(img: np.ndarray, res: float, start_rc: tuple[int, int], radius: float) -> tuple[np.ndarray, int]:
    """A SLAM map cleaned for a robot of ``radius`` m starting at cell ``start_rc``: free space
    narrower than the robot (a laser's ray fans beyond the walls, clutter), taken by a
    morphological opening with a disk of the robot's diameter, and free space the robot cannot
    reach from the start become outside (grey 128). Returns (the map, the cells removed). The
    opening also trims corners narrower than the robot, where its centre cannot be anyway (24 of
    the demo map's 10,800 free cells)."""
    free = img == FREE
    d = max(1, int(round(2 * radius / res)))
    disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (d | 1, d | 1))
    wide = cv2.morphologyEx(free.astype(np.uint8), cv2.MORPH_OPEN, disk).astype(bool)
    r, c = start_rc
    if not wide[r, c]:
        wide |= free & (np.hypot(*np.mgrid[-r:img.shape[0] - r, -c:img.shape[1] - c]) * res <= radius)
    _, lab = cv2.connectedComponents(wide.astype(np.uint8), connectivity=4)
    keep = (lab == lab[r, c]) & wide
    out = img.copy()
    gone = free & ~keep
    out[gone] = UNKNOWN
    return out, int(gone.sum())
