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
    try:
        res = float(d["resolution"])
        ox, oy, yaw = (float(v) for v in d["origin"])
        occupied, free = float(d.get("occupied_thresh", 0.65)), float(d.get("free_thresh", 0.196))
    except (TypeError, ValueError):
        raise ScenarioError(str(path), "origin", "expected resolution (m/cell) and origin [x, y, yaw]") from None
    if not 0.005 <= res <= 1.0:
        raise ScenarioError(str(path), "resolution", f"expected 0.005 to 1 m per cell (got {res})")
    if not (np.isfinite([ox, oy, yaw]).all() and max(abs(ox), abs(oy)) <= 1e6):
        raise ScenarioError(str(path), "origin", f"expected finite numbers within 1e6 m (got {d['origin']!r})")
    if abs(yaw) > 1e-9:
        raise ScenarioError(str(path), "origin", f"a rotated map (yaw {yaw}) is not supported; save it with yaw 0")
    mode = str(d.get("mode", "trinary"))
    if mode not in ("trinary", "scale", "raw"):
        raise ScenarioError(str(path), "mode", f"trinary, scale or raw (got {mode!r})")
    return {"image": str(d["image"]), "resolution": res, "origin": (ox, oy), "negate": bool(int(d.get("negate", 0))),
            "occupied_thresh": occupied, "free_thresh": free,
            "mode": mode}


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
