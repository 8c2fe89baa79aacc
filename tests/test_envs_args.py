"""Every argument of the Gymnasium environments (semsearch_cli.envs) is checked against its range
where it enters: a constructor's argument, ``reset``'s seed and options, and every action. A bad
one is a ``ValueError`` naming it (never a traceback from deep inside, never taken on silently),
and the values at the edges of each range are taken. Issue 35."""

import math
import pickle
import re

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from semsearch_cli.envs import PlannerPolicy  # noqa: E402
from semsearch_cli.envs.base import check_action, check_flag, check_number, check_options  # noqa: E402
from semsearch_cli.envs.doors import MAX_CANDIDATES, MAX_SIGNS, MAX_WINDOW  # noqa: E402

from .test_envs import KWARGS, MODES, ROOT, make  # noqa: E402

ENV_IDS = sorted(KWARGS)
DOORS = "semsearch/DoorSearch-v1"
GENERATED = "semsearch/DoorSearch-Generated-v1"
INDIRECT = "semsearch/IndirectSearch-v0"
_READY: dict = {}  # (env id, mode) -> an environment just reset (refused actions leave it as it is)


def ready(env_id: str, mode: str):
    if (env_id, mode) not in _READY:
        env = make(env_id, action_mode=mode)
        env.reset(seed=0)
        _READY[env_id, mode] = env
    return _READY[env_id, mode]


def refused(name: str):
    """``pytest.raises`` for a ValueError whose message names ``name``."""
    return pytest.raises(ValueError, match=re.escape(name))


# ---- actions ------------------------------------------------------------------------------------
BAD_ACTIONS = {
    "n": lambda n: n,  # one past the last: primitive 10 of Discrete(10), one past the last place or lattice cell
    "n as numpy": lambda n: np.int64(n),
    "-1": lambda n: -1,  # read as the last place or lattice cell before
    "huge": lambda n: 10**30,  # overflows int64 in Discrete.contains
    "string": lambda n: "abc",
    "digit string": lambda n: "0",
    "None": lambda n: None,
    "float": lambda n: 1.5,
    "whole float": lambda n: 0.0,  # Discrete refuses it too
    "bool": lambda n: True,  # an int to Python, a bug in an agent
    "1-d array": lambda n: np.array([0]),
    "float array": lambda n: np.array(0.0),
    "0-d object array": lambda n: np.array(0, dtype=object),  # Discrete.contains refuses it too: no integer dtype
    "complex": lambda n: 1 + 0j,
}


@pytest.mark.parametrize("bad", sorted(BAD_ACTIONS))
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_an_action_outside_the_action_space_is_refused_and_changes_nothing(env_id, mode, bad):
    env = ready(env_id, mode)
    u = env.unwrapped
    steps = u.state.steps
    with refused("action") as e:
        env.step(BAD_ACTIONS[bad](env.action_space.n))
    assert f"0 to {env.action_space.n - 1}" in str(e.value)  # the valid range
    assert u.state.steps == steps and u._actions == [] and u.outcome is None


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("edge", ["last", "first", "numpy", "0-d array"])
def test_the_first_and_last_action_are_taken_as_python_or_numpy_integers(env_id, mode, edge):
    env = make(env_id, action_mode=mode)
    env.reset(seed=0)
    n = env.action_space.n
    a = {"last": n - 1, "first": 0, "numpy": np.int32(n - 1), "0-d array": np.array(n - 1)}[edge]
    env.step(a)
    u = env.unwrapped
    assert u._actions == [int(a)] and type(u._actions[0]) is int  # stored as the int it is: a pickled copy replays it
    copy = pickle.loads(pickle.dumps(env))
    assert copy.unwrapped.state.steps == u.state.steps


def test_check_action_takes_what_discrete_contains_but_a_bool():
    space = gym.spaces.Discrete(3, start=-1)
    for a in (-1, 1, np.int8(0), np.uint64(1), np.array(-1)):
        assert check_action(space, a) == int(a) and space.contains(np.int64(a))
    for a in (2, -2, True, np.bool_(False), 0.0, "0", None, np.array([0]), np.array(0.0)):
        with refused("action") as e:
            check_action(space, a)
        assert "-1 to 1" in str(e.value)


# ---- reset: the seed and the options ------------------------------------------------------------
BAD_OPTIONS = [  # (options, the name the message gives)
    ("abc", "options"),
    (["episode"], "options"),
    ({"foo": 1}, "'foo'"),
    ({"episodes": 0}, "did you mean 'episode'"),
    ({"episode": -1}, "options['episode']"),
    ({"episode": 10**6}, "options['episode']"),
    ({"episode": 1.5}, "options['episode']"),
    ({"episode": "0"}, "options['episode']"),
    ({"episode": True}, "options['episode']"),
    ({"repeat": -1}, "options['repeat']"),
    ({"repeat": 2**32}, "options['repeat']"),
    ({"repeat": "x"}, "options['repeat']"),
    ({"repeat": math.nan}, "options['repeat']"),
]


@pytest.mark.parametrize("options,name", BAD_OPTIONS, ids=[repr(o) for o, _ in BAD_OPTIONS])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_bad_reset_option_is_refused_naming_it(env_id, options, name):
    env = ready(env_id, "macro")
    with refused(name):
        env.reset(options=options)


@pytest.mark.parametrize("seed", [-1, 1.5, "0", True])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_bad_seed_is_refused_naming_it(env_id, seed):
    with refused("seed"):
        ready(env_id, "macro").reset(seed=seed)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_the_edges_of_the_reset_options_are_taken(env_id):
    env = make(env_id)
    u = env.unwrapped
    last = len(u.task.episodes) - 1
    _, info = env.reset(seed=np.int64(3), options={"episode": np.int64(last), "repeat": 2**32 - 1})
    assert (info["episode_index"], info["repeat"]) == (u.task.episodes[last].index, 2**32 - 1)
    _, info = env.reset(options={"episode": 0, "repeat": np.array(0)})
    assert info["repeat"] == 0
    _, info = env.reset(options={})
    assert 0 <= info["repeat"] < 2**31


def test_a_generated_building_outside_the_environments_range_is_refused():
    env = make(GENERATED, first_building=5, buildings=2)
    for b in (4, 7, -1, "5", 5.0):
        with refused("options['building']") as e:
            env.reset(options={"building": b})
        assert "5 to 6" in str(e.value)
    _, info = env.reset(options={"building": 6, "episode": 0})
    assert info["building"] == 6
    with refused("'episod'"):
        env.reset(options={"building": 6, "episod": 0})


# ---- constructor arguments ----------------------------------------------------------------------
COMMON = [("action_mode", "abc"), ("action_mode", None), ("observation_mode", 3), ("render_mode", "ansi"),
          ("success_bonus", math.nan), ("success_bonus", math.inf), ("success_bonus", -1.0), ("success_bonus", "100"),
          ("success_bonus", True), ("scenario", 3)]
DOOR_ARGS = [("window", -1), ("window", 10**6), ("window", MAX_WINDOW + 1), ("window", 2.5), ("window", "32"),
             ("window", True), ("max_candidates", "3"), ("max_candidates", 0), ("max_candidates", MAX_CANDIDATES + 1),
             ("max_candidates", 3.0), ("max_signs", 0), ("max_signs", -1), ("max_signs", MAX_SIGNS + 1),
             ("replan_on_signs", "no"), ("replan_on_signs", 1), ("max_distance", math.inf), ("max_distance", math.nan),
             ("max_distance", 0), ("max_distance", -5.0), ("max_distance", "500"), ("max_distance", 1e7)]
CASES = ([(env_id, k, v) for env_id in ENV_IDS for k, v in COMMON]
         + [(env_id, k, v) for env_id in (DOORS, GENERATED) for k, v in DOOR_ARGS]
         + [(INDIRECT, k, v) for k, v in [("masks", "Soft"), ("masks", 1), ("negative", "no"), ("negative", None),
                                          ("lattice", 0), ("lattice", math.nan), ("lattice", 100.0), ("lattice", "0.5")]]
         + [(GENERATED, k, v) for k, v in [("spacing", 0), ("spacing", math.nan), ("spacing", math.inf), ("spacing", 0.1),
                                           ("spacing", 100.0), ("spacing", "3"), ("buildings", 0), ("buildings", "3"),
                                           ("buildings", 2.5), ("first_building", -1), ("first_building", 2**32),
                                           ("layout", "maze"), ("layout", None), ("numbering", "normal")]])


@pytest.mark.filterwarnings("ignore:.*not in the possible render_modes")  # gymnasium.make's, before ours
@pytest.mark.parametrize("env_id,name,value", CASES, ids=[f"{e.split('/')[1]}-{k}={v!r}" for e, k, v in CASES])
def test_a_bad_constructor_argument_is_refused_naming_it(env_id, name, value):
    with refused(name):
        make(env_id, **{name: value})


@pytest.mark.parametrize("env_id,name,value", [(DOORS, "success_bonus", 10**400), (DOORS, "max_distance", 10**400),
                                                (GENERATED, "spacing", 10**400), (INDIRECT, "lattice", 10**400),
                                                (DOORS, "window", 10**5000), (GENERATED, "first_building", -10**5000)],
                         ids=lambda v: v.split("/")[-1] if isinstance(v, str) else f"{v.bit_length()} bits" if isinstance(v, int) else None)
def test_an_integer_too_large_for_a_float_is_refused_naming_the_argument(env_id, name, value):
    """An int past a float's range (10**400) was an OverflowError from math.isfinite, not the
    argument's ValueError; one past 4,300 digits raised again in the message's repr."""
    with refused(name) as e:
        make(env_id, **{name: value})
    assert "must be" in str(e.value)


def _snapshot(u) -> tuple:
    return (u.task, u.episode, u.repeat, u.state.steps, u.state.x, u.state.y, getattr(u, "building_seed", None),
            u._np_random.bit_generator.state["state"]["state"], dict(u._reset_options))


BAD_RESETS = [(dict(seed=5, options={"episode": 10**6}), "options['episode']"),
              (dict(seed=5, options={"repeat": -1}), "options['repeat']"),
              (dict(seed=5, options={"episode": 0, "repeat": "x"}), "options['repeat']")]


@pytest.mark.parametrize("bad,name", BAD_RESETS, ids=[n for _, n in BAD_RESETS])
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_refused_reset_changes_nothing(env_id, mode, bad, name):
    """A reset refused for one option leaves the environment as it was: its generator (it was
    reseeded before the options were checked), and for the generated family its building and the
    task its steps read (a building named with a bad episode was bound: a primitive step then read
    the new building's map with the old episode's robot, and a pickled copy replayed another run)."""
    env = make(env_id, action_mode=mode)
    u = env.unwrapped
    env.reset(seed=0, options={"building": 0} if env_id == GENERATED else None)
    env.step(0)
    before = _snapshot(u)
    with refused(name):
        env.reset(**bad)
    if env_id == GENERATED:
        with refused("options['episode']"):
            env.reset(seed=5, options={"building": 1, "episode": 10**6})
    assert _snapshot(u) == before
    if u.outcome is None:
        env.step(0)
    copy = pickle.loads(pickle.dumps(env))
    assert (copy.unwrapped.state.x, copy.unwrapped.state.y, copy.unwrapped.state.steps) == (u.state.x, u.state.y, u.state.steps)


def test_the_generated_buildings_end_at_the_largest_seed():
    with refused("buildings") as e:
        make(GENERATED, first_building=2**32 - 1, buildings=2)
    assert "from 1 to 1" in str(e.value)


def test_a_scenario_given_to_the_generated_family_is_refused_not_dropped():
    with refused("scenario"):
        make(GENERATED, scenario=str(ROOT / "configs/demo.yaml"))


@pytest.mark.parametrize("kwargs", [{"window": 0}, {"window": np.int64(MAX_WINDOW)}, {"max_candidates": 1},
                                    {"max_candidates": MAX_CANDIDATES}, {"max_signs": 1}, {"max_distance": 1e6},
                                    {"max_distance": np.float32(0.5)}, {"success_bonus": 0}, {"success_bonus": 1e6},
                                    {"replan_on_signs": np.bool_(False)}],
                         ids=lambda kw: ",".join(f"{k}={v!r}" for k, v in kw.items()))
def test_the_edges_of_the_door_arguments_are_taken(kwargs):
    env = make(DOORS, **kwargs)
    u = env.unwrapped
    n = 2 * u.R + 1
    assert env.observation_space["occupancy"].shape == (n, n)
    if n < 100:  # a reset fills the window (the largest is 4097 cells a side: built, not filled here)
        obs, _ = env.reset(seed=0)
        assert obs["occupancy"].shape == (n, n) and env.observation_space.contains(obs)


@pytest.mark.parametrize("kwargs", [{"lattice": 0.05}, {"lattice": 5}, {"masks": None, "negative": np.bool_(True)},
                                    {"masks": "hard"}])
def test_the_edges_of_the_indirect_arguments_are_taken(kwargs):
    env = make(INDIRECT, **kwargs)
    env.reset(seed=0)
    env.step(env.action_space.n - 1)


def test_the_checks_name_the_argument_and_the_range():
    assert check_number("w", np.array(3), 0, 5, integer=True) == 3 and check_number("d", np.float32(0.5), 0, 1) == 0.5
    with refused("w must be an integer from 0 to 5 (cells), not 6"):
        check_number("w", 6, 0, 5, integer=True, note="cells")
    with refused("d must be a finite number above 0 and at most 1e+06 m, not 0"):
        check_number("d", 0, 0.0, 1e6, above=True, unit="m")
    with refused("s must be an integer at least 0, not -1"):
        check_number("s", -1, 0, integer=True)
    assert check_flag("f", np.bool_(True)) is True
    with refused("f must be True or False"):
        check_flag("f", 0)
    assert check_options(None, ("episode",)) == {}
    with refused("options has an unknown key 'repeat'; valid keys: 'episode'"):
        check_options({"repeat": 0}, ("episode",))


# ---- the planners as policies -------------------------------------------------------------------
@pytest.mark.parametrize("name,said", [("nope", "name must be a registered door planner"), ("nsoss", "did you mean 'nsos'"),
                                       (3, "name must be"), ("lsos", "door planners: ")])
def test_a_policy_names_only_door_planners(name, said):
    with refused(said):
        PlannerPolicy(name)


def test_a_policy_answers_only_a_macro_door_search_waiting_for_a_choice():
    policy = PlannerPolicy("greedy")
    for env_id, mode in ((DOORS, "primitive"), ("semsearch/ObjectSearch-v0", "macro")):
        with refused("env must be a door-search environment"):
            policy(ready(env_id, mode))
    with refused("env has no choice to make"):
        policy(make(DOORS))  # not reset
    env = make(DOORS)
    env.reset(seed=0)
    assert 0 <= policy(env) < env.action_space.n
