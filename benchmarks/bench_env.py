"""Steps per second of the Gymnasium environments, with Minigrid (and IR-SIM, when installed) timed
beside them in the same run.

    pip install '.[benchmarks]'     # gymnasium, minigrid and irsim-x (pyproject's benchmarks extra)
    python benchmarks/bench_env.py [--steps 20000] [--repeat 5] [--md FILE]

One process, random actions (``action_space.sample()``; macro actions drawn among the valid ones
of ``info["action_mask"]``), no rendering, environments made with ``gymnasium.make`` as a user would
(so the order and checker wrappers are timed too), resets counted in. Each figure is the median of
``--repeat`` timed runs of ``--steps`` steps; the ratios are against Minigrid's FourRooms in the
same run, since this machine's speed varies from day to day.

- semsearch primitive: ``semsearch/DoorSearch-v1`` on configs/hotel.yaml in the primitive mode
  (laser into HIMM, door cameras, visited kernel and the observation at every step);
- semsearch macro: the same in the macro mode (a step is a re-plan: about a metre of travel, the
  skeleton and candidates refreshed);
- Minigrid: ``MiniGrid-FourRooms-v0``;
- IR-SIM (irsim-x, in the benchmarks extra): a differential robot with a 181-beam, 10 m lidar on the Hotel
  map (the PNG at its 0.1 m cells), ``env.step()`` driving a wanderer that keeps moving.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import cv2
import gymnasium as gym
import numpy as np

from output import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import semsearch_cli.envs  # noqa: E402,F401  (registers the environments)


def timed(env, steps: int, masked: bool, seed: int) -> float:
    """Steps per second of ``steps`` random steps (resets included)."""
    rng = np.random.default_rng(seed)
    _, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    t0 = time.perf_counter()
    for _ in range(steps):
        if masked:
            a = int(rng.choice(np.flatnonzero(info["action_mask"])))
        else:
            a = env.action_space.sample()
        _, _, term, trunc, info = env.step(a)
        if term or trunc:
            _, info = env.reset()
    return steps / (time.perf_counter() - t0)


def irsim_env(work: Path):
    """An IR-SIM world on the Hotel map: one differential robot with a 181-beam, 10 m lidar; None
    when irsim is not installed."""
    try:
        import irsim
    except ImportError:
        return None
    img = cv2.imread(str(ROOT / "maps/hotel/map.png"), cv2.IMREAD_GRAYSCALE)
    h, w = img.shape[0] * 0.1, img.shape[1] * 0.1  # the map's 0.1 m cells, as configs/hotel.yaml
    (work / "hotel.yaml").write_text(f"""world:
  height: {h:g}
  width: {w:g}
  step_time: 0.1
  obstacle_map: {ROOT / 'maps/hotel/map.png'}
  mdownsample: 1
robot:
  - kinematics: {{name: diff}}
    shape: {{name: circle, radius: 0.2}}
    state: [44.6, 64.0, 0]
    sensors:
      - name: lidar2d
        range_min: 0
        range_max: 10
        angle_range: 3.14159
        number: 181
""")
    return irsim.make(str(work / "hotel.yaml"), display=False, log_level="ERROR")


def timed_irsim(env, steps: int, seed: int) -> float:
    """Steps per second of ``env.step`` driving a wanderer that keeps moving: forward at 0.3 m/s
    with a random turn (+-1 rad/s) while the lidar's middle beams see 1 m clear, else turning on
    the spot (a robot stopped by a collision would make steps cheaper than a moving one's)."""
    rng = np.random.default_rng(seed)
    turns = rng.uniform(-1.0, 1.0, steps)
    lidar = env.robot.sensors[0]
    t0 = time.perf_counter()
    for k in range(steps):
        ahead = np.asarray(lidar.range_data)[80:101].min()
        env.step(np.array([[0.3], [turns[k]]]) if ahead > 1.0 else np.array([[0.0], [1.0]]))
    return steps / (time.perf_counter() - t0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--macro-steps", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--md", type=Path, default=None, help="also write the table as Markdown")
    a = ap.parse_args()
    hotel = str(ROOT / "configs/hotel.yaml")
    cases = {"semsearch primitive (hotel)": (lambda: gym.make("semsearch/DoorSearch-v1", scenario=hotel, action_mode="primitive"), a.steps, False),
             "semsearch macro (hotel)": (lambda: gym.make("semsearch/DoorSearch-v1", scenario=hotel), a.macro_steps, True)}
    try:
        import minigrid  # noqa: F401
        cases["Minigrid FourRooms"] = (lambda: gym.make("MiniGrid-FourRooms-v0"), a.steps, False)
    except ImportError:
        print("minigrid is not installed (pip install '.[benchmarks]'): its column is left out", file=sys.stderr)
    rates: dict[str, list[float]] = {k: [] for k in cases}
    envs = {k: make() for k, (make, _, _) in cases.items()}
    with tempfile.TemporaryDirectory() as tmp:
        ir = irsim_env(Path(tmp))
        if ir is not None:
            rates["IR-SIM (irsim-x), 181-beam lidar (hotel)"] = []
        for r in range(a.repeat):  # interleaved, so that a slow spell of the machine hits every column
            for k, (_, steps, masked) in cases.items():
                rates[k].append(timed(envs[k], steps, masked, seed=r))
            if ir is not None:
                rates["IR-SIM (irsim-x), 181-beam lidar (hotel)"].append(timed_irsim(ir, a.steps // 4, r))
    base = statistics.median(rates["Minigrid FourRooms"]) if "Minigrid FourRooms" in rates else None
    lines = [f"steps per second, median of {a.repeat} runs (one process, random actions, no rendering)", "",
             "| environment | steps/s | min | max | ratio to Minigrid FourRooms |", "|---|---|---|---|---|"]
    for k, v in rates.items():
        med = statistics.median(v)
        ratio = f"{med / base:.2f}" if base else ""
        lines.append(f"| {k} | {med:,.0f} | {min(v):,.0f} | {max(v):,.0f} | {ratio} |")
    return emit("\n".join(lines), a.md)


if __name__ == "__main__":
    sys.exit(main())
