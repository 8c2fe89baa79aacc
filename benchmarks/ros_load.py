"""``semsearch ros live`` under load: the loopback stand-in robot publishing its pose at 200 Hz and its
whole map every 100 ms (as a localisation node and a SLAM node at their usual rates), for minutes.

    python benchmarks/ros_load.py [--scenario configs/hotel.yaml] [--goal 148] [--planner greedy]
                                  [--minutes 10] [--pose-hz 200] [--map-ms 100] [--step-s 0.2] [--md FILE]

The robot (semsearch_cli/ros2/loopback.py's SimRobot, its ticks replaced) steps ``robot.step`` metres
every ``--step-s`` seconds towards ros live's NavigateToPose goal (0.1 m per 0.2 s: 0.5 m/s), and
between steps publishes the pose it stands at, at ``--pose-hz``; its map goes out whole every
``--map-ms`` whether it changed or not. ros live runs in this process, as ``semsearch ros live``
does; the run ends at ``--minutes`` (as Ctrl-C ends it) or when the goal is found.

Measured: the messages ros live took and dropped, the queue between roslibpy's thread and the
session (its length at each message: a queue that grows is a live run falling behind), the time
each message and each re-plan took, the goals the robot received after it had already stepped on
from the pose they were planned on (late: a decision not answered within the stand-in's step
period), and the process's resident memory every 10 s (ros live's process; the stand-in runs in a process of its own, as a robot does).
"""

from __future__ import annotations

import argparse
import asyncio
from array import array
import multiprocessing as mp
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
from output import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.report.document import markdown_table  # noqa: E402
from semsearch_cli.ros2.bag import map_states, to_json  # noqa: E402
from semsearch_cli.ros2.live import Live  # noqa: E402
from semsearch_cli.ros2.loopback import Rosbridge, SimRobot  # noqa: E402
from semsearch_cli.runner import Loaded  # noqa: E402


class LoadRobot(SimRobot):
    """The stand-in robot at a localisation's and a SLAM node's rates: a pose every tick, the map
    every ``map_s`` seconds, a step every ``step_s`` seconds."""

    def __init__(self, *args, pose_hz: float, map_s: float, step_s: float, **kw):
        super().__init__(*args, period=1.0 / pose_hz, **kw)
        self.map_s, self.step_s = map_s, step_s
        self.published = {"/semsearch/pose": 0, "/map": 0}

    def _frame(self) -> None:  # sense and read signs as the simulator does; the map and pose go out on their own clocks
        st = self.st
        found, _ = self.sensing.sense(st)
        self.sensing.update(st)
        if found and self.found_at is None:
            self.found_at = st.distance
        signs = self.task.world.signs
        for i, label in self.frames.reads:
            self.bridge.publish("/semsearch/detections", to_json(self.m.detection(signs, int(i), label)))

    def _publish_map(self) -> None:
        b = self.st.belief
        self.bridge.publish("/map", to_json(self.m.grid(self._ns(), map_states(b.seen, b.free), self.task.world.frame)))
        self.published["/map"] += 1

    async def _ticks(self):
        t0 = time.monotonic()
        next_step = next_map = t0
        k = 0
        self._publish_map()
        while True:
            k += 1
            await asyncio.sleep(max(0.0, t0 + k * self.period - time.monotonic()))
            now = time.monotonic()
            if now >= next_step:
                next_step += self.step_s
                if self.path is not None:
                    self._step()
            if now >= next_map:
                next_map += self.map_s
                self._publish_map()
            self.bridge.publish("/semsearch/pose", to_json(self._pose()))
            self.published["/semsearch/pose"] += 1


class Timed(Live):
    """ros live, each message's and re-plan's time and the queue's length recorded."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        # 8 bytes an entry (a list of floats holds 32), so that the benchmark's own records weigh
        # little in the process's memory it measures
        self.took: dict[str, array] = {}
        self.queue = array("q")
        self.replans = array("d")

    def _take(self, topic, payload):
        self.queue.append(self.q.qsize())
        t = time.perf_counter()
        try:
            return super()._take(topic, payload)
        finally:
            self.took.setdefault(topic, array("d")).append(time.perf_counter() - t)

    def _replan(self):
        t = time.perf_counter()
        try:
            return super()._replan()
        finally:
            self.replans.append(time.perf_counter() - t)


def stand_in(pipe, a) -> None:
    """The robot's process: a rosbridge server on loopback and the load robot behind it, until
    told to stop; then what it published and how late its goals came."""
    loaded = Loaded.load(a.scenario, planners=False)
    bridge = Rosbridge().start()
    robot = LoadRobot(bridge, loaded, a.goal, a.seed, pose_hz=a.pose_hz, map_s=a.map_ms / 1000, step_s=a.step_s).start()
    pipe.send(bridge.url)
    pipe.recv()
    bridge.stop()
    pipe.send({"late": list(robot.late), "published": dict(robot.published)})


def rss_mb() -> float:
    line = next(ln for ln in Path("/proc/self/status").read_text().splitlines() if ln.startswith("VmRSS:"))
    return int(line.split()[1]) / 1024


def ms(v) -> str:
    a = np.asarray(v, float) * 1000
    return f"{np.median(a):.2f} / {np.percentile(a, 99):.2f} / {a.max():.1f}" if len(a) else "-"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenario", default=str(ROOT / "configs" / "hotel.yaml"))
    ap.add_argument("--goal", default="148")
    ap.add_argument("--planner", default="greedy")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--pose-hz", type=float, default=200.0)
    ap.add_argument("--map-ms", type=float, default=100.0)
    ap.add_argument("--step-s", type=float, default=0.2)
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    loaded = Loaded.load(a.scenario, planners=False)
    memory: list[tuple[float, float]] = []
    done = threading.Event()

    def sample():
        t0 = time.monotonic()
        while not done.wait(10.0):
            memory.append((time.monotonic() - t0, rss_mb()))

    def stop(signum, frame):
        raise KeyboardInterrupt

    ctx = mp.get_context("fork")
    ours, theirs = ctx.Pipe()
    robot = ctx.Process(target=stand_in, args=(theirs, a), daemon=True)
    robot.start()  # its own process, as a robot is: its server's JSON work does not share ros live's interpreter
    url = ours.recv()
    with tempfile.TemporaryDirectory() as tmp:
        try:
            live = Timed(url, Variant(a.planner, ()), loaded.task.as_episode(a.goal).goal, loaded.sc,
                         repro=Path(tmp) / "repro", silence=30.0)
            threading.Thread(target=sample, daemon=True).start()
            memory.append((0.0, rss_mb()))
            signal.signal(signal.SIGALRM, stop)
            signal.setitimer(signal.ITIMER_REAL, a.minutes * 60)
            t0 = time.perf_counter()
            res = live.run()
            wall = time.perf_counter() - t0
            signal.setitimer(signal.ITIMER_REAL, 0)
            repro_mb = sum(p.stat().st_size for p in res.repro.rglob("*") if p.is_file()) / 1e6 if res.repro else 0.0
        finally:
            done.set()
            ours.send("stop")
            stats = ours.recv()
            robot.join(30)
    memory.append((wall, rss_mb()))
    robot = SimpleNamespace(**stats)
    late = sum(1 for k in robot.late if k > 0)
    rows = [{"what": "run", "value": f"{res.outcome} after {wall:.0f} s: {res.distance:.1f} m, {res.poses} poses, "
             f"{len(res.decisions)} decisions, {res.goals} goals"},
            {"what": "published by the robot", "value": f"{robot.published['/semsearch/pose']:,} poses "
             f"({robot.published['/semsearch/pose'] / wall:.0f} Hz), {robot.published['/map']:,} maps of "
             f"{loaded.world.frame.width} x {loaded.world.frame.height} cells ({robot.published['/map'] / wall:.1f} Hz)"},
            {"what": "taken by ros live", "value": ", ".join(f"{len(v):,} {t}" for t, v in live.took.items())},
            {"what": "dropped", "value": res.dropped or "none"},
            {"what": "queue length at a message (median / 99th pct / max)",
             "value": f"{np.median(live.queue):.0f} / {np.percentile(live.queue, 99):.0f} / {max(live.queue)}"},
            *({"what": f"ms per {t} message (median / 99th / max)", "value": ms(v)} for t, v in live.took.items()),
            {"what": "ms per re-plan (median / 99th / max)", "value": ms(live.replans)},
            {"what": "goals late (the robot had stepped on from their pose)", "value": f"{late} of {len(robot.late)}"},
            {"what": "resident memory, MB (start, 1 min, end; max)",
             "value": f"{memory[0][1]:.0f}, {next((m for t, m in memory if t >= 60), memory[-1][1]):.0f}, {memory[-1][1]:.0f}; "
                      f"{max(m for _, m in memory):.0f}"},
            {"what": "repro bag", "value": f"{repro_mb:.1f} MB"}]
    text = (f"ros live under load: {Path(a.scenario).name}, goal {a.goal}, {a.planner}, seed {a.seed}; poses at {a.pose_hz:g} Hz, "
            f"the map every {a.map_ms:g} ms, a step every {a.step_s:g} s, for {a.minutes:g} min\n\n"
            + markdown_table(pd.DataFrame(rows)) + "\n\nmemory every 10 s (MB): "
            + " ".join(f"{m:.0f}" for _, m in memory))
    emit(text, a.md)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
