"""The authors' Hotel reference map as a scenario, for the benchmarks that read it: imported from
../shared/reference_maps into a temporary folder (never copied into the repository), at the thesis'
start, 0.1 m cells and segmentation delta, its four goals."""

from __future__ import annotations

import tempfile
from pathlib import Path

from thesis import MAPS

from semsearch_cli.runner import Loaded
from semsearch_cli.world.importers.mobilesim import import_mobilesim

REF = Path(__file__).resolve().parents[2] / "shared" / "reference_maps"


def hotel(prefix: str = "semsearch-") -> Loaded | None:
    """The Hotel reference scenario (goals 76, 135, 148, 185), or None, having said why, when
    ../shared is absent."""
    if not REF.is_dir():
        print(f"skipped: the authors' reference maps are not at {REF} (../shared absent)")
        return None
    _, start, delta = MAPS["hotel2"]
    tmp = Path(tempfile.mkdtemp(prefix=prefix))
    p, _ = import_mobilesim(REF / "hotel2.map", REF / "hotel2.doors", tmp / "hotel", 0.1, start, [76, 135, 148, 185], delta,
                            "hotel-reference")
    return Loaded.load(p)
