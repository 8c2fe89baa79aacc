"""The door-search section of a report: the thesis' Tables 4.2-4.10, success and SPL, significance
against greedy, box plots, the alpha sweep, the median paths over the map and a replay."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..planners.base import planner_named
from ..runner import run_rows
from . import stats as S
from . import tables as T
from .sections import Section, register_section
from .document import Document, atomic_text, markdown_table, write_table
from .figures.common import episode_mean, image_formats, planner_colors
from .figures.distances import budget_curve, plot_alpha_sweep, plot_boxes, plot_budget, swept_values
from .figures.paths import plot_path_panels, plot_scenario
from .figures.replay import animate_run
from .runfiles import (load_paths, median_label, median_panel, replay_frames, row_variant, safe_name, same_goal, start_points,
                       stems)
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
    doc.para(f"{units}; n in brackets after each interval. The interval is a BCa bootstrap (9999 resamples, "
             "drawn as scipy.stats.bootstrap draws them) of the mean of the per-unit mean distances.")
    doc.table(tabs["mean_ci"])
    doc.heading(3, "Mean ratio to the shortest path, in percent (Table 4.10)")
    doc.para(T.RATIO[0].upper() + T.RATIO[1:] + ", times 100.")
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
             "the planner travels more than the baseline. A blank p_value or interval is explained in the note "
             "column: with fewer than 2 non-zero paired differences the signed-rank test has nothing to rank (no "
             "test), and one pair or unit gives no interval; where every paired difference is 0, p = 1 is a "
             "convention.")
    doc.table(sig.set_index(["scenario", "goal", "planner"]), fmt="{:.3g}")
    if image_formats(formats):
        doc.heading(3, "Figures")
        _figures(doc, runs, parts, out / "figures", replay, notes, formats)


def _figures(doc, runs, parts, fdir: Path, replay, notes: list, formats=("png",)) -> None:
    """Per scenario: distance boxes with mean CIs, success against the distance budget, the alpha
    sweep (when nsos ran at two alphas or more); per goal the runs over the map; one replay."""
    img = image_formats(formats)
    order = T.planner_order(runs["planner"])
    colors = planner_colors(order)
    for scen in sorted(runs["scenario"].astype(str).unique()):
        sub = runs[runs["scenario"].astype(str) == scen]
        unit = S.unit_kind(sub)
        f = fdir / f"boxes_{scen}.png"
        plot_boxes(sub, scen, order, f, img, colors)
        doc.figure(f, f"Distance travelled per goal and planner, {scen}: boxes span the quartiles (line: median; "
                      "whiskers: 1.5 IQR; dots: outliers); diamonds: the mean with its 95% interval over "
                      f"{unit} (bootstrap); dashed: the shortest path (mean over the episodes); n: runs per planner and goal")
        curve = budget_curve(sub)
        write_table(fdir.parent / "tables", f"budget_{scen}", curve, formats)
        shortest = {g: episode_mean(d, "shortest_m") for g, d in sub.groupby("goal")}
        f = fdir / f"budget_{scen}.png"
        plot_budget(curve, order, f, img, colors, shortest, unit)
        doc.figure(f, f"Success against the distance budget b, {scen}: a row per goal (goals are not pooled: their "
                      "shortest paths differ), a column per planner; the share of runs that found the goal within b "
                      f"metres, with its 95% interval over {unit} (clustered Wilson), the other planners in grey; "
                      "dotted: the shortest path (mean over the episodes)")
        if len(swept_values(sub)) >= 2:
            f = fdir / f"alpha_{scen}.png"
            plot_alpha_sweep(sub, f, formats=img, colors=colors)
            doc.figure(f, f"Mean ratio to the shortest path against alpha, {scen}, with 95% intervals over {unit}; "
                          "dashed and shaded: greedy's mean and interval. The ratio is each run's distance over its own "
                          "episode's shortest path, averaged over the runs: Table 4.10 gives the same numbers in percent.")
    for part in parts:
        loaded = part.loaded(notes, "Path figures and the replay")
        if loaded is None:
            continue
        rows = run_rows(part.runs)
        w = loaded.world
        for goal in sorted(rows["goal"].unique(), key=goal_key):
            g = rows[rows["goal"] == goal]
            panels = {}
            for lab in [p for p in order if (g["planner"] == p).any()]:
                e = g[g["planner"] == lab]
                found = load_paths(part.folder, e)
                if not found:
                    continue
                panels[lab] = median_panel(e, found, f"n={len(e)}")
            if not panels:
                continue
            value = loaded.task.goal_value(goal)
            stops = [(f"goal {goal}", float(w.signs.x[i]), float(w.signs.y[i])) for i in w.signs.indices_of(value)]
            f = fdir / f"paths_{loaded.sc.name}_goal{safe_name(goal)}.png"
            plot_path_panels(w, panels, stops, "", f, img, colors, start_points(g, w))
            doc.figure(f, f"Goal {goal} ({loaded.sc.name}), one panel per planner: every run faint, the median run "
                          "(by distance; with an even number of runs there is none, and the lower of the two middle "
                          "runs is drawn, the title giving the median and its distance) bold, its end dotted; the "
                          "signs near it numbered; squares: start"
                          f"{'s' if len(start_points(g, w)) > 1 else ''}; star: the goal")
        if replay:
            _replay(doc, loaded, part.folder, rows, fdir, T.planner_order(rows["planner"]), replay)


def _rerun(task, variant, goal, episode: int, seed: int, observer):
    """Re-simulate one run (runs are deterministic): the one place the report calls ``task.run``.
    ``episode`` is the row's index in the task's episode set; when that episode is not of ``goal``
    (rows from before episodes read as episode 0), the goal's first episode."""
    ep = next((e for e in task.episodes if e.index == episode and str(e.goal) == str(goal)), None)
    return task.run(variant, ep if ep is not None else goal, seed, observer)


def _replay(doc, loaded, folder, runs, fdir, order, choice=True) -> None:
    """One run as an animated GIF of the belief at its decisions, from the frames ``semsearch run
    --frames`` recorded, else re-simulated (see :func:`replay_frames`): ``choice``
    (planner, goal, episode, seed: the ``--replay`` value, checked against the rows before the
    report starts), or by default the median run (:func:`median_label`: the lower middle one for
    an even number of runs) of the most semantic variant for the first goal (not a language
    model's: re-simulating it would call the model)."""
    w = loaded.world
    ep = S.episodes(runs)
    if choice is True:
        label = next((lab for lab in reversed(order) if (c := planner_named(lab)) is None or not c.service), order[-1])
        goal = sorted(runs["goal"].unique(), key=goal_key)[0]
        sub = runs[(runs["planner"] == label) & (runs["goal"] == goal)]
        if sub.empty:
            return
        row = sub.loc[median_label(sub)]
    else:
        # the goal matched as check_replay matched it (--replay greedy,304.0,0,0 is the run of goal 304:
        # it was checked to be there, then not drawn, without a word)
        m = (runs["planner"] == choice.planner) & runs["goal"].map(lambda g: same_goal(g, choice.goal)) & \
            (ep == choice.episode) & (runs["seed"].astype(int) == choice.seed)
        if not m.any():
            return  # the run is in another folder of this report
        row = runs[m].iloc[0]
    label, goal, seed, episode = str(row["planner"]), row["goal"], int(row["seed"]), int(ep[row.name])
    variant = row_variant(loaded, row)
    if variant is None:
        return
    frames, how = replay_frames(folder, label, goal, seed, episode,
                                lambda watch: _rerun(loaded.task, variant, goal, episode, seed, watch),
                                failed=row["outcome"] == "error",
                                expect={"kind": "doors", "signs": len(w.signs),
                                        "map_shape": ((w.frame.height + 1) // 2, (w.frame.width + 1) // 2)})
    if not frames:
        return
    signs = w.signs
    i = signs.index_of(loaded.task.goal_value(goal))
    mark = (f"goal {goal}", float(signs.x[i]), float(signs.y[i])) if i >= 0 else None
    f = fdir / f"replay_{loaded.sc.name}_{stems(label, goal, seed, episode)[0]}.gif"
    animate_run(w, frames, f"{label}, goal {goal}, episode {episode}, seed {seed}", f, goal=mark)
    doc.figure(f, f"Replay of {label}, goal {goal}, episode {episode}, seed {seed} ({row['outcome']}, "
               f"{float(row['distance_m']):.1f} m; frames {how}): "
               "the map as built (white free, black occupied, grey unknown), the candidates and the chosen one, the "
               "signs read so far (numbered where the number fits) and the goal (star, its number in its label)")


def console(runs: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    cols = ["goal", "planner", "n", "episodes", "success_rate", "median", "mean", "mean_lo", "mean_hi", "std", "min", "max",
            "shortest_m", "mean_ratio"]
    s = T.summarise(run_rows(runs))
    return [(f"distance travelled (m) per goal and planner; mean_lo-mean_hi: {T.interval_caption(s)}", s[cols])]


def show(loaded, out: Path) -> None:
    w, sc = loaded.world, loaded.sc
    plot_scenario(w, sc.goals, f"{sc.name}: {len(w.signs)} signs, goals {', '.join(map(str, sc.goals))}", out)


register_section(Section("doors", section, console, show, replays=True))
