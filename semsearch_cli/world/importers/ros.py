"""``semsearch import ros MAP.yaml DOORS.csv --out DIR``: a runnable scenario over a ROS map.

The map stays in its own format (copied as ``DIR/map.yaml`` and its image; the scenario reads it
with ``map: {ros: map.yaml}``). The free space is the 4-connected free region holding the start
(default: the free cell farthest from walls and unknown space); each sign is snapped onto the
nearest wall face of that region, facing into it, as the MobileSim importer does.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ...errors import ScenarioError
from ...geometry import GridFrame
from ..scenario_folder import scenario_dict, write_building
from .mobilesim import snap_report, snap_signs, spread_goals
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
    _, lab = cv2.connectedComponents(space.astype(np.uint8), connectivity=4)
    if start is None:
        d = cv2.distanceTransform(space.astype(np.uint8), cv2.DIST_L2, 5)
        r, c = np.unravel_index(int(np.argmax(d)), d.shape)
        sx, sy = frame.to_world(r, c)
        start = (round(float(sx), 2), round(float(sy), 2))
    r, c = frame.to_index(*start)
    if not (0 <= r < H and 0 <= c < W) or not space[r, c]:
        raise ScenarioError("<command line>", "--start", f"start {start} m is not in the free space of {map_yaml}")
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
    report = cleaned + report
    if not goals:
        goals = spread_goals(free, frame, snapped, start)
    copy_ros_map(map_yaml, out)
    scen = scenario_dict(name or Path(map_yaml).stem, res, start, goals, [{"name": "greedy"}, {"name": "bvp"}],
                         density_delta, origin, duplicates)
    scen["map"] = {"ros": "map.yaml", **({"clean": True} if clean else {})}
    header = f"imported from {Path(map_yaml).name} and {Path(doors).name} by `semsearch import ros`\n# " + "\n# ".join(report)
    return write_building(out, None, snapped, scen, header), report
