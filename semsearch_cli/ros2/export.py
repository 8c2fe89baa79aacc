"""A recorded door-search run as a ROS 2 bag (``semsearch export``).

The run is replayed from its decisions record (``semsearch run --decisions``; no planner is built,
as ``semsearch verify`` does) with an observer that sees every step (:class:`BagRecorder`), so the
bag holds the whole run at the simulator's resolution whatever the frames file kept; the replay
must give the row's outcome, distance and steps, or nothing is written.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..config.base import sign_label
from ..engine import ENGINE
from ..errors import ScenarioError, did_you_mean
from ..runner.specs import Loaded, file_stem
from ..runner.store import json_safe, read_runs
from ..runner.verify import check_engine, replay_run
from ..tasks.base import Observer
from ..tasks.doors import DoorDecision, DoorFrame, DoorPlan, DoorStep, DoorTask
from ..tasks.episodes import episode_seed
from .bag import GOAL_RGBA, SIGN_RGBA, START_NS, BagWriter, Messages, drop_bag, map_states, stamp_ns

PATH_EVERY_M = 5.0  # /semsearch/path at the first decision after each 5 m of travel (and at the end)
PATH_STEP_M = 0.5  # its poses, one every 0.5 m


class BagRecorder(Observer):
    """Writes a door search's frames, steps, re-plans and decisions to a :class:`BagWriter` as
    they happen (topics :data:`~semsearch_cli.ros2.bag.TOPICS`). Stamps strictly increase (a
    step's stamp, then a microsecond per message after it), so that reading by time gives the
    order of writing: the order ``semsearch ros replay`` needs."""

    steps = True

    def __init__(self, bag: BagWriter, world, goal, step_m: float, max_range: float):
        self.bag, self.m = bag, bag.msgs
        self.world, self.frame, self.goal = world, world.frame, goal
        self.step_m, self.max_range = step_m, max_range
        self.t = stamp_ns(0, step_m) - 1000  # the first message is stamped at the first step
        self.read: dict[int, str] = {}  # sign index -> label as first read
        self.belief = None
        self.state = np.full((world.frame.height, world.frame.width), -1, np.int8)  # the map as the bag has it so far
        self.reach = int(np.ceil(max_range / world.frame.res)) + 2  # cells a frame may change around the robot
        self.trail: list = []
        self.decisions = 0
        self.path_at = -PATH_EVERY_M  # distance (m) at the last /semsearch/path

    def see(self, event) -> None:
        if isinstance(event, DoorFrame):
            self._frame(event)
        elif isinstance(event, DoorStep):
            self._write("/semsearch/events", event.step, self.m.string({"event": "step", **event.row()}))
            self.trail.append((float(event.x), float(event.y)))
        elif isinstance(event, DoorPlan):
            self._write("/semsearch/events", event.step, self.m.string({"event": "plan", **event.row()}))
        elif isinstance(event, DoorDecision):
            self._decision(event)

    def _stamp(self, step: int) -> int:
        self.t = max(stamp_ns(step, self.step_m), self.t + 1000)
        return self.t

    def _write(self, topic: str, step: int, msg) -> None:
        self.bag.write(topic, self._stamp(step), msg)

    def _frame(self, e: DoorFrame) -> None:
        first = self.belief is None
        self.belief = e.belief
        t = self._stamp(e.step)
        self.bag.write("/tf", t, self.m.tf(t, e.x, e.y, e.heading))
        self.bag.write("/semsearch/pose", self._stamp(e.step), self.m.pose_stamped(t, e.x, e.y, e.heading))
        if e.scan is not None:
            self._write("/scan", e.step, self.m.scan(t, *e.scan, e.heading, self.frame.res, self.max_range))
        self._map_update(e)
        signs = self.world.signs
        new = False
        for i, label in e.reads:
            i = int(i)
            self._write("/semsearch/detections", e.step, self.m.detection(signs, i, label))
            if i not in self.read:
                self.read[i] = str(label)
                new = True
        self._write("/semsearch/events", e.step, self.m.string({"event": "frame", **e.row()}))
        if first:
            t = self._stamp(e.step)
            self.bag.write("/map", t, self.m.grid(t, self.state, self.frame))
        if new or first:
            self._signs(self.t)

    def _map_update(self, e: DoorFrame) -> None:
        """The cells this frame changed, as one map_msgs/OccupancyGridUpdate over their bounding box."""
        H, W = self.state.shape
        r, c = (int(v) for v in self.frame.to_index(e.x, e.y))
        k = self.reach
        r0, r1, c0, c1 = max(0, r - k), min(H, r + k + 1), max(0, c - k), min(W, c + k + 1)
        b = e.belief
        now = map_states(b.seen[r0:r1, c0:c1], b.free[r0:r1, c0:c1])
        changed = now != self.state[r0:r1, c0:c1]
        if not changed.any():
            return
        rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
        a0, a1, b0, b1 = r0 + int(rows[0]), r0 + int(rows[-1]) + 1, c0 + int(cols[0]), c0 + int(cols[-1]) + 1
        self.state[r0:r1, c0:c1] = now
        self._write("/semsearch/map_updates", e.step, self.m.grid_update(self.t, self.state[a0:a1, b0:b1], a0, b0, H))

    def _signs(self, t: int) -> None:
        s = self.world.signs
        items = [self.m.marker(t, "signs", i, "TEXT_VIEW_FACING", s.x[i], s.y[i], SIGN_RGBA, 0.4, label)
                 for i, label in sorted(self.read.items())]
        x0 = self.frame.origin_x
        y1 = self.frame.origin_y + self.frame.height * self.frame.res
        items.append(self.m.marker(t, "goal", 0, "TEXT_VIEW_FACING", x0 + 1.0, y1 - 1.0, GOAL_RGBA, 0.8, f"goal {self.goal}"))
        self.bag.write("/semsearch/signs", self._stamp(0), self.m.markers(items))  # after the last message

    def _decision(self, e: DoorDecision) -> None:
        """The map (:attr:`state`, which every frame's update keeps equal to the belief's), the
        path now and then, the frontiers and target, the decision's row."""
        self.decisions += 1
        k = e.step
        t = self._stamp(k)
        self.bag.write("/map", t, self.m.grid(t, self.state, self.frame))
        if e.distance - self.path_at >= PATH_EVERY_M:
            self.path_at = e.distance
            self.bag.write("/semsearch/path", self._stamp(k), self.m.path(self.t, self._thinned()))
        fronts, goal = self.m.frontiers(self.t, self.frame, e.candidates, e.decision, e.target_xy)
        self._write("/explore/frontiers", k, fronts)
        self._write("/semsearch/goal", k, goal)
        self._write("/semsearch/decision", k, self.m.string(json_safe(e.row())))

    def _thinned(self) -> list:
        """The path so far, one pose every ``PATH_STEP_M`` of travel (its last pose kept): a
        whole path at every decision would grow with the square of the run's length."""
        k = max(1, int(round(PATH_STEP_M / self.step_m)))
        return self.trail[::k] + ([self.trail[-1]] if (len(self.trail) - 1) % k else [])

    def finish(self) -> None:
        """The map and the path as the run ended."""
        if self.belief is not None:
            self.bag.write("/map", self.t + 1000, self.m.grid(self.t, self.state, self.frame))
            self.bag.write("/semsearch/path", self.t + 2000, self.m.path(self.t, self._thinned()))
            self.t += 2000


@dataclass
class Exported:
    """One run written as a bag: its name (the record's file stem), the bag folder, its size in
    bytes, messages, decisions, and the row it replayed to."""

    name: str
    folder: Path
    size: int
    messages: int
    decisions: int
    outcome: str
    distance_m: float


def recorded_runs(folder: Path) -> list[tuple[str, dict, Path]]:
    """(name, the run's row, its decisions record) of every door-search run of a results folder
    that has a record (``semsearch run --decisions``); chain stages are left out (a chain's
    run is exported as its first stage's search is not: one search per bag)."""
    rows = read_runs(folder / "runs.csv", as_written=True)
    check_engine(rows, folder / "runs.csv")  # another engine's runs replay with the release that made them
    out = []
    for row in rows[rows["stage"] == ""].to_dict("records"):
        name = file_stem(str(row["planner"]), row["goal"], int(row["seed"]), int(row["episode"]))
        f = folder / "decisions" / f"{name}.json"
        if f.is_file():
            out.append((name, row, f))
    return out


def export_run(loaded: Loaded, name: str, row: dict, record_file: Path, out: Path, fmt: str) -> Exported:
    """Replay one recorded run into a bag folder ``out`` (which must not exist), checked as
    ``semsearch verify`` checks it (the record the row names, the run it records, the row's
    outcome, distance, steps and decisions); a :class:`ScenarioError` when it does not replay, and
    then nothing is left behind."""
    task = loaded.task
    if not isinstance(task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {task.kind}: only door-search runs export as bags so far")
    episodes = {(str(e.goal), e.index): e for e in task.episodes}
    ep = episodes.get((str(row["goal"]), int(row["episode"])))
    if ep is None:
        raise ScenarioError(str(record_file), "episode", f"the scenario has no episode {row['episode']} of goal {row['goal']}")
    work = out.with_name(f".{out.name}.partial")  # the bag is written here, then moved into place whole
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    tmp = work / out.name  # rosbags names the storage file after its folder
    bag = None
    try:
        bag = BagWriter(tmp, fmt, Messages())
        rec = BagRecorder(bag, loaded.world, ep.goal, loaded.sc.robot.step, loaded.sc.laser.range)
        setup = {"scenario": loaded.sc.name, "file": loaded.path.stem, "fingerprint": loaded.fingerprint, "engine": ENGINE,
                 # the run's generator's increment (fixed for a run; seeded as Task.run seeds it): with the
                 # states the events carry (rng_word), the replay's generator is the run's
                 "rng_inc": np.random.default_rng(episode_seed(ep, int(row["seed"]), loaded.sc.experiment.base_seed))
                 .bit_generator.state["state"]["inc"],
                 "goal": sign_label(ep.goal), "planner": str(row["planner"]), "episode": int(row["episode"]), "seed": int(row["seed"])}
        bag.write("/semsearch/setup", START_NS - 1000, bag.msgs.string(setup))
        why = replay_run(task, record_file, str(row["planner"]), str(row["goal"]), int(row["episode"]), int(row["seed"]), [row],
                         episodes, observer=rec)
        if why:
            raise ScenarioError(str(record_file), "decisions", f"does not replay: {why}")
        rec.finish()
        bag.close()
    except BaseException:
        drop_bag(bag, work)
        raise
    tmp.rename(out)
    work.rmdir()
    size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    return Exported(name, out, size, bag.count, rec.decisions, str(row["outcome"]), float(row["distance_m"]))


def exportable(loaded: Loaded) -> None:
    """A :class:`ScenarioError` unless ``loaded`` is a door search (the kind a bag holds)."""
    if not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind} search: semsearch export writes door-search runs "
                            "as bags (the robot's map, pose and signs); a results folder of door search exports")


def export_folder(loaded: Loaded, folder: Path, out: Path, fmt: str, run: str | None = None,
                  kept: Callable[[str], None] | None = None) -> list[Exported]:
    """Every recorded run of ``folder`` (or the one named ``run``: its decisions file's stem) as a
    bag folder ``out/<run>``; runs whose bag exists already are left as they are (``kept`` is
    called with each one's name). Returns the runs exported. A run that does not replay is
    named in a :class:`ScenarioError` raised once the others are written; a folder of another kind
    of search is refused before anything is written."""
    exportable(loaded)
    runs = recorded_runs(folder)
    if not runs:
        raise ScenarioError(str(folder / "decisions"), "", "no run of this folder has a decisions record: run it with "
                            "--decisions (`semsearch run SCENARIO --decisions --out DIR`)")
    if run is not None:
        named = [r for r in runs if r[0] == run]
        if not named:
            raise ScenarioError("<command line>", "--run", f"no recorded run {run!r} in {folder}{did_you_mean(run, [r[0] for r in runs])} "
                                f"({len(runs)} recorded: the names of {folder / 'decisions'}'s files without .json)")
        runs = named
    other = [r for r in runs if str(r[1].get("fingerprint", "")) != loaded.fingerprint]
    if other:
        raise ScenarioError(str(loaded.path), "fingerprint", f"{len(other)} of the {len(runs)} runs were made with another scenario "
                            f"(fingerprint {other[0][1].get('fingerprint')}, this one's {loaded.fingerprint}): give the scenario "
                            "they were made with (--scenario)")
    out.mkdir(parents=True, exist_ok=True)
    done, failed = [], []
    for name, row, f in runs:
        target = out / name
        if target.exists():
            if kept is not None:
                kept(name)
            continue
        try:
            done.append(export_run(loaded, name, row, f, target, fmt))
        except ScenarioError as exc:
            failed.append(f"{name}: {exc.message}")
    if failed:
        kept = f" ({len(done)} other bag(s) written)" if done else ""
        raise ScenarioError(str(folder / "decisions"), "", f"{len(failed)} run(s) do not replay{kept}: " + "; ".join(failed[:3])
                            + ("; ..." if len(failed) > 3 else ""))
    return done
