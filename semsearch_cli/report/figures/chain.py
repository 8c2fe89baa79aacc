"""Chained searches' figure (thesis ch. 6): the distance of each stage with the map kept against
from scratch, per chain and planner (:func:`plot_chain_stages`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import stats
from . import common
from .common import COLUMN_IN, _paper, planner_colors

import matplotlib.pyplot as plt  # after .common, which chooses the Agg backend
from matplotlib.patches import Patch


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
    return common._save(fig, out, formats)
