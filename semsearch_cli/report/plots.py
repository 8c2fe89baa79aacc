"""Plots (the only module that imports matplotlib)."""

from __future__ import annotations

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
