"""The door-search section of a report: the thesis' Tables 4.2-4.10, success and SPL, significance
against greedy, box plots, the alpha sweep, the median paths over the map and a replay."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..runner import file_stem, run_rows
from . import tables as T
from .document import Document, atomic_text, markdown_table, write_table
from .plots import animate_run, plot_alpha_sweep, plot_boxes, plot_paths_overlay, plot_scenario
from .tables import goal_key


def section(doc: Document, parts: list, out: Path, formats: set, replay: bool, notes: list) -> None:
    runs = pd.concat([run_rows(p.runs) for p in parts], ignore_index=True)
    summary = T.summarise(runs)
    tabs = {
        "summary": summary,
        "five_statistics": T.five_statistics(runs, summary),
        "mean_std": T.mean_std(runs, summary),
        "mean_ci": T.mean_ci(runs, summary),
        "percent_of_optimal": T.percent_of_optimal(runs, summary),
        "success_spl": T.success_and_spl(runs),
        "significance": T.significance(runs),
    }
    tdir = out / "tables"
    for name, df in tabs.items():
        write_table(tdir, name, df, formats)
    if formats & {"md", "html"}:
        for name in ("five_statistics", "mean_std", "mean_ci", "percent_of_optimal"):
            atomic_text(tdir / f"{name}.md", markdown_table(tabs[name], mark_rows=name not in ("mean_std", "mean_ci")))
    units = T.interval_caption(summary)
    doc.heading(2, f"Door search ({len(runs)} runs)")
    doc.heading(3, "Distance travelled (m): median, mean, std, min, max (thesis Tables 4.2-4.5)")
    doc.para(f"Over every run ({T.span(summary['n'])} runs per goal and planner), a failed run at the distance it "
             "travelled before it ended, as the thesis. Best of each row in bold, worst in italics.")
    doc.table(tabs["five_statistics"], mark_rows=True)
    doc.heading(3, "Mean ± std beside the shortest path (Tables 4.6-4.9)")
    doc.para("std: the spread of the runs (ddof = 1), as the thesis prints it, not the uncertainty of the mean "
             "(next table).")
    doc.table(tabs["mean_std"])
    doc.heading(3, "Mean with its 95% interval [low, high] (n) beside the shortest path")
    doc.para(f"{units}; n in brackets after each interval. The interval is a BCa bootstrap (SciPy, 9999 "
             "resamples) of the mean of the per-unit mean distances.")
    doc.table(tabs["mean_ci"])
    doc.heading(3, "Mean as percent of the shortest path (Table 4.10)")
    doc.table(tabs["percent_of_optimal"], mark_rows=True)
    doc.heading(3, "Success rate and SPL")
    doc.para(f"success_lo-success_hi: the Wilson interval at the effective sample size n / deff, deff being Kish's "
             f"design effect of the runs clustered in units; {units}. spl: SPL (Anderson et al. 2018); soft_spl: "
             "SoftSPL (Datta et al. 2020). The failed runs by cause: budget (ran out), stuck (no path to anywhere "
             "new), explored (nowhere left to look), error.")
    doc.table(tabs["success_spl"].drop(columns=["unit"]).set_index(["scenario", "goal", "planner"]), fmt="{:.3g}")
    sig = tabs["significance"]
    doc.heading(3, "Is the difference significant? (Wilcoxon signed-rank, paired on shared episodes; else Mann-Whitney U)")
    doc.para("Each planner against the baseline (greedy where it ran, else the first planner). Where the two ran the "
             "same episodes and seeds, each unit's runs share their start and random stream, so they are compared "
             f"pair by pair, on the units above (n_pairs = {T.span(sig['n_pairs'])}): two-sided Wilcoxon signed-rank test of the "
             "per-unit differences. Elsewhere, the two-sided Mann-Whitney U test of each side's unit means. "
             "mean_diff: planner - baseline (m; negative: the planner travels less) with its 95% bootstrap interval "
             "(diff_lo, diff_hi). effect_r: rank-biserial correlation (matched pairs for Wilcoxon), positive when "
             "the planner travels more than the baseline.")
    doc.table(sig.set_index(["scenario", "goal", "planner"]), fmt="{:.3g}")
    if formats & {"png", "html", "md"}:
        doc.heading(3, "Figures")
        _figures(doc, runs, parts, out / "figures", replay, notes)


def _figures(doc, runs, parts, fdir: Path, replay: bool, notes: list) -> None:
    order = T.planner_order(runs["planner"])
    for scen in sorted(runs["scenario"].astype(str).unique()):
        sub = runs[runs["scenario"].astype(str) == scen]
        f = fdir / f"boxes_{scen}.png"
        plot_boxes(runs.assign(scenario=runs["scenario"].astype(str)), scen, order, f)
        doc.figure(f, f"Distance per goal and planner, {scen} (box: quartiles, line: median, triangle: mean; dashed: shortest path)")
        if sub["planner"].str.startswith("nsos").any():
            f = fdir / f"alpha_{scen}.png"
            plot_alpha_sweep(sub, f)
            doc.figure(f, f"Mean ratio to the shortest path against alpha, {scen}")
    for part in parts:
        loaded = part.loaded(notes, "Path figures and the replay")
        if loaded is None:
            continue
        rows = run_rows(part.runs)
        med = T.median_run(rows)
        w = loaded.world
        for goal in sorted(med["goal"].unique(), key=goal_key):
            paths = {k: (path, float(r.distance_m)) for k, (path, r) in T.median_paths(part.folder, med, goal, order).items()}
            if paths:
                f = fdir / f"paths_{loaded.sc.name}_goal{goal}.png"
                i = w.signs.index_of(loaded.task.goal_value(goal))
                plot_paths_overlay(w, paths, [(f"goal {goal}", float(w.signs.x[i]), float(w.signs.y[i]))],
                                   f"{loaded.sc.name}: median runs, goal {goal}", f)
                doc.figure(f, f"Median run of each planner for goal {goal} ({loaded.sc.name})")
        if replay:
            _replay(doc, loaded, rows, fdir, T.planner_order(rows["planner"]))


def _replay(doc, loaded, runs, fdir, order) -> None:
    """Re-simulate (runs are deterministic) the median run of the most semantic variant for the
    first goal, recording the belief at each decision, and write it as an animated GIF."""
    w = loaded.world
    label = order[-1]
    goal = sorted(runs["goal"].unique(), key=goal_key)[0]
    med = T.median_run(runs[(runs["planner"] == label) & (runs["goal"] == goal)])
    if med.empty:
        return
    variant = next((v for v in loaded.task.variants() if v.label == label), None)
    if variant is None:
        return
    seed = int(med["seed"].iloc[0])
    frames = []
    step = max(1, int(med["decisions"].iloc[0]) // 60)
    count = [0]

    def rec(belief, trail, distance, cands, dec):
        count[0] += 1
        if count[0] % step:
            return
        m = np.where(belief.seen, np.where(belief.free, 2, 0), 1).astype(np.uint8)
        cx, cy = w.frame.to_world(cands.rows, cands.cols)
        frames.append({"map": m[::2, ::2], "path": np.asarray(trail, float), "distance": distance,
                       "cands": np.stack([cx, cy], axis=1) if len(cands) else np.zeros((0, 2)),
                       "target": w.frame.to_world(dec.row, dec.col)})

    res = loaded.task.run(variant, goal, seed, recorder=rec)
    if not frames:
        return
    f = fdir / f"replay_{loaded.sc.name}_{file_stem(label, goal, seed)}.gif"
    animate_run(w, frames, f"{label}, goal {goal}, seed {seed}", f)
    doc.figure(f, f"Replay of {label}, goal {goal}, seed {seed} ({res.outcome}, {res.distance_m:.1f} m): "
               "the map as built (white free, black occupied, gray unknown), candidates and the chosen one")


def console(runs: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    cols = ["goal", "planner", "n", "episodes", "success_rate", "median", "mean", "mean_lo", "mean_hi", "std", "min", "max",
            "shortest_m", "mean_ratio"]
    s = T.summarise(run_rows(runs))
    return [(f"distance travelled (m) per goal and planner; mean_lo-mean_hi: {T.interval_caption(s)}", s[cols])]


def show(loaded, out: Path) -> None:
    w, sc = loaded.world, loaded.sc
    plot_scenario(w, sc.goals, f"{sc.name}: {len(w.signs)} signs, goals {', '.join(map(str, sc.goals))}", out)
