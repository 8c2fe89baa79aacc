"""Object search over time on our office (thesis 5.3): ground truth, recording, the three planners,
the scenario checks and the command line."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.runner import BatchOptions, execute, expand, Loaded, run_batch
from semsearch_cli.planners import LsosParams, lsos_goals
from semsearch_cli.tasks.objects import parse_label, request_label, timeline_at
from semsearch_cli.planners import Variant
from semsearch_cli.world.buildings.office import HOURS, TABLE_5_1
from semsearch_cli.tasks import TraceObserver

ROOT = Path(__file__).resolve().parents[1]
OFFICE = ROOT / "configs" / "office.yaml"
TABLE_5_2 = {"Static": ("A", "H"), "Static-Inv": ("H", "A"), "Mobile": ("A", "H"), "Mobile-Inv": ("H", "A"), "Shift": ("A", "H")}


@pytest.fixture(scope="module")
def office():
    return Loaded.load(OFFICE)


def run(office, label, planner, seed=0):
    req = office.task.request(label)
    return office.task.run(Variant(planner, ()), req.label, seed)


def test_timeline_gives_table_5_2():
    for name, seq in TABLE_5_1.items():
        tl = {"mug": dict(zip(HOURS, seq))}
        assert timeline_at(tl, 12)["mug"] == (TABLE_5_2[name][0],)
        assert timeline_at(tl, 0)["mug"] == (TABLE_5_2[name][1],)  # wraps to the 23:00 entry
        assert timeline_at(tl, 3)["mug"] == (seq[0],) and timeline_at(tl, 4.5)["mug"] == (seq[0],)


def test_requests_and_their_ground_truth(office):
    truth = {r.label: r.truth for r in office.task.requests}
    for name, (noon, midnight) in TABLE_5_2.items():
        assert truth[f"{name}.mug@12"] == (noon,) and truth[f"{name}.mug@0"] == (midnight,)
    assert truth["Combined.mug@12"] == ("H",) and truth["Combined.mug@0"] == ("A",)  # as Mobile-Inv
    assert truth["Moved-mug.mug@0"] == ("H",)  # moved from A, where the data points
    assert parse_label(request_label("Static-Inv", "mug", 12.5)) == ("Static-Inv", "mug", 12.5)


def test_recording_logs_where_the_mug_stood(office):
    log = office.task.logs["Static"]
    mug = log[log["class"] == "mug"]
    assert list(mug["hour"]) == HOURS
    assert "".join(mug["place"]) == TABLE_5_1["Static"]
    # the robot pose of a detection lies within camera range of the object
    d = np.hypot(mug["x"] - mug["robot_x"], mug["y"] - mug["robot_y"])
    assert (d <= 3.0 + 1e-6).all()
    # every fixed object was seen on every patrol; the combined case has one day per pattern
    assert len(log) == 9 * len(HOURS)
    comb = office.task.logs["Combined"]
    assert sorted(comb["day"].unique()) == [0, 1, 2, 3, 4] and len(comb) == 5 * len(log)
    assert (comb[comb["day"] == 0].drop(columns="day").reset_index(drop=True)
            .equals(log.drop(columns="day").reset_index(drop=True)))


def test_last_seen_fails_on_static_at_noon(office):
    # the last detection (23:00) is at H, the mug is at A at noon (thesis 5.3.4)
    res = run(office, "Static.mug@12", "last_seen")
    assert res.outcome == "not_found" and res.decisions == 1
    for planner in ("lsos", "brute_force"):
        assert run(office, "Static.mug@12", planner).outcome == "found"


def test_at_midnight_lsos_goes_straight_to_h_and_brute_force_patrols(office):
    lsos = run(office, "Static.mug@0", "lsos")
    bf = run(office, "Static.mug@0", "brute_force")
    assert lsos.outcome == bf.outcome == "found"
    assert lsos.decisions == 1 and bf.decisions == 8  # brute force reaches H after A-G
    assert bf.distance_m > 5 * lsos.distance_m
    assert lsos.distance_m <= 1.2 * office.shortest["Static.mug@0"]


def test_lsos_goal_order_follows_the_hour_weights(office):
    """Mobile at noon: A weighs 0.25+0.583+0.917+0.583+0.25 = 2.583 (3, 7, 11, 17, 21 h), H 2.417."""
    t = office.task
    fr = office.world.frame
    _, goals = lsos_goals(t.world.frame, t.known, office.task.logs["Mobile"], "mug", 12.0, LsosParams())
    assert len(goals) == 2
    first = np.array(fr.to_world(goals[0][0], goals[0][1]))
    near = min(t.places, key=lambda n: np.hypot(*(first - np.array(t.places[n]))))
    assert near == "A" and goals[0][2] > goals[1][2]
    # other classes never heat the map
    heat, _ = lsos_goals(t.world.frame, t.known, office.task.logs["Mobile"], "umbrella", 12.0, LsosParams())
    assert heat.sum() == 0.0


def test_moved_mug_lsos_tries_a_then_finds_it_at_h(office):
    res = run(office, "Moved-mug.mug@0", "lsos")
    assert res.outcome == "found" and res.decisions == 2
    assert run(office, "Moved-mug.mug@0", "last_seen").outcome == "not_found"


def test_rows_do_not_depend_on_workers(office, tmp_path):
    specs = [s for s in expand(office, seeds=2) if s.goal in ("Mobile.mug@0", "Shift.mug@12")]
    a = run_batch(office, specs, tmp_path / "a", BatchOptions(workers=1)).sort_values(["planner", "goal", "seed"])
    b = run_batch(office, specs, tmp_path / "b", BatchOptions(workers=2)).sort_values(["planner", "goal", "seed"])
    cols = ["planner", "goal", "seed", "outcome", "distance_m", "steps", "decisions"]
    assert a[cols].reset_index(drop=True).equals(b[cols].reset_index(drop=True))
    (row,), _ = execute(office, specs[0])
    assert row["goal"] == specs[0].goal and row["shortest_m"] > 0


def office_copy(tmp_path, edit) -> Path:
    data = yaml.safe_load(OFFICE.read_text())
    data["map"]["image"] = str(ROOT / "maps" / "office" / "map.png")
    edit(data)
    p = tmp_path / "office.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def test_a_recorded_log_replays_like_its_timeline(office, tmp_path):
    r = CliRunner().invoke(app, ["record", str(OFFICE), "--out", str(tmp_path / "logs"), "--case", "Static"])
    assert r.exit_code == 0, r.output

    def edit(d):
        d["objects"]["cases"] = [{"name": "Static", "record": "logs/Static.csv", "truth": "Static"}]

    replay = Loaded.load(office_copy(tmp_path, edit))
    for label in ("Static.mug@12", "Static.mug@0"):
        req = replay.task.request(label)
        a = replay.task.run(Variant("lsos", ()), req.label, 3)
        b = run(office, label, "lsos", 3)
        assert (a.outcome, a.distance_m) == (b.outcome, b.distance_m)


@pytest.mark.parametrize("edit, field, needle", [
    (lambda d: d["objects"]["timelines"]["Static"]["mug"].update({3: "Z"}), "objects.timelines.Static.mug.3", "unknown place 'Z'"),
    (lambda d: d.update(planners=[{"name": "nsos"}]), "planners[0].name", "answers doors scenarios, not objects ones"),
    (lambda d: d["objects"]["cases"][0].update(record=["Tuesday"]), "objects.cases[0].record", "unknown timeline"),
    (lambda d: d["objects"]["places"][0].update(x=-5.0), "objects.places[0]", "outside the map"),
    (lambda d: d["objects"]["requests"][0].update(hour=25), "objects.requests[0].hour", "less than 24"),
    (lambda d: d["planners"].append({"name": "lsos", "radius": -1}), "planners[3].radius", "radius must be more than 0"),
    (lambda d: d["objects"]["camera"].update(p_detect={"distances": [1, 2], "p": [[0.5]]}), "objects.camera.p_detect",
     "p must have 1 row(s) (one per angle) of 2 values"),
])
def test_bad_object_scenarios_name_the_field(tmp_path, edit, field, needle):
    p = office_copy(tmp_path, edit)
    r = CliRunner().invoke(app, ["validate", str(p)])
    text = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in text
    assert field in text and needle in text, text


def test_run_writes_the_object_report(tmp_path):
    out = tmp_path / "res"
    r = CliRunner().invoke(app, ["run", str(OFFICE), "--seeds", "2", "--goal", "Static.mug@12", "--goal", "Static.mug@0",
                                 "--out", str(out), "--workers", "1"])
    assert r.exit_code == 0, r.output
    table = (out / "tables" / "objects.md").read_text()
    assert "Static" in table and "last_seen" in table and "(0/2)" in table  # last seen fails at noon
    for f in ("figures/objects_by_case.png", "figures/heat_Static.mug@12.png", "figures/paths_Static.mug@0.png",
              "logs/Static.csv", "report.html", "tables/objects.csv"):
        assert (out / f).is_file(), f


def test_when_the_mug_is_gone_lsos_and_brute_force_look_everywhere_then_give_up(tmp_path):
    def edit(d):
        d["objects"]["cases"] = [{"name": "Gone", "record": ["Static"], "truth": "Static",
                                  "requests": [{"class": "mug", "hour": 12, "at": []}]}]

    gone = Loaded.load(office_copy(tmp_path, edit))
    req = gone.task.request("Gone.mug@12")
    assert req.truth == () and gone.shortest["Gone.mug@12"] == float("inf")
    for planner in ("lsos", "brute_force"):
        res = gone.task.run(Variant(planner, ()), req.label, 0)
        assert res.outcome == "not_found"
    # lsos went to its heat-map goals, then to every place the camera had not yet seen, in patrol order
    tracer = TraceObserver()
    gone.task.run(Variant("lsos", ()), req.label, 0, tracer)
    trace = tracer.rows
    kinds = [t["kind"] for t in trace]
    k = kinds.count("heat")
    assert k == 2 and kinds == ["heat"] * k + ["patrol"] * (len(kinds) - k)
    visited = [t["place"] for t in trace[k:]]
    route = gone.task.route
    assert visited == sorted(visited, key=route.index) and "A" not in visited and "H" not in visited
    assert 0 < len(visited) < len(route)  # places seen on the way were skipped


def test_a_bad_detection_log_names_the_file_and_column(tmp_path):
    (tmp_path / "log.csv").write_text("class,x,y,hour,robot_x\nmug,1,13.4,3,2.6\n")

    def edit(d):
        d["objects"]["cases"] = [{"name": "L", "record": "log.csv", "truth": "Static"}]

    r = CliRunner().invoke(app, ["validate", str(office_copy(tmp_path, edit))])
    text = " ".join(r.output.split())
    assert r.exit_code == 2 and "log.csv" in text and "robot_y" in text, text
    (tmp_path / "log.csv").write_text("class,x,y,hour,robot_x,robot_y\nmug,1,13.4,noon,2.6,11.8\n")
    r = CliRunner().invoke(app, ["validate", str(office_copy(tmp_path, edit))])
    text = " ".join(r.output.split())
    assert r.exit_code == 2 and "'hour'" in text and "numbers" in text, text


def test_detection_table_by_distance_and_view_angle():
    from semsearch_cli.config import DetectTable
    from semsearch_cli.sensors import detect_probability

    t = DetectTable(distances=[0.8, 1.2, 1.6], angles=[0, 90, 180, 270], p=[[0.8, 0.6, 0.4], [0.1, 0.1, 0.0], [0.5, 0.5, 0.5], [0.2, 0.2, 0.2]])
    assert detect_probability(t, 1.0, 0.0) == pytest.approx(0.7)  # halfway between 0.8 and 0.6
    assert detect_probability(t, 0.3, 350.0) == pytest.approx(0.8)  # clamped; 350 is nearest 0
    assert detect_probability(t, 2.0, 100.0) == pytest.approx(0.0)  # clamped at 1.6, nearest 90
    assert detect_probability(t, 1.4, 200.0) == pytest.approx(0.5)
    assert detect_probability(0.9, 5.0, 0.0) == 0.9
    with pytest.raises(ValueError):
        DetectTable(distances=[1.0, 0.5], p=[[0.5, 0.5]])


def test_a_class_with_a_short_camera_range_is_seen_later(tmp_path):
    def edit(d):
        d["objects"]["camera"]["p_detect"] = 1.0
        d["objects"]["camera"]["classes"] = {"mug": {"range": 1.0}}

    short = Loaded.load(office_copy(tmp_path, edit))
    full = Loaded.load(office_copy(tmp_path, lambda d: d["objects"]["camera"].update(p_detect=1.0)))
    label = "Static.mug@0"
    a = short.task.run(Variant("last_seen", ()), label, 0)
    b = full.task.run(Variant("last_seen", ()), label, 0)
    assert a.outcome == b.outcome == "found"
    assert a.distance_m > b.distance_m + 1.5  # about 2 m later: the mug's range is 1 m, not 3 m
    assert short.shortest[label] > full.shortest[label] + 1.5
