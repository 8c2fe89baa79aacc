"""The door-search replay: a GIF of one run (:func:`animate_run`), frame by frame the map the
robot has built, its path, the candidates and the signs read (:func:`draw_replay_frame`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import (COLUMN_IN, GOAL_COLOR, PALETTE, _animate, _axes_m_per_pt, _extent, _number_layout, _number_signs,
                     _paper, _stops)

import matplotlib.pyplot as plt  # after .common, which chooses the Agg backend
from matplotlib.lines import Line2D


# ---- replays (GIF) ------------------------------------------------------------------------------
REPLAY_NUMBER_PT = 6.5  # the signs' numbers in a replay
@_paper
def animate_run(world, frames: list, title: str, out: Path, goal=None, fps: int = 5) -> None:
    """A GIF replay. Per frame (:func:`draw_replay_frame`): the map the robot has built (free
    white, occupied black, unknown grey), its path so far, the candidates and the chosen one, and
    the signs read so far, numbered where the numbers fit; the goal (``(text, x, y)``) starred and
    labelled throughout.

    frames : list of dict with ``map`` ((h, w) uint8: 0 occupied, 1 unknown, 2 free), ``path``
    ((n, 2) m), ``distance`` (m), ``cands`` ((k, 2) m), ``target`` ((x, y) or None) and ``read``
    (list of int: indices into ``world.signs`` of the signs read so far)."""
    fig, draw_frame = replay_figure(world, goal)
    _animate(fig, lambda k: draw_frame(frames[k], title), len(frames), out, fps)


def replay_figure(world, goal=None):
    """The figure of a replay (two columns wide, its legend under the map) and a function
    ``draw_frame(frame, title)`` that draws one frame on it (:func:`draw_replay_frame`), the
    goal's label in the same place in every frame: where it hides the fewest sign numbers."""
    fr = world.frame
    width = 2 * COLUMN_IN
    fig, ax = plt.subplots(figsize=(width, width * fr.height / fr.width + 0.55), layout="constrained")
    legend = [Line2D([], [], c=PALETTE[1], lw=1.2, label="path"),
              Line2D([], [], ls="", marker="o", ms=4, c=PALETTE[0], label="candidates"),
              Line2D([], [], ls="", marker="o", ms=8, mfc="none", mec=PALETTE[1], mew=1.5, label="chosen"),
              Line2D([], [], ls="", marker="o", ms=4, c=PALETTE[2], mec="black", label="robot"),
              Line2D([], [], ls="", marker=".", ms=5, c="#8a2be2", label="signs read"),
              Line2D([], [], ls="", marker="*", ms=9, mfc=GOAL_COLOR, mec="black", label="goal")]
    fig.legend(handles=legend, loc="outside lower center", ncol=6, handlelength=1.2, columnspacing=0.8)
    ext = _extent(world)
    ax.set_xlim(ext[0], ext[1])
    ax.set_ylim(ext[2], ext[3])
    ax.set_aspect("equal")
    ax.set_title("replay")
    ax.set_xticks([])
    ax.set_yticks([])
    m = _axes_m_per_pt(ax)
    goal_sign = _sign_at(world, goal)
    everyone = [b["box"] for b in _number_layout(world, [i for i in range(len(world.signs)) if i != goal_sign], m,
                                                 REPLAY_NUMBER_PT, True)]

    def draw_frame(f: dict, title: str) -> None:
        ax.clear()
        draw_replay_frame(ax, world, f, title, goal, m, everyone)

    return fig, draw_frame


def _sign_at(world, stop) -> int:
    """The index of the sign at a stop ``(text, x, y)``, or -1."""
    s = world.signs
    if stop is None or not len(s):
        return -1
    d = np.hypot(s.x - stop[1], s.y - stop[2])
    return int(np.argmin(d)) if d.min() < 1e-6 else -1


def draw_replay_frame(ax, world, f: dict, title: str, goal, m_per_pt: float, avoid=()) -> None:
    """One frame of :func:`animate_run` on ``ax``: the map as built, the path, the candidates and
    the chosen one, the robot, the signs read (numbered upright on walls that run left-right, in
    the order they were read, a number that would overlap one kept before, the goal's star or its
    label left out; the goal's own number is in its label) and the goal, its label placed where it
    meets the fewest ``avoid`` boxes."""
    ext = _extent(world)
    ax.imshow(f["map"], cmap="gray", vmin=0, vmax=2, extent=ext, interpolation="nearest")
    read = list(f.get("read", []))
    drawn = _stops(ax, [goal], m_per_pt, avoid) if goal is not None else []
    if read:
        sg = world.signs
        ax.scatter(sg.x[read], sg.y[read], s=8, c="#8a2be2", lw=0, zorder=3)
        goal_sign = _sign_at(world, goal)
        _number_signs(ax, world, [i for i in read if i != goal_sign], m_per_pt, REPLAY_NUMBER_PT, fixed=drawn, rotate=True,
                      color="#4b0f8a")
    ax.plot(f["path"][:, 0], f["path"][:, 1], "-", c=PALETTE[1], lw=1.2, zorder=4)
    if len(f["cands"]):
        ax.scatter(f["cands"][:, 0], f["cands"][:, 1], s=12, c=PALETTE[0], lw=0, zorder=5)
    if f["target"] is not None:
        ax.plot(*f["target"], "o", mfc="none", mec=PALETTE[1], ms=8, mew=1.5, zorder=5)
    ax.plot(f["path"][-1, 0], f["path"][-1, 1], "o", c=PALETTE[2], mec="black", ms=5, zorder=6)
    ax.set_title(f"{title}; {f['distance']:.0f} m, {len(read)} signs read")
    ax.set_xlim(ext[0], ext[1])
    ax.set_ylim(ext[2], ext[3])
    ax.set_xticks([])
    ax.set_yticks([])
