"""The simulator engine is part of every result (issue 54): each row, decisions record, meta.json,
transcript and bag names it; rows of another engine are read, reported and boarded as before, never
resumed or mixed with this engine's, never paired with them on a board, and what replays a run
(verify, export, a bag's replay) refuses them in one line naming the release that replays them."""

import json
import shutil

import pandas as pd
import pytest
from typer.testing import CliRunner

from semsearch_cli import engine
from semsearch_cli.cli import app
from semsearch_cli.engine import ENGINE, engine_of, refusal, release
from semsearch_cli.runner.store import read_runs

OTHER = 2 if ENGINE == 1 else 1  # an engine this release does not run


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    from tests.hostile_bench_surface import make_results
    return make_results(tmp_path_factory.mktemp("engine"))


def _as_engine(folder, n):
    """Rewrite a results folder's rows and records as engine ``n`` made them."""
    for f in folder.rglob("runs.csv"):
        rows = pd.read_csv(f, dtype=str, keep_default_na=False)
        rows["engine"] = str(n)
        rows.to_csv(f, index=False)
    for f in folder.rglob("decisions/*.json"):
        d = json.loads(f.read_text())
        d["engine"] = n
        f.write_text(json.dumps(d))


def _one(text):
    return " ".join(text.split())


def test_every_result_names_the_engine_that_made_it(results):
    folder, _ = results
    rows = pd.read_csv(folder / "runs.csv")
    assert set(rows["engine"]) == {ENGINE}
    assert all(json.loads(f.read_text())["engine"] == ENGINE for f in (folder / "decisions").glob("*.json"))
    assert json.loads((folder / "meta.json").read_text())["semsearch"]["engine"] == ENGINE
    res = CliRunner().invoke(app, ["--version"])
    assert f"(engine {ENGINE}, code " in res.output


def test_rows_written_before_the_engine_column_are_engine_1(results, tmp_path):
    folder, _ = results
    rows = pd.read_csv(folder / "runs.csv", dtype=str, keep_default_na=False).drop(columns="engine")
    rows.to_csv(tmp_path / "runs.csv", index=False)
    assert set(read_runs(tmp_path / "runs.csv")["engine"]) == {1}
    for bad in ("0", "1.5", "two"):
        rows.assign(engine=bad).to_csv(tmp_path / "runs.csv", index=False)
        with pytest.raises(Exception, match="engine"):
            read_runs(tmp_path / "runs.csv")


def test_another_engines_folder_is_refused_by_what_replays_it_and_reported_as_before(results, tmp_path):
    folder, scenario = results
    other = tmp_path / "other"
    shutil.copytree(folder, other)
    _as_engine(other, OTHER)
    for args in (["verify", str(other)], ["export", str(other), "--out", str(tmp_path / "bags")]):
        res = CliRunner().invoke(app, args)
        text = _one(res.output)
        assert res.exit_code == 2 and f"made by simulator engine {OTHER}" in text and release(OTHER) in text, res.output
        assert "Traceback" not in res.output
    assert not (tmp_path / "bags").exists()
    # resuming it with this engine would mix two engines' rows: refused, naming both, nothing written
    before = (other / "runs.csv").read_bytes()
    res = CliRunner().invoke(app, ["run", str(scenario), "--out", str(other), "--workers", "1"])
    assert res.exit_code == 2 and f"engine {OTHER}" in _one(res.output) and f"runs engine {ENGINE}" in _one(res.output), res.output
    assert (other / "runs.csv").read_bytes() == before
    # read and reported as before
    res = CliRunner().invoke(app, ["report", str(other)])
    assert res.exit_code == 0, res.output


def test_a_record_of_another_engine_does_not_replay(results, tmp_path):
    from semsearch_cli.runner import Loaded
    from semsearch_cli.runner.verify import replay_run
    folder, scenario = results
    f = sorted((folder / "decisions").glob("*.json"))[0]
    d = json.loads(f.read_text())
    d["engine"] = OTHER
    (tmp_path / f.name).write_text(json.dumps(d))
    L = Loaded.load(scenario)
    row = pd.read_csv(folder / "runs.csv", dtype=str, keep_default_na=False).iloc[0].to_dict()
    row["decisions_sha256"] = ""
    eps = {(str(e.goal), e.index): e for e in L.task.episodes}
    why = replay_run(L.task, tmp_path / f.name, d["planner"], d["goal"], d["episode"], d["seed"], [row], eps)
    assert f"made by simulator engine {OTHER}" in why


def test_the_release_that_replays_an_engine_is_named(monkeypatch):
    monkeypatch.setattr(engine, "ENGINE", 2)
    assert "pip install 'semsearch==0.2.*'" in refusal(1, "results")
    assert refusal(2, "results") is None
    assert "newer" in refusal(3, "results")
    assert engine_of("") == engine_of(None) == engine_of(float("nan")) == 1 and engine_of("2") == 2 and engine_of(2.0) == 2
    for bad in ("0", "x", "1.5", True, -1, "²"):
        with pytest.raises(ValueError):
            engine_of(bad)


def test_a_board_never_pairs_rows_of_two_engines(tmp_path):
    from tests.hostile_bench_surface import make_bench
    first = make_bench(tmp_path)
    second = tmp_path / "second"
    shutil.copytree(first, second)
    _as_engine(second, OTHER)
    res = CliRunner().invoke(app, ["bench", "board", str(first), str(second), "--out", str(tmp_path / "board")])
    assert res.exit_code == 0, res.output  # the same runs, of two engines: not one run twice
    page = (tmp_path / "board" / "board.md").read_text()
    heads = [line for line in page.splitlines() if line.startswith("## doors-v1 val")]
    assert sorted(heads) == sorted([f"## doors-v1 val, engine {ENGINE}", f"## doors-v1 val, engine {OTHER}"]), heads
    assert "never paired or pooled" in page
    res = CliRunner().invoke(app, ["verify", str(second)])
    assert res.exit_code == 2 and f"made by simulator engine {OTHER}" in _one(res.output), res.output


def test_a_transcript_of_another_engine_does_not_replay(tmp_path):
    from semsearch_cli.errors import PlannerError
    from semsearch_cli.planners.llm import transcript
    head = transcript.header("doors", {"scenario": "demo", "goal": "452", "episode": 0, "seed": 0, "stage": ""}, {}, "x")
    assert head["engine"] == ENGINE
    f = tmp_path / "t.jsonl"
    f.write_text(json.dumps(head) + "\n")
    assert transcript.read(f)[0]["engine"] == ENGINE
    f.write_text(json.dumps({**head, "engine": OTHER}) + "\n")
    with pytest.raises(PlannerError, match=f"made by simulator engine {OTHER}"):
        transcript.read(f)
    del head["engine"]  # written before engines were recorded: engine 1
    f.write_text(json.dumps(head) + "\n")
    if ENGINE == 1:
        assert transcript.read(f)
