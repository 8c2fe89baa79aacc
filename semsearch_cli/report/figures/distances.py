"""The distance figures: success against a distance budget (:func:`budget_curve`,
:func:`plot_budget`), distances per goal and planner as box plots (:func:`plot_boxes`), and
parameter sweeps (:func:`plot_alpha_sweep`, :func:`plot_sweep`)."""

from __future__ import annotations


import inspect
import json
from pathlib import Path

import numpy as np
import pandas as pd

from .. import stats
from ...planners.base import baseline_of, planner_named, swept_value
from ..tables import goal_key, planner_order
from . import common as _common  # by another name: plot_boxes has a local named common
from .common import (COLUMN_IN, wrap_label, _grid, _legend, _n_by_planner, _no_finite, _outer_y, _paper, episode_mean,
                     planner_colors)

import matplotlib.pyplot as plt  # after .common, which chooses the Agg backend
import matplotlib.ticker
from matplotlib.colors import to_rgba
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.transforms import blended_transform_factory

# Axes.boxplot(orientation=) from Matplotlib 3.10 (vert= is deprecated there)
_HORIZONTAL = {"orientation": "horizontal"} if "orientation" in inspect.signature(plt.Axes.boxplot).parameters else {"vert": False}


# ---- statistics over runs -----------------------------------------------------------------------
def swept_rows(runs: pd.DataFrame) -> tuple[type | None, pd.DataFrame]:
    """(the planner class that sweeps a parameter, its rows with the parameter's value in column
    ``swept``): the first swept planner in report order (:attr:`Planner.swept`; nsos and alpha),
    the value each row's ``params`` holds (the parameter's default when they do not set it); from
    the row's label (:func:`~semsearch_cli.planners.base.swept_value`) only for a table without
    ``params``."""
    labels = runs["planner"].astype(str)
    for lab in planner_order(labels):
        cls = planner_named(lab)
        if cls is not None and cls.swept is not None:
            rows = runs[labels.map(lambda x: planner_named(x) is cls)].copy()
            if "params" in rows:
                default = float(cls.Params.model_fields[cls.swept].default)
                rows["swept"] = [float(json.loads(p if isinstance(p, str) and p else "{}").get(cls.swept, default))
                                 for p in rows["params"]]
            else:
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
                # a long label (a language model's endpoint and model) broken at its parameters, to the panel's width
                ax.set_title(f"{wrap_label(lab, 22)}\n(n={n})" if len(lab) > 12 else f"{lab} (n={n})", fontsize=8,
                             color=colors[lab])
            if j == 0:
                ax.set_ylabel(f"goal {g}\nsuccess rate")
    for ax in axes[-1]:
        ax.set_xlabel("budget b (m)")
    handles = [Line2D([], [], c="0.3", lw=1.2, label="the panel's planner: found within b"), Patch(color="0.3", alpha=0.25, lw=0,
               label=f"its 95% CI over {unit_word}"), Line2D([], [], c="0.75", lw=0.6, label="the other planners"),
               Line2D([], [], c="black", ls=":", lw=0.7, label="shortest path (mean over episodes)")]
    fig.legend(handles=handles, loc="outside lower center", ncol=4 if cols >= 4 else 2, handlelength=1.6, columnspacing=1.0)
    return _common._save(fig, out, formats)


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
    ticks = [wrap_label(lab, 30) + (f" (n={common[lab]})" if common else "") for lab in labels]  # a long label on lines
    fig, axes = _grid(len(goals), sum(0.32 + 0.14 * t.count("\n") for t in ticks) + 0.75, sharey=True)
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
    axes[0].set_yticks(y, ticks)
    axes[0].set_ylim(len(labels) - 0.45, -0.55)
    for ax in axes:
        _outer_y(ax)
    unit_word = stats.unit_kind(sub)
    handles = [Patch(facecolor="0.85", edgecolor="0.3", label="quartiles, median; whiskers 1.5 IQR"),
               Line2D([], [], marker="D", ms=3.2, mfc="0.6", mec="black", c="black", label=f"mean, 95% CI over {unit_word}"),
               Line2D([], [], c="black", ls="--", lw=0.8, label="shortest path (mean over episodes)")]
    _legend(fig, axes, handles, ncol=2, handlelength=1.6, columnspacing=1.0)
    return _common._save(fig, out, formats)


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
            ax.set_ylabel("mean ratio to shortest")
    n_a = sorted(set(n_alpha.tolist()))
    n_b = sorted(set(n_base.tolist()))
    handles = [Line2D([], [], c="0.3", marker="o", mfc="0.6", mec="black", ms=4,
                      label=f"{swept_name} (n={'/'.join(map(str, n_a))} per {param})")]
    if len(n_b):
        handles.append(Line2D([], [], c=colors.get(baseline, "black"), ls="--", label=f"{baseline} (n={'/'.join(map(str, n_b))})"))
    band = colors.get(baseline, "0.6") if len(n_b) else "0.6"
    handles.append(Patch(color=band, alpha=0.3, label=f"95% CI over {stats.unit_kind(runs)} (bars{f'; band: {baseline}' if len(n_b) else ''})"))
    handles.append(Line2D([], [], c="0.5", lw=0.6, label="the shortest path (ratio 1)"))
    _legend(fig, axes, handles, ncol=4, handlelength=1.6, columnspacing=1.0)
    return _common._save(fig, out, formats)


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
    return _common._save(fig, out, formats)
