"""The shipped scenario library matches the thesis' Table 4.1 and loads as it is."""

from pathlib import Path

import pytest

from semsearch_cli.runner import Loaded
from semsearch_cli.planners import expand_variants

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
TABLE_4_1 = {"normal": (113, [54, 55, 111, 124]), "inverse": (116, [54, 55, 111, 124]),
             "hotel_thesis": (124, [76, 135, 148, 185]), "kth": (47, [756])}


@pytest.mark.parametrize("name", sorted(TABLE_4_1))
def test_config_matches_table_4_1(name):
    L = Loaded.load(CONFIGS / f"{name}.yaml")
    signs, goals = TABLE_4_1[name]
    assert len(L.world.signs) == signs
    assert L.sc.goals == goals
    assert [v.label for v in expand_variants(L.sc.planners)] == ["greedy", "bvp", "nsos[alpha=0.8]", "nsos[alpha=0.9]", "nsos[alpha=1.0]"]
    assert L.sc.experiment.seeds == 10 and L.sc.episodes is None  # the thesis' fixed start, one episode per goal
    assert all(L.world.readable_mask(i).any() for i in range(len(L.world.signs)))


def test_the_main_job_draws_ten_starts_per_goal():
    thesis, main = Loaded.load(CONFIGS / "hotel_thesis.yaml"), Loaded.load(CONFIGS / "hotel.yaml")
    assert list(main.world.signs.number) == list(thesis.world.signs.number) and main.sc.goals == thesis.sc.goals
    eps = main.task.episodes
    assert len(eps) == 40 and all(sum(e.goal == g for e in eps) == 10 for g in main.sc.goals)
    assert min(e.shortest_m for e in eps) >= 10.0 and main.sc.experiment.seeds == 1


def test_numbering_follows_the_thesis_description():
    import numpy as np

    normal = Loaded.load(CONFIGS / "normal.yaml").world
    inverse = Loaded.load(CONFIGS / "inverse.yaml").world
    # the same building, numbered in opposite directions from its middle
    assert (normal.free == inverse.free).all()
    mid_x = normal.frame.width * normal.frame.res / 2

    def corr(w):
        """Per corridor (a hundred-block and a parity) and per half: the correlation of the
        number with the distance from the middle."""
        num = w.signs.value.astype(int)
        out = []
        for key in set(zip(num // 100, num % 2)):
            for half in (w.signs.x > mid_x, w.signs.x < mid_x):
                m = half & (num // 100 == key[0]) & (num % 2 == key[1])
                out.append(np.corrcoef(num[m], np.abs(w.signs.x[m] - mid_x))[0, 1])
        return np.array(out)

    # one parity per corridor, rising from the middle outward (Normal) or inward (Inverse)
    assert len(corr(normal)) == 8 and (corr(normal) > 0.9).all() and (corr(inverse) < -0.9).all()
    kth = Loaded.load(CONFIGS / "kth.yaml").world
    assert all(str(n).startswith("7") for n in kth.signs.number)
