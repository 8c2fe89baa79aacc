"""Scenarios made from elsewhere: ``generate_building``, ``generate_batch``, ``generate_rooms``, and
the importers (MobileSim, ROS map_server, KTH)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from ..errors import ScenarioError
from ..world.ground_truth import DuplicateSigns
from ..world.buildings import numbered
from ..world.importers import kth, mobilesim, ros
from ..world.rooms import generate_rooms as make_rooms, write_rooms
from ..config.indirect import IndirectSpec
from ..files import output_folder
from .info import validate


def imported(importer, out: str | Path, *args, **kwargs) -> tuple[Path, list[str]]:
    """Run an importer (``import_ros``, ``import_kth``, ``import_mobilesim``: ``importer(*args,
    out=folder, **kwargs)`` -> (scenario path, notes)) into a hidden folder beside ``out``,
    validate what it wrote with the same code as :func:`validate`, and only then move the files
    into ``out``. A scenario that would not validate is a :class:`ScenarioError` (exit 2), and
    ``out`` is left as it was."""
    out = output_folder(out)
    work = out / f".import.{os.getpid()}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir()
    try:
        path, notes = importer(*args, out=work, **kwargs)
        try:
            validate(path)
        except DuplicateSigns as exc:
            raise ScenarioError(str(args[-1] if args else out), "", f"{exc.count} sign number(s) appear more than once: "
                                f"{exc.listed} (positions after snapping onto the walls). Nothing was written: import again with --duplicates keep-first (the "
                                "first sign of each number is kept) or --duplicates any (every sign is kept; the goal is "
                                "found at whichever sign carries it)") from None
        except ScenarioError as exc:
            raise ScenarioError(str(out / path.name), exc.field, f"the imported scenario would not validate, so "
                                f"nothing was written: {exc.message}") from None
        for f in sorted(work.iterdir()):
            os.replace(f, out / f.name)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out / path.name, notes


# ---- hours, buildings, rooms and maps of one's own -------------------------------------------------
LAYOUTS, SCHEMES = numbered.LAYOUTS, numbered.SCHEMES  # generate_building's layouts and numbering schemes
KTH_CORRIDOR_TYPES = kth.CORRIDOR_TYPES  # import_kth's default corridor types


def generate_building(layout: str, numbering: str, seed: int, out: str | Path, spacing: float = 2.5, signs: int | None = None,
                      goals: list | None = None, name: str | None = None, scale: float = 1.0, skip: float = 0.0,
                      letters: float = 0.0, extension: bool = False, style: str = "plain", letter_case: str = "lower") -> Path:
    """Write a generated building into ``out`` (map.png, doors.csv and a scenario that runs as it
    is); returns the scenario's path. ``goals``: door numbers (default: four spread by distance).
    ``skip``, ``letters``, ``extension`` and ``style``: what real floors add (numbers skipped,
    lettered doors (``letter_case`` lower or upper), an extension renumbered, wing prefixes or
    floor-dot-room labels; see
    :func:`~semsearch_cli.world.buildings.numbered.generate_building`)."""
    if goals and any(not isinstance(g, int) or isinstance(g, bool) for g in goals):
        raise ScenarioError("<command line>", "--goals", f"expected door numbers, got {','.join(map(str, goals))!r}")
    return numbered.generate_building(layout, numbering, seed, output_folder(out), spacing=spacing, signs=signs, goals=goals,
                                      name=name, scale=scale, skip=skip, letters=letters, extension=extension, style=style,
                                      letter_case=letter_case)


def _among(items, valid: tuple, flag: str) -> tuple:
    """``items`` (None: all of ``valid``), each checked to be one of ``valid``."""
    if items is None:
        return valid
    items = tuple(items)
    bad = [t for t in items if t not in valid]
    if bad or not items:
        raise ScenarioError("<command line>", flag, f"unknown value(s) {bad or list(items)}; valid: {', '.join(valid)}")
    return items


def generate_batch(out: str | Path, seeds: int = 3, runs: int = 3, layouts=None, schemes=None) -> list[Path]:
    """Every layout x numbering scheme x seed (``layouts``, ``schemes``: None for all) into ``out``,
    one sub-folder each and index.txt: a robustness set. Returns the scenarios' paths."""
    return numbered.generate_batch(output_folder(out), seeds=seeds, runs=runs, layouts=_among(layouts, LAYOUTS, "--layouts"),
                                   schemes=_among(schemes, SCHEMES, "--schemes"))


def generate_rooms(n: int, seed: int, out: str | Path, size: tuple[float, float] = (6.0, 6.0),
                   obstacles: int = 0) -> tuple[Path, list]:
    """``n`` rooms for indirect search as the paper's (Loncomilla et al. 2018, Section 4.5) into
    ``out``/rooms.yaml; returns (its path, the rooms)."""
    w, d = size
    if not (1.0 <= w <= 50.0 and 1.0 <= d <= 50.0):
        raise ScenarioError("<command line>", "--size", f"W and D must lie between 1 and 50 m (got {w:g},{d:g})")
    spec = IndirectSpec()
    try:
        rooms = make_rooms(n, seed, spec.relations, spec.masks, spec.target, (w, d), obstacles)
    except ValueError as exc:  # no free place for an object: the boxes took it, or the room is too small for the rings
        raise ScenarioError("<command line>", "--obstacles" if obstacles else "--size",
                            f"{exc}" + ("" if obstacles else f" (a {w:g} x {d:g} m room is too small for the objects' "
                                                             "rings; give a larger --size)")) from None
    return write_rooms(output_folder(out) / "rooms.yaml", rooms), rooms


def import_mobilesim(map_file: str | Path, doors_file: str | Path, out: str | Path, **options) -> tuple[Path, list[str]]:
    """A MobileSim map and door file as a scenario in ``out`` (see
    :func:`~semsearch_cli.world.importers.mobilesim.import_mobilesim` for ``options``), validated
    before it is written (:func:`imported`); returns (the scenario's path, notes)."""
    return imported(mobilesim.import_mobilesim, out, Path(map_file), Path(doors_file), **options)


def import_ros(map_file: str | Path, doors_file: str | Path, out: str | Path, **options) -> tuple[Path, list[str]]:
    """A scenario over a ROS map (map_server YAML) and a doors CSV in ``out`` (see
    :func:`~semsearch_cli.world.importers.ros.import_ros`), validated before it is written."""
    return imported(ros.import_ros, out, Path(map_file), Path(doors_file), **options)


def import_kth(xml_file: str | Path, out: str | Path, **options) -> tuple[Path, list[str]]:
    """A KTH campus floor plan as a scenario in ``out`` (see
    :func:`~semsearch_cli.world.importers.kth.import_kth`), validated before it is written."""
    return imported(kth.import_kth, out, Path(xml_file), **options)
