"""``semsearch import ros MAP.yaml DOORS.csv --out DIR``: a runnable scenario over a ROS map.

The map stays in its own format (copied as ``DIR/map.yaml`` and its image; the scenario reads it
with ``map: {ros: map.yaml}``). The free space is the 4-connected free region holding the start
(default: the free cell farthest from walls and unknown space); each sign is snapped onto the
nearest wall face of that region, facing into it, as the MobileSim importer does.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import cv2
import numpy as np

from ...errors import ScenarioError
from ...files import read_user_text
from ...geometry import GridFrame
from ..scenario_folder import scenario_dict, write_building
from .mobilesim import MAX_SNAP_M, snap_report, snap_signs, spread_goals
from ..ros_map import FREE, clean_free, copy_ros_map, read_ros_map
from ..ground_truth import read_doors


ROBOT_RADIUS = 0.25  # m: the scenario's robot.radius default, which map.clean uses when the scenario loads


def import_ros(map_yaml: Path, doors: Path, out: Path, start: tuple[float, float] | None = None,
               goals: list | None = None, name: str | None = None, density_delta: float = 2.5,
               clean: bool = False, duplicates: str = "error") -> tuple[Path, list[str]]:
    """Write ``out/map.yaml`` (+ image), ``out/doors.csv`` and ``out/scenario.yaml``; returns the
    scenario's path and what happened to the signs (also in the YAML's header). With ``clean``,
    the free space is cleaned as ``map.clean`` cleans it (:func:`~.ros.clean_free`; the scenario
    gets ``map.clean: true``, the map file stays as it is)."""
    img, res, origin = read_ros_map(map_yaml)
    H, W = img.shape
    frame = GridFrame(res, origin[0], origin[1], H, W)
    space = img == FREE
    size = f"{W} x {H} cells at {res:g} m per cell, {W * res:.2f} x {H * res:.2f} m, {int(space.sum()):,} of them free"
    if not space.any():
        raise ScenarioError(str(map_yaml), "", f"no free cell ({size}): check negate, free_thresh and the image")
    _, lab = cv2.connectedComponents(space.astype(np.uint8), connectivity=4)
    clear = clearance(space, res)
    need = ROBOT_RADIUS + 0.5 * res  # as the scenario's start is checked: the robot's disk fits
    if start is None:
        if clear.max() < need - 1e-6:
            raise ScenarioError(str(map_yaml), "", f"the robot (radius {ROBOT_RADIUS:g} m) fits nowhere in its free space: "
                                f"no free cell is {need:.2f} m from a wall or unknown cell (the widest is "
                                f"{float(clear.max()):.3f} m; {size}); a map this small, or with free space this "
                                "narrow, has no room for a start or goals (is resolution right?)")
        # the widest free cell, as chosen before (a 5 x 5 mask: the same start as earlier imports of a
        # walled map), unless the exact distance puts it short of the robot's room
        d = cv2.distanceTransform(np.pad(space, 1).astype(np.uint8), cv2.DIST_L2, 5)[1:-1, 1:-1]
        r, c = np.unravel_index(int(np.argmax(d)), d.shape)
        if clear[r, c] < need - 1e-6:
            r, c = np.unravel_index(int(np.argmax(clear)), clear.shape)
        sx, sy = frame.to_world(r, c)
        start = (round(float(sx), 2), round(float(sy), 2))
    r, c = frame.to_index(*start)
    if not (0 <= r < H and 0 <= c < W) or not space[r, c]:
        raise ScenarioError("<command line>", "--start", f"start {start} m is not in the free space of {map_yaml}")
    if clear[r, c] < need - 1e-6:
        raise ScenarioError("<command line>", "--start", f"start {start} m is {float(clear[r, c]):.2f} m from a wall or "
                            f"unknown cell of {map_yaml}; the robot (radius {ROBOT_RADIUS:g} m) needs {need:.2f} m")
    cleaned = []
    if clean:
        img, gone = clean_free(img, res, (int(r), int(c)), ROBOT_RADIUS)
        space = img == FREE
        _, lab = cv2.connectedComponents(space.astype(np.uint8), connectivity=4)
        cleaned = [f"cleaned the map: {gone:,} free cells ({gone * res * res:.1f} m2) the robot could not reach from the "
                   f"start, or narrower than the robot (laser fans), became outside (map.clean: true)"]
    free = lab == lab[r, c]
    signs = [(d.number, d.x, d.y, d.facing) for d in read_doors(Path(doors))]
    if not signs:
        raise ScenarioError(str(doors), "", "no door signs")
    snapped, report = snap_report(signs, snap_signs(free, frame, signs), frame)
    if not snapped:
        x0, y0 = frame.to_world(H - 1, 0)
        x1, y1 = frame.to_world(0, W - 1)
        raise ScenarioError(str(doors), "", f"none of its {len(signs)} signs lies within {MAX_SNAP_M:g} m of the free space "
                            f"the robot can reach from the start {start} m ({int(free.sum()):,} cells, "
                            f"{free.sum() * res * res:.2f} m2 of {map_yaml}, whose cells span x {x0:g} to {x1:g} m, y {y0:g} "
                            f"to {y1:g} m): there is no sign to read and no goal to seek; are the signs in the map's frame?")
    report = cleaned + report
    if not goals:
        goals = spread_goals(free, frame, snapped, start)
    copy_ros_map(map_yaml, out)
    scen = scenario_dict(name or Path(map_yaml).stem, res, start, goals, [{"name": "greedy"}, {"name": "bvp"}],
                         density_delta, origin, duplicates)
    scen["map"] = {"ros": "map.yaml", **({"clean": True} if clean else {})}
    header = f"imported from {Path(map_yaml).name} and {Path(doors).name} by `semsearch import ros`\n# " + "\n# ".join(report)
    return write_building(out, None, snapped, scen, header), report


def clearance(space: np.ndarray, res: float) -> np.ndarray:
    """(H, W) float32, m: each cell's distance to the nearest cell that is not free, the map's
    edge counting as one (beyond a ROS map lies unknown space), as a scenario's start is checked.

    Parameters
    ----------
    space : (H, W) bool
        Free cells.
    res : float, m/cell
    """
    d = cv2.distanceTransform(np.pad(space, 1).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
    return d * np.float32(res)
