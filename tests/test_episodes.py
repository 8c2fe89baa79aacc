"""Episodes (start/goal problems), seeds that do not depend on names, results tied to the code
that made them, and what meta.json records."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import __version__
from semsearch_cli.engine import ENGINE
from semsearch_cli.cli import app
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch
from semsearch_cli.tasks.episodes import region_mask

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"


def demo(tmp_path: Path, name: str = "demo", **over) -> Path:
    d = yaml.safe_load((CONFIGS / "demo.yaml").read_text())
    d["name"] = name
    d["map"]["image"] = str(ROOT / "maps" / "demo" / "map.png")
    d["doors"] = str(ROOT / "maps" / "demo" / "doors.csv")
    d["planners"] = [{"name": "greedy"}]
    d["experiment"] = {"seeds": 2, "max_distance": 300}
    d.update(over)
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    return p


def hotel(tmp_path: Path, episodes: dict | None) -> Path:
    d = yaml.safe_load((CONFIGS / "hotel.yaml").read_text())
    d["map"]["image"] = str(ROOT / "maps" / "hotel" / "map.png")
    d["doors"] = str(ROOT / "maps" / "hotel" / "doors.csv")
    d.pop("episodes", None)
    if episodes is not None:
        d["episodes"] = episodes
    p = tmp_path / "hotel.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    return p


# ---- episodes -------------------------------------------------------------------------------
def test_drawn_episodes_are_reproducible_and_every_start_reaches_its_goal(tmp_path):
    spec = {"starts": 6, "seed": 3, "min_distance": 20.0, "max_distance": 80.0}
    a = Loaded.load(hotel(tmp_path, spec)).task
    b = Loaded.load(hotel(tmp_path, spec)).task
    assert [e.content for e in a.episodes] == [e.content for e in b.episodes]
    assert len(a.episodes) == 24 and [str(e.goal) for e in a.episodes] == [g for g in ("76", "135", "148", "185") for _ in range(6)]
    w = a.world
    for e in a.episodes:
        r, c = w.frame.to_index(e.x, e.y)
        assert w.reach[r, c]
        assert 20.0 <= e.shortest_m <= 80.0  # a geodesic within the band: the start reaches its goal
        assert e.shortest_m == pytest.approx(w.geodesic((int(r), int(c)), w.reading_cells(e.goal))[0], abs=1e-6)
    other = Loaded.load(hotel(tmp_path, {**spec, "seed": 4})).task
    assert [e.content for e in other.episodes] != [e.content for e in a.episodes]


def test_shared_starts_serve_every_goal_and_adding_a_goal_moves_no_other_goals_starts(tmp_path):
    shared = Loaded.load(hotel(tmp_path, {"starts": 3, "shared": True})).task.episodes
    starts = {g: [(e.x, e.y) for e in shared if e.goal == g] for g in (76, 135, 148, 185)}
    assert len({tuple(v) for v in starts.values()}) == 1 and len(starts[76]) == 3
    per_goal = Loaded.load(hotel(tmp_path, {"starts": 3})).task.episodes
    p = hotel(tmp_path, {"starts": 3})
    d = yaml.safe_load(p.read_text())
    d["goals"] = [148]
    p.write_text(yaml.safe_dump(d))
    alone = Loaded.load(p).task.episodes
    assert [(e.x, e.y, e.heading) for e in alone] == [(e.x, e.y, e.heading) for e in per_goal if e.goal == 148]


def test_corridors_and_rooms_split_the_free_space():
    free = np.zeros((40, 60), bool)
    free[5:35, 5:25] = True  # a 3 m room (at 0.1 m)
    free[18:22, 25:58] = True  # a 0.4 m corridor
    rooms = region_mask(free, 0.1, "rooms", 1.0)
    corridors = region_mask(free, 0.1, "corridors", 1.0) & free
    assert rooms[20, 15] and not rooms[20, 40] and corridors[20, 40] and not corridors[20, 15]
    assert not (rooms & corridors).any() and ((rooms | corridors) == free).all()


def test_the_thesis_start_is_the_default_episode(tmp_path):
    L = Loaded.load(hotel(tmp_path, None))
    eps = L.task.episodes
    assert [e.goal for e in eps] == [76, 135, 148, 185]
    assert all((e.x, e.y, e.heading) == (44.619, 64.0, None) for e in eps)  # heading random: drawn per repeat
    assert [e.shortest_m for e in eps] == pytest.approx([L.shortest[g] for g in (76, 135, 148, 185)], abs=1e-6)


def test_an_episode_set_is_frozen_to_csv_and_read_back(tmp_path):
    p = hotel(tmp_path, {"starts": 2, "seed": 1})
    res = CliRunner().invoke(app, ["episodes", str(p), "--out", str(tmp_path / "eps.csv")])
    assert res.exit_code == 0, res.output
    eps = pd.read_csv(tmp_path / "eps.csv")
    assert list(eps.columns) == ["episode", "goal", "start_x", "start_y", "start_heading", "room", "shortest_m", "hash"]
    assert len(eps) == 8 and eps["hash"].is_unique
    q = hotel(tmp_path, {"file": "eps.csv"})
    again = Loaded.load(q).task.episodes
    assert [e.hash for e in again] == eps["hash"].tolist()
    assert [e.shortest_m for e in again] == pytest.approx(eps["shortest_m"].tolist(), abs=1e-3)


@pytest.mark.parametrize("episodes,field,words", [
    ({"list": [{"goal": 304, "x": 0.0, "y": 0.0}]}, "episodes.list[0]", "not free space"),
    ({"list": [{"goal": 999, "x": 15.0, "y": 10.0}]}, "episodes.list[0]", "not one of the scenario's goals"),
    ({"starts": 2, "min_distance": 500.0}, "episodes", "no reachable free cell"),
    ({"starts": 2, "file": "x.csv"}, "episodes", "exactly one of"),
])
def test_bad_episodes_are_refused_naming_the_field(tmp_path, episodes, field, words):
    p = demo(tmp_path, episodes=episodes)
    res = CliRunner().invoke(app, ["validate", str(p)])
    assert res.exit_code == 2 and field in res.output and words in res.output and "Traceback" not in res.output


def test_rows_carry_the_episode_and_its_start(tmp_path):
    p = demo(tmp_path, episodes={"list": [{"goal": 452, "x": 15.0, "y": 10.0, "heading": 90.0},
                                          {"goal": 304, "x": 5.0, "y": 10.0}]})
    L = Loaded.load(p)
    rows = run_batch(L, expand(L), tmp_path / "out", BatchOptions(workers=1))
    assert sorted(zip(rows["episode"], rows["seed"])) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    first = rows[rows["episode"] == 0]
    assert (first["start_heading"] == 90.0).all() and (first["goal"] == 452).all() and (first["start_x"] == 15.0).all()
    second = rows[rows["episode"] == 1]
    assert second["start_heading"].nunique() == 2  # no heading given: drawn per repeat
    assert set(rows["cause"].fillna("")) <= {"", "budget", "stuck", "explored"}
    found = rows[rows["success"] == 1]
    assert (found["left_m"] == 0).all() and np.allclose(found["soft_spl"], found["spl"])


# ---- seeds do not depend on names -----------------------------------------------------------
def test_a_renamed_copy_gives_identical_rows(tmp_path):
    (tmp_path / "elsewhere").mkdir()
    a, b = demo(tmp_path, "demo"), demo(tmp_path / "elsewhere", "another-name")
    ra = run_batch(Loaded.load(a), expand(Loaded.load(a)), tmp_path / "a", BatchOptions(workers=1))
    rb = run_batch(Loaded.load(b), expand(Loaded.load(b)), tmp_path / "b", BatchOptions(workers=1))
    cols = [c for c in ra.columns if c not in ("scenario", "wall_s", "fingerprint")]  # the name is part of the fingerprint
    key = ["goal", "episode", "seed"]
    pd.testing.assert_frame_equal(ra.sort_values(key)[cols].reset_index(drop=True), rb.sort_values(key)[cols].reset_index(drop=True))
    assert set(ra["scenario"]) == {"demo"} and set(rb["scenario"]) == {"another-name"}


# ---- results tied to their code -------------------------------------------------------------
def test_an_edited_planner_file_never_yields_the_old_rows(tmp_path):
    src = ROOT / "examples" / "custom_planner"
    # a name of its own: one process registers a name once (the planner list test loads the original)
    (tmp_path / "my_planner.py").write_text((src / "my_planner.py").read_text().replace('"straight_on"', '"straight_on_copy"'))
    d = yaml.safe_load((src / "scenario.yaml").read_text())
    d["map"]["image"] = str(ROOT / "maps" / "demo" / "map.png")
    d["doors"] = str(ROOT / "maps" / "demo" / "doors.csv")
    d["goals"] = [304]
    d["planners"] = [{"name": "greedy"}, {"name": "straight_on_copy", "module": "my_planner.py"}]
    d["experiment"] = {"seeds": 1, "max_distance": 300}
    p = tmp_path / "scenario.yaml"
    p.write_text(yaml.safe_dump(d))
    out = tmp_path / "out"
    r1 = CliRunner().invoke(app, ["run", str(p), "--workers", "1", "--out", str(out)])
    assert r1.exit_code == 0, r1.output
    before = pd.read_csv(out / "runs.csv")
    again = CliRunner().invoke(app, ["run", str(p), "--workers", "1", "--out", str(out)])
    assert again.exit_code == 0 and "made by other code" not in again.output  # nothing changed: nothing re-runs
    pd.testing.assert_frame_equal(pd.read_csv(out / "runs.csv"), before)
    (tmp_path / "my_planner.py").write_text((tmp_path / "my_planner.py").read_text() + "\n# edited\n")
    r2 = CliRunner().invoke(app, ["run", str(p), "--workers", "1", "--out", str(out)])
    assert r2.exit_code == 0, r2.output
    assert "straight_on_copy" in r2.output and "made by other code" in r2.output
    after = pd.read_csv(out / "runs.csv")
    old = before.set_index("planner")["code"]
    new = after.set_index("planner")["code"]
    assert new["greedy"] == old["greedy"] and new["straight_on_copy"] != old["straight_on_copy"] and len(after) == 2
    side = pd.read_csv(out / "runs.superseded.csv")
    assert side["planner"].tolist() == ["straight_on_copy"] and side["code"].iloc[0] == old["straight_on_copy"]
    meta = json.loads((out / "meta.json").read_text())
    assert meta["planners"]["straight_on_copy"]["file"] == "../my_planner.py"
    assert meta["planners"]["straight_on_copy"]["hash"] == new["straight_on_copy"]


def test_meta_json_records_the_provenance(tmp_path):
    p = demo(tmp_path)
    out = tmp_path / "results" / "demo"
    res = CliRunner().invoke(app, ["run", str(p), "--workers", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    meta = json.loads((out / "meta.json").read_text())
    assert meta["scenario"] == "../../demo.yaml"  # relative to the results folder
    sem = meta["semsearch"]
    assert {"version", "code", "commit", "python", "numpy", "scipy", "numba", "pandas", "platform"} <= set(sem)
    assert meta["planners"]["greedy"]["source"] == "built-in" and len(meta["planners"]["greedy"]["hash"]) == 16
    assert meta["episodes"]["count"] == 2 and len(meta["scenario_sha256"]) == 64
    report = (out / "report.md").read_text()
    assert "Provenance" in report and sem["code"] in report
    assert set(pd.read_csv(out / "runs.csv")["code"]) == {meta["planners"]["greedy"]["hash"]}


def test_version_and_the_planner_list():
    res = CliRunner().invoke(app, ["--version"])
    assert res.exit_code == 0 and res.output.startswith(f"semsearch {__version__} (engine {ENGINE}, code ")
    # a process of its own, as a user runs it (a process registers a planner name from one file only), from the
    # checkout: the planner file's path is shown relative to the working folder, whatever the clone's path
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "planners",
                          "examples/custom_planner/scenario.yaml"], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    for words in ("nsos", "alpha = 0.9", "straight_on", "file examples/custom_planner/my_planner.py", "turn_weight",
                  "ISCG-PN-SM", "lsos"):
        assert words in res.stdout, words


# ---- indirect search ------------------------------------------------------------------------
def test_indirect_search_draws_a_start_per_trial_inside_its_room(tmp_path):
    d = {"name": "rooms", "indirect": {"rooms": {"count": 3, "seed": 1}, "view_scales": [1.0, 2.5], "time_limit": 30.0},
         "planners": [{"name": "UIS"}], "episodes": {"starts": 2, "seed": 0}, "experiment": {"seeds": 1}}
    p = tmp_path / "rooms.yaml"
    p.write_text(yaml.safe_dump(d))
    t = Loaded.load(p).task
    eps = t.episodes
    assert len(eps) == 12 and [e.room for e in eps[:6]] == [0, 0, 1, 1, 2, 2]
    assert [(e.x, e.y) for e in eps[:6]] == [(e.x, e.y) for e in eps[6:]]  # the same starts at every scale
    for e in eps:
        g = t.grids[e.room]
        r, c = g.frame.to_index(e.x, e.y)
        assert g.stand[r, c] and np.isfinite(e.shortest_m)
    assert len({(e.x, e.y) for e in eps}) == 6


def test_object_search_and_chains_draw_starts_too(tmp_path):
    d = yaml.safe_load((CONFIGS / "office.yaml").read_text())
    d["map"]["image"] = str(ROOT / "maps" / "office" / "map.png")
    d["objects"]["cases"] = [c for c in d["objects"]["cases"] if c["name"] == "Moved-mug"]
    d["planners"] = [{"name": "lsos"}]
    d["episodes"] = {"starts": 3, "where": "rooms", "corridor_width": 2.0}
    d["experiment"] = {"seeds": 1, "max_distance": 300}
    p = tmp_path / "office.yaml"
    p.write_text(yaml.safe_dump(d))
    L = Loaded.load(p)
    t, w = L.task, L.world
    rooms = region_mask(w.free, w.frame.res, "rooms", 2.0)
    assert len(t.episodes) == 3 * len(t.goals)
    for e in t.episodes:
        r, c = w.frame.to_index(e.x, e.y)
        assert rooms[r, c] and w.reach[r, c]
        assert e.shortest_m == pytest.approx(w.geodesic((int(r), int(c)), t.goal_cells(e.goal))[0], abs=1e-6)
    rows = run_batch(L, expand(L, goals=[t.goals[0]]), tmp_path / "out", BatchOptions(workers=1))
    assert len(rows) == 3 and (rows["start_x"].tolist() == [e.x for e in t.episodes[:3]])
    h = yaml.safe_load((CONFIGS / "hospital.yaml").read_text())
    h["map"]["image"] = str(ROOT / "maps" / "hospital" / "map.png")
    h["doors"] = str(ROOT / "maps" / "hospital" / "doors.csv")
    h["episodes"] = {"starts": 2}
    q = tmp_path / "hospital.yaml"
    q.write_text(yaml.safe_dump(h))
    c = Loaded.load(q).task
    first = c.episodes[0]
    ch = c.chains[str(first.goal)]
    r, cc = c.world.frame.to_index(first.x, first.y)
    legs = c._shortest_legs(ch, c.stages[ch.name], "x", (int(r), int(cc)))
    assert first.shortest_m == pytest.approx(sum(legs)) and first.shortest_m > legs[0]  # every leg, not the first alone


@pytest.mark.parametrize("text,where", [
    ("", "expected a CSV"),
    ("goal,start_x\n304,1\n", "expected a CSV"),
    ("goal,start_x,start_y\n304,15,10\n\n304,abc,10\n", "line 4"),
    ("goal,start_x,start_y\n304,15,nan\n", "finite"),
    ('goal,start_x,start_y\n304,15,"' + "x" * 200_000 + '"\n', "not a CSV"),
])
def test_a_bad_episodes_file_is_refused_naming_it_and_the_line(tmp_path, text, where):
    (tmp_path / "eps.csv").write_text(text)
    res = CliRunner().invoke(app, ["validate", str(demo(tmp_path, episodes={"file": "eps.csv"}))])
    assert res.exit_code == 2 and "eps.csv" in res.output and where in res.output and "Traceback" not in res.output


def test_a_changed_episode_set_never_passes_off_another_starts_rows(tmp_path):
    """Rows are resumed by (goal, episode index): when the set changes under an index (here a
    goal added to shared starts), the rows of the old start are moved aside and re-run."""
    p = demo(tmp_path, goals=[304], episodes={"starts": 2, "shared": True, "min_distance": 5.0})
    L = Loaded.load(p)
    out = tmp_path / "out"
    first = run_batch(L, expand(L, seeds=1), out, BatchOptions(workers=1))
    p2 = demo(tmp_path, goals=[304, 452], episodes={"starts": 2, "shared": True, "min_distance": 5.0})
    L2 = Loaded.load(p2)
    starts = {(str(e.goal), e.index): (e.x, e.y) for e in L2.task.episodes}
    again = run_batch(L2, expand(L2, seeds=1), out, BatchOptions(workers=1))
    assert len(again) == 4 and all(starts[(str(g), e)] == (x, y) for g, e, x, y in
                                   zip(again["goal"], again["episode"], again["start_x"], again["start_y"]))
    side = pd.read_csv(out / "runs.superseded.csv")
    moved = [(x, y) for x, y in zip(first["start_x"], first["start_y"]) if (x, y) not in set(zip(again["start_x"], again["start_y"]))]
    assert len(side) == len(moved) > 0
