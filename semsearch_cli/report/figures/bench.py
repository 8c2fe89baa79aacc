"""The bench board's figure: each floor's semantic gain against its predictability."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .common import COLUMN_IN, PALETTE, _paper, _save, plt


GAIN_FLOOR = 1e-9  # SPL: a gain this close to 0 is float noise (two equal SPLs computed apart), shown as 0


@_paper
def plot_gain_vs_predictability(floors: pd.DataFrame, out: Path, formats=("png",), title: str = "") -> list[Path]:
    """One panel per planner: each floor's semantic gain (the mean over its episodes of SPL under
    its true numbering minus SPL under shuffled labels, paired episode by episode) against the
    floor's predictability, marked by its numbering convention, with the least-squares line over
    the floors. ``floors``: columns planner, floor, convention, predictability, gain."""
    floors = floors.assign(gain=floors["gain"].where(~(floors["gain"].abs() <= GAIN_FLOOR), 0.0))  # noise is no gain
    planners = list(dict.fromkeys(floors["planner"]))
    conventions = sorted(set(floors["convention"]))
    marks = dict(zip(conventions, "os^vD<>pPX*h"))
    colors = {c: PALETTE[k % len(PALETTE)] for k, c in enumerate(conventions)}
    n = len(planners)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(COLUMN_IN * cols, 2.4 * rows + 0.5), squeeze=False,
                             sharex=True, sharey=True, layout="constrained")
    for ax, lab in zip(axes.ravel(), planners):
        d = floors[floors["planner"] == lab]
        for c in conventions:
            e = d[d["convention"] == c]
            ax.scatter(e["predictability"], e["gain"], s=14, marker=marks[c], color=colors[c], label=c, linewidths=0)
        ok = np.isfinite(d["predictability"]) & np.isfinite(d["gain"])
        fit = ""  # under the panel's title, never over its points
        if ok.sum() >= 3 and d.loc[ok, "gain"].nunique() == 1:  # no line through a constant (r undefined)
            fit = f"gain {d.loc[ok, 'gain'].iloc[0]:+.3f} on every one of {int(ok.sum())} floors"
        elif ok.sum() >= 3:
            k, b = np.polyfit(d.loc[ok, "predictability"], d.loc[ok, "gain"], 1)
            x = np.linspace(d.loc[ok, "predictability"].min(), d.loc[ok, "predictability"].max(), 2)
            ax.plot(x, k * x + b, color="0.3", lw=0.8)
            r = float(np.corrcoef(d.loc[ok, "predictability"], d.loc[ok, "gain"])[0, 1])
            fit = f"slope {k:+.2g}, r = {r:+.2f}, {int(ok.sum())} floors"  # .2g: a slope of 5e-4 is not -0.00
        ax.axhline(0.0, color="0.6", lw=0.6, ls=":")
        ax.set_title(lab + (f"\n{fit}" if fit else ""), fontsize=None if not fit else 8)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("floor predictability")
    for ax in axes[:, 0]:
        ax.set_ylabel("semantic gain (SPL true - shuffled)")
    handles, labels = axes.ravel()[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(labels)), title="numbering convention")
    fig.suptitle(title or "Semantic gain per floor (mean over its episodes of SPL, true minus shuffled labels) "
                 "against the floor's predictability", wrap=True)
    return _save(fig, out, formats)
