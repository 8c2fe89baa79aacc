"""`semsearch report`: every table and figure rebuilt from runs.csv alone, plus one self-contained
report per results folder (issue: reports). Figures that need the map (paths, replay) also read
the scenario named in the folder's meta.json and the stored paths; they are skipped, with a note,
when those are gone.
"""

from __future__ import annotations

import base64
import datetime
import html
import json
import os
import shlex
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from ..experiment import file_stem
from . import tables as T
from .tables import goal_key

ALL_FORMATS = ("md", "csv", "png", "html")


def write_meta(out_dir: Path, scenario: Path) -> None:
    """Record, beside runs.csv, the scenario and the command that produced (or extended) it."""
    out_dir.mkdir(parents=True, exist_ok=True)
    f = out_dir / "meta.json"
    meta = json.loads(f.read_text()) if f.is_file() else {"commands": []}
    meta["scenario"] = str(Path(scenario).resolve())
    meta["semsearch"] = __version__
    cmd = "semsearch " + " ".join(shlex.quote(a) for a in sys.argv[1:]) if Path(sys.argv[0]).name == "semsearch" else " ".join(sys.argv)
    if cmd not in meta["commands"]:
        meta["commands"].append(cmd)
    tmp = f.with_suffix(".tmp")
    tmp.write_text(json.dumps(meta, indent=2))
    os.replace(tmp, f)


def _atomic_text(path: Path, text: str) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def build_report(folders: list[Path], out: Path | None = None, formats=ALL_FORMATS, replay: bool = True) -> list[Path]:
    """Write tables (CSV, Markdown), figures (PNG, GIF) and report.md / report.html for each
    results folder (into ``out/<folder name>`` when several, else ``out``; default: the folder
    itself). Returns the report files written."""
    written = []
    for folder in folders:
        folder = Path(folder)
        target = folder if out is None else (Path(out) / folder.name if len(folders) > 1 else Path(out))
        written += _report_one(folder, target, set(formats), replay)
    return written


def _report_one(folder: Path, out: Path, formats: set, replay: bool) -> list[Path]:
    from ..errors import ScenarioError
    from ..experiment import read_runs

    t0 = time.perf_counter()
    runs = read_runs(folder / "runs.csv")
    if runs.empty:
        raise ScenarioError(str(folder / "runs.csv"), "", "no finished runs to report (is this a semsearch results folder?)")
    out.mkdir(parents=True, exist_ok=True)
    meta = json.loads((folder / "meta.json").read_text()) if (folder / "meta.json").is_file() else {}
    from .objects import is_object_runs, report_objects

    if is_object_runs(runs):
        return report_objects(runs, folder, out, formats, meta)
    order = T.planner_order(runs["planner"])
    tabs = {
        "summary": T.summarise(runs),
        "five_statistics": T.five_statistics(runs),
        "mean_std": T.mean_std(runs),
        "percent_of_optimal": T.percent_of_optimal(runs),
        "success_spl": T.success_and_spl(runs),
        "significance": T.significance(runs),
    }
    tdir = out / "tables"
    tdir.mkdir(exist_ok=True)
    if "csv" in formats:
        for name, df in tabs.items():
            tmp = tdir / f".{name}.csv.tmp"
            df.to_csv(tmp, index=not isinstance(df.index, pd.RangeIndex))
            os.replace(tmp, tdir / f"{name}.csv")
    figs: list[tuple[str, Path]] = []
    notes: list[str] = []
    if formats & {"png", "html", "md"}:
        figs, notes = _figures(runs, folder, out, order, meta, replay)
    md = _markdown(runs, tabs, figs, notes, meta, folder, out)
    files = []
    if "md" in formats or "html" in formats:
        _atomic_text(out / "report.md", md)
        files.append(out / "report.md")
        for name in ("five_statistics", "mean_std", "percent_of_optimal"):
            _atomic_text(tdir / f"{name}.md", T.markdown(tabs[name], mark_rows=name != "mean_std"))
    if "html" in formats:
        _atomic_text(out / "report.html", _html(md, out))
        files.append(out / "report.html")
    print(f"report of {folder}: {len(runs)} runs, {len(figs)} figures, {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return files


def _figures(runs, folder: Path, out: Path, order, meta, replay):
    from .plots import plot_alpha_sweep, plot_boxes, plot_paths_overlay

    fdir = out / "figures"
    fdir.mkdir(exist_ok=True)
    figs, notes = [], []
    for scen in sorted(runs["scenario"].unique()):
        f = fdir / f"boxes_{scen}.png"
        plot_boxes(runs, scen, order, f)
        figs.append((f"Distance per goal and planner, {scen} (box: quartiles, line: median, triangle: mean; dashed: shortest path)", f))
        sub = runs[runs["scenario"] == scen]
        if sub["planner"].str.startswith("nsos").any():
            f = fdir / f"alpha_{scen}.png"
            plot_alpha_sweep(sub, f)
            figs.append((f"Mean ratio to the shortest path against alpha, {scen}", f))
    world = _world(meta, notes)
    if world is not None:
        med = T.median_run(runs)
        for goal in sorted(med["goal"].unique(), key=goal_key):
            paths = {}
            for _, r in med[med["goal"] == goal].iterrows():
                p = folder / "paths" / f"{file_stem(r['planner'], goal, int(r['seed']))}.npz"
                if p.is_file():
                    paths[r["planner"]] = (np.load(p)["path"], float(r["distance_m"]))
            if paths:
                g = _goal(world, goal)
                f = fdir / f"paths_goal{goal}.png"
                plot_paths_overlay(world[0], {k: paths[k] for k in order if k in paths}, g, f"median runs, goal {goal}", f)
                figs.append((f"Median run of each planner for goal {goal}", f))
        if replay:
            f = _replay(world, runs, meta, fdir, order, notes)
            if f is not None:
                figs.append(f)
    return figs, notes


def _world(meta, notes):
    from ..config import load_scenario
    from ..world.scenario import build_world

    def load(path):
        sc = load_scenario(path)
        return build_world(sc, path.parent, str(path)), sc

    return from_meta(meta, notes, "Path figures and the replay", load)


def _goal(world, goal):
    w, sc = world
    for g in sc.goals:
        if str(g) == str(goal):
            return g
    return goal


def _replay(world, runs, meta, fdir, order, notes):
    """Re-simulate (runs are deterministic) the median run of the most semantic variant for the
    first goal, recording the belief at each decision, and write it as an animated GIF."""
    from ..episode import Episode
    from ..planners import Variant
    from .plots import animate_run

    w, sc = world
    label = order[-1]
    params = json.loads(runs[runs["planner"] == label]["params"].iloc[0])
    goal = sorted(runs["goal"].unique(), key=goal_key)[0]
    med = T.median_run(runs[(runs["planner"] == label) & (runs["goal"] == goal)])
    if med.empty:
        return None
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

    g = _goal(world, goal)
    res = Episode(w, sc, Variant(label.split("[")[0], tuple(sorted(params.items()))), g, seed, recorder=rec).run()
    if not frames:
        return None
    f = fdir / f"replay_{file_stem(label, goal, seed)}.gif"
    animate_run(w, frames, f"{label}, goal {goal}, seed {seed}", f)
    return (f"Replay of {label}, goal {goal}, seed {seed} ({res.outcome}, {res.distance_m:.1f} m): "
            "the map as built (white free, black occupied, gray unknown), candidates and the chosen one", f)


def head_lines(runs, meta, folder: Path, kind: str = "") -> list[str]:
    """The top of a report: title, version, the commands that produced the rows, the scenario."""
    now = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    scen = ", ".join(sorted(runs["scenario"].unique()))
    lines = [f"# semsearch report: {scen}{kind}", "",
             f"semsearch {__version__}, {now}; {len(runs)} finished runs from `{folder / 'runs.csv'}`.", ""]
    if meta.get("commands"):
        lines += ["Produced by:", "", *[f"    {c}" for c in meta["commands"]], "",
                  f"Report: `semsearch report {folder}`", ""]
    if meta.get("scenario") and Path(meta["scenario"]).is_file():
        lines += ["## Scenario", "", "```yaml", Path(meta["scenario"]).read_text().strip(), "```", ""]
    return lines


def tail_lines(figs, notes, out: Path) -> list[str]:
    """The end of a report: the figures with their captions, then the notes."""
    lines = []
    if figs:
        lines += ["## Figures", ""]
        for caption, f in figs:
            lines += [f"![{caption}]({os.path.relpath(f, out)})", "", f"*{caption}*", ""]
    for n in notes:
        lines += [f"> {n}", ""]
    return lines


def from_meta(meta, notes, what: str, load):
    """``load(path)`` of the scenario named in meta.json, or None with a note saying that
    ``what`` were skipped and why."""
    from ..errors import ScenarioError

    path = Path(meta.get("scenario", ""))
    if not meta.get("scenario") or not path.is_file():
        notes.append(f"{what} were skipped: the scenario file named in meta.json is not available.")
        return None
    try:
        return load(path)
    except ScenarioError as exc:
        notes.append(f"{what} were skipped: {exc}")
        return None


def _markdown(runs, tabs, figs, notes, meta, folder: Path, out: Path) -> str:
    lines = head_lines(runs, meta, folder)
    lines += ["## Distance travelled (m): median, mean, std, min, max (thesis Tables 4.2-4.5)", "",
              "Best of each row in **bold**, worst in _italics_.", "", T.markdown(tabs["five_statistics"], mark_rows=True), "",
              "## Mean ± std beside the shortest path (Tables 4.6-4.9)", "", T.markdown(tabs["mean_std"]), "",
              "## Mean as percent of the shortest path (Table 4.10)", "", T.markdown(tabs["percent_of_optimal"], mark_rows=True), "",
              "## Success rate and SPL", "", T.markdown(tabs["success_spl"].set_index(["scenario", "goal", "planner"]), fmt="{:.3g}"), "",
              "## Is the difference significant? (Mann-Whitney U against greedy, two-sided)", "",
              "effect_r: rank-biserial correlation, positive when the planner travels less than greedy.", "",
              T.markdown(tabs["significance"].set_index(["scenario", "goal", "planner"]).drop(columns=["baseline"]), fmt="{:.3g}"), ""]
    return "\n".join(lines + tail_lines(figs, notes, out))


def _html(md: str, out: Path) -> str:
    """A self-contained HTML page: the Markdown report's text, tables and images (inlined)."""
    body = []
    in_table = in_code = False
    for line in md.splitlines():
        if line.startswith("```"):
            body.append("<pre>" if not in_code else "</pre>")
            in_code = not in_code
            continue
        if in_code:
            body.append(html.escape(line))
            continue
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if set("".join(cells)) <= set("-"):
                continue
            if not in_table:
                body.append("<table>")
                in_table = True
                body.append("<tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in cells) + "</tr>")
                continue
            tds = []
            for c in cells:
                t = html.escape(c)
                if c.startswith("**"):
                    t = f"<b class=best>{html.escape(c.strip('*'))}</b>"
                elif c.startswith("_") and c.endswith("_") and len(c) > 1:
                    t = f"<i class=worst>{html.escape(c.strip('_'))}</i>"
                tds.append(f"<td>{t}</td>")
            body.append("<tr>" + "".join(tds) + "</tr>")
            continue
        if in_table:
            body.append("</table>")
            in_table = False
        if line.startswith("!["):
            cap, path = line[2:].split("](", 1)
            f = out / path.rstrip(")")
            mime = "image/gif" if f.suffix == ".gif" else "image/png"
            data = base64.b64encode(f.read_bytes()).decode() if f.is_file() else ""
            body.append(f'<figure><img src="data:{mime};base64,{data}" alt="{html.escape(cap)}"></figure>')
        elif line.startswith("#"):
            n = len(line) - len(line.lstrip("#"))
            body.append(f"<h{n}>{html.escape(line[n:].strip())}</h{n}>")
        elif line.startswith("    "):
            body.append(f"<pre>{html.escape(line.strip())}</pre>")
        elif line.startswith("> "):
            body.append(f"<blockquote>{html.escape(line[2:])}</blockquote>")
        elif line.startswith("*") and line.endswith("*"):
            body.append(f"<p class=caption>{html.escape(line.strip('*'))}</p>")
        elif line.strip():
            body.append(f"<p>{html.escape(line).replace('`', '')}</p>")
    if in_table:
        body.append("</table>")
    style = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}table{border-collapse:collapse;"
             "font-size:12px;margin:1em 0}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
             ".best{color:#1a7f37}.worst{color:#c62828}img{max-width:100%}.caption{color:#555;font-size:13px}")
    return f"<!doctype html><html><head><meta charset=utf-8><title>semsearch report</title><style>{style}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n"
