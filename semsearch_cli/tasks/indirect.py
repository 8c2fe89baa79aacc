"""Indirect search with secondary objects (Loncomilla et al. 2018): find the main object A
in a room, helped by the secondary objects the semantic camera sees.

Goals are view scales (m): how far A can be detected (the secondary objects always at
``camera.secondary_range``). An episode is one room at one scale, from a start in that room (the
room's own start, or starts drawn per room: :meth:`IndirectTask.build_episodes`), so the rooms are
used equally often, as in the paper. One step of the loop is one camera frame
(``camera.fps``): (1) the camera detects (Section 4.2-4.3), (2) the map of A takes the frame in
(Section 3.1: A not seen; each secondary object seen or, for PN planners, not seen; a planner
without masks folds in A's non-detections only), (3) A detected ends the search, (4) the planner
re-plans every ``replan_every`` s, when its goal is reached, and (ISUP) on a frame that detects a
secondary object, (5) the robot turns at ``turn_rate`` and drives at ``speed`` (turning on the spot
until it faces its next waypoint), (6) the search ends at ``time_limit``.

The shortest path of a run (for SPL): the geodesic, on the cells the robot can stand on, from the
start to the nearest cell from which A is in view at the goal's scale for some heading and the
detection table gives a chance of detecting it (A is not seen from every side).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage
import yaml

from ..belief.indirect import IndirectBelief, relation_mask
from ..config.indirect import CATEGORIES, SIDE_BLIND_TABLES
from ..errors import ScenarioError, did_you_mean
from ..geometry import GridFrame, wrap_angle
from ..kernels.grid import GridSearch
from ..kernels.raycast import line_of_sight
from ..planners import Goal, IndirectContext, Variant
from ..sensors.indirect import SemanticCamera, YawMemory
from ..world.rooms import OBJECT_GAP, WALL_MARGIN, Room, estimate_relations, generate_rooms, read_rooms
from .base import Event, Observer, Outcome, RobotState, RunResult, Task, checked_point, register_task
from .episodes import Episode, check_hash, draw_starts, given_episodes, label_words
from .decisions import Codec, DecisionPoint
from .loop import drive


def _encode(goal: Goal):
    """An indirect choice in a few bytes: ``[x, y, heading]`` (m, rad), ``[x, y]`` without a
    heading to turn to."""
    xy = [float(goal.x), float(goal.y)]
    return xy if goal.heading is None else [*xy, float(goal.heading)]


def _decode(item) -> Goal:
    if not isinstance(item, list) or len(item) not in (2, 3) or not all(isinstance(v, (int, float)) for v in item):
        raise ValueError("expected [x, y] or [x, y, heading]")
    return Goal(float(item[0]), float(item[1]), float(item[2]) if len(item) == 3 else None, {})


INDIRECT_CODEC = Codec(_encode, _decode)


@dataclass
class RoomGrid:
    """A room on the probability map's grid: its frame, obstacle cells, the cells the robot's
    centre may stand on, and a reusable path search."""

    room: Room
    frame: GridFrame
    blocked: np.ndarray
    stand: np.ndarray
    cost: np.ndarray
    search: GridSearch
    full_from: tuple = (-1, -1, -1)  # (row, col, search generation) of the last whole-room search

    @classmethod
    def of(cls, room: Room, res: float, radius: float, bodies: dict[str, float] | None = None) -> "RoomGrid":
        """``bodies``: class -> diameter (m) of the objects that block the robot's path (not its
        view: objects hide each other by Algorithm 4); none by default."""
        fr = room.frame(res)
        blocked = room.blocked(fr)
        body = blocked.copy()
        if bodies:
            cx, cy = fr.to_world(np.arange(fr.height)[:, None], np.arange(fr.width)[None, :])
            for cls_name, t in room.objects.items():
                body |= np.hypot(cx - t.x, cy - t.y) <= bodies.get(cls_name, 0.0) / 2
        walls = np.pad(body, 1, constant_values=True)
        clear = ndimage.distance_transform_edt(~walls)[1:-1, 1:-1] * res
        stand = clear >= radius
        r, c = fr.to_index(*room.start[:2])
        if not (0 <= r < fr.height and 0 <= c < fr.width):
            raise ValueError(f"{room.name}: the start lies outside the room")
        stand[r, c] = True  # the robot stands where it starts
        return cls(room, fr, blocked, stand, np.ones(stand.shape, np.float32), GridSearch(stand.shape))

    def lengths_from(self, x: float, y: float) -> np.ndarray:
        """(H, W) path length (m) over the standing cells from (x, y); inf where unreachable."""
        r, c = (int(v) for v in self.frame.to_index(x, y))
        r, c = min(max(r, 0), self.frame.height - 1), min(max(c, 0), self.frame.width - 1)
        self.search.run(self.stand, self.cost, r, c, np.zeros(0, np.int64), np.zeros(0, np.int64), 0)
        self.full_from = (r, c, self.search.gen)  # a whole-room search: path() can backtrack in it
        return self.search.length_grid() * self.frame.res

    def path(self, x: float, y: float, tx: float, ty: float):
        """Waypoints (xs, ys) m from (x, y) to (tx, ty) over the standing cells, pulled taut by
        line of sight (any-angle, as the paper's theta*); None when unreachable."""
        fr = self.frame
        r, c = (int(v) for v in fr.to_index(x, y))
        tr, tc = (int(v) for v in fr.to_index(tx, ty))
        H, W = self.stand.shape
        if not (0 <= tr < H and 0 <= tc < W and self.stand[tr, tc]):
            return None
        r, c = min(max(r, 0), H - 1), min(max(c, 0), W - 1)
        reuse = self.full_from == (r, c, self.search.gen) and self.search.settled(tr, tc)
        if not reuse and self.search.run(self.stand, self.cost, r, c, np.array([tr]), np.array([tc]), 1) < 1:
            return None
        rows, cols = self.search.path(tr, tc)
        occ = ~self.stand
        keep = [0]
        k = 0
        while k < len(rows) - 1:
            j = len(rows) - 1
            while j > k + 1 and not line_of_sight(occ, rows[k] + 0.5, cols[k] + 0.5, rows[j] + 0.5, cols[j] + 0.5, 0.0):
                j -= 1
            keep.append(j)
            k = j
        xs, ys = fr.to_world(rows[keep], cols[keep])
        xs, ys = np.asarray(xs, float), np.asarray(ys, float)
        xs[0], ys[0], xs[-1], ys[-1] = x, y, tx, ty
        return xs, ys


@dataclass
class Rooms:
    """The world of indirect search: its rooms, each on the probability map's grid (one size)."""

    grids: list[RoomGrid]
    training: list[Room] | None = None  # indirect.learned's rooms, drawn as the test rooms, where relations are learned

    @property
    def rooms(self) -> list[Room]:
        return [g.room for g in self.grids]


@dataclass(frozen=True, kw_only=True)
class IndirectGoal(Event):
    """An indirect planner's goal at a re-plan (every re-plan; ``new`` when it changed, and only
    those are traced): at ``step`` (``t_s`` s of simulated time), from the pose (``x``, ``y`` m,
    ``heading`` rad), the :class:`~semsearch_cli.planners.Goal` ``goal``; ``p`` the probability
    map of A as it is now (copy what you keep), ``p0`` the outside cell's probability, ``trail``
    the path so far ([(x, y)] m) and ``seen`` the secondary objects seen (class -> (x, y) m)."""

    step: int
    t_s: float
    x: float
    y: float
    heading: float
    goal: Goal
    new: bool
    p: np.ndarray
    p0: float
    trail: list
    seen: dict

    @property
    def traced(self) -> bool:
        return self.new

    def frame(self) -> dict:
        return {"p": self.p.copy(), "p0": float(self.p0), "trail": np.asarray(self.trail, float), "t": float(self.t_s),
                "goal": (float(self.goal.x), float(self.goal.y)), "seen": dict(self.seen)}

    def row(self) -> dict:
        return {"step": self.step, "t_s": round(self.t_s, 2), "x": round(self.x, 3), "y": round(self.y, 3),
                "heading_deg": round(math.degrees(self.heading), 1),
                "target": [round(self.goal.x, 3), round(self.goal.y, 3)], **self.goal.info}


class IndirectSearch:
    """One search (a :class:`~semsearch_cli.tasks.loop.Search`)."""

    def __init__(self, task: "IndirectTask", grid: RoomGrid, planner, scale: float, rng, observer: Observer | None = None):
        self.task, self.grid, self.planner, self.scale, self.rng = task, grid, planner, scale, rng
        self.observer = observer
        spec = task.spec
        self.dt = 1.0 / spec.camera.fps
        self.replan_frames = max(1, int(round(spec.replan_every * spec.camera.fps)))
        self.ranges = {spec.target: scale, **{c: spec.camera.secondary_range for c in spec.secondary}}
        self.masks = task.masks_for(planner.masks) if planner.masks and planner.uses_map else {}
        self.coarse_masks = task.masks_for(planner.masks, task.spec.coarse) if self.masks else None
        self.negative = planner.negative and bool(self.masks)
        self.seen: dict[str, tuple[float, float]] = {}
        self.latest: set[str] = set()
        self.in_view_before: set[str] = set()
        self.frames_since_plan = 0
        self.since_plan: list = []
        self.final_heading: float | None = None
        self.goal: Goal | None = None
        self.decisions = 0
        self.D = np.zeros((grid.frame.height, grid.frame.width))
        self.memory: dict[str, YawMemory] = {}
        self.occ = grid.blocked if grid.blocked.any() else None
        # the grid of the secondary objects' non-detections (coarser by spec.coarse)
        q = spec.coarse if self.masks else 1
        fr = grid.frame
        self.neg_frame = GridFrame(fr.res * q, fr.origin_x, fr.origin_y, fr.height // q, fr.width // q)
        blocked_q = grid.blocked.reshape(fr.height // q, q, fr.width // q, q).any(axis=(1, 3))
        self.neg_occ = blocked_q if blocked_q.any() else None

    def new_belief(self) -> IndirectBelief:
        g, spec = self.grid, self.task.spec
        prior = (~g.blocked).astype(float)
        p_out = spec.p_outside if spec.p_outside is not None else 1.0 / (prior.sum() + 1.0)
        coarse = spec.coarse if self.masks else 1
        return IndirectBelief(g.blocked.shape, self.masks, prior, p_out, coarse, self.coarse_masks)

    # ---- the loop's steps -------------------------------------------------------------------
    def sense(self, st: RobotState):
        spec = self.task.spec
        room = self.grid.room
        got = self.task.camera.frame(room, st.x, st.y, st.heading, self.ranges, self.rng)
        self.latest = got - {spec.target}
        for cls in self.latest:
            t = room.objects[cls]
            self.seen[cls] = (t.x, t.y)  # the camera gives the object's position
        if spec.noise.false_positive or spec.noise.position_sd:
            self.err(st)
        return spec.target in got, bool(self.latest)

    def err(self, st: RobotState) -> None:
        """The noisy detector (``indirect.noise``): true detections displaced, and each secondary
        class not detected reported with the false-positive rate at a point drawn uniformly in the
        view (a fixed number of draws per frame, but for the rejection of points out of view)."""
        noise, room, w, h = self.task.spec.noise, self.grid.room, *self.grid.room.size
        classes = list(self.task.spec.secondary)
        u, e = self.rng.random(len(classes)), self.rng.normal(0.0, 1.0, (len(classes), 2)) * noise.position_sd
        half = self.task.camera.half_h
        for k, cls in enumerate(classes):
            if cls in self.latest:
                x, y = self.seen[cls]
                self.seen[cls] = (min(max(x + e[k, 0], 0.0), w), min(max(y + e[k, 1], 0.0), h))
            elif u[k] < noise.false_positive:
                for _ in range(50):
                    r = self.ranges[cls] * math.sqrt(self.rng.random())
                    a = st.heading + self.rng.uniform(-half, half)
                    x, y = st.x + r * math.cos(a), st.y + r * math.sin(a)
                    if 0.0 <= x <= w and 0.0 <= y <= h and self.sees(np.array([st.x, st.y, st.heading]), [x], [y],
                                                                      self.ranges[cls])[0, 0]:
                        self.seen[cls] = (x, y)
                        self.latest.add(cls)
                        break

    def update(self, st: RobotState) -> None:
        spec, b, fr = self.task.spec, st.belief, self.grid.frame
        b.not_seen_main(self.detection(spec.target, st))
        for cls in self.masks:
            if cls in self.latest:
                if not (spec.count_once and cls in self.in_view_before):
                    r, c = (int(v) for v in fr.to_index(*self.seen[cls]))
                    b.seen_secondary(cls, min(max(r, 0), fr.height - 1), min(max(c, 0), fr.width - 1),
                                     spec.noise.false_positive)
            elif self.negative:
                b.not_seen_secondary(cls, self.detection(cls, st).copy())
        self.in_view_before = set(self.latest)
        self.frames_since_plan += 1
        self.since_plan.append((st.x, st.y, st.heading))

    def detection(self, cls: str, st: RobotState) -> np.ndarray:
        """The robot's model of detecting ``cls`` in each cell from this frame's pose: A on the
        map's grid, the secondary objects on the grid of their non-detections; given the misses
        before, per yaw hypothesis (:class:`~semsearch_cli.sensors.indirect.YawMemory`), or the
        table's mean over yaws (``camera.model: mean``). Reused at the next frame."""
        main = cls == self.task.spec.target
        fr, occ = (self.grid.frame, self.occ) if main else (self.neg_frame, self.neg_occ)
        if self.task.spec.camera.model == "mean":
            out = self.D if main else None
            return self.task.camera.detect_image(fr, st.x, st.y, st.heading, cls, self.ranges[cls], occ, out)
        if cls not in self.memory:
            self.memory[cls] = YawMemory(self.task.camera, cls, fr, occ)
        return self.memory[cls].look(st.x, st.y, st.heading, self.ranges[cls])

    def sees(self, poses, xs, ys, max_range: float | None = None) -> np.ndarray:
        return self.task.camera.sees(poses, xs, ys, self.scale if max_range is None else max_range)

    def replan_due(self, path_done: bool, since_plan: float, event: bool) -> bool:
        return path_done or self.frames_since_plan >= self.replan_frames or (event and self.planner.replan_on_detection)

    def plan(self, st: RobotState):
        """A re-plan, the indirect search's decision point (a generator, see
        :class:`~semsearch_cli.tasks.loop.Session`): the map of A brought up to date, then a goal
        pose (any cell the robot can stand on, and a heading or None), driven to along the
        standing cells."""
        g, spec = self.grid, self.task.spec
        st.belief.flush()
        lengths = None

        def path_length(xs, ys):
            nonlocal lengths
            if lengths is None:
                lengths = g.lengths_from(st.x, st.y)
            r, c = g.frame.to_index(np.asarray(xs), np.asarray(ys))
            H, W = lengths.shape
            ok = (r >= 0) & (r < H) & (c >= 0) & (c < W)
            out = np.full(np.shape(r), np.inf)
            out[ok] = lengths[r[ok], c[ok]]
            return out

        ctx = IndirectContext(st.belief, g.frame, g.stand, st.x, st.y, st.heading, st.steps * self.dt, self.scale,
                              self.task.cones(self.scale), spec.robot.speed, math.radians(spec.robot.turn_rate),
                              spec.replan_every, self.rng, dict(self.seen), set(self.latest),
                              np.asarray(self.since_plan).reshape(-1, 3), self.sees, path_length, self.task.relations,
                              self.task.cooccurrence, spec.target, g.room.name, tuple(g.room.size), spec.time_limit)
        stand = g.stand.view()
        stand.flags.writeable = False  # the room's own cells: a driver reads them, never writes
        goal = yield DecisionPoint("indirect", ctx, stand, stand, lambda: self.planner.plan(ctx), INDIRECT_CODEC, self.rng)
        checked_point(self.planner.name, goal.x, goal.y, g.frame, goal.heading)
        goal = Goal(float(goal.x), float(goal.y), None if goal.heading is None else float(goal.heading), goal.info)
        self.frames_since_plan = 0
        self.since_plan = []
        new = self.goal is None or (goal.x, goal.y, goal.heading) != (self.goal.x, self.goal.y, self.goal.heading)
        self.decisions += new
        self.goal = goal
        if self.observer is not None:
            self.observer.see(IndirectGoal(step=st.steps, t_s=st.steps * self.dt, x=st.x, y=st.y, heading=st.heading, goal=goal,
                                           new=new, p=st.belief.p, p0=st.belief.p0, trail=st.trail,
                                           seen=dict(self.seen)))
        if math.hypot(goal.x - st.x, goal.y - st.y) < 1e-9:
            xs, ys = np.array([st.x, st.x]), np.array([st.y, st.y])
        else:
            p = g.path(st.x, st.y, goal.x, goal.y)
            xs, ys = p if p is not None else (np.array([st.x, st.x]), np.array([st.y, st.y]))
        self.final_heading = goal.heading
        self._turned = False
        return xs, ys

    def move(self, st: RobotState, px, py, i: int):
        """One frame of motion: turn toward the next waypoint at the turn rate, drive at the
        speed once facing it; at the last waypoint, turn to the goal's heading. Returns (i, moved)."""
        spec = self.task.spec
        w, v = math.radians(spec.robot.turn_rate), spec.robot.speed
        t_left, moved = self.dt, 0.0
        n = len(px)
        while t_left > 1e-12 and i < n:
            dx, dy = px[i] - st.x, py[i] - st.y
            d = math.hypot(dx, dy)
            if d < 1e-9:
                if i == n - 1 and self.final_heading is not None:
                    err = float(wrap_angle(self.final_heading - st.heading))
                    if abs(err) > 1e-9:
                        rot = min(abs(err), w * t_left)
                        st.heading = float(wrap_angle(st.heading + math.copysign(rot, err)))
                        t_left -= rot / w
                        continue
                i += 1
                continue
            err = float(wrap_angle(math.atan2(dy, dx) - st.heading))
            if abs(err) > 1e-6:
                rot = min(abs(err), w * t_left)
                st.heading = float(wrap_angle(st.heading + math.copysign(rot, err)))
                t_left -= rot / w
                continue
            step = min(d, v * t_left)
            st.x += dx / d * step
            st.y += dy / d * step
            moved += step
            t_left -= step / v
            if step >= d - 1e-12:
                st.x, st.y = float(px[i]), float(py[i])
        return i, moved


MAX_ROOM_CELLS = 1_000_000  # cells of one room's grid: the map, eight yaw hypotheses per class, the masks


def check_classes(spec, file: str) -> None:
    """A :class:`ScenarioError` naming ``indirect.target`` or ``indirect.relations.<class>`` for an
    object class with no detection table: the paper's four (the tables of config/indirect.py serve
    those) and those given in ``indirect.camera.detection``. A mistyped class was accepted, and
    searched for with a table meant for another."""
    known = list(dict.fromkeys([*SIDE_BLIND_TABLES, *(spec.camera.detection or {})]))
    for field, name in [("indirect.target", spec.target), *((f"indirect.relations.{c}", c) for c in spec.secondary)]:
        if name not in known:
            raise ScenarioError(file, field, f"no detection table for the class {name!r}{did_you_mean(name, known)}; "
                                f"the classes with one: {', '.join(known)}. A class of your own needs its table in "
                                "indirect.camera.detection (8 rows, yaw 0..315 by 45 degrees, of 5 percentages, at "
                                "0.8, 1.2, 1.6, 2.0 and 2.5 m)")


def _generated(spec, file: str, field: str, n: int, seed: int, size, obstacles: int, which: str = "") -> list[Room]:
    """:func:`generate_rooms`, its failure (no place left for an object after many draws: rooms
    too small, or too full of obstacles) a :class:`ScenarioError` naming ``field``."""
    try:
        return generate_rooms(n, seed, spec.relations, spec.masks, spec.target, size, obstacles)
    except ValueError as exc:
        w, h = size
        raise ScenarioError(file, field, f"{which}{exc}: rooms of {w:g} x {h:g} m{' with obstacles' if obstacles else ''} "
                            f"cannot hold the {spec.target} and {len(spec.secondary)} secondary object(s), each "
                            f"{WALL_MARGIN:g} m from the walls and obstacles and {OBJECT_GAP:g} m from the others; "
                            "give larger rooms" + (" or fewer obstacles" if obstacles else "")) from None


@register_task
class IndirectTask(Task):
    """Indirect search: goals are view scales; each episode searches one room from one start."""

    kind = "indirect"
    planner_kind = "indirect"
    noun = "a target object in a room, through the secondary objects that co-occur with it"
    records = ("room", "time_s", "soft_spl", "left_m")
    columns = ("room", "time_s")

    @classmethod
    def example(cls, folder, planner):
        """Two generated rooms, the target visible from 1.5 m, 60 s per search, two seeds."""
        folder.mkdir(parents=True, exist_ok=True)
        d = {"name": "rooms", "indirect": {"rooms": {"count": 2, "seed": 1}, "view_scales": [1.5], "time_limit": 60.0},
             "planners": [{"name": planner}], "experiment": {"seeds": 2}}
        path = folder / "scenario.yaml"
        path.write_text(yaml.safe_dump(d, sort_keys=False))
        return path

    def __init__(self, sc, world, path):
        super().__init__(sc, world, path)
        self.spec = sc.indirect
        self.camera = SemanticCamera(self.spec.camera)
        self.grids: list[RoomGrid] = world.grids
        self._masks: dict = {}
        self._cones: dict = {}
        self._views: dict = {}  # (room, scale) -> path length field to the cells that see A
        self.relations: dict = {}
        self.believe(self.spec.model_relations())

    def believe(self, relations: dict) -> None:
        """Set the co-occurrences the robot believes (and p(o | A) = 1 - C^VF of each class)."""
        self.believed = relations
        self.cooccurrence = {c: 1.0 - row[CATEGORIES.index("VF")] for c, row in relations.items()}
        self._masks = {}

    def memory_per_run(self) -> int:
        """A room's grid times what a search keeps per cell (the map, eight yaw hypotheses for A
        and for each secondary object, the masks' convolutions)."""
        H, W = self.grids[0].stand.shape
        return int(H * W * (150 + 64 * len(self.spec.secondary)))

    @classmethod
    def build_world(cls, sc, base, file: str) -> "Rooms":
        """The rooms of the scenario (read from its rooms file, or generated), each on the
        probability map's grid, checked: one size, a grid a search can hold, divisible by
        ``coarse``."""
        spec = sc.indirect
        field = "indirect.rooms"
        check_classes(spec, file)
        if isinstance(spec.rooms, str):
            rooms = read_rooms(Path(base) / spec.rooms, spec.target, spec.secondary)
        else:
            g = spec.rooms
            rooms = _generated(spec, file, "indirect.rooms.size", g.count, g.seed, g.size, g.obstacles)
        training = None
        if spec.learned is not None:  # training rooms of the test rooms' size (a rooms file's, or rooms.size)
            where = "indirect.rooms.size" if not isinstance(spec.rooms, str) else "indirect.learned"
            training = _generated(spec, file, where, spec.learned.rooms, spec.learned.seed, rooms[0].size, 0,
                                  "a training room of indirect.learned: ")
        if spec.ablation == "no_secondary":
            for r in rooms:
                r.objects = {spec.target: r.objects[spec.target]}
        w, h = rooms[0].size
        cells = math.ceil(w / spec.resolution) * math.ceil(h / spec.resolution)
        if cells > MAX_ROOM_CELLS:
            raise ScenarioError(file, "indirect.resolution", f"rooms of {w:g} x {h:g} m at {spec.resolution:g} m "
                                f"cells are {cells:,} cells, more than the {MAX_ROOM_CELLS:,} a search holds in memory"
                                "; take coarser cells or smaller rooms")
        try:
            bodies = spec.camera.diameters if spec.objects_block else None
            grids = [RoomGrid.of(r, spec.resolution, spec.robot.radius, bodies) for r in rooms]
        except ValueError as exc:
            raise ScenarioError(file, field, str(exc)) from None
        if len({g.stand.shape for g in grids}) > 1:
            raise ScenarioError(file, field, "the rooms differ in size; give rooms of one size")
        H, W = grids[0].stand.shape
        if H % spec.coarse or W % spec.coarse:
            raise ScenarioError(file, "indirect.coarse", f"the map ({H} x {W} cells) must divide by coarse = "
                                f"{spec.coarse}; change the resolution or set coarse: 1")
        return Rooms(grids, training)

    @classmethod
    def build(cls, sc, world, path):
        task = cls(sc, world, path)
        spec = task.spec
        if world.training is not None:  # the co-occurrences the robot believes, learned in the training rooms
            task.believe(estimate_relations(world.training, spec.target, spec.secondary, spec.masks))
        task.relations = {c: task.masks_for("soft")[c].full for c in spec.secondary}
        task.variants()
        return task

    # ---- built once per process ---------------------------------------------------------
    def masks_for(self, kind: str, coarse: int = 1) -> dict:
        """class -> RelationMask of ``kind`` (hard or soft), on the rooms' grid (or one
        ``coarse`` times coarser)."""
        key = (kind, coarse)
        if key not in self._masks:
            spec, g = self.spec, self.grids[0]
            H, W = g.stand.shape
            self._masks[key] = {c: relation_mask(kind, spec.masks, co, spec.resolution * coarse, H // coarse, W // coarse)
                                for c, co in self.believed.items()}
        return self._masks[key]

    def cones(self, scale: float):
        if scale not in self._cones:
            self._cones[scale] = self.camera.templates(scale, self.spec.resolution)
        return self._cones[scale]

    def field(self, k: int, scale: float) -> np.ndarray:
        """(H, W) path length (m) over room ``k``'s standing cells to the nearest cell from which
        A is in view at ``scale`` for some heading and the detection table gives a chance of
        detecting it (A is not seen from every side); inf where no such cell is reachable."""
        key = (k, scale)
        if key not in self._views:
            g = self.grids[k]
            t = g.room.objects[self.spec.target]
            fr = g.frame
            cx, cy = fr.to_world(np.arange(fr.height)[:, None], np.arange(fr.width)[None, :])
            cx, cy = np.broadcast_to(cx, g.stand.shape), np.broadcast_to(cy, g.stand.shape)
            h = np.hypot(cx - t.x, cy - t.y)
            dz = t.height - self.spec.camera.height
            r = np.hypot(h, dz)
            cam = self.camera
            # in view for the heading that faces A: the vertical angle and the depth decide; and
            # the table must give a chance of detection from that side of A
            down = np.arctan2(-dz, h)  # angle below the horizon
            ok = (r >= self.spec.camera.min_depth) & (r <= scale) & (np.abs(down - cam.pitch) <= cam.half_v) & g.stand
            seen_yaw = np.degrees(np.arctan2(cy - t.y, cx - t.x)) - t.yaw
            ok &= cam.probability(self.spec.target, r, seen_yaw) > 0
            if g.blocked.any():
                occ = g.blocked
                v0, u0 = fr.to_cell(t.x, t.y)
                rr, cc = np.nonzero(ok)
                for a, b in zip(rr, cc):
                    if not line_of_sight(occ, float(v0), float(u0), a + 0.5, b + 0.5, 0.0):
                        ok[a, b] = False
            rr, cc = np.nonzero(ok)
            if not len(rr):
                self._views[key] = np.full(g.stand.shape, np.inf)
            else:
                g.search.run(g.stand, g.cost, rr, cc, np.zeros(0, np.int64), np.zeros(0, np.int64), 0)
                self._views[key] = g.search.length_grid() * fr.res
        return self._views[key]

    def shortest_of(self, k: int, scale: float, x: float | None = None, y: float | None = None) -> float:
        """Shortest path (m) in room ``k`` at ``scale`` from (x, y) (default: the room's start)."""
        g = self.grids[k]
        if x is None:
            x, y = g.room.start[:2]
        r, c = g.frame.to_index(x, y)
        f = self.field(k, scale)
        return float(f[r, c]) if 0 <= r < f.shape[0] and 0 <= c < f.shape[1] else math.inf

    @property
    def goals(self) -> list:
        return list(self.spec.view_scales)

    def goal_value(self, label):
        for g in self.goals:
            if str(g) == str(label) or (isinstance(label, (int, float)) and float(label) == g):
                return g
        return label

    # ---- episodes ---------------------------------------------------------------------------
    def room_name(self, ep: Episode) -> str:
        return self.grids[ep.room].room.name

    def record(self, ep: Episode, res: RunResult) -> dict:
        """The room searched and the simulated time (s) the search took (beside what the planner's
        decisions cost, when it reports any)."""
        return {**super().record(ep, res), "room": self.room_name(ep),
                "time_s": round(res.time_s, 2) if res.time_s == res.time_s else ""}

    def episode_row(self, ep: Episode) -> dict:
        return ep.row() | {"room": self.room_name(ep)}

    def build_episodes(self) -> list[Episode]:
        """Per view scale, the rooms' episodes: each room from its own start (no ``episodes``
        section); ``starts`` drawn per room, the same for every scale, uniformly over the cells the
        robot can stand on from which A can be detected (within the distances given); or given by
        hand (``goal``: the room's name, searched at every scale) or in a file (``goal``: the
        scale, ``room``: the room's name)."""
        spec = self.sc.episodes
        names = {g.room.name: k for k, g in enumerate(self.grids)}
        per_room: list[tuple[int, float, float, float | None, str, str]] = []  # room, x, y, heading, file, field
        scaled: list[tuple[float, int, float, float, float | None, str, str]] = []  # given with a scale
        given: dict[tuple[str, str], dict] = {}  # (file, field) -> a row of an episodes file
        if spec is None:
            per_room = [(k, *g.room.start, self.file, f"indirect.rooms ({g.room.name})") for k, g in enumerate(self.grids)]
        elif spec.starts is not None:
            if spec.where != "anywhere":
                raise ScenarioError(self.file, "episodes.where", "indirect search draws its starts inside its rooms; "
                                    "remove where")
            for k, g in enumerate(self.grids):
                fields = [f for f in (self.field(k, s) for s in self.goals) if np.isfinite(f).any()]
                starts = draw_starts(g.stand, fields, g.frame.to_world, spec.starts,
                                     np.random.default_rng([spec.seed, *label_words(g.room.name)]),
                                     spec.min_distance, spec.max_distance)
                if not starts:
                    raise ScenarioError(self.file, "episodes", f"no cell of room {g.room.name} lies within the distances "
                                        "given from a pose that detects A; widen them")
                per_room += [(k, x, y, h, self.file, "episodes") for x, y, h in starts]
        else:
            for e in given_episodes(spec, self.path.parent, self.file):
                given[(e["file"], e["field"])] = e
                room = e["room"] if e["room"] is not None else str(e.get("text", e["goal"]))  # a room name as written (01)
                if room not in names:
                    raise ScenarioError(e["file"], e["field"], f"no room named {room!r} (rooms: {', '.join(list(names)[:5])}, ...)")
                if e["room"] is None:
                    per_room.append((names[room], e["x"], e["y"], e["heading"], e["file"], e["field"]))
                else:
                    scale = self.goal_value(e["goal"])
                    if scale not in self.goals:
                        raise ScenarioError(e["file"], e["field"], f"goal {e['goal']} is not one of the view scales {self.goals}")
                    scaled.append((scale, names[room], e["x"], e["y"], e["heading"], e["file"], e["field"]))
        items = [(s, *p) for s in self.goals for p in per_room] + scaled
        out = []
        for scale, k, x, y, h, file, field in items:
            g = self.grids[k]
            r, c = g.frame.to_index(x, y)
            if not (0 <= r < g.stand.shape[0] and 0 <= c < g.stand.shape[1] and g.stand[r, c]):
                raise ScenarioError(file, field, f"the start ({x:g}, {y:g}) m is not a cell of room {g.room.name} "
                                    "the robot can stand on")
            out.append(Episode(len(out), scale, float(x), float(y), None if h is None else float(h), k,
                               self.shortest_of(k, scale, x, y)))
            if (file, field) in given and given[(file, field)]["room"] is not None:  # one row, one episode
                check_hash(out[-1], given[(file, field)])
        return out

    # ---- running ----------------------------------------------------------------------------
    def search(self, variant: Variant, ep: Episode, seed: int, st: RobotState, rng, seat, observer: Observer | None) -> Outcome:
        """One room's search at the episode's scale; the result adds the simulated time, and the
        distance left is measured in the room."""
        scale = float(ep.goal)
        out, st = yield from self.steps(st, seat.planner(variant), scale, rng, observer, room=ep.room)
        out.left_m = 0.0 if out.outcome == "found" else self.shortest_of(ep.room, scale, st.x, st.y)
        out.time_s = out.steps / self.spec.camera.fps
        out.message = "the robot could not move" if out.outcome == "stuck" else ""
        return out

    def steps(self, state, planner, goal, rng, observer: Observer | None = None, room: int = 0):
        """Search room ``room`` for A at view scale ``goal`` from ``state`` (a new map of A when it
        has none); the time limit counts from the state's steps (camera frames)."""
        spec = self.spec
        search = IndirectSearch(self, self.grids[room], planner, float(goal), rng, observer)
        if state.belief is None:
            state.belief = search.new_belief()
        d0, s0 = state.distance, state.steps
        max_steps = s0 + int(round(spec.time_limit * spec.camera.fps))
        outcome = yield from drive(search, state, 0.0, math.inf, max_steps, move=search.move)
        return Outcome(outcome, state.distance - d0, state.steps - s0, search.decisions), state

    def describe(self):
        spec = self.spec
        blind = {f"{s:g} m": [g.room.name for k, g in enumerate(self.grids) if not np.isfinite(self.shortest_of(k, s))]
                 for s in spec.view_scales}
        blind = {s: names for s, names in blind.items() if names}
        return {"name": self.sc.name, "kind": self.kind, "rooms": len(self.grids),
                "rooms where no reachable pose can detect A (their searches cannot succeed)": blind or "none",
                "grid": f"{self.grids[0].frame.height} x {self.grids[0].frame.width} cells at {spec.resolution} m",
                "view scales (m)": spec.view_scales, "target": spec.target, "secondary": spec.secondary,
                "planners": self.planner_labels()}
