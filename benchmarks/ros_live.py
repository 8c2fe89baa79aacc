"""``semsearch ros live`` over the loopback rosbridge against ``semsearch run``, episode for episode.

    python benchmarks/ros_live.py [--seeds 3] [--period 0.04] [--md FILE]

On the demo building (configs/demo.yaml), for greedy and nsos, goals 304 and 452, seeds 0..N-1:
the simulator's run (Task.run) and the same episode driven live, the stand-in robot
(semsearch_cli/ros2/loopback.py: the simulator behind a rosbridge server on 127.0.0.1, a step
every --period seconds) taking ros live's NavigateToPose goals. Prints, per run, the outcome,
the run's distance and the robot's (the distance at the frame that read the goal's sign, as the
run measures it), their difference, the decisions of each, the first decision where they part
(their targets or steps differ; "-" when none does), the goals the robot took after it had
already moved on from the pose they were planned on (late), and the live run's wall time.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from output import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from semsearch_cli.report.document import markdown_table  # noqa: E402
from semsearch_cli.ros2.live import Live  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.ros2.loopback import Rosbridge, SimRobot  # noqa: E402
from semsearch_cli.runner import Loaded  # noqa: E402
from semsearch_cli.tasks.base import Observer  # noqa: E402
from semsearch_cli.tasks.doors import DoorDecision  # noqa: E402


class Decisions(Observer):
    def __init__(self):
        self.rows = []

    def see(self, event):
        if isinstance(event, DoorDecision):
            self.rows.append((int(event.step), round(float(event.target_xy[0]), 6), round(float(event.target_xy[1]), 6)))


def one(loaded, planner: str, goal: str, seed: int, period: float, tmp: Path) -> dict:
    variant = Variant(planner, ())
    seen = Decisions()
    res = loaded.task.run(variant, goal, seed, observer=seen)
    bridge = Rosbridge().start()
    try:
        robot = SimRobot(bridge, loaded, goal, seed, period=period).start()
        t0 = time.perf_counter()
        live = Live(bridge.url, variant, goal, loaded.sc, repro=tmp / f"{planner}_{goal}_{seed}", max_distance=500.0,
                    silence=20.0).run()
        wall = time.perf_counter() - t0
    finally:
        bridge.stop()
    got = [(r["step"], round(r["target"][0], 6), round(r["target"][1], 6)) for r in live.decisions]
    part = next((k for k, (a, b) in enumerate(zip(seen.rows, got)) if a != b), None)
    if part is None and len(seen.rows) != len(got):
        part = min(len(seen.rows), len(got))
    robot_m = robot.found_at if robot.found_at is not None else robot.distance
    return {"planner": planner, "goal": goal, "seed": seed, "run": res.outcome, "live": live.outcome,
            "run m": round(res.distance_m, 2), "robot m": round(robot_m, 2), "diff m": round(robot_m - res.distance_m, 2),
            "run decisions": res.decisions, "live decisions": len(live.decisions),
            "parts at": "-" if part is None else part, "late goals": f"{sum(1 for k in robot.late if k > 0)}/{len(robot.late)}",
            "wall s": round(wall, 1)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--period", type=float, default=0.04, help="s between the stand-in robot's steps")
    ap.add_argument("--md", type=Path)
    a = ap.parse_args()
    loaded = Loaded.load(ROOT / "configs" / "demo.yaml", planners=False)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for planner in ("greedy", "nsos"):
            for goal in ("304", "452"):
                for seed in range(a.seeds):
                    rows.append(one(loaded, planner, goal, seed, a.period, Path(tmp)))
                    print(rows[-1], file=sys.stderr, flush=True)
    diffs = [abs(r["diff m"]) / r["run m"] for r in rows]
    text = (f"ros live over the loopback rosbridge against semsearch run (demo building, a robot step every {a.period:g} s)\n\n"
            + markdown_table(pd.DataFrame(rows)) + f"\n\nfound live: {sum(r['live'] == 'found' for r in rows)}/{len(rows)}; "
            f"|robot - run| / run: median {sorted(diffs)[len(diffs) // 2]:.1%}, largest {max(diffs):.1%}; "
            f"identical decisions: {sum(r['parts at'] == '-' for r in rows)}/{len(rows)}\n")
    return emit(text, a.md)


if __name__ == "__main__":
    raise SystemExit(main())
