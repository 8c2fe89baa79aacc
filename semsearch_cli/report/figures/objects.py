"""Object search's figures (thesis ch. 5): the LSOS heat map with its goals (:func:`plot_heat`),
the heat map built step by step (:func:`plot_heat_steps`) and the distance per case, request
hour and planner as bars (:func:`plot_object_bars`, the thesis' Figure 5.12)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import common
from .common import (_HALO, COLUMN_IN, PALETTE, _draw_map, _extent, _grid, _legend, _map_axes, _outer_y, _paper, _places,
                     _starts, planner_colors)

import matplotlib.pyplot as plt  # after .common, which chooses the Agg backend
from matplotlib.lines import Line2D
from matplotlib.patches import Patch


# ---- object search (thesis ch. 5) ---------------------------------------------------------------
@_paper
def plot_heat(world, heat: np.ndarray, places: dict, truth, goals, title: str, out: Path, formats=("png",)) -> list[Path]:
    """LSOS heat map (Eq. 5.4) over the map, the goals (Eqs. 5.5-5.6) numbered in visiting order."""
    fr = world.frame
    fig, ax = plt.subplots(figsize=(COLUMN_IN, 0.82 * COLUMN_IN * fr.height / fr.width + 0.75), layout="constrained")
    _draw_map(ax, world, COLUMN_IN)
    h = np.ma.masked_where(heat <= 0, heat)
    im = ax.imshow(h, cmap="viridis", extent=_extent(world), interpolation="nearest", alpha=0.9)
    fig.colorbar(im, ax=ax, shrink=0.75, aspect=18, pad=0.02, label="heat")
    _places(ax, places, truth)
    for k, (x, y, phi) in enumerate(goals):
        ax.plot(x, y, "X", c=PALETTE[1], mec="black", mew=0.5, ms=6)
        ax.annotate(str(k + 1), (x, y), xytext=(-9, -9), textcoords="offset points", color=PALETTE[1], weight="bold",
                    path_effects=_HALO)
    _starts(ax, [world.start_xy])
    handles = [Line2D([], [], ls="", marker="X", ms=6, c=PALETTE[1], mec="black", mew=0.5, label="goals, in order"),
               Line2D([], [], ls="", marker="s", ms=4.5, mfc="white", mec="black", label="start R")]
    if truth:
        handles.append(Line2D([], [], ls="", marker="o", ms=8, mfc="none", mec="black", mew=1.4, label="target at the request"))
    _map_axes(ax)
    ax.set_title(title)
    fig.legend(handles=handles, loc="outside lower center", ncol=3, handlelength=1.0, columnspacing=0.8)
    return common._save(fig, out, formats)


@_paper
def plot_object_bars(table, order: list, out: Path, formats=("png",), colors: dict | None = None) -> list[Path]:
    """The thesis' Figure 5.12: per case, the mean distance per request hour and planner with its
    95% CI (columns ``mean``, ``mean_lo``, ``mean_hi``; no bar where there is no interval, as
    with one run); where some runs did not find the object, the bar is hatched and the share that
    did is written above it."""
    colors = colors or planner_colors(order)
    cases = list(dict.fromkeys(table["case"]))
    fig, axes = _grid(len(cases), 2.2, sharey=True)
    width = 0.8 / max(1, len(order))
    for ax, case in zip(axes, cases):
        sub = table[table["case"] == case]
        hours = sorted(sub["hour"].unique(), key=lambda h: (h == 0, h))  # noon before midnight, as the thesis
        for k, lab in enumerate(order):
            s = sub[sub["planner"] == lab].set_index("hour")
            xs = np.arange(len(hours)) + (k - (len(order) - 1) / 2) * width
            mean = np.array([float(s["mean"].get(h, np.nan)) for h in hours])
            lo = np.array([float(s["mean_lo"].get(h, np.nan)) if "mean_lo" in s else np.nan for h in hours])
            hi = np.array([float(s["mean_hi"].get(h, np.nan)) if "mean_hi" in s else np.nan for h in hours])
            bars = ax.bar(xs, mean, width, color=colors[lab])
            ci = np.isfinite(lo) & np.isfinite(hi) & (hi > lo)  # an interval only where there is one (n >= 2, spread)
            if ci.any():
                ax.errorbar(xs[ci], mean[ci], yerr=np.vstack([mean - lo, hi - mean])[:, ci], fmt="none", ecolor="black",
                            capsize=1.5, lw=0.7)
            for bar, x, m, h in zip(bars, xs, mean, hours):
                if h in s.index:
                    rate = float(s.loc[h, "success_rate"])
                    if rate < 1:  # runs that gave up: hatched, the share found above
                        bar.set_hatch("////")
                        bar.set_alpha(0.6)
                        top = hi[list(hours).index(h)]
                        ax.text(x, (top if np.isfinite(top) else m if np.isfinite(m) else 0), f"{rate:.0%}", ha="center",
                                va="bottom", fontsize=7)
        ax.set_xticks(range(len(hours)), [f"{h:02.0f}:{(h % 1) * 60:02.0f}" for h in hours])
        ax.set_title(case)
        ax.set_ylabel("distance (m)")
        ax.set_xlabel("request hour")
        _outer_y(ax)
    top = axes[0].get_ylim()[1]
    axes[0].set_ylim(0, top * 1.2)
    n = table.groupby("planner")["n"].agg(["min", "max"])
    labels = [f"{lab} (n={n.loc[lab, 'min']}" + (f"-{n.loc[lab, 'max']}" if n.loc[lab, "max"] != n.loc[lab, "min"] else "") + ")"
              for lab in order]
    handles = [Patch(color=colors[lab], label=t) for lab, t in zip(order, labels)]
    handles += [Patch(facecolor="white", edgecolor="0.3", hatch="////", label="not found in every run (% found above)"),
                Line2D([], [], c="black", lw=0.7, marker="_", ms=4, label="95% CI of the mean (where n > 1)")]
    _legend(fig, axes, handles, ncol=min(3, len(handles)))
    return common._save(fig, out, formats)


@_paper
def plot_heat_steps(world, panels: list, places: dict, title: str, out: Path, formats=("png",)) -> list[Path]:
    """The heat map built step by step (the thesis' Figures 5.7-5.8): ``panels`` is a list of
    (caption, heat) drawn side by side over the map."""
    fr = world.frame
    fig, axes = _grid(len(panels), COLUMN_IN * fr.height / fr.width + 0.35, maps=True, sharex=True, sharey=True)
    for ax, (caption, heat) in zip(axes, panels):
        _draw_map(ax, world, COLUMN_IN)
        h = np.ma.masked_where(heat <= 0, heat)
        ax.imshow(h, cmap="viridis", extent=_extent(world), interpolation="nearest", alpha=0.9)
        for name, (x, y) in places.items():
            ax.plot(x, y, "o", ms=2.5, c="#444444")
            ax.annotate(name, (x, y), xytext=(2, 2), textcoords="offset points", fontsize=6.5, path_effects=_HALO)
        ax.set_title(caption, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_aspect("equal")
    fig.suptitle(title)
    return common._save(fig, out, formats)
