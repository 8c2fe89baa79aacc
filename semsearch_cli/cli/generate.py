"""``semsearch generate``: numbered buildings, and rooms for indirect search, of one's own."""

from __future__ import annotations

from typing import Optional

import typer

from .. import api
from ..errors import ScenarioError
from .common import _fail, _finite, _path, _split, _xy, app, out


generate_app = typer.Typer(no_args_is_help=True, help="Generate numbered buildings, and rooms for indirect search, of your own.")
app.add_typer(generate_app, name="generate")


@generate_app.command("building")
def generate_building(
    layout: str = typer.Option(..., "--layout", help="grid, wings, angled, single or hall."),
    numbering: str = typer.Option(..., "--numbering", help=", ".join(api.SCHEMES) + "."),
    seed: int = typer.Option(0, "--seed", min=0, max=2**32 - 1, help="Seed of the layout's variations (and of random numbering)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for map.png, doors.csv and scenario.yaml."),
    spacing: float = typer.Option(2.5, "--spacing", callback=_finite, min=0.5, max=50.0, help="m between door slots along a wall."),
    signs: Optional[int] = typer.Option(None, "--signs", min=1, help="Keep exactly this many signs (doors trimmed at random, numbers kept)."),
    goals: Optional[str] = typer.Option(None, "--goals", help="Comma-separated goal numbers (default: four spread by distance)."),
    name: Optional[str] = typer.Option(None, "--name", help="Scenario name (default LAYOUT-NUMBERING-SEED)."),
    scale: float = typer.Option(1.0, "--scale", callback=_finite, min=0.5, max=4.0,
                                help="Stretch the layout this many times in x and y (scale^2 the area), corridors as wide."),
    skip: float = typer.Option(0.0, "--skip", callback=_finite, min=0.0, max=0.95,
                               help="Share of each prefix's number range left without a door (numbers skipped, as real floors do)."),
    letters: float = typer.Option(0.0, "--letters", callback=_finite, min=0.0, max=0.9,
                                  help="Share of doors that share a room's number with a letter suffix (24a, 24b)."),
    extension: bool = typer.Option(False, "--extension", help="Renumber the last corridor in a hundred-block of its own."),
    style: str = typer.Option("plain", "--style", help="plain (214), wing (K214: a wing letter per corridor) or dot (2.14)."),
    letter_case: str = typer.Option("lower", "--letter-case", help="lower (24a) or upper (24A): the lettered doors' suffixes."),
):
    """Write a generated building: map PNG, doors CSV and a scenario YAML that runs as it is."""
    try:
        wanted = _split([goals], "--goals") if goals is not None else None
        path = api.generate_building(layout, numbering, seed, out_dir, spacing=spacing, signs=signs, goals=wanted, name=name,
                                     scale=scale, skip=skip, letters=letters, extension=extension, style=style,
                                     letter_case=letter_case)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {out_dir / 'map.png'}, {out_dir / 'doors.csv'}, {path}")


MAX_BATCH_SEEDS = 100  # generate batch: 2,800 buildings at most


def _items(text: Optional[str]) -> Optional[list]:
    """Comma-separated values, None when not given."""
    return None if text is None else [t.strip() for t in text.split(",") if t.strip()]


@generate_app.command("batch")
def generate_batch(
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for the buildings (one sub-folder each) and index.txt."),
    seeds: int = typer.Option(3, "--seeds", min=1, max=MAX_BATCH_SEEDS, help="Buildings per layout and numbering scheme "
                              f"(at most {MAX_BATCH_SEEDS}: 4 x 7 x {MAX_BATCH_SEEDS} buildings)."),
    runs: int = typer.Option(3, "--runs", min=1, help="Runs per goal and planner in each scenario."),
    layouts: Optional[str] = typer.Option(None, "--layouts", help="Comma-separated layouts (default: all)."),
    schemes: Optional[str] = typer.Option(None, "--schemes", help="Comma-separated numbering schemes (default: all)."),
):
    """Every layout x numbering scheme x seed: a robustness set (4 x 7 x 3 = 84 buildings by default)."""
    try:
        paths = api.generate_batch(out_dir, seeds=seeds, runs=runs, layouts=_items(layouts), schemes=_items(schemes))
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {len(paths)} scenarios under {out_dir} (listed in {out_dir / 'index.txt'})")


@generate_app.command("rooms")
def generate_rooms(
    n: int = typer.Option(20, "--n", min=1, max=10000, help="How many rooms."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed (room k is the same whatever --n)."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="Folder for rooms.yaml."),
    size: str = typer.Option("6,6", "--size", help="W,D: the room's width and depth in metres."),
    obstacles: int = typer.Option(0, "--obstacles", min=0, max=20, help="Boxes per room (the paper's rooms have none)."),
):
    """Rooms for indirect search as the paper's (Loncomilla et al. 2018, Section 4.5): the monitor
    uniform, each secondary object in a ring drawn from its co-occurrences (Table 2)."""
    try:
        w, d = _xy(size, "--size", "W,D in metres")
        path, rooms = api.generate_rooms(n, seed, out_dir, (w, d), obstacles)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"wrote {len(rooms)} rooms of {w:g} x {d:g} m to {path}")
