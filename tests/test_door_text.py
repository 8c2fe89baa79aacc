"""One text of a door decision (issue 55, item 3): ``semsearch/DoorSearch-v1`` shows the llm
planner's targets (by path length, greedy's choice first) and its text observation is the
planner's prompt, byte for byte; an agent that always answers 0 travels greedy's runs; the
planners as policies of v1 travel the batch's runs (tests/test_envs.py); v0 is deprecated."""

from __future__ import annotations

import warnings

import pytest

gym = pytest.importorskip("gymnasium")
pytest.importorskip("openai")

import semsearch_cli.envs  # noqa: E402,F401  (registers the environments)
from semsearch_cli import api  # noqa: E402
from semsearch_cli.envs import PlannerPolicy  # noqa: E402
from semsearch_cli.planners.llm import transcript  # noqa: E402
from semsearch_cli.runner import BatchOptions  # noqa: E402

from .llm_server import ChatServer, first_target  # noqa: E402
from .test_llm import llm, own_cache, rows_of, scenario  # noqa: E402,F401


def decisions(env, row, answer=lambda obs: 0):
    """The text observations of ``row``'s episode and repeat in ``env`` at each decision, the
    agent answering ``answer(obs)``; and the last step's info."""
    obs, info = env.reset(options={"episode": int(row["episode"]), "repeat": int(row["seed"])})
    seen, done = [], False
    while not done:
        seen.append(obs)
        obs, _, term, trunc, info = env.step(answer(obs))
        done = term or trunc
    return seen, info


def test_an_agent_in_v1_reads_the_llm_planners_prompt_byte_for_byte(tmp_path):
    with ChatServer(first_target) as srv:
        sc = scenario(tmp_path, [llm(srv, max_targets=16)], seeds=2, goals=[304, 452])
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1, transcripts=True), plots=False)
        kwargs = PlannerPolicy("llm", base_url=srv.base_url, model="scripted").env_kwargs
    rows = rows_of(tmp_path / "out", "llm")
    prompts = {}
    for path in sorted((tmp_path / "out" / "transcripts").glob("*.jsonl")):
        lines = transcript.read(path)
        run = lines[0]["run"]
        prompts[(int(run["episode"]), int(run["seed"]))] = [c["observation"] for c in lines
                                                            if c["type"] == "call" and c["attempt"] == 0]
    assert len(prompts) == len(rows) >= 4
    env = gym.make("semsearch/DoorSearch-v1", scenario=str(sc), observation_mode="text", max_candidates=16, **kwargs)
    for _, row in rows.iterrows():
        seen, info = decisions(env, row)
        assert seen == prompts[(int(row["episode"]), int(row["seed"]))]
        assert (info["outcome"], info["distance_m"]) == (row["outcome"], pytest.approx(row["distance_m"], abs=1e-3))


def test_an_agent_that_always_answers_0_in_v1_travels_greedys_runs(tmp_path):
    sc = scenario(tmp_path, [{"name": "greedy"}], seeds=2, goals=[304, 452])
    api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False)
    rows = rows_of(tmp_path / "out", "greedy")
    env = gym.make("semsearch/DoorSearch-v1", scenario=str(sc), replan_on_signs=False)  # greedy's cadence
    for _, row in rows.iterrows():
        seen, info = decisions(env, row)
        assert (info["outcome"], info["steps"]) == (row["outcome"], row["steps"])
        assert info["distance_m"] == pytest.approx(row["distance_m"], abs=1e-3)


def test_v1s_mask_offers_the_targets_and_the_wall_after_them(tmp_path):
    env = gym.make("semsearch/DoorSearch-v1", scenario="shipped:demo").unwrapped
    obs, info = env.reset(seed=0)
    n = len(env.slots)
    assert info["action_mask"].nonzero()[0].tolist() == list(range(n + 1)) and env.sweep_action == n
    assert obs["targets"].shape == (env.K, 5) and (obs["targets"][:n, 0] == 1).all() and (obs["targets"][n:] == 0).all()
    assert (obs["targets"][:n, 4] > 0).all()  # the path lengths, in the order shown (nearest first after greedy's)
    assert list(obs["targets"][1:n, 4]) == sorted(obs["targets"][1:n, 4])


def test_v0_warns_naming_v1_and_v1_does_not():
    with pytest.warns(DeprecationWarning, match=r"DoorSearch-v0 .* 0\.4\.0 .* 0\.5\.0: use semsearch/DoorSearch-v1"):
        gym.make("semsearch/DoorSearch-v0", scenario="shipped:demo")
    with pytest.warns(DeprecationWarning, match=r"DoorSearch-Generated-v1"):
        gym.make("semsearch/DoorSearch-Generated-v0", buildings=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        gym.make("semsearch/DoorSearch-Hotel-v1")
        gym.make("semsearch/DoorSearch-Generated-v1", buildings=1)
