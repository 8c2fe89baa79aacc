"""One run: reset(seed), then steps in a fixed order until an outcome (SPEC 2-5).

Step order: sense (laser -> HIMM, door cameras -> reads) -> update belief (free cells, visited
kernel and density class) -> stop if the goal sign was read -> re-plan if an event asks (no path,
target reached, a sign reached ``min_reads`` for planners that use signs, ``replan_every`` metres
travelled) -> move one step along the path -> check the budget. When a re-plan finds no candidate
the robot first turns on the spot in three quarter turns, sensing after each (its laser covers
only 180 degrees ahead, so a start facing a dead end would otherwise see nowhere to go); only if
there is still no candidate is the run ``stuck``.
"""

from __future__ import annotations

import time
import zlib
from dataclasses import dataclass, field

import numpy as np

from .belief import Belief
from .config import Scenario
from .geometry import advance, wrap_angle
from .navigation import NAVIGATORS
from .planners import PlanContext, Variant
from .sensors.devices import DoorCamera, Laser
from .sensors.raycast import himm_update
from .world.scenario import World

STALL_STEPS = 50
MAX_RETRIES = 5


def run_seed(scenario: str, goal, seed: int, base_seed: int) -> np.random.SeedSequence:
    """The seed of one run, derived from (scenario, goal, seed) only: every planner variant sees
    the same start heading and sensor draws for seed k, whatever the worker count."""
    return np.random.SeedSequence([base_seed, seed, zlib.crc32(scenario.encode()), zlib.crc32(str(goal).encode())])


@dataclass
class RunResult:
    outcome: str  # found | budget | stuck
    distance_m: float
    steps: int
    decisions: int
    wall_s: float
    path: np.ndarray  # (n, 2) float32, m
    read_signs: list = field(default_factory=list)  # sign indices read at least once
    trace: list = field(default_factory=list)  # one dict per decision


class Episode:
    """A single search for ``goal`` by one planner variant in ``world``."""

    def __init__(self, world: World, sc: Scenario, variant: Variant, goal, seed: int, trace: bool = False,
                 recorder=None):
        """``recorder(belief, trail, distance, cands, decision)``, when given, is called at each
        decision (for replays); it must not change the belief."""
        self.world, self.sc, self.variant, self.goal, self.seed = world, sc, variant, goal, seed
        self.recorder = recorder
        self.goal_idx = world.signs.index_of(goal)
        self.laser = Laser(world, sc.laser)
        self.camera = DoorCamera(world, sc.door_camera)
        self.keep_trace = trace

    def run(self) -> RunResult:
        t0 = time.perf_counter()
        w, sc, fr = self.world, self.sc, self.world.frame
        rng = np.random.default_rng(run_seed(sc.name, self.goal, self.seed, sc.experiment.base_seed))
        heading = w.start_heading if w.start_heading is not None else float(rng.uniform(-np.pi, np.pi))
        x, y = w.start_xy
        belief = Belief(fr, sc.belief, sc.robot.radius)
        planner = self.variant.build()
        navigator = NAVIGATORS[sc.navigation.navigator]()
        uses_signs = getattr(planner, "replan_on_signs", False)
        H, W = fr.height, fr.width
        step_len = sc.robot.step
        max_steps = sc.experiment.max_steps or int(np.ceil(sc.experiment.max_distance / step_len * 1.5)) + 100
        path_r = path_c = None
        path_i = 0
        since_plan = 0.0
        distance = 0.0
        decisions = 0
        steps = 0
        stall = 0
        headings: list[float] = []
        trail = [(x, y)]
        read_signs: set[int] = set()
        trace: list[dict] = []
        outcome = None
        min_reads = sc.belief.min_reads
        bbox = np.empty(4, np.int64)

        def sense(x, y, heading, r, c):
            """Laser into HIMM, door cameras into reads; returns (goal read, a sign reached min_reads)."""
            v, u = fr.to_cell(x, y)
            thetas, dist, hit = self.laser.scan(float(v), float(u), heading, rng)
            bbox[:] = (H, -1, W, -1)
            himm_update(belief.cv, belief.seen, float(v), float(u), thetas, dist, hit,
                        sc.belief.himm_inc, sc.belief.himm_dec, sc.belief.himm_max, bbox)
            belief.refresh_free(bbox)
            found = event = False
            for i, label in self.camera.read(x, y, heading, rng):
                read_signs.add(i)
                if i == self.goal_idx and label == self.goal:
                    found = True
                if belief.reads.add(label, r * W + c, x, y, heading) == min_reads:
                    event = True
            return found, event

        looked_around = False
        while outcome is None:
            # 1. sense
            v, u = fr.to_cell(x, y)
            r, c = int(np.floor(v)), int(np.floor(u))
            found, event = sense(x, y, heading, r, c)
            # 2. belief
            belief.visit(r, c)
            headings.append(heading)
            if found:
                outcome = "found"
                break
            # 3. re-plan on events
            if path_r is None or path_i >= len(path_r) or since_plan >= sc.navigation.replan_every or (event and uses_signs):
                belief.refresh_derived()
                cands = belief.candidates()
                if len(cands) == 0 and not looked_around:
                    # nowhere to go with what the forward laser has seen: turn on the spot (three
                    # quarter turns, no distance travelled) and look again
                    looked_around = True
                    for _ in range(3):
                        heading = float(wrap_angle(heading + np.pi / 2))
                        f, e = sense(x, y, heading, r, c)
                        found, event = found or f, event or e
                    if found:
                        outcome = "found"
                        break
                    belief.refresh_derived()
                    cands = belief.candidates()
                ctx = PlanContext(belief, r, c, x, y, heading, self.goal, rng, headings)
                path_r = None
                for _ in range(MAX_RETRIES):
                    dec = planner.choose(ctx, cands)
                    if dec is None:
                        break
                    kept = dec.info.get("kept", False)
                    decisions += not kept
                    if self.recorder is not None and not kept:
                        self.recorder(belief, trail, distance, cands, dec)
                    if self.keep_trace and not kept:
                        tx, ty = fr.to_world(dec.row, dec.col)
                        trace.append({"step": steps, "distance_m": round(distance, 3), "x": round(float(x), 3), "y": round(float(y), 3),
                                      "heading_deg": round(float(np.degrees(heading)), 1),
                                      "target": [round(float(tx), 2), round(float(ty), 2)], "n_candidates": len(cands), **dec.info})
                    p = navigator.plan(belief, r, c, dec.row, dec.col)
                    if p is not None and len(p[0]) >= 2:
                        path_r, path_c = p
                        px, py = fr.to_world(path_r, path_c)
                        break
                    keep = ~((cands.rows == dec.row) & (cands.cols == dec.col))
                    if keep.all():
                        break
                    cands = cands.take(np.flatnonzero(keep))
                if path_r is None:
                    outcome = "stuck"
                    break
                path_i = 1
                since_plan = 0.0
                looked_around = False
            # 4. move one step along the path
            x, y, path_i, heading, moved = advance(px, py, path_i, x, y, heading, step_len)
            distance += moved
            since_plan += moved
            steps += 1
            trail.append((x, y))
            stall = stall + 1 if moved < 1e-9 else 0
            # 5. budget
            if stall >= STALL_STEPS:
                outcome = "stuck"
            elif distance >= sc.experiment.max_distance or steps >= max_steps:
                outcome = "budget"
        return RunResult(outcome, distance, steps, decisions, time.perf_counter() - t0,
                         np.asarray(trail, np.float32), sorted(read_signs), trace)
