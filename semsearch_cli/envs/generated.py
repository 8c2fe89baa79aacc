"""``semsearch/DoorSearch-Generated-v0``: door search in a building generated at each reset.

Each reset draws a building seed among ``first_building .. first_building + buildings - 1`` (or
takes ``options["building"]``), generates that building as ``semsearch generate building --layout
LAYOUT --numbering NUMBERING --seed SEED --spacing SPACING`` would (into a folder of this process,
once per seed), and draws an episode of it: its four goals spread by distance, from its start, a
random heading. Training on one range of seeds and evaluating on another holds buildings out.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from gymnasium.utils import seeding

from ..world.buildings.numbered import LAYOUTS, SCHEMES, generate_building
from .base import load_task
from .doors import DoorSearchEnv

_FOLDER: tempfile.TemporaryDirectory | None = None


def building(layout: str, numbering: str, seed: int, spacing: float) -> Path:
    """The scenario of a generated building, written once per process."""
    global _FOLDER
    if _FOLDER is None:
        _FOLDER = tempfile.TemporaryDirectory(prefix="semsearch-buildings-")
    out = Path(_FOLDER.name) / f"{layout}-{numbering}-{seed}-{spacing:g}"
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

    def __init__(self, layout: str = "wings", numbering: str = "odd-even-out", buildings: int = 100,
                 first_building: int = 0, spacing: float = 3.0, **kwargs):
        if layout not in LAYOUTS:
            raise ValueError(f"layout must be one of {', '.join(LAYOUTS)}, not {layout!r}")
        if numbering not in SCHEMES:
            raise ValueError(f"numbering must be one of {', '.join(SCHEMES)}, not {numbering!r}")
        if buildings < 1 or first_building < 0:
            raise ValueError("buildings must be at least 1 and first_building at least 0")
        self.layout, self.numbering, self.buildings, self.first, self.spacing = layout, numbering, int(buildings), int(first_building), spacing
        kwargs.pop("scenario", None)
        super().__init__(building(layout, numbering, self.first, spacing), **kwargs)
        self._init_args = {k: v for k, v in self._init_args.items() if k != "scenario"}
        self._init_args.update(layout=layout, numbering=numbering, buildings=buildings, first_building=first_building,
                               spacing=spacing)
        self.building_seed = self.first

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        if seed is not None:  # seed the generator here: the building is drawn before the episode
            self._np_random, self._np_random_seed = seeding.np_random(seed)
        options = dict(options or {})
        b = options.pop("building", None)
        self.building_seed = self.first + int(self.np_random.integers(self.buildings)) if b is None else int(b)
        self.bind(load_task(building(self.layout, self.numbering, self.building_seed, self.spacing), self.kind))
        obs, info = super().reset(options=options)
        self._reset_options = {**self._reset_options, "building": self.building_seed}
        return obs, info

    def _info(self) -> dict:
        return {**super()._info(), "building": self.building_seed}
