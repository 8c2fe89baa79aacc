"""A learned door-search baseline: MaskablePPO (sb3-contrib) in the macro mode of
``semsearch/DoorSearch-Generated-v1``, trained on generated buildings and evaluated on held-out
ones against greedy and nsos, on the same episodes.

    pip install torch==2.13.0   # a CPU build; see the README of this folder
    pip install '.[gym]' sb3-contrib
    python examples/rl/train_maskable_ppo.py [--minutes 25] [--buildings 100] [--eval-buildings 20] [--out results/rl]

Training: buildings 0 .. buildings-1 (layout wings, numbering odd-even-out, 3 m door spacing), a
building and an episode (one of its four goals, from its start, a random heading) drawn at each
reset, two environments in subprocesses, episodes cut at 500 m (``max_distance``), for at most
``--minutes`` of wall-clock time. The policy sees a compact vector (:class:`Features`): per
candidate slot, whether it is filled, its offset (m / 20) and branch direction; per sign read,
whether it shares the goal's prefix, its number minus the goal's (/ 100, clipped to +-1), its
offset and facing; and the candidate mask.

Evaluation: buildings 1000 .. 1000 + eval-buildings - 1 (never seen in training), each of their four
episodes once (repeat 0), the scenario's own 2000 m budget; the learned policy, greedy and
nsos[alpha=0.9] (through :class:`semsearch_cli.envs.PlannerPolicy`, the same simulator) on the same
episodes. Prints success, SPL and the paired distance differences with 95% bootstrap intervals over
the episodes, and writes them to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
import pandas as pd
from sb3_contrib import MaskablePPO
from sb3_contrib.common.wrappers import ActionMasker
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import SubprocVecEnv

import semsearch_cli.envs  # noqa: F401  (registers the environments)
from semsearch_cli.envs import PlannerPolicy
from semsearch_cli.report.document import markdown_table
from semsearch_cli.report.stats import mean_ci

ENV = "semsearch/DoorSearch-Generated-v1"
LAYOUT = {"layout": "wings", "numbering": "odd-even-out", "spacing": 3.0}


class Features(gym.ObservationWrapper):
    """The macro observation as one float32 vector a small MLP can read (see the module docstring)."""

    def __init__(self, env):
        super().__init__(env)
        u = env.unwrapped
        self.K, self.S = u.K, u.S
        n = self.K * 4 + self.S * 7 + 2
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (n,), np.float32)

    def observation(self, obs):
        t = obs["targets"][:, :4].copy()  # the first four columns (v1 adds the path length, fifth)
        t[:, 1:3] = np.clip(t[:, 1:3] / 20.0, -1, 1)
        t[:, 3] /= np.pi
        s = obs["signs"]
        goal = obs["goal"][0]
        rel = np.where(s[:, 0] > 0, np.clip((s[:, 2] - goal) / 100.0, -1, 1), 0.0)
        sg = np.stack([s[:, 0], s[:, 1], rel, np.clip(s[:, 3] / 20.0, -1, 1), np.clip(s[:, 4] / 20.0, -1, 1),
                       np.cos(s[:, 5]) * s[:, 0], np.sin(s[:, 5]) * s[:, 0]], axis=1)
        h = obs["pose"][2]
        return np.concatenate([t.ravel(), sg.ravel(), [np.cos(h), np.sin(h)]]).astype(np.float32)


def make_env(first: int, buildings: int, max_distance: float | None, seed: int):
    def make():
        env = gym.make(ENV, first_building=first, buildings=buildings, max_distance=max_distance, **LAYOUT)
        env = Features(env)
        env = ActionMasker(env, lambda e: e.unwrapped.action_masks())
        env.reset(seed=seed)
        return env
    return make


class WallClock(BaseCallback):
    """Stops training after ``seconds``."""

    def __init__(self, seconds: float):
        super().__init__()
        self.until = time.monotonic() + seconds

    def _on_step(self) -> bool:
        return time.monotonic() < self.until


def episode(env, act, building: int, k: int) -> dict:
    obs, info = env.reset(options={"building": building, "episode": k, "repeat": 0})
    done = False
    while not done:
        obs, _, term, trunc, info = env.step(act(env, obs, info))
        done = term or trunc
    found = info["outcome"] == "found"
    spl = info["shortest_m"] / max(info["shortest_m"], info["distance_m"]) if found else 0.0
    return {"building": building, "episode": k, "goal": info["goal"], "outcome": info["outcome"], "found": found,
            "distance_m": info["distance_m"], "shortest_m": info["shortest_m"], "spl": spl}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=25.0)
    ap.add_argument("--buildings", type=int, default=100)
    ap.add_argument("--eval-buildings", type=int, default=20)
    ap.add_argument("--out", type=Path, default=Path("results/rl"))
    a = ap.parse_args()
    if not (math.isfinite(a.minutes) and a.minutes > 0):
        ap.error(f"--minutes must be a positive number, got {a.minutes}")
    for flag, n in (("--buildings", a.buildings), ("--eval-buildings", a.eval_buildings)):
        if n < 1:
            ap.error(f"{flag} must be at least 1, got {n}")
    a.out.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    vec = SubprocVecEnv([make_env(0, a.buildings, 500.0, s) for s in range(2)])
    model = MaskablePPO("MlpPolicy", vec, n_steps=512, batch_size=128, gamma=0.995, ent_coef=0.01, seed=0, verbose=0,
                        device="cpu")
    model.learn(total_timesteps=10**9, callback=WallClock(a.minutes * 60))
    vec.close()
    trained_s = time.monotonic() - t0
    model.save(a.out / "maskable_ppo")

    rows = []
    learned_env = Features(gym.make(ENV, first_building=1000, buildings=a.eval_buildings, **LAYOUT))

    def learned(env, obs, info):
        action, _ = model.predict(obs, action_masks=env.unwrapped.action_masks(), deterministic=True)
        return int(action)

    for b in range(1000, 1000 + a.eval_buildings):
        for k in range(4):
            rows.append({"policy": "MaskablePPO", **episode(learned_env, learned, b, k)})
    for name, params, label in (("greedy", {}, "greedy"), ("nsos", {"alpha": 0.9}, "nsos[alpha=0.9]")):
        pol = PlannerPolicy(name, **params)
        env = gym.make(ENV, first_building=1000, buildings=a.eval_buildings, **LAYOUT, **pol.env_kwargs)

        def act(env, obs, info, pol=pol):
            return pol(env)

        for b in range(1000, 1000 + a.eval_buildings):
            for k in range(4):
                pol.reset()
                rows.append({"policy": label, **episode(env, act, b, k)})
    df = pd.DataFrame(rows)
    df.to_csv(a.out / "evaluation.csv", index=False)
    summary = []
    base = df[df["policy"] == "MaskablePPO"].set_index(["building", "episode"])
    for policy, g in df.groupby("policy", sort=False):
        g = g.set_index(["building", "episode"])
        row = {"policy": policy, "episodes": len(g), "success": f"{g['found'].mean():.0%}", "SPL": round(g["spl"].mean(), 3),
               "mean distance (m)": round(g["distance_m"].mean(), 1)}
        if policy != "MaskablePPO":
            d = (base["distance_m"] - g.loc[base.index, "distance_m"]).to_numpy()
            m, lo, hi = mean_ci(d, np.arange(len(d)))
            row["MaskablePPO - this (m)"] = f"{m:+.1f} [{lo:+.1f}, {hi:+.1f}]"
        summary.append(row)
    table = pd.DataFrame(summary)
    print(f"trained {trained_s / 60:.1f} min ({model.num_timesteps} macro steps) on buildings 0-{a.buildings - 1}; "
          f"evaluated on buildings 1000-{999 + a.eval_buildings}")
    print(markdown_table(table))
    (a.out / "summary.json").write_text(json.dumps({"trained_minutes": trained_s / 60, "timesteps": int(model.num_timesteps),
                                                    "table": summary}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
