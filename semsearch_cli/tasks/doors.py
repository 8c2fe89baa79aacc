"""Door search (thesis ch. 4): find the door sign with a given number on a map the
robot builds as it goes.

Sensing is the laser into HIMM and the two door cameras into sign reads; the belief update marks
the visited kernel and density class; the target is seen when the goal sign is read. Re-plans
happen when the path is used up, every ``replan_every`` metres, and, for planners that use signs,
when a sign reaches ``min_reads``. When a re-plan finds no candidate the robot first turns on the
spot in three quarter turns, sensing after each (its laser covers only 180 degrees ahead, so a
start facing a dead end would otherwise see nowhere to go); only if there is still no candidate
is the run ``stuck``. A goal whose sign the robot has already read (a later stage of a chain) is
reached by path planning on the map built so far, to the mean pose of its reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import yaml

from ..belief import DoorBelief
from ..config.base import sign_label
from ..errors import ScenarioError
from ..geometry import wrap_angle
from ..navigation import NAVIGATORS
from ..belief import Candidates
from ..planners import Decision, DoorContext, Told
from ..planners.doors.greedy import nearest_candidate
from ..sensors import DoorCamera, Laser
from ..world.ground_truth import check_goals_reachable
from ..world.buildings.demo import write_demo
from .base import Event, Observer, Outcome, RobotState, OnMapTask, checked_cell, register_task
from .decisions import Codec, DecisionPoint, rng_word
from .loop import drive

MAX_RETRIES = 5


def _encode(dec: Decision | None):
    """A door choice in a few bytes: ``[row, col]``, ``[row, col, 1]`` when the planner marked it
    kept (``info["kept"]``), null for no target."""
    if dec is None:
        return None
    return [int(dec.row), int(dec.col), 1] if dec.info.get("kept", False) else [int(dec.row), int(dec.col)]


def _decode(item) -> Decision | None:
    if item is None:
        return None
    row, col, *kept = item
    if not (isinstance(row, int) and isinstance(col, int)) or kept not in ([], [1]):
        raise ValueError("expected [row, col] or [row, col, 1]")
    return Decision(row, col, {"kept": True} if kept else {})


DOOR_CODEC = Codec(_encode, _decode)


class DoorSensing:
    """Laser into HIMM and door cameras into reads, shared by the searches of this task. An
    observer that asks for steps (``Observer.steps``) sees a :class:`DoorFrame` after each
    sensing and a :class:`DoorStep` after each step's belief update."""

    observer: Observer | None = None
    _planning = False  # inside a re-plan (DoorSearch.plan): frames sensed now tell the generator's state after them

    def __init__(self, task: "DoorTask", goal, rng: np.random.Generator):
        self.task, self.goal, self.rng = task, goal, rng
        self.goal_idx = set(task.world.signs.indices_of(goal))  # more than one under duplicates: any

    def sense(self, st: RobotState) -> tuple[bool, bool]:
        """(goal read, a sign reached min_reads)."""
        t, b, fr = self.task, st.belief, self.task.world.frame
        v, u, r, c = fr.point_to_cell(st.x, st.y)
        scan = t.laser.scan(v, u, st.heading, self.rng)
        b.fold_scan(v, u, *scan)
        min_reads = b.spec.min_reads
        b.add_view(v, u, st.heading)
        found = event = False
        reads = t.camera.read(st.x, st.y, st.heading, self.rng)
        bearings = tuple(t.camera.bearing(i, st.x, st.y) for i, _ in reads)
        for (i, label), bearing in zip(reads, bearings):
            st.read_signs[i] = label
            if i in self.goal_idx and label == self.goal:
                found = True
            if b.reads.add(label, r * fr.width + c, st.x, st.y, st.heading, bearing) == min_reads:
                event = True
        if self.observer is not None and self.observer.steps:
            rng = rng_word(self.rng) if self._planning else None
            self.observer.see(DoorFrame(step=st.steps, x=st.x, y=st.y, heading=st.heading, belief=b, reads=tuple(reads), bearings=bearings,
                                        scan=scan, found=found, rng=rng))
        return found, event

    def update(self, st: RobotState) -> None:
        _, _, r, c = self.task.world.frame.point_to_cell(st.x, st.y)
        st.belief.visit(r, c)
        st.headings.append(st.heading)
        if self.observer is not None and self.observer.steps:
            self.observer.see(DoorStep(step=st.steps, x=st.x, y=st.y, heading=st.heading, distance=st.distance,
                                       belief=st.belief))


@dataclass(frozen=True, kw_only=True)
class DoorFrame(Event):
    """One sensing frame of a door search, shown to observers that ask for steps
    (``Observer.steps``): the pose (``x``, ``y`` m, ``heading`` rad) it sensed from during step
    ``step``, the belief after folding it in (``belief``: copy what you keep), the signs it read
    [(sign index, label as read)], the direction from the robot to each (``bearings``, radians) and
    its laser scan (beam angles rad in the world, ranges in cells, hit flags); ``found``: whether it read the goal's sign; ``rng``: inside a re-plan (a
    turn on the spot), the run's generator state after it (:func:`~.decisions.rng_word`), else
    None. A step senses one frame; turning on the spot senses several within one step. Not
    traced."""

    step: int
    x: float
    y: float
    heading: float
    belief: DoorBelief
    reads: tuple = ()
    bearings: tuple = ()
    scan: tuple | None = None
    found: bool = False
    rng: str | None = None

    @property
    def traced(self) -> bool:
        return False

    def row(self) -> dict:
        """The frame as the robot has it: its pose, the labels read (a whole number as a number) and
        the direction to each (radians), whether the goal's sign was among them, the generator's
        state inside a re-plan."""
        labels = [sign_label(v) for _, v in self.reads]
        return {"step": self.step, "x": float(self.x), "y": float(self.y), "heading": float(self.heading), "reads": labels,
                **({"bearings": [float(a) for a in self.bearings]} if self.bearings else {}),
                "found": bool(self.found), **({"rng": self.rng} if self.rng is not None else {})}


@dataclass(frozen=True, kw_only=True)
class DoorStep(Event):
    """The belief update that ends a step of a door search (the visited kernel at the robot's
    cell), shown to observers that ask for steps: the pose (``x``, ``y`` m, ``heading`` rad) after
    ``step`` steps, ``distance`` m into the run, and the belief (``belief``: copy what you keep).
    Not traced."""

    step: int
    x: float
    y: float
    heading: float
    distance: float
    belief: DoorBelief

    @property
    def traced(self) -> bool:
        return False

    def row(self) -> dict:
        return {"step": self.step, "x": float(self.x), "y": float(self.y), "heading": float(self.heading),
                "distance": float(self.distance)}


@dataclass(frozen=True, kw_only=True)
class DoorPlan(Event):
    """A re-plan of a door search starts (``start``) or ends, shown to observers that ask for
    steps, with the run's generator's state as it starts (``rng``: :func:`~.decisions.rng_word`,
    None at the end): the frames sensed between the two were sensed by the re-plan (turning on
    the spot). Not traced."""

    step: int
    start: bool
    rng: str | None = None

    @property
    def traced(self) -> bool:
        return False

    def row(self) -> dict:
        return {"step": self.step, "plan": "start" if self.start else "end", **({"rng": self.rng} if self.rng else {})}


@dataclass(frozen=True, kw_only=True)
class DoorDecision(Event):
    """A door planner's new target: at ``step``, ``distance`` m into the episode, from the pose
    (``x``, ``y`` m, ``heading`` rad), the target ``target_xy`` (m) chosen among ``candidates`` by
    ``decision`` (its ``info`` the numbers behind it), on the map built so far (``belief``, as it
    is at this moment: copy what you keep) after the path ``trail`` [(x, y) m]."""

    step: int
    distance: float
    x: float
    y: float
    heading: float
    target_xy: tuple
    candidates: Candidates
    decision: Decision
    belief: DoorBelief
    trail: list
    read: tuple = ()  # indices of the signs read so far

    def frame(self) -> dict:
        b = self.belief
        cx, cy = b.frame.to_world(self.candidates.rows, self.candidates.cols)
        return {"map": np.where(b.seen, np.where(b.free, 2, 0), 1).astype(np.uint8)[::2, ::2],
                "path": np.asarray(self.trail, float), "distance": float(self.distance),
                "cands": np.stack([cx, cy], axis=1) if len(self.candidates) else np.zeros((0, 2)),
                "target": tuple(float(v) for v in self.target_xy), "read": list(self.read)}

    def row(self) -> dict:
        tx, ty = self.target_xy
        return {"step": self.step, "distance_m": round(self.distance, 3), "x": round(float(self.x), 3),
                "y": round(float(self.y), 3), "heading_deg": round(float(np.degrees(self.heading)), 1),
                "target": [round(float(tx), 2), round(float(ty), 2)], "n_candidates": len(self.candidates),
                **self.decision.info}


def views_needed(p_read: float, miss: float = 0.01, cap: int = 20) -> int:
    """Frames from which a wall face must be seen before a sign on it counts as read-or-absent:
    the fewest n with (1 - p_read)^n <= ``miss`` (1 for a camera that never misses), at most
    ``cap`` (a camera that never reads would otherwise need infinitely many)."""
    if p_read >= 1.0:
        return 1
    if p_read <= 0.0:
        return cap
    # less a hair: where the ratio is a whole number (0.99 -> exactly 1), log1p's last bit differs by numpy version
    return int(min(cap, max(1, np.ceil(np.log(miss) / np.log1p(-p_read) - 1e-9))))


class DoorSearch(DoorSensing):
    """Explore with a door planner until the goal sign is read."""

    def __init__(self, task, planner, goal, rng, observer: Observer | None = None):
        super().__init__(task, goal, rng)
        self.planner, self.observer = planner, observer
        self.navigator = NAVIGATORS[task.sc.navigation.navigator]()
        self.uses_signs = getattr(planner, "replan_on_signs", False)
        self.replan_every = task.sc.navigation.replan_every
        self.periodic = task.sc.navigation.replan == "periodic"
        self._belief = None  # the belief and its lost-cell count when the path was planned (events)
        self._lost_at_plan = 0
        self.looked_around = False
        self.decisions = 0
        self.target: tuple[int, int] | None = None  # the cell the robot is heading for
        self.start_distance = 0.0
        cam = task.sc.door_camera
        # completeness sweep: how close to an unviewed wall face to go, and the turns that
        # sweep the two side cameras over every direction
        self.approach = min(cam.range, max(0.5 * cam.range, task.world.frame.res * 3 + task.sc.robot.radius))
        self.look_turns = int(np.ceil(180.0 / cam.fov)) - 1
        self.views_needed = views_needed(cam.p_read)
        self.sweep_target: tuple[int, int] | None = None
        signs = task.world.signs
        self.told = None
        if getattr(planner, "privileged", ""):  # a privileged planner's ground truth (oracle_goal, wall_rule)
            wall = signs.walls()
            self.told = Told(tuple((float(signs.x[i]), float(signs.y[i])) for i in sorted(self.goal_idx)),
                             tuple((signs.number[i], float(signs.x[i]), float(signs.y[i]), int(wall[i])) for i in range(len(signs))))

    def replan_due(self, path_done, since_plan, event):
        if path_done or (event and self.uses_signs):
            return True
        if self.periodic:
            return since_plan >= self.replan_every
        # events: the path may no longer be free (a cell of the map stopped being free: paths keep
        # the robot's clearance from unknown space too, so a newly seen wall cannot come closer
        # than that otherwise)
        return self._belief.lost != self._lost_at_plan

    def turn(self, st, turns: int, angle: float, frames: int = 1) -> bool:
        """Turn on the spot ``turns`` times by ``angle`` radians, sensing ``frames`` times after
        each; whether the goal was read."""
        found = False
        for _ in range(turns):
            st.heading = float(wrap_angle(st.heading + angle))
            for _ in range(frames):
                f, _ = self.sense(st)
                found = found or f
        return found

    def look_round(self, st) -> bool:
        """At a wall face not yet looked at enough: dwell ``views_needed`` frames at each of the
        headings that sweep the two side cameras over every direction (a half turn); whether
        the goal was read."""
        found = False
        for _ in range(self.views_needed - 1):  # the frame of this step was the first
            found = self.sense(st)[0] or found
        return self.turn(st, self.look_turns, np.pi / (self.look_turns + 1), self.views_needed) or found

    def plan(self, st):
        """A re-plan, the door search's one decision point (a generator, see
        :class:`~semsearch_cli.tasks.loop.Session`): look where the robot came to look
        (:meth:`prepare`), then ask for a target among the frontier candidates; a target with no
        path is taken out and the question asked again, at most ``MAX_RETRIES`` times; no target
        (None), or none reachable, sends the robot to the nearest wall face not read yet
        (:meth:`sweep`). The retry-and-sweep policy is here alone, for every driver."""
        stepping = self.observer is not None and self.observer.steps
        if stepping:
            self.observer.see(DoorPlan(step=st.steps, start=True, rng=rng_word(self.rng)))
        self._planning = True
        try:
            out = yield from self._plan(st)
        finally:
            self._planning = False
        if stepping:
            self.observer.see(DoorPlan(step=st.steps, start=False))
        return out

    def _plan(self, st):
        prep = self.prepare(st)
        if isinstance(prep, str):
            return prep
        ctx, cands = prep
        for _ in range(MAX_RETRIES):
            dec = yield self.point(ctx, cands)
            p, cands = self.attempt(st, ctx, cands, dec)
            if p is not None:
                return p
            if cands is None:
                break
        return self.sweep(st, ctx)

    def point(self, ctx, cands) -> DecisionPoint:
        """The decision: a target among ``cands`` (every one legal), or None. What the planner
        leaves behind that the run reads: the last path search it ran over the belief from the
        robot's cell (the path to the target reuses it; :meth:`searched`, :meth:`search_again`)."""
        return DecisionPoint("doors", ctx, cands, np.ones(len(cands), bool), lambda: self.planner.choose(ctx, cands),
                             DOOR_CODEC, self.rng, keep=lambda: self.searched(ctx, cands),
                             restore=lambda left: self.search_again(ctx, cands, left))

    @staticmethod
    def searched(ctx, cands) -> list | None:
        """The search the planner left in the belief, if the path to its target may reuse it
        (from the robot's cell, on the current maps): ``[n_stop, again]`` over the candidates, or
        ``[n_stop, rows, cols, again]`` over other cells (``again`` 1 when the search went on over
        every cell, :meth:`~semsearch_cli.belief.DoorBelief.search`); None when there is none."""
        held = ctx.belief.held_search(ctx.row, ctx.col)
        if held is None:
            return None
        rows, cols, n_stop, again = held
        if np.array_equal(rows, cands.rows) and np.array_equal(cols, cands.cols):
            return [int(n_stop), int(again)]
        return [int(n_stop), [int(v) for v in rows], [int(v) for v in cols], int(again)]

    @staticmethod
    def search_again(ctx, cands, left) -> None:
        """Put back the search :meth:`searched` recorded (a replay: the planner that ran it is
        absent), run at the path to the chosen target and stopped there
        (:meth:`~semsearch_cli.belief.DoorBelief.search_again`). A record of semsearch 0.3 before
        this (``[n_stop]``, ``[n_stop, rows, cols]``: no ``again``) runs it in whole at once."""
        if len(left) in (2, 4):
            *spec, again = left
            if again not in (0, 1) or isinstance(again, bool):
                raise ValueError("the search's last item is 0 or 1")
            again = bool(again)
        elif len(left) in (1, 3):
            spec, again = left, None
        else:
            raise ValueError("expected [n_stop, again] or [n_stop, rows, cols, again]")
        n_stop, *cells = spec
        rows, cols = (cands.rows, cands.cols) if not cells else (np.asarray(cells[0], np.int64), np.asarray(cells[1], np.int64))
        ctx.belief.search_again(ctx.row, ctx.col, rows, cols, int(n_stop), again)

    def prepare(self, st):
        """The first half of a re-plan: at a wall face the robot came to look at, look all round;
        then the planner's context and the frontier candidates (after turning on the spot once
        when there are none). Returns ``(ctx, cands)``, or ``"found"`` when looking saw the goal."""
        b, fr = st.belief, self.task.world.frame
        r, c = (int(v) for v in fr.to_index(st.x, st.y))
        if self.sweep_target is not None and max(abs(r - self.sweep_target[0]), abs(c - self.sweep_target[1])) <= 1:
            # at a wall face not yet looked at enough: look all round, then give up on the faces
            # near here
            self.sweep_target = None
            if self.look_round(st):
                return "found"
            b.mark_examined(r, c, self.approach + 2 * fr.res)
        b.refresh_derived()
        cands = b.candidates()
        if len(cands) == 0 and not self.looked_around:
            # nowhere to go with what the forward laser has seen: turn on the spot (three quarter
            # turns, no distance travelled) and look again
            self.looked_around = True
            if self.turn(st, 3, np.pi / 2):
                return "found"
            b.refresh_derived()
            cands = b.candidates()
        ctx = DoorContext(b, r, c, st.x, st.y, st.heading, self.goal, self.rng, st.headings,
                          explain=self.observer is not None, distance=st.distance, told=self.told)
        return ctx, cands

    def attempt(self, st, ctx, cands, dec):
        """The second half: decision ``dec`` (None: nowhere to go) checked and planned.
        Returns ``(waypoints, cands)`` when there is a path; ``(None, cands without the chosen
        cell)`` to ask again; ``(None, None)`` to give up on the frontier (then :meth:`sweep`)."""
        if dec is None:
            return None, None
        checked_cell(self.planner.name, dec.row, dec.col, st.belief.free)
        p = self.go(st, ctx, cands, dec)
        if p is not None:
            return p, cands
        keep = ~((cands.rows == dec.row) & (cands.cols == dec.col))
        if keep.all():
            return None, None
        return None, cands.take(np.flatnonzero(keep))

    def sweep(self, st, ctx):
        """No frontier left (or none reachable): go to the nearest wall face no camera has looked
        at from within reading range; ``stuck`` only when there is none the robot can reach."""
        cam = self.task.sc.door_camera
        for _ in range(MAX_RETRIES):
            cands = st.belief.unread_walls(cam.range, np.radians(cam.fov) / 2, self.approach, self.views_needed)
            dec = nearest_candidate(ctx, cands)
            if dec is None:
                return "stuck"
            dec.info["sweep"] = True
            p = self.go(st, ctx, cands, dec)
            if p is not None:
                self.sweep_target = (dec.row, dec.col)
                return p
            st.belief.mark_examined(dec.row, dec.col, self.approach + 2 * self.task.world.frame.res)
        return "stuck"

    def go(self, st, ctx, cands, dec):
        """Record decision ``dec`` and plan a path to it: waypoints (m), or None without a path."""
        b, fr = st.belief, self.task.world.frame
        # a decision is a new target: the one the robot heads for already, chosen again at a
        # re-plan or kept by the planner (info["kept"]), is not one, for every planner alike
        kept = dec.info.get("kept", False) or (dec.row, dec.col) == self.target
        self.decisions += not kept
        if self.observer is not None and not kept:
            self.observer.see(DoorDecision(step=st.steps, distance=st.distance - self.start_distance, x=st.x, y=st.y,
                                           heading=st.heading, target_xy=fr.to_world(dec.row, dec.col), candidates=cands,
                                           decision=dec, belief=b, trail=st.trail, read=tuple(sorted(st.read_signs))))
        p = self.navigator.plan(b, ctx.row, ctx.col, dec.row, dec.col)
        if p is not None and len(p[0]) >= 2:
            self.looked_around = False
            self.target = (dec.row, dec.col)
            self._belief, self._lost_at_plan = b, b.lost
            return fr.to_world(p[0], p[1])
        return None


class GoToRead(DoorSensing):
    """Go to a sign already read, by the cheapest path on the map built so far: the target is
    seen on arrival at the mean robot position of its reads."""

    def __init__(self, task, goal, rng, target_xy):
        super().__init__(task, goal, rng)
        self.target = target_xy
        self.path = None
        self.decisions = 0

    def sense(self, st):
        found, event = super().sense(st)
        arrived = self.path is not None and np.hypot(st.x - self.target[0], st.y - self.target[1]) < 1e-6
        return found or arrived, event

    def replan_due(self, path_done, since_plan, event):
        return path_done

    def plan(self, st):
        if self.path is not None:
            return "stuck"
        b, fr = st.belief, self.task.world.frame
        b.refresh_derived()
        r, c = (int(v) for v in fr.to_index(st.x, st.y))
        tr, tc = (int(v) for v in fr.to_index(*self.target))
        p = b.path(r, c, tr, tc)
        if p is None or len(p[0]) < 2:
            return "stuck"
        self.decisions = 1
        xs, ys = fr.to_world(p[0], p[1])
        xs[-1], ys[-1] = self.target  # end exactly on the reading pose
        self.path = (xs, ys)
        return self.path


def read_position(belief: DoorBelief, goal) -> tuple[float, float] | None:
    """Mean robot position (m) at the reads of sign ``goal``, or None when it was never read."""
    reads = belief.reads
    if goal not in reads._label_id:
        return None
    rows = np.flatnonzero(reads.label[: reads.n] == reads._label_id[goal])
    n = reads.count[rows].sum()
    return float(reads.sx[rows].sum() / n), float(reads.sy[rows].sum() / n)


@register_task
class DoorTask(OnMapTask):
    """Door search: goals are door numbers; the shortest path of each is the ground-truth geodesic
    to the nearest pose that reads its sign."""

    kind = "doors"
    planner_kind = "doors"
    noun = "a door sign with a given number, read by cameras on the robot's sides"
    records = ("soft_spl", "left_m")

    @classmethod
    def example(cls, folder, planner):
        """The demo building (30 m x 20 m, 24 signs), goal 452, one seed, a 300 m budget."""
        path = write_demo(folder, goals=(452,), planners=[{"name": planner}], seeds=1)
        d = yaml.safe_load(path.read_text())
        d["experiment"]["max_distance"] = 300.0
        path.write_text(yaml.safe_dump(d, sort_keys=False))
        return path

    def __init__(self, sc, world, path):
        super().__init__(sc, world, path)
        self.laser = Laser(world, sc.laser)
        self.camera = DoorCamera(world, sc.door_camera)

    @classmethod
    def build(cls, sc, world, path):
        if len(world.signs) == 0:
            raise ScenarioError(str(path), "doors", "no door signs given")
        task = cls(sc, world, path)
        task.check_goals(sc.goals, "goals")
        task.shortest = check_goals_reachable(world, sc.goals, task.file)
        task.variants()
        return task

    def check_goals(self, goals, field: str) -> None:
        for k, g in enumerate(goals):
            if self.world.signs.index_of(g) < 0:
                raise ScenarioError(self.file, f"{field}[{k}]", f"no door sign carries the number {g}")

    def goal_cells(self, goal) -> np.ndarray:
        """The poses that read sign ``goal`` (see :meth:`World.reading_cells`)."""
        return self.world.reading_cells(goal)

    def new_belief(self) -> DoorBelief:
        return DoorBelief(self.world.frame, self.sc.belief, self.sc.robot.radius)

    def steps(self, state, planner, goal, rng, observer: Observer | None = None, reuse_reads: bool = False):
        """Search for sign ``goal`` from ``state`` (a new belief when it has none), as a generator
        of its decision points (:func:`~semsearch_cli.tasks.loop.drive`). With ``reuse_reads``
        and the sign already read, go there on the map built so far."""
        if state.belief is None:
            state.belief = self.new_belief()
        d0, s0 = state.distance, state.steps
        target = read_position(state.belief, goal) if reuse_reads else None
        search = GoToRead(self, goal, rng, target) if target is not None else DoorSearch(self, planner, goal, rng, observer)
        search.start_distance = d0
        outcome = yield from drive(search, state, self.sc.robot.step, self.sc.experiment.max_distance, self.max_steps())
        if outcome == "stuck" and isinstance(search, GoToRead):  # the map built so far has no path: search again
            search = DoorSearch(self, planner, goal, rng, observer)
            search.start_distance = d0
            outcome = yield from drive(search, state, self.sc.robot.step, self.sc.experiment.max_distance, self.max_steps())
        return Outcome(outcome, state.distance - d0, state.steps - s0, search.decisions), state

    def describe(self):
        w = self.world
        readable = sum(1 for i in range(len(w.signs)) if w.readable_mask(i).any())
        dup = {str(n): ", ".join(f"({x:g}, {y:g})" for x, y in xy) for n, xy in w.duplicates.items()}
        return {"name": self.sc.name, "kind": self.kind, "signs": len(w.signs), "readable_signs": readable,
                f"duplicated numbers ({self.sc.duplicates})": dup or "none",
                "grid": f"{w.frame.height} x {w.frame.width} cells at {w.frame.res} m",
                "planners": self.planner_labels(),
                "shortest_m": {str(k): round(v, 2) for k, v in self.shortest.items()}}
