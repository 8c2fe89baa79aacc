"""Our office for object search (thesis 5.3.1): 20.5 m x 14.5 m, seven rooms off one corridor,
ten object places A-J, the start R in the middle of the corridor.

Four rooms lie above the corridor and three below. The patrol route (thesis Fig. 5.11) runs
clockwise: A and B in the top-left room, C, D, then E and F in the top-right room, G and H in the
bottom-right room, I, J, and back to R; A and H lie in opposite directions from R, as in the thesis.
"""

from __future__ import annotations

import numpy as np

from ..scenario_folder import corridor_floor

WIDTH_M, HEIGHT_M = 20.5, 14.5
WALL_M = 0.15
CORRIDOR = (6.0, 8.0)  # y range, m
TOP_SPLITS = (5.1, 10.2, 15.3)  # x of the walls between the top rooms
BOTTOM_SPLITS = (6.8, 13.7)
TOP_DOORS = (2.6, 7.7, 12.8, 17.9)  # door centres, m
BOTTOM_DOORS = (3.4, 10.25, 17.1)
DOOR_M = 1.0
START = (10.25, 7.0)
PLACES = {
    "A": (1.0, 13.4), "B": (4.3, 10.0), "C": (7.7, 13.4), "D": (12.8, 13.4), "E": (16.3, 13.4),
    "F": (19.5, 10.0), "G": (19.5, 4.6), "H": (19.5, 1.0), "I": (10.25, 1.0), "J": (1.0, 1.0),
}
FIXED = {"B": "book", "C": "laptop", "D": "book", "E": "smartphone", "F": "laptop", "G": "smartphone",
         "I": "book", "J": "laptop"}
# thesis Table 5.1: where the mug was seen at each recording hour
HOURS = [3, 5, 7, 9, 11, 15, 17, 19, 21, 23]
TABLE_5_1 = {
    "Static": "AAAAAHHHHH",
    "Static-Inv": "HHHHHAAAAA",
    "Mobile": "AHAHAHAHAH",
    "Mobile-Inv": "HAHAHAHAHA",
    "Shift": "HHHHAAAAAH",
}


def office_image(res: float = 0.05) -> np.ndarray:
    """(H, W) uint8 map: 255 free, 0 wall."""
    img, box = corridor_floor(WIDTH_M, HEIGHT_M, WALL_M, CORRIDOR, res)
    lo, hi = CORRIDOR
    for x in TOP_SPLITS:
        box(x, x + WALL_M, hi, HEIGHT_M, 0)
    for x in BOTTOM_SPLITS:
        box(x, x + WALL_M, 0, lo, 0)
    for x in TOP_DOORS:
        box(x - DOOR_M / 2, x + DOOR_M / 2, hi, hi + WALL_M, 255)
    for x in BOTTOM_DOORS:
        box(x - DOOR_M / 2, x + DOOR_M / 2, lo - WALL_M, lo, 255)
    return img


def office_scenario(res: float = 0.05, image: str = "map.png") -> dict:
    """The scenario of thesis 5.3.3-5.3.4: the five patterns, requests at 12:00 and 00:00, the
    combined-patterns run and the moved-mug run."""
    timelines = {name: {"mug": dict(zip(HOURS, seq))} for name, seq in TABLE_5_1.items()}
    cases = [{"name": n, "record": [n], "truth": n} for n in TABLE_5_1]
    cases.append({"name": "Combined", "record": list(TABLE_5_1), "truth": "Mobile-Inv"})
    cases.append({"name": "Moved-mug", "record": ["Mobile-Inv"], "truth": "Mobile-Inv",
                  "requests": [{"class": "mug", "hour": 0, "at": ["H"]}]})
    return {
        "name": "office",
        "map": {"image": image, "resolution": res},
        "start": {"x": START[0], "y": START[1], "heading": "random"},
        "objects": {
            "camera": {"fov": 60.0, "range": 3.0, "p_detect": 0.9},
            "places": [{"name": k, "x": v[0], "y": v[1]} for k, v in PLACES.items()],
            "fixed": dict(FIXED),
            "route": list(PLACES),
            "recording_hours": HOURS,
            "timelines": timelines,
            "requests": [{"class": "mug", "hour": 12}, {"class": "mug", "hour": 0}],
            "cases": cases,
        },
        "planners": [{"name": "brute_force"}, {"name": "last_seen"}, {"name": "lsos"}],
        "experiment": {"seeds": 10, "base_seed": 0, "max_distance": 500.0},
    }


def random_office(rng: np.random.Generator, res: float = 0.05, name: str = "office") -> tuple[np.ndarray, dict]:
    """An office drawn like ours (rooms off one corridor, a place or two per room, the thesis'
    five mug patterns and its combined and moved-mug cases), for semsearch-bench's objects test
    split: 18-26 m wide, 3-5 rooms above the corridor and 2-4 below (each at least 3.5 m wide),
    each room's door anywhere along its corridor wall, one place per room (two in a room 5 m or
    wider, one time in two) at least 0.8 m from its walls, the other objects fixed as in the
    thesis (a book, a laptop or a smartphone at every place but the mug's two), the mug's two
    places (the thesis' A and H) one above and one below the corridor, each toward an end of the
    office (a quarter of its width or more from its middle, where the robot starts).
    Returns (the map image, the scenario)."""
    width = float(rng.uniform(18.0, 26.0))
    lo, hi = CORRIDOR
    img, box = corridor_floor(width, HEIGHT_M, WALL_M, CORRIDOR, res)
    places, rooms = {}, []
    letters = iter("ABCDEFGHJKLMNPQRSTUV")
    for side, n in (("top", int(rng.integers(3, 6))), ("bottom", int(rng.integers(2, 5)))):
        inner = width - 2 * WALL_M
        cuts = np.sort(rng.uniform(0.0, 1.0, n - 1)) if n > 1 else np.zeros(0)
        edges = WALL_M + inner * np.r_[0.0, cuts, 1.0]
        while n > 1 and np.diff(edges).min() < 3.5:  # rooms at least 3.5 m wide: spread the cuts evenly, jittered
            edges = WALL_M + inner * np.r_[0.0, np.sort(np.arange(1, n) / n + rng.uniform(-0.03, 0.03, n - 1)), 1.0]
        y0, y1 = (hi + WALL_M, HEIGHT_M - WALL_M) if side == "top" else (WALL_M, lo - WALL_M)
        for x0, x1 in zip(edges[:-1], edges[1:]):
            if x0 > WALL_M:
                box(x0, x0 + WALL_M, y0 - WALL_M if side == "top" else 0.0, HEIGHT_M if side == "top" else lo, 0)
            door = float(rng.uniform(x0 + WALL_M + DOOR_M / 2 + 0.2, x1 - DOOR_M / 2 - 0.2))
            wy = (hi, hi + WALL_M) if side == "top" else (lo - WALL_M, lo)
            box(door - DOOR_M / 2, door + DOOR_M / 2, *wy, 255)
            k = 2 if x1 - x0 >= 5.0 and rng.random() < 0.5 else 1
            for _ in range(k):
                px = float(rng.uniform(x0 + WALL_M + 0.8, x1 - 0.8))
                py = float(rng.uniform(y0 + 0.8, y1 - 0.8))
                places[next(letters)] = (round(px, 2), round(py, 2))
            rooms.append(side)
    names = list(places)
    top = [p for p in names if places[p][1] > hi]
    bottom = [p for p in names if places[p][1] < lo]
    def far(group):  # a place toward an end of the office (as the thesis' A and H), not beside the start
        off = {p: abs(places[p][0] - width / 2) for p in group}
        pool = [p for p in group if off[p] >= 0.25 * width] or [max(group, key=off.get)]
        return str(rng.choice(pool))

    a, h = far(top), far(bottom)
    route = top + bottom[::-1]  # clockwise: along the top rooms, back along the bottom ones
    kinds = ("book", "laptop", "smartphone")
    fixed = {p: kinds[int(rng.integers(3))] for p in names if p not in (a, h)}
    timelines = {n: {"mug": {hr: (a if c == "A" else h) for hr, c in zip(HOURS, seq)}} for n, seq in TABLE_5_1.items()}
    cases = [{"name": n, "record": [n], "truth": n} for n in TABLE_5_1]
    cases.append({"name": "Combined", "record": list(TABLE_5_1), "truth": "Mobile-Inv"})
    cases.append({"name": "Moved-mug", "record": ["Mobile-Inv"], "truth": "Mobile-Inv",
                  "requests": [{"class": "mug", "hour": 0, "at": [h]}]})
    scen = office_scenario(res)
    scen["name"] = name
    scen["start"] = {"x": round(width / 2, 2), "y": (lo + hi) / 2, "heading": "random"}
    scen["objects"].update(places=[{"name": k, "x": v[0], "y": v[1]} for k, v in places.items()], fixed=fixed, route=route,
                           timelines=timelines, cases=cases)
    return img, scen
