"""The ground-truth world built from a scenario: map grid, door signs, start; checks.

Map images: gray value < 100 is wall, >= 200 free, anything between is "outside" (never entered,
blocks beams like a wall). The world is immutable once built and shared by every run of a batch.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import cv2
import numpy as np

from ..config import DoorSpec, OnMap, Scenario, SignSections, read_yaml
from ..config.base import label_column, number_text
from ..errors import ScenarioError
from ..files import read_user_text
from ..geometry import GridFrame
from ..kernels.grid import GridSearch
from ..kernels.raycast import line_of_sight
from .images import read_gray
from .ros_map import clean_free, read_ros_map

WALL_BELOW = 100
FREE_FROM = 200


@dataclass(frozen=True)
class Signs:
    """Door signs. ``number`` keeps labels as given; ``value`` is the integer or -1 for text labels.

    x, y : (n,) float64, m; facing : (n,) float64, radians.
    """

    number: tuple
    value: np.ndarray
    x: np.ndarray
    y: np.ndarray
    facing: np.ndarray

    def __len__(self) -> int:
        return len(self.number)

    def walls(self, across: float = 0.3, gap: float = 12.0) -> np.ndarray:
        """(n,) int: a stretch of wall per sign, from the ground truth: signs facing the same way
        (within a degree) whose faces lie within ``across`` m of one line, split where two
        neighbours along it are more than ``gap`` m apart (a junction's far side is another
        stretch)."""
        n = len(self.number)
        out = np.full(n, -1, np.int64)
        fx, fy = np.cos(self.facing), np.sin(self.facing)
        todo = list(range(n))
        wall = 0
        while todo:
            i = todo[0]
            same = [j for j in todo if fx[i] * fx[j] + fy[i] * fy[j] > np.cos(np.radians(1.0))
                    and abs((self.x[j] - self.x[i]) * fx[i] + (self.y[j] - self.y[i]) * fy[i]) < across]
            t = np.array([-(self.x[j] * fy[i]) + self.y[j] * fx[i] for j in same])  # along the wall
            order = np.argsort(t, kind="stable")
            cut = np.flatnonzero(np.diff(t[order]) > gap) + 1
            for part in np.split(order, cut):
                out[[same[k] for k in part]] = wall
                wall += 1
            done = set(same)
            todo = [j for j in todo if j not in done]
        return out

    def index_of(self, label) -> int:
        """The first sign carrying ``label``, or -1."""
        key = str(label)
        for i, n in enumerate(self.number):
            if str(n) == key:
                return i
        return -1

    def indices_of(self, label) -> list[int]:
        """Every sign carrying ``label`` (more than one under ``duplicates: any``)."""
        key = str(label)
        return [i for i, n in enumerate(self.number) if str(n) == key]


def read_doors(path: Path, field: str = "doors", owner: str | None = None) -> list[DoorSpec]:
    """Door signs from a CSV (columns number,x,y,facing) or YAML list file."""
    rows: list[dict]
    if path.suffix.lower() in (".yaml", ".yml"):
        rows = read_yaml(path, "door file", owner, field) or []
        if not isinstance(rows, list):
            raise ScenarioError(str(path), "", "expected a YAML list of signs, each {number, x, y, facing}")
    else:
        reader = csv.DictReader(io.StringIO(read_user_text(path, "door file", owner, field), newline=""))
        need = {"number", "x", "y", "facing"}
        if reader.fieldnames is None or not need <= set(reader.fieldnames):
            raise ScenarioError(str(path), field, f"expected CSV columns number,x,y,facing (got {reader.fieldnames})")
        rows = []
        for row in reader:  # a row of more or fewer fields than the header is no sign
            if None in row or None in row.values():
                fields = [v for k, v in row.items() if k is not None and v is not None] + list(row.get(None) or ())
                raise ScenarioError(str(path), f"line {reader.line_num}", f"{len(fields)} fields ({','.join(fields)}); "
                                    f"expected {len(reader.fieldnames)}, one per column of the header "
                                    f"({','.join(reader.fieldnames)})")
            rows.append(row)
    out = []
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            raise ScenarioError(str(path), f"row {i + 1}", f"expected a sign {{number, x, y, facing}}, got {row!r}")
    if rows and all("number" in r for r in rows):  # a spreadsheet's column of floats (304.0) is its numbers
        try:
            rows = [{**r, "number": n} for r, n in zip(rows, label_column([r["number"] for r in rows]))]
        except ValueError:
            pass  # each row's own label then names what is wrong, below
    for i, row in enumerate(rows):
        try:
            out.append(DoorSpec(number=row["number"], x=number_text(row["x"]), y=number_text(row["y"]),
                                facing=number_text(row["facing"])))
        except (KeyError, ValueError, TypeError) as exc:
            raise ScenarioError(str(path), f"row {i + 1}", f"cannot read a door sign from {row!r}: {exc}") from None
    return out


def load_map(path: Path, field: str = "map.image", owner: str | None = None) -> np.ndarray:
    """Gray image (H, W) uint8 of a map file (see :func:`~semsearch_cli.world.images.read_gray`)."""
    return read_gray(path, "map image", owner, field)


@dataclass(frozen=True)
class World:
    """Ground truth of one scenario.

    Attributes
    ----------
    frame : GridFrame
    free : (H, W) bool
        Free cells of the map image.
    signs : Signs
    start_xy : (float, float), m
    start_heading : float or None
        Radians, or None for a random heading per run.
    radius : float
        Robot radius, m.
    """

    frame: GridFrame
    free: np.ndarray
    signs: Signs
    start_xy: tuple[float, float]
    start_heading: float | None
    radius: float
    read_range: float
    read_fov: float = np.radians(60.0)
    duplicates: dict = field(default_factory=dict)  # number -> [(x, y) m] of every sign carrying it, when > 1

    @cached_property
    def occ(self) -> np.ndarray:
        return ~self.free

    @cached_property
    def clearance(self) -> np.ndarray:
        """(H, W) float32, m: distance from each cell centre to the nearest blocked cell centre."""
        d = cv2.distanceTransform(self.free.astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        return d * np.float32(self.frame.res)

    @cached_property
    def cspace(self) -> np.ndarray:
        """(H, W) bool: cells where the robot disk fits (clearance >= radius + half a cell)."""
        return self.clearance >= self.radius + 0.5 * self.frame.res - 1e-6

    @cached_property
    def start_cell(self) -> tuple[int, int]:
        r, c = self.frame.to_index(*self.start_xy)
        return int(r), int(c)

    @cached_property
    def reach(self) -> np.ndarray:
        """(H, W) bool: c-space cells 4-connected to the start."""
        n, lab = cv2.connectedComponents(self.cspace.astype(np.uint8), connectivity=4)
        r, c = self.start_cell
        if not self.cspace[r, c]:
            return np.zeros_like(self.cspace)
        return lab == lab[r, c]

    def sight_mask(self, x: float, y: float, rng: float, stop_short: float, facing: float | None = None,
                   within: np.ndarray | None = None) -> np.ndarray:
        """(H, W) bool: cells of ``within`` (default: reachable) within ``rng`` m of the point
        (x, y) and in line of sight of it (the last ``stop_short`` cells of the line unchecked);
        with ``facing`` (radians), only cells in front of it."""
        within = self.reach if within is None else within
        fr = self.frame
        v, u = fr.to_cell(x, y)
        R = int(np.ceil(rng / fr.res)) + 1
        r0, r1 = max(0, int(v) - R), min(fr.height, int(v) + R + 1)
        c0, c1 = max(0, int(u) - R), min(fr.width, int(u) + R + 1)
        out = np.zeros(self.free.shape, bool)
        rr, cc = np.nonzero(within[r0:r1, c0:c1])
        rr += r0
        cc += c0
        px, py = fr.to_world(rr, cc)
        dx, dy = px - x, py - y
        ok = dx * dx + dy * dy <= rng * rng
        if facing is not None:
            ok &= dx * np.cos(facing) + dy * np.sin(facing) > 0
        occ = self.occ
        for r, c in zip(rr[ok], cc[ok]):
            if line_of_sight(occ, r + 0.5, c + 0.5, float(v), float(u), stop_short):
                out[r, c] = True
        return out

    def readable_mask(self, i: int, within: np.ndarray | None = None) -> np.ndarray:
        """(H, W) bool: cells of ``within`` (default: reachable) from which sign ``i`` can be read.

        A pose reads a sign within camera range, in line of sight, in front of the sign's face
       ; the side cameras can always be turned onto it, so heading is free.
        """
        s = self.signs
        return self.sight_mask(s.x[i], s.y[i], self.read_range, 0.75, s.facing[i], within)

    def shortest_path(self, label) -> float:
        """Ground-truth geodesic (m), with the robot's clearance, from the start to the pose that
        reads sign ``label``; inf when no reachable pose reads it.

        The reading pose is the reachable cell nearest to the sign among those that see its face
        (the robot abreast of the door). With side cameras whose field of view is centred on the
        perpendicular (60 degrees by default), a robot travelling along a corridor reads a sign
        only when nearly abreast of it, so this is the shortest distance a search can achieve;
        it is also how the thesis measured Tables 4.6-4.8 (ours agree within 10% on all 12 goals
        of the three reference maps, whereas the distance to the edge of the 3 m read disk is
        5-30% shorter than the published values).
        """
        target = self.reading_cells(label)
        if not target.any():
            return float("inf")
        return self.geodesic(self.start_cell, target)[0]

    def reading_cells(self, label) -> np.ndarray:
        """(H, W) bool: the reachable cells nearest to sign ``label`` among those that read it
        (the robot abreast of the door), for every sign carrying the label; empty when no
        reachable pose reads one."""
        target = np.zeros(self.free.shape, bool)
        for i in self.signs.indices_of(label):  # several signs under duplicates: any; the nearest wins
            disk = self.readable_mask(i)
            if not disk.any():
                continue
            rr, cc = np.nonzero(disk)
            x, y = self.frame.to_world(rr, cc)
            d = np.hypot(x - self.signs.x[i], y - self.signs.y[i])
            near = d <= d.min() + 0.5 * self.frame.res
            target[rr[near], cc[near]] = True
        return target

    def geodesic(self, cell: tuple[int, int], target: np.ndarray) -> tuple[float, tuple[int, int] | None]:
        """Ground-truth geodesic (m), with the robot's clearance, from ``cell`` to the nearest cell
        of ``target``, and that cell; (inf, None) when none is reachable."""
        r, c = cell
        tr, tc = np.nonzero(target)  # row-major, as the first nearest target was picked before
        gs = GridSearch(self.reach.shape)  # read at the targets only: no map-sized result arrays
        gs.run(self.reach, np.ones((1, 1), np.float32), r, c, tr, tc, 1, np.inf)
        lengths = gs.lengths(tr, tc)
        if not lengths.size or not np.isfinite(lengths.min()):
            return float("inf"), None
        k = int(np.argmin(lengths))
        return float(lengths[k] * self.frame.res), (int(tr[k]), int(tc[k]))


def build_world(sc: Scenario, base: Path, file: str) -> World | None:
    """Build and check the world of a scenario (paths relative to ``base``); None for a scenario
    without a map (one that brings rooms of its own)."""
    if not isinstance(sc, OnMap):
        return None
    if sc.map.ros is not None:
        img, res, origin = read_ros_map(base / sc.map.ros, owner=file)
        map_field = "map.ros"
    else:
        img, res, origin = load_map(base / sc.map.image, owner=file), sc.map.resolution, sc.map.origin
        map_field = "map.image"
    H, W = img.shape
    frame = GridFrame(res, origin[0], origin[1], H, W)
    if sc.map.clean:
        r, c = frame.to_index(sc.start.x, sc.start.y)
        if not (0 <= r < H and 0 <= c < W) or img[r, c] < FREE_FROM:
            raise ScenarioError(file, "start", f"map.clean keeps the free space reachable from the start, and the start "
                                f"({sc.start.x:g}, {sc.start.y:g}) m is not on a free cell")
        img = clean_free(img, res, (int(r), int(c)), sc.robot.radius)[0]
    free = img >= FREE_FROM
    if not free.any():
        raise ScenarioError(file, map_field, f"the map has no free cells (light pixels, >= {FREE_FROM} of 255; a 16-bit image "
                            "is scaled to 8 bits): is it inverted, or all dark?")
    extent = (f"the map spans x {origin[0]:g} to {origin[0] + W * res:g} m and y {origin[1]:g} to {origin[1] + H * res:g} m "
              f"({W} x {H} cells of {res:g} m" + (", map.resolution" if sc.map.image is not None else "") + ")")

    signed = sc if isinstance(sc, SignSections) else SignSections()  # a kind that reads no signs: none
    doors = read_doors(base / signed.doors, owner=file) if isinstance(signed.doors, str) else list(signed.doors)
    dfile = str(base / signed.doors) if isinstance(signed.doors, str) else file
    doors, duplicates = apply_duplicates(doors, signed.duplicates, dfile)
    labels = [d.number for d in doors]
    signs = Signs(
        number=tuple(labels),
        value=np.array([lab if isinstance(lab, int) else -1 for lab in labels], np.int64),
        x=np.array([d.x for d in doors], np.float64),
        y=np.array([d.y for d in doors], np.float64),
        facing=np.radians(np.array([d.facing for d in doors], np.float64)),
    )
    heading = None if sc.start.heading == "random" else float(np.radians(sc.start.heading))
    world = World(frame, free, signs, (sc.start.x, sc.start.y), heading, sc.robot.radius, signed.door_camera.range,
                  float(np.radians(signed.door_camera.fov)), duplicates)
    # every sign must sit next to free space, and the start where the robot fits
    r, c = frame.to_index(signs.x, signs.y)
    pad = np.pad(free, 2)
    bad = [k for k in range(len(signs)) if not (0 <= r[k] < H and 0 <= c[k] < W)
           or not pad[r[k] : r[k] + 5, c[k] : c[k] + 5].any()]
    sr, scc = world.start_cell
    start_in = 0 <= sr < H and 0 <= scc < W
    start_ok = start_in and bool(world.cspace[sr, scc])
    if not start_ok and bad:
        # start and signs wrong together: the map's scale or origin is wrong, not each position
        raise ScenarioError(file, "map.resolution" if sc.map.image is not None else map_field,
                            f"neither the start ({sc.start.x:g}, {sc.start.y:g}) m nor {len(bad)} of the {len(signs)} signs "
                            f"(e.g. {signs.number[bad[0]]} at ({signs.x[bad[0]]:g}, {signs.y[bad[0]]:g}) m) lie in free space: "
                            f"{extent}; check map.resolution and map.origin")
    if not start_in:
        raise ScenarioError(file, "start", f"start ({sc.start.x:g}, {sc.start.y:g}) m lies outside the map: {extent}")
    if not start_ok:
        wall = int((img < WALL_BELOW).sum())
        if wall > free.sum() and not free[sr, scc]:  # more wall than free space, the start on a wall: an inverted image
            raise ScenarioError(file, map_field, f"the start ({sc.start.x:g}, {sc.start.y:g}) m is on a wall, and the map "
                                f"is more wall ({wall / img.size:.0%} of its pixels, < {WALL_BELOW} of 255) than free space "
                                f"({free.sum() / img.size:.0%}, >= {FREE_FROM}): is the image inverted? Walls are dark, "
                                "free space light")
        raise ScenarioError(file, "start", f"start ({sc.start.x}, {sc.start.y}) m is inside a wall or closer than the robot radius ({sc.robot.radius} m) to one")
    if bad:
        k = bad[0]
        where = "is not next to free space (within 2 cells)" if 0 <= r[k] < H and 0 <= c[k] < W else f"lies outside the map: {extent}"
        raise ScenarioError(dfile, f"doors[{k}]", f"sign {signs.number[k]} at ({signs.x[k]:.2f}, {signs.y[k]:.2f}) m {where}")
    return world


class DuplicateSigns(ScenarioError):
    """Signs that share a number under ``duplicates: error``; ``listed`` names each number with
    the positions of its signs (an importer turns this into advice on its ``--duplicates``)."""

    def __init__(self, file: str, listed: str, count: int):
        self.listed, self.count = listed, count
        super().__init__(file, "doors", f"{count} sign number(s) appear more than once: {listed}. Set duplicates: "
                         "keep-first (the first sign of each number) or any (the goal is found at whichever sign "
                         "carries it) in the scenario")


def apply_duplicates(doors: list, policy: str, dfile: str) -> tuple[list, dict]:
    """Signs that share a number, under the scenario's ``duplicates`` policy: ``error`` refuses
    them, naming every duplicate with its positions; ``keep-first`` keeps the first sign of each
    number; ``any`` keeps them all (the goal is found at whichever carries it). Returns the signs
    kept and number -> [(x, y)] of every duplicated number."""
    where: dict[str, list] = {}
    for d in doors:
        where.setdefault(str(d.number), []).append((round(d.x, 2), round(d.y, 2)))
    dup = {n: xy for n, xy in where.items() if len(xy) > 1}
    if dup and policy == "error":
        listed = "; ".join(f"{n} at " + ", ".join(f"({x:g}, {y:g})" for x, y in xy) for n, xy in dup.items())
        raise DuplicateSigns(dfile, listed, len(dup))
    if dup and policy == "keep-first":
        seen: set[str] = set()
        kept = []
        for d in doors:
            if str(d.number) not in seen:
                kept.append(d)
                seen.add(str(d.number))
        doors = kept
    return doors, dup


def check_goals_reachable(world: World, goals, file: str) -> dict:
    """Shortest path per goal (m); raise when a goal cannot be read from reachable free space."""
    out = {}
    for k, g in enumerate(goals):
        d = world.shortest_path(g)
        if not np.isfinite(d):
            raise ScenarioError(file, f"goals[{k}]", f"sign {g} cannot be read from any pose reachable from the start")
        out[g] = d
    return out
