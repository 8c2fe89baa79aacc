"""Writing a building as a scenario folder (map.png, doors.csv, scenario.yaml): shared by the
importers and the generator."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import yaml

OUTSIDE_GRAY = 160
DEFAULT_PLANNERS = [{"name": "greedy"}, {"name": "bvp"}, {"name": "nsos", "alpha": [0.8, 0.9, 1.0]}]


def map_image(free: np.ndarray, walls: np.ndarray | None = None) -> np.ndarray:
    """(H, W) uint8: free 255, walls 0, everything else the "outside" gray. Without ``walls`` the
    wall is the one-cell ring around the free space."""
    if walls is None:
        walls = cv2.dilate(free.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool) & ~free
    img = np.full(free.shape, OUTSIDE_GRAY, np.uint8)
    img[free] = 255
    img[walls] = 0
    return img


def scenario_dict(name: str, res: float, start, goals, planners=None, density_delta: float = 2.5, origin=None,
                  duplicates: str = "error") -> dict:
    """The scenario of a building folder, with the experiment defaults (10 seeds, 2000 m);
    ``duplicates`` (signs that share a number: ``error``, ``keep-first``, ``any``) is written only
    when it is not the default."""
    m = {"image": "map.png", "resolution": res}
    if origin is not None:
        m["origin"] = [round(float(origin[0]), 4), round(float(origin[1]), 4)]
    out = {
        "name": name,
        "map": m,
        "start": {"x": round(float(start[0]), 3), "y": round(float(start[1]), 3), "heading": "random"},
        "doors": "doors.csv",
        "goals": [int(g) if isinstance(g, (int, np.integer)) else g for g in goals],
        "planners": planners or DEFAULT_PLANNERS,
        "belief": {"density_delta": density_delta},
        "experiment": {"seeds": 10, "base_seed": 0, "max_distance": 2000.0},
    }
    if duplicates != "error":
        out["duplicates"] = duplicates
    return out


def fill_box(img: np.ndarray, res: float, x0: float, x1: float, y0: float, y1: float, value: int) -> None:
    """Paint the world rectangle [x0, x1] x [y0, y1] (m, origin at the image's bottom-left) of a
    map image (in place) with ``value``."""
    H = img.shape[0]
    c0, c1 = int(round(x0 / res)), int(round(x1 / res))
    r0, r1 = H - int(round(y1 / res)), H - int(round(y0 / res))
    img[max(0, r0) : r1, max(0, c0) : c1] = value


def corridor_floor(width_m: float, height_m: float, wall_m: float, corridor: tuple[float, float], res: float):
    """A walled floor (free inside the outer wall) with a corridor along x between the walls at
    y = ``corridor`` (lo, hi): (the image, ``box(x0, x1, y0, y1, value)`` painting onto it)."""
    img = np.zeros((int(round(height_m / res)), int(round(width_m / res))), np.uint8)

    def box(x0, x1, y0, y1, v):
        fill_box(img, res, x0, x1, y0, y1, v)

    lo, hi = corridor
    box(wall_m, width_m - wall_m, wall_m, height_m - wall_m, 255)
    box(0, width_m, hi, hi + wall_m, 0)  # the corridor's walls
    box(0, width_m, lo - wall_m, lo, 0)
    return img, box


def write_doors(path: Path, signs) -> None:
    """A doors CSV (number,x,y,facing) from (label, x m, y m, facing degrees) tuples."""
    with path.open("w") as fh:
        fh.write("number,x,y,facing\n")
        for label, x, y, f in signs:
            fh.write(f"{label},{x},{y},{f}\n")


def write_building(out: Path, img: np.ndarray | None, signs, scen: dict, header: str) -> Path:
    """Write ``out/map.png`` (unless ``img`` is None: a map kept in its own format),
    ``out/doors.csv`` (signs: (label, x, y, facing_deg)) and ``out/scenario.yaml`` (prefixed by
    the comment ``header``); returns the YAML path."""
    out.mkdir(parents=True, exist_ok=True)
    if img is not None:
        cv2.imwrite(str(out / "map.png"), img)
    write_doors(out / "doors.csv", signs)
    path = out / "scenario.yaml"
    path.write_text(f"# {header}\n" + yaml.safe_dump(scen, sort_keys=False))
    return path
