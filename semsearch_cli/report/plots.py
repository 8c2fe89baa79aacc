"""Plots (the only module that imports matplotlib)."""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..files import temp_path
from .tables import goal_key

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
import numpy as np  # noqa: E402


def _extent(world):
    fr = world.frame
    return (fr.origin_x, fr.origin_x + fr.width * fr.res, fr.origin_y, fr.origin_y + fr.height * fr.res)


def _map_figure(world, width: float = 10.0):
    """A figure with the ground-truth map drawn (free light, the rest dark), axes in metres."""
    fr = world.frame
    fig, ax = plt.subplots(figsize=(width, max(3.0, width * fr.height / fr.width)))
    ax.imshow(np.where(world.free, 1.0, 0.25), cmap="gray", vmin=0, vmax=1, extent=_extent(world), interpolation="nearest")
    return fig, ax


def _finish_map(fig, ax, title: str, out: Path, dpi: int = 110) -> None:
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.85)
    fig.tight_layout()
    _save(fig, out, dpi)


def _save(fig, out: Path, dpi: int = 110) -> None:
    """Write a figure atomically and close it."""
    tmp = temp_path(out)
    fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    os.replace(tmp, out)


def plot_path(world, path: np.ndarray, read_signs, goal, title: str, out: Path) -> None:
    """The path of one run over the ground-truth map with the start, the signs read and the goal."""
    fig, ax = _map_figure(world)
    s = world.signs
    ax.scatter(s.x, s.y, s=6, c="#9999cc", label="signs")
    if len(read_signs):
        idx = np.asarray(read_signs, int)
        ax.scatter(s.x[idx], s.y[idx], s=10, c="tab:blue", label="signs read")
    ax.plot(path[:, 0], path[:, 1], "-", c="tab:orange", lw=1.2, label="path")
    ax.plot(*world.start_xy, "s", c="tab:green", ms=8, label="start")
    g = s.index_of(goal)
    ax.plot(s.x[g], s.y[g], "*", c="tab:red", ms=14, label=f"goal {goal}")
    _finish_map(fig, ax, title, out)


def plot_alpha_sweep(runs, out: Path, baseline: str = "greedy") -> None:
    """Mean ratio to the shortest path (+- std across seeds) against alpha, one panel per goal;
    the baseline planner (greedy) as a dashed line with its spread shaded."""
    nsos = runs[runs["planner"].str.startswith("nsos")].copy()
    nsos["alpha"] = nsos["params"].map(lambda p: json.loads(p).get("alpha", 0.9))
    goals = sorted(runs["goal"].unique(), key=goal_key)
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
    _save(fig, out)


def plot_sweep(table, param: str, out: Path) -> None:
    """A parameter sweep (:func:`~semsearch_cli.report.tables.sweep_table`): mean ratio to the
    shortest path (+- std over seeds) against the parameter, one line per planner, one panel per
    goal, and the success rate in a panel underneath."""
    goals = sorted(table["goal"].unique(), key=goal_key)
    fig, axes = plt.subplots(2, len(goals), figsize=(max(6.5, 4.2 * len(goals)), 5.8), squeeze=False, sharex=True,
                             gridspec_kw={"height_ratios": [3, 1.2]})
    for j, g in enumerate(goals):
        d = table[table["goal"] == g]
        for planner, p in d.groupby("planner", sort=False):
            x = p[param].to_numpy()
            axes[0, j].errorbar(x, p["mean_ratio"], yerr=p["std_ratio"].fillna(0), fmt="o-", capsize=3, label=planner)
            axes[1, j].plot(x, p["success_rate"], "o-", label=planner)
        axes[0, j].axhline(1.0, c="gray", lw=0.8)
        axes[0, j].set_title(f"goal {g}")
        axes[0, j].set_ylabel("distance / shortest path")
        axes[1, j].set_ylabel("success rate")
        axes[1, j].set_ylim(-0.05, 1.05)
        axes[1, j].set_xlabel(param)
        axes[0, j].legend(fontsize=7)
    fig.suptitle(f"sweep of {param}\nmean ratio to the shortest path (+- std over seeds) and success rate")
    fig.tight_layout()
    _save(fig, out)


def plot_scenario(world, goals, title: str, out: Path) -> None:
    """The ground-truth map with every sign (dot, number, facing tick), the start and the goals."""
    fig, ax = _map_figure(world, 12.0)
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
    _finish_map(fig, ax, title, out, dpi=130)


def plot_boxes(runs, scenario: str, order: list, out: Path) -> None:
    """Box plots of distance per goal (one panel each) and planner variant, shortest path dashed."""
    sub = runs[runs["scenario"] == scenario]
    goals = sorted(sub["goal"].unique(), key=goal_key)
    fig, axes = plt.subplots(1, len(goals), figsize=(max(4.5, 1.1 * len(order)) * len(goals) / 1.4, 4.2), squeeze=False)
    for ax, g in zip(axes[0], goals):
        d = sub[sub["goal"] == g]
        labels = [lab for lab in order if (d["planner"] == lab).any()]
        ax.boxplot([d[d["planner"] == lab]["distance_m"].to_numpy() for lab in labels], tick_labels=labels, showmeans=True)
        ax.axhline(float(d["shortest_m"].iloc[0]), ls="--", c="tab:green", label="shortest path")
        ax.set_title(f"{scenario}: goal {g}")
        ax.set_ylabel("distance travelled (m)")
        ax.tick_params(axis="x", labelrotation=35, labelsize=7)
        ax.legend(fontsize=7)
    fig.tight_layout()
    _save(fig, out)


def plot_paths_overlay(world, paths: dict, stops: list, title: str, out: Path) -> None:
    """The median run of each planner variant, overlaid on the ground-truth map, with the signs
    it sought marked and labelled (``stops``: (label, x, y): a goal, or a chain's doors in order)."""
    fig, ax = _map_figure(world)
    ax.scatter(world.signs.x, world.signs.y, s=5, c="#9999cc")
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (lab, (path, dist)) in enumerate(paths.items()):
        ax.plot(path[:, 0], path[:, 1], "-", lw=1.3, c=colors[k % len(colors)], label=f"{lab}: {dist:.1f} m", alpha=0.85)
    ax.plot(*world.start_xy, "s", c="tab:green", ms=8, label="start")
    for lab, x, y in stops:
        ax.plot(x, y, "*", c="tab:red", ms=13)
        ax.annotate(lab, (x, y), xytext=(5, 5), textcoords="offset points", fontsize=9, weight="bold", color="tab:red")
    _finish_map(fig, ax, title, out)


def animate_run(world, frames: list, title: str, out: Path, fps: int = 5) -> None:
    """A GIF replay: per frame the map the robot has built (free white, occupied black, unknown
    gray), its path so far, the candidates and the chosen one."""

    fr = world.frame
    fig, ax = plt.subplots(figsize=(8, max(3.0, 8 * fr.height / fr.width)))
    ext = _extent(world)

    def draw(k):
        ax.clear()
        f = frames[k]
        ax.imshow(f["map"], cmap="gray", vmin=0, vmax=2, extent=ext, interpolation="nearest")
        ax.plot(f["path"][:, 0], f["path"][:, 1], "-", c="tab:orange", lw=1)
        if len(f["cands"]):
            ax.scatter(f["cands"][:, 0], f["cands"][:, 1], s=25, c="tab:blue", label="candidates")
        if f["target"] is not None:
            ax.plot(*f["target"], "o", mfc="none", mec="tab:red", ms=12, mew=2, label="chosen")
        ax.plot(f["path"][-1, 0], f["path"][-1, 1], "o", c="tab:green", ms=6, label="robot")
        ax.set_title(f"{title}  {f['distance']:.0f} m")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.legend(loc="upper right", fontsize=6)

    anim = FuncAnimation(fig, draw, frames=len(frames))
    tmp = temp_path(out)
    anim.save(tmp, writer=PillowWriter(fps=fps))
    plt.close(fig)
    os.replace(tmp, out)


# ---- object search (thesis ch. 5) ---------------------------------------------------------------
def _places(ax, places: dict, truth=(), instances=()) -> None:
    """Places as labelled dots; the ones holding the target at the request ringed in red."""
    for name, (x, y) in places.items():
        ax.plot(x, y, "o", ms=5, c="#555555")
        ax.annotate(name, (x, y), xytext=(4, 4), textcoords="offset points", fontsize=9, weight="bold")
    for name in truth:
        x, y = places[name]
        ax.plot(x, y, "o", ms=13, mfc="none", mec="tab:red", mew=2)
    if truth:
        ax.plot([], [], "o", ms=9, mfc="none", mec="tab:red", mew=2, label="target at the request")


def plot_heat(world, heat: np.ndarray, places: dict, truth, goals, title: str, out: Path) -> None:
    """LSOS heat map (Eq. 5.4) over the map, the goals (Eqs. 5.5-5.6) numbered in visiting order."""
    fig, ax = _map_figure(world, 9.0)
    h = np.ma.masked_where(heat <= 0, heat)
    im = ax.imshow(h, cmap="hot_r", extent=_extent(world), interpolation="nearest", alpha=0.85)
    fig.colorbar(im, ax=ax, shrink=0.7, label="heat")
    _places(ax, places, truth)
    for k, (x, y, phi) in enumerate(goals):
        ax.plot(x, y, "X", c="tab:blue", ms=10, label="goals (in order)" if k == 0 else None)
        ax.annotate(str(k + 1), (x, y), xytext=(-12, -12), textcoords="offset points", color="tab:blue", weight="bold")
    ax.plot(*world.start_xy, "s", c="tab:green", ms=8, label="start R")
    _finish_map(fig, ax, title, out)


def plot_object_paths(world, paths: dict, places: dict, truth, title: str, out: Path, route=None) -> None:
    """The median run of each planner for one request; ``paths``: label -> (path, distance, outcome).
    ``route`` (n, 2), when given, is drawn dotted (the patrol order)."""
    fig, ax = _map_figure(world, 9.0)
    _places(ax, places, truth)
    if route is not None:
        ax.plot(route[:, 0], route[:, 1], ":", c="tab:red", lw=1.2, label="patrol route")
    for k, (lab, (p, d, outcome)) in enumerate(paths.items()):
        ax.plot(p[:, 0], p[:, 1], "-", lw=1.4, c=f"C{k}", label=f"{lab}: {d:.1f} m, {outcome}")
        ax.plot(p[-1, 0], p[-1, 1], "o", c=f"C{k}", ms=5)
    ax.plot(*world.start_xy, "s", c="tab:green", ms=8, label="start R")
    _finish_map(fig, ax, title, out)


def plot_object_bars(table, order: list, out: Path) -> None:
    """The thesis' Figure 5.12: per case, mean +- std distance per request hour and planner;
    the share of runs that found the object is written on each bar (red when below 1)."""
    cases = list(dict.fromkeys(table["case"]))
    n = len(cases)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.3 * rows), squeeze=False, sharey=True)
    width = 0.8 / max(1, len(order))
    for ax, case in zip(axes.flat, cases):
        sub = table[table["case"] == case]
        hours = sorted(sub["hour"].unique(), key=lambda h: (h == 0, h))  # noon before midnight, as the thesis
        for k, lab in enumerate(order):
            s = sub[sub["planner"] == lab].set_index("hour")
            xs = np.arange(len(hours)) + (k - (len(order) - 1) / 2) * width
            mean = [float(s["mean"].get(h, np.nan)) for h in hours]
            std = [float(s["std"].get(h, 0.0)) if not np.isnan(s["std"].get(h, np.nan)) else 0.0 for h in hours]
            bars = ax.bar(xs, mean, width, yerr=std, capsize=2, color=f"C{k}", label=lab)
            for bar, x, m, h in zip(bars, xs, mean, hours):
                if h in s.index:
                    rate = float(s.loc[h, "success_rate"])
                    if rate < 1:  # runs that gave up: hatched, the share found in red
                        bar.set_hatch("///")
                        bar.set_alpha(0.6)
                    ax.text(x, (m if np.isfinite(m) else 0), f"{rate:.0%}", ha="center", va="bottom", fontsize=7,
                            color="tab:red" if rate < 1 else "black")
        ax.set_xticks(range(len(hours)), [f"{h:02.0f}:{(h % 1) * 60:02.0f}" for h in hours])
        ax.set_title(case, fontsize=10)
        ax.set_ylabel("distance (m)")
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    top = axes.flat[0].get_ylim()[1]
    axes.flat[0].set_ylim(0, top * 1.1)

    axes.flat[0].legend(handles=[Patch(color=f"C{k}", label=lab) for k, lab in enumerate(order)], fontsize=7)
    fig.suptitle("Distance until the object is seen or the search gave up (mean +- std; % = runs that found it, "
                 "hatched when some did not)", fontsize=10)
    fig.tight_layout()
    _save(fig, out)


def plot_heat_steps(world, panels: list, places: dict, title: str, out: Path) -> None:
    """The heat map built step by step (the thesis' Figures 5.7-5.8): ``panels`` is a list of
    (caption, heat) drawn side by side over the map."""
    fr = world.frame
    n = len(panels)
    cols = 2
    rows = (n + 1) // 2
    w = 6.0
    fig, axes = plt.subplots(rows, cols, figsize=(w * cols, w * fr.height / fr.width * rows + 0.8), squeeze=False)
    for ax, (caption, heat) in zip(axes.flat, panels):
        ax.imshow(np.where(world.free, 1.0, 0.25), cmap="gray", vmin=0, vmax=1, extent=_extent(world), interpolation="nearest")
        h = np.ma.masked_where(heat <= 0, heat)
        ax.imshow(h, cmap="hot_r", extent=_extent(world), interpolation="nearest", alpha=0.85)
        for name, (x, y) in places.items():
            ax.plot(x, y, "o", ms=3, c="#555555")
            ax.annotate(name, (x, y), xytext=(3, 3), textcoords="offset points", fontsize=7)
        ax.set_title(caption, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    _save(fig, out)


def plot_chain_stages(stages, order: list, out: Path) -> None:
    """Per chain (one panel each): mean distance of each stage with the map kept and from scratch,
    per planner (bars side by side; scratch hatched)."""
    chains = list(dict.fromkeys(stages["goal"]))
    fig, axes = plt.subplots(len(chains), 1, figsize=(9, 2.8 * len(chains)), squeeze=False)
    for ax, ch in zip(axes[:, 0], chains):
        d = stages[stages["goal"] == ch]
        labels = list(dict.fromkeys(d["stage"]))
        x = np.arange(len(labels))
        width = 0.8 / max(1, 2 * len(order))
        for j, p in enumerate(order):
            for m, mode in enumerate(("kept", "scratch")):
                s = d[(d["planner"] == p) & (d["map"] == mode)].set_index("stage").reindex(labels)
                ax.bar(x + (2 * j + m - len(order)) * width + width / 2, s["mean"].to_numpy(float), width,
                       color=f"C{j}", alpha=1.0 if mode == "kept" else 0.45, hatch=None if mode == "kept" else "//",
                       label=f"{p}, map {mode}")
        ax.set_xticks(x, labels, fontsize=8)
        ax.set_ylabel("mean distance (m)")
        ax.set_title(f"chain {ch}: each stage with the map kept and from scratch")
        ax.legend(fontsize=7)
    fig.tight_layout()
    _save(fig, out)


# ---- indirect search (Loncomilla et al. 2018) ---------------------------------------------------
def plot_success_by_scale(table, order: list, paper: dict, paper_scales, out: Path) -> None:
    """Success rate against the view scale, one line per method: ours with Wilson 95% intervals
    (left), the paper's Table 3 (right), in the same colours and axes."""
    fig, (ax, axp) = plt.subplots(1, 2, figsize=(13, 5.5), sharey=True)
    for k, m in enumerate(order):
        d = table[table["planner"] == m].sort_values("view_scale")
        c, ls = f"C{k % 10}", ("-" if k < 10 else "--")
        ax.errorbar(d["view_scale"], 100 * d["success"], yerr=[100 * (d["success"] - d["ci_low"]), 100 * (d["ci_high"] - d["success"])],
                    fmt="o", ls=ls, c=c, ms=4, capsize=2, lw=1.4, label=m)
        ref = paper.get(m.split("[", 1)[0])
        if ref is not None:
            axp.plot(paper_scales, ref, "o", ls=ls, c=c, ms=4, lw=1.4, label=m)
    for a, title in ((ax, "ours (Wilson 95% intervals)"), (axp, "the paper's Table 3")):
        a.set_xlabel("view scale (m): how far the main object can be detected")
        a.set_ylim(0, 100)
        a.grid(alpha=0.3)
        a.set_title(title, fontsize=10)
    ax.set_ylabel("success rate (%)")
    ax.legend(fontsize=7, ncol=2, loc="lower right")
    fig.tight_layout()
    _save(fig, out)


def plot_rooms(rooms: list, title: str, out: Path) -> None:
    """Rooms of indirect search, small multiples: obstacles, the objects (A red), the start."""
    n = len(rooms)
    cols = min(5, n)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.4 * cols, 2.4 * rows + 0.4), squeeze=False)
    colors = ["tab:red", "tab:orange", "tab:blue", "tab:purple", "tab:brown"]
    for ax, room in zip(axes.ravel(), rooms):
        w, h = room.size
        ax.add_patch(plt.Rectangle((0, 0), w, h, fill=False, lw=1.5))
        for x0, y0, x1, y1 in room.obstacles:
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.4"))
        for k, (cls, t) in enumerate(room.objects.items()):
            ax.plot(t.x, t.y, "o", c=colors[k % len(colors)], ms=6, label=cls)
            a = np.radians(t.yaw)
            ax.plot([t.x, t.x + 0.35 * np.cos(a)], [t.y, t.y + 0.35 * np.sin(a)], "-", c=colors[k % len(colors)], lw=1)
        x, y, hd = room.start
        ax.plot(x, y, "s", c="tab:green", ms=6)
        ax.arrow(x, y, 0.4 * np.cos(np.radians(hd)), 0.4 * np.sin(np.radians(hd)), color="tab:green", width=0.03)
        ax.set_xlim(-0.1, w + 0.1)
        ax.set_ylim(-0.1, h + 0.1)
        ax.set_aspect("equal")
        ax.set_title(room.name, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    handles, labels = axes.ravel()[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=len(labels), frameon=False)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    _save(fig, out)


def animate_probability(room, target: str, frames: list, title: str, out: Path, fps: int = 4) -> None:
    """A GIF of one indirect search: per re-plan, the probability map of A (the robot's belief,
    each frame scaled to its own maximum), the path so far, the secondary objects seen, the goal;
    A itself ringed."""
    w, h = room.size
    fig, ax = plt.subplots(figsize=(5.2, 5.6))
    target = room.objects[target]

    def draw(k):
        ax.clear()
        f = frames[k]
        ax.imshow(f["p"], cmap="magma", vmin=0.0, vmax=float(f["p"].max()) or 1.0, extent=(0, w, 0, h),
                  interpolation="nearest")
        for x0, y0, x1, y1 in room.obstacles:
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.6"))
        ax.plot(f["trail"][:, 0], f["trail"][:, 1], "-", c="tab:cyan", lw=1)
        ax.plot(*f["trail"][-1], "o", c="tab:green", ms=6)
        for cls, (x, y) in f["seen"].items():
            ax.plot(x, y, "s", c="tab:orange", ms=6)
            ax.annotate(cls, (x, y), xytext=(3, 3), textcoords="offset points", fontsize=7, color="white")
        ax.plot(target.x, target.y, "o", mfc="none", mec="tab:red", ms=12, mew=2)
        ax.plot(*f["goal"], "x", c="white", ms=8, mew=2)
        ax.set_title(f"{title}\nt = {f['t']:.0f} s, p(outside) = {f['p0']:.2f}", fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])

    anim = FuncAnimation(fig, draw, frames=len(frames))
    tmp = temp_path(out)
    anim.save(tmp, writer=PillowWriter(fps=fps))
    plt.close(fig)
    os.replace(tmp, out)
