"""Maps with paths: every run of each planner over the ground truth as small multiples
(:func:`plot_path_panels`; the door, object and chain reports), and a scenario's map with its
signs, start and goals (:func:`plot_scenario`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import common
from .common import (COLUMN_IN, EVERY_RUN_LW, GOAL_COLOR, PALETTE, _axes_m_per_pt, _draw_map, _grid, _label_outer, _legend,
                     _map_axes, _number_signs, _paper, _places, _sign_labels, _starts, _stops, every_run_alpha,
                     planner_colors, wrap_label)

import matplotlib.pyplot as plt  # after .common, which chooses the Agg backend
from matplotlib.lines import Line2D


@_paper
def plot_path_panels(world, panels: dict, stops, title: str, out: Path, formats=("png",), colors: dict | None = None,
                     starts=None, places: dict | None = None, truth=(), route=None, near_m: float = 3.0) -> list[Path]:
    """Runs over the ground-truth map as small multiples: one panel per planner, shared axes.

    Parameters
    ----------
    world : World
        The ground truth (map light, walls dark; signs as grey dots).
    panels : {label: (paths, median, note)}
        Per planner: every run's path (list of (n, 2) float arrays, m), drawn faint
        (:func:`every_run_alpha`); the index of the run to draw bold in that list (its median run,
        :func:`~semsearch_cli.report.runfiles.median_panel`), with the signs within ``near_m`` m of
        it numbered (labels that would overlap are dropped); a note for the panel's title, one or
        two lines (a second line makes the legend say the title names the bold run). ``{}``
        draws the map alone. The legend takes the grid's free cell when there is one.
    stops : list of (text, x, y)
        The goal(s), or a chain's doors, starred and labelled.
    starts : list of (x, y), optional
        The starts of the runs shown (default: the scenario's start).
    places, truth, route :
        Object search: the places (labelled), the ones holding the target (ringed), the patrol
        route ((n, 2), dotted).
    """
    colors = colors or planner_colors(list(panels))
    n = max(1, len(panels))
    fr = world.frame
    aspect = fr.height / fr.width
    two_lines = any("\n" in note for _, _, note in panels.values())
    fig, axes = _grid(n, COLUMN_IN * aspect + (0.6 if two_lines else 0.45), maps=True, sharex=True, sharey=True)
    starts = [world.start_xy] if starts is None else starts
    items = list(panels.items()) or [("", ([], -1, ""))]
    s = world.signs
    stop_signs = {i for _, x, y in stops for i in np.flatnonzero(np.hypot(s.x - x, s.y - y) < 1e-6)} if len(s) else set()
    for ax, (lab, (paths, median, note)) in zip(axes, items):
        _draw_map(ax, world, COLUMN_IN)
        if len(s):
            ax.scatter(s.x, s.y, s=1.5, c="#777777", lw=0, zorder=2)
        if route is not None:
            ax.plot(route[:, 0], route[:, 1], ":", c="black", lw=0.9, zorder=3)
        c = colors.get(lab, "black")
        for k, p in enumerate(paths):
            if k != median:
                ax.plot(p[:, 0], p[:, 1], "-", c=c, lw=EVERY_RUN_LW, alpha=every_run_alpha(len(paths)), zorder=3)
        if 0 <= median < len(paths):
            p = paths[median]
            ax.plot(p[:, 0], p[:, 1], "-", c=c, lw=1.5, zorder=4, solid_capstyle="round")
            ax.plot(p[-1, 0], p[-1, 1], "o", c=c, mec="black", mew=0.5, ms=4, zorder=5)
        if places:
            _places(ax, places, truth)
        _starts(ax, starts)
        if lab:
            ax.set_title(f"{wrap_label(lab, 40)}: {note}" if note else wrap_label(lab, 40), color="black")
        _map_axes(ax)
    _label_outer(axes)
    handles = [Line2D([], [], c="0.35", lw=EVERY_RUN_LW, alpha=every_run_alpha(10), label="every run"),
               Line2D([], [], c="0.35", lw=1.5, label="median run (dot: its end)" if not two_lines else
                      "bold: the run its title names (dot: its end)"),
               Line2D([], [], ls="", marker="s", ms=4.5, mfc="white", mec="black", label="start" + ("s" if len(starts) > 1 else "")),
               Line2D([], [], ls="", marker="*", ms=9, mfc=GOAL_COLOR, mec="black", label="goal")]
    if not stops:
        handles.pop(3)
    if not panels:
        handles = handles[2:]
    if len(s):
        handles.append(Line2D([], [], ls="", marker="o", ms=2, mfc="#777777", mec="none", label="door sign"))
    if truth:
        handles.append(Line2D([], [], ls="", marker="o", ms=8, mfc="none", mec="black", mew=1.4, label="target at the request"))
    if route is not None:
        handles.append(Line2D([], [], ls=":", c="black", lw=0.9, label="patrol route"))
    _legend(fig, axes, handles, ncol=min(len(handles), 5 if n > 1 else 3), handlelength=1.6, columnspacing=1.0)
    if title:
        fig.suptitle(title)
    # labels last, sized by the panels as laid out: the goals', then the numbers of the signs near
    # the bold run that meet no label already drawn
    m = _axes_m_per_pt(axes[0])
    start_boxes = [(x, y, 6 * m, 6 * m) for x, y in starts]
    for ax, (lab, (paths, median, note)) in zip(axes, items):
        bold = paths[median] if 0 <= median < len(paths) else np.zeros((0, 2))
        # a stop's label keeps off the starts and the bold run (sampled every ~2 pt of the map)
        trail = [(x, y, 2 * m, 2 * m) for x, y in bold[:: max(1, len(bold) // 400)]]
        drawn = _stops(ax, stops, m, start_boxes + trail)
        if 0 <= median < len(paths) and len(s) and places is None:
            _sign_labels(ax, world, paths[median], stop_signs, m, near_m, fixed=drawn + start_boxes)
    return common._save(fig, out, formats)


@_paper
def plot_scenario(world, goals, title: str, out: Path, formats=("png",)) -> list[Path]:
    """The ground-truth map with every sign (dot, facing tick, number behind its wall), the start
    and the goals, two columns wide (every number is shown, at 5.5 pt; a goal's in its star's
    label, placed where it covers no other number when there is such a place)."""
    width = 2 * COLUMN_IN
    fr = world.frame
    fig, ax = plt.subplots(figsize=(width, width * fr.height / fr.width + 0.6), layout="constrained")
    _draw_map(ax, world, width)
    s = world.signs
    ax.quiver(s.x, s.y, np.cos(s.facing), np.sin(s.facing), color=PALETTE[0], scale=80, width=0.0012, zorder=3)
    ax.scatter(s.x, s.y, s=4, c=PALETTE[0], lw=0, zorder=4, label=f"door signs ({len(s)}), facing; number behind the wall")
    _starts(ax, [world.start_xy])
    ax.plot([], [], "s", ms=4.5, mfc="white", mec="black", ls="", label="start")
    ax.plot([], [], "*", ms=9, mfc=GOAL_COLOR, mec="black", ls="", label="goals")
    _map_axes(ax)
    ax.set_title(title)
    fig.legend(loc="outside lower center", ncol=3)
    m = _axes_m_per_pt(ax)  # labels last, sized by the map as laid out
    at = [s.index_of(g) for g in goals]
    stops = [(f"goal {g}", float(s.x[i]), float(s.y[i])) for g, i in zip(goals, at) if i >= 0]
    # a goal's own number is in its star's label: not written again under the star
    goal_signs = set(at)
    numbers = _number_signs(ax, world, [i for i in range(len(s)) if i not in goal_signs], m, 5.5, rotate=True)
    _stops(ax, stops, m, numbers + [(*world.start_xy, 6 * m, 6 * m)])
    return common._save(fig, out, formats)
