"""What every semsearch environment shares: the scenario it loads, the episode a reset draws, the
reward, the action mask (``info["action_mask"]``, int8), the robot-centred window of a grid, and
the text observation's charset and shared wording (the frame statement, the answer line).

An environment runs the batch's own simulator (the task a scenario builds, its sensors, belief and
step loop, :class:`~semsearch_cli.tasks.loop.Session`); only who answers each decision point changes:
the agent's action, where the batch asks the planner. A
reset draws an episode of the scenario's episode set (``episodes:`` section, or one per goal from
its start) and a repeat, from the environment's generator; ``options={"episode": k, "repeat": s}``
names them, and then the run is the one ``semsearch run`` records as episode ``k``, seed ``s``.

Reward: minus the metres travelled in the step, plus ``success_bonus`` (default 100) on the step
that finds the target. ``terminated`` when the target is found or the search has nowhere left to go
(``info["outcome"]``: found, stuck, not_found; also stuck after 100 actions in a row that take
no step of the loop); ``truncated`` at the scenario's budget
(``experiment.max_distance`` and the step limit; for indirect search its time limit).

Arguments are checked where they enter, each against its range, and refused with a ``ValueError``
that names the argument and the range (as Gymnasium's own environments refuse theirs), never
taken on silently nor left to fail deep inside: the constructors' arguments
(:func:`check_number`, :func:`check_flag`, :func:`check_choice`), ``reset``'s ``seed`` and
``options`` (:func:`check_options`; ``episode`` in 0..E-1 for a set of E episodes, ``repeat`` in
0..2^32-1, no other key) and every action (:func:`check_action`: an integer of the action space,
a Python ``int``, a numpy integer or a 0-d integer array; not a ``bool``, a float, a string or
None). ``success_bonus`` lies in 0..1e6.
"""

from __future__ import annotations

import math
import os
import warnings
import string
from collections.abc import Mapping
from pathlib import Path

import gymnasium as gym
import numpy as np

from ..config import load_scenario
from .. import shipped as shipped_scenarios
from ..errors import ScenarioError, did_you_mean
from ..tasks import Task, build_task
from ..tasks.decisions import Agent, DecisionPoint
from ..tasks.episodes import Episode, episode_seed

SUCCESS_BONUS = 100.0
BIG = 1e6  # bound of the observations' coordinates (m), as config.base.MAX_COORD, and of sign numbers
IDLE_ACTIONS = 100  # actions in a row that take no step (the agent choosing where it stands) before the episode is stuck
TEXT_CHARSET = frozenset(string.ascii_letters + string.digits + string.punctuation + " \n")
TEXT_LENGTH = 8192
MAX_REPEAT = 2**32 - 1  # the largest repeat reset(options=) names: one numpy seed word (the batch's seeds are 0..999,999)
_TASKS: dict[tuple, Task] = {}  # (resolved path, mtime) -> task: the envs of one process share a loaded scenario


def shipped(name: str) -> Path:
    """The path of a shipped scenario (``hotel``, ``demo``, ...: package data, so a wheel install
    finds it from any folder; see :mod:`semsearch_cli.shipped`)."""
    return shipped_scenarios.path(name, "gymnasium.make(..., scenario=)")


def load_task(scenario: str | Path, kind: str) -> Task:
    """The task of a scenario file (loaded once per process; ``shipped:NAME`` or a bare ``NAME``
    is a shipped scenario, see :func:`shipped`), checked to be of ``kind``."""
    if isinstance(scenario, str) and scenario.startswith("shipped:"):
        scenario = shipped(scenario.split(":", 1)[1])
    path = shipped_scenarios.scenario_file(scenario, "gymnasium.make(..., scenario=)").resolve()
    if not path.is_file():
        raise ScenarioError(str(scenario), "scenario", "no such scenario file")
    key = (str(path), path.stat().st_mtime_ns)
    task = _TASKS.get(key)
    if task is None:
        sc = load_scenario(path)
        task = build_task(sc, None, path)
        _TASKS[key] = task
    if task.kind != kind:
        raise ScenarioError(str(path), "kind", f"a {task.kind} scenario; this environment runs {kind} scenarios")
    return task


# ---- checking what comes in: arguments, reset options, actions --------------------------------
def _show(value) -> str:
    """A value as a message quotes it (at most 60 characters; an int past Python's 4,300 digits
    of text by its length: its repr raises)."""
    try:
        text = repr(value)
    except ValueError:
        return f"an integer of {value.bit_length()} bits" if isinstance(value, int) else f"a {type(value).__name__}"
    return text if len(text) <= 60 else text[:57] + "..."


def _num(x) -> str:
    """A bound as a message writes it: an int whole (4294967295), a float short (1e+06, 0.05)."""
    return str(x) if isinstance(x, int) else f"{x:g}"


def _scalar(value):
    """A numpy scalar or 0-d array of numbers (or bools) as the Python value it holds; anything
    else as it is: a 0-d array of objects (``np.array(1, dtype=object)``) is no number, as
    Gymnasium's ``Discrete.contains`` says, whatever it holds."""
    if isinstance(value, (np.ndarray, np.generic)) and value.ndim == 0 and value.dtype.kind in "biufc":
        return value.item()
    return value


def check_number(name: str, value, lo: float | None = None, hi: float | None = None, *, integer: bool = False,
                 above: bool = False, unit: str = "", note: str = "") -> int | float:
    """``value`` as a Python int (``integer``) or a finite float in ``lo..hi`` (``lo`` excluded
    with ``above``; None: no bound), or a ``ValueError`` naming ``name`` and the range (and
    ``note``, what the range is, in brackets).

    Python and numpy numbers and 0-d arrays are taken; a ``bool`` (``True`` reads as 1), a string
    (``"3"``), None, NaN and infinity are not, nor a float for an integer (``2.5`` would be cut to
    2 without a word; ``2.0`` is refused too, as ``Discrete`` refuses it)."""
    v = _scalar(value)
    if integer:
        ok = isinstance(v, int) and not isinstance(v, bool)
        what = "an integer"
    else:  # an int is finite however large (math.isfinite(10**400) overflows converting it to a float)
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and (isinstance(v, int) or math.isfinite(v))
        what = "a finite number"
    u = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        what += f" above {_num(lo)} and at most {_num(hi)}{u}" if above else f" from {_num(lo)} to {_num(hi)}{u}"
    elif lo is not None:
        what += f" {'above' if above else 'at least'} {_num(lo)}{u}"
    elif hi is not None:
        what += f" at most {_num(hi)}{u}"
    if ok:
        ok = (lo is None or (v > lo if above else v >= lo)) and (hi is None or v <= hi)
    if not ok:
        raise ValueError(f"{name} must be {what}{f' ({note})' if note else ''}, not {_show(value)}")
    return int(v) if integer else float(v)


def check_flag(name: str, value) -> bool:
    """``value`` (a bool or a numpy bool) as a bool, or a ``ValueError`` naming ``name``: a string
    such as ``"no"`` would read as True."""
    v = _scalar(value)
    if not isinstance(v, bool):
        raise ValueError(f"{name} must be True or False, not {_show(value)}")
    return v


def check_choice(name: str, value, choices) -> str | None:
    """``value`` if it is one of ``choices`` (strings, and None where None is a choice), else a
    ``ValueError`` naming ``name`` and the choices."""
    if (value is None or isinstance(value, str)) and value in choices:
        return value
    names = [repr(c) for c in choices]
    raise ValueError(f"{name} must be {', '.join(names[:-1])} or {names[-1]}, not {_show(value)}"
                     + (did_you_mean(value, [c for c in choices if c is not None]) if isinstance(value, str) else ""))


def check_options(options, keys) -> dict:
    """``reset``'s ``options`` (None or a mapping whose keys are among ``keys``) as a dict, or a
    ``ValueError`` naming ``options`` (and the unknown key) with the valid keys."""
    valid = ", ".join(repr(k) for k in keys)
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ValueError(f"options must be a dict (keys {valid}) or None, not {_show(options)}")
    for k in options:
        if k not in keys:
            raise ValueError(f"options has an unknown key {_show(k)}"
                             f"{did_you_mean(k, keys) if isinstance(k, str) else ''}; valid keys: {valid}")
    return dict(options)


def check_action(space: gym.spaces.Discrete, action) -> int:
    """``action`` as the int it is, if ``space`` (a ``Discrete``) contains it, else a ``ValueError``
    naming ``action`` and the range. As ``space.contains``: a Python int, a numpy integer or a 0-d
    integer array; unlike it, never a ``bool`` (``True`` is an int to Python, but an agent that
    answers a bool has a bug, not an action) and never an int too big for int64 (it overflows in
    ``contains``)."""
    a = _scalar(action)
    lo, hi = int(space.start), int(space.start) + int(space.n) - 1
    if not (isinstance(a, int) and not isinstance(a, bool) and lo <= a <= hi):
        raise ValueError(f"action must be an integer from {lo} to {hi} (the action space, Discrete({space.n}); "
                         f"info['action_mask'] marks those valid now), not {_show(action)}")
    return a


def ended(point) -> str | None:
    """The outcome :meth:`~semsearch_cli.tasks.loop.Session.start` or ``answer`` returned, or None
    when the episode waits at a decision point."""
    return None if isinstance(point, DecisionPoint) else point


def window(a: np.ndarray, r: int, c: int, radius: int, out: np.ndarray) -> np.ndarray:
    """The (2 radius + 1)^2 cells of ``a`` centred on (r, c), written into ``out`` (cells off the
    grid keep ``out``'s fill, which the caller sets)."""
    H, W = a.shape
    r0, r1, c0, c1 = r - radius, r + radius + 1, c - radius, c + radius + 1
    a0, a1, b0, b1 = max(r0, 0), min(r1, H), max(c0, 0), min(c1, W)
    if a0 < a1 and b0 < b1:
        out[a0 - r0:a1 - r0, b0 - c0:b1 - c0] = a[a0:a1, b0:b1]
    return out


COMPASS = ("east", "north-east", "north", "north-west", "west", "south-west", "south", "south-east")
TWO_PI = 2.0 * math.pi


def compass_move(st, a: int, step: float, cspace: np.ndarray, frame) -> float:
    """The primitive actions of a robot on a grid, applied to ``st`` (a RobotState): 0-7 move
    ``step`` m towards ``COMPASS[a]``, the heading turning to it (a move into a cell where the
    robot's disk does not fit, ``cspace`` False, leaves it where it is); 8 and 9 turn 45 degrees
    left and right. Returns the metres moved; the episode counts the step
    (:meth:`~semsearch_cli.tasks.base.OpenEpisode.take`)."""
    moved = 0.0
    if a < 8:
        ang = a * math.pi / 4
        x, y = st.x + step * math.cos(ang), st.y + step * math.sin(ang)
        _, _, r, c = frame.point_to_cell(x, y)
        st.heading = (ang + math.pi) % TWO_PI - math.pi
        if 0 <= r < frame.height and 0 <= c < frame.width and cspace[r, c]:
            st.x, st.y, moved = x, y, step
    else:
        st.heading = (st.heading + (math.pi / 4 if a == 8 else -math.pi / 4) + math.pi) % TWO_PI - math.pi
    return moved


def compass_step(st, a: int, step: float, cspace: np.ndarray, frame) -> float:
    """:func:`compass_move`, the step counted in ``st`` too (distance, steps, trail): for an
    environment that steps the robot itself (one written before 0.4.0, with its own ``_act``)."""
    moved = compass_move(st, a, step, cspace, frame)
    st.distance += moved
    st.steps += 1
    st.trail.append((st.x, st.y))
    return moved


def box(low, high, shape=None) -> gym.spaces.Box:
    """A float32 Box with finite bounds (per column when ``low`` and ``high`` are lists)."""
    if shape is None:
        return gym.spaces.Box(np.asarray(low, np.float32), np.asarray(high, np.float32), dtype=np.float32)
    return gym.spaces.Box(np.broadcast_to(np.asarray(low, np.float32), shape).copy(),
                          np.broadcast_to(np.asarray(high, np.float32), shape).copy(), dtype=np.float32)


def text_space() -> gym.spaces.Text:
    return gym.spaces.Text(max_length=TEXT_LENGTH, min_length=1, charset=TEXT_CHARSET)


def clip_text(text: str) -> str:
    """``text`` inside the Text space: characters outside its charset (a label's accents, a tab)
    as ``?``, at most ``TEXT_LENGTH`` characters. A text cut short keeps its last line (the
    answer line, which names the valid actions) when that line is short enough, the cut marked
    ``...``."""
    text = "".join(ch if ch in TEXT_CHARSET else "?" for ch in text) or "?"
    if len(text) <= TEXT_LENGTH:
        return text
    last = text.rsplit("\n", 1)[-1]
    if len(last) > TEXT_LENGTH // 2:
        return text[:TEXT_LENGTH - 4] + "\n..."
    return text[:TEXT_LENGTH - len(last) - 5] + "\n...\n" + last


# ---- the text observation's wording (what every kind shares is in planners/text.py) ------------
def compass_moves(step: float) -> str:
    """The primitive actions of :func:`compass_move`, as the text observation offers them."""
    return ("Moves (a move into a wall leaves you where you are): "
            + "; ".join(f"[{k}] {step:g} m {d}" for k, d in enumerate(COMPASS))
            + "; [8] turn 45 deg left (counter-clockwise); [9] turn 45 deg right.")


class SearchEnv(gym.Env):
    """The part of every semsearch environment that is not the kind's: scenario, episodes,
    reward, pickling, and the episode itself: the batch's run opened with the agent in the
    planner's seat (:meth:`_begin`), its primitive steps and its answers (:meth:`_act`), written
    once. Subclasses set ``kind`` and the spaces and implement :meth:`_choice` (the macro action
    as the kind's choice), :meth:`_motion` (a primitive action), :meth:`_observe` and
    :meth:`action_masks`; :meth:`agent_attributes`, :meth:`_opened` and :meth:`_settle` when the
    kind needs them."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}
    kind = ""
    reset_keys: tuple = ("episode", "repeat")  # the keys reset(options=) takes
    env_name = ""  # the id: semsearch/<env_name>-v0
    shipped: dict = {}  # building -> a shipped config: semsearch/<env_name>-<building>-v0

    def __init__(self, scenario: str | Path, action_mode: str = "macro", observation_mode: str = "dict",
                 render_mode: str | None = None, success_bonus: float = SUCCESS_BONUS):
        if not isinstance(scenario, (str, os.PathLike)):
            raise ValueError(f"scenario must be a scenario file's path or a shipped scenario's name, not {_show(scenario)}")
        check_choice("action_mode", action_mode, ("macro", "primitive"))
        check_choice("observation_mode", observation_mode, ("dict", "text"))
        check_choice("render_mode", render_mode, (*self.metadata["render_modes"], None))
        # a bonus below 0 would punish finding the target; 1e6 is past any building's metres
        success_bonus = check_number("success_bonus", success_bonus, 0.0, BIG)
        self._init_args = dict(scenario=scenario, action_mode=action_mode, observation_mode=observation_mode,
                               render_mode=render_mode, success_bonus=success_bonus)
        self.scenario = scenario
        self.task = load_task(scenario, self.kind)
        self.action_mode, self.observation_mode, self.render_mode = action_mode, observation_mode, render_mode
        self.success_bonus = float(success_bonus)
        self.episode: Episode | None = None
        self.repeat = 0
        self.outcome: str | None = None
        self._actions: list = []  # since the last reset: a pickled environment replays them

    # ---- gymnasium --------------------------------------------------------------------
    def check_reset(self, seed, options, task: Task | None = None) -> tuple[int | None, dict]:
        """``reset``'s ``seed`` and ``options`` checked, every one, before anything changes (a
        refused reset leaves the environment, its generator too, as it was): the seed, the keys,
        ``options['episode']`` against ``task``'s episodes (the environment's own by default) and
        ``options['repeat']``. Returns the seed (an int or None) and the options as a dict, the
        episode and the repeat given as ints."""
        seed = None if seed is None else check_number("seed", seed, 0, integer=True)
        options = check_options(options, self.reset_keys)
        eps = (task or self.task).episodes
        if options.get("episode") is not None:
            options["episode"] = check_number("options['episode']", options["episode"], 0, len(eps) - 1, integer=True,
                                              note=f"the scenario has {len(eps)} episodes")
        if options.get("repeat") is not None:
            options["repeat"] = check_number("options['repeat']", options["repeat"], 0, MAX_REPEAT, integer=True)
        return seed, options

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        seed, options = self.check_reset(seed, options)
        super().reset(seed=seed)
        eps = self.task.episodes
        k = options.get("episode")
        k = int(self.np_random.integers(len(eps))) if k is None else k
        s = options.get("repeat")
        self.repeat = int(self.np_random.integers(2**31 - 1)) if s is None else s
        self.episode = eps[k]
        self.outcome = None
        self._reset_options = {"episode": k, "repeat": self.repeat}
        self._actions = []
        self._idle = 0
        # the run's generator, as the batch seeds it (Task.open draws the same; an environment of
        # a kind from before 0.4.0 that starts its episode itself reads it here)
        self.rng = np.random.default_rng(episode_seed(self.episode, self.repeat, self.task.sc.experiment.base_seed))
        self._begin()
        # what the robot travelled inside reset() (a sweep before the first choice) is charged to
        # the first step, so that the return is always minus the distance (plus the bonus)
        self._unpaid = float(self.state.distance)
        # an episode that ends at its start (the goal read from the first pose) ends at the first
        # step, which travels nothing: gymnasium has no way to end an episode in reset()
        self._ended_at_reset, self.outcome = self.outcome, None
        return self._observe(), self._info()

    def step(self, action):
        if self.episode is None:
            raise RuntimeError("call reset() before step()")
        if self.outcome is not None:
            raise RuntimeError(f"the episode has ended ({self.outcome}); call reset()")
        action = check_action(self.action_space, action)
        self._actions.append(action)
        s0 = self.state.steps
        if self._ended_at_reset is not None:
            moved, outcome = 0.0, self._ended_at_reset
        else:
            moved, outcome = self._act(action)
        moved, self._unpaid = moved + self._unpaid, 0.0
        self._idle = self._idle + 1 if self.state.steps == s0 and outcome is None else 0
        if self._idle >= IDLE_ACTIONS:
            outcome = "stuck"
        self.outcome = outcome
        reward = -float(moved) + (self.success_bonus if outcome == "found" else 0.0)
        terminated = outcome in ("found", "stuck", "not_found", "error")
        truncated = outcome == "budget"
        return self._observe(), reward, terminated, truncated, self._info()

    def _info(self) -> dict:
        st = self.state
        # "episode_index", not "episode": Gymnasium's RecordEpisodeStatistics and Stable-Baselines3
        # keep their episode statistics (a dict) under info["episode"]
        # the mask as int8, as Gymnasium's own (Taxi) and Discrete.sample(mask) take it;
        # action_masks() stays bool, as sb3-contrib's MaskablePPO takes it
        return {"episode_index": self.episode.index, "repeat": self.repeat, "goal": str(self.episode.goal),
                "distance_m": float(st.distance), "steps": int(st.steps), "outcome": self.outcome or "",
                "shortest_m": float(self.episode.shortest_m), "action_mask": self.action_masks().astype(np.int8)}

    # ---- pickling: the arguments, the generator and the actions since the reset ----------
    def __getstate__(self):
        return {"args": self._init_args, "np_random": getattr(self, "_np_random", None),
                "np_random_seed": getattr(self, "_np_random_seed", None),
                "reset": getattr(self, "_reset_options", None), "actions": list(self._actions)}

    def __setstate__(self, state):
        with warnings.catch_warnings():  # a deprecated version warned when it was made, not again at each copy
            warnings.simplefilter("ignore", DeprecationWarning)
            self.__init__(**state["args"])
        if state["reset"] is not None:
            self.reset(options=state["reset"])
            for a in state["actions"]:
                self.step(a)
        self._np_random, self._np_random_seed = state["np_random"], state["np_random_seed"]

    # ---- the episode: the batch's own run, the agent in the planner's seat -------------------
    def _begin(self) -> None:
        """Open the drawn episode as the batch does (:meth:`~semsearch_cli.tasks.base.Task.open`:
        the same start, generator and search), the agent in the planner's seat
        (:class:`~semsearch_cli.tasks.decisions.Agent`, with the kind's :meth:`agent_attributes`),
        and run it to the first decision the agent answers (macro) or only sense at the start
        (primitive)."""
        self.run = self.run_task.open(None, self.episode, self.repeat, seat=Agent("agent", **self.agent_attributes()))
        self.state, self.rng = self.run.state, self.run.rng
        self._opened()
        if self.action_mode == "primitive":
            self.outcome = self.run.start(primitive=True)
        else:
            self.outcome = self._settle(self.run.start())
        self.search = self.run.search  # the kind's search (what an observation reads besides the robot's state)

    def _act(self, action) -> tuple[float, str | None]:
        """One action: a primitive move (the kind's :meth:`_motion`, then sensing) or the answer
        to the pending decision (the kind's :meth:`_choice`); (metres travelled, outcome or None)."""
        d0 = self.state.distance
        if self.action_mode == "primitive":
            out = self.run.take(lambda st: self._motion(st, action))
        else:
            out = self._settle(self.run.answer(self._choice(action)))
        return self.state.distance - d0, out

    @property
    def run_task(self) -> Task:
        """The task the episodes run in (the environment's own; door search: its budget)."""
        return self.task

    # ---- the kind's ---------------------------------------------------------------------
    def agent_attributes(self) -> dict:
        """The run attributes of the agent's seat that the kind's search reads (door search:
        ``replan_on_signs``)."""
        return {}

    def _opened(self) -> None:
        """The episode is open (``self.run``), not started: what the kind sets up for it."""

    def _settle(self, point) -> str | None:
        """The run from ``point`` (a decision point, or the outcome) to the next decision the agent
        answers: the outcome, or None. A kind may answer some points itself (door search: one with
        no frontier target has one answer)."""
        return ended(point)

    def _choice(self, action: int):  # pragma: no cover
        """The kind's choice that the (checked) macro action names."""
        raise NotImplementedError

    def _motion(self, st, action: int) -> float:  # pragma: no cover
        """Move ``st`` by the primitive action; the metres moved (the step is counted after)."""
        raise NotImplementedError

    def _observe(self):  # pragma: no cover
        raise NotImplementedError

    def action_masks(self) -> np.ndarray:  # pragma: no cover
        """(action_space.n,) bool: the actions valid now (``info["action_mask"]`` holds it as int8)."""
        raise NotImplementedError
