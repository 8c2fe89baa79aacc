"""Every registered task and planner through one test; planners from the user's own files and
from entry points; chains (thesis ch. 6); one report over folders of several kinds."""

import html as html_lib
import json
import os
import pickle
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.planners import PLANNERS, base as planner_base
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch
from semsearch_cli.tasks import TASKS, TraceObserver

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"
CHROMIUM = next((p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None)


def write_scenario(tmp_path: Path, data: dict, name: str = "scenario.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def demo_data(**over) -> dict:
    d = yaml.safe_load((CONFIGS / "demo.yaml").read_text())
    d["map"]["image"] = str(ROOT / "maps" / "demo" / "map.png")
    d["doors"] = str(ROOT / "maps" / "demo" / "doors.csv")
    d.update(over)
    return d


def small_scenario(kind: str, planner: str, tmp_path: Path) -> Path:
    """The kind's own small example, run by ``planner`` (for the chain: greedy's door stages)."""
    return TASKS[kind].example(tmp_path / "example", planner)


def cases():
    out = []
    for name, cls in sorted(PLANNERS.items()):
        if cls.service:  # a language model's endpoint: tests/test_llm.py
            continue
        kinds = [k for k, t in TASKS.items() if t.planner_kind == cls.task]
        out += [(k, name) for k in sorted(kinds)]
    return out


@pytest.mark.parametrize("kind,planner", cases())
def test_every_task_and_planner(kind, planner, tmp_path):
    """Ends within its budget, the same rows with 1 and 2 workers, and its loaded scenario pickles."""
    p = small_scenario(kind, planner, tmp_path)
    loaded = Loaded.load(p)
    assert loaded.kind == kind
    back = pickle.loads(pickle.dumps(loaded))
    assert back.goals == loaded.goals and back.shortest == loaded.shortest
    specs = expand(loaded, seeds=1)[:2]
    a = run_batch(loaded, specs, tmp_path / "w1", BatchOptions(workers=1))
    b = run_batch(back, specs, tmp_path / "w2", BatchOptions(workers=2))
    assert set(a["kind"]) == {kind}
    for col in TASKS[kind].records:  # what the kind says it records, it records
        assert (a[col].astype(str) != "").all() and a[col].notna().all(), col
    assert (a["outcome"].isin(["found", "not_found", "stuck", "budget"])).all()
    step = loaded.sc.robot.step if hasattr(loaded.sc, "robot") else 0.0  # indirect search's robot is in its own section
    assert (a["distance_m"] <= loaded.sc.experiment.max_distance + step).all()
    key = ["planner", "goal", "episode", "seed", "stage", "map"]
    cols = [c for c in a.columns if c != "wall_s"]
    pd.testing.assert_frame_equal(a.sort_values(key)[cols].reset_index(drop=True), b.sort_values(key)[cols].reset_index(drop=True))


def test_decisions_count_new_targets_only(demo_loaded):
    """A decision is a new target, for every door planner: bvp marks a kept target (info kept),
    greedy and nsos choose the same cell again at periodic re-plans; neither counts."""
    for name in ("greedy", "bvp", "nsos"):
        v = planner_base.Variant(name, ())
        tracer = TraceObserver()
        res = demo_loaded.task.run(v, 452, 2, tracer)
        assert res.decisions == len(tracer.rows) > 0
        assert not any(d.get("kept") for d in tracer.rows)
        targets = [tuple(d["target"]) for d in tracer.rows]
        assert all(a != b for a, b in zip(targets, targets[1:])), name


# ---- planners from the user's own files -------------------------------------------------
PLANNER_FILE = '''
import numpy as np
from semsearch_cli.planners import Decision, DoorPlanner, register_planner

@register_planner("{name}")
class Mine(DoorPlanner):
    def choose(self, ctx, cands):
        if len(cands) == 0:
            return None
        {body}
        return Decision(int(cands.rows[0]), int(cands.cols[0]), {{}})
'''


def user_scenario(tmp_path, name, body="pass", text=None, planners=None):
    (tmp_path / "mine.py").write_text(text if text is not None else PLANNER_FILE.format(name=name, body=body))
    return write_scenario(tmp_path, demo_data(goals=[452, 304], experiment={"seeds": 2, "max_distance": 300},
                                              planners=planners or [{"name": "greedy"}, {"name": name, "module": "mine.py"}]))


def test_the_example_planner_runs_from_its_own_file_with_two_workers(tmp_path):
    ex = tmp_path / "custom_planner"
    shutil.copytree(ROOT / "examples" / "custom_planner", ex)
    d = yaml.safe_load((ex / "scenario.yaml").read_text())
    d["map"]["image"] = str(ROOT / "maps" / "demo" / "map.png")
    d["doors"] = str(ROOT / "maps" / "demo" / "doors.csv")
    d["experiment"]["seeds"] = 2
    (ex / "scenario.yaml").write_text(yaml.safe_dump(d))
    res = CliRunner().invoke(app, ["run", str(ex / "scenario.yaml"), "--workers", "2", "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    runs = pd.read_csv(tmp_path / "out" / "runs.csv")
    assert set(runs["planner"]) == {"greedy", "straight_on[turn_weight=0.0]", "straight_on[turn_weight=2.0]"}
    assert len(runs) == 12 and (runs["outcome"] == "found").all()


def test_a_planner_from_the_users_file_runs_in_spawned_workers(tmp_path):
    """A spawned worker starts a fresh interpreter that has never seen the user's file: it must
    load it again from the pickled scenario, and give the rows of the serial run."""
    p = user_scenario(tmp_path, "spawned", body="pass")
    loaded = Loaded.load(p)
    specs = expand(loaded)
    a = run_batch(loaded, specs, tmp_path / "serial", BatchOptions(workers=1))
    b = run_batch(loaded, specs, tmp_path / "spawn", BatchOptions(workers=2, start_method="spawn"))
    assert set(b["planner"]) == {"greedy", "spawned"} and (b["outcome"] != "error").all(), b["message"].tolist()
    key, cols = ["planner", "goal", "seed"], [c for c in a.columns if c != "wall_s"]
    pd.testing.assert_frame_equal(a.sort_values(key)[cols].reset_index(drop=True), b.sort_values(key)[cols].reset_index(drop=True))


@pytest.mark.parametrize("text,needle", [
    ("def broken(:\n", "'line 1': not valid Python"),
    ("x = 1\n", "registers no planner"),
    (PLANNER_FILE.format(name="greedy", body="pass"), "'greedy' is already registered"),
    ("raise RuntimeError('boom')\n", "'line 1': the planner file raised RuntimeError: boom"),
])
def test_a_broken_planner_file_exits_2_naming_the_file(tmp_path, text, needle):
    p = user_scenario(tmp_path, "whatever", text=text, planners=[{"name": "whatever", "module": "mine.py"}])
    res = CliRunner().invoke(app, ["validate", str(p)])
    assert res.exit_code == 2 and "mine.py" in res.output and needle in res.output.replace("\n", " "), res.output
    assert "Traceback" not in res.output


def test_a_planner_that_raises_gives_error_rows_and_the_batch_goes_on(tmp_path):
    p = user_scenario(tmp_path, "raiser", body="raise ValueError('no idea where to go')")
    res = CliRunner().invoke(app, ["run", str(p), "--workers", "2", "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    runs = pd.read_csv(tmp_path / "out" / "runs.csv")
    bad = runs[runs["planner"] == "raiser"]
    assert len(bad) == 4 and (bad["outcome"] == "error").all()
    assert bad["message"].str.contains("ValueError: no idea where to go").all()
    assert (runs[runs["planner"] == "greedy"]["outcome"] == "found").all()
    assert "4 run(s) raised an error" in res.output


def test_installed_packages_register_planners_through_entry_points(tmp_path, monkeypatch):
    site = tmp_path / "site"
    (site / "ep_planner_pkg").mkdir(parents=True)
    (site / "ep_planner_pkg" / "__init__.py").write_text(PLANNER_FILE.format(name="from_entry_point", body="pass"))
    dist = site / "ep_planner_pkg-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: ep-planner-pkg\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[semsearch.planners]\nmine = ep_planner_pkg\n")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(planner_base, "_ENTRY_POINTS_LOADED", False)
    p = write_scenario(tmp_path, demo_data(goals=[452], planners=[{"name": "from_entry_point"}], experiment={"seeds": 1, "max_distance": 300}))
    try:
        loaded = Loaded.load(p)
        rows = run_batch(loaded, expand(loaded), tmp_path / "out")
        assert rows["planner"].tolist() == ["from_entry_point"] and rows["outcome"].iloc[0] in ("found", "stuck", "budget")
    finally:
        PLANNERS.pop("from_entry_point", None)
        sys.modules.pop("ep_planner_pkg", None)


# ---- chains -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def hospital_runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("hospital")
    res = CliRunner().invoke(app, ["run", str(CONFIGS / "hospital.yaml"), "--seeds", "1", "--planner", "greedy",
                                   "--workers", "2", "--out", str(out)])
    assert res.exit_code == 0, res.output
    return out, pd.read_csv(out / "runs.csv", dtype={"stage": str, "map": str}, keep_default_na=False)


def test_a_chain_keeps_its_map_and_each_stage_is_also_run_from_scratch(hospital_runs):
    out, runs = hospital_runs
    assert set(runs["kind"]) == {"chain"}
    chain = runs[(runs["goal"] == "ward-round") & (runs["stage"] == "")].iloc[0]
    stages = runs[(runs["goal"] == "ward-round") & (runs["stage"] != "")]
    kept, scratch = stages[stages["map"] == "kept"], stages[stages["map"] == "scratch"]
    assert kept["stage"].tolist() == ["1:7", "2:16", "3:12", "4:7", "5:20"] == scratch["stage"].tolist()
    assert chain["outcome"] == "found" and chain["distance_m"] == pytest.approx(kept["distance_m"].astype(float).sum(), abs=0.01)
    assert chain["shortest_m"] == pytest.approx(kept["shortest_m"].astype(float).sum(), abs=0.01)
    # the first stage starts with an empty map either way: the same run
    assert kept["distance_m"].iloc[0] == scratch["distance_m"].iloc[0]
    # stage 4 returns to door 7, whose sign was read in stage 1: path planning, one decision
    four = kept[kept["stage"] == "4:7"].iloc[0]
    assert int(four["decisions"]) == 1 and float(four["distance_m"]) <= 1.3 * float(four["shortest_m"])
    md = (out / "report.md").read_text()
    assert "## Chained searches (4 chains)" in md and "Do later requests get cheaper?" in md


def test_an_object_stage_searches_the_room_behind_its_door(hospital_runs):
    _, runs = hospital_runs
    fetch = runs[(runs["goal"] == "fetch") & (runs["map"] == "kept") & (runs["stage"] != "")]
    assert fetch["stage"].tolist() == ["1:12/laptop@11", "2:15/mug@16", "3:12"]
    assert (fetch["outcome"] == "found").all()


@pytest.mark.parametrize("edit,field,needle", [
    (lambda c: c[0]["stages"].append({"door": 999}), "chains[0].stages[3]", "no door sign carries the number 999"),
    (lambda c: c[2]["stages"][0].update(object="laptop", hour=None), "chains[2].stages[0]", "both object and hour"),
    (lambda c: c[2]["stages"][0].update(door=3), "chains[2].stages[0]", "no place has room: 3"),
    (lambda c: c[2].pop("truth"), "chains[2]", "record (timelines or a log) and truth"),
])
def test_bad_chains_name_the_field(tmp_path, edit, field, needle):
    d = yaml.safe_load((CONFIGS / "hospital.yaml").read_text())
    d["map"]["image"] = str(ROOT / "maps" / "hospital" / "map.png")
    d["doors"] = str(ROOT / "maps" / "hospital" / "doors.csv")
    edit(d["chains"])
    res = CliRunner().invoke(app, ["validate", str(write_scenario(tmp_path, d))])
    assert res.exit_code == 2 and field in res.output and needle in res.output.replace("\n", " "), res.output


@pytest.fixture(scope="module")
def mixed_report(hospital_runs, demo_dir, tmp_path_factory):
    """One report over a chain folder and a door-search folder."""
    out, _ = hospital_runs
    tmp = tmp_path_factory.mktemp("mixed")
    res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "1", "--goal", "304", "--out", str(tmp / "d")])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, ["report", str(out), str(tmp / "d"), "--out", str(tmp / "both"), "--no-replay"])
    assert res.exit_code == 0, res.output
    return tmp / "both"


def test_one_report_over_folders_of_several_kinds(mixed_report):
    md = (mixed_report / "report.md").read_text()
    assert "## Chained searches" in md and "## Door search (2 runs)" in md
    html = (mixed_report / "report.html").read_text()
    assert "**" not in html and "<span class=best>" in html  # marks rendered, not raw Markdown


# Appended to a copy of the report (never to the report itself): once the page has loaded, write
# what a reader would see wrong into an attribute that --dump-dom prints.
PROBE = """<script>addEventListener("load", () => {
  const marks = /[*][*]|(^|\\s)_[^_\\s]+_(\\s|$)|^\\s*#+ /;
  const walk = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  const raw = [];
  for (let n = walk.nextNode(); n; n = walk.nextNode())
    if (!n.parentElement.closest("pre, code, script") && marks.test(n.data)) raw.push(n.data.slice(0, 80));
  document.body.dataset.probe = JSON.stringify({
    overflow: document.documentElement.scrollWidth - window.innerWidth,
    raw_marks: raw,
    images: document.images.length,
    broken_images: [...document.images].filter(i => !(i.complete && i.naturalWidth > 0)).length,
    tables: document.querySelectorAll("table").length,
    headings: [...document.querySelectorAll("h2")].map(h => h.innerText)});
});</script>"""


@pytest.mark.skipif(CHROMIUM is None and not os.environ.get("CI"),
                    reason="no chromium on PATH (.ci/run installs it from Debian's packages, and there it must run)")
def test_the_html_report_reads_well_in_a_browser(mixed_report, tmp_path):
    """Headless Chromium, a 900 px wide window: no raw Markdown marks in the text a reader sees, no
    line wider than the page, every figure decoded, every kind's section present."""
    page = tmp_path / "probe.html"
    page.write_text((mixed_report / "report.html").read_text().replace("</body>", PROBE + "</body>"))
    res = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--window-size=900,1200",
                          "--virtual-time-budget=10000", "--dump-dom", page.as_uri()],
                         capture_output=True, text=True, timeout=120)
    found = re.search(r'data-probe="([^"]*)"', res.stdout)
    assert found, res.stderr[-2000:]
    probe = json.loads(html_lib.unescape(found.group(1)))
    assert probe["overflow"] <= 0 and probe["raw_marks"] == [], probe
    assert probe["images"] > 0 and probe["broken_images"] == 0 and probe["tables"] > 0, probe
    assert any(h.startswith("Chained searches") for h in probe["headings"]), probe
    assert any(h.startswith("Door search") for h in probe["headings"]), probe


# ---- signs that share a number ------------------------------------------------------------
def duplicated_demo(tmp_path, policy=None):
    """The demo with its sign nearest the start (by path) renumbered 304, so that 304 appears
    twice: the original, 11.7 m away, and this nearer one."""
    demo = Loaded.load(CONFIGS / "demo.yaml").world
    others = [n for n in demo.signs.number if str(n) != "304"]
    near = min(others, key=demo.shortest_path)
    rows = (ROOT / "maps" / "demo" / "doors.csv").read_text().splitlines()
    rows = [rows[0]] + [("304" + r[len(str(near)):]) if r.split(",")[0] == str(near) else r for r in rows[1:]]
    (tmp_path / "doors.csv").write_text("\n".join(rows) + "\n")
    extra = {"duplicates": policy} if policy else {}
    d = demo_data(goals=[304], planners=[{"name": "greedy"}], experiment={"seeds": 1, "max_distance": 300}, **extra)
    d["doors"] = str(tmp_path / "doors.csv")
    return write_scenario(tmp_path, d), demo.shortest_path(near), demo.shortest_path(304), demo.signs.index_of(near) < demo.signs.index_of(304)


def test_duplicate_numbers_are_refused_by_default_naming_each(tmp_path):
    p, _, _, _ = duplicated_demo(tmp_path)
    res = CliRunner().invoke(app, ["validate", str(p)])
    out = res.output.replace("\n", " ")
    assert res.exit_code == 2 and "304 at (" in out and "duplicates: keep-first" in out, res.output


def test_duplicates_keep_first_keeps_the_first_sign_of_a_number(tmp_path):
    p, near_m, orig_m, near_first = duplicated_demo(tmp_path, "keep-first")
    L = Loaded.load(p)
    assert len(L.world.signs.indices_of(304)) == 1 and "304" in L.world.duplicates
    assert L.shortest[304] == pytest.approx(near_m if near_first else orig_m)  # the sign listed first


def test_duplicates_any_finds_the_goal_at_the_nearest_sign(tmp_path):
    p, near_m, orig_m, _ = duplicated_demo(tmp_path, "any")
    L = Loaded.load(p)
    assert len(L.world.signs.indices_of(304)) == 2
    assert near_m < orig_m and L.shortest[304] == pytest.approx(near_m)  # the nearer of the two
    res = CliRunner().invoke(app, ["validate", str(p)])
    assert res.exit_code == 0 and "duplicated numbers (any)" in res.output and "304" in res.output, res.output
    rows = run_batch(L, expand(L), tmp_path / "out")
    assert (rows["outcome"] == "found").all()
