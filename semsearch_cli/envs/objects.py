"""``semsearch/ObjectSearch-v0``: answer an object request (a class at an hour) on the recorded map.

The environment is the batch's object search (:class:`~semsearch_cli.tasks.objects.ObjectSearch`
in the :class:`~semsearch_cli.tasks.loop.Session` loop); the agent names the places to visit, as
an object planner does. An episode is one request of the scenario (``goal``: ``Static.mug@12``).

Action modes
------------
``macro`` (default): ``Discrete(P)``, one action per place of ``objects.places`` (in the
scenario's order): drive there on the recorded map, sensing at every step, and look around on
arrival (three quarter turns), as the object planners' targets are driven. ``info["action_mask"]``
holds every place but the one the robot has just looked around at; choosing that one, or a place
with no path, travels nothing and the agent chooses again.

``primitive``: ``Discrete(10)``: 0-7 move ``robot.step`` m towards east, north-east, ..., south-east
(a move into a cell the robot's disk does not fit in leaves it where it is), 8 and 9 turn 45 degrees;
the object camera senses after every action.

Observation (``observation_mode="dict"``)
-----------------------------------------
- ``places``: float32 (P, 5), per place: [dx, dy (m, from the robot), 1 if the camera has had it in
  view in this search, detections of the requested class there in the recorded log, those within
  an hour of the request's hour];
- ``hour``: float32 (1,), the request's hour;
- ``pose``: float32 (3,): x, y (m), heading (rad).

``observation_mode="text"`` renders the same as a short text; ``render_mode="rgb_array"`` draws the
map, the places (seen ones green) and the path.

Arguments are those every environment takes (``success_bonus`` 0..1e6; anything else is a
``ValueError`` naming the argument, see :mod:`~semsearch_cli.envs.base`). Actions: an integer of
the action space (macro 0..P-1, primitive 0..9); -1 or P is refused, not read as a place.
"""

from __future__ import annotations

import cv2
import gymnasium as gym
import numpy as np

from ..geometry import wrap_angle
from .base import (BIG, SearchEnv, box, clip_text, compass_moves, compass_move, text_space)
from ..planners.text import object_fields, place_history


class ObjectSearchEnv(SearchEnv):
    """Object search over an object scenario (see the module docstring for the spaces)."""

    kind = "objects"
    env_name = "ObjectSearch"
    shipped = {"Office": "office"}

    def __init__(self, scenario, action_mode: str = "macro", observation_mode: str = "dict", render_mode=None,
                 success_bonus: float = 100.0):
        super().__init__(scenario, action_mode, observation_mode, render_mode, success_bonus)
        t = self.task
        self.names = list(t.places)
        self.P = len(self.names)
        self.step_m = t.sc.robot.step
        spaces = {"places": box([-BIG, -BIG, 0, 0, 0], [BIG, BIG, 1, BIG, BIG], (self.P, 5)),
                  "hour": box([0.0], [24.0]),
                  "pose": box([-BIG, -BIG, -np.pi], [BIG, BIG, np.pi])}
        self.action_space = gym.spaces.Discrete(self.P if action_mode == "macro" else 10)
        self.observation_space = gym.spaces.Dict(spaces) if observation_mode == "dict" else text_space()
        self._cspace = t.world.cspace

    def _opened(self) -> None:
        t = self.task
        self.request = req = t.request(self.episode.goal)
        self.history = place_history(t.logs[req.case], req.cls, req.hour, self.names)

    @property
    def ctx(self):
        """The search's :class:`~semsearch_cli.planners.ObjectContext` (the places seen so far)."""
        return self.search.ctx

    def _choice(self, a: int):
        """Place ``a``, driven to on the recorded map, looked around on arrival; a place with no
        path, or the one the robot stands at, travels nothing and asks again, as a planner's
        target does."""
        x, y = self.task.places[self.names[a]]
        return x, y, {"place": self.names[a]}

    def _motion(self, st, a: int) -> float:
        return compass_move(st, a, self.step_m, self._cspace, self.task.world.frame)

    def action_masks(self) -> np.ndarray:
        """(action_space.n,) bool. Macro: every place but the one the robot has just looked around
        at (choosing it again would travel nothing and see nothing new); primitive: every action."""
        point = self.run.point if self.action_mode == "macro" else None
        return point.mask.copy() if point is not None else np.ones(self.action_space.n, bool)

    def _places(self) -> np.ndarray:
        st = self.state
        out = np.zeros((self.P, 5), np.float32)
        for k, n in enumerate(self.names):
            x, y = self.task.places[n]
            out[k, :3] = (x - st.x, y - st.y, float(n in self.ctx.seen_places))
        out[:, 3:] = self.history
        return out

    def _observe(self):
        st = self.state
        if self.observation_mode == "text":
            return self._text()
        return {"places": self._places(), "hour": np.array([self.request.hour], np.float32),
                "pose": np.array([st.x, st.y, wrap_angle(st.heading)], np.float32)}

    def _text(self) -> str:
        """The text observation (:func:`~semsearch_cli.planners.text.object_fields`, as the llm
        planner reads it): the request, the frame, the pose, the places (the choices, each ``[n]``,
        in the macro mode) and an answer line naming exactly the actions :meth:`action_masks`
        allows."""
        st, req = self.state, self.request
        here = self.search.here if self.action_mode == "macro" else None
        moves = None if self.action_mode == "macro" else compass_moves(self.step_m)
        f = object_fields(req.cls, req.hour, (st.x, st.y, st.heading), st.distance, self.names, self.task.places,
                          self.ctx.seen_places, self.history, here, self.action_masks(), moves)
        return clip_text(f["observation"])

    def render(self):
        if self.render_mode != "rgb_array" or self.episode is None:
            return None
        st, w = self.state, self.task.world
        fr = w.frame
        img = np.where(w.free[..., None], np.uint8(255), np.uint8(0)).repeat(3, axis=2)
        trail = np.asarray(st.trail)
        rr, cc = fr.to_index(trail[:, 0], trail[:, 1])
        cv2.polylines(img, [np.stack([cc, rr], axis=1).astype(np.int32).reshape(-1, 1, 2)], False, (220, 40, 40), 1)
        for n, (x, y) in self.task.places.items():
            r, c = fr.to_index(x, y)
            cv2.circle(img, (int(c), int(r)), 4, (0, 160, 0) if n in self.ctx.seen_places else (240, 150, 0), -1)
        r, c = fr.to_index(st.x, st.y)
        cv2.circle(img, (int(c), int(r)), 5, (200, 0, 200), -1)
        return img
