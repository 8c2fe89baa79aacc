"""The built-in door planners as policies of the macro environment.

    env = gymnasium.make("semsearch/DoorSearch-v1", scenario="configs/hotel.yaml", **policy.env_kwargs)
    policy = PlannerPolicy("nsos", alpha=0.9)
    obs, info = env.reset(options={"episode": 3, "repeat": 0}); policy.reset()
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(env)); done = terminated or truncated

The planner sees what it sees in the batch (the belief, the pose, every candidate) and its choice
becomes the candidate's slot (planners that choose among the frontier candidates: greedy, nsos,
geometric, draft; bvp picks cells of its own and cannot), so the run is the one ``semsearch run`` records for that episode and
seed (tests/test_envs.py checks it run for run). Call ``policy.reset()`` after each
``env.reset()``: the policy's first choice then gives the planner the episode and repeat, so the
llm planner replays its transcripts as a policy too (``PlannerPolicy("llm", replay=DIR)``).

A name that is not a registered door planner is a ``ValueError`` listing the door planners (with
"did you mean"); a parameter the planner does not take, or out of its range, is its parameters'
``ValidationError`` (a ``ValueError``) naming the parameter. Calling the policy on anything but a
macro door-search environment waiting for a choice is a ``ValueError`` naming ``env``.
"""

from __future__ import annotations

import numpy as np

from ..errors import PlannerError, did_you_mean
from ..planners import PLANNERS, DoorPlanner, Variant, load_entry_points
from .doors import DoorSearchEnv


class PlannerPolicy:
    """A registered door planner with fixed parameters, answering the macro environment."""

    def __init__(self, name: str, **params):
        if isinstance(name, str) and name not in PLANNERS:
            load_entry_points()
        if not (isinstance(name, str) and name in PLANNERS and issubclass(PLANNERS[name], DoorPlanner)):
            valid = sorted(n for n, c in PLANNERS.items() if issubclass(c, DoorPlanner))
            near = did_you_mean(name, valid) if isinstance(name, str) else ""
            raise ValueError(f"name must be a registered door planner{near}, not {repr(name)[:60]}; door planners: "
                             f"{', '.join(valid)} (semsearch planners lists them with their parameters)")
        self.variant = Variant(name, tuple(sorted(params.items())))
        self.reset()

    @property
    def env_kwargs(self) -> dict:
        """The environment arguments that give the batch's re-plan cadence for this planner."""
        return {"replan_on_signs": bool(getattr(self.planner, "replan_on_signs", False))}

    def reset(self) -> None:
        """A fresh planner for a new episode (the batch builds one per run)."""
        self.planner = self.variant.build()
        self._started = False

    def _start(self, u) -> None:
        """Give a planner that wants it (``start_run``) the run's identity, as the batch does: the
        scenario, the episode and the repeat of ``env.reset`` (the llm planner's replay finds its
        transcript by them)."""
        start = getattr(self.planner, "start_run", None)
        if callable(start):
            start({"scenario": u.task.sc.name, "kind": u.kind, "planner": self.variant.label, "goal": str(u.episode.goal),
                   "episode": int(u.episode.index), "seed": int(u.repeat), "stage": 0})
        self._started = True

    def __call__(self, env) -> int:
        u = getattr(env, "unwrapped", None)
        if not isinstance(u, DoorSearchEnv) or u.action_mode != "macro":
            raise ValueError(f"env must be a door-search environment in the macro action mode (semsearch/DoorSearch-*, "
                             f"action_mode='macro'), not {str(env)[:80]}")
        if getattr(u, "decision", None) is None:
            raise ValueError("env has no choice to make: call env.reset() first (an ended episode asks for none)")
        if not getattr(self, "_started", False):
            self._start(u)
        ctx, cands = u.decision
        u.rewind()  # the run's generator as the planner finds it in the batch (v1 drew greedy's tie to order the targets)
        dec = self.planner.choose(ctx, cands)
        if dec is None:
            return u.sweep_action
        k = np.flatnonzero((cands.rows[u.slots] == dec.row) & (cands.cols[u.slots] == dec.col))
        if k.size == 0:
            inside = ((cands.rows == dec.row) & (cands.cols == dec.col)).any()
            where = (f"is not among the {len(u.slots)} candidates the environment shows (max_candidates {u.K})" if inside
                     else "is not a frontier candidate (a planner that picks cells of its own, as bvp does, cannot run "
                          "as a policy of the macro environment)")
            raise PlannerError(f"planner {self.variant.label!r} chose the cell ({dec.row}, {dec.col}), which {where}")
        return int(k[0])
