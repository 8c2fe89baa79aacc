"""The authors' maps (read from ../shared, never copied): import and shortest paths."""

import pytest

from semsearch_cli.runner import Loaded
from semsearch_cli.world.importers.mobilesim import import_mobilesim

from .conftest import REF, needs_reference

# thesis Tables 4.7, 4.8 and, for Normal (Table 4.6 is held out of our copy), the shortest path
# implied by Table 4.10: Greedy mean / (percent of optimal / 100) on both its rows.
THESIS = {
    "par_impar_par_impar": ((25.5, 28.5), 4.5, {54: 121.94 / 7.0937, 55: 132.68 / 4.9745, 111: 170.69 / 4.5602, 124: 148.50 / 4.4783}),
    "par_impar_par_impar_inverse": ((25.5, 28.5), 4.5, {54: 7.65, 55: 15.98, 111: 40.67, 124: 24.65}),
    "hotel2": ((46.0, 64.0), 2.5, {76: 63.16, 135: 72.51, 148: 75.81, 185: 52.53}),
}


@needs_reference()
@pytest.mark.parametrize("name", sorted(THESIS))
def test_shortest_paths_within_ten_percent_of_thesis(name, tmp_path):
    start, delta, published = THESIS[name]
    p, _ = import_mobilesim(REF / f"{name}.map", REF / f"{name}.doors", tmp_path, 0.1, start, list(published), delta)
    L = Loaded.load(p)
    assert len(L.world.signs) == {"hotel2": 124, "par_impar_par_impar": 113, "par_impar_par_impar_inverse": 116}[name]
    for goal, ref in published.items():
        assert L.shortest[goal] == pytest.approx(ref, rel=0.10), (goal, L.shortest[goal], ref)
