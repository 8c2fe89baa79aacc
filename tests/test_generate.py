"""Generated buildings: every layout and scheme gives a valid scenario with the promised numbering."""

import csv

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.runner import Loaded
from semsearch_cli.world.buildings.numbered import LAYOUTS, SCHEMES, generate_building


def doors(path):
    with open(path / "doors.csv") as fh:
        return [(int(r["number"]), float(r["x"]), float(r["y"]), float(r["facing"])) for r in csv.DictReader(fh)]


@pytest.mark.parametrize("layout", LAYOUTS)
def test_every_layout_validates(layout, tmp_path):
    p = generate_building(layout, "odd-even-out", 1, tmp_path, spacing=4.0)
    L = Loaded.load(p)  # every loader check: start free, signs next to free space, goals reachable
    assert len(L.world.signs) >= 10
    assert all(np.isfinite(v) for v in L.shortest.values())
    # every sign is readable from somewhere reachable
    assert all(L.world.readable_mask(i).any() for i in range(len(L.world.signs)))


def test_odd_even_out_on_a_single_corridor(tmp_path):
    generate_building("single", "odd-even-out", 0, tmp_path)
    d = doors(tmp_path)
    start_x = 2.0 + (np.random.default_rng(0).uniform(-8, 8) + 60.0) / 2
    for parity in (0, 1):
        side = sorted((abs(x - start_x), n) for n, x, y, f in d if n % 2 == parity)
        nums = [n for _, n in side]
        assert nums == sorted(nums)  # rising away from the middle
    ys_odd = {round(y, 1) for n, x, y, f in d if n % 2 == 1 and x > start_x}
    ys_even = {round(y, 1) for n, x, y, f in d if n % 2 == 0 and x > start_x}
    assert len(ys_odd) == 1 and len(ys_even) == 1 and ys_odd != ys_even  # one wall each, beyond the start


def test_odd_even_in_reverses(tmp_path):
    generate_building("single", "odd-even-out", 0, tmp_path / "a")
    generate_building("single", "odd-even-in", 0, tmp_path / "b")
    a = {(round(x, 2), round(y, 2)): n for n, x, y, f in doors(tmp_path / "a")}
    b = {(round(x, 2), round(y, 2)): n for n, x, y, f in doors(tmp_path / "b")}
    far = max(a, key=lambda k: a[k])
    assert b[far] in (1, 2)  # the farthest door carries the smallest number


def test_floor_blocks_and_random(tmp_path):
    generate_building("grid", "floor", 0, tmp_path / "f")
    nums = sorted(n for n, *_ in doors(tmp_path / "f"))  # floor digit first, running on past 299 (no 2100)
    assert nums[0] == 201 and len(set(nums)) == len(nums) and len(nums) > 99 and max(nums) < 200 + 2 * len(nums)
    generate_building("grid", "blocks", 0, tmp_path / "b")
    assert {n // 100 for n, *_ in doors(tmp_path / "b")} == set(range(1, 8))  # 7 corridors, one block each
    generate_building("grid", "random", 0, tmp_path / "r")
    d = doors(tmp_path / "r")
    assert len({n for n, *_ in d}) == len(d)
    y0 = min(y for _, _, y, _ in d)
    along = [n for n, x, y, f in sorted(d, key=lambda r: r[1]) if abs(y - y0) < 0.2]  # one wall, by x
    assert len(along) > 10 and along != sorted(along) and along != sorted(along, reverse=True)


def test_sign_count_and_goals_are_kept(tmp_path):
    generate_building("wings", "blocks", 0, tmp_path, signs=50, goals=[101, 305])
    nums = [n for n, *_ in doors(tmp_path)]
    assert len(nums) == 50 and {101, 305} <= set(nums)


def test_generate_command_and_errors(tmp_path):
    r = CliRunner().invoke(app, ["generate", "building", "--layout", "angled", "--numbering", "random", "--seed", "3", "--out", str(tmp_path / "g")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "g" / "scenario.yaml").is_file()
    r = CliRunner().invoke(app, ["generate", "building", "--layout", "maze", "--numbering", "random", "--out", str(tmp_path / "x")])
    assert r.exit_code == 2 and "--layout" in r.output
    r = CliRunner().invoke(app, ["generate", "building", "--layout", "single", "--numbering", "floor", "--goals", "999", "--out", str(tmp_path / "y")])
    assert r.exit_code == 2 and "--goals" in r.output


def test_generate_batch_covers_every_layout_and_scheme(tmp_path):
    r = CliRunner().invoke(app, ["generate", "batch", "--out", str(tmp_path), "--seeds", "1", "--runs", "2"])
    assert r.exit_code == 0, r.output
    index = (tmp_path / "index.txt").read_text().split()
    assert len(index) == len(LAYOUTS) * len(SCHEMES)
    names = {line.split("/")[0].rsplit("-", 1)[0] for line in index}
    assert names == {f"{lay}-{sch}" for lay in LAYOUTS for sch in SCHEMES}
    L = Loaded.load(tmp_path / index[0])
    assert L.sc.experiment.seeds == 2 and [p.name for p in L.sc.planners] == ["greedy", "nsos"]


def test_corridor_parity_gives_each_long_corridor_one_parity(tmp_path):
    """The authors' Normal: every long corridor one parity on both walls, even and odd in turn
    from the start's corridor, a hundred-block per pair; rising outward from the middle, the
    walls alternating; no signs on the cross corridors."""
    generate_building("grid", "corridor-parity", 3, tmp_path / "n", spacing=2.7)
    generate_building("grid", "corridor-parity-in", 3, tmp_path / "i", spacing=2.7)
    d = doors(tmp_path / "n")
    assert all(f in (90.0, -90.0) for n, x, y, f in d)  # horizontal walls only: cross corridors unsigned
    rows = {}
    for n, x, y, f in d:  # a corridor = the two walls facing each other, 2 m apart
        key = round((y + (1.0 if f == 90.0 else -1.0)) / 2.0)  # centre line, rounded to 2 m
        rows.setdefault(key, []).append((n, x, y))
    assert len(rows) == 4
    top_down = [rows[k] for k in sorted(rows, reverse=True)]  # the start is on the top corridor
    for k, signs in enumerate(top_down):
        parities = {n % 2 for n, _, _ in signs}
        assert parities == {0 if k % 2 == 0 else 1}  # even, odd, even, odd
        assert {n // 100 for n, _, _ in signs} == {k // 2}
        assert len({round(y, 1) for _, _, y in signs}) == 2  # on both walls
        mid = 25.0
        right = sorted((x, n) for n, x, _ in signs if x > mid)
        assert [n for _, n in right] == sorted(n for _, n in right)  # rising from the middle outward
    inv = {(round(x, 2), round(y, 2)): n for n, x, y, f in doors(tmp_path / "i")}
    nor = {(round(x, 2), round(y, 2)): n for n, x, y, f in d}
    assert set(inv) == set(nor)
    assert all(inv[p] % 2 == nor[p] % 2 and inv[p] // 100 == nor[p] // 100 for p in nor)  # same corridors
    far_right = max((p for p in nor if nor[p] < 100 and nor[p] % 2 == 0), key=lambda p: p[0])
    assert inv[far_right] in (2, 4)  # the Inverse starts at the corridor's end


def test_generate_batch_picks_layouts_and_schemes(tmp_path):
    r = CliRunner().invoke(app, ["generate", "batch", "--out", str(tmp_path), "--seeds", "1", "--layouts", "single",
                                 "--schemes", "corridor-parity,floor"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "index.txt").read_text().split() == ["single-corridor-parity-0/scenario.yaml", "single-floor-0/scenario.yaml"]
    r = CliRunner().invoke(app, ["generate", "batch", "--out", str(tmp_path / "x"), "--schemes", "parity"])
    assert r.exit_code == 2 and "--schemes" in r.output and "corridor-parity" in r.output


def test_a_scaled_building_is_larger_with_corridors_as_wide(tmp_path):
    imgs = {}
    for k in (1.0, 2.0):
        p = generate_building("single", "odd-even-out", 0, tmp_path / f"x{k:g}", scale=k)
        imgs[k] = cv2.imread(str(p.parent / "map.png"), cv2.IMREAD_GRAYSCALE) >= 200
    (h1, w1), (h2, w2) = imgs[1.0].shape, imgs[2.0].shape
    assert abs(w2 - 2 * w1) <= 2 and abs(h2 - 2 * h1) <= 2
    assert imgs[1.0][:, w1 // 2].sum() == imgs[2.0][:, w2 // 2].sum() > 0  # the 2 m corridor, as many cells across
