"""The llm planner against a real OpenAI-compatible server on loopback (tests/llm_server.py): the
client, its retries and timeouts, the parsing of replies, the counts on the rows, transcripts that
replay offline, and the key kept out of every file."""

from __future__ import annotations

import json
import os
import random
import re
import shutil
import socket
import subprocess
import sys
import uuid
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

pytest.importorskip("openai")

from semsearch_cli import api  # noqa: E402
from semsearch_cli.cli import app  # noqa: E402
from semsearch_cli.errors import ScenarioError  # noqa: E402
from semsearch_cli.planners.llm import LlmParams, LlmPlanner, load_prompt  # noqa: E402
from semsearch_cli.planners.llm.core import by_expected_cost  # noqa: E402
from semsearch_cli.planners.llm.replies import parse_number, parse_probabilities  # noqa: E402
from semsearch_cli.runner import BatchOptions, Loaded  # noqa: E402
from semsearch_cli.tasks.decisions import Seat  # noqa: E402

from .llm_server import Answer, ChatServer, decision_text, first_target  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAME = ["goal", "episode", "seed", "outcome", "distance_m", "steps", "decisions", "spl"]
COSTS = ["llm_calls", "tokens_in", "tokens_out", "invalid_replies", "fallbacks", "llm_s"]


@pytest.fixture(autouse=True)
def own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))  # the request slots' lock files


def scenario(tmp_path: Path, planners: list, name: str = "demo", seeds: int = 2, goals=None) -> Path:
    """A copy of a shipped door scenario (demo) or a generated floor (name 'floor') with these planners."""
    if name == "floor":
        src = api.generate_building("hall", "blocks", 3, tmp_path / "floor")
    else:
        api.init(name, tmp_path / name, force=True)
        src = tmp_path / name / f"{name}.yaml"
    d = yaml.safe_load(src.read_text())
    d["planners"] = planners
    d["experiment"]["seeds"] = seeds
    d["goals"] = goals or d["goals"][:2]
    out = src.with_name(f"{src.stem}_llm.yaml")
    out.write_text(yaml.safe_dump(d))
    return out


def llm(srv, **kw) -> dict:
    return {"name": "llm", "base_url": srv.base_url, "model": "scripted", **kw}


def rows_of(folder: Path, prefix: str) -> pd.DataFrame:
    df = pd.read_csv(folder / "runs.csv")
    return df[df["planner"].str.startswith(prefix)].sort_values(["goal", "episode", "seed"]).reset_index(drop=True)


# ---- the harness adds nothing of its own to a decision -------------------------------------------
@pytest.mark.parametrize("name", ["demo", "floor"])
def test_a_nearest_target_model_makes_greedys_runs(tmp_path, name):
    with ChatServer(first_target) as srv:
        sc = scenario(tmp_path, [{"name": "greedy"}, llm(srv)], name)
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
    greedy, model = rows_of(tmp_path / "out", "greedy"), rows_of(tmp_path / "out", "llm")
    assert len(greedy) == len(model) >= 4
    pd.testing.assert_frame_equal(greedy[SAME], model[SAME])
    assert (model["llm_calls"] >= model["decisions"]).all() and model["llm_calls"].sum() == len(srv.requests)
    assert model["invalid_replies"].sum() == 0 and model["fallbacks"].sum() == 0
    assert model["tokens_in"].sum() == 100 * len(srv.requests) and model["tokens_out"].sum() == 3 * len(srv.requests)
    assert greedy[COSTS].isna().all().all()  # a planner that reports no cost leaves them empty


# ---- transcripts ---------------------------------------------------------------------------------
def flaky(request, n):
    """Every third reply prose (invalid), else the first target: re-asks appear in the transcript."""
    return Answer("I would rather look around first.") if n % 3 == 1 else first_target(request, n)


def test_a_replay_from_transcripts_gives_the_live_rows_with_no_server(tmp_path):
    with ChatServer(flaky) as srv:
        sc = scenario(tmp_path, [llm(srv, reasks=1)])
        api.run(sc, BatchOptions(out=tmp_path / "live", workers=2, transcripts=True, decisions=True), plots=False)
        label = rows_of(tmp_path / "live", "llm")["planner"].iloc[0]
    live = rows_of(tmp_path / "live", "llm")
    assert live["invalid_replies"].sum() > 0 and live["llm_calls"].sum() == len(srv.requests)
    files = sorted((tmp_path / "live" / "transcripts").glob("*.jsonl"))
    assert len(files) == len(live)
    lines = [json.loads(x) for x in files[0].read_text().splitlines()]
    head, calls = lines[0], [x for x in lines if x["type"] == "call"]
    assert head["format"] == "semsearch-transcript" and head["version"] == 1 and head["run"]["planner"] == label
    assert set(calls[0]) == {"type", "decision", "attempt", "observation", "messages", "reply", "error", "choice", "valid",
                             "reason", "tokens_in", "tokens_out", "latency_s", "model", "temperature", "seed", "reply_format"}
    assert calls[0]["model"] == "scripted-1" and decision_text(calls[0]["messages"]) == calls[0]["observation"]
    # the server is gone: a replay calls nothing
    rp = scenario(tmp_path, [{"name": "llm", "replay": str(tmp_path / "live")}])
    api.run(rp, BatchOptions(out=tmp_path / "replay", workers=1, transcripts=True), plots=False)
    again = rows_of(tmp_path / "replay", "llm")
    pd.testing.assert_frame_equal(live[SAME + COSTS], again[SAME + COSTS], check_dtype=False)
    # the replay's own transcripts are the live ones, line for line
    mine = sorted((tmp_path / "replay" / "transcripts").glob("*.jsonl"))
    assert [p.read_text().splitlines()[1:] for p in mine] == [p.read_text().splitlines()[1:] for p in files]
    # and semsearch verify replays the live runs from their decisions, without any model
    assert api.verify(tmp_path / "live").verdict.verified == len(live)


def test_a_replay_whose_run_diverges_names_the_run_and_the_step(tmp_path):
    with ChatServer(first_target) as srv:
        sc = scenario(tmp_path, [llm(srv)], seeds=1, goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "live", workers=1, transcripts=True), plots=False)
    f = next((tmp_path / "live" / "transcripts").glob("*.jsonl"))
    lines = [json.loads(x) for x in f.read_text().splitlines()]
    call = next(x for x in lines if x.get("decision") == 2)
    call["observation"] = call["observation"].replace("Goal: read", "Goal: find")
    f.write_text("".join(json.dumps(x) + "\n" for x in lines))
    rp = scenario(tmp_path, [{"name": "llm", "replay": str(tmp_path / "live")}], seeds=1, goals=[304])
    api.run(rp, BatchOptions(out=tmp_path / "replay", workers=1), plots=False)
    row = rows_of(tmp_path / "replay", "llm").iloc[0]
    assert row["outcome"] == "error" and row["llm_calls"] == 2  # what a failed run paid for is still counted
    assert "goal 304 episode 0 seed 0: decision 3: the observation differs from the transcript's (line 1:" in row["message"]
    # a replay that ends before its transcript does (a smaller budget) is named too
    d = yaml.safe_load(rp.read_text())
    d["experiment"]["max_distance"] = 3.0
    rp.write_text(yaml.safe_dump(d))
    call["observation"] = call["observation"].replace("Goal: find", "Goal: read")  # the transcript as it was
    f.write_text("".join(json.dumps(x) + "\n" for x in lines))
    api.run(rp, BatchOptions(out=tmp_path / "short", workers=1), plots=False)
    row = rows_of(tmp_path / "short", "llm").iloc[0]
    assert row["outcome"] == "error" and "the run ended after" in row["message"] and "the transcript holds" in row["message"]


def test_rows_of_another_prompt_are_not_reused(tmp_path):
    prompt = tmp_path / "mine.txt"
    prompt.write_text("=== system ===\nFind $label.\n=== user ===\n$observation\n")
    with ChatServer(first_target) as srv:
        sc = scenario(tmp_path, [llm(srv, prompt=str(prompt))], seeds=1, goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
        n = len(srv.requests)
        assert srv.requests[0]["messages"][0] == {"role": "system", "content": "Find 304."}
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
        assert len(srv.requests) == n  # done: resumed, nothing asked again
        prompt.write_text("=== system ===\nFind the sign $label.\n=== user ===\n$observation\n")
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
        assert len(srv.requests) > n and srv.requests[n]["messages"][0]["content"] == "Find the sign 304."


# ---- invalid replies are counted, never hidden ----------------------------------------------------
def first_decision(tmp_path):
    """A real decision of a demo run: (ctx, cands) at the run's first re-plan with candidates."""
    L = Loaded.load(scenario(tmp_path, [{"name": "greedy"}], seeds=1, goals=[304]))

    class Stop(Exception):
        pass

    class Capture(Seat):
        def decide(self, point):
            if len(point.choices) >= 2:
                self.point = point
                raise Stop()
            return point.ask()

    seat = Capture()
    with pytest.raises(Stop):
        L.task.run(L.task.variants()[0], L.task.episodes[0], 0, seat=seat)
    return seat.point.observation, seat.point.choices


KINDS = ["valid", "valid_bracket", "valid_answer", "empty", "none", "prose", "out_of_range", "negative", "huge", "unicode",
         "json", "http500", "http429", "http400", "not_json", "wrong_shape", "no_choices", "bytes", "deep_json", "digits",
         "newlines", "think_unclosed"]


def kind_of(n: int) -> str:
    """The fuzz kind of request n: one of KINDS, drawn; every 400th a server that hangs past the timeout."""
    return "hang" if n % 400 == 399 else random.Random(n).choice(KINDS)


def fuzz(request, n):
    kind = kind_of(n)
    prompt = decision_text(request["messages"])
    offered = re.findall(r"^\[(\d+)\]", prompt, re.M)
    first = offered[0]
    if "JSON object" in prompt and kind.startswith("valid"):  # an estimator's valid replies
        return Answer({"valid": f'{{"{first}": 0.7}}', "valid_bracket": f'```json\n{{"{first}": 1}}\n```',
                       "valid_answer": json.dumps({o: 0.1 for o in offered})}[kind])
    rng = random.Random(-n)
    return {"valid": Answer(first), "valid_bracket": Answer(f"[{first}]"), "valid_answer": Answer(f"Let me see.\nAnswer: {first}"),
            "empty": Answer(""), "none": Answer(None), "prose": Answer("The corridor to the north looks promising."),
            "out_of_range": Answer(str(len(offered) + 7)), "negative": Answer("-1"), "huge": Answer("7" * 200_000),
            "unicode": Answer("\u0663 \u2603 \ud83d\ude80".encode("utf-8", "surrogatepass").decode("utf-8", "replace")),
            "json": Answer('{"target": 0}'), "http500": Answer(status=500), "http429": Answer(status=429),
            "http400": Answer(status=400), "not_json": Answer(raw=b"{not json"), "wrong_shape": Answer(raw=b'{"foo": 1}'),
            "no_choices": Answer(raw=b'{"id": "x", "object": "chat.completion", "choices": []}'),
            "bytes": Answer("#" + bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400))).decode("utf-8", "replace")),
            "deep_json": Answer(raw=b'{"choices": ' + b"[" * 20_000 + b"]" * 20_000 + b"}"),
            "digits": Answer("9" * rng.choice([10, 4_400, 19_000])), "newlines": Answer("a" + "\n" * 19_000 + "a"),
            "think_unclosed": Answer("<think>" * 2_000 + first),
            "hang": Answer("0", delay=2.0)}[kind]


def test_ten_thousand_fuzzed_replies_give_no_traceback_and_every_one_is_counted(tmp_path):
    ctx, cands = first_decision(tmp_path)
    planners, decisions = [], 0
    with ChatServer(fuzz) as srv:
        for mode, upto in (("actor", 6_000), ("estimator", 10_000)):  # the first 6,000 replies to an actor, then an estimator
            p = LlmPlanner(LlmParams(base_url=srv.base_url, model="fuzz", mode=mode, retries=0, timeout_s=0.5, max_calls=10**6,
                                     unavailable_after=0))  # the counting measured, not the stop of a failing model
            p.start_run({"scenario": "demo", "planner": "llm", "goal": "304", "episode": 0, "seed": 0})
            planners.append(p)
            while len(srv.requests) < upto:
                dec = p.choose(ctx, cands)  # never raises
                decisions += 1
                assert dec is None or (int(dec.row), int(dec.col)) in set(zip(cands.rows.tolist(), cands.cols.tolist()))
    kinds = [kind_of(n) for n in range(len(srv.requests))]  # one client, no retries: request n is call n
    calls = [x for p in planners for x in p.transcript if x["type"] == "call"]
    falls = [x for p in planners for x in p.transcript if x["type"] == "fallback"]
    p = LlmPlanner(LlmParams(model="tally"))
    for q in planners:
        p.calls, p.invalid, p.fallbacks = p.calls + q.calls, p.invalid + q.invalid, p.fallbacks + q.fallbacks
    assert p.calls == len(srv.requests) == len(calls) >= 10_000
    # a fuzzed reply is never taken; a good one always is, unless a loaded machine made it late (then it is counted as such)
    assert not [c for c, k in zip(calls, kinds) if c["valid"] != k.startswith("valid") and c["reason"] != "no reply within timeout_s"]
    assert not [c for c, k in zip(calls, kinds) if c["valid"] and not k.startswith("valid")]
    valid = sum(c["valid"] for c in calls)
    assert p.invalid == len(srv.requests) - valid and valid >= sum(k.startswith("valid") for k in kinds) - 5
    assert p.fallbacks == len(falls) and p.fallbacks + valid == decisions  # each decision: one valid reply, or the fallback
    assert all(c["reason"] for c in calls if not c["valid"])
    reasons = {c["reason"] for c in calls if not c["valid"]}
    assert {"no reply within timeout_s", "HTTP 500 from the server", "HTTP 429 from the server", "the reply is empty",
            "the reply is too long (200,000 characters)"} <= reasons
    assert planners[1].transcript[-1].get("reason") != "" or planners[1].calls  # the estimator was fuzzed too
    print(f"fuzz: {p.calls} calls, {p.calls - p.invalid} valid, {p.invalid} invalid, {p.fallbacks} fallbacks over "
          f"{decisions} decisions; reasons: {len(reasons)}")
    print("\n".join(f"  {n:5d}  {r}" for r, n in sorted(Counter(c["reason"] for c in calls if not c["valid"]).items(),
                                                        key=lambda kv: -kv[1])))


def test_a_server_that_fails_then_answers_is_retried_with_backoff(tmp_path):
    ctx, cands = first_decision(tmp_path)
    with ChatServer(lambda r, n: Answer(status=429) if n < 2 else first_target(r, n)) as srv:
        p = LlmPlanner(LlmParams(base_url=srv.base_url, model="m", retries=2))
        p.choose(ctx, cands)
    assert len(srv.requests) == 3 and p.calls == 1 and p.invalid == 0
    assert p.transcript[-1]["latency_s"] > 0.5  # two waits: 0.5 s and 1 s, less jitter
    with ChatServer(lambda r, n: Answer("0", delay=1.0)) as srv:
        p = LlmPlanner(LlmParams(base_url=srv.base_url, model="m", retries=1, timeout_s=0.2, reasks=0))
        p.choose(ctx, cands)
    assert len(srv.requests) == 2 and p.calls == 1 and p.invalid == 1 and p.fallbacks == 1
    assert p.transcript[-2]["error"] == "no reply within timeout_s"


def test_a_run_whose_calls_are_spent_ends_as_budget(tmp_path):
    with ChatServer(first_target) as srv:
        sc = scenario(tmp_path, [llm(srv, max_calls=5)], seeds=1, goals=[452])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1, decisions=True), plots=False)
    row = rows_of(tmp_path / "out", "llm").iloc[0]
    assert (row["outcome"], row["cause"], row["llm_calls"]) == ("budget", "budget", 5)
    assert row["message"] == "the llm planner made max_calls = 5 calls"
    record = json.loads(next((tmp_path / "out" / "decisions").glob("*.json")).read_text())
    assert record["decisions"][-1] == "budget"  # where the budget ended the run: its replay ends there too
    v = api.verify(tmp_path / "out").verdict
    assert (v.verified, v.failed) == (1, [])


def test_the_key_is_sent_and_never_written(tmp_path, monkeypatch):
    secret = f"sk-test-{uuid.uuid4().hex}"
    monkeypatch.setenv("SEMSEARCH_TEST_KEY", secret)
    with ChatServer(flaky) as srv:
        sc = scenario(tmp_path, [llm(srv, api_key_env="SEMSEARCH_TEST_KEY")], seeds=1)
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1, transcripts=True, decisions=True, trace=True, frames=True))
        api.report([tmp_path / "out"], tmp_path / "report")
    assert set(srv.keys) == {f"Bearer {secret}"}
    costs = pd.read_csv(tmp_path / "report" / "tables" / "costs.csv")  # the report sums what the model cost
    assert costs["llm_calls"].tolist() == [len(srv.requests)] and costs["runs"].tolist() == [2]
    assert "What the planners' decisions cost" in (tmp_path / "report" / "report.md").read_text()
    written = [p for p in tmp_path.rglob("*") if p.is_file() and "cache" not in p.parts]
    assert len(written) > 10
    assert not [p for p in written if secret.encode() in p.read_bytes()]


# ---- the estimator -------------------------------------------------------------------------------
def test_the_estimator_chooses_by_expected_cost():
    d = np.array([1.0, 5.0, 9.0])  # mean 5: cost_i = d_i + (1 - p_i) (d_i + 5)
    every = [0, 1, 2]
    assert by_expected_cost({2: 1.0}, d, every) == 0  # 7, 15, 9
    assert by_expected_cost({1: 1.0}, d, every) == 1  # 7, 5, 23
    assert by_expected_cost({0: 0.0, 2: 1.0}, np.array([4.0, 5.0, 6.0]), every) == 2  # 13, 15, 6
    assert by_expected_cost({0: 2 / 3, 2: 2 / 3}, np.array([6.0, 9.0, 6.0]), every) == 0  # scaled to 1/2: a tie, the nearer
    # among the choices offered only (an object search leaves out the place just looked at): mean of 5 and 9 is 7
    assert by_expected_cost({}, d, [1, 2]) == 1  # 5 + 12, 9 + 16


def test_an_estimator_run_reads_json_probabilities(tmp_path):
    def estimate(request, n):
        k = len(re.findall(r"^\[(\d+)\]", decision_text(request["messages"]), re.M))
        return Answer("```json\n" + json.dumps({str(i): round(1 / (i + 1), 3) for i in range(k)}) + "\n```")

    with ChatServer(estimate) as srv:
        sc = scenario(tmp_path, [llm(srv, mode="estimator")], seeds=1, goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
        assert "JSON object" in decision_text(srv.requests[0]["messages"])
    row = rows_of(tmp_path / "out", "llm").iloc[0]
    assert row["outcome"] == "found" and row["invalid_replies"] == 0 and row["fallbacks"] == 0


# ---- replies, prompts, parameters -----------------------------------------------------------------
def test_replies_parse_strictly():
    r = range(5)
    assert [parse_number(x, r)[0] for x in ("3", " [3] ", "3.", '"3"', "Answer: 3", "I think 1.\n**Answer:** [3]",
                                          "<think>0 or 1?</think>3")] == [3] * 7
    assert parse_number("3 or 4", r) == (None, "the reply is not one number (answer with the number alone)")
    assert parse_number("7", r) == (None, "7 is not one of the choices offered")
    assert parse_number("\u0663", r)[0] is None  # an Arabic-Indic three is not a number of the choices
    assert parse_number("", r) == (None, "the reply is empty") == parse_number(None, r)
    t = range(3)
    assert parse_probabilities('{"0": 0.2, "2": 1}', t) == ({0: 0.2, 2: 1.0}, "")
    assert parse_probabilities('{"3": 0.2}', t)[1] == "'3' is not one of the choices offered (0-2)"
    assert parse_probabilities('{"1": 0.2}', {0, 2})[1] == "'1' is not one of the choices offered (0 or 2)"
    assert parse_probabilities('{"0": 1.5}', t)[1] == "the probability of target 0 is 1.5, not a number from 0 to 1"
    assert parse_probabilities("[0.2]", t)[1] == "the reply is JSON, but not an object mapping targets to probabilities"
    assert parse_probabilities("{}", t)[1] == "the object gives no target a probability"


def test_prompt_templates_are_checked_where_they_are_named(tmp_path):
    system, user, sha = load_prompt(None, "doors", "actor")
    assert user == "$observation" and "door sign" in system and len(sha) == 64
    bad = tmp_path / "bad.txt"
    bad.write_text("=== system ===\nFind $goal_label.\n=== user ===\n$observation\n")
    with pytest.raises(ScenarioError, match=r"no field \$goal_label in doors search; its fields: \$observation, \$goal"):
        load_prompt(str(bad), "doors", "actor")
    bad.write_text("=== system ===\nFind it.\n=== user ===\n$signs\n")  # a door search's field, in object search
    with pytest.raises(ScenarioError, match=r"no field \$signs in objects search; its fields: \$observation, \$goal, "
                       r"\$frame, \$pose, \$places, \$answer"):
        load_prompt(str(bad), "objects", "actor")
    bad.write_text("Find the door.\n")
    with pytest.raises(ScenarioError, match="a line '=== system ===' and, after it, a line '=== user ==='"):
        load_prompt(str(bad), "doors", "actor")


def test_a_scenario_without_a_model_is_refused_naming_the_field(tmp_path):
    sc = scenario(tmp_path, [{"name": "llm"}])
    res = CliRunner().invoke(app, ["validate", str(sc)])
    assert res.exit_code == 2 and "planners[0].model" in res.output and "name the model the server serves" in res.output
    sc = scenario(tmp_path, [{"name": "llm", "model": "m", "prompt": "nowhere.txt"}])
    res = CliRunner().invoke(app, ["validate", str(sc)])
    assert res.exit_code == 2 and "planners[0].prompt" in res.output and "nowhere.txt does not exist" in res.output


def test_dry_run_prints_the_first_prompt_and_calls_nothing(tmp_path):
    sc = scenario(tmp_path, [{"name": "greedy"}, {"name": "llm", "base_url": "http://127.0.0.1:9/v1", "model": "m"}])
    res = CliRunner().invoke(app, ["run", str(sc), "--dry-run", "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    assert res.output.startswith("--- system ---\nYou control a mobile robot")
    assert "--- user ---\nGoal: read the door sign 304.\n" in res.output and "Answer with one number: 0" in res.output
    assert not (tmp_path / "out").exists()
    res = CliRunner().invoke(app, ["run", str(scenario(tmp_path, [{"name": "greedy"}])), "--dry-run"])
    assert res.exit_code == 2 and "no planner of" in res.output


def test_the_bench_runs_and_verifies_a_language_model(tmp_path):
    with ChatServer(first_target) as srv:
        spec = f"llm[base_url={srv.base_url},model=scripted]"
        api.bench_run("doors-classic-v1", [spec], tmp_path / "b", options=BatchOptions(workers=1, transcripts=True), limit=1)
    runs = pd.concat([pd.read_csv(p) for p in sorted((tmp_path / "b").glob("*/runs.csv"))])
    assert len(runs) >= 1 and (runs["llm_calls"] > 0).all() and runs["suite"].eq("doors-classic-v1").all()
    assert api.verify(tmp_path / "b").verdict.failed == []
    api.bench_board([tmp_path / "b"], tmp_path / "site")  # the board sums what the model cost
    board = (tmp_path / "site" / "board.md").read_text()
    header = next(line for line in board.splitlines() if line.startswith("| planner |"))
    assert "| llm_calls |" in header and "| calls per run |" in header
    assert f"| {int(runs['llm_calls'].sum()):,} |" in board
    # the bench folder's transcripts replay the same runs, offline
    api.bench_run("doors-classic-v1", [f"llm[replay={tmp_path / 'b'}]"], tmp_path / "r", options=BatchOptions(workers=1), limit=1)
    again = pd.concat([pd.read_csv(p) for p in sorted((tmp_path / "r").glob("*/runs.csv"))])
    pd.testing.assert_frame_equal(runs[["floor", *SAME, *COSTS]].reset_index(drop=True),
                                  again[["floor", *SAME, *COSTS]].reset_index(drop=True), check_dtype=False)
    shutil.rmtree(tmp_path / "b")


def test_the_key_variable_is_named_not_read_into_params(monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", "sk-not-in-any-transcript")
    p = LlmPlanner(LlmParams(model="m"))
    p.start_run({"scenario": "s", "kind": "doors", "planner": "llm", "goal": "1", "episode": 0, "seed": 0})
    assert p.transcript[0]["params"]["api_key_env"] == "OPENAI_API_KEY"
    assert os.environ["OPENAI_API_KEY"] not in json.dumps(p.transcript)


def test_the_model_as_a_gymnasium_policy_travels_greedys_runs(tmp_path):
    gym = pytest.importorskip("gymnasium")
    import semsearch_cli.envs  # noqa: F401  (registers the environments)
    from semsearch_cli.envs import PlannerPolicy
    sc = scenario(tmp_path, [{"name": "greedy"}], seeds=2, goals=[304])
    api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
    rows = rows_of(tmp_path / "out", "greedy")
    with ChatServer(first_target) as srv:
        policy = PlannerPolicy("llm", base_url=srv.base_url, model="scripted")
        env = gym.make("semsearch/DoorSearch-v0", scenario=str(sc), **policy.env_kwargs)
        for _, row in rows.iterrows():
            play(policy, env, row)
    assert len(srv.requests) > 0 and policy.planner.calls > 0


def play(policy, env, row) -> None:
    """The policy on the row's episode and repeat travels what the row records."""
    env.reset(options={"episode": int(row["episode"]), "repeat": int(row["seed"])})
    policy.reset()
    done = False
    while not done:
        _, _, term, trunc, info = env.step(policy(env))
        done = term or trunc
    assert (info["outcome"], info["distance_m"]) == (row["outcome"], pytest.approx(row["distance_m"], abs=1e-3))


def test_a_gymnasium_policy_replays_the_batchs_transcripts_with_no_server(tmp_path):
    gym = pytest.importorskip("gymnasium")
    import semsearch_cli.envs  # noqa: F401  (registers the environments)
    from semsearch_cli.envs import PlannerPolicy
    with ChatServer(flaky) as srv:
        sc = scenario(tmp_path, [llm(srv, reasks=1, replan_on_signs=True)], seeds=2, goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1, transcripts=True), plots=False)
    rows = rows_of(tmp_path / "out", "llm")
    assert rows["invalid_replies"].sum() > 0
    policy = PlannerPolicy("llm", replay=str(tmp_path / "out"))
    assert policy.env_kwargs == {"replan_on_signs": True}  # the transcripts' cadence, before any run starts
    env = gym.make("semsearch/DoorSearch-v0", scenario=str(sc), **policy.env_kwargs)
    for _, row in rows.iterrows():
        play(policy, env, row)
        assert policy.planner.costs() == {c: (int(row[c]) if c != "llm_s" else row[c]) for c in COSTS}


def test_a_report_never_calls_the_model(tmp_path):
    with ChatServer(first_target) as srv:
        sc = scenario(tmp_path, [{"name": "greedy"}, llm(srv)], seeds=1, goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
        made = len(srv.requests)
        api.report([tmp_path / "out"], tmp_path / "report")  # no frames recorded: the default replay is greedy's
        api.report([tmp_path / "out"], tmp_path / "again", replay="llm[base_url=" + srv.base_url + ",model=scripted],304,0,0")
        assert len(srv.requests) == made
    gifs = sorted(p.name for p in (tmp_path / "report").rglob("replay_*.gif"))
    assert gifs and all("greedy" in g for g in gifs)
    assert not list((tmp_path / "again").rglob("replay_*.gif"))


# ---- a model that does not answer is never a result ---------------------------------------------
def closed_port() -> int:
    """A loopback port nothing listens on (bound, then let go)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def refused(tmp_path: Path, entry: dict, env: dict | None = None) -> str:
    """``semsearch run`` of the demo with greedy and ``entry``: exit 2 with nothing written; its
    output. Fast failure is the look's own (one request, no retries,
    PREFLIGHT_TIMEOUT_S): the tests count the requests rather than time them."""
    sc = scenario(tmp_path, [{"name": "greedy"}, entry], seeds=1)
    res = CliRunner().invoke(app, ["run", str(sc), "--out", str(tmp_path / "out"), "--workers", "1"], env=env)
    assert res.exit_code == 2, res.output
    assert not [p for p in (tmp_path / "out").rglob("*")]  # nothing written (the folder itself is made as --out is read)
    assert "Traceback" not in res.output and res.output.startswith("error: ")
    return " ".join(res.output.split())


def test_a_refused_endpoint_on_resume_moves_no_row_and_bench_run_writes_nothing(tmp_path):
    """A folder whose llm runs could not run, resumed while the endpoint is still down: refused
    before the folder is touched (its rows stay where they are); a bench run likewise writes no
    bench.json nor floor."""
    with ChatServer(lambda r, n: Answer(status=500), models=["scripted"]) as srv:
        sc = scenario(tmp_path, [llm(srv, retries=0)], seeds=1, goals=[452])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
    before = (tmp_path / "out" / "runs.csv").read_bytes()
    assert b"unavailable: " in before
    res = CliRunner().invoke(app, ["run", str(sc), "--out", str(tmp_path / "out"), "--workers", "1"])  # the server is gone
    assert res.exit_code == 2 and "no connection to" in " ".join(res.output.split()), res.output
    assert (tmp_path / "out" / "runs.csv").read_bytes() == before and not (tmp_path / "out" / "runs.superseded.csv").exists()
    url = f"http://127.0.0.1:{closed_port()}/v1"
    res = CliRunner().invoke(app, ["bench", "run", "doors-v1", "--planner", f"llm[base_url={url},model=m]", "--limit", "1",
                                   "--workers", "1", "--out", str(tmp_path / "bench")])
    assert res.exit_code == 2 and "field '--planner'" in res.output and "no connection to" in " ".join(res.output.split())
    assert not (tmp_path / "bench").exists()


def test_a_server_that_answers_500_is_refused_before_the_first_run(tmp_path):
    with ChatServer(models=["scripted"], status=500) as srv:
        text = refused(tmp_path, llm(srv))
        assert srv.gets == ["/v1/models"] and srv.requests == []  # one look, no call
    assert f"field 'planners.base_url': llm[base_url={srv.base_url},model=scripted]: the server at {srv.base_url} " \
           f"answered HTTP 500 at {srv.base_url}/models" in text


def test_a_base_url_without_v1_is_refused_naming_v1(tmp_path):
    with ChatServer(models=["scripted"]) as srv:
        bare = srv.base_url[:-len("/v1")]
        text = refused(tmp_path, {**llm(srv), "base_url": bare})
    assert f"the server at {bare} answered HTTP 404 at {bare}/models: an OpenAI-compatible server serves under /v1, and " \
           f"base_url does not end in /v1 (e.g. {bare}/v1)" in text


def test_a_closed_port_is_refused_at_once(tmp_path):
    url = f"http://127.0.0.1:{closed_port()}/v1"
    text = refused(tmp_path, {"name": "llm", "base_url": url, "model": "m"})
    assert f"field 'planners.base_url': llm[base_url={url},model=m]: no connection to {url} (ConnectError" in text


def test_a_key_the_server_wants_and_the_variable_unset_are_refused(tmp_path, monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    monkeypatch.delenv("SEMSEARCH_TEST_KEY", raising=False)
    with ChatServer(models=["scripted"], key="sk-right") as srv:
        text = refused(tmp_path / "a", llm(srv))  # the default variable, unset: the server says 401
        assert f"planners.base_url': llm[base_url={srv.base_url},model=scripted]: the server at {srv.base_url} answered " \
               "HTTP 401 (not authorised): the variable OPENAI_API_KEY (api_key_env) is not set" in text
        text = refused(tmp_path / "b", llm(srv, api_key_env="SEMSEARCH_TEST_KEY"))  # a variable named and unset: no request
        assert "field 'planners.api_key_env'" in text and "api_key_env names the variable SEMSEARCH_TEST_KEY, which is " \
               "not set in this environment" in text
        assert len(srv.gets) == 1
        monkeypatch.setenv("SEMSEARCH_TEST_KEY", "sk-wrong")
        text = refused(tmp_path / "c", llm(srv, api_key_env="SEMSEARCH_TEST_KEY"))
        assert "answered HTTP 401 (not authorised): the key in SEMSEARCH_TEST_KEY (api_key_env) was refused" in text
        monkeypatch.setenv("SEMSEARCH_TEST_KEY", "sk-right")  # the right key: the batch runs
        sc = scenario(tmp_path / "d", [llm(srv, api_key_env="SEMSEARCH_TEST_KEY")], seeds=1, goals=[452])
        api.run(sc, BatchOptions(out=tmp_path / "d" / "out", workers=1), plots=False)
    assert rows_of(tmp_path / "d" / "out", "llm")["outcome"].tolist() == ["found"]


def test_a_model_the_server_does_not_list_is_refused(tmp_path):
    with ChatServer(models=["qwen2.5:7b", "llama3.1:8b"]) as srv:
        text = refused(tmp_path, llm(srv))
        assert srv.requests == []
    assert f"field 'planners.model': llm[base_url={srv.base_url},model=scripted]: the server at {srv.base_url} does not " \
           "serve the model 'scripted'; it lists qwen2.5:7b, llama3.1:8b" in text


def test_a_base_url_without_a_scheme_is_a_scenario_error(tmp_path):
    sc = scenario(tmp_path, [{"name": "llm", "base_url": "localhost:8000", "model": "m"}])
    res = CliRunner().invoke(app, ["validate", str(sc)])
    assert res.exit_code == 2 and "field 'planners[0].base_url'" in res.output
    assert "'localhost:8000' is not an http:// or https:// address with a host; write it whole, e.g. " \
           "http://localhost:8000/v1" in " ".join(res.output.split())


def test_a_run_whose_model_fails_ends_error_unavailable_not_found(tmp_path):
    # the endpoint answers its list of models (the look before the batch passes), then 500 to every call
    with ChatServer(lambda r, n: Answer(status=500), models=["scripted"]) as srv:
        sc = scenario(tmp_path, [llm(srv, retries=0)], seeds=1, goals=[452])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
    row = rows_of(tmp_path / "out", "llm").iloc[0]
    assert row["outcome"] == "error" and "unavailable" in row["message"].lower()
    assert "every call of its first 3 decisions was invalid (9 calls; the last: HTTP 500 from the server)" in row["message"]
    assert (row["llm_calls"], row["fallbacks"]) == (9, 3) and len(srv.requests) == 9  # 3 decisions x (1 + 2 re-asks)
    # a model that answers its first decision, then nothing: more than half its decisions fell back by the end
    with ChatServer(lambda r, n: first_target(r, n) if n == 0 else Answer("I am not sure."), models=["scripted"]) as srv:
        sc = scenario(tmp_path, [llm(srv, reasks=0)], seeds=1, goals=[452])
        api.run(sc, BatchOptions(out=tmp_path / "out2", workers=1), plots=False)
    row = rows_of(tmp_path / "out2", "llm").iloc[0]
    assert row["outcome"] == "error" and f"{row['fallbacks']} of its {row['fallbacks'] + 1} decisions fell back (more " \
        "than max_fallback_share = 0.5); the last failure: the reply is not one number" in row["message"], row["message"]


def test_without_openai_run_bench_and_dry_run_refuse_in_one_line(tmp_path):
    sc = scenario(tmp_path, [{"name": "greedy"}, {"name": "llm", "base_url": "http://127.0.0.1:9/v1", "model": "m"}], seeds=1)
    no_openai = "import sys; sys.modules['openai'] = None; from semsearch_cli.cli import main; sys.argv[0] = 'semsearch'; main()"
    line = "the llm planner needs the llm extra: pip install 'semsearch[llm]'"
    for args, out in ((["run", str(sc), "--out", str(tmp_path / "r")], tmp_path / "r"),
                      (["run", str(sc), "--dry-run", "--out", str(tmp_path / "d")], tmp_path / "d"),
                      (["bench", "run", "doors-classic-v1", "--planner", "llm[base_url=http://127.0.0.1:9/v1,model=m]",
                        "--out", str(tmp_path / "b"), "--limit", "1"], tmp_path / "b")):
        res = subprocess.run([sys.executable, "-c", no_openai, *args], capture_output=True, text=True, timeout=120,
                             env={**os.environ, "PYTHONPATH": str(ROOT), "COLUMNS": "400"})
        assert res.returncode == 2, (args, res.stderr)
        assert len(res.stderr.strip().splitlines()) == 1 and line in res.stderr and "Traceback" not in res.stderr, res.stderr
        assert not list(out.rglob("runs.csv")) or all(len(pd.read_csv(f)) == 0 for f in out.rglob("runs.csv"))


def test_a_batch_and_the_board_say_the_share_of_decisions_that_fell_back(tmp_path):
    # every fifth reply is prose: with no re-ask, about a fifth of the decisions fall back (the run is still the model's)
    with ChatServer(lambda r, n: Answer("I am not sure.") if n % 5 == 4 else first_target(r, n), models=["scripted"]) as srv:
        spec = f"llm[base_url={srv.base_url},model=scripted,reasks=0]"
        res = CliRunner().invoke(app, ["bench", "run", "doors-classic-v1", "--planner", spec, "--planner", "greedy",
                                       "--limit", "1", "--workers", "1", "--out", str(tmp_path / "b")])
    assert res.exit_code == 0, res.output
    runs = pd.concat([pd.read_csv(p) for p in (tmp_path / "b").glob("*/runs.csv")])
    model = runs[runs["planner"] == spec]
    assert (model["outcome"] == "found").all()
    n, asked = int(model["fallbacks"].sum()), int(model["llm_calls"].sum())  # no re-asks: a call is a decision
    assert 0.05 < n / asked < 0.5
    last = res.output.strip().splitlines()[-1]
    assert last == f"fell back: {spec}: {n} of {asked} decisions ({n / asked:.1%}) (more than 5%: the bench board marks it)"
    assert "fell back: greedy" not in res.output  # a planner without a fallback has no line
    api.bench_board([tmp_path / "b"], tmp_path / "site")
    md = (tmp_path / "site" / "board.md").read_text()
    row = next(line for line in md.splitlines() if line.startswith(f"| {spec} |"))
    assert f"| {n / asked:.1%} of {asked:,} |" in row and f"| not verified, {n / asked:.1%} of decisions fell back |" in row
    greedy = next(line for line in md.splitlines() if line.startswith("| greedy |"))
    assert "fell back" not in greedy


# ---- replies a model can keep to ------------------------------------------------------------------
def keeps_to(request: dict, n: int) -> Answer:
    """A server that honours what it is asked to keep to: the first choice its JSON schema's enum
    (or its grammar's first alternative) names, written as the schema (or grammar) asks; the
    estimator's table with all its weight on the first target."""
    fmt = request.get("response_format")
    if fmt is not None:
        props = fmt["json_schema"]["schema"]["properties"]
        if "choice" in props:
            return Answer(json.dumps({"choice": props["choice"]["enum"][0]}))
        return Answer(json.dumps({k: (1.0 if i == 0 else 0.0) for i, k in enumerate(props)}))
    g = request.get("grammar")
    if g is not None and not g.startswith('root ::= "{"'):
        return Answer(re.match(r'root ::= "(\d+)"', g).group(1))
    if g is not None:
        keys = re.findall(r'\\"(\d+)\\":', g)
        return Answer("{" + ", ".join(f'"{k}": {1 if i == 0 else 0}' for i, k in enumerate(keys)) + "}")
    return first_target(request, n)


@pytest.mark.parametrize("reply_format", ["json_schema", "grammar"])
@pytest.mark.parametrize("mode", ["actor", "estimator"])
def test_a_constrained_reply_names_only_the_choices_offered_and_is_read(tmp_path, reply_format, mode):
    with ChatServer(keeps_to) as srv:
        sc = scenario(tmp_path, [{"name": "greedy"}, llm(srv, mode=mode, reply_format=reply_format, seed=7)], seeds=1,
                      goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1, transcripts=True), plots=False)
    greedy, model = rows_of(tmp_path / "out", "greedy"), rows_of(tmp_path / "out", "llm")
    assert model["invalid_replies"].sum() == 0 and model["fallbacks"].sum() == 0
    if mode == "actor":  # the first choice, every time: greedy's runs
        pd.testing.assert_frame_equal(greedy[SAME], model[SAME])
    calls = [c for p in sorted((tmp_path / "out" / "transcripts").glob("*.jsonl")) for c in map(json.loads, p.open())
             if c["type"] == "call"]
    assert len(calls) == len(srv.requests) > 0
    for call, req in zip(calls, srv.requests):
        assert (call["reply_format"], call["seed"], call["temperature"]) == (reply_format, 7, 0.0)
        assert req["seed"] == 7 and req["messages"] == call["messages"]
        offered = offered_numbers(call["observation"], mode)
        if reply_format == "json_schema":
            schema = req["response_format"]["json_schema"]["schema"]
            named = schema["properties"]["choice"]["enum"] if mode == "actor" else [int(k) for k in schema["required"]]
        else:
            named = [int(v) for v in re.findall(r'"(\d+)"' if mode == "actor" else r'\\"(\d+)\\"', req["grammar"])]
        assert named == offered


def offered_numbers(observation: str, mode: str) -> list[int]:
    """The numbers an observation's answer line offers (actor), or its targets' (estimator)."""
    last = observation.rsplit("\n", 1)[-1]
    words = re.search(r"one number: (.+)\.$", last).group(1) if mode == "actor" else re.search(r"numbers \((.+)\)", last).group(1)
    out = []
    for item in re.split(r", | or ", words):
        a, _, b = item.partition("-")
        out += range(int(a), int(b or a) + 1)
    return out


def test_a_server_that_ignores_the_schema_is_read_as_text(tmp_path):
    with ChatServer(first_target) as srv:  # answers a bare number whatever it is asked to keep to
        sc = scenario(tmp_path, [{"name": "greedy"}, llm(srv, reply_format="json_schema")], seeds=1, goals=[304])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
    greedy, model = rows_of(tmp_path / "out", "greedy"), rows_of(tmp_path / "out", "llm")
    assert model["invalid_replies"].sum() == 0
    pd.testing.assert_frame_equal(greedy[SAME], model[SAME])
    assert all("response_format" in r for r in srv.requests)


@pytest.mark.parametrize("reply,valid", [('{"choice": 1}', 1), ('```json\n{"choice": 0}\n```', 0), ("1", 1),
                                         ('{"choice": 9}', None), ('{"choice": "1"}', None), ('{"choice": true}', None),
                                         ('{"choice": 1, "why": "near"}', None), ('{"choice": 1', None), ("", None)])
def test_parse_choice_takes_the_schemas_object_or_a_plain_number(reply, valid):
    from semsearch_cli.planners.llm.replies import parse_choice
    choice, why = parse_choice(reply, frozenset({0, 1, 2}))
    assert choice == valid and (why == "") == (valid is not None)
