"""Bad input: exit status 2, one paragraph naming the file and the field, no traceback."""

import shutil

import cv2
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app

runner = CliRunner()


def scenario_copy(demo_dir, tmp_path, **changes):
    for f in ("map.png", "doors.csv"):
        shutil.copy(demo_dir / f, tmp_path / f)
    data = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    for k, v in changes.items():
        if v is None:
            data.pop(k, None)
        else:
            data[k] = v
    p = tmp_path / "scenario.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def check_error(path, *needles, file=None):
    res = runner.invoke(app, ["validate", str(path)])
    assert res.exit_code == 2, res.output
    text = " ".join(res.output.split())
    assert "Traceback" not in text
    assert str(file or path.name) in text
    for n in needles:
        assert n in text, text
    return text


def test_valid_demo(demo_dir):
    res = runner.invoke(app, ["validate", str(demo_dir / "scenario.yaml")])
    assert res.exit_code == 0, res.output
    assert "signs: 24" in res.output


def test_unknown_key(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, colour="red"), "colour", "unknown key")


def test_unknown_nested_key(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, experiment={"seeds": 2, "sedes": 3}), "experiment.sedes", "unknown key")


def test_a_mistyped_key_gets_the_nearest_valid_names_and_the_keys_of_its_section(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, experiment={"seeds": 2, "max_distnace": 300}), "experiment.max_distnace",
                "unknown key 'max_distnace' (did you mean 'max_distance'?)",
                "valid keys here: base_seed, max_distance, max_steps, out, run_time_limit, seeds")
    check_error(scenario_copy(demo_dir, tmp_path, belief={"densty_delta": 2.0}), "belief.densty_delta", "did you mean 'density_delta'?")


def test_wrong_type(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, experiment={"seeds": "many"}), "experiment.seeds", "integer")


def test_missing_field(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, goals=None), "goals", "missing")


def test_missing_image(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, map={"image": "nope.png", "resolution": 0.1}), "nope.png", "map.image", "not found")


def test_a_missing_file_names_the_resolved_path_and_what_paths_are_relative_to(demo_dir, tmp_path):
    (tmp_path / "sub").mkdir()
    p = scenario_copy(demo_dir, tmp_path / "sub", map={"image": "../maps/nope.png", "resolution": 0.1})
    check_error(p, "map image", "not found", f"(looked for {tmp_path / 'maps' / 'nope.png'}; a scenario's relative "
                "paths are read from the folder the scenario is in)")


def test_not_an_image(demo_dir, tmp_path):
    p = scenario_copy(demo_dir, tmp_path)
    (tmp_path / "map.png").write_text("this is not a png")
    check_error(p, "map.image", "not a readable image")


def test_start_in_wall(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, start={"x": 15.0, "y": 5.0}), "field 'start'", "inside a wall")


def test_goal_no_sign_carries(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, goals=[304, 999]), "goals[1]", "no door sign carries the number 999")


def test_unknown_planner(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, planners=[{"name": "greedy"}, {"name": "astar"}]), "planners[1].name", "valid: bvp, distance_advantage, draft, geometric, greedy, learned, llm, nsos, numbering, oracle_goal, wall_numbers, wall_rule")
    check_error(scenario_copy(demo_dir, tmp_path, planners=[{"name": "nsso"}]), "unknown planner 'nsso' (did you mean 'nsos'?)")


def test_unknown_planner_parameter(demo_dir, tmp_path):
    check_error(scenario_copy(demo_dir, tmp_path, planners=[{"name": "bvp", "windw": 3}]), "planners[0].windw", "'bvp' has no parameter 'windw'")
    check_error(scenario_copy(demo_dir, tmp_path, planners=[{"name": "nsos", "alfa": 0.9}]), "planners[0].alfa",
                "'nsos' has no parameter 'alfa' (did you mean 'alpha'?); its parameters: alpha = 0.9 (weight of the semantic factor",
                "hysteresis = 0.01")
    check_error(scenario_copy(demo_dir, tmp_path, planners=[{"name": "greedy", "alpha": 0.9}]), "it takes no parameters")


def test_duplicate_sign_numbers(demo_dir, tmp_path):
    p = scenario_copy(demo_dir, tmp_path)
    lines = (tmp_path / "doors.csv").read_text().splitlines()
    lines.append(lines[1].split(",", 1)[0] + ",15.0,9.0,90.0")
    (tmp_path / "doors.csv").write_text("\n".join(lines) + "\n")
    check_error(p, "more than once", file="doors.csv")


def test_sign_not_next_to_free_space(demo_dir, tmp_path):
    p = scenario_copy(demo_dir, tmp_path)
    with (tmp_path / "doors.csv").open("a") as fh:
        fh.write("777,15.0,4.0,90.0\n")
    check_error(p, "doors[24]", "not next to free space", file="doors.csv")


def test_goal_unreachable(demo_dir, tmp_path):
    p = scenario_copy(demo_dir, tmp_path, goals=[304, 888])
    img = cv2.imread(str(tmp_path / "map.png"), cv2.IMREAD_GRAYSCALE)
    img[10:30, 10:30] = 255  # a closed room of free space, away from the corridors
    img[9, 9:31] = img[30, 9:31] = 0
    img[9:31, 9] = img[9:31, 30] = 0
    cv2.imwrite(str(tmp_path / "map.png"), img)
    with (tmp_path / "doors.csv").open("a") as fh:
        fh.write("888,2.0,18.0,-90.0\n")  # on the room's wall face (row 20 -> y 18 m)
    check_error(p, "goals[1]", "cannot be read from any pose reachable")


def test_bad_yaml(tmp_path):
    p = tmp_path / "broken.yaml"
    p.write_text("name: [unclosed\n")
    check_error(p, "not valid YAML")


def test_run_reports_bad_goal_option(demo_dir):
    res = runner.invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--goal", "12345", "--out", "/tmp/never"])
    assert res.exit_code == 2 and "--goal" in res.output


def test_density_delta_too_fine_for_the_class_map(demo_dir, tmp_path):
    # a delta of 0.001 m^2 would give a 20 m kernel 800,000 classes, more than the 16-bit class map holds
    p = scenario_copy(demo_dir, tmp_path, belief={"density_delta": 0.001})
    check_error(p, "belief.density_delta")
