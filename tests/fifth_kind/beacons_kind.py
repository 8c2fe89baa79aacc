"""A fifth kind of search, written as another package would write it (tests/test_fifth_kind.py
installs it beside semsearch, under the entry-point group ``semsearch.kinds``, and runs it through
``semsearch run``, ``report``, ``verify`` and a Gymnasium environment; nothing in semsearch knows
it).

Beacon search: posts stand on a map, each carrying a beacon with an id read within
``read_range`` metres; the robot knows where the posts are, not which carries the goal's id, and
visits them one after another until it reads the goal. Its files: the scenario model (its
section), the task (its world is the map, so it is an OnMapTask; its search and its decision
point), a planner protocol and one planner, its row column, a report section and an environment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Literal

import cv2
import gymnasium as gym
import numpy as np
import pandas as pd
import yaml
from pydantic import Field

from semsearch_cli.config import OnMap, Strict, register_kind
from semsearch_cli.errors import ScenarioError
from semsearch_cli.envs.base import SearchEnv, box
from semsearch_cli.navigation import KnownMap
from semsearch_cli.planners import Planner, register_planner
from semsearch_cli.report.document import write_table
from semsearch_cli.report.figures.paths import plot_scenario
from semsearch_cli.report.sections import Section, register_section
from semsearch_cli.runner import run_rows
from semsearch_cli.tasks import OnMapTask, Outcome, register_task
from semsearch_cli.tasks.decisions import Codec, DecisionPoint
from semsearch_cli.tasks.loop import drive


# ---- the scenario section ------------------------------------------------------------------------
class PostSpec(Strict):
    x: float
    y: float
    beacon: str = Field(pattern=r"^[A-Za-z0-9]+$")


@register_kind("beacons")
class BeaconScenario(OnMap):
    """Posts with beacons on a map; the goals are beacon ids."""

    section = "beacons"
    needs = "a beacons section (posts: x, y, beacon)"

    kind: Literal["beacons"] = "beacons"
    beacons: list[PostSpec] = Field(min_length=1)
    goals: list[str] = Field(min_length=1)
    read_range: float = Field(1.5, gt=0.0, le=20.0)


# ---- the planners' protocol and one planner --------------------------------------------------------
@dataclass
class BeaconContext:
    x: float
    y: float
    posts: np.ndarray  # (n, 2) m
    unread: np.ndarray  # (n,) bool
    rng: np.random.Generator


class BeaconPlanner(Planner):
    """Chooses the next post to visit (its index), or None."""

    task: ClassVar[str] = "beacons"

    def choose(self, ctx: BeaconContext) -> int | None:  # pragma: no cover
        raise NotImplementedError


@register_planner("nearest_post")
class NearestPost(BeaconPlanner):
    """The nearest post whose beacon is not read yet (straight line; ties at random)."""

    def choose(self, ctx):
        if not ctx.unread.any():
            return None
        d = np.hypot(ctx.posts[:, 0] - ctx.x, ctx.posts[:, 1] - ctx.y)
        d[~ctx.unread] = np.inf
        best = np.flatnonzero(d <= d.min() + 1e-9)
        return int(best[0] if len(best) == 1 else ctx.rng.choice(best))


CODEC = Codec(lambda k: None if k is None else [int(k)], lambda item: None if item is None else int(item[0]))


# ---- the search: sensing, the belief, the decision point ---------------------------------------------
class BeaconSearch:
    def __init__(self, task: "BeaconTask", planner, goal: str, rng):
        self.task, self.planner, self.goal, self.rng = task, planner, str(goal), rng
        self.read = np.zeros(len(task.posts), bool)
        self.decisions = 0

    def sense(self, st):
        near = np.hypot(self.task.posts[:, 0] - st.x, self.task.posts[:, 1] - st.y) <= self.task.sc.read_range
        self.read |= near
        return bool((near & (self.task.ids == self.goal)).any()), False

    def update(self, st):
        pass

    def replan_due(self, path_done, since_plan, event):
        return path_done

    def plan(self, st):
        fr = self.task.world.frame
        while True:
            ctx = BeaconContext(st.x, st.y, self.task.posts, ~self.read, self.rng)
            k = yield DecisionPoint("beacons", ctx, self.task.posts, ~self.read, lambda: self.planner.choose(ctx), CODEC,
                                    self.rng)
            if k is None:
                return "not_found"
            self.decisions += 1
            p = self.task.known.path_to(st.x, st.y, *self.task.posts[k])
            if p is None or len(p[0]) < 2:  # no way there, or already there: counted as read
                self.read[k] = True
                continue
            return fr.to_world(p[0], p[1])


@register_task
class BeaconTask(OnMapTask):
    kind = "beacons"
    planner_kind = "beacons"
    noun = "a beacon of a given id, among posts on a map"
    records = ("posts_read",)
    columns = ("posts_read",)

    def __init__(self, sc, world, path):
        super().__init__(sc, world, path)
        self.posts = np.array([[b.x, b.y] for b in sc.beacons], float)
        self.ids = np.array([b.beacon for b in sc.beacons])
        self.known = KnownMap(world)

    @classmethod
    def build(cls, sc, world, path):
        task = cls(sc, world, path)
        for k, g in enumerate(sc.goals):
            if g not in set(task.ids):
                raise ScenarioError(task.file, f"goals[{k}]", f"no post carries the beacon {g}")
        task.shortest = {g: task.shortest_from(g, *world.start_xy) for g in sc.goals}
        task.variants()
        return task

    def goal_cells(self, goal) -> np.ndarray:
        fr, w = self.world.frame, self.world
        rows, cols = np.mgrid[0:fr.height, 0:fr.width]
        x, y = fr.to_world(rows, cols)
        out = np.zeros(w.reach.shape, bool)
        for px, py in self.posts[self.ids == str(goal)]:
            out |= np.hypot(x - px, y - py) <= self.sc.read_range
        return out & w.reach

    def steps(self, state, planner, goal, rng, observer=None):
        search = BeaconSearch(self, planner, goal, rng)
        d0, s0 = state.distance, state.steps
        outcome = yield from drive(search, state, self.sc.robot.step, self.sc.experiment.max_distance, self.max_steps())
        return Outcome(outcome, state.distance - d0, state.steps - s0, search.decisions,
                       record={"posts_read": int(search.read.sum())}), state

    @classmethod
    def example(cls, folder: Path, planner: str) -> Path:
        return write_example(folder, planner)


def write_example(folder: Path, planner: str = "nearest_post") -> Path:
    """A 12 m x 8 m room with six posts, goals B and E, from the south-west corner."""
    folder.mkdir(parents=True, exist_ok=True)
    img = np.full((80, 120), 255, np.uint8)
    img[0, :] = img[-1, :] = img[:, 0] = img[:, -1] = 0
    img[20:60, 58:62] = 0  # a wall in the middle
    cv2.imwrite(str(folder / "map.png"), img)
    posts = [(2.0, 6.0, "A"), (10.0, 6.0, "B"), (10.0, 2.0, "C"), (4.0, 2.0, "D"), (7.0, 7.0, "E"), (3.0, 4.0, "F")]
    d = {"name": "beacons-example", "kind": "beacons", "map": {"image": "map.png", "resolution": 0.1},
         "start": {"x": 1.0, "y": 1.0, "heading": 0.0},
         "beacons": [{"x": x, "y": y, "beacon": b} for x, y, b in posts], "goals": ["B", "E"],
         "planners": [{"name": planner}], "experiment": {"seeds": 2, "max_distance": 200.0}}
    path = folder / "scenario.yaml"
    path.write_text(yaml.safe_dump(d, sort_keys=False))
    return path


# ---- the report section ------------------------------------------------------------------------------
def beacon_table(runs: pd.DataFrame) -> pd.DataFrame:
    g = run_rows(runs).groupby(["goal", "planner"], sort=False)
    return g.agg(n=("distance_m", "size"), success_rate=("success", "mean"), mean_m=("distance_m", "mean"),
                 posts_read=("posts_read", "mean")).round(3).reset_index()


def section(doc, parts, out, formats, replay, notes):
    runs = pd.concat([p.runs for p in parts], ignore_index=True)
    table = beacon_table(runs)
    write_table(out / "tables", "beacons", table, formats)
    doc.heading(2, f"Beacon search ({len(run_rows(runs))} runs)")
    doc.para("Per goal and planner: runs, success rate, mean distance (m) and mean posts read.")
    doc.table(table)


def console(runs):
    return [("beacon search: success, distance (m) and posts read", beacon_table(runs))]


def show(loaded, out):
    plot_scenario(loaded.world, [], f"{loaded.sc.name}: {len(loaded.task.posts)} posts", out)


register_section(Section("beacons", section, console, show))


# ---- the Gymnasium environment: a thin adapter over the same decision points --------------------------
class BeaconSearchEnv(SearchEnv):
    """Action: the post to visit next; observation: each post's offset and whether it is read."""

    kind = "beacons"
    env_name = "BeaconSearch"

    def __init__(self, scenario, **kwargs):
        super().__init__(scenario, **kwargs)
        n = len(self.task.posts)
        self.action_space = gym.spaces.Discrete(n)
        self.observation_space = gym.spaces.Dict({"posts": box([-1e6, -1e6, 0], [1e6, 1e6, 1], (n, 3)),
                                                  "pose": box([-1e6, -1e6, -math.pi], [1e6, 1e6, math.pi])})

    def _choice(self, action):
        return int(action)  # the post to visit

    def action_masks(self):
        p = self.run.point
        return p.mask.copy() if p is not None else np.ones(self.action_space.n, bool)

    def _observe(self):
        st = self.state
        posts = np.column_stack([self.task.posts - (st.x, st.y), self.search.read]).astype(np.float32)
        heading = (st.heading + math.pi) % (2 * math.pi) - math.pi
        return {"posts": posts, "pose": np.array([st.x, st.y, heading], np.float32)}


gym.register(id="beacons/BeaconSearch-v0", entry_point=BeaconSearchEnv)
