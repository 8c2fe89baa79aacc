"""Building a suite's split: its floors' folders, their episodes and the manifest.

``doors-v1`` draws floors from the building generator (a layout, a numbering convention and a
seed per floor, from the split's salt), each with four goals spread by distance and five drawn
starts per goal; ``doors-classic-v1`` freezes the shipped thesis scenarios with the thesis' own
starts. ``scripts/make_bench.py`` writes the shipped ``val`` splits with these; a maintainer's
``--salt-file`` builds a hidden ``test`` split the same way (:func:`~.suites.open_split`).
"""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import yaml

from ..config import load_scenario
from ..runner.specs import Loaded
from ..shipped import CONFIGS
from ..tasks.episodes import EPISODE_COLUMNS
from ..world.buildings.numbered import generate_building
from ..world.buildings.office import random_office
from ..world.rooms import generate_rooms, write_rooms
from .predictability import predictability
from .solvable import solvable_episodes
from .suites import Suite, write_manifest

DEFAULT_PLANNER = [{"name": "nsos", "alpha": 0.9}]  # what `semsearch run FLOOR/scenario.yaml` runs; a bench run sets its own


def floor_rng(salt: str, suite: str, split: str, i: int) -> np.random.Generator:
    """The generator of floor ``i`` of a split: seeded by the split's salt, never by the order
    of other floors."""
    words = np.frombuffer(hashlib.sha256(f"{suite}/{split}/{salt}/{i}".encode()).digest()[:16], "<u4")  # any machine's byte order
    return np.random.default_rng([int(w) for w in words])


def freeze_episodes(scenario: Path, repeats: int, rng: np.random.Generator | None = None) -> int:
    """Draw (or take) the scenario's episodes, write them to ``episodes.csv`` beside it and make
    the scenario read that file (``repeats`` runs of each): the floor's episodes frozen. Every
    episode is checked to be solvable (:mod:`.solvable`); a drawn one that is not is drawn again
    by ``rng`` (the builder's own generator), a given one (or any, without ``rng``) is an error.
    Returns their number."""
    loaded = Loaded.load(scenario)
    eps, _ = solvable_episodes(loaded.task, repeats, rng)
    rows = pd.DataFrame([loaded.task.episode_row(e) for e in eps], columns=EPISODE_COLUMNS)
    rows.to_csv(scenario.parent / "episodes.csv", index=False, lineterminator="\n")
    doc = yaml.safe_load(scenario.read_text())
    doc["episodes"] = {"file": "episodes.csv"}
    doc.setdefault("planners", DEFAULT_PLANNER)
    doc.setdefault("experiment", {})["seeds"] = repeats
    header = "".join(line + "\n" for line in scenario.read_text().splitlines() if line.startswith("#"))
    scenario.write_text(header + yaml.safe_dump(doc, sort_keys=False))
    return len(eps)


# doors-v1's mix. Calibrated on the label statistics of 142 public KTH floor plans
# (benchmarks/kth_labels.py; docs/bench.md quotes the table):
P_PARITY = 0.23  # of the floors that are not the control: one parity per wall (KTH: parity statistic >= 0.5 on 23% of floors)
P_LETTERS = 0.63  # floors with lettered doors (KTH: 63% of floors)
LETTERS = (0.08, 0.41)  # a lettered floor's share of lettered doors: KTH's quartiles (of the floors with any)
SKIP = (0.43, 0.83)  # share of each prefix's number range without a door: KTH's quartiles


def with_quartiles(rng: np.random.Generator, q1: float, q3: float, lo: float, hi: float) -> float:
    """A uniform draw whose quartiles are ``q1`` and ``q3`` (on ``[q1 - (q3 - q1) / 2, q3 + (q3 -
    q1) / 2]``), clipped to ``[lo, hi]``, rounded to 3 decimals."""
    h = (q3 - q1) / 2
    return round(float(np.clip(rng.uniform(q1 - h, q3 + h), lo, hi)), 3)
# Stated choices, not calibrated (the KTH floors have no prefixes, no dotted labels, and no record
# of extensions or layouts):
P_RANDOM = 0.10  # the random-numbering control
P_EXTENSION = 0.15  # the last corridor renumbered in a block of its own
STYLES = (("plain", 0.8), ("wing", 0.1), ("dot", 0.1))
LAYOUTS = ("grid", "wings", "angled", "single", "hall")  # uniform
PARITY_SCHEMES = ("odd-even-out", "odd-even-in", "corridor-parity", "corridor-parity-in", "floor", "blocks")  # uniform
SEQUENTIAL_SCHEMES = ("loop",)
SPACING = 2.5  # m between door slots
DOORS_V1_FLOORS = {"val": 40, "test": 40}
DOORS_V1_STARTS = 5  # drawn per goal
MIN_SIGNS = 8  # a floor has at least this many signs (the real track keeps KTH floors of as many)
DOORS_V1_MIN_DISTANCE = 10.0  # m, geodesic from a start to its goal


def draw_floor(rng: np.random.Generator) -> dict:
    """One floor's recipe from doors-v1's mix (the constants above)."""
    if rng.random() < P_RANDOM:
        scheme = "random"
    elif rng.random() < P_PARITY:
        scheme = PARITY_SCHEMES[int(rng.integers(len(PARITY_SCHEMES)))]
    else:
        scheme = SEQUENTIAL_SCHEMES[int(rng.integers(len(SEQUENTIAL_SCHEMES)))]
    names, w = zip(*STYLES)
    return {"layout": LAYOUTS[int(rng.integers(len(LAYOUTS)))], "numbering": scheme, "seed": int(rng.integers(2**31)),
            "spacing": SPACING, "skip": with_quartiles(rng, *SKIP, 0.0, 0.95),
            "letters": with_quartiles(rng, *LETTERS, 0.02, 0.9) if rng.random() < P_LETTERS else 0.0,
            "extension": bool(rng.random() < P_EXTENSION), "style": str(rng.choice(names, p=np.array(w) / sum(w))),
            "letter_case": "lower" if rng.random() < 0.5 else "upper"}


def make_doors_v1(split: str, salt: str, out: Path) -> None:
    """``doors-v1``: :data:`DOORS_V1_FLOORS` floors drawn by :func:`draw_floor`, each with its
    generator's four goals and :data:`DOORS_V1_STARTS` starts per goal; each floor's recipe
    records its predictability (:mod:`.predictability`)."""
    out.mkdir(parents=True, exist_ok=True)
    floors = []
    for i in range(DOORS_V1_FLOORS[split]):
        rng = floor_rng(salt, "doors-v1", split, i)
        fid = f"f{i:03d}"
        for _ in range(20):  # a floor with fewer than MIN_SIGNS signs is drawn again (from the same stream)
            r = draw_floor(rng)
            shutil.rmtree(out / fid, ignore_errors=True)
            path = generate_building(r["layout"], r["numbering"], r["seed"], out / fid, spacing=r["spacing"],
                                     name=f"doors-v1-{split}-{fid}", planners=DEFAULT_PLANNER, skip=r["skip"],
                                     letters=r["letters"], extension=r["extension"], style=r["style"],
                                     letter_case=r["letter_case"])
            if sum(1 for _ in open(path.parent / "doors.csv")) - 1 >= MIN_SIGNS:
                break
        doc = yaml.safe_load(path.read_text())
        doc["episodes"] = {"starts": DOORS_V1_STARTS, "seed": int(rng.integers(2**31)),
                           "min_distance": DOORS_V1_MIN_DISTANCE}
        if len(doc["goals"]) < 4:  # a floor of few signs: the spread quantiles met twice on one sign; draw the rest
            labels = pd.read_csv(path.parent / "doors.csv", dtype=str, keep_default_na=False)["number"].tolist()
            rest = [a for a in labels if str(a) not in {str(g) for g in doc["goals"]}]
            doc["goals"] += [int(a) if a.isdigit() else a for a in rng.choice(rest, 4 - len(doc["goals"]), replace=False)]
        path.write_text(path.read_text().split("\n", 1)[0] + "\n" + yaml.safe_dump(doc, sort_keys=False))
        freeze_episodes(path, 1, rng)  # an unsolvable start drawn again, after every other draw of the floor's
        d = pd.read_csv(path.parent / "doors.csv", dtype={"number": str}, keep_default_na=False)
        p = predictability(d["number"].tolist(), d["x"], d["y"], d["facing"], fid)
        floors.append((fid, {"generator": "building", **r, "signs": len(d),
                             "predictability": {"order": round(p.order, 4), "parity": round(p.parity, 4),
                                                "value": round(p.value, 4)}}))
    write_manifest(SUITE_DOORS, split, out, floors)


def freeze_shipped(name: str, suite: Suite, dest: Path) -> None:
    """The shipped scenario ``name`` frozen into ``dest`` for ``suite``: its map image and its
    labels' file (the suite's ``labels`` key, when it has one) copied beside it, its episodes
    frozen with the suite's repeats (:func:`freeze_episodes`)."""
    src = CONFIGS / f"{name}.yaml"
    doc = yaml.safe_load(src.read_text())
    dest.mkdir()
    files = [(doc["map"], "image")] + ([(doc, suite.labels)] if suite.labels else [])
    for owner, key in files:
        f = src.parent / owner[key]
        shutil.copyfile(f, dest / f.name)
        owner[key] = f.name
    doc["experiment"].pop("out", None)
    (dest / "scenario.yaml").write_text(f"# the shipped scenario {name} (configs/{name}.yaml), frozen for {suite.name}\n"
                                        + yaml.safe_dump(doc, sort_keys=False))
    freeze_episodes(dest / "scenario.yaml", suite.repeats)


CLASSIC = ("normal", "inverse", "hotel_thesis", "kth")  # the shipped thesis door scenarios, in the thesis' order


def make_doors_classic(split: str, salt: str, out: Path) -> None:
    """``doors-classic-v1``: the shipped thesis scenarios (:data:`CLASSIC`) with their own
    starts (one per goal, the heading drawn at each repeat), their files copied beside them."""
    out.mkdir(parents=True, exist_ok=True)
    floors = []
    for name in CLASSIC:
        freeze_shipped(name, SUITE_CLASSIC, out / name)
        floors.append((name, {"scenario": f"configs/{name}.yaml"}))
    write_manifest(SUITE_CLASSIC, split, out, floors)


INDIRECT_ROOMS = 20  # per split, as Table 3's
INDIRECT_STARTS = 10  # drawn per room and view scale


def make_indirect(split: str, salt: str, out: Path) -> None:
    """``indirect-v1``: the paper's protocol as ``configs/indirect.yaml`` runs it (11 methods' rooms
    of 6 m x 6 m, view scales 1.0-2.5 m, 5 minutes per search, :data:`INDIRECT_STARTS` starts per
    room and scale), on :data:`INDIRECT_ROOMS` rooms written to ``rooms.yaml``: for ``val`` the
    rooms of Table 3's experiment (the config's seed 0), for ``test`` rooms generated from the
    split's salt."""
    src = CONFIGS / "indirect.yaml"
    doc = yaml.safe_load(src.read_text())
    sc = load_scenario(src)
    spec, gen = sc.indirect, sc.indirect.rooms
    seed = gen.seed if split == "val" else int(floor_rng(salt, "indirect-v1", split, 0).integers(2**31))
    dest = out / "rooms"
    dest.mkdir(parents=True)
    rooms = generate_rooms(INDIRECT_ROOMS, seed, spec.relations, spec.masks, spec.target, gen.size, gen.obstacles)
    write_rooms(dest / "rooms.yaml", rooms)
    doc["indirect"]["rooms"] = "rooms.yaml"
    doc["episodes"] = {"starts": INDIRECT_STARTS, "seed": 0 if split == "val" else int(floor_rng(salt, "indirect-v1", split, 1).integers(2**31))}
    doc["experiment"].pop("out", None)
    (dest / "scenario.yaml").write_text(f"# configs/indirect.yaml on {INDIRECT_ROOMS} rooms frozen for indirect-v1 {split}\n"
                                        + yaml.safe_dump(doc, sort_keys=False))
    freeze_episodes(dest / "scenario.yaml", 1)
    write_manifest(SUITE_INDIRECT, split, out, [("rooms", {"rooms": INDIRECT_ROOMS, "seed": seed if split == "val" else "salted"})])


OFFICES = 8  # generated offices in a test split


def make_objects(split: str, salt: str, out: Path) -> None:
    """``objects-v1``: for ``val`` the thesis' office (``configs/office.yaml``: the five mug patterns
    of Table 5.1, the combined and the moved-mug cases, requests at 12:00 and 00:00, its start);
    for ``test`` :data:`OFFICES` offices drawn by
    :func:`~semsearch_cli.world.buildings.office.random_office` from the split's salt. Ten
    repeats of each episode (the start's heading drawn at each)."""
    out.mkdir(parents=True, exist_ok=True)
    floors = []
    if split == "val":
        freeze_shipped("office", SUITE_OBJECTS, out / "office")
        floors.append(("office", {"scenario": "configs/office.yaml"}))
    else:
        for i in range(OFFICES):
            rng = floor_rng(salt, "objects-v1", split, i)
            fid = f"o{i:03d}"
            img, doc = random_office(rng, name=f"objects-v1-{split}-{fid}")
            dest = out / fid
            dest.mkdir()
            cv2.imwrite(str(dest / "map.png"), img)
            (dest / "scenario.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
            freeze_episodes(dest / "scenario.yaml", 10)
            floors.append((fid, {"generator": "office"}))
    write_manifest(SUITE_OBJECTS, split, out, floors)


SUITE_DOORS = Suite("doors-v1", "doors", "generated floors: corridor layouts x numbering conventions, 4 goals x 5 drawn "
                    "starts each", repeats=1, splits=("val", "test"), shipped=("val",), make=make_doors_v1, hidden=("test",),
                    labels="doors")
SUITE_CLASSIC = Suite("doors-classic-v1", "doors", "the thesis' Hotel, Normal, Inverse and KTH floors with its own starts, "
                      "10 repeats (Tables 4.2-4.10)", repeats=10, splits=("val",), shipped=("val",), make=make_doors_classic,
                      labels="doors")
SUITE_INDIRECT = Suite("indirect-v1", "indirect", "Loncomilla et al.'s protocol: 20 rooms x 7 view scales x 10 starts, "
                        "success within 60 s and 5 min, and at a budget calibrated on UIS", repeats=1, splits=("val", "test"),
                        shipped=("val",), make=make_indirect, hidden=("test",))
SUITE_REAL = Suite("doors-real-v1", "doors", "real floors fetched by their SHA-256 (semsearch bench fetch): the authors' "
                    "Normal, Inverse and Hotel maps and KTH campus floors; 4 goals x 5 drawn starts each", repeats=1,
                    splits=("val",), shipped=(), fetched=True, labels="doors")
SUITE_OBJECTS = Suite("objects-v1", "objects", "the thesis' office patterns (val: Table 5.1's five, combined, moved mug; 13 "
                       "episodes) and generated offices (test), 10 repeats", repeats=10, splits=("val", "test"),
                       shipped=("val",), make=make_objects, hidden=("test",))
