"""Our hospital floor for chained searches (thesis ch. 6): 44 m x 20 m, twenty numbered rooms off
a main corridor (2 m wide, east-west) crossed by a second corridor (north-south) in the middle.

Rooms 1, 3, ..., 19 lie north of the main corridor and 2, 4, ..., 20 south of it, numbers rising
from west to east; each room has a 1 m door in the corridor wall with its sign just east of the
door, facing the corridor. The start lies at the south end of the cross corridor. Rooms 5, 12, 15
and 18 hold object places (two each, named by the room: 12a, 12b, ...): a laptop that moves
between 12a and 12b over the day, a mug between 15a and 15b, a monitor fixed at 18a, books at 5a
and 18b.
"""

from __future__ import annotations

import numpy as np

from ..scenario_folder import corridor_floor

WIDTH_M, HEIGHT_M = 44.0, 20.0
WALL_M = 0.15
CORRIDOR = (9.0, 11.0)  # y range of the main corridor, m
CROSS = (21.0, 23.0)  # x range of the cross corridor, m
ROOMS_PER_SIDE = 5  # rooms on each side of the cross corridor, north and south
DOOR_M = 1.0
START = (22.0, 1.5)


def _room_spans() -> list[tuple[float, float]]:
    """x ranges of the rooms along one side, west to east."""
    west = np.linspace(0.0, CROSS[0], ROOMS_PER_SIDE + 1)
    east = np.linspace(CROSS[1], WIDTH_M, ROOMS_PER_SIDE + 1)
    return [(a, b) for a, b in zip(west, west[1:])] + [(a, b) for a, b in zip(east, east[1:])]


def rooms() -> list[tuple[int, float, float, str]]:
    """(number, door centre x, sign x, side) for every room; side ``north`` or ``south``."""
    out = []
    for k, (a, b) in enumerate(_room_spans()):
        door = a + 1.2
        out.append((2 * k + 1, door, door + 0.9, "north"))
        out.append((2 * k + 2, door, door + 0.9, "south"))
    return out


def hospital_image(res: float = 0.1) -> np.ndarray:
    """(H, W) uint8 map: 255 free, 0 wall."""
    img, box = corridor_floor(WIDTH_M, HEIGHT_M, WALL_M, CORRIDOR, res)
    lo, hi = CORRIDOR
    box(CROSS[0] - WALL_M, CROSS[0], 0, HEIGHT_M, 0)  # the cross corridor's walls
    box(CROSS[1], CROSS[1] + WALL_M, 0, HEIGHT_M, 0)
    box(CROSS[0], CROSS[1], 0, HEIGHT_M, 255)
    for a, b in _room_spans()[1:]:
        if abs(a - CROSS[1]) > 1e-6:
            box(a - WALL_M / 2, a + WALL_M / 2, 0, HEIGHT_M, 0)  # walls between rooms
    box(CROSS[0], CROSS[1], WALL_M, HEIGHT_M - WALL_M, 255)
    box(WALL_M, WIDTH_M - WALL_M, lo, hi, 255)  # the main corridor itself
    for _, door, _, side in rooms():
        y0, y1 = (hi, hi + WALL_M) if side == "north" else (lo - WALL_M, lo)
        box(door - DOOR_M / 2, door + DOOR_M / 2, y0, y1, 255)
    return img


def hospital_signs() -> list[tuple[int, float, float, float]]:
    """(number, x, y, facing degrees): each sign on the corridor wall east of its door."""
    lo, hi = CORRIDOR
    return [(n, round(float(sx), 2), hi + 0.05 if side == "north" else lo - 0.05, -90.0 if side == "north" else 90.0)
            for n, _, sx, side in rooms()]


def _places() -> list[dict]:
    doors = {n: d for n, d, _, _ in rooms()}
    out = []
    for n in (5, 12, 15, 18):
        north = n % 2 == 1
        y = 17.5 if north else 2.5
        out.append({"name": f"P{n}a", "x": round(float(doors[n]) - 0.5, 2), "y": y, "room": n})
        out.append({"name": f"P{n}b", "x": round(float(doors[n]) + 2.3, 2), "y": 15.0 if north else 5.0, "room": n})
    return out


HOURS = [3, 5, 7, 9, 11, 15, 17, 19, 21, 23]
TIMELINES = {
    "Weekday": {"laptop": {7: "P12a", 13: "P12b", 18: "P12a"}, "mug": {8: "P15b", 12: "P15a", 20: "P15b"}},
}
CHAINS = [
    {"name": "disinfect", "stages": [{"door": 12}, {"door": 15}, {"door": 3}]},
    {"name": "ward-round", "stages": [{"door": 7}, {"door": 16}, {"door": 12}, {"door": 7}, {"door": 20}]},
    {"name": "fetch", "record": ["Weekday"], "truth": "Weekday",
     "stages": [{"door": 12, "object": "laptop", "hour": 11}, {"door": 15, "object": "mug", "hour": 16}, {"door": 12}]},
    {"name": "night", "record": ["Weekday"], "truth": "Weekday", "object_planner": "brute_force",
     "stages": [{"door": 18, "object": "monitor", "hour": 2}, {"door": 5}, {"door": 15, "object": "mug", "hour": 23}]},
]


def hospital_scenario(image: str = "map.png", doors: str = "doors.csv", res: float = 0.1) -> dict:
    return {
        "name": "hospital",
        "map": {"image": image, "resolution": res},
        "start": {"x": START[0], "y": START[1], "heading": "random"},
        "doors": doors,
        "objects": {
            "camera": {"fov": 60.0, "range": 3.0, "p_detect": 0.9},
            "places": _places(),
            "fixed": {"P18a": "monitor", "P5a": "book", "P18b": "book"},
            "recording_hours": HOURS,
            "timelines": TIMELINES,
        },
        "chains": CHAINS,
        "planners": [{"name": "greedy"}, {"name": "nsos", "alpha": 0.9}],
        "belief": {"density_delta": 2.5},
        "experiment": {"seeds": 5, "base_seed": 0, "max_distance": 3000.0},
    }
