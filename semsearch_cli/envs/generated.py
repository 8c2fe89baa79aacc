"""``semsearch/DoorSearch-Generated-v1`` (and the deprecated ``-v0``): door search in a building generated at each reset.

Each reset draws a building seed among ``first_building .. first_building + buildings - 1`` (or
takes ``options["building"]``), generates that building as ``semsearch generate building --layout
LAYOUT --numbering NUMBERING --seed SEED --spacing SPACING`` would (into a folder of this process,
once per seed), and draws an episode of it: its four goals spread by distance, from its start, a
random heading. Training on one range of seeds and evaluating on another holds buildings out.

Arguments and their ranges (anything else is a ``ValueError`` naming the argument; the door
search's own, ``window`` and the rest, as :mod:`~semsearch_cli.envs.doors`): ``layout`` and
``numbering`` as ``semsearch generate building`` takes them; ``first_building`` an integer
0..2^32-1 and ``buildings`` 1..2^32 - ``first_building`` (the seeds ``--seed`` takes);
``spacing`` 0.5..50 m (as ``--spacing``). ``options["building"]`` names a seed of this
environment's range, ``first_building .. first_building + buildings - 1``: a building outside it
(one held out) is refused, never run by a training environment without a word; make an environment
with that ``first_building`` to run it.
"""

from __future__ import annotations

import copy
import os
import shutil
import tempfile
from pathlib import Path

from gymnasium.utils import seeding

from ..world.buildings.numbered import LAYOUTS, SCHEMES, generate_building
from .base import check_choice, check_number, check_options, load_task
from .doors import DoorSearchEnv

MAX_SEED = 2**32 - 1  # the largest building seed, as `semsearch generate building --seed`
SPACING = (0.5, 50.0)  # m between door slots, as `semsearch generate building --spacing` (0 divided by zero)

_FOLDER: tempfile.TemporaryDirectory | None = None


def building(layout: str, numbering: str, seed: int, spacing: float) -> Path:
    """The scenario of a generated building, written once per process."""
    global _FOLDER
    if _FOLDER is None:
        _FOLDER = tempfile.TemporaryDirectory(prefix="semsearch-buildings-")
    out = Path(_FOLDER.name) / f"{layout}-{numbering}-{seed}-{spacing!r}"  # not :g, which wrote 3 for 3.0000001
    if not (out / "scenario.yaml").is_file():
        # written aside and renamed into place: processes forked from one parent share the
        # folder, and one must never read a building another is still writing
        tmp = out.with_name(f"{out.name}.{os.getpid()}")
        generate_building(layout, numbering, seed, tmp, spacing=spacing)
        try:
            os.rename(tmp, out)
        except OSError:  # another process put it there first: the same building
            shutil.rmtree(tmp, ignore_errors=True)
    return out / "scenario.yaml"


class GeneratedDoorSearchEnv(DoorSearchEnv):
    """:class:`DoorSearchEnv` over generated buildings (see the module docstring)."""

    reset_keys = ("building", "episode", "repeat")
    id_name = "DoorSearch-Generated"

    def __init__(self, layout: str = "wings", numbering: str = "odd-even-out", buildings: int = 100,
                 first_building: int = 0, spacing: float = 3.0, **kwargs):
        check_choice("layout", layout, LAYOUTS)
        check_choice("numbering", numbering, SCHEMES)
        first_building = check_number("first_building", first_building, 0, MAX_SEED, integer=True)
        buildings = check_number("buildings", buildings, 1, MAX_SEED + 1 - first_building, integer=True,
                                 note=f"seeds {first_building} onwards, at most {MAX_SEED}")
        spacing = check_number("spacing", spacing, *SPACING, unit="m")
        self.layout, self.numbering, self.spacing = layout, numbering, spacing
        self.buildings, self.first = buildings, first_building
        if "scenario" in kwargs:  # was dropped without a word
            raise ValueError("scenario: DoorSearch-Generated-v1 generates its buildings (layout, numbering, buildings, "
                             "first_building, spacing); run a scenario file with semsearch/DoorSearch-v1")
        super().__init__(building(layout, numbering, self.first, spacing), **kwargs)
        self._init_args = {k: v for k, v in self._init_args.items() if k != "scenario"}
        self._init_args.update(layout=layout, numbering=numbering, buildings=buildings, first_building=first_building,
                               spacing=spacing)
        self.building_seed = self.first

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        # everything checked before anything changes: a refused reset (a building outside the
        # range, an episode the building has not) leaves the environment as it was, its generator,
        # its building and the task its steps read (a primitive step read the new building's map
        # with the old episode's robot)
        options = check_options(options, self.reset_keys)
        seed = None if seed is None else check_number("seed", seed, 0, integer=True)
        b = options.pop("building", None)
        last = self.first + self.buildings - 1
        if b is not None:
            b = check_number("options['building']", b, self.first, last, integer=True, note="this environment's buildings")
        # the generator the reset draws from, committed only once every option is checked: seeded
        # here (the building is drawn before the episode), else a copy of the environment's own
        rng, rng_seed = seeding.np_random(seed) if seed is not None else (copy.deepcopy(self.np_random), self._np_random_seed)
        b = self.first + int(rng.integers(self.buildings)) if b is None else b
        task = load_task(building(self.layout, self.numbering, b, self.spacing), self.kind)
        _, options = self.check_reset(None, options, task)
        self._np_random, self._np_random_seed = rng, rng_seed
        self.building_seed = b
        self.bind(task)
        obs, info = super().reset(options=options)
        self._reset_options = {**self._reset_options, "building": self.building_seed}
        return obs, info

    def _info(self) -> dict:
        return {**super()._info(), "building": self.building_seed}
