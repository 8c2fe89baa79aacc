"""The chain section of a report (thesis ch. 6): per chain and planner the distance of
each stage with the map kept against the same stage from scratch, the saving, and whether later
stages get cheaper as the robot knows more."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from . import tables as T
from .sections import Section, register_section
from .document import Document, atomic_text, markdown_table, write_table
from .figures.chain import plot_chain_stages
from .figures.common import image_formats, planner_colors
from .figures.paths import plot_path_panels, plot_scenario
from .runfiles import load_paths, median_panel, safe_name, start_points


def chain_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per chain x planner (the chain rows): n, success rate, mean and std of the total distance,
    the shortest chain (the sum of the shortest legs) and the mean ratio, and the episode-level
    95% intervals of the mean and the rate (:func:`.tables.intervals`)."""
    rows = runs[runs["stage"] == ""]
    keys = ["scenario", "goal", "planner"]
    g = rows.groupby(keys, sort=False)
    out = g.agg(n=("distance_m", "size"), success_rate=("success", "mean"), mean=("distance_m", "mean"),
                std=("distance_m", "std"), shortest_m=("shortest_m", "mean"), mean_ratio=("ratio", "mean")).reset_index()
    return out.merge(T.per_group(rows, keys, T.intervals, T.INTERVALS), on=keys, how="left").round(3)


def stage_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per chain x stage x planner x map (kept / scratch): n, success rate, mean distance, the
    shortest leg."""
    st = runs[runs["stage"] != ""]
    g = st.groupby(["scenario", "goal", "stage", "planner", "map"], sort=False)
    return g.agg(n=("distance_m", "size"), success_rate=("success", "mean"), mean=("distance_m", "mean"),
                 shortest_m=("shortest_m", "mean")).round(3).reset_index()


def saving_table(stages: pd.DataFrame) -> pd.DataFrame:
    """Wide: rows (chain, stage), per planner ``kept / scratch m (saving %)``; the saving is
    1 - kept / scratch of the mean distances. A last row per chain sums the stages."""
    out = []
    for (ch, stage), d in stages.groupby(["goal", "stage"], sort=False):
        row = {"chain": ch, "stage": stage, "shortest (m)": f"{d['shortest_m'].iloc[0]:.1f}"}
        for p, e in d.groupby("planner", sort=False):
            k, s = e[e["map"] == "kept"]["mean"], e[e["map"] == "scratch"]["mean"]
            if len(k) and len(s):
                row[p] = f"{k.iloc[0]:.1f} / {s.iloc[0]:.1f} ({_saving(k.iloc[0], s.iloc[0])})"
        out.append(row)
    for ch, d in stages.groupby("goal", sort=False):
        row = {"chain": ch, "stage": "all stages", "shortest (m)": f"{d.drop_duplicates('stage')['shortest_m'].sum():.1f}"}
        for p, e in d.groupby("planner", sort=False):
            k, s = e[e["map"] == "kept"]["mean"].sum(), e[e["map"] == "scratch"]["mean"].sum()
            row[p] = f"{k:.1f} / {s:.1f} ({_saving(k, s)})"
        out.append(row)
    order = {c: i for i, c in enumerate(dict.fromkeys(stages["goal"]))}
    df = pd.DataFrame(out)
    df["_c"] = df["chain"].map(order)
    return df.sort_values("_c", kind="stable").drop(columns="_c").set_index(["chain", "stage"])


def by_position(stages: pd.DataFrame) -> pd.DataFrame:
    """Mean saving (%) of the k-th stage over all chains, per planner: does the robot's growing
    knowledge make later requests cheaper (thesis ch. 6)?"""
    s = stages.assign(position=stages["stage"].str.split(":").str[0].astype(int))
    w = s.pivot_table(index=["goal", "position", "planner"], columns="map", values="mean", aggfunc="first").reset_index()
    w["saving_pct"] = 100.0 * (1.0 - w["kept"] / w["scratch"])
    t = w.pivot_table(index="position", columns="planner", values="saving_pct", aggfunc="mean").round(1)
    t.columns.name = None
    return t


def _saving(kept: float, scratch: float) -> str:
    return f"{100.0 * (1.0 - kept / scratch):+.0f}%" if scratch > 0 else "n/a"


def section(doc: Document, parts: list, out: Path, formats: set, replay: bool, notes: list) -> None:
    runs = pd.concat([p.runs for p in parts], ignore_index=True)
    chains, stages = chain_table(runs), stage_table(runs)
    wide, pos = saving_table(stages), by_position(stages)
    tdir = out / "tables"
    write_table(tdir, "chains", chains, formats)
    write_table(tdir, "chain_stages", stages, formats)
    if formats & {"md", "html"}:
        atomic_text(tdir / "chain_saving.md", markdown_table(wide))
    doc.heading(2, f"Chained searches ({int((runs['stage'] == '').sum())} chains)")
    doc.para("Each chain runs its stages in order, keeping the robot's pose, map and sign reads; each stage is also "
             "run from scratch (same starting pose, empty map). A stage is door:N, or door:N/class@hour for an "
             "object found in the room behind door N.")
    doc.heading(3, "Whole chains: distance (m) beside the shortest chain")
    doc.para("std: the spread of the runs; mean_lo-mean_hi (bootstrap) and success_lo-success_hi (clustered "
             f"Wilson): {T.interval_caption(chains)}.")
    doc.table(chains.set_index(["scenario", "goal", "planner"]), fmt="{:.3g}")
    doc.heading(3, "Each stage: mean distance with the map kept / from scratch (m), and the saving")
    doc.table(wide)
    doc.heading(3, "Do later requests get cheaper? Mean saving (%) of the k-th stage over all chains")
    doc.table(pos, fmt="{:.1f}")
    img = image_formats(formats)
    if img:
        order = T.planner_order(runs["planner"])
        f = out / "figures" / "chain_stages.png"
        stage_rows = runs[runs["stage"] != ""]
        plot_chain_stages(stage_rows, order, f, img, planner_colors(order))
        one = int(stage_rows.groupby(["planner", "goal", "stage", "map"]).size().max()) < 2
        doc.figure(f, "Each stage's mean distance with the map kept (solid) and from scratch (hatched), per planner, "
                      + ("one run each, so no interval" if one else "with 95% intervals (bootstrap over units)"))
        _path_figures(doc, parts, out / "figures", notes, img, planner_colors(order))


def _path_figures(doc: Document, parts: list, fdir: Path, notes: list, img=("png",), colors: dict | None = None) -> None:
    """Per chain, one panel per planner: every run's whole path faint, the median run (by total
    distance) bold, the stage doors starred and numbered in order."""
    for part in parts:
        loaded = part.loaded(notes, "Chain path figures")
        if loaded is None:
            continue
        w, chains = loaded.world, part.runs[part.runs["stage"] == ""]
        order = T.planner_order(chains["planner"])
        for goal in dict.fromkeys(chains["goal"]):
            stages = loaded.task.stages.get(str(goal), [])
            g = chains[chains["goal"] == goal]
            panels = {}
            for lab in order:
                e = g[g["planner"] == lab]
                found = load_paths(part.folder, e)
                if found:
                    panels[lab] = median_panel(e, found, f"n={len(e)}")
            if not panels or not stages:
                continue
            at: dict = {}  # door -> the stages there ("1, 4: 7" when a chain comes back)
            for k, s in enumerate(stages, 1):
                at.setdefault(s.door, []).append((k, s.label))
            stops = []
            for door, ks in at.items():
                i = w.signs.index_of(door)
                by_label: dict = {}  # what is sought there -> its stages ("1: 12/laptop@11; 3: 12")
                for k, lab in ks:
                    by_label.setdefault(lab, []).append(str(k))
                label = "; ".join(f"{', '.join(k)}: {lab}" for lab, k in by_label.items())
                stops.append((label, float(w.signs.x[i]), float(w.signs.y[i])))
            f = fdir / f"chain_paths_{loaded.sc.name}_{safe_name(goal)}.png"
            plot_path_panels(w, panels, stops, "", f, img, colors, start_points(g, w))
            doc.figure(f, f"Chain {goal} ({loaded.sc.name}), one panel per planner: every run faint, the median run "
                          "(by total distance; with an even number of runs the lower of the two middle runs, the "
                          "title giving the median and its distance) bold; stars: the stages' doors, numbered in order")


def console(runs: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    stages = stage_table(runs)
    return [("chains: distance travelled (m)", chain_table(runs).drop(columns=["scenario"])),
            ("each stage: map kept / from scratch (m) (saving)", saving_table(stages).reset_index()),
            ("mean saving (%) of the k-th stage", by_position(stages).reset_index())]


def show(loaded, out: Path) -> None:
    w, t = loaded.world, loaded.task
    doors = list(dict.fromkeys(s.door for st in t.stages.values() for s in st))
    plot_scenario(w, doors, f"{loaded.sc.name}: {len(w.signs)} signs; chains: "
                  + "; ".join(f"{n}: {' > '.join(s.label for s in st)}" for n, st in t.stages.items()), out)


register_section(Section("chain", section, console, show, replays=False))
