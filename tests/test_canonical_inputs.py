"""Issue 35's root fixes, each on small exact inputs: one label parser with bounds, numbers read as
written, episodes files bounded and hashed, runs.csv read strictly, replay frames validated from
their headers, output paths checked before a batch, and a superseded or forced run's files kept."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

from semsearch_cli.config.base import label_column, sign_label
from semsearch_cli.config.scenario import load_yaml_text
from semsearch_cli.errors import ScenarioError
from semsearch_cli.metrics import COLUMNS
from semsearch_cli.runner import BatchOptions, Loaded, expand, run_batch
from semsearch_cli.runner import batch
from semsearch_cli.runner.store import read_frames, read_runs, write_frames
from semsearch_cli.tasks import episodes as episodes_mod
from semsearch_cli.tasks.episodes import Episode


@pytest.mark.parametrize("written, label", [(148, 148), ("148", 148), (" 148 ", 148), ("304.0", "304.0"), (304.0, 304),
                                            ("Room\xa0101", "Room 101"),
                                            ("2.14", "2.14"), ("4.50", "4.50"), ("1e3", "1e3"), ("NA", "NA"),
                                            ("30²", "30²"), ("K202", "K202"), (10 ** 17, 10 ** 17)])
def test_a_label_has_one_canonical_form(written, label):
    assert sign_label(written) == label and type(sign_label(written)) is type(label)


@pytest.mark.parametrize("written, says", [("", "empty"), ("  ", "empty"), ("x" * 65, "64 characters"),
                                           ("9" * 19, "18 digits"), (10 ** 19, "18 digits"), (float("nan"), "finite"),
                                           ("a\tb", "control character"), ("9" * 60_000, "64 characters")])
def test_a_label_beyond_its_bounds_is_refused_naming_the_bound(written, says):
    with pytest.raises(ValueError, match=says):
        sign_label(written)


def test_a_spreadsheets_column_of_floats_is_its_numbers_and_a_mixed_column_is_text():
    assert label_column(["304.0", " 101.00", "-2.0"]) == [304, 101, -2]
    assert label_column(["3.0", "K202", "148"]) == ["3.0", "K202", 148]


def test_numbers_are_read_as_written():
    got = load_yaml_text("a: 1_5\nb: 1:30\nc: 010\nd: 0x10\ne: 1.0e+3\nf: 1e3\ng: -.5\nh: 12\ni: 0b11\n")
    assert got == {"a": "1_5", "b": "1:30", "c": "010", "d": 16, "e": 1000.0, "f": "1e3", "g": "-.5", "h": 12, "i": "0b11"}
    data = {"s": ["1_5", "010", "1.0e2", "yes"], "n": [1, -2, 0.5, 1e20], "b": True, "z": None}
    assert load_yaml_text(yaml.safe_dump(data)) == data  # what yaml writes reads back as it was


def _scenario(demo_dir: Path, folder: Path, **changes) -> Path:
    sc = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    sc.update({"map": {**sc["map"], "image": str(demo_dir / "map.png")}, "doors": str(demo_dir / "doors.csv"), "goals": [304],
               "planners": [{"name": "greedy"}], "experiment": {"seeds": 1, "max_distance": 120.0}, **changes})
    path = folder / "s.yaml"
    path.write_text(yaml.safe_dump(sc))
    return path


@pytest.mark.parametrize("text, says", [("episodes:\n  starts: yes\n", "episodes.starts"),
                                        ("start: {x: 1_5, y: 10.0}\n", "start.x"),
                                        ("start: {x: 15.0, y: 10.0}\nlaser: {beams: 010}\n", "laser.beams"),
                                        ("start: {x: 15.0, y: 10.0}\nlaser: {beams: '010'}\n", "laser.beams"),
                                        ("start: {x: 15.0, y: 10.0}\nrobot: {radius: yes}\n", "robot.radius")])
def test_a_yaml_boolean_or_an_underscored_number_is_refused_where_a_number_belongs(demo_dir, tmp_path, text, says):
    path = _scenario(demo_dir, tmp_path)
    data = yaml.safe_load(path.read_text())
    data.pop("start" if "start" in text else "episodes", None)
    path.write_text(yaml.safe_dump(data) + text)
    with pytest.raises(ScenarioError, match=says.replace(".", r"\.")):
        Loaded.load(path)


def _episodes(demo_dir, tmp_path, rows: list[str]) -> Path:
    (tmp_path / "eps.csv").write_text("\n".join(["goal,start_x,start_y,start_heading,hash", *rows]) + "\n")
    return _scenario(demo_dir, tmp_path, episodes={"file": "eps.csv"})


def test_an_episodes_file_reads_304_0_as_304_and_checks_its_hash(demo_dir, tmp_path):
    right = Episode(0, 304, 15.0, 10.0, 90.0, None).hash
    eps = Loaded.load(_episodes(demo_dir, tmp_path, [f"304.0,15.0,10.0,90.0,{right}"])).task.episodes
    assert [(e.goal, e.x, e.y, e.heading, e.hash) for e in eps] == [(304, 15.0, 10.0, 90.0, right)]
    with pytest.raises(ScenarioError, match=f"line 2 hash.*the row's hash 0123456789abcdef is not its episode's \\({right}\\)"):
        Loaded.load(_episodes(demo_dir, tmp_path, ["304,15.0,10.0,90.0,0123456789abcdef"]))


@pytest.mark.parametrize("row, says", [("304,1_5,10.0,90,", "line 2 start_x.*start_x must be a number"), ("304,15.0,10.0,90,,7", "more fields|fields where"),
                                       (",15.0,10.0,90,", "empty")])
def test_an_episodes_row_is_read_strictly(demo_dir, tmp_path, row, says):
    with pytest.raises(ScenarioError, match=says):
        Loaded.load(_episodes(demo_dir, tmp_path, [row]))


def test_an_episodes_file_past_its_bound_is_refused_before_any_start_is_measured(demo_dir, tmp_path, monkeypatch):
    monkeypatch.setattr(episodes_mod, "MAX_EPISODES", 3)
    with pytest.raises(ScenarioError, match="line 5.*more than 3 episodes"):
        Loaded.load(_episodes(demo_dir, tmp_path, ["304,15.0,10.0,90,"] * 5)).task.episodes


def test_runs_csv_is_read_strictly(tmp_path):
    base = {**dict.fromkeys(COLUMNS, ""), "kind": "doors", "planner": "greedy", "goal": 304, "episode": 0, "seed": 0, "outcome": "found", "distance_m": 12.5,
            "wall_s": 0.1}
    f = tmp_path / "runs.csv"
    pd.DataFrame([base, {**base, "seed": 1, "outcome": "error", "distance_m": float("nan")}]).to_csv(f, index=False)
    assert list(read_runs(f)["seed"]) == [0, 1]  # a failed run has no distance
    pd.DataFrame([{**base, "outcome": "not_found", "shortest_m": float("inf"), "left_m": float("inf")}]).to_csv(f, index=False)
    assert np.isinf(read_runs(f)["shortest_m"]).all()  # semsearch writes inf for a goal nothing achieves
    for change, says in (({"distance_m": float("nan")}, "distance_m"), ({"distance_m": float("inf")}, "distance_m"),
                         ({"distnace": 1.0}, "'distnace'.*did you mean 'distance_m'")):
        pd.DataFrame([{**base, **change}]).to_csv(f, index=False)
        with pytest.raises(ScenarioError, match=says):
            read_runs(f)


FRAME = {"map": np.zeros((4, 5), np.uint8), "path": np.zeros((3, 2)), "distance": 1.5, "cands": np.zeros((0, 2)),
         "target": (1.0, 2.0), "read": [3, 4]}


def _npz(path: Path, members: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w") as z:
        for name, data in members.items():
            z.writestr(f"{name}.npy", data)
    return path


def _npy(a) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a, allow_pickle=True)
    return buf.getvalue()


def _claims(shape) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "|u1", "fortran_order": False, "shape": shape})
    return buf.getvalue() + b"\0" * 64


def test_frames_read_back_as_written(tmp_path):
    write_frames(tmp_path / "f.npz", [FRAME, FRAME])
    got = read_frames(tmp_path / "f.npz")
    assert len(got) == 2 and got[1]["target"] == (1.0, 2.0) and got[1]["read"] == [3, 4] and got[1]["distance"] == 1.5


@pytest.mark.parametrize("members, field", [
    ({}, "n"),
    ({"n": _npy(np.int64(10 ** 9))}, "n"),
    ({"n": _npy(np.int64(1)), "5/map": _npy(np.zeros((2, 2), np.uint8))}, "5/map"),
    ({"n": _npy(np.int64(1)), "0/distance": _npy(np.float64(1))}, "0/"),
    ({"n": _npy(np.int64(1)), "0/path": _npy(np.array(["a", "b"]))}, "0/path"),
    ({"n": _npy(np.int64(1)), "0/path": _npy(np.array([{"a": 1}], dtype=object))}, "0/path"),
    ({"n": _npy(np.int64(1)), "0/map": _claims((40_000, 40_000))}, "0/map"),
])
def test_a_damaged_frames_file_is_refused_naming_the_key(tmp_path, members, field):
    with pytest.raises(ScenarioError) as exc:
        read_frames(_npz(tmp_path / "f.npz", members))
    assert exc.value.field == field and "not a replay frames file semsearch wrote" in exc.value.message


def test_an_empty_frames_file_is_refused(tmp_path):
    (tmp_path / "f.npz").write_bytes(b"")
    with pytest.raises(ScenarioError, match="not a replay frames file"):
        read_frames(tmp_path / "f.npz")


@pytest.mark.parametrize("name, make", [("paths", "file"), ("frames", "file"), ("summary.csv", "folder"), ("report.md", "folder")])
def test_an_output_of_the_wrong_kind_is_refused_before_anything_runs(demo_dir, tmp_path, name, make):
    out = tmp_path / "out"
    out.mkdir()
    (out / name).mkdir() if make == "folder" else (out / name).write_text("")
    loaded = Loaded.load(_scenario(demo_dir, tmp_path))
    with pytest.raises(ScenarioError, match=f"{name} is a {make}, where semsearch writes"):
        run_batch(loaded, expand(loaded, 1), out, BatchOptions(workers=1, frames=True))
    assert not (out / "runs.csv").exists()


def test_a_superseded_run_takes_its_files_aside_and_force_keeps_what_it_replaces(demo_dir, tmp_path, capsys):
    out = tmp_path / "out"
    loaded = Loaded.load(_scenario(demo_dir, tmp_path))
    run_batch(loaded, expand(loaded, 2), out, BatchOptions(workers=1, frames=True, trace=True, decisions=True))
    stems = sorted(p.stem for p in (out / "paths").iterdir())
    assert len(stems) == 2
    batch._supersede(out, lambda rows: rows["seed"].astype(int) == 0, "were made by other code (a test)")
    assert "and their 4 file(s) (paths, traces, frames, decisions) to superseded/1/" in " ".join(capsys.readouterr().err.split())
    assert sorted(p.name for p in (out / "superseded" / "1").iterdir()) == ["decisions", "frames", "paths", "traces"]
    assert [p.stem for p in (out / "paths").iterdir()] == [stems[1]]
    run_batch(loaded, expand(loaded, 2), out, BatchOptions(workers=1, frames=True))  # the superseded run runs again
    assert sorted(p.stem for p in (out / "paths").iterdir()) == stems
    edited = Loaded.load(_scenario(demo_dir, tmp_path, experiment={"seeds": 1, "max_distance": 130.0}))
    run_batch(edited, expand(edited, 1), out, BatchOptions(workers=1, force=True))
    assert (out / "runs.1.csv.bak").is_file() and len(read_runs(out / "runs.1.csv.bak")) == 2
    assert sorted(p.stem for p in (out / "runs.1.bak" / "paths").iterdir()) == stems  # kept, not overwritten
    assert [p.stem for p in (out / "runs.1.bak" / "traces").iterdir()] == [stems[1]]  # the re-run one had no --trace
    assert [p.stem for p in (out / "paths").iterdir()] == [stems[0]]


def test_an_inverted_map_is_blamed_on_the_map_not_the_start(demo_dir, tmp_path):
    cv2.imwrite(str(tmp_path / "inverted.png"), 255 - cv2.imread(str(demo_dir / "map.png"), cv2.IMREAD_GRAYSCALE))
    path = _scenario(demo_dir, tmp_path)
    data = yaml.safe_load(path.read_text())
    data["map"]["image"] = str(tmp_path / "inverted.png")
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ScenarioError, match="is the image inverted") as exc:
        Loaded.load(path)
    assert exc.value.field == "map.image"
