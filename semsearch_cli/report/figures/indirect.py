"""Indirect search's figures (Loncomilla et al. 2018): success against the view scale beside the
paper's (:func:`plot_success_by_scale`), the rooms (:func:`plot_rooms`) and a GIF of the
probability map during one search (:func:`animate_probability`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import common
from .common import COLUMN_IN, GOAL_COLOR, PALETTE, _animate, _legend, _paper, planner_colors, wrap_label

import matplotlib.pyplot as plt  # after .common, which chooses the Agg backend
from matplotlib.lines import Line2D
from matplotlib.patches import Patch


# ---- indirect search (Loncomilla et al. 2018) ---------------------------------------------------
@_paper
def plot_success_by_scale(table, order: list, paper: dict, paper_scales, out: Path, formats=("png",)) -> list[Path]:
    """Success rate against the view scale as small multiples, one panel per method: ours (the
    method's colour, 95% intervals from columns ci_low, ci_high) beside the paper's Table 3 (grey,
    dashed) on shared axes."""
    colors = planner_colors(order)
    cols = min(4, max(1, len(order)))
    rows = -(-len(order) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2 * COLUMN_IN, 1.45 * rows + 0.45), squeeze=False, sharex=True,
                             sharey=True, layout="constrained")
    for ax, m in zip(axes.flat, order):
        d = table[table["planner"] == m].sort_values("view_scale")
        ref = paper.get(m.split("[", 1)[0])
        if ref is not None:
            ax.plot(paper_scales, ref, "s--", c="0.55", ms=2.5, lw=0.9, zorder=2)
        c = colors[m]
        lo, hi = d["ci_low"].fillna(d["success"]), d["ci_high"].fillna(d["success"])
        ax.fill_between(d["view_scale"], 100 * lo, 100 * hi, color=c, alpha=0.2, lw=0, zorder=1)
        ax.plot(d["view_scale"], 100 * d["success"], "o-", c=c, ms=3, lw=1.2, zorder=3)
        n = sorted(set(d["n"].astype(int)))
        ax.set_title(f"{wrap_label(m, 30)} (n={'/'.join(map(str, n))})", fontsize=8, color=c if c != "#000000" else "black")
        ax.set_ylim(-3, 104)  # room for the markers at 0 and 100%, which the frame would cut in half
        ax.set_yticks([0, 25, 50, 75, 100])
        ax.grid(alpha=0.3, lw=0.5)
    for ax in axes.flat[len(order):]:
        ax.remove()
    used = list(axes.flat[:len(order)])
    for ax in axes[:, 0]:
        ax.set_ylabel("success (%)")
    for j in range(cols):  # the lowest panel of each column carries the x label
        col = [ax for ax in axes[:, j] if ax in used]
        col[-1].set_xlabel("view scale (m)")
        col[-1].xaxis.set_tick_params(labelbottom=True)
    handles = [Line2D([], [], c="0.3", marker="o", ms=3, label="ours"),
               Patch(color="0.3", alpha=0.2, lw=0, label="its 95% interval"),
               Line2D([], [], c="0.55", ls="--", marker="s", ms=2.5, label="the paper's Table 3")]
    _legend(fig, used, handles, ncol=3)
    return common._save(fig, out, formats)


@_paper
def plot_rooms(rooms: list, title: str, out: Path, formats=("png",)) -> list[Path]:
    """Rooms of indirect search, small multiples: obstacles, the objects (A first), the start."""
    n = len(rooms)
    cols = min(5, n)
    rows = -(-n // cols)
    side = 2 * COLUMN_IN / cols
    fig, axes = plt.subplots(rows, cols, figsize=(side * cols, side * rows + 0.5), squeeze=False, layout="constrained")
    colors = [PALETTE[1], PALETTE[4], PALETTE[0], PALETTE[3], PALETTE[2]]
    for ax, room in zip(axes.ravel(), rooms):
        w, h = room.size
        ax.add_patch(plt.Rectangle((0, 0), w, h, fill=False, lw=1.0))
        for x0, y0, x1, y1 in room.obstacles:
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.55"))
        for k, (cls, t) in enumerate(room.objects.items()):
            ax.plot(t.x, t.y, "o", c=colors[k % len(colors)], ms=4, label=cls)
            a = np.radians(t.yaw)
            ax.plot([t.x, t.x + 0.35 * np.cos(a)], [t.y, t.y + 0.35 * np.sin(a)], "-", c=colors[k % len(colors)], lw=0.8)
        x, y, hd = room.start
        ax.plot(x, y, "s", ms=4, mfc="white", mec="black")
        ax.arrow(x, y, 0.4 * np.cos(np.radians(hd)), 0.4 * np.sin(np.radians(hd)), color="black", width=0.02)
        ax.set_xlim(-0.1, w + 0.1)
        ax.set_ylim(-0.1, h + 0.1)
        ax.set_aspect("equal")
        ax.set_title(room.name, fontsize=7)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.axis("off")  # the room's own outline is the frame
    for ax in axes.ravel()[n:]:
        ax.remove()
    handles, labels = axes.ravel()[0].get_legend_handles_labels()
    _legend(fig, list(axes.ravel()[:n]), handles, ncol=min(5, len(labels)))
    fig.suptitle(title)
    return common._save(fig, out, formats)


@_paper
def animate_probability(room, target: str, frames: list, title: str, out: Path, fps: int = 4) -> None:
    """A GIF of one indirect search: per re-plan, the probability map of A (the robot's belief,
    each frame scaled to its own maximum), the path so far, the secondary objects seen, the goal;
    A itself ringed."""
    w, h = room.size
    fig, ax = plt.subplots(figsize=(COLUMN_IN, COLUMN_IN * h / w + 0.55), layout="constrained")
    target = room.objects[target]
    key = [Line2D([], [], c=PALETTE[5], lw=1, label="path"),
           Line2D([], [], ls="", marker="o", ms=5, c=PALETTE[2], mec="black", label="robot"),
           Line2D([], [], ls="", marker="s", ms=5, c=PALETTE[4], label="objects seen"),
           Line2D([], [], ls="", marker="x", ms=6, mew=1.8, c="black", label="goal"),
           Line2D([], [], ls="", marker="o", ms=8, mfc="none", mec=GOAL_COLOR, mew=1.8, label="A, the target")]
    fig.legend(handles=key, loc="outside lower center", ncol=5, fontsize=6.5, handlelength=1.0, columnspacing=0.7,
               handletextpad=0.3)

    def draw(k):
        ax.clear()
        f = frames[k]
        ax.imshow(f["p"], cmap="magma", vmin=0.0, vmax=float(f["p"].max()) or 1.0, extent=(0, w, 0, h),
                  interpolation="nearest")
        for x0, y0, x1, y1 in room.obstacles:
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.6"))
        ax.plot(f["trail"][:, 0], f["trail"][:, 1], "-", c=PALETTE[5], lw=1)
        ax.plot(*f["trail"][-1], "o", c=PALETTE[2], mec="black", ms=5)
        for cls, (x, y) in f["seen"].items():
            ax.plot(x, y, "s", c=PALETTE[4], ms=5)
            ax.annotate(cls, (x, y), xytext=(3, 3), textcoords="offset points", fontsize=6.5, color="white")
        ax.plot(target.x, target.y, "o", mfc="none", mec=GOAL_COLOR, ms=11, mew=1.8)
        ax.annotate("A", (target.x, target.y), xytext=(6, 6), textcoords="offset points", color=GOAL_COLOR, weight="bold")
        ax.plot(*f["goal"], "x", c="white", ms=7, mew=1.8)
        ax.set_title(f"{title}\nt = {f['t']:.0f} s, p(outside) = {f['p0']:.2f}", fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])

    _animate(fig, draw, len(frames), out, fps)
