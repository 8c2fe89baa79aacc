"""The Gymnasium environments (semsearch_cli.envs), tested as Minigrid tests its registered ids:
Gymnasium's own checker on every id in both action modes, determinism, pickling, vector envs; and
the equivalence with the batch: the built-in planners as policies travel, run for run, what
``semsearch run`` records."""

import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env, data_equivalence  # noqa: E402

import semsearch_cli.envs as envs  # noqa: E402
from semsearch_cli.envs import PlannerPolicy  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.runner import BatchOptions, Loaded, RunSpec, run_batch  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
KWARGS = {"semsearch/DoorSearch-v1": {"scenario": str(ROOT / "configs/demo.yaml")},
          "semsearch/DoorSearch-v0": {"scenario": str(ROOT / "configs/demo.yaml")},
          "semsearch/ObjectSearch-v0": {"scenario": str(ROOT / "configs/office.yaml")},
          "semsearch/IndirectSearch-v0": {"scenario": str(ROOT / "configs/indirect_quick.yaml")},
          "semsearch/DoorSearch-Generated-v1": {"buildings": 2}}
MODES = ["macro", "primitive"]


def make(env_id, **kw):
    return gym.make(env_id, **{**KWARGS.get(env_id, {}), **kw})


def rollout(env, seed: int, n: int) -> list:
    """``n`` steps of valid random actions from ``reset(seed)``: every transition."""
    rng = np.random.default_rng(seed)
    out = [env.reset(seed=seed)]
    info = out[0][1]
    for _ in range(n):
        t = env.step(int(rng.choice(np.flatnonzero(info["action_mask"]))))
        out.append(t)
        info = t[4]
        if t[2] or t[3]:
            break
    return out


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", envs.ENV_IDS)
def test_every_registered_env_passes_gymnasiums_checker(env_id, mode):
    env = make(env_id, action_mode=mode, render_mode="rgb_array")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    # a deprecated version (DoorSearch v0) warns as the checker makes it again; nothing else may
    caught = [w for w in caught if not ("DoorSearch" in env_id and env_id.endswith("-v0") and "deprecated since semsearch 0.4.0"
                                        in str(w.message))]
    assert not caught, [str(w.message) for w in caught]
    img = env.unwrapped.render()
    assert img.ndim == 3 and img.shape[2] == 3 and img.dtype == np.uint8
    env.close()


@pytest.mark.parametrize("env_id", ["semsearch/DoorSearch-Hotel-v1", "semsearch/ObjectSearch-Office-v0",
                                    "semsearch/IndirectSearch-Quick-v0"])
@pytest.mark.parametrize("observation_mode", ["dict", "text"])
@pytest.mark.parametrize("mode", MODES)
def test_the_same_seed_gives_the_same_observations_and_rewards(env_id, mode, observation_mode):
    a = rollout(make(env_id, action_mode=mode, observation_mode=observation_mode), 7, 40)
    b = rollout(make(env_id, action_mode=mode, observation_mode=observation_mode), 7, 40)
    assert data_equivalence(a, b)
    c = rollout(make(env_id, action_mode=mode, observation_mode=observation_mode), 8, 40)
    assert not data_equivalence(a, c)


@pytest.mark.parametrize("env_id", ["semsearch/DoorSearch-Hotel-v1", "semsearch/ObjectSearch-Office-v0",
                                    "semsearch/IndirectSearch-Quick-v0", "semsearch/DoorSearch-Generated-v1"])
def test_an_environment_pickles_before_reset_and_mid_episode(env_id):
    env = make(env_id)
    copy = pickle.loads(pickle.dumps(env))
    assert data_equivalence(env.reset(seed=3), copy.reset(seed=3))
    info = env.unwrapped._info()
    for _ in range(3):  # mid-episode: the copy replays the actions since the reset
        a = int(np.flatnonzero(info["action_mask"])[0])
        t = env.step(a)
        info = t[4]
        if t[2] or t[3]:
            break
    later = pickle.loads(pickle.dumps(env))
    a = int(np.flatnonzero(info["action_mask"])[-1])
    assert data_equivalence(env.step(a), later.step(a))


@pytest.mark.parametrize("vector", ["sync", "async"])
def test_vector_envs_of_four(vector):
    fns = [lambda: make("semsearch/DoorSearch-v1", action_mode="primitive")] * 4
    vec = gym.vector.SyncVectorEnv(fns) if vector == "sync" else gym.vector.AsyncVectorEnv(fns)
    try:
        obs, infos = vec.reset(seed=[0, 1, 2, 3])
        assert obs["occupancy"].shape == (4, 65, 65) and len(set(infos["repeat"])) == 4
        total = np.zeros(4)
        for _ in range(20):
            obs, rew, term, trunc, infos = vec.step(vec.action_space.sample())
            total += rew
            assert not (term | trunc).any()  # 2 m at most from the starts: no episode ends
        # each copy's return is minus the metres it travelled, and they went their own ways
        np.testing.assert_allclose(total, -infos["distance_m"], atol=1e-9)
        assert infos["steps"].tolist() == [20] * 4 and len(set(np.round(obs["pose"][:, 0], 6))) > 1
    finally:
        vec.close()


def test_a_primitive_move_into_a_wall_leaves_the_robot_where_it_stands():
    env = make("semsearch/DoorSearch-v1", action_mode="primitive").unwrapped
    env.reset(seed=0)
    st = env.state
    moved = []
    for _ in range(200):  # west until the wall stops it
        x0 = st.x
        _, r, term, trunc, _ = env.step(4)
        moved.append(x0 - st.x)
        if term or trunc:
            break
    assert moved[0] == pytest.approx(0.1) and moved[-1] == 0.0
    assert env.task.world.cspace[tuple(int(v) for v in env.task.world.frame.to_index(st.x, st.y))]


@pytest.fixture(scope="module")
def batch_rows(tmp_path_factory):
    """greedy and nsos[alpha=0.9] on two door scenarios, two episodes x two repeats each, as
    ``semsearch run`` records them."""
    out = {}
    for name in ("demo", "hotel_thesis"):
        L = Loaded.load(ROOT / "configs" / f"{name}.yaml")
        specs = [RunSpec(ep, v, s) for ep in L.task.episodes[:2] for v in (Variant("greedy", ()), Variant("nsos", (("alpha", 0.9),)))
                 for s in range(2)]
        out[name] = run_batch(L, specs, tmp_path_factory.mktemp(name), BatchOptions(workers=1))
    return out


@pytest.mark.parametrize("version", ["v1", "v0"])
@pytest.mark.parametrize("scenario", ["demo", "hotel_thesis"])
@pytest.mark.parametrize("planner,params", [("greedy", {}), ("nsos", {"alpha": 0.9})])
def test_the_planners_as_policies_travel_what_the_batch_records(batch_rows, scenario, planner, params, version):
    rows = batch_rows[scenario]
    label = planner if not params else f"{planner}[alpha=0.9]"
    rows = rows[rows["planner"] == label]
    assert len(rows) >= 2
    policy = PlannerPolicy(planner, **params)
    env = gym.make(f"semsearch/DoorSearch-{version}", scenario=str(ROOT / "configs" / f"{scenario}.yaml"), **policy.env_kwargs)
    for _, row in rows.iterrows():
        env.reset(options={"episode": int(row["episode"]), "repeat": int(row["seed"])})
        policy.reset()
        done, ret = False, 0.0
        while not done:
            _, r, term, trunc, info = env.step(policy(env))
            ret += r
            done = term or trunc
        assert info["outcome"] == row["outcome"]
        assert info["distance_m"] == pytest.approx(row["distance_m"], abs=1e-3)
        assert ret == pytest.approx(-row["distance_m"] + (100.0 if row["outcome"] == "found" else 0.0), abs=1e-3)


def test_an_object_agent_cannot_look_again_for_free_at_the_place_it_stands():
    env = make("semsearch/ObjectSearch-Office-v0").unwrapped
    for a in range(env.P):  # a place away from the start, where the request's object is not
        env.reset(seed=1, options={"episode": 0})
        _, r, term, trunc, info = env.step(a)
        if not (term or trunc):
            break
    assert r < 0 and not info["action_mask"][a] and info["action_mask"].sum() == env.P - 1
    steps, seen = info["steps"], set(env.ctx.seen_places)
    _, r, term, trunc, info = env.step(a)  # the masked place again: nothing travelled, nothing sensed
    assert (r, term, info["steps"], set(env.ctx.seen_places)) == (0.0, False, steps, seen)

