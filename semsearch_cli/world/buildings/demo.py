"""A small building of our own, drawn in code: used by the tests and by ``configs/demo.yaml``.

An H-shaped corridor network (30 m x 20 m): a horizontal corridor joining two vertical ones, each
2 m wide, with signs every 2.5 m on both walls; odd numbers on one side, even on the other, rising
away from the middle (the thesis' Normal scheme).
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import yaml

from ..scenario_folder import write_doors

RES = 0.1
SIZE = (30.0, 20.0)  # m
# corridors as (x0, y0, x1, y1) rectangles, metres
CORRIDORS = [(2.0, 9.0, 28.0, 11.0), (7.0, 2.0, 9.0, 18.0), (21.0, 2.0, 23.0, 18.0)]
START = (15.0, 10.0)


def demo_image() -> np.ndarray:
    W, H = int(SIZE[0] / RES), int(SIZE[1] / RES)
    img = np.full((H, W), 160, np.uint8)
    for x0, y0, x1, y1 in CORRIDORS:
        c0, c1 = int(round(x0 / RES)) - 1, int(round(x1 / RES))
        r0, r1 = H - int(round(y1 / RES)) - 1, H - int(round(y0 / RES))
        img[r0 : r1 + 1, c0 : c1 + 1] = np.minimum(img[r0 : r1 + 1, c0 : c1 + 1], 0)
    for x0, y0, x1, y1 in CORRIDORS:
        c0, c1 = int(round(x0 / RES)), int(round(x1 / RES))
        r0, r1 = H - int(round(y1 / RES)), H - int(round(y0 / RES))
        img[r0:r1, c0:c1] = 255
    return img


def demo_signs() -> list[tuple]:
    """(number, x, y, facing_deg) on the corridor walls; numbers rise away from the middle."""
    signs = []
    # horizontal corridor: walls at y=9 (facing up, odd) and y=11 (facing down, even)
    xs_left = [12.5, 10.0]  # going left from the middle
    xs_right = [17.5, 20.0]
    n = 1
    for xl, xr in zip(xs_left, xs_right):
        signs += [(100 + n, xl, 9.0, 90.0), (100 + n + 1, xl, 11.0, -90.0)]
        signs += [(200 + n, xr, 9.0, 90.0), (200 + n + 1, xr, 11.0, -90.0)]
        n += 2
    for base, x in ((300, 7.0), (400, 21.0)):
        n = 1
        for y in (13.5, 16.0):  # north wing
            signs += [(base + n, x, y, 0.0), (base + n + 1, x + 2.0, y, 180.0)]
            n += 2
        n = 51
        for y in (6.5, 4.0):  # south wing
            signs += [(base + n, x, y, 0.0), (base + n + 1, x + 2.0, y, 180.0)]
            n += 2
    return signs


def write_demo(out: Path, goals=(304, 452), planners=None, seeds: int = 3) -> Path:
    """Write map.png, doors.csv and scenario.yaml for the demo building into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(out / "map.png"), demo_image())
    write_doors(out / "doors.csv", demo_signs())
    scen = {
        "name": "demo",
        "map": {"image": "map.png", "resolution": RES},
        "start": {"x": START[0], "y": START[1], "heading": "random"},
        "doors": "doors.csv",
        "goals": list(goals),
        "planners": planners or [{"name": "greedy"}, {"name": "bvp"}],
        "experiment": {"seeds": seeds, "base_seed": 0, "max_distance": 500.0},
    }
    path = out / "scenario.yaml"
    path.write_text(yaml.safe_dump(scen, sort_keys=False))
    return path
