"""``semsearch import``: maps of other tools (MobileSim, ROS map_server, KTH) as scenarios."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from .. import api
from ..errors import ScenarioError, did_you_mean
from .common import _fail, _finite, _path, _split, _xy, import_app, out


DUPLICATES_POLICIES = ("error", "keep-first", "any")


def _duplicates(value: str) -> str:
    if value not in DUPLICATES_POLICIES:
        raise typer.BadParameter(f"{value!r} is not one of {', '.join(DUPLICATES_POLICIES)}{did_you_mean(value, DUPLICATES_POLICIES)}")
    return value


DUPLICATES = typer.Option("error", "--duplicates", callback=_duplicates,
                          help="Signs that share a number: error (refuse), keep-first (the first sign of each number) or "
                               "any (keep every one; the goal is found at whichever carries it). Written into the scenario.")


@import_app.command("mobilesim")
def import_mobilesim(
    map_file: Path = typer.Argument(..., help="MobileSim .map file (walls in mm)."),
    doors_file: Path = typer.Argument(..., help=".doors file: x y number facing (m, degrees)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.png, doors.csv and scenario.yaml."),
    resolution: float = typer.Option(0.1, "--resolution", callback=_finite, min=0.01, max=1.0, help="m per cell."),
    start: Optional[str] = typer.Option(None, "--start", help="X,Y in metres (default: the widest free cell)."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance)."),
    density_delta: float = typer.Option(2.5, "--density-delta", callback=_finite, min=0.01, max=1e4, help="m^2, segmentation delta (Eq. 4.4)."),
    duplicates: str = DUPLICATES,
):
    """Convert a MobileSim map and door file into a scenario that runs as it is."""
    try:
        path, notes = api.import_mobilesim(map_file, doors_file, out_dir, res=resolution, start=_xy(start, "--start"),
                                   goals=_split([goals], "--goals") if goals is not None else None, density_delta=density_delta,
                                   duplicates=duplicates)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.png'}, {out_dir / 'doors.csv'}, {path}\n" + "\n".join(notes))


@import_app.command("ros")
def import_ros(
    map_file: Path = typer.Argument(..., help="ROS map YAML (map_server / map_saver: a PGM or PNG beside it)."),
    doors_file: Path = typer.Argument(..., help="Door signs: CSV with columns number,x,y,facing (m, degrees) in the map's frame."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.yaml (and its image), doors.csv and scenario.yaml."),
    start: Optional[str] = typer.Option(None, "--start", help="X,Y in metres (default: the widest free cell)."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance)."),
    density_delta: float = typer.Option(2.5, "--density-delta", callback=_finite, min=0.01, max=1e4, help="m^2, segmentation delta (Eq. 4.4)."),
    clean: bool = typer.Option(False, "--clean", help="Clean a SLAM map: free space not reachable from the start, and laser fans narrower than the robot, become outside (map.clean)."),
    duplicates: str = DUPLICATES,
):
    """Make a scenario over a ROS map (the format of every ROS user's SLAM maps), keeping the map as it is."""
    try:
        path, notes = api.import_ros(map_file, doors_file, out_dir, start=_xy(start, "--start"),
                                   goals=_split([goals], "--goals") if goals is not None else None, density_delta=density_delta,
                                   clean=clean, duplicates=duplicates)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.yaml'}, {out_dir / 'doors.csv'}, {path}\n" + "\n".join(notes))


@import_app.command("kth")
def import_kth(
    xml_file: Path = typer.Argument(..., help="KTH campus floor-plan XML file."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.png, doors.csv and scenario.yaml."),
    resolution: float = typer.Option(0.1, "--resolution", callback=_finite, min=0.01, max=1.0, help="m per cell."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance, among readable signs)."),
    corridor_types: str = typer.Option(",".join(api.KTH_CORRIDOR_TYPES), "--corridor-types",
                                       help="Comma-separated space types the robot drives in (untyped spaces joined to several others count too)."),
    duplicates: str = DUPLICATES,
):
    """Convert a KTH floor plan: circulation spaces become free space, each room-to-corridor portal a sign."""
    try:
        types = tuple(t.strip().upper() for t in corridor_types.split(",") if t.strip())
        path, notes = api.import_kth(xml_file, out_dir, res=resolution,
                                   goals=_split([goals], "--goals") if goals is not None else None, corridor_types=types,
                                   duplicates=duplicates)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.png'}, {out_dir / 'doors.csv'}, {path}\n" + "\n".join(notes))
