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
    """``n`` panels, ``cols`` to a row, each :data:`COLUMN_IN` wide and ``panel_h`` tall; the
    unused cells of the last row hold no axes (:func:`_legend` may put the legend there).
    ``maps``: the panels have a fixed aspect (the layout closes the gaps that leaves). Returns
    (figure, the n axes)."""
    cols = max(1, min(cols, n))
    rows = -(-max(n, 1) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(COLUMN_IN * cols, panel_h * rows), squeeze=False, **kw)
    fig.set_layout_engine("constrained", compress=maps)
    for ax in axes.flat[max(n, 1):]:
        ax.remove()
    used = list(axes.flat[:max(n, 1)])
    _label_outer(used)
    return fig, used


def _cell(ax) -> tuple[int, int]:
    ss = ax.get_subplotspec()
    return ss.rowspan.start, ss.colspan.start


def _label_outer(axes) -> None:
    """Axes that share x (y) show their tick labels only where no panel of ``axes`` is below
    (left of) them: :meth:`matplotlib.axes.Axes.label_outer` for a grid whose last row is not
    full (the panel above an empty cell keeps its x tick labels)."""
    cells = {_cell(ax) for ax in axes}
    for ax in axes:
        r, c = _cell(ax)
        if len(ax.get_shared_x_axes().get_siblings(ax)) > 1:
            below = any((rr, c) in cells for rr in range(r + 1, ax.get_subplotspec().get_gridspec().nrows))
            ax.tick_params(labelbottom=not below)
            if below:
                ax.set_xlabel("")
        if len(ax.get_shared_y_axes().get_siblings(ax)) > 1:
            left = any((r, cc) in cells for cc in range(c))
            ax.tick_params(labelleft=not left)
            if left:
                ax.set_ylabel("")


def _legend(fig, axes, handles, ncol: int, **kw):
    """The figure's legend: in the free cells of the grid's last row when :func:`_grid` left
    some (so no cell stays empty), else under the panels."""
    gs = axes[0].get_subplotspec().get_gridspec()
    used = {_cell(ax) for ax in axes}
    free = [c for c in range(gs.ncols) if (gs.nrows - 1, c) not in used]
    if free and len(axes) > 1:
        lax = fig.add_subplot(gs[gs.nrows - 1, free[0]:free[-1] + 1])
        lax.axis("off")
        return lax.legend(handles=handles, loc="center", ncol=1 if len(free) == 1 else min(ncol, 2), **kw)
    return fig.legend(handles=handles, loc="outside lower center", ncol=ncol, **kw)


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


def _overlap(a, b) -> bool:
    """Whether boxes ``a`` and ``b`` (cx, cy, width, height) overlap (touching is not)."""
    return abs(a[0] - b[0]) * 2 < a[2] + b[2] and abs(a[1] - b[1]) * 2 < a[3] + b[3]


def thin_boxes(boxes, fixed=()) -> list[int]:
    """Indices of ``boxes`` (cx, cy, width, height) to draw, in the given order of priority: a box
    that overlaps a kept one, or one of the ``fixed`` boxes already drawn, is dropped."""
    drawn = [tuple(map(float, b)) for b in fixed]
    kept: list[int] = []
    for i, b in enumerate(boxes):
        b = tuple(map(float, b))
        if not any(_overlap(b, d) for d in drawn):
            kept.append(i)
            drawn.append(b)
    return kept


CHAR_W = 0.64  # a digit's width (DejaVu Sans: 0.636), in units of the font size
LINE_H = 1.2  # a line's height, in units of the font size
LABEL_PAD = 0.5  # room kept between two numbers, in units of the font size


def _text_box(ax_, ay_, w: float, h: float, ha: str, va: str) -> tuple[float, float, float, float]:
    """The box (cx, cy, w, h) of a text ``w`` x ``h`` anchored at (ax_, ay_) with alignment ha, va."""
    cx = ax_ + {"left": w / 2, "right": -w / 2}.get(ha, 0.0)
    cy = ay_ + {"bottom": h / 2, "top": -h / 2}.get(va, 0.0)
    return cx, cy, w, h


def _axes_m_per_pt(ax) -> float:
    """Metres of the map per printed point on ``ax`` (equal aspect) as its figure lays it out."""
    fig = ax.figure
    fig.draw_without_rendering()
    bb = ax.get_window_extent()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    pt = 72.0 / fig.dpi
    return max(abs(x1 - x0) / max(bb.width * pt, 1e-9), abs(y1 - y0) / max(bb.height * pt, 1e-9))


def _sign_labels(ax, world, path: np.ndarray, skip: set, m_per_pt: float, near_m: float, size: float = 6.5,
                 fixed=()) -> None:
    """Number the signs within ``near_m`` of ``path`` (the others stay unlabelled dots), nearest
    to the path's end first, dropping labels that would overlap a kept one or one of the
    ``fixed`` boxes (the stops' stars and labels, the starts: :func:`thin_boxes`)."""
    s = world.signs
    if not len(s) or not len(path):
        return
    d, _ = cKDTree(path[:: max(1, len(path) // 4000)]).query(np.c_[s.x, s.y])
    idx = [i for i in np.flatnonzero(d <= near_m) if i not in skip]
    idx.sort(key=lambda i: np.hypot(s.x[i] - path[-1, 0], s.y[i] - path[-1, 1]))
    _number_signs(ax, world, idx, m_per_pt, size, fixed)


def _number_layout(world, idx, m_per_pt: float, size: float, rotate: bool = False) -> list[dict]:
    """Where the numbers of signs ``idx`` go: each behind its sign's wall (opposite the way the
    sign faces), ``gap`` points from the sign. Per sign: text, offset (points), ha, va, rotation
    and its box (cx, cy, w, h) in metres. With ``rotate``, numbers on walls that run left-right
    are written upright."""
    s = world.signs
    gap = 2.0  # pt between the sign and its number
    out = []
    for i in idx:
        text = str(s.number[i])
        ux, uy = -np.cos(s.facing[i]), -np.sin(s.facing[i])
        ha = "left" if ux > 0.4 else "right" if ux < -0.4 else "center"
        va = "bottom" if uy > 0.4 else "top" if uy < -0.4 else "center"
        upright = rotate and abs(uy) > 0.7
        w, h = (len(text) * CHAR_W + LABEL_PAD) * size * m_per_pt, LINE_H * size * m_per_pt
        if upright:
            w, h = h, w
        box = _text_box(s.x[i] + ux * gap * m_per_pt, s.y[i] + uy * gap * m_per_pt, w, h, ha, va)
        out.append({"i": i, "text": text, "xytext": (ux * gap, uy * gap), "ha": ha, "va": va,
                    "rotation": 90 if upright else 0, "box": box})
    return out


def _number_signs(ax, world, idx, m_per_pt: float, size: float, fixed=None, rotate: bool = False,
                  color: str = "#222222") -> list[tuple]:
    """Write the numbers of signs ``idx`` (:func:`_number_layout`: behind each sign's wall, off
    the corridor and any path in it). With ``fixed`` (boxes already drawn, see
    :func:`thin_boxes`), a number that would overlap one of them or a number kept before is
    written the other way (level instead of upright, with ``rotate``) if that overlaps nothing,
    else dropped; earlier ones are placed first. Returns the boxes of the numbers written (m)."""
    s = world.signs
    idx = list(idx)
    lay = _number_layout(world, idx, m_per_pt, size, rotate)
    if fixed is None:
        chosen = lay
    else:
        other = _number_layout(world, idx, m_per_pt, size, False) if rotate else [None] * len(lay)
        drawn, chosen = [tuple(map(float, b)) for b in fixed], []
        for d in zip(lay, other):
            fit = next((c for c in d if c is not None and not any(_overlap(c["box"], b) for b in drawn)), None)
            if fit is not None:
                chosen.append(fit)
                drawn.append(fit["box"])
    for d in chosen:
        i = d["i"]
        ax.annotate(d["text"], (s.x[i], s.y[i]), xytext=d["xytext"], textcoords="offset points", fontsize=size, ha=d["ha"],
                    va=d["va"], color=color, path_effects=_HALO, zorder=6, rotation=d["rotation"])
    return [d["box"] for d in chosen]


STAR_PT = 10.0  # a stop's star marker (points)
STAR_BOX_PT = 9.0  # the box a star takes from labels (its points reach 10 pt across; labels may touch them)
# where a stop's label may go, in order of preference: (dx, dy) points, ha, va
STOP_LABEL_AT = ((5, 4, "left", "bottom"), (-5, 4, "right", "bottom"), (5, -4, "left", "top"), (-5, -4, "right", "top"),
                 (7, 0, "left", "center"), (-7, 0, "right", "center"), (0, 7, "center", "bottom"), (0, -7, "center", "top"),
                 (0, 18, "center", "bottom"), (0, -18, "center", "top"), (5, 18, "left", "bottom"), (-5, 18, "right", "bottom"),
                 (5, -18, "left", "top"), (-5, -18, "right", "top"))


def place_stop_labels(stops, m_per_pt: float, avoid=(), size: float = 7.5) -> list[tuple]:
    """Where each stop's label goes: the first of :data:`STOP_LABEL_AT` whose box meets none of
    the ``avoid`` boxes (cx, cy, w, h; m), the stars and the labels placed before; else the one
    meeting the fewest. Returns per stop (dx, dy, ha, va, label box)."""
    stars = [(x, y, STAR_BOX_PT * m_per_pt, STAR_BOX_PT * m_per_pt) for _, x, y in stops]
    taken = [tuple(map(float, b)) for b in avoid] + stars
    out = []
    for text, x, y in stops:
        w, h = len(str(text)) * 0.66 * size * m_per_pt, LINE_H * size * m_per_pt  # bold: a little wider
        best = None
        for dx, dy, ha, va in STOP_LABEL_AT:
            box = _text_box(x + dx * m_per_pt, y + dy * m_per_pt, w, h, ha, va)
            hits = sum(_overlap(box, b) for b in taken)
            if best is None or hits < best[0]:
                best = (hits, (dx, dy, ha, va, box))
            if hits == 0:
                break
        out.append(best[1])
        taken.append(best[1][4])
    return out


def _stops(ax, stops, m_per_pt: float, avoid=(), size: float = 7.5) -> list[tuple]:
    """Goals (or a chain's doors) as yellow stars, labelled beside them where the label meets no
    ``avoid`` box (:func:`place_stop_labels`). Returns the boxes drawn (stars and labels, m)."""
    placed = place_stop_labels(stops, m_per_pt, avoid, size)
    boxes = []
    for (lab, x, y), (dx, dy, ha, va, box) in zip(stops, placed):
        ax.plot(x, y, "*", ms=STAR_PT, mfc=GOAL_COLOR, mec="black", mew=0.7, zorder=8)
        ax.annotate(lab, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=size, weight="bold", zorder=9,
                    ha=ha, va=va, path_effects=_HALO)
        boxes += [(x, y, STAR_BOX_PT * m_per_pt, STAR_BOX_PT * m_per_pt), box]
    return boxes


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


EVERY_RUN_LW = 0.9  # every run's path in the small multiples (pt)


def every_run_alpha(n: int) -> float:
    """The opacity of each of ``n`` runs drawn over one another: where all of them pass the
    colour is nearly solid, where one passes it still shows (at least 0.4)."""
    return float(np.clip(4.0 / max(1, n), 0.4, 0.7))


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
            ax.set_title(f"{lab}: {note}" if note else lab, color="black")
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
    return _save(fig, out, formats)


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
    goal's rows, so every planner of a goal has the same kind of unit), computed for all budgets at
    once (:func:`.stats.rate_ci_by_budget`).

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
            r = stats.rate_ci_by_budget(found[m], dist[m], unit.to_numpy()[m], grid, confidence)
            out.append(pd.DataFrame({"goal": [goal] * len(grid), "planner": lab, "budget_m": grid.astype(float),
                                     "n": int(m.sum()), **r}))
    cols = ["goal", "planner", "budget_m", "n", "successes", "rate", "lo", "hi"]
    return pd.concat(out, ignore_index=True)[cols] if out else pd.DataFrame(columns=cols)


BUDGET_PAD = 0.08  # the budget axis runs this share past the longest run


def budget_limit(longest: float) -> float:
    """The right end of a budget axis whose longest run is ``longest`` m: a little past it, so
    that a last step (the longest run finding the goal) shows as a level, not as the frame."""
    return longest * (1 + BUDGET_PAD) if np.isfinite(longest) and longest > 0 else 1.0


def _no_finite(ax, y: float | None = None) -> None:
    """Say on ``ax`` that its data has no finite distance (in its middle, or at data height ``y``)."""
    at = (0.5, 0.5, ax.transAxes) if y is None else (0.02, y, blended_transform_factory(ax.transAxes, ax.transData))
    ax.text(at[0], at[1], "no finite distance", transform=at[2], ha="center" if y is None else "left", va="center",
            fontsize=7, color="0.3")


def _to_limit(e: pd.DataFrame, right: float) -> pd.DataFrame:
    """A planner's budget curve (rows by budget ascending) carried on at its last rate to ``right``."""
    if not len(e) or float(e["budget_m"].iloc[-1]) >= right:
        return e
    return pd.concat([e, e.iloc[[-1]].assign(budget_m=right)], ignore_index=True)


@_paper
def plot_budget(curve: pd.DataFrame, order: list, out: Path, formats=("png",), colors: dict | None = None,
                shortest: dict | None = None, unit_word: str = "repeats") -> list[Path]:
    """Success rate against the distance budget (:func:`budget_curve`) as small multiples: a row
    per goal (shared budget axis, running :data:`BUDGET_PAD` past the goal's longest run, each
    curve carried on to its end, so that a last step shows), a column per planner. Each panel
    draws its planner's step curve with the 95% band, the other planners' curves thin grey behind
    it (so none hides another), and the shortest path dotted."""
    colors = colors or planner_colors(order)
    goals = list(dict.fromkeys(curve["goal"]))
    labels = [p for p in order if (curve["planner"] == p).any()]
    cols = len(labels)
    w = min(1.45, 2 * COLUMN_IN / cols) * cols
    fig, axes = plt.subplots(len(goals), cols, figsize=(w, 1.05 * len(goals) + 0.55), squeeze=False, sharex="row",
                             sharey=True, layout="constrained")
    for r, g in enumerate(goals):
        d = curve[curve["goal"] == g]
        finite = np.isfinite(d["budget_m"].astype(float))
        none = not finite.all() and not (d.loc[finite, "budget_m"] > 0).any()  # every distance infinite or NaN
        d = d[finite]  # the axis and the curves from finite budgets only (an infinite distance has no place on it)
        right = budget_limit(float(d["budget_m"].max()) if len(d) else 0.0)
        for j, lab in enumerate(labels):
            ax = axes[r, j]
            if none:
                _no_finite(ax)
            for other in labels:
                if other != lab:
                    e = _to_limit(d[d["planner"] == other], right)
                    ax.step(e["budget_m"], e["rate"], where="post", c="0.75", lw=0.6, zorder=1)
            e = _to_limit(d[d["planner"] == lab], right)
            if len(e):
                c = colors[lab]
                ax.fill_between(e["budget_m"], e["lo"].fillna(e["rate"]), e["hi"].fillna(e["rate"]), step="post", color=c,
                                alpha=0.25, lw=0, zorder=2)
                ax.step(e["budget_m"], e["rate"], where="post", c=c, lw=1.2, zorder=3)
            if shortest and g in shortest and np.isfinite(shortest[g]):
                ax.axvline(shortest[g], c="black", ls=":", lw=0.7, zorder=4)
            ax.set_xlim(0, right)
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
    fig.legend(handles=handles, loc="outside lower center", ncol=4 if cols >= 4 else 2, handlelength=1.6, columnspacing=1.0)
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
            if not np.isfinite(v).any():
                _no_finite(ax, y[k])
            else:
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
    _legend(fig, axes, handles, ncol=2, handlelength=1.6, columnspacing=1.0)
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
    _legend(fig, axes, handles, ncol=4, handlelength=1.6, columnspacing=1.0)
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
        ax.remove()
    handles, labels = axes.ravel()[0].get_legend_handles_labels()
    _legend(fig, list(axes.ravel()[:n]), handles, ncol=min(5, len(labels)))
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
