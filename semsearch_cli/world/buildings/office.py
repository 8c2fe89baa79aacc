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
