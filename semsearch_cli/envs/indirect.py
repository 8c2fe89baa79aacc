"""``semsearch/IndirectSearch-v0``: find the target object (the monitor, A) in a room, helped by
the secondary objects, within the time limit.

The environment is the batch's indirect search (:class:`~semsearch_cli.tasks.indirect.IndirectSearch`
in the :class:`~semsearch_cli.tasks.loop.Session` loop, one step a camera frame); the agent answers
its decision points with the poses, as a planner's goals. An episode is a room, a start and a view scale of the scenario.

The robot's map of A is built as the methods of the paper build theirs: ``masks`` ``"soft"``
(default), ``"hard"`` or None (A's non-detections only), and ``negative`` (default True: the
secondary objects' non-detections count too), as ISC-PN-SM does.

Action modes
------------
``macro`` (default): ``Discrete(N x 8)``: a pose of a lattice every ``lattice`` metres over the
room (row-major from the room's origin) and one of 8 headings (0, 45, ..., 315 degrees); the robot
turns, drives at its speed and turns to the heading, sensing every frame, until the next re-plan
(``indirect.replan_every`` seconds, the pose reached, or a detection). ``info["action_mask"]``
holds the lattice points the robot can stand on in this room; another is taken as the nearest
that it can.

``primitive``: ``Discrete(4)``: 0 drive forward one frame at the robot's speed (where the robot fits),
1 and 2 turn left and right one frame at its turn rate, 3 wait a frame.

Observation (``observation_mode="dict"``)
-----------------------------------------
- ``belief``: float32 (H, W), the robot's p(A) on the room's grid (row 0 north);
- ``secondary``: float32 (n, 3), per secondary class in ``indirect.secondary`` order: [1 if
  detected so far, dx, dy (m, from the robot)];
- ``pose``: float32 (3,): x, y (m, room coordinates), heading (rad);
- ``time``: float32 (2,): seconds elapsed, the view scale (m).

``observation_mode="text"`` renders the same as a short text (the five likeliest cells of A);
``render_mode="rgb_array"`` draws the belief, the objects detected and the path.

Arguments and their ranges (anything else is a ``ValueError`` naming the argument, see
:mod:`~semsearch_cli.envs.base`): ``masks`` ``"soft"``, ``"hard"`` or None; ``negative`` a bool;
``lattice`` 0.05..5 m; ``success_bonus`` 0..1e6. Actions: an integer of the action space (macro
0..8N-1, primitive 0..3); -1 is refused, not read as the last lattice point.
"""

from __future__ import annotations

import math

import cv2
import gymnasium as gym
import numpy as np

from ..geometry import wrap_angle
from ..planners import Goal
from ..planners.indirect import Lattice
from .base import (BIG, TWO_PI, SearchEnv, box, check_choice, check_flag, check_number, clip_text, text_space)
from ..planners.text import indirect_fields, lattice_choices

class IndirectSearchEnv(SearchEnv):
    """Indirect search over an indirect scenario (see the module docstring for the spaces)."""

    kind = "indirect"
    env_name = "IndirectSearch"
    shipped = {"Quick": "indirect_quick"}

    def __init__(self, scenario, action_mode: str = "macro", observation_mode: str = "dict", render_mode=None,
                 success_bonus: float = 100.0, masks: str | None = "soft", negative: bool = True, lattice: float = 0.5):
        # checked before the scenario loads: a bad argument is named at once
        masks = check_choice("masks", masks, ("soft", "hard", None))
        negative = check_flag("negative", negative)
        lattice = check_number("lattice", lattice, 0.05, 5.0, unit="m")
        super().__init__(scenario, action_mode, observation_mode, render_mode, success_bonus)
        self._init_args.update(masks=masks, negative=negative, lattice=lattice)
        t = self.task
        self.masks, self.negative = masks, negative and masks is not None
        self.lattice = lattice
        self.secondary = list(t.spec.secondary)
        g = t.grids[0]  # the action space: the first room's lattice of points
        self.N = Lattice.over(g.frame, g.stand, g.room.size, lattice).n
        H, W = t.grids[0].stand.shape
        spaces = {"belief": gym.spaces.Box(0.0, 1.0, (H, W), np.float32),
                  "secondary": box([0, -BIG, -BIG], [1, BIG, BIG], (len(self.secondary), 3)),
                  "pose": box([-BIG, -BIG, -np.pi], [BIG, BIG, np.pi]),
                  "time": box([0.0, 0.0], [BIG, BIG])}
        self.action_space = gym.spaces.Discrete(self.N * 8 if action_mode == "macro" else 4)
        self.observation_space = gym.spaces.Dict(spaces) if observation_mode == "dict" else text_space()

    def agent_attributes(self) -> dict:
        # the map's kind, and re-plans on detections too
        return {"masks": self.masks, "negative": self.negative, "uses_map": True, "replan_on_detection": True}

    def _opened(self) -> None:
        self.grid = self.task.grids[self.episode.room]
        self.lattice_poses = Lattice.over(self.grid.frame, self.grid.stand, self.grid.room.size, self.lattice)
        self.standable, self.points = self.lattice_poses.standable, self.lattice_poses.points

    def _choice(self, a: int):
        x, y, heading = self.lattice_poses.pose(a)  # a point the robot cannot stand on: the nearest that it can
        return Goal(x, y, heading, {"action": a})

    def _motion(self, st, a: int) -> float:
        """0: drive one frame's distance along the heading (not off the standing cells); 1, 2:
        turn one frame's angle left, right; 3: wait."""
        spec = self.task.spec
        dt = 1.0 / spec.camera.fps
        if a == 0:
            x, y = st.x + spec.robot.speed * dt * math.cos(st.heading), st.y + spec.robot.speed * dt * math.sin(st.heading)
            _, _, r, c = self.grid.frame.point_to_cell(x, y)
            H, W = self.grid.stand.shape
            if 0 <= r < H and 0 <= c < W and self.grid.stand[r, c]:
                moved = math.hypot(x - st.x, y - st.y)
                st.x, st.y = float(x), float(y)
                return moved
        elif a in (1, 2):
            turn = (1 if a == 1 else -1) * math.radians(spec.robot.turn_rate) * dt
            st.heading = (st.heading + turn + math.pi) % TWO_PI - math.pi
        return 0.0

    def action_masks(self) -> np.ndarray:
        """(action_space.n,) bool. Macro: every heading of the lattice points the robot can stand
        on in this room; primitive: every action."""
        if self.action_mode == "primitive":
            return np.ones(4, bool)
        return self.lattice_poses.mask()

    def _info(self) -> dict:
        return {**super()._info(), "room": self.grid.room.name}

    def _belief(self) -> np.ndarray:
        return self.state.belief.inside()

    def _secondary(self) -> np.ndarray:
        st = self.state
        out = np.zeros((len(self.secondary), 3), np.float32)
        for k, cls in enumerate(self.secondary):
            if cls in self.search.seen:
                x, y = self.search.seen[cls]
                out[k] = (1.0, x - st.x, y - st.y)
        return out

    def _observe(self):
        st = self.state
        t_s = st.steps * self.search.dt  # as the search's planners read it
        if self.observation_mode == "text":
            return self._text(t_s)
        return {"belief": self._belief(), "secondary": self._secondary(),
                "pose": np.array([st.x, st.y, wrap_angle(st.heading)], np.float32),
                "time": np.array([t_s, float(self.episode.goal)], np.float32)}

    def _text(self, t_s: float) -> str:
        """The text observation (:func:`~semsearch_cli.planners.text.indirect_fields`, as the llm
        planner reads it): the goal, the frame, the pose, the objects detected, the five likeliest
        cells of the target, the choices and an answer line naming exactly the actions
        :meth:`action_masks` allows (macro: ranges of action numbers)."""
        st, spec = self.state, self.task.spec
        if self.action_mode == "macro":
            lat = self.lattice_poses
            choices = lattice_choices(len(lat.xs), len(lat.ys), lat.step, spec.replan_every)
        else:
            dt = 1.0 / spec.camera.fps
            turn = f"{spec.robot.turn_rate * dt:.3g} deg"
            choices = (f"Choices (each takes one camera frame, {dt:.2f} s): [0] drive {spec.robot.speed * dt:.3g} m "
                       f"forward, along your heading (not into an obstacle); [1] turn {turn} left (counter-clockwise); "
                       f"[2] turn {turn} right; [3] wait.")
        f = indirect_fields(spec.target, self.grid.room.name, float(self.episode.goal), t_s, spec.time_limit,
                            (st.x, st.y, st.heading), self.search.seen, self._belief(), self.grid.frame, choices,
                            self.action_masks())
        return clip_text(f["observation"])

    def render(self):
        if self.render_mode != "rgb_array" or self.episode is None:
            return None
        p = self._belief()
        g = (255 * (1.0 - p / max(float(p.max()), 1e-12))).astype(np.uint8)
        img = np.stack([g, g, np.full_like(g, 255)], axis=2)
        img[self.grid.blocked] = 0
        img = cv2.resize(img, None, fx=4, fy=4, interpolation=cv2.INTER_NEAREST)
        fr, st = self.grid.frame, self.state
        trail = np.asarray(st.trail)
        rr, cc = fr.to_index(trail[:, 0], trail[:, 1])
        cv2.polylines(img, [(np.stack([cc, rr], axis=1) * 4 + 2).astype(np.int32).reshape(-1, 1, 2)], False, (220, 40, 40), 1)
        for cls, (x, y) in self.search.seen.items():
            r, c = fr.to_index(x, y)
            cv2.circle(img, (int(c) * 4 + 2, int(r) * 4 + 2), 5, (0, 160, 0), -1)
        r, c = fr.to_index(st.x, st.y)
        cv2.circle(img, (int(c) * 4 + 2, int(r) * 4 + 2), 6, (200, 0, 200), -1)
        return img
