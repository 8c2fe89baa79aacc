"""semsearch-bench: suites, their hashes, the numbering ablation, bench runs and their verification."""

from __future__ import annotations

import functools
import hashlib
import html as html_lib
import http.server
import json
import os
import re
import shutil
import subprocess
import threading
import urllib.parse

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

from semsearch_cli import api, bench
from semsearch_cli.bench.board import at_budget, paired_diff, uis_budgets
from semsearch_cli.bench.predictability import predictability
from semsearch_cli.engine import ENGINE
from semsearch_cli.bench.suites import build, read_split
from semsearch_cli.cli import app
from semsearch_cli.planners import PLANNERS, Variant
from semsearch_cli.report.figures import bench as figures
from semsearch_cli.runner import BatchOptions, Loaded
from semsearch_cli.shipped import scenario_file
from semsearch_cli.world.buildings.numbered import generate_building

from .conftest import REF

runner = CliRunner()


# -- the numbering ablation ------------------------------------------------------------------------

def test_parity_flip_swaps_each_odd_number_with_the_next_even_one():
    assert bench.relabel([1, 2, 3, 4, 5], "parity-flipped", "x") == {1: 2, 2: 1, 3: 4, 4: 3, 5: 5}


def test_reversed_trades_the_kth_smallest_with_the_kth_largest_within_each_prefix():
    got = bench.relabel(["K101", "K103", "K105", "B7", "B8", "Lab"], "reversed", "x")
    assert got == {"K101": "K105", "K103": "K103", "K105": "K101", "B7": "B8", "B8": "B7", "Lab": "Lab"}


def test_parity_flip_pairs_across_skipped_numbers_and_reversed_carries_suffixes():
    assert bench.relabel([23, 24, 26, 27, 28], "parity-flipped", "x") == {23: 24, 24: 23, 26: 27, 27: 26, 28: 28}
    assert bench.relabel(["23", "24a", "24b", "25"], "reversed", "x") == {"23": "25", "24a": "24b", "24b": "24a", "25": "23"}


def test_lettered_labels_trade_with_the_same_letter_only():
    got = bench.relabel(["24A", "24B", "25A", "23"], "parity-flipped", "x")
    # 23 <-> 24 needs a 24 without a letter: none, so 23 stays; 24A, 25A... 25 is odd: 25A <-> 26A (absent)
    assert got == {"24A": "24A", "24B": "24B", "25A": "25A", "23": "23"}
    got = bench.relabel(["23A", "24A", "24B"], "parity-flipped", "x")
    assert got == {"23A": "24A", "24A": "23A", "24B": "24B"}


@pytest.mark.parametrize("how", bench.NUMBERINGS)
def test_every_numbering_is_a_bijection_of_the_floors_labels(how):
    labels = [*range(101, 141), "K201", "K202", "2.14", "2.15", "Lab"]
    m = bench.relabel(labels, how, "floor-7")
    assert sorted(map(str, m)) == sorted(map(str, labels)) and sorted(map(str, m.values())) == sorted(map(str, labels))
    assert (m == {a: a for a in labels}) == (how == "true")


def test_shuffled_is_seeded_by_the_floor():
    labels = list(range(1, 30))
    assert bench.relabel(labels, "shuffled", "a") == bench.relabel(labels, "shuffled", "a")
    assert bench.relabel(labels, "shuffled", "a") != bench.relabel(labels, "shuffled", "b")


@pytest.mark.parametrize("how", ["shuffled", "parity-flipped", "reversed"])
def test_a_renumbered_floor_keeps_every_sign_and_each_goal_door_in_its_place(tmp_path, how):
    sp = bench.open_split("doors-v1")
    # the first floor this numbering changes (one numbered with a single parity has no parity to flip)
    labels = {f.id: pd.read_csv(f.scenario.parent / "doors.csv", dtype=str)["number"].tolist() for f in sp.floors}
    floor = next(f for f in sp.floors if any(a != b for a, b in bench.relabel(labels[f.id], how, f.id).items()))
    true = bench.materialise(sp, floor, "true", tmp_path / "true")
    other = bench.materialise(sp, floor, how, tmp_path / how)
    a = pd.read_csv(true.parent / "doors.csv", dtype=str)
    b = pd.read_csv(other.parent / "doors.csv", dtype=str)
    assert (a[["x", "y", "facing"]].to_numpy() == b[["x", "y", "facing"]].to_numpy()).all()  # positions kept
    assert sorted(a["number"]) == sorted(b["number"]) and (a["number"] != b["number"]).any()  # labels permuted
    where = {n: (x, y) for n, x, y in zip(b["number"], b["x"], b["y"])}
    old = {n: (x, y) for n, x, y in zip(a["number"], a["x"], a["y"])}
    ea = pd.read_csv(true.parent / "episodes.csv", dtype=str, keep_default_na=False)
    eb = pd.read_csv(other.parent / "episodes.csv", dtype=str, keep_default_na=False)
    assert (ea[["start_x", "start_y", "start_heading", "shortest_m"]] == eb[["start_x", "start_y", "start_heading", "shortest_m"]]).all().all()
    assert all(old[g] == where[h] for g, h in zip(ea["goal"], eb["goal"]))  # each episode's goal is the same door
    assert api.validate(other)["signs"] == len(a)  # and the renumbered floor loads (the episodes' hashes are its own)


# -- suites and their hashes -----------------------------------------------------------------------

def test_every_shipped_split_has_its_published_hash():
    for s in bench.SUITES.values():
        for split in s.shipped:
            sp = bench.open_split(s.name, split)
            assert sp.hash == bench.PUBLISHED[(s.name, split)] and sp.official


@pytest.mark.parametrize("suite", ["doors-v1", "doors-classic-v1", "indirect-v1", "objects-v1"])
def test_a_shipped_split_is_rebuilt_byte_for_byte_from_its_builder(tmp_path, suite):
    s = bench.SUITES[suite]
    build(s, "val", f"{suite}/val", tmp_path / "val")
    again = read_split(s, "val", tmp_path / "val")
    assert again.hash == bench.open_split(suite).hash


def test_doors_v1_val_has_40_floors_of_4_goals_and_5_starts_each():
    sp = bench.open_split("doors-v1")
    assert len(sp.floors) == 40
    for f in sp.floors:
        eps = pd.read_csv(f.scenario.parent / "episodes.csv")
        assert eps.groupby("goal").size().tolist() == [5] * 4, f.id
        assert (eps["shortest_m"] >= 10.0).all()


def test_a_hidden_split_needs_its_salt_and_is_official_only_with_the_published_hash(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    with pytest.raises(api.ScenarioError, match="--salt-file"):
        bench.open_split("doors-v1", "test")
    salt = tmp_path / "salt.txt"
    salt.write_text("a test salt, not the project's: 0123456789abcdef\n")
    sp = bench.open_split("doors-v1", "test", salt)
    assert len(sp.floors) == 40 and sp.hash != bench.open_split("doors-v1").hash
    assert not sp.official  # no published test hash in this repository: a placeholder
    monkeypatch.setitem(bench.PUBLISHED, ("doors-v1", "test"), sp.hash)
    assert bench.open_split("doors-v1", "test", salt).official  # the maintainer's hash, filled in
    other = tmp_path / "other.txt"
    other.write_text("another salt entirely, 16+ chars")
    assert not bench.open_split("doors-v1", "test", other).official
    res = runner.invoke(app, ["bench", "hash", "doors-v1", "--split", "test", "--salt-file", str(other)])
    assert res.exit_code == 0 and res.stdout.strip() == bench.open_split("doors-v1", "test", other).hash


def test_bench_list_shows_every_split_with_its_size_and_hash(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    rows = {(r["suite"], r["split"]): r for r in api.bench_list()}
    assert (rows[("doors-v1", "val")]["floors"], rows[("doors-v1", "val")]["goals"], rows[("doors-v1", "val")]["episodes"]) == (40, 160, 800)
    assert (rows[("indirect-v1", "val")]["floors"], rows[("indirect-v1", "val")]["episodes"]) == ("20 rooms", 1400)
    assert rows[("doors-v1", "test")]["hidden"] and rows[("doors-real-v1", "val")].get("fetch")
    res = runner.invoke(app, ["bench", "list"])
    assert res.exit_code == 0 and "doors-classic-v1" in res.stdout and "= published" in res.stdout


def test_a_short_salt_and_an_unknown_suite_are_refused_in_words(tmp_path):
    salt = tmp_path / "salt.txt"
    salt.write_text("short")
    res = runner.invoke(app, ["bench", "hash", "doors-v1", "--split", "test", "--salt-file", str(salt)])
    assert res.exit_code == 2 and "at least 16" in res.stderr
    res = runner.invoke(app, ["bench", "run", "doors-v2", "--planner", "greedy", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "did you mean 'doors-v1'" in res.stderr
    res = runner.invoke(app, ["bench", "run", "doors-v1", "--planner", "nsoss", "--limit", "1", "--out", str(tmp_path / "p")])
    assert res.exit_code == 2 and "<command line>, field '--planner': unknown planner 'nsoss' (did you mean 'nsos'?)" in res.stderr


# -- bench runs and verify ------------------------------------------------------------------------

def _run(tmp_path, planner, limit=3, numbering="true", suite="doors-v1", **kw):
    return api.bench_run(suite, [planner], tmp_path / f"{planner}-{numbering}", numbering=numbering,
                         options=BatchOptions(workers=1), limit=limit, **kw)


@pytest.mark.parametrize("planner", ["greedy", "nsos[alpha=0.9]", "bvp", "draft", "oracle_goal", "distance_advantage"])
def test_every_built_in_door_planner_verifies_exactly_on_a_slice(tmp_path, planner):
    res = _run(tmp_path, planner, limit=7)  # floor f000's 20 episodes are more than 7: one floor
    runs = res.runs
    if planner in ("oracle_goal", "distance_advantage"):  # distance_advantage without its hysteresis turned back and
        assert set(runs["outcome"]) == {"found"}         # forth on episode 4 until the budget was spent (2000 m)
    assert len(runs) == 7 and set(runs["suite_hash"]) == {res.split.hash} and set(runs["floor"]) == {"f000"}
    files = sorted((res.out / "f000" / "decisions").glob("*.json"))
    assert len(files) == 7  # and each row names its record by the SHA-256 of its bytes
    assert sorted(runs["decisions_sha256"]) == sorted(hashlib.sha256(f.read_bytes()).hexdigest() for f in files)
    v = api.verify(res.out, workers=1).verdict
    assert (v.runs, v.verified, v.failed) == (7, 7, [])


def test_a_slice_spans_floors_and_resumes(tmp_path):
    res = _run(tmp_path, "greedy", limit=22)
    assert res.floors == ["f000", "f001"] and len(res.runs) == 22
    again = _run(tmp_path, "greedy", limit=22)
    assert len(again.runs) == 22  # nothing ran twice


def test_verify_names_a_tampered_distance_and_a_truncated_decision_sequence(tmp_path):
    res = _run(tmp_path, "nsos[alpha=0.9]", limit=3)
    f = res.out / "f000" / "runs.csv"
    decisions = res.out / "f000" / "decisions"
    rows = pd.read_csv(f, dtype=str, keep_default_na=False)
    rows.loc[0, "distance_m"] = str(float(rows.loc[0, "distance_m"]) - 1.0)  # episode 0: a shorter distance
    for ep in (1, 2):  # episode 1: a truncated record; episode 2: the same, and the row's digest changed to match
        dec = sorted(decisions.glob(f"*ep{ep}__seed0.json"))[0]
        rec = json.loads(dec.read_text())
        rec["decisions"] = rec["decisions"][: len(rec["decisions"]) // 2]
        dec.write_text(json.dumps(rec))
        if ep == 2:
            rows.loc[rows["episode"] == "2", "decisions_sha256"] = hashlib.sha256(dec.read_bytes()).hexdigest()
    rows.to_csv(f, index=False)
    out = runner.invoke(app, ["verify", str(res.out), "--workers", "1"])
    assert out.exit_code == 1
    assert "floor f000: nsos[alpha=0.9] goal" in out.stdout and "episode 0 seed 0: distance_m" in out.stdout
    assert "is not the record the row names" in out.stdout  # episode 1
    assert "episode 2 seed 0: the replay stopped" in out.stdout
    assert "0 of 3 runs replayed" in out.stdout


def test_verify_fails_a_folder_that_is_no_floor_and_a_run_whose_record_was_taken_away(tmp_path):
    res = _run(tmp_path, "greedy", limit=3)
    shutil.copytree(res.out / "f000", res.out / "zzz")  # rows that name no floor of the split
    next((res.out / "f000" / "decisions").glob("*ep2__seed0.json")).unlink()
    out = runner.invoke(app, ["verify", str(res.out), "--workers", "1"])
    assert out.exit_code == 1
    assert "floor zzz: its rows: folder zzz is not a floor of doors-v1 val" in out.stdout
    assert re.search(r"floor f000: greedy goal \S+ episode 2 seed 0: its record decisions/\S+, which the row names "
                     r"\(decisions_sha256\), is gone", " ".join(out.stdout.split()))
    board = api.bench_board([res.out], tmp_path / "site")  # the board reads the split's floors alone, and says it failed
    md = (tmp_path / "site" / "board.md").read_text()
    assert "| greedy | 3 of 800 | 3 |" in md and "failed" in md and board


def test_a_folder_of_another_numbering_is_refused(tmp_path):
    _run(tmp_path, "greedy", limit=1)
    with pytest.raises(api.ScenarioError, match="numbering"):
        api.bench_run("doors-v1", ["greedy"], tmp_path / "greedy-true", numbering="shuffled", options=BatchOptions(workers=1), limit=1)


def test_a_renumbered_run_pairs_with_the_true_one_episode_by_episode(tmp_path):
    a = _run(tmp_path, "nsos[alpha=0.9]", limit=4).runs
    b = _run(tmp_path, "nsos[alpha=0.9]", limit=4, numbering="shuffled").runs
    assert (a[["floor", "episode", "start_x", "start_y", "shortest_m"]].to_numpy() == b[["floor", "episode", "start_x", "start_y", "shortest_m"]].to_numpy()).all()
    assert set(b["numbering"]) == {"shuffled"} and (a["goal"].astype(str) != b["goal"].astype(str)).any()
    assert api.verify(tmp_path / "nsos[alpha=0.9]-shuffled", workers=1).verdict.verified == 4


USER_PLANNER = '''
from semsearch_cli.planners import Decision, Planner, register_planner


@register_planner("u_first_candidate")
class FirstCandidate(Planner):
    """Always the first frontier candidate."""

    task = "doors"

    def choose(self, ctx, cands):
        return Decision(int(cands.rows[0]), int(cands.cols[0])) if len(cands) else None
'''


def test_a_users_planner_file_runs_on_the_bench_and_verifies_without_it(tmp_path):
    f = tmp_path / "mine.py"
    f.write_text(USER_PLANNER)
    res = runner.invoke(app, ["bench", "run", "doors-v1", "--planner", "u_first_candidate", "--planner-file", str(f),
                              "--limit", "3", "--workers", "1", "--out", str(tmp_path / "mine")])
    assert res.exit_code == 0, res.stderr
    assert "u_first_candidate" in res.stdout
    f.unlink()  # the planner is gone: its runs still verify from their decisions
    res = runner.invoke(app, ["verify", str(tmp_path / "mine"), "--workers", "1"])
    assert res.exit_code == 0 and "3 of 3 runs replayed" in res.stdout


def test_the_classic_suite_runs_the_thesis_scenario_as_semsearch_run_does(tmp_path):
    res = api.bench_run("doors-classic-v1", ["greedy"], tmp_path / "b", options=BatchOptions(workers=1), limit=1)
    direct = api.run("normal", BatchOptions(seeds=10, goals=[54], planners=["greedy"], out=tmp_path / "r", workers=1), plots=False)
    cols = ["goal", "episode", "seed", "start_x", "start_y", "start_heading", "outcome", "distance_m", "steps", "shortest_m"]
    assert set(res.runs["floor"]) == {"normal"} and len(res.runs) == 10  # the first floor's first episode, 10 repeats
    assert (res.runs[cols].reset_index(drop=True) == direct.runs[cols].reset_index(drop=True)).all().all()


# -- predictability and the board ------------------------------------------------------------------

def test_predictability_of_walls_numbered_steadily_with_one_parity_each_is_one():
    xs = [0.0, 3.0, 6.0, 9.0, 12.0] * 2
    ys = [0.0] * 5 + [4.0] * 5
    facing = [90.0] * 5 + [-90.0] * 5
    labels = [1, 3, 5, 7, 9, 2, 4, 6, 8, 10]
    p = predictability(labels, xs, ys, facing, "t")
    assert (p.order, p.parity, p.walls, p.signs) == (1.0, 1.0, 2, 10)


def test_a_loop_numbered_wall_is_ordered_without_parity():
    xs = [0.0, 3.0, 6.0, 9.0, 12.0, 15.0] * 2
    ys = [0.0] * 6 + [4.0] * 6
    facing = [90.0] * 6 + [-90.0] * 6
    labels = [201, 202, 203, 204, 205, 206, 212, 211, 210, 209, 208, 207]
    p = predictability(labels, xs, ys, facing, "t")
    assert p.order == 1.0 and p.parity < 0.0  # half of each wall odd: less parity than a shuffle gives


def test_a_shuffled_floors_predictability_is_near_zero():
    sp = bench.open_split("doors-v1")
    values = [f.recipe["predictability"]["value"] for f in sp.floors if f.recipe["numbering"] == "random"]
    assert values and all(abs(v) < 0.2 for v in values)


CHROMIUM = next((p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None)
PROBE = """<script>
window.addEventListener("load", () => {
  const t = document.querySelector("table");
  const k = [...t.rows[0].cells].findIndex(h => h.innerText.trim() === "SPL");
  const col = () => [...t.rows].slice(1).map(r => parseFloat(r.cells[k].innerText));
  const before = col();
  t.rows[0].cells[k].click();
  const up = col();
  t.rows[0].cells[k].click();
  const down = col();
  document.body.setAttribute("data-probe", JSON.stringify({before, up, down,
    headings: [...document.querySelectorAll("h2")].map(h => h.innerText),
    images: document.images.length, broken: [...document.images].filter(i => !i.naturalWidth).length}));
});</script>"""


@pytest.mark.skipif(CHROMIUM is None and not os.environ.get("CI"),
                    reason="no chromium on PATH (.ci/run installs it from Debian's packages, and there it must run)")
def test_the_board_opens_in_a_browser_and_sorts_by_a_column(tmp_path):
    folders = [_run(tmp_path, p, limit=6, numbering=n).out for p, n in
               (("nsos[alpha=0.9]", "true"), ("nsos[alpha=0.9]", "shuffled"), ("greedy", "true"))]
    api.verify(folders[0], workers=1)
    files = api.bench_board(folders, tmp_path / "site")
    md = (tmp_path / "site" / "board.md").read_text()
    assert "| nsos[alpha=0.9] | 6 of 800 | 6 |" in md and "verified" in md and "not verified" in md
    assert "semantic gain" in md and "(n=6)" in md
    page = tmp_path / "probe.html"
    page.write_text((tmp_path / "site" / "index.html").read_text().replace("</body>", PROBE + "</body>"))
    res = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--window-size=1100,1200",
                          "--virtual-time-budget=10000", "--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=120)
    found = re.search(r'data-probe="([^"]*)"', res.stdout)
    assert found, res.stderr[-2000:]
    probe = json.loads(html_lib.unescape(found.group(1)))
    assert probe["headings"] == [f"doors-v1 val, engine {ENGINE}"] and probe["images"] >= 1 and probe["broken"] == 0
    assert probe["up"] == sorted(probe["before"]) and probe["down"] == sorted(probe["before"], reverse=True)
    assert len(files) >= 2


# -- indirect-v1 ------------------------------------------------------------------------------------

def test_indirect_v1_val_holds_table_3s_rooms_and_starts():
    sp = bench.open_split("indirect-v1")
    eps = pd.read_csv(sp.floors[0].scenario.parent / "episodes.csv")
    assert len(eps) == 1400 and eps.groupby(["goal", "room"]).size().eq(10).all() and eps["room"].nunique() == 20
    frozen = Loaded.load(sp.floors[0].scenario).task
    config = Loaded.load(scenario_file("indirect")).task
    for a, b in zip(frozen.episodes[::350], config.episodes[::350]):  # the same starts, and the same searches from them
        assert a.content == b.content
        ra, rb = frozen.run(Variant("ISCG-PN-SM", ()), a, 0), config.run(Variant("ISCG-PN-SM", ()), b, 0)
        assert (ra.outcome, ra.distance_m, ra.steps, ra.time_s) == (rb.outcome, rb.distance_m, rb.steps, rb.time_s)


@pytest.mark.parametrize("planner", sorted(n for n, c in PLANNERS.items() if c.task == "indirect"))
def test_every_indirect_method_verifies_exactly_on_a_slice(tmp_path, planner):
    res = _run(tmp_path, planner, limit=2, suite="indirect-v1")
    v = api.verify(res.out, workers=1).verdict
    assert (v.runs, v.verified, v.failed) == (2, 2, [])


def test_loop_numbers_run_on_past_99_doors_and_skip_leaves_that_share_of_the_range(tmp_path):
    p = generate_building("grid", "loop", 3, tmp_path / "g", spacing=2.5)
    nums = sorted(pd.read_csv(p.parent / "doors.csv")["number"])
    assert nums[0] == 201 and len(nums) <= max(nums) - 200 < len(nums) + 20 and len(set(nums)) == len(nums)  # 299, 300, ... (no 2100)
    q = generate_building("grid", "loop", 3, tmp_path / "s", spacing=2.5, skip=0.6)
    kept = sorted(pd.read_csv(q.parent / "doors.csv")["number"])
    gap = 1 - len(kept) / (kept[-1] - kept[0] + 1)
    assert abs(gap - 0.6) < 0.01 and kept[0] == nums[0] and kept[-1] == nums[-1]


def test_the_uis_budget_is_the_least_time_at_which_uis_reaches_the_papers_rate():
    # 100 searches at 1 m that find the target at 1, 2, ..., 90 s and 10 that never do
    t = pd.DataFrame({"method": "UIS", "scale": 1.0, "success": [1] * 90 + [0] * 10,
                      "time_s": [float(k) for k in range(1, 91)] + [300.0] * 10})
    b = uis_budgets(t)
    assert b[1.0] == 28.0  # the paper's UIS at 1 m: 28%, reached at the 28th search's time
    assert np.isnan(b[2.5]) or b[2.5] == 65.0  # no searches at 2.5 m here: nan
    assert at_budget(t, b)["success"].sum() == 28
    assert at_budget(t, 60.0)["success"].sum() == 60


# -- real floors, fetched by their SHA-256 -------------------------------------------------------------

@pytest.fixture
def mirror(tmp_path):
    """An HTTP server on loopback laid out as the track's sources' URLs, holding the files of
    ../shared (the authors' three maps and one KTH floor): what `bench fetch --mirror` downloads."""
    www = tmp_path / "www"
    for fl in bench.real.read_sources("doors-real-v1")["floors"]:
        for e in fl["files"].values():
            local = next(iter(sorted(REF.rglob(e["name"]))), None)
            if local is not None:
                dest = www / urllib.parse.urlparse(e["url"]).path.lstrip("/")
                dest.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(local, dest)
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(www))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}", www
    server.shutdown()


@pytest.mark.skipif(not REF.is_dir(), reason=f"the authors' reference maps are not at {REF} (../shared absent)")
def test_the_real_track_is_fetched_over_http_checked_and_runs(tmp_path, monkeypatch, mirror):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    url, _ = mirror
    with pytest.raises(api.ScenarioError, match="--partial"):  # the KTH floors that ../shared lacks
        api.bench_fetch("doors-real-v1", mirror=url)
    sp, missing = api.bench_fetch("doors-real-v1", mirror=url, partial=True)
    ids = [f.id for f in sp.floors]
    assert ids[:3] == ["normal", "inverse", "hotel"] and "kth-A0043016-0510035517_A_40_1_105" in ids and len(ids) == 4
    assert missing and not sp.official  # a part of the track: never official
    sources = {fl["id"]: fl for fl in bench.real.read_sources("doors-real-v1")["floors"]}
    assert all(f.recipe["hash"] == sources[f.id]["hash"] for f in sp.floors)  # each floor is the one the track names
    res = api.bench_run("doors-real-v1", ["nsos[alpha=0.9]"], tmp_path / "out", options=BatchOptions(workers=1), limit=2)
    assert set(res.runs["floor"]) == {"normal"}
    assert api.verify(res.out, workers=1).verdict.verified == 2


@pytest.mark.skipif(not REF.is_dir(), reason=f"the authors' reference maps are not at {REF} (../shared absent)")
def test_a_source_file_of_another_version_is_refused_by_its_sha(tmp_path, monkeypatch, mirror):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    url, www = mirror
    doors = next(www.rglob("hotel2.doors"))
    doors.write_text(doors.read_text().replace("148", "149", 1))
    _, missing = api.bench_fetch("doors-real-v1", mirror=url, partial=True)
    assert any(m.startswith("hotel: hotel2.doors: its SHA-256 is") for m in missing)


def test_a_track_not_fetched_says_how_to_fetch_it(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "empty"))
    res = runner.invoke(app, ["bench", "run", "doors-real-v1", "--planner", "greedy", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "semsearch bench fetch doors-real-v1" in res.stderr


# -- objects-v1 ---------------------------------------------------------------------------------------

def test_objects_v1_val_is_the_thesis_office_and_runs_as_semsearch_run_does(tmp_path):
    res = api.bench_run("objects-v1", ["lsos"], tmp_path / "b", options=BatchOptions(workers=1), limit=1)
    direct = api.run("office", BatchOptions(goals=["Static.mug@12"], planners=["lsos"], out=tmp_path / "r", workers=1), plots=False)
    cols = ["goal", "episode", "seed", "start_x", "start_y", "start_heading", "outcome", "distance_m", "steps", "shortest_m"]
    assert len(res.runs) == 10 and set(res.runs["goal"]) == {"Static.mug@12"}
    assert (res.runs[cols].reset_index(drop=True) == direct.runs[cols].reset_index(drop=True)).all().all()


@pytest.mark.parametrize("planner", sorted(n for n, c in PLANNERS.items() if c.task == "objects"))
def test_every_object_planner_verifies_exactly_on_a_slice(tmp_path, planner):
    res = _run(tmp_path, planner, limit=2, suite="objects-v1")  # 2 episodes x 10 repeats
    v = api.verify(res.out, workers=1).verdict
    assert (v.runs, v.verified, v.failed) == (20, 20, [])


def test_the_objects_test_split_is_drawn_offices(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))
    salt = tmp_path / "salt.txt"
    salt.write_text("a test salt for the offices, not the project's")
    sp = bench.open_split("objects-v1", "test", salt)
    assert [f.id for f in sp.floors] == [f"o{i:03d}" for i in range(8)] and not sp.official
    shortest = pd.concat([pd.read_csv(f.scenario.parent / "episodes.csv") for f in sp.floors])["shortest_m"]
    assert len(shortest) == 8 * 13 and (shortest > 3.0).all()  # the mug never beside the start


# -- the board is honest about what it shows --------------------------------------------------------

def test_a_limit_run_is_partial_in_bench_json_and_on_the_board_never_official(tmp_path):
    res = _run(tmp_path, "greedy", limit=3)
    meta = json.loads((res.out / "bench.json").read_text())
    assert res.partial and (meta["partial"], meta["limit"], meta["floors"]["f000"]["episodes"]) == (True, 3, 20)
    out = runner.invoke(app, ["bench", "board", str(res.out), "--out", str(tmp_path / "site")])
    assert out.exit_code == 0, out.output
    md = (tmp_path / "site" / "board.md").read_text()
    assert "| greedy | 3 of 800 | 3 |" in md and "| no (partial: 3 of 800 episodes, 3 of 800 runs) |" in md
    assert "the split: 800 episodes (each planner's own count in its row)" in md
    assert "the published hash, but partial" in md and "| yes |" not in md and "official (the published hash)" not in md
    # the same rows, as a folder whose split were these 3 episodes: complete, hence official
    meta["floors"] = {"f000": {**meta["floors"]["f000"], "episodes": 3}}
    (res.out / "bench.json").write_text(json.dumps(meta))
    api.bench_board([res.out], tmp_path / "site2")
    md = (tmp_path / "site2" / "board.md").read_text()
    assert "| greedy | 3 of 3 | 3 |" in md and md.rstrip().endswith("| yes |") and "official (the published hash)" in md


def test_each_planner_says_its_own_episode_count(tmp_path):
    a = _run(tmp_path, "greedy", limit=3).out
    b = _run(tmp_path, "bvp", limit=1).out
    api.bench_board([a, b], tmp_path / "site")
    md = (tmp_path / "site" / "board.md").read_text()
    assert "| greedy | 3 of 800 | 3 |" in md and "| bvp | 1 of 800 | 1 |" in md


def test_a_planner_none_of_whose_runs_could_run_has_a_row_saying_so_and_no_statistic(tmp_path):
    res = _run(tmp_path, "greedy", limit=1)
    f = res.out / "f000" / "runs.csv"
    rows = pd.read_csv(f, dtype=str, keep_default_na=False)
    rows["outcome"], rows["message"] = "error", "unavailable: the model's endpoint did not answer"
    rows.to_csv(f, index=False)  # as a language model's run that could not run is recorded
    api.bench_board([res.out], tmp_path / "site")
    md = (tmp_path / "site" / "board.md").read_text()
    assert "| greedy | 0 | 0 |" in md and "1 run(s) unavailable (left out; the same bench run runs them again)" in md
    assert "no (no run of it could run)" in md and "official (the published hash)" not in md


def test_a_planner_file_stands_beside_built_in_planners(tmp_path):
    f = tmp_path / "mine.py"
    f.write_text(USER_PLANNER.replace("u_first_candidate", "u_beside"))  # a name registers once per process
    res = runner.invoke(app, ["bench", "run", "doors-v1", "--planner-file", str(f), "--planner", "u_beside",
                              "--planner", "greedy", "--limit", "2", "--workers", "1", "--out", str(tmp_path / "both")])
    assert res.exit_code == 0, res.output
    runs = pd.read_csv(tmp_path / "both" / "f000" / "runs.csv")
    assert sorted(runs["planner"].unique()) == ["greedy", "u_beside"] and len(runs) == 4
    res = runner.invoke(app, ["bench", "run", "doors-v1", "--planner-file", str(f), "--planner", "u_besid",
                              "--limit", "1", "--workers", "1", "--out", str(tmp_path / "typo")])
    assert res.exit_code == 2 and "registers u_beside, not 'u_besid'" in " ".join(res.output.split())
    # semsearch run: a scenario's own planner file beside built-in planners, one of them chosen with --planner
    api.init("demo", tmp_path / "demo")
    src = tmp_path / "demo" / "demo.yaml"
    doc = yaml.safe_load(src.read_text())
    doc["planners"] = [{"name": "greedy"}, {"name": "u_beside", "module": str(f)}]
    doc["goals"], doc["experiment"]["seeds"] = doc["goals"][:1], 1
    sc = tmp_path / "demo" / "demo_mine.yaml"
    sc.write_text(yaml.safe_dump(doc))
    for chosen in (["greedy"], ["u_beside"], ["greedy", "u_beside"]):
        out = tmp_path / ("run-" + "-".join(chosen))
        res = runner.invoke(app, ["run", str(sc), "--out", str(out), "--workers", "1",
                                  *[a for c in chosen for a in ("--planner", c)]])
        assert res.exit_code == 0, res.output
        assert sorted(pd.read_csv(out / "runs.csv")["planner"].unique()) == chosen


def test_a_mistyped_numbering_is_named_with_the_nearest(tmp_path):
    res = runner.invoke(app, ["bench", "run", "doors-v1", "--planner", "greedy", "--numbering", "shufled",
                              "--out", str(tmp_path / "x")])
    assert res.exit_code == 2
    assert "unknown numbering 'shufled' (did you mean 'shuffled'?); valid: true, shuffled, parity-flipped, reversed" \
        in " ".join(res.output.split())


def test_a_gain_within_float_noise_is_shown_as_zero(tmp_path, monkeypatch):
    units = [f"f{k}/0" for k in range(4)]
    a = pd.DataFrame({"unit": units, "spl": [0.3, 0.5, 0.25, 0.7]})
    b = a.assign(spl=a["spl"] - 2.8e-18 * np.array([1, 0, 1, 1]) - np.array([0, 5.6e-17, 0, 0]))
    assert paired_diff(a, b) == (0.0, 0.0, 0.0, 4)
    assert paired_diff(a, a.assign(spl=a["spl"] - 0.01))[0] == pytest.approx(0.01)  # a real gain stays
    seen = []
    monkeypatch.setattr(figures, "_save", lambda fig, out, formats: seen.append(fig) or [])
    floors = pd.DataFrame({"planner": "nsos", "floor": ["a", "b", "c"], "convention": "loop",
                           "predictability": [0.2, 0.5, 0.9], "gain": [2.8e-18, 2.8e-18, -1e-17]})
    figures.plot_gain_vs_predictability(floors, tmp_path / "g.png")
    ax = seen[0].axes[0]
    seen[0].canvas.draw()
    assert ax.yaxis.get_offset_text().get_text() == ""  # no 1e-18 over the axis
    assert [float(y) for y in ax.collections[0].get_offsets()[:, 1]] == [0.0, 0.0, 0.0]
    assert "gain +0.000 on every one of 3 floors" in ax.get_title()  # under the title, over no point
    plt.close(seen[0])


# -- a falsified bench folder, folders that share runs, damaged files (issue 52) --------------------

@pytest.fixture(scope="module")
def bench_two(tmp_path_factory):
    """A real bench folder (doors-v1 val, greedy, --limit 2; tests/hostile_bench_surface.make_bench)."""
    from tests.hostile_bench_surface import make_bench
    return make_bench(tmp_path_factory.mktemp("bench_two"))


def _copy(src, tmp_path, name="b"):
    shutil.copytree(src, tmp_path / name)
    return tmp_path / name


def test_the_board_refuses_the_same_runs_twice_naming_both_folders(bench_two, tmp_path):
    b = _copy(bench_two, tmp_path)
    c = _copy(bench_two, tmp_path, "copy")
    for folders, says in (([b, b], [str(b), "given again"]), ([b, c], [str(b), str(c), "counts each run once"])):
        res = runner.invoke(app, ["bench", "board", *map(str, folders), "--out", str(tmp_path / "site")])
        text = " ".join(res.output.split())
        assert res.exit_code == 2 and "Traceback" not in text and all(s in text for s in says), text
    assert not (tmp_path / "site" / "board.md").exists()
    assert runner.invoke(app, ["bench", "board", str(b), "--out", str(tmp_path / "site")]).exit_code == 0


@pytest.mark.parametrize("name, text, says", [
    ("bench.json without its hash", lambda m: json.dumps({k: v for k, v in m.items() if k != "hash"}), "bench.json, field 'hash'"),
    ("bench.json a list", lambda m: "[1]", "a JSON list, not an object"),
    ("bench.json not JSON", lambda m: "{", "not a bench.json semsearch wrote"),
    ("verify.json a list", "[1]", "verify.json"),
    ("verify.json not JSON", "{", "verify.json"),
])
def test_a_malformed_bench_or_verify_json_is_one_error_naming_it(bench_two, tmp_path, name, text, says):
    b = _copy(bench_two, tmp_path)
    if name.startswith("bench.json"):
        (b / "bench.json").write_text(text(json.loads((b / "bench.json").read_text())))
    else:
        (b / "verify.json").write_text(text)
    res = runner.invoke(app, ["bench", "board", str(b), "--out", str(tmp_path / "site")])
    assert res.exception is None or isinstance(res.exception, SystemExit)
    assert res.exit_code == 2 and says in " ".join(res.output.split()) and str(b) in res.output, res.output


def test_verify_of_a_bench_folder_without_its_split_or_its_floor(bench_two, tmp_path):
    b = _copy(bench_two, tmp_path)
    meta = json.loads((b / "bench.json").read_text())
    (b / "bench.json").write_text(json.dumps({k: v for k, v in meta.items() if k != "split"}))
    res = runner.invoke(app, ["verify", str(b), "--workers", "1"])
    assert res.exit_code == 2 and "bench.json, field 'split'" in " ".join(res.output.split()), res.output
    (b / "bench.json").write_text(json.dumps(meta))
    shutil.rmtree(b / "f000")  # the floor that holds the rows, taken away
    res = runner.invoke(app, ["verify", str(b), "--workers", "1"])
    assert res.exit_code == 1 and "floor f000: its rows: are gone: bench.json says floor f000 holds 2 run(s)" in \
        " ".join(res.output.split()), res.output


def test_a_bench_folder_and_a_plain_folder_never_share_an_out(bench_two, tmp_path):
    from tests.hostile_bench_surface import make_results
    plain, scenario = make_results(tmp_path / "plain")
    res = runner.invoke(app, ["bench", "run", "doors-v1", "--planner", "greedy", "--limit", "1", "--workers", "1",
                              "--out", str(plain)])
    assert res.exit_code == 2 and "never share a folder" in " ".join(res.output.split()), res.output
    assert not (plain / "bench.json").exists() and not (plain / "f000").exists()
    b = _copy(bench_two, tmp_path)
    for out in (b, b / "f000"):
        res = runner.invoke(app, ["run", str(scenario), "--workers", "1", "--out", str(out)])
        assert res.exit_code == 2 and "never share a folder" in " ".join(res.output.split()), res.output
    assert not (b / "runs.csv").exists()
    assert api.verify(b, workers=1).verdict.failed == []  # the bench folder as it was


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_salt_file_that_is_a_fifo_a_folder_or_huge_is_refused_without_reading_it(tmp_path):
    import signal
    fifo = tmp_path / "salt.fifo"
    os.mkfifo(fifo)
    huge = tmp_path / "salt.huge"
    huge.write_text("s" * 100_000)

    def hang(signum, frame):
        raise TimeoutError("the salt file blocked")
    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(20)
    try:
        for f, says in ((fifo, "is a FIFO, not a regular file"), (tmp_path, "is a folder"), (huge, "100,000 bytes")):
            res = runner.invoke(app, ["bench", "hash", "doors-v1", "--split", "test", "--salt-file", str(f)])
            assert res.exit_code == 2 and says in " ".join(res.output.split()), res.output
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def test_the_suite_hash_is_kept_once_and_a_verdict_goes_stale_with_bench_json(bench_two, tmp_path):
    """verify.json keeps no copy of the suite hash: it digests bench.json (where the folder keeps its
    hash) with the rows, so an edit of either makes the verdict stale; a verify.json written before
    0.4.0 (the hash copied in, the rows digested alone) still reads."""
    b = _copy(bench_two, tmp_path)
    assert api.verify(b, workers=1).verdict.verified == 2
    v = json.loads((b / "verify.json").read_text())
    assert "hash" not in v and v["rows"] == bench.board.rows_digest(b)
    meta = json.loads((b / "bench.json").read_text())
    assert bench.board.verdict_of(b, meta["hash"]) == "verified"
    (b / "bench.json").write_text(json.dumps(meta, indent=2))  # the same hash, another bench.json
    assert bench.board.verdict_of(b, meta["hash"]) == "changed since verified"
    old = {"hash": meta["hash"], **{k: v[k] for k in ("runs", "verified", "failed", "unfinished")},
           "rows": bench.board.rows_digest(b, with_meta=False)}
    (b / "verify.json").write_text(json.dumps(old))
    assert bench.board.verdict_of(b, meta["hash"]) == "verified"
    assert bench.board.verdict_of(b, "0" * 64) == "changed since verified"
