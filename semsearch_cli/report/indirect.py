"""The indirect-search section of a report (Loncomilla et al. 2018, Table 3): the success rate per
method and view scale with 95% intervals clustered on rooms beside the paper's, the time to find
and SPL, and success against the view scale. Tables come from runs.csv alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..planners.base import planner_named
from ..runner import run_rows
from . import stats as S
from . import tables as T
from .sections import Section, register_section
from .document import Document, atomic_text, markdown_table, write_table
from .figures.common import image_formats
from .figures.indirect import animate_probability, plot_rooms, plot_success_by_scale
from .runfiles import replay_frames, row_variant, stems

# The paper's Table 3: success rate (%) per method and view scale (m), 200 trials each
PAPER_SCALES = (1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5)
PAPER_TABLE3 = {
    "UIS": (28, 26, 38, 50, 58, 65, 65),
    "ISUP": (31, 38, 46, 53, 67, 70, 70),
    "AOSEOOR": (51, 63, 71, 76, 73, 78, 83),
    "ISC-PN-HM": (49, 60, 63, 64, 77, 79, 85),
    "ISC-OP-HM": (41, 42, 44, 44, 59, 65, 67),
    "ISC-PN-SM": (53, 64, 68, 71, 77, 80, 88),
    "ISC-OP-SM": (42, 42, 48, 55, 62, 67, 69),
    "ISCG-PN-HM": (77, 75, 77, 87, 89, 90, 93),
    "ISCG-OP-HM": (70, 70, 76, 84, 84, 87, 89),
    "ISCG-PN-SM": (79, 74, 86, 87, 88, 94, 95),
    "ISCG-OP-SM": (74, 76, 82, 82, 87, 88, 91),
}
def success_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per scenario x method x view scale: n, found, success rate with its 95% interval clustered
    on rooms (:func:`.stats.rate_ci`: Wilson at the effective sample size n / deff, Kish's design
    effect of the searches in one room layout, which are not independent), mean time to
    find (s, over the searches that found A), mean distance, mean SPL, and the ``unit`` of the
    interval with their number ``n_units``: ``rooms``, or for rows without a room (older folders)
    the episodes, or the repeats of one episode (then it is the plain Wilson interval)."""
    rows = []
    for (scen, planner, scale), g in runs.groupby(["scenario", "planner", "goal"], sort=False):
        n, k = len(g), int(g["success"].sum())
        u = S.units(g, cluster="room")
        _, lo, hi = S.rate_ci(g["success"], u)
        found = g[g["success"] == 1]
        rows.append({"scenario": scen, "planner": planner, "view_scale": float(scale), "n": n, "found": k,
                     "success": k / n, "ci_low": lo, "ci_high": hi, "unit": S.unit_kind(g, cluster="room"),
                     "n_units": int(u.nunique()),
                     "time_to_find_s": found["time_s"].astype(float).mean() if k else np.nan,
                     "distance_m": g["distance_m"].mean(), "spl": g["spl"].mean()})
    out = pd.DataFrame(rows)
    if out.empty:
        return out
    order = T.planner_order(out["planner"])
    out["_p"] = out["planner"].map(order.index)
    return out.sort_values(["scenario", "_p", "view_scale"]).drop(columns="_p").round(4).reset_index(drop=True)


def wide(table: pd.DataFrame) -> pd.DataFrame:
    """Rows method, columns view scale; cells ``ours% [low-high] (paper%)``."""
    return _pivot(table.assign(cell=[_cell(r) for r in table.itertuples(index=False)]))


def _cell(r) -> str:
    paper = PAPER_TABLE3.get(r.planner.split("[", 1)[0])
    ref = ""
    if paper is not None and r.view_scale in PAPER_SCALES:
        ref = f" ({paper[PAPER_SCALES.index(r.view_scale)]})"
    ci = "[-]" if r.ci_low != r.ci_low else f"[{100 * r.ci_low:.0f}-{100 * r.ci_high:.0f}]"
    return f"{100 * r.success:.0f} {ci}{ref}"


def interval_text(table: pd.DataFrame) -> str:
    """What the intervals of :func:`success_table` are over, in words."""
    what = {"rooms": "clustered on room layouts", "episodes": "clustered on episodes (runs without a room)",
            "repeats": "plain Wilson, each search its own unit (runs without a room)"}
    kinds = [what[k] for k in dict.fromkeys(table["unit"])] if len(table) else []
    return (f"95% interval {'; '.join(kinds)}: Wilson at the effective sample size n / deff, deff being Kish's "
            f"design effect ({T.span(table['n_units'])} units per cell)") if kinds else "95% interval"


def time_spl(table: pd.DataFrame) -> pd.DataFrame:
    """Rows method, columns view scale; cells ``time to find (s) / SPL``."""
    return _pivot(table.assign(cell=[f"{t:.0f} s / {s:.2f}" if t == t else f"- / {s:.2f}"
                                     for t, s in zip(table["time_to_find_s"], table["spl"])]))


def _pivot(t: pd.DataFrame) -> pd.DataFrame:
    w = t.pivot_table(index="planner", columns="view_scale", values="cell", aggfunc="first", sort=False)
    w = w.loc[[m for m in T.planner_order(t["planner"]) if m in w.index]]
    w.columns = [f"{c:g} m" for c in w.columns]
    w.index.name = "method"
    return w


def difference_table(table: pd.DataFrame) -> tuple[pd.DataFrame, float]:
    """Rows method, columns view scale: ours minus the paper's Table 3 (percentage points), where
    the paper has the cell; and the mean absolute difference over those cells (nan without any)."""
    t = table[table["view_scale"].isin(PAPER_SCALES)].copy()
    paper = [PAPER_TABLE3.get(p.split("[", 1)[0]) for p in t["planner"]]
    t["diff"] = [100 * r - (ref[PAPER_SCALES.index(v)] if ref else np.nan)
                 for r, v, ref in zip(t["success"], t["view_scale"], paper)]
    t = t.dropna(subset=["diff"])
    if t.empty:
        return pd.DataFrame(), float("nan")
    w = _pivot(t.assign(cell=[f"{d:+.0f}" for d in t["diff"]]))
    return w, float(t["diff"].abs().mean())


def _claims() -> list[tuple[str, str, str]]:
    """The paper's claims as (claim, better, worse) pairs of methods: the global search over the
    local one, positive and negative information over positive only, soft masks over hard ones
    (the paper's Table 3 has each of them in most cells), searching with secondary objects over
    searching without them (each informed method over UIS, the same search on A's map alone: "the
    methods using informed search outperform the baseline method", Section 4.5), and AOSEOOR over
    UIS."""
    out = []
    for info in ("PN", "OP"):
        for m in ("HM", "SM"):
            out.append(("ISCG over ISC", f"ISCG-{info}-{m}", f"ISC-{info}-{m}"))
    for search in ("ISC", "ISCG"):
        for m in ("HM", "SM"):
            out.append(("PN over OP", f"{search}-PN-{m}", f"{search}-OP-{m}"))
    for search in ("ISC", "ISCG"):
        for info in ("PN", "OP"):
            out.append(("SM over HM", f"{search}-{info}-SM", f"{search}-{info}-HM"))
    for search in ("ISC", "ISCG"):
        for info in ("PN", "OP"):
            for m in ("HM", "SM"):
                out.append(("with secondary objects over without (UIS)", f"{search}-{info}-{m}", "UIS"))
    out.append(("AOSEOOR over UIS", "AOSEOOR", "UIS"))
    return out


PAIR_KEYS = ["room", "start_x", "start_y", "seed"]  # what two searches share when they are paired


def paired_success(a: pd.DataFrame, b: pd.DataFrame, keys: list[str]) -> tuple[float, float, float, int]:
    """Mean paired difference of success (a - b, over the searches both ran from the same start,
    room and repeat, and ``keys``) with its 95% bootstrap interval over rooms; (nan, ...) when
    nothing pairs."""
    j = a[keys + ["success"]].merge(b[keys + ["success"]], on=keys, suffixes=("_a", "_b"))
    if j.empty:
        return np.nan, np.nan, np.nan, 0
    d = j["success_a"].astype(float) - j["success_b"].astype(float)
    room = j["room"].astype(str) if (j["room"].astype(str) != "").all() else pd.Series(range(len(j)), index=j.index)
    m, lo, hi = S.mean_ci(d, room)
    return m, lo, hi, len(j)


def _verdict(paper: float, lo: float, hi: float) -> str:
    if not (lo == lo and hi == hi):
        return "too few to judge"
    if lo > 0 or hi < 0:
        return "reproduced" if (lo > 0) == (paper > 0) and paper != 0 else "contradicted"
    return "inside the noise"


def claims_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Each of the paper's claims (:func:`_claims`, and for every method that success grows from
    the smallest view scale to the largest) as a paired difference of success rate (points, ours:
    over the searches both sides ran from the same start; the interval a bootstrap over rooms)
    beside the paper's difference (the mean over the view scales both ran), marked reproduced
    (our interval excludes 0 on the paper's side), contradicted (it excludes 0 on the other side)
    or inside the noise."""
    runs = runs.assign(method=runs["planner"].astype(str).str.split("[").str[0], scale=runs["goal"].astype(float))
    for k in PAIR_KEYS:
        if k not in runs.columns:
            runs[k] = 0 if k != "room" else ""
    rows = []
    scales = sorted(runs["scale"].unique())
    for claim, better, worse in _claims():
        a, b = runs[runs["method"] == better], runs[runs["method"] == worse]
        if a.empty or b.empty:
            continue
        m, lo, hi, n = paired_success(a, b, PAIR_KEYS + ["scale"])
        both = [s for s in scales if s in PAPER_SCALES]
        paper = np.mean([PAPER_TABLE3[better][PAPER_SCALES.index(s)] - PAPER_TABLE3[worse][PAPER_SCALES.index(s)]
                         for s in both]) if both else np.nan
        rows.append({"claim": claim, "better": better, "worse": worse, "pairs": n, "ours": 100 * m, "lo": 100 * lo,
                     "hi": 100 * hi, "paper": paper, "verdict": _verdict(paper, lo, hi)})
    if len(scales) >= 2:
        s0, s1 = scales[0], scales[-1]
        for method in T.planner_order(runs["method"]):
            g = runs[runs["method"] == method]
            m, lo, hi, n = paired_success(g[g["scale"] == s1], g[g["scale"] == s0], PAIR_KEYS)
            ref = PAPER_TABLE3.get(method)
            paper = (ref[PAPER_SCALES.index(s1)] - ref[PAPER_SCALES.index(s0)]) if ref and {s0, s1} <= set(PAPER_SCALES) else np.nan
            rows.append({"claim": f"success grows from {s0:g} m to {s1:g} m", "better": f"{method} at {s1:g} m",
                         "worse": f"{method} at {s0:g} m", "pairs": n, "ours": 100 * m, "lo": 100 * lo, "hi": 100 * hi,
                         "paper": paper, "verdict": _verdict(paper, lo, hi)})
    out = pd.DataFrame(rows, columns=["claim", "better", "worse", "pairs", "ours", "lo", "hi", "paper", "verdict"]).round(1)
    return out.astype({"pairs": int})


def section(doc: Document, parts: list, out: Path, formats: set, replay: bool, notes: list) -> None:
    runs = pd.concat([run_rows(p.runs) for p in parts], ignore_index=True)
    table = success_table(runs)
    tdir = out / "tables"
    write_table(tdir, "indirect", table, formats)
    tab3 = wide(table)
    if formats & {"md", "html"}:
        atomic_text(tdir / "indirect_table3.md", markdown_table(tab3))
    doc.heading(2, f"Indirect search with secondary objects ({len(runs)} searches)")
    doc.para("Success rate (%) per method and view scale (the farthest the main object can be detected), with its "
             f"{interval_text(table)}; in brackets the paper's Table 3 (Loncomilla et al. 2018; their rooms, simulator "
             "and detection table, so compare shapes, not values).")
    doc.table(tab3)
    diff, mad = difference_table(table)
    claims = claims_table(runs)
    write_table(tdir, "indirect_claims", claims, formats)
    if len(diff):
        doc.heading(3, "Ours minus the paper's Table 3 (percentage points)")
        doc.para(f"Mean absolute difference over the {diff.notna().sum().sum()} cells the paper has: {mad:.1f} points.")
        doc.table(diff)
    if len(claims):
        doc.heading(3, "The paper's claims, paired")
        doc.para("Each claim as a difference of success rate (points; ours: the mean over the searches both sides ran "
                 "from the same start, room and repeat, with its 95% bootstrap interval over rooms; the paper's: the "
                 "mean of its Table 3 differences over the same view scales). Reproduced: our interval excludes 0 on "
                 "the paper's side; contradicted: on the other side; inside the noise: it holds 0.")
        doc.table(claims.set_index(["claim", "better", "worse"]), fmt="{:.1f}")
    doc.heading(3, "Time to find (s, over the searches that found it) / SPL")
    doc.table(time_spl(table))
    img = image_formats(formats)
    if img:
        f = out / "figures" / "indirect_success.png"
        plot_success_by_scale(table, T.planner_order(table["planner"]), PAPER_TABLE3, PAPER_SCALES, f, img)
        doc.figure(f, "Success rate against the view scale, one panel per method: ours with the "
                      f"{interval_text(table)}, beside the paper's Table 3 (grey, dashed); n: searches per view scale")
        if replay:
            for part in parts:
                _replay(doc, part, run_rows(part.runs), out / "figures", notes, replay)


def _episode_of(task, scale: float, episode: int):
    """The episode a row names: its index in the task's episode set at ``scale``; for rows from
    before episodes (read as episode 0), the scale's first episode."""
    return next((e for e in task.episodes if e.index == episode and float(e.goal) == scale), None) or task.as_episode(scale)


def _replay(doc: Document, part, runs: pd.DataFrame, fdir: Path, notes: list, choice=True) -> None:
    """One search as a GIF of the probability map at its re-plans, from the frames ``semsearch run
    --frames`` recorded, else re-simulated (see :func:`replay_frames`):
    ``choice`` (the ``--replay`` run: planner, view scale, episode, seed), or by default the first
    search of ISCG-PN-SM (the paper's best; else the last method, not a language model's) at the
    smallest view scale."""
    loaded = part.loaded(notes, "The replay")
    if loaded is None or runs.empty:
        return
    ep = S.episodes(runs)
    scales = runs["goal"].astype(float)
    if choice is True:
        order = T.planner_order(runs["planner"])
        order = [lab for lab in order if (c := planner_named(lab)) is None or not c.service] or order  # never a model, by default
        label = next((lab for lab in order if (c := planner_named(lab)) is not None and c.replay), order[-1])
        sub = runs[(runs["planner"] == label) & (scales == scales.min())]
    else:
        try:
            scale = float(choice.goal)
        except ValueError:
            return
        sub = runs[(runs["planner"] == choice.planner) & (scales == scale) & (ep == choice.episode)
                   & (runs["seed"].astype(int) == choice.seed)]
    if sub.empty:
        return  # the run is in another folder of this report
    row = sub.assign(_ep=ep[sub.index]).sort_values(["_ep", "seed"]).iloc[0]
    label, scale, seed, episode = str(row["planner"]), float(row["goal"]), int(row["seed"]), int(ep[row.name])
    variant = row_variant(loaded, row)
    if variant is None:
        return
    ep_run = _episode_of(loaded.task, scale, episode)
    frames, how = replay_frames(part.folder, label, row["goal"], seed, episode,
                                lambda watch: loaded.task.run(variant, ep_run, seed, watch), failed=row["outcome"] == "error",
                                expect={"kind": "indirect"})
    room = loaded.task.grids[ep_run.room].room
    if not frames:
        return
    f = fdir / f"replay_{loaded.sc.name}_{stems(label, f'{scale:g}', seed, episode)[0]}.gif"
    animate_probability(room, loaded.task.spec.target, frames, f"{label}, view scale {scale:g} m, {room.name}", f)
    doc.figure(f, f"Replay of {label} at view scale {scale:g} m, episode {episode}, seed {seed} ({row['outcome']} after "
               f"{float(row['time_s']):.0f} s; frames {how}): the robot's probability map of A at each re-plan, its path (cyan), the secondary "
               "objects seen (squares), the goal (cross); A ringed in yellow")


def console(runs: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    table = success_table(run_rows(runs))
    return [(f"success rate (%) [{interval_text(table)}] (paper's Table 3)", wide(table).reset_index())]


def show(loaded, out: Path) -> None:
    t = loaded.task
    shown = min(20, len(t.grids))
    plot_rooms([g.room for g in t.grids[:shown]], f"{loaded.sc.name}: {len(t.grids)} rooms"
               f"{f' (the first {shown})' if shown < len(t.grids) else ''}; A ({t.spec.target}) vermillion, secondary "
               "objects coloured (tick: facing), start square (arrow: heading)", out)


register_section(Section("indirect", section, console, show, replays=True))
