"""Object-search reports (thesis 5.3.4, Figure 5.12): tables per case, request hour and planner,
the bar figure, the LSOS heat map of every request, and the median paths. Tables come from
runs.csv alone; heat maps and paths also need the scenario named in meta.json."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from ..belief.objects import heat_map
from ..planners import LsosParams, lsos_goals
from ..runner import run_rows
from ..tasks.objects import parse_label, read_log
from . import tables as T
from .sections import Section, register_section
from .document import Document, atomic_text, markdown_table, write_table
from .figures.common import image_formats, planner_colors
from .figures.objects import plot_heat, plot_heat_steps, plot_object_bars
from .figures.paths import plot_path_panels
from .runfiles import load_paths, median_panel, start_points

def object_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per case x class x request hour x planner: n, found, success rate, mean, std (ddof 1),
    min, max of the distance until the object was seen (or the search gave up), the shortest, and
    the episode-level 95% intervals of the mean and the rate (:func:`.tables.intervals`)."""
    df = runs.copy()
    parts = [parse_label(g) for g in df["goal"]]
    df["case"] = [p[0] for p in parts]
    df["class"] = [p[1] for p in parts]
    df["hour"] = [p[2] for p in parts]
    g = df.groupby(["case", "class", "hour", "planner"], sort=False)
    out = g.agg(n=("distance_m", "size"), found=("success", "sum"), success_rate=("success", "mean"),
                mean=("distance_m", "mean"), std=("distance_m", "std"), min=("distance_m", "min"),
                max=("distance_m", "max"), shortest_m=("shortest_m", "mean")).reset_index()
    keys = ["case", "class", "hour", "planner"]
    out = out.merge(T.per_group(df, keys, T.intervals, T.INTERVALS), on=keys, how="left")
    case_order = list(dict.fromkeys(df["case"]))
    out["_c"] = out["case"].map(case_order.index)
    out["_h"] = out["hour"].map(lambda h: (h == 0, h))
    planner_rank = {p: i for i, p in enumerate(T.planner_order(df["planner"]))}
    out["_p"] = out["planner"].map(planner_rank)
    return out.sort_values(["_c", "class", "_h", "_p"]).drop(columns=["_c", "_h", "_p"]).round(3).reset_index(drop=True)


def figure_table(table: pd.DataFrame) -> pd.DataFrame:
    """Wide: rows (case, request), one column per planner, cells ``mean ± std (found/n)``."""
    t = table.copy()
    t["request"] = [f"{c} {h:02.0f}:{(h % 1) * 60:02.0f}" for c, h in zip(t["class"], t["hour"])]
    t["cell"] = [f"{m:.1f} ± {0.0 if np.isnan(s) else s:.1f} ({f}/{n})" for m, s, f, n in
                 zip(t["mean"], t["std"], t["found"], t["n"])]
    wide = t.pivot_table(index=["case", "request"], columns="planner", values="cell", aggfunc="first", sort=False)
    wide = wide[[p for p in T.planner_order(t["planner"]) if p in wide.columns]]
    wide["shortest (m)"] = t.groupby(["case", "request"], sort=False)["shortest_m"].first().map(lambda v: f"{v:.1f}")
    wide.columns.name = None
    return wide


def section(doc: Document, parts: list, out: Path, formats: set, replay: bool, notes: list) -> None:
    runs = pd.concat([run_rows(p.runs) for p in parts], ignore_index=True)
    table = object_table(runs)
    wide = figure_table(table)
    tdir = out / "tables"
    write_table(tdir, "objects", table, formats)
    if formats & {"md", "html"}:
        atomic_text(tdir / "objects.md", markdown_table(wide))
    doc.heading(2, f"Object search over time ({len(runs)} runs)")
    doc.heading(3, "Distance until the object is seen (m): mean ± std (found / runs)")
    doc.para("A run that does not find the object counts the distance until the planner gave up "
             "(Last Seen after its one spot, Brute Force after its whole route). std is the spread of the runs; "
             "tables/objects.csv adds the intervals of the mean distance (mean_lo, mean_hi: bootstrap) and of the "
             f"success rate (success_lo, success_hi: clustered Wilson), {T.interval_caption(table)}.")
    doc.table(wide)
    img = image_formats(formats)
    if img:
        doc.heading(3, "Figures")
        fdir = out / "figures"
        f = fdir / "objects_by_case.png"
        order = T.planner_order(runs["planner"])
        plot_object_bars(table, order, f, img, planner_colors(order))
        doc.figure(f, "Distance until the object is seen per case, request hour and planner (the thesis' Figure 5.12): "
                      f"the mean with its 95% interval ({T.interval_caption(table)}); hatched bars: some runs did not find "
                      "the object (the share that did above the bar)")
        for part in parts:
            _figures(doc, run_rows(part.runs), part, fdir, notes, img, planner_colors(order))


def console(runs: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    return [("distance until the object is seen (m): mean ± std (found / runs)",
             figure_table(object_table(run_rows(runs))).reset_index())]


def show(loaded, out: Path) -> None:
    task, sc = loaded.task, loaded.sc
    route = task.patrol_route()
    length = float(np.hypot(*np.diff(route, axis=0).T).sum())
    plot_path_panels(loaded.world, {}, [], f"{sc.name}: places {' '.join(task.places)}; patrol route {length:.1f} m (dotted)",
                     out, places=task.places, route=route)


def _figures(doc, runs, part, fdir: Path, notes: list, img=("png",), colors: dict | None = None) -> None:
    order = T.planner_order(runs["planner"])
    colors = colors or planner_colors(order)
    folder = part.folder
    loaded = part.loaded(notes, "Heat maps and paths")
    if loaded is None:
        return
    task, world = loaded.task, loaded.world
    lsos = next((lab for lab in order if lab.split("[", 1)[0] == "lsos"), None)
    stepped: set[str] = set()
    for label in dict.fromkeys(runs["goal"]):
        try:
            req = task.request(label)
        except StopIteration:
            notes.append(f"{label}: not a request of the scenario any more; its figures were skipped.")
            continue
        stem = label  # letters, digits, - _ . @ only
        if lsos is not None:
            params = json.loads(runs[runs["planner"] == lsos]["params"].iloc[0])
            heat, goals = lsos_goals(world.frame, task.known, _log(folder, loaded, req.case), req.cls, req.hour, LsosParams(**params))
            gx = [(*world.frame.to_world(r, c), phi) for r, c, phi in goals]
            f = fdir / f"heat_{stem}.png"
            plot_heat(world, heat, task.places, req.truth, gx, f"{req.case}: {req.cls} at {req.hour:g}:00", f, img)
            doc.figure(f, f"Heat map of {lsos} for {label} (Eq. 5.4) and its goals (Eqs. 5.5-5.6), numbered in visiting "
                          f"order; ringed: where the {req.cls} is")
            if req.case not in stepped:  # the construction, once per case (thesis Figures 5.7-5.8)
                stepped.add(req.case)
                f = fdir / f"heat_steps_{stem}.png"
                _heat_steps(task, world, _log(folder, loaded, req.case), req, LsosParams(**params), f, img)
                doc.figure(f, f"How the heat map for {label} is built (thesis Figures 5.7-5.8)")
        panels = {}
        for lab in order:
            e = runs[(runs["goal"] == label) & (runs["planner"] == lab)]
            found = load_paths(folder, e)
            if found:
                panels[lab] = median_panel(e, found, f"{int(e['success'].sum())}/{len(e)} found")
        if panels:
            f = fdir / f"paths_{stem}.png"
            plot_path_panels(world, panels, [], "", f, img, colors, start_points(runs[runs["goal"] == label], world),
                             places=task.places, truth=req.truth)
            doc.figure(f, f"{req.case}: {req.cls} requested at {req.hour:g}:00, one panel per planner: every run faint, "
                          "the median run (by distance; with an even number of runs the lower of the two middle runs, "
                          "the title giving the median and its distance) bold, its end dotted; ringed: the places "
                          "holding the object")


def _heat_steps(task, world, log, req, p, out: Path, img=("png",)) -> None:
    rows = list(zip(log["class"], log["x"], log["y"], log["hour"], log["robot_x"], log["robot_y"]))
    args = (req.hour, world.frame, p.radius, task.known)
    panels = [
        ("(a) every detection, circular kernel K (Eq. 5.1)", heat_map(rows, None, *args, sector_deg=180.0, inverted=False)),
        (f"(b) kernels cut to {p.sector:g} degrees toward the robot pose", heat_map(rows, None, *args, sector_deg=p.sector, inverted=False)),
        (f"(c) only the class {req.cls}", heat_map(rows, req.cls, *args, sector_deg=p.sector, inverted=False)),
        ("(d) inverted kernel IK (Eq. 5.4): what LSOS uses", heat_map(rows, req.cls, *args, sector_deg=p.sector, inverted=True)),
    ]
    plot_heat_steps(world, panels, task.places, f"{req.case}: heat map for {req.cls} at {req.hour:g}:00, step by step "
                    f"(r = {p.radius:g} m, W of Eq. 5.3)", out, img)


def _log(folder: Path, loaded, case: str) -> pd.DataFrame:
    """The detection log the runs used (``logs/<case>.csv`` beside runs.csv), else the scenario's."""
    f = folder / "logs" / f"{case}.csv"
    return read_log(f) if f.is_file() else loaded.task.logs[case]


register_section(Section("objects", section, console, show, replays=False))
