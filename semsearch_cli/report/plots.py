"""Plots (the only module that imports matplotlib)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _extent(world):
    fr = world.frame
    return (fr.origin_x, fr.origin_x + fr.width * fr.res, fr.origin_y, fr.origin_y + fr.height * fr.res)


def plot_path(world, path: np.ndarray, read_signs, goal, title: str, out: Path) -> None:
    """The path of one run over the ground-truth map with the start, the signs read and the goal."""
    fr = world.frame
    aspect = fr.height / fr.width
    fig, ax = plt.subplots(figsize=(10, max(3.0, 10 * aspect)))
    ax.imshow(np.where(world.free, 1.0, 0.25), cmap="gray", vmin=0, vmax=1, extent=_extent(world), interpolation="nearest")
    s = world.signs
    ax.scatter(s.x, s.y, s=6, c="#9999cc", label="signs")
    if len(read_signs):
        idx = np.asarray(read_signs, int)
        ax.scatter(s.x[idx], s.y[idx], s=10, c="tab:blue", label="signs read")
    ax.plot(path[:, 0], path[:, 1], "-", c="tab:orange", lw=1.2, label="path")
    ax.plot(*world.start_xy, "s", c="tab:green", ms=8, label="start")
    g = s.index_of(goal)
    ax.plot(s.x[g], s.y[g], "*", c="tab:red", ms=14, label=f"goal {goal}")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.8)
    fig.tight_layout()
    tmp = out.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, out)


def plot_alpha_sweep(runs, out: Path, baseline: str = "greedy") -> None:
    """Mean ratio to the shortest path (+- std across seeds) against alpha, one panel per goal;
    the baseline planner (greedy) as a dashed line with its spread shaded."""
    nsos = runs[runs["planner"].str.startswith("nsos")].copy()
    nsos["alpha"] = nsos["params"].map(lambda p: json.loads(p).get("alpha", 0.9))
    goals = sorted(runs["goal"].unique(), key=str)
    fig, axes = plt.subplots(1, len(goals), figsize=(4.2 * len(goals), 3.6), squeeze=False, sharey=False)
    for ax, g in zip(axes[0], goals):
        d = nsos[nsos["goal"] == g].groupby("alpha")["ratio"].agg(["mean", "std", "count"]).reset_index()
        ax.errorbar(d["alpha"], d["mean"], yerr=d["std"].fillna(0), fmt="o-", capsize=3, c="tab:blue", label="nsos")
        base = runs[(runs["planner"] == baseline) & (runs["goal"] == g)]["ratio"]
        if len(base):
            m, s = base.mean(), (base.std() if len(base) > 1 else 0.0)
            ax.axhline(m, ls="--", c="tab:orange", label=baseline)
            ax.axhspan(m - s, m + s, color="tab:orange", alpha=0.15)
        ax.axhline(1.0, c="gray", lw=0.8)
        ax.set_title(f"goal {g}")
        ax.set_xlabel("alpha (weight of the semantic factor)")
        ax.set_ylabel("distance / shortest path")
        ax.legend(fontsize=7)
    fig.suptitle("alpha sweep: mean ratio to the shortest path, +- std over seeds")
    fig.tight_layout()
    tmp = out.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, out)


def plot_scenario(world, goals, title: str, out: Path) -> None:
    """The ground-truth map with every sign (dot, number, facing tick), the start and the goals."""
    fr = world.frame
    aspect = fr.height / fr.width
    fig, ax = plt.subplots(figsize=(12, max(3.5, 12 * aspect)))
    ax.imshow(np.where(world.free, 1.0, 0.25), cmap="gray", vmin=0, vmax=1, extent=_extent(world), interpolation="nearest")
    s = world.signs
    ax.quiver(s.x, s.y, np.cos(s.facing), np.sin(s.facing), color="tab:blue", scale=40, width=0.002)
    ax.scatter(s.x, s.y, s=8, c="tab:blue", label=f"signs ({len(s)})")
    size = 6 if len(s) <= 60 else 4.5
    for lab, x, y in zip(s.number, s.x, s.y):
        ax.annotate(str(lab), (x, y), fontsize=size, color="navy", xytext=(2, 2), textcoords="offset points")
    for g in goals:
        i = s.index_of(g)
        ax.plot(s.x[i], s.y[i], "*", c="tab:red", ms=14)
        ax.annotate(f"goal {g}", (s.x[i], s.y[i]), fontsize=8, color="tab:red", xytext=(4, -10), textcoords="offset points")
    ax.plot(*world.start_xy, "s", c="tab:green", ms=9, label="start")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.8)
    fig.tight_layout()
    tmp = out.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=130)
    plt.close(fig)
    os.replace(tmp, out)
