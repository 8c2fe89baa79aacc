"""The llm planner in object and indirect search, against a real OpenAI-compatible server on
loopback (tests/llm_server.py): the model reads exactly the environments' text observations, the
harness adds nothing of its own (a scripted model in the batch travels what the same script
travels as an agent of the environment, run for run), and transcripts replay offline."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pandas as pd
import pytest
import yaml
from typer.testing import CliRunner

pytest.importorskip("openai")
gym = pytest.importorskip("gymnasium")

import semsearch_cli.envs  # noqa: E402,F401  (registers the environments)
from semsearch_cli import api  # noqa: E402
from semsearch_cli.cli import app  # noqa: E402
from semsearch_cli.runner import BatchOptions  # noqa: E402

from .llm_server import Answer, ChatServer, decision_text  # noqa: E402

COSTS = ["llm_calls", "tokens_in", "tokens_out", "invalid_replies", "fallbacks", "llm_s"]
SAME = ["goal", "episode", "seed", "outcome", "distance_m", "steps", "decisions"]


@pytest.fixture(autouse=True)
def own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))  # the request slots' lock files


# ---- scripted models: each a function of the text alone, so an environment's agent can run it too --
def nearest_unviewed_place(text: str) -> int:
    """Object search: the nearest place offered that the camera has not had in view (else the nearest)."""
    offered = [(float(d), int(k), v != "viewed") for k, d, v in
               re.findall(r"^\[(\d+)\] [^\n:]+: ([0-9.]+) m, bearing -?\d+ deg, (viewed|not viewed yet);", text, re.M)]
    fresh = [o for o in offered if o[2]] or offered
    return min(fresh)[1]


def toward_the_likeliest_cell(text: str) -> int:
    """Indirect search: the allowed lattice point nearest the likeliest cell, facing that cell."""
    cx, cy = map(float, re.search(r"probability\): \(([-0-9.]+), ([-0-9.]+)\) m", text).groups())
    nx, x0, step = re.search(r"point k = i \+ (\d+) j is at x = ([0-9.]+) \+ ([0-9.]+) i m", text).groups()
    nx, x0, step = int(nx), float(x0), float(step)
    allowed = set()
    for part in re.search(r"Answer with one number: (.*)\.$", text, re.M).group(1).replace(" or ", ", ").split(", "):
        a, _, b = part.partition("-")
        allowed.update(range(int(a), int(b or a) + 1))

    def where(k):
        return x0 + step * (k % nx), x0 + step * (k // nx)

    k = min({a // 8 for a in allowed}, key=lambda k: (math.hypot(where(k)[0] - cx, where(k)[1] - cy), k))
    px, py = where(k)
    h = 0 if math.hypot(cx - px, cy - py) < 1e-9 else round(math.degrees(math.atan2(cy - py, cx - px)) / 45.0) % 8
    return 8 * k + h


def serve(policy):
    return lambda request, n: Answer(str(policy(decision_text(request["messages"]))))


# ---- the scenarios ----------------------------------------------------------------------------------
def object_scenario(tmp_path: Path, planners: list) -> Path:
    api.init("office", tmp_path / "office", force=True)
    src = tmp_path / "office" / "office.yaml"
    d = yaml.safe_load(src.read_text())
    d["planners"], d["experiment"]["seeds"] = planners, 2
    out = src.with_name("office_llm.yaml")
    out.write_text(yaml.safe_dump(d))
    return out


def indirect_scenario(tmp_path: Path, planners: list) -> Path:
    api.init("indirect_quick", tmp_path / "quick", force=True)
    src = tmp_path / "quick" / "indirect_quick.yaml"
    d = yaml.safe_load(src.read_text())
    d["planners"], d["experiment"]["seeds"] = planners, 2
    d["indirect"]["rooms"]["count"], d["indirect"]["view_scales"] = 2, [2.0]
    out = src.with_name("quick_llm.yaml")
    out.write_text(yaml.safe_dump(d))
    return out


def llm(srv, **kw) -> dict:
    return {"name": "llm", "base_url": srv.base_url, "model": "scripted", **kw}


def rows(folder: Path) -> pd.DataFrame:
    df = pd.read_csv(folder / "runs.csv")
    return df[df["planner"].str.startswith("llm")].sort_values(["goal", "episode", "seed"]).reset_index(drop=True)


def transcripts(folder: Path) -> dict:
    """(goal, episode, seed) -> the observations the model read, in order."""
    out = {}
    for p in (folder / "transcripts").glob("*.jsonl"):
        lines = [json.loads(x) for x in p.read_text().splitlines()]
        r = lines[0]["run"]
        out[(str(r["goal"]), int(r["episode"]), int(r["seed"]))] = [x["observation"] for x in lines if x["type"] == "call"]
    return out


def as_agent(env_id: str, scenario: Path, policy, row) -> tuple[list, dict]:
    """The script as the text environment's agent on the row's episode and repeat."""
    env = gym.make(env_id, scenario=str(scenario), observation_mode="text")
    obs, info = env.reset(options={"episode": int(row["episode"]), "repeat": int(row["seed"])})
    seen, done = [obs], False
    while not done:
        obs, _, term, trunc, info = env.step(policy(obs))
        done = term or trunc
        if not done:
            seen.append(obs)
    return seen, info


@pytest.mark.parametrize("kind", ["objects", "indirect"])
def test_the_model_reads_the_environments_text_and_travels_what_its_agent_travels(tmp_path, kind):
    make, policy, env_id = {"objects": (object_scenario, nearest_unviewed_place, "semsearch/ObjectSearch-v0"),
                            "indirect": (indirect_scenario, toward_the_likeliest_cell, "semsearch/IndirectSearch-v0")}[kind]
    with ChatServer(serve(policy)) as srv:
        sc = make(tmp_path, [llm(srv)])
        api.run(sc, BatchOptions(out=tmp_path / "live", workers=2, transcripts=True, decisions=True), plots=False)
    live = rows(tmp_path / "live")
    assert len(live) >= 4 and live["llm_calls"].sum() == len(srv.requests) > len(live)
    assert live["invalid_replies"].sum() == 0 and live["fallbacks"].sum() == 0
    said = transcripts(tmp_path / "live")
    for _, row in live.iterrows():
        seen, info = as_agent(env_id, sc, policy, row)
        assert said[(str(row["goal"]), int(row["episode"]), int(row["seed"]))] == seen  # the same text, decision by decision
        assert info["outcome"] == row["outcome"]
        assert info["distance_m"] == pytest.approx(row["distance_m"], abs=1e-3)
    # the server is gone: the transcripts replay the same rows, and verify replays the decisions
    rp = sc.with_name("replay.yaml")
    d = yaml.safe_load(sc.read_text())
    d["planners"] = [{"name": "llm", "replay": str(tmp_path / "live")}]
    rp.write_text(yaml.safe_dump(d))
    api.run(rp, BatchOptions(out=tmp_path / "replay", workers=1), plots=False)
    pd.testing.assert_frame_equal(live[SAME + COSTS], rows(tmp_path / "replay")[SAME + COSTS], check_dtype=False)
    assert api.verify(tmp_path / "live").verdict.verified == len(live)


def test_an_object_estimator_reads_probabilities_by_place(tmp_path):
    def likely(request, n):  # all weight on the places the log saw the mug at within the hour (first, some prose)
        if n == 0:
            return Answer("The mug is probably in the kitchen.")
        text = decision_text(request["messages"])
        near = {k: int(w) for k, w in re.findall(r"^\[(\d+)\] .*detections, (\d+) within the hour$", text, re.M)}
        total = sum(near.values()) or 1
        return Answer(json.dumps({k: round(w / total, 3) for k, w in near.items()}))

    with ChatServer(likely) as srv:
        sc = object_scenario(tmp_path, [llm(srv, mode="estimator")])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1, seeds=1), plots=False)
        assert "JSON object" in decision_text(srv.requests[0]["messages"])
        again = srv.requests[1]["messages"][-1]["content"]  # the re-ask asks for what the mode answers
        assert again == ("Your reply could not be used: the reply is not one JSON object. Answer with one JSON object "
                         "mapping place numbers (0-9) to probabilities from 0 to 1.")
    got = rows(tmp_path / "out")
    assert len(got) >= 2 and got["invalid_replies"].sum() == 1 and got["fallbacks"].sum() == 0
    assert got["llm_calls"].sum() == got["decisions"].sum() + 1


def test_an_indirect_estimator_and_a_prompt_of_another_kind_are_refused_naming_the_field(tmp_path):
    sc = indirect_scenario(tmp_path, [{"name": "llm", "model": "m", "mode": "estimator"}])
    res = CliRunner().invoke(app, ["validate", str(sc)])
    assert res.exit_code == 2 and "planners[0].mode" in res.output and "indirect search takes mode actor" in res.output
    (tmp_path / "doors.txt").write_text("=== system ===\nFind it.\n=== user ===\n$signs\n")
    sc = object_scenario(tmp_path, [{"name": "llm", "model": "m", "prompt": "../doors.txt"}])
    res = CliRunner().invoke(app, ["validate", str(sc)])
    assert res.exit_code == 2 and "planners[0].prompt" in res.output and "no field $signs in objects search" in res.output
    assert "Traceback" not in res.output


def test_a_dry_run_prints_an_object_searchs_first_prompt(tmp_path):
    sc = object_scenario(tmp_path, [{"name": "llm", "model": "m"}])
    res = CliRunner().invoke(app, ["run", str(sc), "--dry-run"])
    assert res.exit_code == 0, res.output
    assert "--- system ---" in res.output and "searches an office" in res.output
    assert re.search(r"^\[0\] A: [0-9.]+ m, bearing -?\d+ deg, not viewed yet; log: \d+ detections", res.output, re.M)


@pytest.mark.parametrize("suite", ["objects-v1", "indirect-v1"])
def test_the_bench_runs_and_verifies_a_model_on_object_and_indirect_suites(tmp_path, suite):
    def script(request, n):
        text = decision_text(request["messages"])
        return Answer(str((toward_the_likeliest_cell if "lattice point" in text else nearest_unviewed_place)(text)))

    with ChatServer(script) as srv:
        api.bench_run(suite, [f"llm[base_url={srv.base_url},model=scripted]"], tmp_path / "b",
                      options=BatchOptions(workers=1), limit=1)
    runs = pd.concat([pd.read_csv(p) for p in sorted((tmp_path / "b").rglob("runs.csv"))])
    assert len(runs) >= 1 and runs["suite"].eq(suite).all() and runs["llm_calls"].sum() == len(srv.requests) > 0
    assert api.verify(tmp_path / "b").verdict.failed == []
