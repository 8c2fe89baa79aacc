"""Plots (the only module that imports matplotlib), in one paper style.

Every figure is drawn inside :data:`PAPER_RC` (white background; 8 pt text, 9 pt titles; the
Okabe-Ito colour-blind-safe palette) at the size it is printed: panels :data:`COLUMN_IN` (3.5 in,
one journal column) wide, two side by side for a two-column figure, so nothing is scaled down.
A planner keeps its colour in every figure of a report (:func:`planner_colors` over the section's
planner order). Each figure is written in every image format asked for (:func:`image_formats`);
GIF replays stay GIF. Confidence intervals come from :mod:`.stats` (over units: episodes, or the
repeats of a single episode).
"""

from __future__ import annotations

import functools
import inspect
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..files import temp_path
from . import stats
from ..planners.base import baseline_of, planner_named, swept_value
from .tables import goal_key, planner_order

import cv2
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
from cycler import cycler  # noqa: E402
from matplotlib import patheffects  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.transforms import blended_transform_factory  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402

# Okabe & Ito (2008), "Color Universal Design": distinguishable under every common colour-vision
# deficiency. Yellow is kept out of the planner colours (too light for lines on white) and marks goals.
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")
GOAL_COLOR = "#F0E442"
COLUMN_IN = 3.5  # one journal column (in)
PNG_DPI = 200
IMAGE_FORMATS = ("png", "pdf", "svg")
PAPER_RC = {
    "figure.facecolor": "white", "axes.facecolor": "white", "savefig.facecolor": "white", "savefig.edgecolor": "white",
    "font.size": 8, "axes.titlesize": 9, "axes.labelsize": 8, "xtick.labelsize": 8, "ytick.labelsize": 8,
    "legend.fontsize": 8, "legend.title_fontsize": 8, "figure.titlesize": 9, "legend.frameon": False,
    "axes.prop_cycle": cycler(color=PALETTE), "axes.linewidth": 0.6, "lines.linewidth": 1.2, "lines.markersize": 4,
    "xtick.major.width": 0.6, "ytick.major.width": 0.6, "xtick.major.size": 2.5, "ytick.major.size": 2.5,
    "axes.titlepad": 3.0, "axes.labelpad": 2.0, "pdf.fonttype": 42, "ps.fonttype": 42,
    "figure.constrained_layout.h_pad": 0.03, "figure.constrained_layout.w_pad": 0.03,
}
# Axes.boxplot(orientation=) from Matplotlib 3.10 (vert= is deprecated there)
_HORIZONTAL = {"orientation": "horizontal"} if "orientation" in inspect.signature(plt.Axes.boxplot).parameters else {"vert": False}
_HALO = [patheffects.withStroke(linewidth=1.8, foreground="white")]  # text readable over lines and walls


def _paper(fn):
    """Draw ``fn``'s figure in the paper style (:data:`PAPER_RC`)."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with plt.rc_context(PAPER_RC):
            return fn(*args, **kwargs)
    return wrapper


def image_formats(formats) -> tuple[str, ...]:
    """The image formats to write for a report's ``formats``: png, pdf and svg as chosen, and png
    whenever md or html is (report.md and report.html embed the PNG)."""
    f = set(formats)
    return tuple(x for x in IMAGE_FORMATS if x in f or (x == "png" and f & {"md", "html"}))


def planner_colors(order) -> dict:
    """Planner label -> colour, by position in ``order`` (a section's planner order, so a planner
    has one colour in all its figures); past the palette's seven colours they repeat."""
    return {lab: PALETTE[k % len(PALETTE)] for k, lab in enumerate(order)}


def _linestyle(order, lab) -> str:
    """Solid for the first seven planners, dashed for the next seven (colours repeat)."""
    return "-" if list(order).index(lab) < len(PALETTE) else "--"


def _save(fig, out: Path, formats=("png",), dpi: int = PNG_DPI) -> list[Path]:
    """Write ``fig`` atomically once per image format (``out`` names the PNG; the others take
    its name with their suffix) and close it. Vector files carry no creation date (the same rows
    give the same bytes)."""
    out = Path(out)
    base = out.name[: -len(out.suffix)] if out.suffix in (".png", ".pdf", ".svg") else out.name
    written = []
    for fmt in formats:
        f = out.with_name(f"{base}.{fmt}")
        tmp = temp_path(f)
        meta = {"pdf": {"CreationDate": None}, "svg": {"Date": None}}.get(fmt, {})
        fig.savefig(tmp, format=fmt, dpi=dpi, bbox_inches="tight", pad_inches=0.03, metadata=meta)
        os.replace(tmp, f)
        written.append(f)
    plt.close(fig)
    return written


def _grid(n: int, panel_h: float, cols: int = 2, maps: bool = False, **kw):
    """``n`` panels, ``cols`` to a row, each :data:`COLUMN_IN` wide and ``panel_h`` tall;
    unused panels hidden. ``maps``: the panels have a fixed aspect (the layout closes the gaps
    that leaves). Returns (figure, the n axes)."""
    cols = max(1, min(cols, n))
    rows = -(-max(n, 1) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(COLUMN_IN * cols, panel_h * rows), squeeze=False, **kw)
    fig.set_layout_engine("constrained", compress=maps)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:max(n, 1)])


def _outer_y(ax) -> None:
    """The y label only in the first column (panels that share y; their x axes differ)."""
    if not ax.get_subplotspec().is_first_col():
        ax.set_ylabel("")
        ax.tick_params(labelleft=False)


def _n_by_planner(df: pd.DataFrame) -> dict | None:
    """Planner -> its number of runs when it is the same in every goal of ``df``, else None."""
    n = df.groupby(["planner", "goal"]).size()
    per = n.groupby(level=0).agg(["min", "max"])
    return None if (per["min"] != per["max"]).any() else per["min"].to_dict()


# ---- maps ---------------------------------------------------------------------------------------
def episode_mean(d, col: str) -> float:
    """The mean of a per-episode column (``shortest_m``) over the distinct episodes of ``d``."""
    if "episode" not in d.columns:
        return float(d[col].iloc[0])
    return float(d.drop_duplicates(["goal", "episode"])[col].mean())


def _extent(world):
    fr = world.frame
    return (fr.origin_x, fr.origin_x + fr.width * fr.res, fr.origin_y, fr.origin_y + fr.height * fr.res)


def map_image(free: np.ndarray, wall_cells: int = 1) -> np.ndarray:
    """The map to draw under paths: free space white, walls (cells that are not free within
    ``wall_cells`` of free space) dark, everything else (solid and outside) light grey.

    free : (H, W) bool. Returns (H, W) float32 grey levels in [0, 1]."""
    k = 2 * max(1, int(wall_cells)) + 1
    near = cv2.dilate(free.astype(np.uint8), np.ones((k, k), np.uint8)) > 0
    img = np.full(free.shape, 0.9, np.float32)
    img[near & ~free] = 0.3
    img[free] = 1.0
    return img


def _draw_map(ax, world, width_in: float) -> None:
    """The ground-truth map, walls about one printed pixel thick at ``width_in``."""
    fr = world.frame
    m_per_px = fr.width * fr.res / (width_in * PNG_DPI)
    ax.imshow(map_image(world.free, round(m_per_px / fr.res)), cmap="gray", vmin=0, vmax=1, extent=_extent(world),
              interpolation="antialiased")


def _map_axes(ax) -> None:
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def thin_labels(x, y, texts, char_w: float, height: float, fixed=()) -> list[int]:
    """Indices of the labels to draw, in the given order of priority, such that no two boxes
    overlap: label i is a box ``(len(texts[i]) + 1) * char_w`` wide (a character's margin) and
    ``height`` tall centred on (x[i], y[i]) (same units as x, y); a label whose box meets a kept
    one, or one of the ``fixed`` boxes (cx, cy, width, height) already drawn, is dropped."""
    boxes = [tuple(map(float, b)) for b in fixed]
    kept: list[int] = []
    for i, t in enumerate(texts):
        w = (len(str(t)) + 1) * char_w
        if all(abs(x[i] - bx) * 2 >= w + bw or abs(y[i] - by) * 2 >= height + bh for bx, by, bw, bh in boxes):
            kept.append(i)
            boxes.append((x[i], y[i], w, height))
    return kept


def _sign_labels(ax, world, path: np.ndarray, skip: set, width_in: float, near_m: float, size: float = 6.5,
                 stops=(), starts=()) -> None:
    """Number the signs within ``near_m`` of ``path`` (the others stay unlabelled dots), nearest
    to the path's end first, dropping labels that would overlap a kept one (or the stops' stars
    and labels, the starts) at ``width_in``."""
    s = world.signs
    if not len(s) or not len(path):
        return
    d, _ = cKDTree(path[:: max(1, len(path) // 4000)]).query(np.c_[s.x, s.y])
    idx = [i for i in np.flatnonzero(d <= near_m) if i not in skip]
    idx.sort(key=lambda i: np.hypot(s.x[i] - path[-1, 0], s.y[i] - path[-1, 1]))
    x0, x1, _, _ = _extent(world)
    m = (x1 - x0) / (width_in * 72.0)  # metres per point
    fixed = [(x, y, 10 * m, 10 * m) for _, x, y in stops] + [(x, y, 6 * m, 6 * m) for x, y in starts]
    fixed += [(x + (5 + 0.31 * 7.5 * len(t)) * m, y + (4 + 3.75) * m, 0.62 * 7.5 * len(t) * m, 9 * m) for t, x, y in stops]
    _number_signs(ax, world, idx, m, size, fixed)


def _number_signs(ax, world, idx, m_per_pt: float, size: float, fixed=None, rotate: bool = False) -> None:
    """Write the numbers of signs ``idx``, each behind its sign's wall (opposite the way the sign
    faces: off the corridor and any path in it). With ``fixed`` (boxes already drawn, see
    :func:`thin_labels`), labels that would overlap are dropped, earlier ones kept first. With
    ``rotate``, numbers on walls that run left-right are written upright, so that close signs
    along such a wall do not run into each other."""
    s = world.signs
    idx = list(idx)
    texts = [str(s.number[i]) for i in idx]
    gap = 2.0  # pt between the sign and its number
    ux, uy = -np.cos(s.facing[idx]), -np.sin(s.facing[idx])
    w = np.array([len(t) for t in texts]) * 0.62 * size
    cx = s.x[idx] + ux * (gap + w / 2) * m_per_pt
    cy = s.y[idx] + uy * (gap + size / 2) * m_per_pt
    keep = range(len(idx)) if fixed is None else thin_labels(cx, cy, texts, 0.62 * size * m_per_pt, 1.15 * size * m_per_pt, fixed)
    for k in keep:
        i = idx[k]
        ha = "left" if ux[k] > 0.4 else "right" if ux[k] < -0.4 else "center"
        va = "bottom" if uy[k] > 0.4 else "top" if uy[k] < -0.4 else "center"
        ax.annotate(texts[k], (s.x[i], s.y[i]), xytext=(ux[k] * gap, uy[k] * gap), textcoords="offset points",
                    fontsize=size, ha=ha, va=va, color="#222222", path_effects=_HALO, zorder=6,
                    rotation=90 if rotate and abs(uy[k]) > 0.7 else 0)


def _stops(ax, stops, size: float = 7.5) -> None:
    """Goals (or a chain's doors) as yellow stars, labelled."""
    for lab, x, y in stops:
        ax.plot(x, y, "*", ms=10, mfc=GOAL_COLOR, mec="black", mew=0.7, zorder=8)
        ax.annotate(lab, (x, y), xytext=(5, 4), textcoords="offset points", fontsize=size, weight="bold", zorder=9,
                    path_effects=_HALO)


def _starts(ax, starts) -> None:
    for x, y in starts:
        ax.plot(x, y, "s", ms=4.5, mfc="white", mec="black", mew=0.8, zorder=7)


def _places(ax, places: dict, truth=(), size: float = 7.5) -> None:
    """Object places as labelled dots; the ones holding the target at the request ringed."""
    for name, (x, y) in places.items():
        ax.plot(x, y, "o", ms=3, c="#444444", zorder=6)
        ax.annotate(name, (x, y), xytext=(3, 3), textcoords="offset points", fontsize=size, weight="bold",
                    path_effects=_HALO, zorder=6)
    for name in truth:
        x, y = places[name]
        ax.plot(x, y, "o", ms=10, mfc="none", mec="black", mew=1.4, zorder=7)


@_paper
def plot_path_panels(world, panels: dict, stops, title: str, out: Path, formats=("png",), colors: dict | None = None,
                     starts=None, places: dict | None = None, truth=(), route=None, near_m: float = 3.0) -> list[Path]:
    """Runs over the ground-truth map as small multiples: one panel per planner, shared axes.

    Parameters
    ----------
    world : World
        The ground truth (map light, walls dark; signs as grey dots).
    panels : {label: (paths, median, note)}
        Per planner: every run's path (list of (n, 2) float arrays, m), drawn faint; the index of
        its median run in that list, drawn bold, with the signs within ``near_m`` m of it numbered
        (labels that would overlap are dropped); a note for the panel's title. ``{}`` draws the map alone.
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
    fig, axes = _grid(n, COLUMN_IN * aspect + 0.45, maps=True, sharex=True, sharey=True)
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
        faint = float(np.clip(3.0 / max(1, len(paths)), 0.2, 0.5))
        for k, p in enumerate(paths):
            if k != median:
                ax.plot(p[:, 0], p[:, 1], "-", c=c, lw=0.7, alpha=faint, zorder=3)
        if 0 <= median < len(paths):
            p = paths[median]
            ax.plot(p[:, 0], p[:, 1], "-", c=c, lw=1.5, zorder=4, solid_capstyle="round")
            ax.plot(p[-1, 0], p[-1, 1], "o", c=c, mec="black", mew=0.5, ms=4, zorder=5)
            if len(s) and places is None:
                _sign_labels(ax, world, p, stop_signs, COLUMN_IN, near_m, stops=stops, starts=starts)
        if places:
            _places(ax, places, truth)
        _starts(ax, starts)
        _stops(ax, stops)
        if lab:
            ax.set_title(f"{lab}: {note}" if note else lab, color="black")
        _map_axes(ax)
        ax.label_outer()
    handles = [Line2D([], [], c="0.35", lw=0.6, alpha=0.5, label="every run"),
               Line2D([], [], c="0.35", lw=1.5, label="median run (dot: its end)"),
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
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 5 if n > 1 else 3), handlelength=1.6,
               columnspacing=1.0)
    if title:
        fig.suptitle(title)
    return _save(fig, out, formats)


@_paper
def plot_scenario(world, goals, title: str, out: Path, formats=("png",)) -> list[Path]:
    """The ground-truth map with every sign (dot, facing tick, number behind its wall), the start
    and the goals, two columns wide (every number is shown, at 5.5 pt)."""
    width = 2 * COLUMN_IN
    fr = world.frame
    fig, ax = plt.subplots(figsize=(width, width * fr.height / fr.width + 0.6), layout="constrained")
    _draw_map(ax, world, width)
    s = world.signs
    ax.quiver(s.x, s.y, np.cos(s.facing), np.sin(s.facing), color=PALETTE[0], scale=80, width=0.0012, zorder=3)
    ax.scatter(s.x, s.y, s=4, c=PALETTE[0], lw=0, zorder=4, label=f"door signs ({len(s)}), facing; number behind the wall")
    x0, x1, _, _ = _extent(world)
    _number_signs(ax, world, range(len(s)), (x1 - x0) / (width * 72.0), 5.5, rotate=True)
    stops = [(f"goal {g}", float(s.x[s.index_of(g)]), float(s.y[s.index_of(g)])) for g in goals if s.index_of(g) >= 0]
    _stops(ax, stops)
    _starts(ax, [world.start_xy])
    ax.plot([], [], "s", ms=4.5, mfc="white", mec="black", ls="", label="start")
    ax.plot([], [], "*", ms=9, mfc=GOAL_COLOR, mec="black", ls="", label="goals")
    _map_axes(ax)
    ax.set_title(title)
    fig.legend(loc="outside lower center", ncol=3)
    return _save(fig, out, formats)


# ---- statistics over runs -----------------------------------------------------------------------
def swept_rows(runs: pd.DataFrame) -> tuple[type | None, pd.DataFrame]:
    """(the planner class that sweeps a parameter, its rows with the parameter's value in column
    ``swept``): the first swept planner in report order (:attr:`Planner.swept`; nsos and alpha),
    the value read from each row's label (:func:`~semsearch_cli.planners.base.swept_value`)."""
    labels = runs["planner"].astype(str)
    for lab in planner_order(labels):
        cls = planner_named(lab)
        if cls is not None and cls.swept is not None:
            rows = runs[labels.map(lambda x: planner_named(x) is cls)].copy()
            rows["swept"] = rows["planner"].astype(str).map(swept_value)
            return cls, rows
    return None, runs.iloc[:0].assign(swept=pd.Series(dtype=float))


def swept_values(runs: pd.DataFrame) -> list[float]:
    """The distinct values of the swept parameter in ``runs`` (see :func:`swept_rows`)."""
    return sorted(set(swept_rows(runs)[1]["swept"]))


def budget_curve(runs: pd.DataFrame, budgets=None, confidence: float = 0.95) -> pd.DataFrame:
    """Success rate against a distance budget, per goal and planner.

    A run succeeds at budget ``b`` (m) when it found the goal (``success`` 1) and travelled
    ``distance_m <= b``: the share of runs that would have succeeded had the search been cut off
    at ``b``. The interval is :func:`.stats.rate_ci` over :func:`.stats.units` (taken over all the
    goal's rows, so every planner of a goal has the same kind of unit).

    Parameters
    ----------
    runs : DataFrame
        Rows of one scenario: goal, planner, seed, success (0/1), distance_m (m), optionally episode.
    budgets : (k,) float, m, optional
        Where to evaluate; default, per goal, 0, every distance at which a run of that goal
        succeeded, and the longest distance of that goal (the curve is a step function that
        changes only there).

    Returns
    -------
    DataFrame with columns goal, planner, budget_m, n (runs), successes, rate, lo, hi; goals in
    :func:`goal_key` order, planners in :func:`planner_order`, budgets ascending.
    """
    out = []
    for goal in sorted(runs["goal"].unique(), key=goal_key):
        g = runs[runs["goal"] == goal]
        unit = stats.units(g)
        found = g["success"].astype(float).to_numpy() == 1
        dist = g["distance_m"].astype(float).to_numpy()
        grid = np.unique(np.r_[0.0, dist[found], np.nanmax(dist, initial=0.0)]) if budgets is None else np.sort(np.asarray(budgets, float))
        for lab in planner_order(g["planner"]):
            m = (g["planner"] == lab).to_numpy()
            u = unit.to_numpy()[m]
            for b in grid:
                ok = (found[m] & (dist[m] <= b)).astype(float)
                rate, lo, hi = stats.rate_ci(ok, u, confidence)
                out.append({"goal": goal, "planner": lab, "budget_m": float(b), "n": int(m.sum()), "successes": int(ok.sum()),
                            "rate": rate, "lo": lo, "hi": hi})
    return pd.DataFrame(out, columns=["goal", "planner", "budget_m", "n", "successes", "rate", "lo", "hi"])


@_paper
def plot_budget(curve: pd.DataFrame, order: list, out: Path, formats=("png",), colors: dict | None = None,
                shortest: dict | None = None, unit_word: str = "repeats") -> list[Path]:
    """Success rate against the distance budget (:func:`budget_curve`) as small multiples: a row
    per goal (shared budget axis), a column per planner. Each panel draws its planner's step
    curve with the 95% band, the other planners' curves thin grey behind it (so none hides
    another), and the shortest path dotted."""
    colors = colors or planner_colors(order)
    goals = list(dict.fromkeys(curve["goal"]))
    labels = [p for p in order if (curve["planner"] == p).any()]
    cols = len(labels)
    w = min(1.45, 2 * COLUMN_IN / cols) * cols
    fig, axes = plt.subplots(len(goals), cols, figsize=(w, 1.05 * len(goals) + 0.55), squeeze=False, sharex="row",
                             sharey=True, layout="constrained")
    for r, g in enumerate(goals):
        d = curve[curve["goal"] == g]
        for j, lab in enumerate(labels):
            ax = axes[r, j]
            for other in labels:
                if other != lab:
                    e = d[d["planner"] == other]
                    ax.step(e["budget_m"], e["rate"], where="post", c="0.75", lw=0.6, zorder=1)
            e = d[d["planner"] == lab]
            if len(e):
                c = colors[lab]
                ax.fill_between(e["budget_m"], e["lo"].fillna(e["rate"]), e["hi"].fillna(e["rate"]), step="post", color=c,
                                alpha=0.25, lw=0, zorder=2)
                ax.step(e["budget_m"], e["rate"], where="post", c=c, lw=1.2, zorder=3)
            if shortest and g in shortest and np.isfinite(shortest[g]):
                ax.axvline(shortest[g], c="black", ls=":", lw=0.7, zorder=4)
            ax.set_xlim(0, float(d["budget_m"].max()))
            ax.set_ylim(-0.03, 1.03)
            ax.set_yticks([0, 0.5, 1], ["0", ".5", "1"])
            ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(3, integer=True))
            if r == 0:
                n = int(e["n"].iloc[0]) if len(e) else 0
                ax.set_title(f"{lab}\n(n={n})" if len(lab) > 12 else f"{lab} (n={n})", fontsize=8, color=colors[lab])
            if j == 0:
                ax.set_ylabel(f"goal {g}\nsuccess rate")
    for ax in axes[-1]:
        ax.set_xlabel("budget b (m)")
    handles = [Line2D([], [], c="0.3", lw=1.2, label="the panel's planner: found within b"), Patch(color="0.3", alpha=0.25, lw=0,
               label=f"its 95% CI over {unit_word}"), Line2D([], [], c="0.75", lw=0.6, label="the other planners"),
               Line2D([], [], c="black", ls=":", lw=0.7, label="shortest path (mean over episodes)")]
    fig.legend(handles=handles, loc="outside lower center", ncol=4, handlelength=1.6, columnspacing=1.0)
    return _save(fig, out, formats)


@_paper
def plot_boxes(runs, scenario: str, order: list, out: Path, formats=("png",), colors: dict | None = None) -> list[Path]:
    """Distance per goal (one panel each) and planner: a box (quartiles, median line, whiskers
    to 1.5 IQR, outliers as dots) and under it the mean with its 95% CI (:func:`.stats.mean_ci`
    over units); the shortest path dashed; n beside each planner."""
    colors = colors or planner_colors(order)
    sub = runs[runs["scenario"].astype(str) == str(scenario)]
    goals = sorted(sub["goal"].unique(), key=goal_key)
    labels = [lab for lab in order if (sub["planner"] == lab).any()]
    common = _n_by_planner(sub)
    fig, axes = _grid(len(goals), 0.32 * len(labels) + 0.75, sharey=True)
    y = np.arange(len(labels), dtype=float)
    for ax, g in zip(axes, goals):
        d = sub[sub["goal"] == g]
        unit = stats.units(d)
        for k, lab in enumerate(labels):
            m = d["planner"] == lab
            v = d.loc[m, "distance_m"].astype(float).to_numpy()
            if not len(v):
                continue
            c = colors[lab]
            ax.boxplot([v], positions=[y[k] - 0.12], widths=0.42, **_HORIZONTAL, patch_artist=True,
                       boxprops=dict(facecolor=to_rgba(c, 0.25), edgecolor=c, lw=0.8), medianprops=dict(color=c, lw=1.4),
                       whiskerprops=dict(color=c, lw=0.8), capprops=dict(color=c, lw=0.8),
                       flierprops=dict(marker="o", ms=2.2, mfc=c, mec="none", alpha=0.7))
            mean, lo, hi = stats.mean_ci(v, unit[m])
            err = [[mean - lo], [hi - mean]] if np.isfinite(lo) else None
            ax.errorbar([mean], [y[k] + 0.28], xerr=err, fmt="D", ms=3.2, c="black", mfc=c, mec="black", mew=0.5,
                        capsize=2, lw=0.9)
            if common is None:
                ax.text(1.01, y[k], f"n={len(v)}", transform=blended_transform_factory(ax.transAxes, ax.transData),
                        va="center", fontsize=7)
        ax.axvline(float(episode_mean(d, "shortest_m")), ls="--", c="black", lw=0.8)
        ax.set_title(f"goal {g}")
        ax.set_xlabel("distance travelled (m)")
        ax.set_xlim(left=0)
    axes[0].set_yticks(y, [f"{lab} (n={common[lab]})" if common else lab for lab in labels])
    axes[0].set_ylim(len(labels) - 0.45, -0.55)
    for ax in axes:
        _outer_y(ax)
    unit_word = stats.unit_kind(sub)
    handles = [Patch(facecolor="0.85", edgecolor="0.3", label="quartiles, median; whiskers 1.5 IQR"),
               Line2D([], [], marker="D", ms=3.2, mfc="0.6", mec="black", c="black", label=f"mean, 95% CI over {unit_word}"),
               Line2D([], [], c="black", ls="--", lw=0.8, label="shortest path (mean over episodes)")]
    fig.legend(handles=handles, loc="outside lower center", ncol=2, handlelength=1.6, columnspacing=1.0)
    return _save(fig, out, formats)


@_paper
def plot_alpha_sweep(runs, out: Path, baseline: str | None = None, formats=("png",), colors: dict | None = None) -> list[Path]:
    """Mean ratio to the shortest path against the swept parameter (nsos' alpha, see
    :func:`swept_rows`), one panel per goal: the swept planner at each value (points in each
    variant's colour, 95% CI over units), the baseline planner (default: greedy, see
    :func:`~semsearch_cli.planners.base.baseline_of`) as a dashed line with its 95% CI shaded."""
    colors = colors or planner_colors(planner_order(runs["planner"]))
    cls, nsos = swept_rows(runs)
    nsos = nsos.rename(columns={"swept": "alpha"})
    swept_name, param = (cls.name, cls.swept) if cls is not None else ("", "")
    what = cls.Params.model_fields[param].description if cls is not None else None
    xlabel = f"{param} ({what.split(',')[0]})" if what else str(param)
    if baseline is None:
        rest = [lab for lab in runs["planner"].astype(str).unique() if planner_named(lab) is not cls]
        baseline = baseline_of(rest) if rest else ""
    goals = sorted(runs["goal"].unique(), key=goal_key)
    fig, axes = _grid(len(goals), 2.0)
    n_alpha = nsos.groupby(["goal", "alpha"]).size()
    n_base = runs[runs["planner"] == baseline].groupby("goal").size()
    for ax, g in zip(axes, goals):
        unit = stats.units(runs[runs["goal"] == g])
        d = nsos[nsos["goal"] == g]
        pts = []
        for (alpha, lab), e in d.groupby(["alpha", "planner"]):
            pts.append((alpha, lab, *stats.mean_ci(e["ratio"].astype(float), unit[e.index])))
        pts.sort()
        if pts:
            ax.plot([p[0] for p in pts], [p[2] for p in pts], "-", c="0.3", lw=0.9, zorder=2)
        for alpha, lab, m, lo, hi in pts:
            err = [[m - lo], [hi - m]] if np.isfinite(lo) else None
            ax.errorbar([alpha], [m], yerr=err, fmt="o", ms=4.5, c=colors.get(lab, "black"), mec="black", mew=0.5, capsize=2,
                        ecolor="0.15", lw=0.9, zorder=3)
        base = runs[(runs["planner"] == baseline) & (runs["goal"] == g)]
        if len(base):
            m, lo, hi = stats.mean_ci(base["ratio"].astype(float), unit[base.index])
            c = colors.get(baseline, "black")
            ax.axhline(m, ls="--", c=c, lw=1.0)
            if np.isfinite(lo):
                ax.axhspan(lo, hi, color=c, alpha=0.15, lw=0)
        ax.axhline(1.0, c="0.5", lw=0.6)
        ax.set_title(f"goal {g}")
        ax.set_xticks(sorted(nsos["alpha"].unique()))
        ax.set_ylim(bottom=0)
        if ax.get_subplotspec().is_last_row() or len(goals) - goals.index(g) <= 2:
            ax.set_xlabel(xlabel)
        if ax.get_subplotspec().is_first_col():
            ax.set_ylabel("distance / shortest path")
    n_a = sorted(set(n_alpha.tolist()))
    n_b = sorted(set(n_base.tolist()))
    handles = [Line2D([], [], c="0.3", marker="o", mfc="0.6", mec="black", ms=4,
                      label=f"{swept_name} (n={'/'.join(map(str, n_a))} per {param})")]
    if len(n_b):
        handles.append(Line2D([], [], c=colors.get(baseline, "black"), ls="--", label=f"{baseline} (n={'/'.join(map(str, n_b))})"))
    handles.append(Patch(color="0.6", alpha=0.4, label=f"95% CI over {stats.unit_kind(runs)}"))
    handles.append(Line2D([], [], c="0.5", lw=0.6, label="the shortest path (ratio 1)"))
    fig.legend(handles=handles, loc="outside lower center", ncol=4, handlelength=1.6, columnspacing=1.0)
    return _save(fig, out, formats)


@_paper
def plot_sweep(table, param: str, out: Path, formats=("png",)) -> list[Path]:
    """A parameter sweep (:func:`~semsearch_cli.report.tables.sweep_table`): mean ratio to the
    shortest path (+- std over seeds) against the parameter, one line per planner, one panel per
    goal, and the success rate in a panel underneath."""
    goals = sorted(table["goal"].unique(), key=goal_key)
    order = [p for p in planner_order(table["planner"])]
    colors = planner_colors(order)
    fig, axes = plt.subplots(2, len(goals), figsize=(COLUMN_IN * min(2, len(goals)) * max(1, len(goals) / 2), 3.6),
                             squeeze=False, sharex=True, gridspec_kw={"height_ratios": [3, 1.2]}, layout="constrained")
    for j, g in enumerate(goals):
        d = table[table["goal"] == g]
        for planner, p in d.groupby("planner", sort=False):
            x = p[param].to_numpy()
            axes[0, j].errorbar(x, p["mean_ratio"], yerr=p["std_ratio"].fillna(0), fmt="o-", capsize=2, c=colors[planner],
                                ms=3, label=f"{planner} (n={int(p['n'].iloc[0])})")
            axes[1, j].plot(x, p["success_rate"], "o-", c=colors[planner], ms=3)
        axes[0, j].axhline(1.0, c="0.5", lw=0.6)
        axes[0, j].set_title(f"goal {g}")
        axes[0, j].set_ylabel("distance / shortest path")
        axes[1, j].set_ylabel("success rate")
        axes[1, j].set_ylim(-0.05, 1.05)
        axes[1, j].set_xlabel(param)
        axes[0, j].legend(fontsize=7)
    fig.suptitle(f"sweep of {param}: mean ratio to the shortest path (± std over seeds) and success rate")
    return _save(fig, out, formats)


# ---- replays (GIF) ------------------------------------------------------------------------------
@_paper
def animate_run(world, frames: list, title: str, out: Path, goal=None, fps: int = 5) -> None:
    """A GIF replay. Per frame: the map the robot has built (free white, occupied black, unknown
    grey), its path so far, the candidates and the chosen one, and the signs read so far, numbered;
    the goal (``(text, x, y)``) starred and labelled throughout.

    frames : list of dict with ``map`` ((h, w) uint8: 0 occupied, 1 unknown, 2 free), ``path``
    ((n, 2) m), ``distance`` (m), ``cands`` ((k, 2) m), ``target`` ((x, y) or None) and ``read``
    (list of int: indices into ``world.signs`` of the signs read so far)."""
    fr = world.frame
    width = 2 * COLUMN_IN
    fig, ax = plt.subplots(figsize=(width, width * fr.height / fr.width + 0.55), layout="constrained")
    ext = _extent(world)
    legend = [Line2D([], [], c=PALETTE[1], lw=1.2, label="path"),
              Line2D([], [], ls="", marker="o", ms=4, c=PALETTE[0], label="candidates"),
              Line2D([], [], ls="", marker="o", ms=8, mfc="none", mec=PALETTE[1], mew=1.5, label="chosen"),
              Line2D([], [], ls="", marker="o", ms=4, c=PALETTE[2], mec="black", label="robot"),
              Line2D([], [], ls="", marker=".", ms=5, c="#8a2be2", label="signs read"),
              Line2D([], [], ls="", marker="*", ms=9, mfc=GOAL_COLOR, mec="black", label="goal")]
    fig.legend(handles=legend, loc="outside lower center", ncol=6, handlelength=1.2, columnspacing=0.8)

    def draw(k):
        ax.clear()
        f = frames[k]
        ax.imshow(f["map"], cmap="gray", vmin=0, vmax=2, extent=ext, interpolation="nearest")
        read = f.get("read", [])
        if read:
            sg = world.signs
            ax.scatter(sg.x[read], sg.y[read], s=8, c="#8a2be2", lw=0, zorder=3)
            for i in read:  # the number behind the sign's wall, off the corridor
                ux, uy = -np.cos(sg.facing[i]), -np.sin(sg.facing[i])
                ax.annotate(str(sg.number[i]), (sg.x[i], sg.y[i]), xytext=(2.5 * ux, 2.5 * uy), textcoords="offset points",
                            fontsize=6.5, color="#4b0f8a", ha="left" if ux > 0.4 else "right" if ux < -0.4 else "center",
                            va="bottom" if uy > 0.4 else "top" if uy < -0.4 else "center", path_effects=_HALO, zorder=4)
        ax.plot(f["path"][:, 0], f["path"][:, 1], "-", c=PALETTE[1], lw=1.2, zorder=4)
        if len(f["cands"]):
            ax.scatter(f["cands"][:, 0], f["cands"][:, 1], s=12, c=PALETTE[0], lw=0, zorder=5)
        if f["target"] is not None:
            ax.plot(*f["target"], "o", mfc="none", mec=PALETTE[1], ms=8, mew=1.5, zorder=5)
        ax.plot(f["path"][-1, 0], f["path"][-1, 1], "o", c=PALETTE[2], mec="black", ms=5, zorder=6)
        if goal is not None:
            _stops(ax, [goal])
        ax.set_title(f"{title}; {f['distance']:.0f} m, {len(read)} signs read")
        ax.set_xlim(ext[0], ext[1])
        ax.set_ylim(ext[2], ext[3])
        ax.set_xticks([])
        ax.set_yticks([])

    _animate(fig, draw, len(frames), out, fps)


def _animate(fig, draw, n: int, out: Path, fps: int, dpi: int = 130) -> None:
    anim = FuncAnimation(fig, draw, frames=n)
    tmp = temp_path(out)
    anim.save(tmp, writer=PillowWriter(fps=fps), dpi=dpi)
    plt.close(fig)
    os.replace(tmp, out)


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
    return _save(fig, out, formats)


@_paper
def plot_object_bars(table, order: list, out: Path, formats=("png",), colors: dict | None = None) -> list[Path]:
    """The thesis' Figure 5.12: per case, the mean distance per request hour and planner with its
    95% CI (columns ``mean``, ``mean_lo``, ``mean_hi``); where some runs did not find the object,
    the bar is hatched and the share that did is written above it."""
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
            err = np.nan_to_num(np.vstack([mean - lo, hi - mean]))
            bars = ax.bar(xs, mean, width, yerr=err, capsize=1.5, color=colors[lab], error_kw=dict(lw=0.7))
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
    fig.legend(handles=[Patch(color=colors[lab], label=t) for lab, t in zip(order, labels)], loc="outside lower center",
               ncol=min(3, len(order)))
    return _save(fig, out, formats)


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
    return _save(fig, out, formats)


@_paper
def plot_chain_stages(stage_rows, order: list, out: Path, formats=("png",), colors: dict | None = None) -> list[Path]:
    """Per chain (one panel each): the mean distance of each stage with the map kept (solid) and
    from scratch (hatched), per planner, with 95% CIs over units (:func:`.stats.mean_ci`).

    stage_rows : DataFrame, the per-stage rows (goal = the chain, stage, planner, map, distance_m, seed)."""
    colors = colors or planner_colors(order)
    chains = list(dict.fromkeys(stage_rows["goal"]))
    fig, axes = plt.subplots(len(chains), 1, figsize=(2 * COLUMN_IN, 1.9 * len(chains) + 0.5), squeeze=False,
                             layout="constrained")
    for ax, ch in zip(axes[:, 0], chains):
        d = stage_rows[stage_rows["goal"] == ch]
        labels = list(dict.fromkeys(d["stage"]))
        x = np.arange(len(labels))
        width = 0.8 / max(1, 2 * len(order))
        for j, p in enumerate(order):
            for m, mode in enumerate(("kept", "scratch")):
                e = d[(d["planner"] == p) & (d["map"] == mode)]
                ci = [stats.mean_ci(s["distance_m"].astype(float), stats.units(s)) if len(s) else (np.nan,) * 3
                      for s in (e[e["stage"] == lab] for lab in labels)]
                mean, lo, hi = (np.array(v, float) for v in zip(*ci))
                xs = x + (2 * j + m - len(order)) * width + width / 2
                ax.bar(xs, mean, width, color=colors[p], alpha=1.0 if mode == "kept" else 0.45,
                       hatch=None if mode == "kept" else "////")
                has = np.isfinite(lo) & np.isfinite(hi)  # one run per stage has no interval: no bar drawn
                if has.any():
                    ax.errorbar(xs[has], mean[has], yerr=np.vstack([mean - lo, hi - mean])[:, has], fmt="none",
                                ecolor="black", elinewidth=0.7, capsize=1.5)
        ax.set_xticks(x, [f"stage {lab.split(':', 1)[0]}\ndoor {lab.split(':', 1)[1]}" if ":" in lab else lab for lab in labels])
        ax.set_ylabel("distance (m)")
        ax.set_title(f"chain {ch}")
    n = stage_rows.groupby(["planner", "goal", "stage", "map"]).size().groupby(level=0).agg(["min", "max"])
    handles = [Patch(color=colors[p], label=f"{p} (n={n.loc[p, 'min']}" + (f"-{n.loc[p, 'max']}" if n.loc[p, "max"] != n.loc[p, "min"] else "") + ")")
               for p in order if p in n.index]
    handles += [Patch(facecolor="0.5", label="map kept"), Patch(facecolor="0.5", alpha=0.45, hatch="////", label="from scratch")]
    fig.legend(handles=handles, loc="outside lower center", ncol=min(4, len(handles)))
    one = int(stage_rows.groupby(["planner", "goal", "stage", "map"]).size().max()) < 2
    fig.suptitle("distance per stage (one run each: no interval)" if one else
                 f"mean distance per stage, 95% CI over {stats.unit_kind(stage_rows)}")
    return _save(fig, out, formats)


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
        ax.set_title(f"{m} (n={'/'.join(map(str, n))})", fontsize=8, color=c if c != "#000000" else "black")
        ax.set_ylim(-3, 104)  # room for the markers at 0 and 100%, which the frame would cut in half
        ax.set_yticks([0, 25, 50, 75, 100])
        ax.grid(alpha=0.3, lw=0.5)
    for ax in axes.flat[len(order):]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("success (%)")
    for j in range(cols):  # the lowest visible panel of each column carries the x label
        col = [ax for ax in axes[:, j] if ax.get_visible()]
        col[-1].set_xlabel("view scale (m)")
        col[-1].xaxis.set_tick_params(labelbottom=True)
    handles = [Line2D([], [], c="0.3", marker="o", ms=3, label="ours"),
               Patch(color="0.3", alpha=0.2, lw=0, label="its 95% interval"),
               Line2D([], [], c="0.55", ls="--", marker="s", ms=2.5, label="the paper's Table 3")]
    fig.legend(handles=handles, loc="outside lower center", ncol=3)
    return _save(fig, out, formats)


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
        ax.axis("off")
    handles, labels = axes.ravel()[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(5, len(labels)))
    fig.suptitle(title)
    return _save(fig, out, formats)


@_paper
def animate_probability(room, target: str, frames: list, title: str, out: Path, fps: int = 4) -> None:
    """A GIF of one indirect search: per re-plan, the probability map of A (the robot's belief,
    each frame scaled to its own maximum), the path so far, the secondary objects seen, the goal;
    A itself ringed."""
    w, h = room.size
    fig, ax = plt.subplots(figsize=(COLUMN_IN, COLUMN_IN * h / w + 0.35), layout="constrained")
    target = room.objects[target]

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
