"""The other commands check what they are given: each bad input below is exit 2
with one paragraph naming the option, file or field, never a traceback."""

import shutil

import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import batch, BatchOptions, expand, run_batch
from semsearch_cli.tasks.objects import read_log

runner = CliRunner()


def refused(args, *words):
    res = runner.invoke(app, [str(a) for a in args])
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output and all(w in res.output for w in words), res.output
    return res.output


@pytest.mark.parametrize("args,flag", [(["--seed", "-5"], "--seed"), (["--goals", "abc"], "--goals")])
def test_generate_building_checks_its_options(tmp_path, args, flag):
    refused(["generate", "building", "--layout", "grid", "--numbering", "sequential", "--out", tmp_path / "b", *args], flag)


def test_generate_batch_is_bounded(tmp_path):
    refused(["generate", "batch", "--out", tmp_path / "b", "--seeds", "1000000"], "--seeds")


@pytest.mark.parametrize("text,where", [("hour,A,B\n1,-2,3\n", "'A'"), ("hour,A,B\n1,inf,3\n", "'A'"),
                                        ("hour,A,B\n", "no row with an hour"), ("hour,A,B\n1,2\n", "line 2")])
def test_presence_checks_counts(tmp_path, text, where):
    (tmp_path / "c.csv").write_text(text)
    refused(["presence", tmp_path / "c.csv", "--hours", "1"], where)


def test_presence_out_naming_a_folder_is_refused_and_leaves_nothing(tmp_path):
    (tmp_path / "c.csv").write_text("hour,A,B\n1,2,3\n")
    refused(["presence", tmp_path / "c.csv", "--hours", "1", "--out", tmp_path], "--out", "is a folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.csv"]


def test_report_names_a_column_that_is_not_numbers(demo_dir, tmp_path):
    out = tmp_path / "o"
    res = runner.invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "1", "--workers", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    lines = (out / "runs.csv").read_text().splitlines()
    head = lines[0].split(",")
    cells = lines[1].split(",")
    cells[head.index("distance_m")] = "abc"
    (out / "runs.csv").write_text("\n".join([lines[0], ",".join(cells), *lines[2:]]) + "\n")
    refused(["report", out], "distance_m", "abc")


def test_a_runs_csv_that_is_a_folder_is_refused(demo_dir, tmp_path):
    (tmp_path / "o" / "runs.csv").mkdir(parents=True)
    refused(["run", demo_dir / "scenario.yaml", "--seeds", "1", "--out", tmp_path / "o"], "runs.csv", "is a folder")


def test_indirect_rooms_too_large_for_memory_are_refused(tmp_path):
    p = tmp_path / "big.yaml"
    p.write_text(yaml.safe_dump({"name": "big", "indirect": {"rooms": {"count": 2, "size": [50, 50]}, "resolution": 0.01,
                                                             "view_scales": [1.0]}, "planners": [{"name": "UIS"}]}))
    refused(["validate", p], "indirect.resolution", "25,000,000 cells")


def test_a_sweep_value_is_typed_by_its_field(demo_dir, tmp_path):
    refused(["sweep", demo_dir / "scenario.yaml", "--param", "door_camera.p_misread=true", "--out", tmp_path / "s"],
            "--param", "not yes/no")
    assert not (tmp_path / "s").exists() or not any((tmp_path / "s").rglob("runs.csv"))
    shutil.rmtree(tmp_path / "s", ignore_errors=True)


def test_an_empty_list_of_planner_values_is_refused(demo_dir, tmp_path):
    d = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    d["map"]["image"] = str(demo_dir / "map.png")
    d["doors"] = str(demo_dir / "doors.csv")
    d["planners"] = [{"name": "nsos", "alpha": []}]
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(d))
    refused(["validate", p], "planners[0].alpha", "empty list")


@pytest.mark.parametrize("row,col", [("mug,1,2,99,0,0", "hour"), ("mug,inf,2,10,0,0", "x")])
def test_an_object_log_with_an_impossible_hour_or_coordinate_is_refused(tmp_path, row, col):
    (tmp_path / "log.csv").write_text(f"class,x,y,hour,robot_x,robot_y\n{row}\n")
    with pytest.raises(ScenarioError) as err:
        read_log(tmp_path / "log.csv")
    assert err.value.field == col


def test_show_into_a_folder_that_takes_no_files_is_refused(demo_dir, tmp_path):
    refused(["show", demo_dir / "scenario.yaml", "--out", "/proc/semsearch.png"], "--out", "cannot write files in /proc")


def test_a_batch_of_many_runs_says_so_before_it_starts(demo_loaded, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(batch, "MANY_RUNS", 4)
    run_batch(demo_loaded, expand(demo_loaded, 2), tmp_path / "o", BatchOptions(workers=1))
    assert "runs: 8 to do (2 planner variant(s)" in capsys.readouterr().err
