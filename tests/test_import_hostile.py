"""Hostile inputs of the second review (issue 35): each is refused in one paragraph naming the file
or flag and the field (exit 2, no traceback), where it had crashed or been accepted. The Dask
executor's cases that need a scheduler or a cluster are in test_dask.py."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import Loaded
from semsearch_cli.runner.cluster import check_address

ROOT = Path(__file__).resolve().parents[1]
DEMO_DOORS = ROOT / "maps" / "demo" / "doors.csv"


def refused(args: list, *says: str) -> str:
    """The command's output, after checking it exits 2 with no traceback and says each of ``says``."""
    res = CliRunner().invoke(app, [str(a) for a in args])
    text = " ".join(res.output.split())  # the console wraps long lines
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output and not isinstance(res.exception, (IndexError, ValueError, KeyError)), res.output
    for s in says:
        assert s in text, text
    return text


def ros_map(folder: Path, name: str, pgm: np.ndarray, res: float = 0.1) -> Path:
    """A map_saver map (free 254, occupied 0) named ``name`` in ``folder``; returns its YAML."""
    cv2.imwrite(str(folder / f"{name}.pgm"), pgm)
    (folder / f"{name}.yaml").write_text(f"image: {name}.pgm\nresolution: {res}\norigin: [0.0, 0.0, 0.0]\n"
                                         "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return folder / f"{name}.yaml"


def walled_room(h: int = 40, w: int = 60) -> np.ndarray:
    img = np.zeros((h, w), np.uint8)
    img[2:-2, 2:-2] = 254
    return img


# ---- --scheduler: the address's form, before any connection ----------------------------------

@pytest.mark.parametrize("address, says", [("notanaddress", "is not a scheduler address"),
                                           ("tcp://:99999", "is not a scheduler address"),
                                           ("tcp://127.0.0.1:99999", "outside 1-65535"),
                                           ("tcp://127.0.0.1:0", "outside 1-65535"),
                                           ("tcp://host:port", "is not a scheduler address"),
                                           ("http://127.0.0.1:8786", "unknown protocol 'http'")])
def test_a_malformed_scheduler_address_names_the_flag(address, says):
    with pytest.raises(ScenarioError, match=says) as err:
        check_address(address)
    assert err.value.field == "--scheduler" and err.value.file == "<command line>"


@pytest.mark.parametrize("address, parsed", [("tcp://10.0.0.5:8786", ("tcp", "10.0.0.5", 8786)),
                                             ("127.0.0.1:8786", ("tcp", "127.0.0.1", 8786)),
                                             ("tls://[::1]:8786", ("tls", "::1", 8786)),
                                             ("  tcp://node-3.cluster:8786/ ", ("tcp", "node-3.cluster", 8786))])
def test_a_well_formed_scheduler_address_is_parsed(address, parsed):
    assert check_address(address) == parsed


# ---- import ros: the doors CSV ------------------------------------------------------------------

@pytest.mark.parametrize("row, n", [("102,2.0,0.5,90,7", 5), ("102,2.0,0.5", 3)])
def test_a_doors_row_with_more_or_fewer_fields_names_file_line_and_fields(tmp_path, row, n):
    m = ros_map(tmp_path, "room", walled_room())
    (tmp_path / "doors.csv").write_text(f"number,x,y,facing\n101,1.0,1.0,0\n\n{row}\n")
    refused(["import", "ros", m, tmp_path / "doors.csv", "--out", tmp_path / "o"],
            "doors.csv", "field 'line 4'", f"{n} fields ({row})", "expected 4", "number,x,y,facing")
    assert not (tmp_path / "o" / "scenario.yaml").exists()


def test_a_doors_file_whose_rows_match_its_header_imports(tmp_path):
    m = ros_map(tmp_path, "room", walled_room())
    (tmp_path / "doors.csv").write_text("number,x,y,facing\n101,0.25,2.0,0\n102,5.75,2.0,180\n")
    res = CliRunner().invoke(app, ["import", "ros", str(m), str(tmp_path / "doors.csv"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert Loaded.load(tmp_path / "o" / "scenario.yaml").world.signs.number == (101, 102)


# ---- import ros: maps with no room for a start or goals -----------------------------------------

CHECKER = np.where(np.indices((40, 40)).sum(0) % 2, 254, 0).astype(np.uint8)


@pytest.mark.parametrize("clean", [True, False])
@pytest.mark.parametrize("name, pgm, res, widest", [
    ("three", np.full((3, 3), 254, np.uint8), 0.1, "0.200 m"),  # all free: the edge is unknown space beyond
    ("checker", CHECKER, 0.1, "0.100 m"),  # every free cell alone between walls
    ("fine", walled_room(60, 80), 0.005, "0.140 m"),  # a room of 0.28 x 0.38 m: the scale is wrong
])
def test_a_map_the_robot_fits_nowhere_in_is_refused_naming_it(tmp_path, clean, name, pgm, res, widest):
    """It had ended in an IndexError in spread_goals: every sign was dropped (none near the one
    free cell, or the few centimetres, the robot could reach), and the goals were drawn from none."""
    m = ros_map(tmp_path, name, pgm, res)
    refused(["import", "ros", m, DEMO_DOORS, "--out", tmp_path / "o"] + (["--clean"] if clean else []),
            f"{name}.yaml:", "the robot (radius 0.25 m) fits nowhere", f"the widest is {widest}", f"at {res:g} m per cell")


def test_a_map_with_no_free_cell_is_refused_naming_it(tmp_path):
    m = ros_map(tmp_path, "black", np.zeros((20, 20), np.uint8))
    refused(["import", "ros", m, DEMO_DOORS, "--out", tmp_path / "o"], "black.yaml:", "no free cell")


def test_signs_none_of_which_lie_near_the_free_space_are_refused_naming_the_doors_file(tmp_path):
    m = ros_map(tmp_path, "room", walled_room())  # 6 x 4 m at the origin
    (tmp_path / "far.csv").write_text("number,x,y,facing\n101,40.0,40.0,0\n102,-30.0,5.0,90\n")
    refused(["import", "ros", m, tmp_path / "far.csv", "--out", tmp_path / "o", "--goals", "101"],
            "far.csv:", "none of its 2 signs lies within 2 m of the free space", "x 0.05 to 5.95 m",
            "are the signs in the map's frame?")


def test_a_start_too_near_a_wall_names_the_flag(tmp_path):
    m = ros_map(tmp_path, "room", walled_room())
    refused(["import", "ros", m, DEMO_DOORS, "--out", tmp_path / "o", "--start", "0.3,2.0"],
            "field '--start'", "0.10 m from a wall or unknown cell", "needs 0.30 m")


# ---- indirect: rooms too small, classes with no detection table ---------------------------------

def indirect(tmp_path: Path, **section) -> Path:
    data = {"kind": "indirect", "name": "hostile", "indirect": {"rooms": {"count": 1, "seed": 0}, **section},
            "planners": [{"name": "UIS"}], "experiment": {"seeds": 1}}
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_learned_relations_in_rooms_too_small_for_the_objects_name_the_size(tmp_path):
    """The one test room of 1 x 1 m held its objects by luck; the 20 training rooms of that size
    raised the generator's ValueError."""
    p = indirect(tmp_path, rooms={"count": 1, "seed": 0, "size": [1.0, 1.0]}, learned={"rooms": 20})
    refused(["validate", p], "field 'indirect.rooms.size'", "a training room of indirect.learned",
            "rooms of 1 x 1 m cannot hold the monitor and 3 secondary object(s)", "give larger rooms")


def test_test_rooms_too_small_for_the_objects_name_the_size(tmp_path):
    p = indirect(tmp_path, rooms={"count": 1, "seed": 0, "size": [0.8, 0.8]})
    refused(["validate", p], "field 'indirect.rooms.size'", "rooms of 0.8 x 0.8 m cannot hold")


def test_learned_relations_over_a_rooms_file_of_small_rooms_name_learned(tmp_path):
    at = {"monitor": (0.3, 0.3), "keyboard": (0.7, 0.3), "system_unit": (0.3, 0.7), "router": (0.7, 0.7)}
    objects = {c: {"x": x, "y": y, "height": 0.5, "yaw": 0} for c, (x, y) in at.items()}
    rooms = {"size": [1.0, 1.0], "rooms": [{"name": "tiny", "start": {"x": 0.5, "y": 0.5, "heading": 0}, "objects": objects}]}
    (tmp_path / "rooms.yaml").write_text(yaml.safe_dump(rooms, sort_keys=False))
    p = indirect(tmp_path, rooms="rooms.yaml", learned={"rooms": 20})
    refused(["validate", p], "field 'indirect.learned'", "a training room of indirect.learned", "rooms of 1 x 1 m")


@pytest.mark.parametrize("section, field, near", [
    ({"relations": {"keybaord": [0.7, 0.1, 0.1, 0.1]}}, "indirect.relations.keybaord", "'keyboard'"),
    ({"relations": {"keyboard": [0.7, 0.1, 0.1, 0.1], "routr": [0.1, 0.1, 0.4, 0.4]}}, "indirect.relations.routr", "'router'"),
    ({"target": "moniter"}, "indirect.target", "'monitor'"),
    ({"target": "laptop", "camera": {"table": "side_blind"}}, "indirect.target", None),
])
def test_a_class_with_no_detection_table_is_refused_naming_the_field_and_the_nearest(tmp_path, section, field, near):
    text = refused(["validate", indirect(tmp_path, **section)], f"field '{field}'", "no detection table for the class",
                   "the classes with one: monitor, keyboard, system_unit, router", "indirect.camera.detection")
    assert (f"(did you mean {near}?)" in text) if near else ("did you mean" not in text)


def test_a_class_of_your_own_with_its_table_loads(tmp_path):
    table = [[60, 50, 40, 30, 20]] * 8
    p = indirect(tmp_path, relations={"mouse": [0.7, 0.2, 0.05, 0.05]}, camera={"detection": {"mouse": table}})
    task = Loaded.load(p).task
    assert task.spec.secondary == ["mouse"] and "mouse" in task.grids[0].room.objects
