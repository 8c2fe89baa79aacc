"""The paper style and the drawing helpers every figure shares: the style, colours and sizes,
the one writer of figures (:func:`_save`), panel grids and legends, the map under paths,
label placement (sign numbers, stops), and the GIF writer.

Every figure is drawn inside :data:`PAPER_RC` (white background; 8 pt text, 9 pt titles; the
Okabe-Ito colour-blind-safe palette) at the size it is printed: panels :data:`COLUMN_IN` (3.5 in,
one journal column) wide, two side by side for a two-column figure, so nothing is scaled down.
A planner keeps its colour in every figure of a report (:func:`planner_colors` over the section's
planner order). Each figure is written in every image format asked for (:func:`image_formats`);
GIF replays stay GIF. Confidence intervals come from :mod:`..stats` (over units: episodes, or the
repeats of a single episode).
"""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ...files import temp_path

import cv2
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from cycler import cycler  # noqa: E402
from matplotlib import patheffects  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402
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


def wrap_label(lab: str, width: int) -> str:
    """A planner label over lines of about ``width`` characters (a language model's label holds
    its endpoint and model), broken only after a ``,`` or a ``/``: a piece between two such
    marks longer than ``width`` keeps its own line whole."""
    lab = str(lab)
    if len(lab) <= width:
        return lab
    lines = [""]
    for piece in re.findall(r"[^,/]*[,/]|[^,/]+$", lab):
        if lines[-1] and len(lines[-1]) + len(piece) > width:
            lines.append("")
        lines[-1] += piece
    return "\n".join(lines)


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


def _no_finite(ax, y: float | None = None) -> None:
    """Say on ``ax`` that its data has no finite distance (in its middle, or at data height ``y``)."""
    at = (0.5, 0.5, ax.transAxes) if y is None else (0.02, y, blended_transform_factory(ax.transAxes, ax.transData))
    ax.text(at[0], at[1], "no finite distance", transform=at[2], ha="center" if y is None else "left", va="center",
            fontsize=7, color="0.3")


def _animate(fig, draw, n: int, out: Path, fps: int, dpi: int = 130) -> None:
    anim = FuncAnimation(fig, draw, frames=n)
    tmp = temp_path(out)
    anim.save(tmp, writer=PillowWriter(fps=fps), dpi=dpi)
    plt.close(fig)
    os.replace(tmp, out)
