"""What every semsearch environment shares: the scenario it loads, the episode a reset draws, the
reward, the action mask (``info["action_mask"]``, int8), the robot-centred window of a grid, and
the text observation's charset and shared wording (the frame statement, the answer line).

An environment runs the batch's own simulator (the task a scenario builds, its sensors, belief and
step loop, :class:`~semsearch_cli.tasks.loop.Stepper`); only who makes each decision changes. A
reset draws an episode of the scenario's episode set (``episodes:`` section, or one per goal from
its start) and a repeat, from the environment's generator; ``options={"episode": k, "repeat": s}``
names them, and then the run is the one ``semsearch run`` records as episode ``k``, seed ``s``.

Reward: minus the metres travelled in the step, plus ``success_bonus`` (default 100) on the step
that finds the target. ``terminated`` when the target is found or the search has nowhere left to go
(``info["outcome"]``: found, stuck, not_found; also stuck after 100 actions in a row that take
no step of the loop); ``truncated`` at the scenario's budget
(``experiment.max_distance`` and the step limit; for indirect search its time limit).
"""

from __future__ import annotations

import math
import string
from pathlib import Path

import gymnasium as gym
import numpy as np

from ..config import load_scenario
from .. import shipped as shipped_scenarios
from ..errors import ScenarioError
from ..tasks import Task, build_task
from ..tasks.episodes import Episode, episode_seed
from ..world.ground_truth import build_world

SUCCESS_BONUS = 100.0
BIG = 1e6  # bound of the observations' coordinates (m), as config.base.MAX_COORD, and of sign numbers
IDLE_ACTIONS = 100  # actions in a row that take no step (the agent choosing where it stands) before the episode is stuck
TEXT_CHARSET = frozenset(string.ascii_letters + string.digits + string.punctuation + " \n")
TEXT_LENGTH = 8192
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
        task = build_task(sc, build_world(sc, path.parent, str(path)), path)
        _TASKS[key] = task
    if task.kind != kind:
        raise ScenarioError(str(path), "kind", f"a {task.kind} scenario; this environment runs {kind} scenarios")
    return task


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


def compass_step(st, a: int, step: float, cspace: np.ndarray, frame) -> float:
    """The primitive actions of a robot on a grid, applied to ``st`` (a RobotState): 0-7 move
    ``step`` m towards ``COMPASS[a]``, the heading turning to it (a move into a cell where the
    robot's disk does not fit, ``cspace`` False, leaves it where it is); 8 and 9 turn 45 degrees
    left and right. Counts the step and the trail; returns the metres moved."""
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


# ---- the text observation's shared wording (read by language models) -----------------------
FRAME_TEXT = ("Frame: x points east and y north, in metres; distances are straight lines. Every angle is in "
              "degrees counter-clockwise from east in this fixed map frame (0 east, 90 north, 180 west, -90 "
              "south), not relative to your heading; a bearing is the direction from you to a thing.")


def deg(a: float) -> str:
    """An angle (rad) as whole degrees in (-180, 180], for the text observation."""
    d = round(math.degrees(a))
    return str(-((180 - d) % 360 - 180))


def spell(numbers) -> str:
    """Sorted action numbers in words: ``0, 1 or 64``; runs of three or more as ``4-9``."""
    runs: list[list[int]] = []
    for n in (int(v) for v in numbers):
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    items = []
    for a, b in runs:
        items += [str(a)] if a == b else [str(a), str(b)] if b == a + 1 else [f"{a}-{b}"]
    if not items:
        return "none"
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " or " + items[-1]


def answer_line(mask: np.ndarray) -> str:
    """The text observation's last line: the actions ``mask`` allows, and only those."""
    return f"Answer with one number: {spell(np.flatnonzero(mask))}."


def compass_moves(step: float) -> str:
    """The primitive actions of :func:`compass_step`, as the text observation offers them."""
    return ("Moves (a move into a wall leaves you where you are): "
            + "; ".join(f"[{k}] {step:g} m {d}" for k, d in enumerate(COMPASS))
            + "; [8] turn 45 deg left (counter-clockwise); [9] turn 45 deg right.")


class SearchEnv(gym.Env):
    """The part of every semsearch environment that is not the kind's: scenario, episodes,
    reward, pickling. Subclasses set ``kind`` and implement ``_begin`` (start the drawn episode),
    ``_act`` (one action: metres travelled, outcome or None) and ``_observe``."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}
    kind = ""
    env_name = ""  # the id: semsearch/<env_name>-v0
    shipped: dict = {}  # building -> a shipped config: semsearch/<env_name>-<building>-v0

    def __init__(self, scenario: str | Path, action_mode: str = "macro", observation_mode: str = "dict",
                 render_mode: str | None = None, success_bonus: float = SUCCESS_BONUS):
        if action_mode not in ("macro", "primitive"):
            raise ValueError(f"action_mode must be 'macro' or 'primitive', not {action_mode!r}")
        if observation_mode not in ("dict", "text"):
            raise ValueError(f"observation_mode must be 'dict' or 'text', not {observation_mode!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None")
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
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        options = options or {}
        eps = self.task.episodes
        k = options.get("episode")
        k = int(self.np_random.integers(len(eps))) if k is None else int(k)
        if not 0 <= k < len(eps):
            raise ValueError(f"options['episode'] = {k}: the scenario has episodes 0..{len(eps) - 1}")
        s = options.get("repeat")
        self.repeat = int(self.np_random.integers(2**31 - 1)) if s is None else int(s)
        self.episode = eps[k]
        self.outcome = None
        self._reset_options = {"episode": k, "repeat": self.repeat}
        self._actions = []
        self._idle = 0
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
        self.__init__(**state["args"])
        if state["reset"] is not None:
            self.reset(options=state["reset"])
            for a in state["actions"]:
                self.step(a)
        self._np_random, self._np_random_seed = state["np_random"], state["np_random_seed"]

    # ---- the kind's ---------------------------------------------------------------------
    def _begin(self) -> None:  # pragma: no cover
        raise NotImplementedError

    def _act(self, action) -> tuple[float, str | None]:  # pragma: no cover
        raise NotImplementedError

    def _observe(self):  # pragma: no cover
        raise NotImplementedError

    def action_masks(self) -> np.ndarray:  # pragma: no cover
        """(action_space.n,) bool: the actions valid now (``info["action_mask"]`` holds it as int8)."""
        raise NotImplementedError
