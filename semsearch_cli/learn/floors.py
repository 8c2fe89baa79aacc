"""Training floors for a learned door planner: drawn from doors-v1's mix (layouts, numbering
conventions, lettering, skipped numbers, wings; :func:`~semsearch_cli.bench.make.draw_floor`) but
from a salt of their own, so that no floor is one of a benchmark split's: each floor's generator
seed is checked against the shipped val split's recipes (a hidden test split is drawn from a
maintainer's salt; a collision of two 31-bit seeds drawn from different SHA-256 streams is not
expected, and the check covers what can be checked)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import yaml

from ..bench.make import DEFAULT_PLANNER, MIN_SIGNS, draw_floor, floor_rng
from ..shipped import DATA
from ..world.buildings.numbered import generate_building

SALT = "semsearch-train-v1"  # the training floors' salt: not a benchmark split's
SUITE = "doors-train"


def benchmark_seeds() -> set[int]:
    """The generator seeds of the shipped doors-v1 floors (their recipes)."""
    doc = json.loads((DATA / "bench" / "doors-v1" / "val" / "suite.json").read_text())
    return {int(f["recipe"]["seed"]) for f in doc["floors"] if "seed" in f.get("recipe", {})}


def training_floor(i: int, out: Path, salt: str = SALT) -> tuple[Path, dict]:
    """Training floor ``i`` (from its own stream of ``salt``) written into ``out/t<i>``: (its
    scenario, its recipe). A floor with fewer than bench's ``MIN_SIGNS`` signs, or whose seed is a
    benchmark floor's, is drawn again from the same stream."""
    rng = floor_rng(salt, SUITE, "train", i)
    taken = benchmark_seeds()
    fid = f"t{i:04d}"
    for _ in range(20):
        r = draw_floor(rng)
        if r["seed"] in taken:
            continue
        shutil.rmtree(out / fid, ignore_errors=True)
        path = generate_building(r["layout"], r["numbering"], r["seed"], out / fid, spacing=r["spacing"],
                                 name=f"{SUITE}-{fid}", planners=DEFAULT_PLANNER, skip=r["skip"], letters=r["letters"],
                                 extension=r["extension"], style=r["style"], letter_case=r["letter_case"])
        if len((path.parent / "doors.csv").read_text().splitlines()) - 1 >= MIN_SIGNS:
            doc = yaml.safe_load(path.read_text())
            doc["episodes"] = {"starts": 3, "seed": int(rng.integers(2**31)), "min_distance": 10.0}
            path.write_text(path.read_text().split("\n", 1)[0] + "\n" + yaml.safe_dump(doc, sort_keys=False))
            return path, r
    raise RuntimeError(f"training floor {i}: no floor of {MIN_SIGNS} signs in 20 draws")


__all__ = ["SALT", "SUITE", "benchmark_seeds", "training_floor"]
