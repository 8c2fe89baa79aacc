"""``semsearch/DoorSearch-v1``: find the door sign with the goal's label, one decision at a time.

The environment is the batch's door search (:class:`~semsearch_cli.tasks.doors.DoorSearch` in
the :class:`~semsearch_cli.tasks.loop.Session` loop); the agent takes the planner's place, answering the
same decision points.

Versions
--------
``v1`` (``version=1``) shows a decision as the ``llm`` planner's model reads it: the same targets
in the same order and, in the text mode, the same text byte for byte
(:func:`~semsearch_cli.planners.text.door_fields`; with ``max_candidates=16``, the planner's
``max_targets``). ``v0`` (``version=0``, the constructor's default until 0.5.0) orders the targets
by straight-line distance and has a text of its own; it is deprecated since 0.4.0 and goes in
0.5.0 (a DeprecationWarning names v1).

Action modes
------------
``macro`` (default): ``Discrete(K + 1)``. At each re-plan of the batch (the path used up, every
``navigation.replan_every`` metres, and, with ``replan_on_signs``, when a sign reaches
``belief.min_reads``) the agent chooses one of the belief's frontier candidates
(``info["action_mask"]``, int8 as ``action_space.sample(mask)`` takes it; :meth:`action_masks`, bool,
for sb3-contrib's MaskablePPO); the navigator drives there until the next re-plan.

- v1: slots ``0..n-1`` hold the reachable candidates by their path length from the robot, greedy's
  choice first (its tie drawn from the run's generator, as greedy and the llm planner draw it:
  an agent that always answers 0 travels greedy's runs), at most K; action ``n``, right after the
  last target, looks at the nearest wall face no camera has read yet (the batch's completeness
  sweep, what it does when a planner returns None). A re-plan with no reachable candidate is not
  shown to the agent (the llm planner asks its model nothing there either).
- v0: slots ``0..K-1`` hold the K nearest candidates (straight-line), nearest first; action ``K``
  looks at a wall. When a chosen candidate has no path the agent is asked again at once (no
  distance travelled), with that candidate removed, as a planner is.

An action naming an empty slot is taken as the wall. Re-plans that find no candidate are not
shown to the agent: the robot turns on the spot or sweeps, as in the batch. A planner answering
the decision itself (:class:`~semsearch_cli.envs.policies.PlannerPolicy`) calls :meth:`rewind`
first, so that it finds the run's generator as the batch leaves it.

``primitive``: ``Discrete(10)``. Actions 0-7 move ``robot.step`` metres towards east, north-east,
north, ..., south-east (the heading turns to that direction; a move into a cell the robot's disk does
not fit in leaves it where it is); 8 and 9 turn 45 degrees left and right on the spot. The robot
senses after every action.

Observation (``observation_mode="dict"``)
-----------------------------------------
- ``occupancy``: uint8 (2R+1, 2R+1), the belief's map around the robot (row 0 north, the robot at
  the centre): 0 unknown (or off the map), 1 free, 2 occupied. R = ``window`` cells.
- ``explored``: uint8 (2R+1, 2R+1), 1 where the robot's visited kernel has passed.
- ``candidates`` (macro): uint8 (2R+1, 2R+1), k + 1 at the cell of candidate slot k, else 0.
- ``targets`` (macro): float32 (K, 4), per slot: [1 if the slot holds a candidate, dx, dy (m, from
  the robot, world axes), the branch direction theta_f (rad)]; v1: (K, 5), the fifth the path
  length (m) the targets are ordered by.
- ``signs``: float32 (S, 6), the signs read so far, nearest first: [1, 1 if its label shares the
  goal's prefix, its number (-1 for a label without digits), dx, dy (m), facing (rad)].
- ``goal``: float32 (2,): [the goal's number, 1 if it has a prefix or suffix (K202, 24D)].
- ``pose``: float32 (3,): x, y (m), heading (rad).

``observation_mode="text"`` renders the same as a short text (a ``Text`` space) for language-model
agents: positions and angles in the world frame (x east, y north; degrees counter-clockwise from
east), the choices numbered ``[n]``, and a last line that names exactly the actions the mask
allows. v1: the llm planner's text (the signs read, where the robot stood to read each; each
target's path length and bearing; in the primitive mode the moves in the targets' place); v0:
each sign's own position and facing, each target's straight-line distance. ``render_mode="rgb_array"`` draws the belief and the path (north up). ``max_distance`` (m)
replaces the scenario's budget, e.g. for shorter training episodes.

Arguments and their ranges (anything else is a ``ValueError`` naming the argument, see
:mod:`~semsearch_cli.envs.base`): ``window`` R, an integer 0..2048 (``MAX_WINDOW``: a window of
4097 cells a side, 410 m at 0.1 m cells, holds the whole Hotel from any pose; each of its grids is
16 MB); ``max_candidates`` K, 1..254 (the ``candidates`` grid holds k + 1 in a uint8);
``max_signs`` S, 1..10,000 (``MAX_SIGNS``, far more signs than a building has);
``replan_on_signs`` a bool; ``version`` 0 or 1; ``max_distance`` None or above 0 and at most 1e6 m (as the scenario's
``experiment.max_distance``); ``success_bonus`` 0..1e6. Actions: an integer of the action space
(macro 0..K, primitive 0..9).
"""

from __future__ import annotations

import math

import cv2
import gymnasium as gym
import numpy as np

from .. import deprecation
from ..geometry import wrap_angle
from ..planners import Decision
from ..planners.doors.greedy import path_order
from ..tasks.decisions import DecisionPoint
from ..world.labels import parse_label
from .base import (BIG, SearchEnv, box, check_flag, check_number, clip_text, compass_moves, compass_move,
                   text_space, window)
from ..planners.text import FRAME_TEXT, answer_line, deg, door_fields, door_targets

# The largest window radius (cells). 2048 gives a window of 4097 cells a side (410 m at 0.1 m
# cells: the whole Hotel, 133 m x 70 m, from any pose); each uint8 grid of it is 16 MB and an
# observation holds three. A radius of 10**6 asked for 3.6 TiB.
MAX_WINDOW = 2048
MAX_CANDIDATES = 254  # the candidates grid holds k + 1 (1..K) in a uint8
VERSIONS = (0, 1)  # 0: deprecated since 0.4.0 (straight-line order, a text of its own); 1: the llm planner's targets and text
MAX_SIGNS = 10_000  # rows of the signs observation: far more than a building has (the Hotel's layout at twice the scale: 469)


class DoorSearchEnv(SearchEnv):
    """Door-sign search over a door scenario (see the module docstring for the spaces)."""

    kind = "doors"
    env_name = "DoorSearch"  # registered as semsearch/DoorSearch-v1 (and -v0), and one id per shipped building:
    shipped = {"Hotel": "hotel", "Normal": "normal", "Inverse": "inverse", "KTH": "kth"}
    id_name = "DoorSearch"  # the id's name before its version, as a warning names it

    def __init__(self, scenario, action_mode: str = "macro", observation_mode: str = "dict", render_mode=None,
                 success_bonus: float = 100.0, window: int = 32, max_candidates: int = 64, max_signs: int = 32,
                 replan_on_signs: bool = True, max_distance: float | None = None, version: int = 0):
        # checked before the scenario loads: a bad argument is named at once
        version = check_number("version", version, 0, 1, integer=True, note="1 is the llm planner's targets and text")
        if version == 0:
            deprecation.warn(f"semsearch/{self.id_name}-v0 (version=0: targets ordered by straight-line distance, a text "
                             "of its own)", f"use semsearch/{self.id_name}-v1 (version=1), whose targets and text are "
                             "the llm planner's", since="0.4.0", until="0.5.0", stacklevel=3)
        window = check_number("window", window, 0, MAX_WINDOW, integer=True, note="cells; the window is 2 window + 1 a side")
        max_candidates = check_number("max_candidates", max_candidates, 1, MAX_CANDIDATES, integer=True)
        max_signs = check_number("max_signs", max_signs, 1, MAX_SIGNS, integer=True)
        replan_on_signs = check_flag("replan_on_signs", replan_on_signs)
        if max_distance is not None:  # as the scenario's experiment.max_distance
            max_distance = check_number("max_distance", max_distance, 0.0, BIG, above=True, unit="m", note="or None")
        super().__init__(scenario, action_mode, observation_mode, render_mode, success_bonus)
        self._init_args.update(window=window, max_candidates=max_candidates, max_signs=max_signs,
                               replan_on_signs=replan_on_signs, max_distance=max_distance, version=version)
        self.version = version
        self.max_distance = max_distance
        self.R, self.K, self.S = window, max_candidates, max_signs
        self.replan_on_signs = replan_on_signs
        n = 2 * self.R + 1
        grid = gym.spaces.Box(0, 2, (n, n), np.uint8)
        spaces = {"occupancy": grid, "explored": gym.spaces.Box(0, 1, (n, n), np.uint8),
                  "signs": box([0, 0, -1, -BIG, -BIG, -np.pi], [1, 1, BIG, BIG, BIG, np.pi], (self.S, 6)),
                  "goal": box([-1, 0], [BIG, 1]),
                  "pose": box([-BIG, -BIG, -np.pi], [BIG, BIG, np.pi])}
        if action_mode == "macro":
            spaces["candidates"] = gym.spaces.Box(0, self.K, (n, n), np.uint8)
            # v1: a fifth column, the path length (m) the targets are ordered by
            spaces["targets"] = (box([0, -BIG, -BIG, -np.pi], [1, BIG, BIG, np.pi], (self.K, 4)) if version == 0 else
                                 box([0, -BIG, -BIG, -np.pi, 0], [1, BIG, BIG, np.pi, BIG], (self.K, 5)))
            self.action_space = gym.spaces.Discrete(self.K + 1)
        else:
            self.action_space = gym.spaces.Discrete(10)
        self.observation_space = gym.spaces.Dict(spaces) if observation_mode == "dict" else text_space()
        self._buf = {k: np.zeros(s.shape, s.dtype) for k, s in spaces.items()}
        self._free = np.zeros((n, n), np.uint8)
        self.bind(self.task)
        self.decision = None  # (DoorContext, Candidates) while the agent is to choose (macro)

    def bind(self, task) -> None:
        """Run ``task`` from the next reset on, with what the steps read of it."""
        self.task, self.step_m, self._cspace = task, task.sc.robot.step, task.world.cspace
        self._facing = wrap_angle(task.world.signs.facing)  # the signs' facings in [-pi, pi), for the observation

    @property
    def budget(self) -> float:
        """m: ``max_distance`` when given, else the scenario's ``experiment.max_distance``."""
        return self.max_distance if self.max_distance is not None else self.task.sc.experiment.max_distance

    @property
    def step_limit(self) -> int:
        return self.task.max_steps(self.budget)

    @property
    def run_task(self):
        return self.task if self.max_distance is None else self.task.with_budget(self.max_distance)

    # ---- episode ----------------------------------------------------------------------
    def agent_attributes(self) -> dict:
        return {"replan_on_signs": self.replan_on_signs}  # the re-plan cadence the agent asks for

    def _opened(self) -> None:
        self.goal_label = parse_label(self.episode.goal)
        self.decision = None

    def _settle(self, point):
        """The episode from a decision point to the next one that offers the agent a choice (one
        with no frontier candidate, or in v1 none reachable, has one answer, the sweep, and is
        answered so, as the llm planner answers it), or to its end; returns the outcome, or None."""
        while isinstance(point, DecisionPoint) and not self._set_decision(point.observation, point.choices):
            point = self.run.answer(None)
        if not isinstance(point, DecisionPoint):
            self.decision = None
            return point
        return None

    def _set_decision(self, ctx, cands) -> bool:
        """The agent's choice, if it has one (else False): ``slots[k]`` is the candidate (its index
        in ``cands``) in action slot k. v1: the llm planner's targets
        (:func:`~semsearch_cli.planners.doors.greedy.path_order`: reachable ones by path length,
        greedy's choice first, its tie drawn from the run's generator as the planner draws it;
        ``path_m`` their lengths); v0: the K nearest to the robot (straight-line), nearest first."""
        self.decision = None
        if len(cands) == 0:
            return False
        self._rng_state = ctx.rng.bit_generator.state  # before the draw: rewind() gives it back
        if self.version == 0:
            xs, ys = self.task.world.frame.to_world(cands.rows, cands.cols)
            d = np.hypot(xs - self.state.x, ys - self.state.y)
            self.decision, self.slots = (ctx, cands), np.argsort(d, kind="stable")[:self.K]
            return True
        shown = path_order(ctx, cands, self.K)
        if shown is None:
            return False
        self.path_m, self.slots = shown
        self.decision = (ctx, cands)
        return True

    @property
    def sweep_action(self) -> int:
        """The action that looks at the nearest wall face not read yet: ``K`` in v0; in v1 the
        number after the last target, as the llm planner numbers it (``K`` names it too)."""
        return self.K if self.version == 0 or self.decision is None else len(self.slots)

    def rewind(self) -> None:
        """Give the run's generator back the state it had before this decision's targets were
        ordered (v1 draws greedy's tie, as the llm planner does): a planner that then answers the
        decision itself (:class:`~semsearch_cli.envs.policies.PlannerPolicy`) draws as it does in
        the batch. Nothing to give back in v0, which draws nothing."""
        if self.decision is not None:
            self.decision[0].rng.bit_generator.state = self._rng_state

    def _choice(self, a: int):
        """Slot ``a``'s candidate; the sweep action (or an empty slot, which the mask forbids):
        None, look at the nearest wall face not read yet. A candidate with no path is taken out
        and the agent asked again (travelling nothing), as the planner is in the batch; sweeps
        on the way travel too."""
        cands = self.decision[1]
        if 0 <= a < len(self.slots):
            j = int(self.slots[a])
            return Decision(int(cands.rows[j]), int(cands.cols[j]))
        return None

    def _motion(self, st, a: int) -> float:
        return compass_move(st, a, self.step_m, self._cspace, self.task.world.frame)

    # ---- what the agent sees ----------------------------------------------------------
    def action_masks(self) -> np.ndarray:
        """(action_space.n,) bool: the actions that name something (macro: the filled candidate
        slots and the sweep, v0 ``K``, v1 the action after the last target as the llm planner
        numbers it, n; primitive: every action)."""
        if self.action_mode == "primitive":
            return np.ones(10, bool)
        m = np.zeros(self.K + 1, bool)
        n = 0 if self.decision is None else len(self.slots)
        m[:n] = True
        m[self.K if self.version == 0 else n] = True
        return m

    def _info(self) -> dict:
        info = super()._info()
        info["n_candidates"] = 0 if self.decision is None else len(self.decision[1])
        return info

    def _signs(self):
        """(index, label, dx, dy, facing) of the signs read so far, nearest first."""
        st, sg = self.state, self.task.world.signs
        facing = self._facing
        out = [(i, lab, float(sg.x[i]) - st.x, float(sg.y[i]) - st.y, float(facing[i])) for i, lab in st.read_signs.items()]
        out.sort(key=lambda s: s[2] * s[2] + s[3] * s[3])
        return out

    def _observe(self):
        if self.observation_mode == "text":
            return self._text()
        st, b, fr, buf = self.state, self.state.belief, self.task.world.frame, self._buf
        _, _, r, c = fr.point_to_cell(st.x, st.y)
        occ = buf["occupancy"]
        occ.fill(0)
        window(b.seen, r, c, self.R, occ)
        free = self._free
        free.fill(0)
        window(b.free, r, c, self.R, free)
        occ[(occ > 0) & (free == 0)] = 2
        buf["explored"].fill(0)
        window(b.visited, r, c, self.R, buf["explored"])
        sg = buf["signs"]
        sg.fill(0.0)
        for k, (_, lab, dx, dy, facing) in enumerate(self._signs()[:self.S]):
            p = parse_label(lab)
            same = p is not None and self.goal_label is not None and p.prefix == self.goal_label.prefix
            sg[k] = (1.0, float(same), -1.0 if p is None else min(p.number, BIG), dx, dy, facing)
        g = self.goal_label
        buf["goal"][:] = (-1.0, 0.0) if g is None else (min(g.number, BIG), float(bool(g.prefix or g.suffix)))
        buf["pose"][:] = (st.x, st.y, (st.heading + math.pi) % (2 * math.pi) - math.pi)
        obs = {k: buf[k].copy() for k in ("occupancy", "explored", "signs", "goal", "pose")}
        if self.action_mode == "macro":
            cm, tg = buf["candidates"], buf["targets"]
            cm.fill(0)
            tg.fill(0.0)
            if self.decision is not None:
                cands = self.decision[1].take(self.slots)
                n = len(cands)
                xs, ys = fr.to_world(cands.rows, cands.cols)
                tg[:n, 0] = 1.0
                tg[:n, 1] = xs - st.x
                tg[:n, 2] = ys - st.y
                tg[:n, 3] = cands.theta
                if self.version == 1:
                    tg[:n, 4] = self.path_m[self.slots]
                rr, cc = cands.rows - r + self.R, cands.cols - c + self.R
                ok = (rr >= 0) & (rr < cm.shape[0]) & (cc >= 0) & (cc < cm.shape[1])
                cm[rr[ok], cc[ok]] = (np.arange(n) + 1)[ok]
            obs["candidates"], obs["targets"] = cm.copy(), tg.copy()
        return obs

    def _text(self) -> str:
        """The text observation: the goal, the frame, the pose, the signs read, the choices (each
        ``[n]``) and an answer line naming exactly the actions :meth:`action_masks` allows. v1:
        the llm planner's text (:func:`~semsearch_cli.planners.text.door_fields`), byte for byte."""
        st = self.state
        if self.version == 1:
            macro = self.action_mode == "macro"
            if macro and self.decision is not None:
                ctx, cands = self.decision
                targets = door_targets(ctx, self.path_m, self.slots, cands)
            else:
                targets = []
            return clip_text(door_fields(self.episode.goal, (st.x, st.y, st.heading), st.distance, st.belief, targets,
                                         moves=None if macro else compass_moves(self.step_m))["observation"])
        lines = [f"Goal: read the door sign {self.episode.goal}.", FRAME_TEXT,
                 f"You are at x {st.x:.1f} m, y {st.y:.1f} m, heading {deg(st.heading)} deg; travelled {st.distance:.1f} m."]
        signs = self._signs()[:self.S]
        if signs:
            lines.append("Signs read, nearest first (facing: the direction the sign's face points): " + "; ".join(
                f"{lab} at {math.hypot(dx, dy):.1f} m, bearing {deg(math.atan2(dy, dx))} deg, facing {deg(f)} deg"
                for _, lab, dx, dy, f in signs) + ".")
        else:
            lines.append("No sign read yet.")
        if self.action_mode == "macro":
            if self.decision is not None:
                # the direction of each target is theta_f, the planners' branch direction
                lines.append("Choices: drive to a frontier target (a point on the edge of the explored area), nearest "
                             "first, with the direction in which unexplored space goes on beyond it; or look at a wall:")
                cands = self.decision[1].take(self.slots)
                xs, ys = self.task.world.frame.to_world(cands.rows, cands.cols)
                dx, dy = xs - st.x, ys - st.y
                lines += [f"[{k}] {math.hypot(a, b):.1f} m away, bearing {deg(math.atan2(b, a))} deg, unexplored space "
                          f"towards {deg(t)} deg" for k, (a, b, t) in enumerate(zip(dx, dy, cands.theta))]
            else:
                lines.append("Choices:")
            lines.append(f"[{self.K}] look at the nearest wall face no camera has read yet")
        else:
            lines.append(compass_moves(self.step_m))
        lines.append(answer_line(self.action_masks()))
        return clip_text("\n".join(lines))

    def render(self):
        if self.render_mode != "rgb_array" or self.episode is None:
            return None
        st, b, fr = self.state, self.state.belief, self.task.world.frame
        img = np.full((fr.height, fr.width, 3), 128, np.uint8)
        img[b.seen & b.free] = (255, 255, 255)
        img[b.seen & ~b.free] = (0, 0, 0)
        img[b.visited & b.free] = (200, 225, 255)
        trail = np.asarray(st.trail)
        rr, cc = fr.to_index(trail[:, 0], trail[:, 1])
        pts = np.stack([cc, rr], axis=1).astype(np.int32).reshape(-1, 1, 2)
        cv2.polylines(img, [pts], False, (220, 40, 40), 1)
        if self.decision is not None:
            cands = self.decision[1].take(self.slots)
            for rc, cc_ in zip(cands.rows, cands.cols):
                cv2.circle(img, (int(cc_), int(rc)), 3, (240, 150, 0), -1)
        sg = self.task.world.signs
        for i in st.read_signs:
            r, c = fr.to_index(sg.x[i], sg.y[i])
            cv2.circle(img, (int(c), int(r)), 2, (0, 160, 0), -1)
        r, c = fr.to_index(st.x, st.y)
        cv2.circle(img, (int(c), int(r)), 4, (200, 0, 200), -1)
        return img
