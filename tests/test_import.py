"""MobileSim import on a small line map written here; ROS maps saved as map_saver saves them."""

from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.runner import Loaded
from semsearch_cli.world.ros_map import read_ros_map

ROOT = Path(__file__).resolve().parents[1]


def test_import_mobilesim_snaps_signs_and_runs(tmp_path):
    # a 20 m x 2 m corridor (mm), closed at both ends; signs 0.5 m behind its walls
    lines = ["0 0 20000 0", "20000 0 20000 2000", "20000 2000 0 2000", "0 2000 0 0"]
    (tmp_path / "c.map").write_text("2D-Map\nResolution: 0\nNumLines: 4\nLINES\n" + "\n".join(lines) + "\nDATA\n")
    (tmp_path / "c.doors").write_text("5.0 -0.5 1 90\n5.0 2.5 2 -90\n15.0 -0.5 3 90\n15.0 2.5 4 -90\n")
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["import", "mobilesim", str(tmp_path / "c.map"), str(tmp_path / "c.doors"),
                                   "--out", str(out), "--start", "2,1", "--goals", "3,4"])
    assert res.exit_code == 0, res.output
    assert "snapped 4 of 4 signs onto the walls" in res.output.replace("\n", " "), res.output
    L = Loaded.load(out / "scenario.yaml")
    s = L.world.signs
    # snapped onto the wall faces of the corridor, facing into it
    assert np.allclose(s.y, [0.05, 1.95, 0.05, 1.95], atol=0.06)
    assert np.allclose(np.degrees(s.facing), [90, -90, 90, -90])
    assert L.shortest[3] > 12.0 and L.shortest[4] > 12.0
    res = CliRunner().invoke(app, ["run", str(out / "scenario.yaml"), "--seeds", "1", "--workers", "1", "--out", str(tmp_path / "r")])
    assert res.exit_code == 0, res.output


def test_import_reports_bad_start(tmp_path):
    (tmp_path / "c.map").write_text("LINES\n0 0 1000 0\n1000 0 1000 1000\n1000 1000 0 1000\n0 1000 0 0\nDATA\n")
    (tmp_path / "c.doors").write_text("0.5 -0.2 1 90\n")
    res = CliRunner().invoke(app, ["import", "mobilesim", str(tmp_path / "c.map"), str(tmp_path / "c.doors"),
                                   "--out", str(tmp_path / "o"), "--start", "5,5"])
    assert res.exit_code == 2 and "--start" in res.output


KTH_XML = """<?xml version="1.0" encoding="UTF-8"?>
<floor BuildingName="B" FloorName="F">
  <Scale PixelDistance="100" RealDistance="1"/>
  <space name="B_100" type="KORRIDOR"><contour>
    <linesegment x1="0" y1="0" x2="1000" y2="0" type="Wall" target=""/>
    <linesegment x1="1000" y1="0" x2="1000" y2="200" type="Portal" target="B_200"/>
    <linesegment x1="1000" y1="200" x2="0" y2="200" type="Wall" target=""/>
    <linesegment x1="0" y1="200" x2="0" y2="0" type="Wall" target=""/>
  </contour></space>
  <space name="B_200" type="KORRIDOR"><contour>
    <linesegment x1="1030" y1="0" x2="2000" y2="0" type="Wall" target=""/>
    <linesegment x1="2000" y1="0" x2="2000" y2="200" type="Wall" target=""/>
    <linesegment x1="2000" y1="200" x2="1030" y2="200" type="Wall" target=""/>
    <linesegment x1="1030" y1="200" x2="1030" y2="0" type="Portal" target="B_100"/>
  </contour></space>
  <space name="B_101" type="KONTOR"><contour>
    <linesegment x1="300" y1="-20" x2="400" y2="-20" type="Portal" target="B_100"/>
    <linesegment x1="600" y1="-20" x2="700" y2="-20" type="Portal" target="B_100"/>
  </contour></space>
  <space name="B_WC" type="TOALETT"><contour>
    <linesegment x1="1500" y1="220" x2="1600" y2="220" type="Portal" target="B_200"/>
  </contour></space>
  <space name="B_202" type="KONTOR"><contour>
    <linesegment x1="1800" y1="-20" x2="1900" y2="-20" type="Portal" target="B_200"/>
  </contour></space>
</floor>
"""


def test_import_kth_bridges_corridors_and_labels_doors(tmp_path):
    (tmp_path / "f.xml").write_text(KTH_XML)
    res = CliRunner().invoke(app, ["import", "kth", str(tmp_path / "f.xml"), "--out", str(tmp_path / "o"), "--goals", "202"])
    assert res.exit_code == 0, res.output
    L = Loaded.load(tmp_path / "o" / "scenario.yaml")
    assert sorted(map(str, L.world.signs.number)) == ["101", "101/2", "202", "WC"]
    assert L.world.signs.value.tolist().count(-1) == 2  # "101/2" and "WC" are text
    assert L.world.reach.sum() > 1500  # both corridors (20 m x 2 m) joined through the portal
    assert all(L.world.readable_mask(i).any() for i in range(4))
    # pixel y points down: room 101 (y = -20 px) lies above the corridor (0..200 px), so its sign is
    # on the corridor's upper wall in the world too, facing down into it
    i = L.world.signs.index_of(101)
    assert np.degrees(L.world.signs.facing[i]) == -90.0
    assert L.world.signs.y[i] > L.world.signs.y[L.world.signs.index_of("WC")]


def test_import_kth_reference_floor(tmp_path):
    from .conftest import REF

    f = REF / "kth" / "0510035517_A_40_1_105.xml"
    if not f.is_file():
        import pytest

        pytest.skip(f"the KTH sample floor is not at {f} (../shared absent)")
    from semsearch_cli.world.importers.kth import import_kth

    L = Loaded.load(import_kth(f, tmp_path)[0])
    # one per room-to-circulation portal: 53 into its KORRIDOR spaces, 10 into two untyped halls
    # and an anteroom (each joined to three or more spaces)
    assert len(L.world.signs) == 63
    assert all(L.world.readable_mask(i).any() for i in range(len(L.world.signs)))


def saved_like_map_saver(tmp_path, origin=(-3.0, -2.0)):
    """Our demo map saved as ROS's map_saver saves one: a PGM with free 254, occupied 0, unknown
    205, and its YAML (negate 0, thresholds 0.65 / 0.196), the origin moved to ``origin``."""
    img = cv2.imread(str(ROOT / "maps" / "demo" / "map.png"), cv2.IMREAD_GRAYSCALE)
    pgm = np.where(img >= 200, 254, np.where(img < 100, 0, 205)).astype(np.uint8)
    cv2.imwrite(str(tmp_path / "lab.pgm"), pgm)
    (tmp_path / "lab.yaml").write_text(f"image: lab.pgm\nresolution: 0.1\norigin: [{origin[0]}, {origin[1]}, 0.0]\n"
                                       "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    doors = (ROOT / "maps" / "demo" / "doors.csv").read_text().splitlines()
    rows = [doors[0]] + [f"{n},{float(x) + origin[0]},{float(y) + origin[1]},{f}" for n, x, y, f in
                         (line.split(",") for line in doors[1:])]
    (tmp_path / "doors.csv").write_text("\n".join(rows) + "\n")
    return img, pgm


def test_a_ros_map_reads_as_map_server_reads_it(tmp_path):
    img, pgm = saved_like_map_saver(tmp_path)
    grey, res, origin = read_ros_map(tmp_path / "lab.yaml")
    assert res == 0.1 and origin == (-3.0, -2.0)
    assert ((grey == 255) == (img >= 200)).all() and ((grey == 0) == (img < 100)).all()
    # 205 is p = 50/255 = 0.196: not below free_thresh, so unknown, as map_server has it
    assert (grey[pgm == 205] == 128).all()
    (tmp_path / "neg.yaml").write_text("image: lab.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 1\n")
    neg, _, _ = read_ros_map(tmp_path / "neg.yaml")
    # negated, p = v / 255: 254 and 205 are occupied (above 0.65), 0 is free
    assert ((neg == 0) == (pgm >= 205)).all() and ((neg == 255) == (pgm == 0)).all()


def test_import_ros_writes_a_scenario_that_runs(tmp_path):
    saved_like_map_saver(tmp_path)
    with (tmp_path / "doors.csv").open("a") as fh:
        fh.write("999,80.0,80.0,0\n")  # far outside the building: no pose could read it
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "lab.yaml"), str(tmp_path / "doors.csv"),
                                   "--out", str(out), "--goals", "304"])
    assert res.exit_code == 0, res.output
    assert "dropped 1 signs more than 2 m from the free space" in res.output.replace("\n", " ") and "999" in res.output
    d = yaml.safe_load((out / "scenario.yaml").read_text())
    assert d["map"] == {"ros": "map.yaml"} and (out / "lab.pgm").is_file()
    ros = Loaded.load(out / "scenario.yaml")
    demo = Loaded.load(ROOT / "configs" / "demo.yaml")
    assert ros.world.frame.origin_x == -3.0 and (ros.world.free == demo.world.free).all()
    assert ros.world.signs.index_of(999) == -1 and len(ros.world.signs) == len(demo.world.signs)
    assert ros.shortest[304] > 0
    res = CliRunner().invoke(app, ["run", str(out / "scenario.yaml"), "--seeds", "1", "--planner", "greedy",
                                   "--workers", "1", "--out", str(tmp_path / "r")])
    assert res.exit_code == 0, res.output
    assert (pd.read_csv(tmp_path / "r" / "runs.csv")["outcome"] == "found").all()


def test_a_rotated_or_incomplete_ros_map_names_the_key(tmp_path):
    saved_like_map_saver(tmp_path)
    (tmp_path / "rot.yaml").write_text("image: lab.pgm\nresolution: 0.1\norigin: [0, 0, 0.5]\n")
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "rot.yaml"), str(tmp_path / "doors.csv"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "origin" in res.output and "rotated" in res.output, res.output
    (tmp_path / "bad.yaml").write_text("image: lab.pgm\norigin: [0, 0, 0]\n")
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "bad.yaml"), str(tmp_path / "doors.csv"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "resolution" in res.output, res.output


KTH_PASSAGE = """<?xml version="1.0" encoding="UTF-8"?>
<floor BuildingName="B" FloorName="F">
  <Scale PixelDistance="100" RealDistance="1"/>
  <space name="B_P1" type="PASSAGE"><contour>
    <linesegment x1="0" y1="0" x2="1000" y2="0" type="Wall" target=""/>
    <linesegment x1="1000" y1="0" x2="1000" y2="200" type="Portal" target="B_H"/>
    <linesegment x1="1000" y1="200" x2="0" y2="200" type="Wall" target=""/>
    <linesegment x1="0" y1="200" x2="0" y2="0" type="Wall" target=""/>
  </contour></space>
  <space name="B_H"><contour>
    <linesegment x1="1030" y1="0" x2="1600" y2="0" type="Wall" target=""/>
    <linesegment x1="1600" y1="0" x2="1600" y2="200" type="Portal" target="B_STAIR"/>
    <linesegment x1="1600" y1="200" x2="1030" y2="200" type="Portal" target="B_302"/>
    <linesegment x1="1030" y1="200" x2="1030" y2="0" type="Portal" target="B_P1"/>
  </contour></space>
  <space name="B_301" type="KONTOR"><contour>
    <linesegment x1="300" y1="-20" x2="400" y2="-20" type="Portal" target="B_P1"/>
  </contour></space>
  <space name="B_302" type="KONTOR"><contour>
    <linesegment x1="1300" y1="220" x2="1400" y2="220" type="Portal" target="B_H"/>
  </contour></space>
  <space name="B_STAIR" type="TRAPPA"><contour>
    <linesegment x1="1620" y1="50" x2="1620" y2="150" type="Portal" target="B_H"/>
  </contour></space>
</floor>
"""


def test_import_kth_drives_in_passages_and_untyped_halls(tmp_path):
    """A floor with no KORRIDOR: a PASSAGE and an untyped hall joined to three other spaces are
    the circulation; the default goals are readable signs; --corridor-types narrows the set."""
    (tmp_path / "f.xml").write_text(KTH_PASSAGE)
    res = CliRunner().invoke(app, ["import", "kth", str(tmp_path / "f.xml"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    L = Loaded.load(tmp_path / "o" / "scenario.yaml")
    assert sorted(map(str, L.world.signs.number)) == ["301", "302", "STAIR"]
    assert L.world.reach.sum() > 800  # the passage and the hall, joined through their portal
    assert all(np.isfinite(L.world.shortest_path(g)) for g in L.sc.goals)
    res = CliRunner().invoke(app, ["import", "kth", str(tmp_path / "f.xml"), "--out", str(tmp_path / "k"),
                                   "--corridor-types", "KORRIDOR"])
    # the untyped hall alone still counts; with no circulation at all the import exits 2
    assert res.exit_code == 0, res.output
    (tmp_path / "g.xml").write_text(KTH_PASSAGE.replace('<space name="B_H">', '<space name="B_H" type="KONTOR">'))
    res = CliRunner().invoke(app, ["import", "kth", str(tmp_path / "g.xml"), "--out", str(tmp_path / "g"),
                                   "--corridor-types", "KORRIDOR"])
    assert res.exit_code == 2 and "no circulation space" in res.output and "PASSAGE" in res.output, res.output


@pytest.mark.parametrize("line,key", [("occupied_thresh: 1.5", "occupied_thresh"), ("free_thresh: -0.1", "free_thresh"),
                                      ("free_thresh: 0.9", "free_thresh"), ("negate: 'yes'", "negate"),
                                      ("negate: 2", "negate"), ("occupied_thresh: abc", "occupied_thresh"),
                                      ("mode: fancy", "mode")])
def test_ros_keys_are_checked_as_map_server_checks_them_each_error_naming_its_key(tmp_path, line, key):
    saved_like_map_saver(tmp_path)
    (tmp_path / "bad.yaml").write_text(f"image: lab.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n{line}\n")
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "bad.yaml"), str(tmp_path / "doors.csv"),
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and f"field '{key}'" in res.output and "Traceback" not in res.output, res.output


def test_a_string_origin_is_not_read_as_digits(tmp_path):
    saved_like_map_saver(tmp_path)
    (tmp_path / "bad.yaml").write_text("image: lab.pgm\nresolution: 0.1\norigin: '100'\n")
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "bad.yaml"), str(tmp_path / "doors.csv"),
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "field 'origin'" in res.output and "three numbers" in res.output, res.output


def test_import_ros_keeps_each_signs_facing_and_lists_what_it_changed(tmp_path):
    """Every demo sign given a slanted facing (30 degrees off its wall's normal) keeps it; one
    turned to face its own wall is re-faced, square to the wall, and listed."""
    saved_like_map_saver(tmp_path)
    lines = (tmp_path / "doors.csv").read_text().splitlines()
    rows = [ln.split(",") for ln in lines[1:]]
    given = {int(n): (float(f) + 30.0) for n, x, y, f in rows}
    n0 = int(rows[0][0])
    given[n0] = float(rows[0][3]) + 180.0  # faces its own wall
    (tmp_path / "doors.csv").write_text(lines[0] + "\n" + "\n".join(f"{n},{x},{y},{given[int(n)]}" for n, x, y, f in rows) + "\n")
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "lab.yaml"), str(tmp_path / "doors.csv"), "--out", str(out)])
    assert res.exit_code == 0, res.output
    got = {int(r["number"]): float(r["facing"]) for _, r in pd.read_csv(out / "doors.csv").iterrows()}
    for n, f in given.items():
        if n != n0:
            assert (got[n] - f + 180) % 360 - 180 == pytest.approx(0.0, abs=0.01), n
    assert (got[n0] - float(rows[0][3]) + 180) % 360 - 180 == pytest.approx(0.0, abs=0.01)
    text = res.output.replace("\n", " ")
    assert "re-faced 1 signs" in text and f"sign {n0}: " in text and "pointed into the wall" in text


def test_an_import_that_would_not_validate_is_exit_2_and_writes_nothing(tmp_path):
    """A goal that is not a sign: the scenario the import would write fails `semsearch validate`,
    so the import says so (exit 2) and leaves --out as it was."""
    saved_like_map_saver(tmp_path)
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "lab.yaml"), str(tmp_path / "doors.csv"),
                                   "--out", str(out), "--goals", "12345"])
    assert res.exit_code == 2 and "would not validate" in res.output and "Traceback" not in res.output, res.output
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("old,new,where", [
    ('PixelDistance="100"', 'PixelDistance="0"', "PixelDistance"),
    ('RealDistance="1"', 'RealDistance="abc"', "RealDistance"),
    ('x1="0" y1="0" x2="1000" y2="0"', 'y1="0" x2="1000" y2="0"', "x1"),
    ('x1="0" y1="0" x2="1000" y2="0"', 'x1="1e12" y1="0" x2="1000" y2="0"', "from the origin"),
    ('x1="0" y1="0" x2="1000" y2="0"', 'x1="nan" y1="0" x2="1000" y2="0"', "x1"),
    ('<space name="B_301" type="KONTOR">', '<space type="KONTOR">', "without a name"),
])
def test_a_malformed_kth_floor_is_exit_2_naming_the_element_and_attribute(tmp_path, old, new, where):
    assert old in KTH_PASSAGE
    (tmp_path / "f.xml").write_text(KTH_PASSAGE.replace(old, new, 1))
    res = CliRunner().invoke(app, ["import", "kth", str(tmp_path / "f.xml"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and where in res.output and "Traceback" not in res.output, res.output


def test_import_ros_clean_removes_laser_fans_and_unreachable_space(tmp_path):
    """The demo map saved as map_saver saves it, plus what SLAM leaves: five one-pixel laser rays
    from the corridor out through the walls, and a free blob outside. `--clean` makes them
    outside, keeps the building's free space as the demo has it, and the scenario cleans alike."""
    img, pgm = saved_like_map_saver(tmp_path)
    demo = Loaded.load(ROOT / "configs" / "demo.yaml")
    H, W = pgm.shape
    r0, c0 = demo.world.frame.to_index(*demo.world.start_xy)
    fans = np.zeros_like(pgm)
    for k in range(5):
        cv2.line(fans, (int(c0), int(r0)), (int(c0) + 40 * (k - 2), 0), 1, 1)
    added = (fans > 0) & (pgm != 254)
    pgm[added] = 254
    pgm[H - 6:H - 2, 2:8] = 254  # a blob of free space no robot can reach
    cv2.imwrite(str(tmp_path / "lab.pgm"), pgm)
    res = CliRunner().invoke(app, ["import", "ros", str(tmp_path / "lab.yaml"), str(tmp_path / "doors.csv"),
                                   "--out", str(tmp_path / "out"), "--clean", "--start",
                                   ",".join(f"{v - o}" for v, o in zip(demo.world.start_xy, (3.0, 2.0)))])
    assert res.exit_code == 0, res.output
    assert "cleaned the map" in res.output and yaml.safe_load((tmp_path / "out" / "scenario.yaml").read_text())["map"]["clean"]
    cleaned = Loaded.load(tmp_path / "out" / "scenario.yaml").world
    # of the 439 ray cells, 7 stay: single notches in a wall beside free space, where the tip of
    # the robot's disk fits
    assert cleaned.free[added].sum() <= 0.02 * added.sum() and not cleaned.free[H - 6:H - 2, 2:8].any()
    # the building's free space is the demo's, but for cells next to where a ray crossed a wall
    diff = cleaned.free != demo.world.free
    assert diff.sum() <= 0.01 * demo.world.free.sum()


def test_duplicate_numbers_refused_with_the_option_to_pass_then_imported_under_each_policy(tmp_path):
    # sign 1 twice (as the authors' hotel11 carries 343 twice), on opposite walls of one corridor
    lines = ["0 0 20000 0", "20000 0 20000 2000", "20000 2000 0 2000", "0 2000 0 0"]
    (tmp_path / "c.map").write_text("LINES\n" + "\n".join(lines) + "\nDATA\n")
    (tmp_path / "c.doors").write_text("5.0 -0.5 1 90\n10.0 2.5 1 -90\n15.0 -0.5 3 90\n")
    base = ["import", "mobilesim", str(tmp_path / "c.map"), str(tmp_path / "c.doors"), "--start", "2,1", "--goals", "1"]
    res = CliRunner().invoke(app, [*base, "--out", str(tmp_path / "refused")])
    assert res.exit_code == 2
    assert "1 sign number(s) appear more than once: 1 at (5.05, 0), (10.05, 1.9) (positions after snapping onto the walls)" in res.output
    assert "--duplicates keep-first" in res.output and "--duplicates any" in res.output
    assert not (tmp_path / "refused" / "scenario.yaml").exists()
    for policy, kept in (("keep-first", 2), ("any", 3)):
        out = tmp_path / policy
        res = CliRunner().invoke(app, [*base, "--out", str(out), "--duplicates", policy])
        assert res.exit_code == 0, res.output
        assert yaml.safe_load((out / "scenario.yaml").read_text())["duplicates"] == policy
        assert len(Loaded.load(out / "scenario.yaml").world.signs.x) == kept
    res = CliRunner().invoke(app, [*base, "--out", str(tmp_path / "x"), "--duplicates", "anny"])
    assert res.exit_code == 2 and "did you mean 'any'?" in res.output
