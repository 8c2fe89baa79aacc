"""Rooms for indirect search (Loncomilla et al. 2018, Section 4.5).

A room is a rectangle (6 m x 6 m by default) holding the main object A and the secondary objects,
each with a position, a height and a yaw (a multiple of 45 degrees), optional box obstacles, and
the robot's start pose. The generator follows the paper: A uniform in the room; each secondary
object draws a spatial category (VN, N, F, VF) from its co-occurrences with A (Table 2), then a
position uniform over the area of that ring around A (VF: from u3 out to the room's diagonal),
redrawn until it lies in the room, off the obstacles and away from the other objects. Where the
paper is silent (ours): objects keep 0.25 m from walls and obstacles and 0.3 m from each other;
obstacles are boxes 0.4-1.2 m a side; the start is uniform over the free space with a uniform
heading.

File format (``rooms.yaml``)::

    size: [6.0, 6.0]
    rooms:
    - name: room00
      start: {x: 1.0, y: 2.0, heading: 90}
      objects:
        monitor: {x: 3.1, y: 4.2, height: 0.5, yaw: 45}
        keyboard: {...}
      obstacles: [[x0, y0, x1, y1], ...]
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from ..config import read_yaml
from ..config.indirect import CATEGORIES, MasksSpec
from ..errors import ScenarioError
from ..geometry import GridFrame
from ..files import temp_path

WALL_MARGIN = 0.25  # m, objects and the start keep this from walls and obstacles
OBJECT_GAP = 0.3  # m, between objects
MAX_TRIES = 2000


@dataclass(frozen=True)
class Thing:
    """One object: its class, centre (m), height of the centre above the floor (m), yaw (deg)."""

    cls: str
    x: float
    y: float
    height: float = 0.5
    yaw: float = 0.0


@dataclass
class Room:
    name: str
    size: tuple[float, float]
    objects: dict[str, Thing]
    start: tuple[float, float, float]  # x, y (m), heading (deg)
    obstacles: list[tuple[float, float, float, float]] = field(default_factory=list)

    def frame(self, res: float) -> GridFrame:
        """The room's grid at ``res`` m/cell (origin at the room's corner (0, 0))."""
        w, h = self.size
        return GridFrame(res, 0.0, 0.0, int(round(h / res)), int(round(w / res)))

    def blocked(self, frame: GridFrame) -> np.ndarray:
        """(H, W) bool on ``frame``: True where a cell's centre is in an obstacle box."""
        xs, ys = frame.to_world(np.arange(frame.height)[:, None], np.arange(frame.width)[None, :])
        out = np.zeros((frame.height, frame.width), bool)
        for x0, y0, x1, y1 in self.obstacles:
            out |= (xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1)
        return out

    def is_free(self, x: float, y: float, margin: float = WALL_MARGIN) -> bool:
        w, h = self.size
        if not (margin <= x <= w - margin and margin <= y <= h - margin):
            return False
        return not any(x0 - margin <= x <= x1 + margin and y0 - margin <= y <= y1 + margin
                       for x0, y0, x1, y1 in self.obstacles)

    def to_dict(self) -> dict:
        return {"name": self.name, "start": {"x": round(self.start[0], 3), "y": round(self.start[1], 3),
                                             "heading": round(self.start[2], 1)},
                "objects": {k: {"x": round(t.x, 3), "y": round(t.y, 3), "height": t.height, "yaw": t.yaw}
                            for k, t in self.objects.items()},
                "obstacles": [[round(v, 3) for v in b] for b in self.obstacles]}


def ring(category: str, masks: MasksSpec, far: float) -> tuple[float, float]:
    """Inner and outer radius (m) of a spatial category's ring around A (VF reaches ``far``)."""
    edges = (0.0, masks.u1, masks.u2, masks.u3, far)
    k = CATEGORIES.index(category)
    return edges[k], max(edges[k + 1], edges[k])


def generate_room(name: str, rng: np.random.Generator, relations: dict, masks: MasksSpec, target: str = "monitor",
                  size: tuple[float, float] = (6.0, 6.0), n_obstacles: int = 0, height: float = 0.5) -> Room:
    w, h = size
    room = Room(name, (float(w), float(h)), {}, (0.0, 0.0, 0.0))
    for _ in range(n_obstacles):
        for _ in range(MAX_TRIES):
            bw, bh = rng.uniform(0.4, 1.2, 2)
            x0, y0 = rng.uniform(0, w - bw), rng.uniform(0, h - bh)
            box = (float(x0), float(y0), float(x0 + bw), float(y0 + bh))
            # keep a free band around every box so the room stays connected
            if all(box[0] > b[2] + 0.8 or box[2] < b[0] - 0.8 or box[1] > b[3] + 0.8 or box[3] < b[1] - 0.8
                   for b in room.obstacles):
                room.obstacles.append(box)
                break

    def place(cx: float, cy: float, lo: float, hi: float) -> tuple[float, float] | None:
        for _ in range(MAX_TRIES):
            r = np.sqrt(rng.uniform(lo * lo, hi * hi))  # uniform over the ring's area
            a = rng.uniform(-np.pi, np.pi)
            x, y = cx + r * np.cos(a), cy + r * np.sin(a)
            if room.is_free(x, y) and all(np.hypot(x - t.x, y - t.y) >= OBJECT_GAP for t in room.objects.values()):
                return float(x), float(y)
        return None

    far = float(np.hypot(w, h))
    a = place(w / 2, h / 2, 0.0, far)
    if a is None:
        raise ValueError(f"{name}: no free place for {target}; fewer obstacles?")
    room.objects[target] = Thing(target, *a, height, float(45 * rng.integers(8)))
    for cls, row in relations.items():
        p = np.asarray(row, float)
        for _ in range(100):
            cat = CATEGORIES[int(rng.choice(4, p=p / p.sum()))]
            xy = place(*a, *ring(cat, masks, far))
            if xy is not None:
                break
        else:
            raise ValueError(f"{name}: no free place for {cls}")
        room.objects[cls] = Thing(cls, *xy, height, float(45 * rng.integers(8)))
    for _ in range(MAX_TRIES):
        x, y = rng.uniform(0, w), rng.uniform(0, h)
        if room.is_free(x, y) and all(np.hypot(x - t.x, y - t.y) >= OBJECT_GAP for t in room.objects.values()):
            room.start = (float(x), float(y), float(rng.uniform(-180.0, 180.0)))
            break
    return room


def generate_rooms(n: int, seed: int, relations: dict, masks: MasksSpec, target: str = "monitor",
                   size: tuple[float, float] = (6.0, 6.0), n_obstacles: int = 0) -> list[Room]:
    """``n`` rooms from one seed (room k draws from its own stream, so room k is the same
    whatever ``n``)."""
    streams = np.random.SeedSequence(seed).spawn(n)
    return [generate_room(f"room{k:02d}", np.random.default_rng(s), relations, masks, target, size, n_obstacles)
            for k, s in enumerate(streams)]


def estimate_relations(rooms: list[Room], target: str, secondary: list[str], masks: MasksSpec) -> dict[str, tuple]:
    """Co-occurrences (VN, N, F, VF) of each secondary class around ``target`` as a robot would
    learn them from these rooms: each object's distance to the target falls in one category (u1,
    u2, u3) and is counted there; the shares are add-one smoothed (Laplace), so that a category no
    training room happened to show is unlikely, not impossible (with a zero weight, one detection
    of the class would rule out every cell at that distance)."""
    edges = (masks.u1, masks.u2, masks.u3)
    out = {}
    for cls in secondary:
        counts = np.ones(len(CATEGORIES))
        for r in rooms:
            a, b = r.objects[target], r.objects[cls]
            counts[int(np.searchsorted(edges, np.hypot(b.x - a.x, b.y - a.y), side="right"))] += 1
        out[cls] = tuple(float(c) for c in counts / counts.sum())
    return out


def write_rooms(path: Path, rooms: list[Room]) -> Path:
    path = Path(path)
    size = rooms[0].size if rooms else (6.0, 6.0)
    text = yaml.safe_dump({"size": list(size), "rooms": [r.to_dict() for r in rooms]}, sort_keys=False,
                          default_flow_style=None)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(path)
    tmp.write_text("# rooms for indirect search: semsearch generate rooms\n" + text)
    os.replace(tmp, path)
    return path


def read_rooms(path: Path, target: str, secondary: list[str]) -> list[Room]:
    """Rooms from a rooms.yaml; errors name the file and the field."""
    path = Path(path)
    data = read_yaml(path, "rooms file")
    if not isinstance(data, dict) or not isinstance(data.get("rooms"), list) or not data["rooms"]:
        raise ScenarioError(str(path), "rooms", "expected a list of rooms")
    try:
        w, h = (float(v) for v in data.get("size", (6.0, 6.0)))
        if not (1.0 <= w <= 50.0 and 1.0 <= h <= 50.0):  # NaN fails too
            raise ValueError
    except (TypeError, ValueError):
        raise ScenarioError(str(path), "size", "expected [width, depth] in metres, each 1 to 50") from None
    rooms = []
    for k, d in enumerate(data["rooms"]):
        where = f"rooms[{k}]"
        try:
            objs = {}
            for cls in [target, *secondary]:
                o = d["objects"].get(cls)
                if o is None:
                    raise ScenarioError(str(path), f"{where}.objects", f"no {cls} (the scenario needs {target} and "
                                        f"{', '.join(secondary)})")
                yaw = float(o.get("yaw", 0.0))
                if yaw % 45:
                    raise ScenarioError(str(path), f"{where}.objects.{cls}.yaw", f"a multiple of 45 degrees (got {yaw:g})")
                objs[cls] = Thing(cls, float(o["x"]), float(o["y"]), float(o.get("height", 0.5)), yaw)
            s = d["start"]
            room = Room(str(d.get("name", f"room{k:02d}")), (w, h), objs, (float(s["x"]), float(s["y"]), float(s.get("heading", 0.0))),
                        [tuple(float(v) for v in b) for b in d.get("obstacles") or []])
        except ScenarioError:
            raise
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise ScenarioError(str(path), where, f"expected name, start {{x, y, heading}}, objects {{class: {{x, y, "
                                f"height, yaw}}}} and optional obstacles [[x0, y0, x1, y1]] ({exc})") from None
        for cls, t in objs.items():
            if not (0 <= t.x <= w and 0 <= t.y <= h):
                raise ScenarioError(str(path), f"{where}.objects.{cls}", f"({t.x:g}, {t.y:g}) is outside the {w:g} x {h:g} m room")
        if not room.is_free(*room.start[:2], margin=0.0):
            raise ScenarioError(str(path), f"{where}.start", "the start is outside the room or in an obstacle")
        rooms.append(room)
    return rooms
