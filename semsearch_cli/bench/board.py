"""``semsearch bench board``: the results page of one or more bench folders (HTML and Markdown).

Per suite, split and simulator engine (rows of two engines are never paired or pooled), every
planner's success, SPL, SoftSPL and mean distance over the episodes,
each with a 95% interval over episodes (the unit: a floor's episode, its repeats averaged); the
paired difference in SPL to ``nsos[alpha=0.9]`` on the same episodes; the semantic gain (SPL under
the true numbering minus SPL under shuffled labels, paired episode by episode) overall and per
numbering convention, and the other numberings' differences; cost columns when the rows carry
them; whether the folder was verified (``semsearch verify`` wrote its verdict beside the rows
and the rows have not changed since); and whether the results are official (a test split's hash
is the published one). Intervals: success, Wilson's interval widened for clustered runs
(:func:`~semsearch_cli.report.stats.rate_ci`); means and differences, the BCa bootstrap over
episodes (:func:`~semsearch_cli.report.stats.mean_ci`).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import kendalltau, spearmanr

from ..errors import ScenarioError
from ..files import atomic_text, output_folder
from ..metrics import COST_COLUMNS, FALLBACK_FLAG, PRIVILEGED, fallback_shares, outside_the_run
from ..planners.base import planner_named
from ..report.document import Document
from ..report.figures.bench import GAIN_FLOOR, plot_gain_vs_predictability
from ..report.indirect import PAPER_SCALES, PAPER_TABLE3, claims_table
from ..report.stats import mean_ci, rate_ci, ratio_ci
from ..runner import read_runs
from .run import BENCH_FILE, is_bench, read_bench
from .suites import is_official

BASELINES = {"doors": "nsos[alpha=0.9]", "objects": "lsos"}  # each kind's planner of the thesis, the board's reference
# per kind, the gap every planner's share is measured on: door search's from nearest-frontier to
# the planner told where the goal is (planners/doors/oracle.py)
GAPS = {"doors": ("greedy", "oracle_goal")}
VERIFY_FILE = "verify.json"


def rows_digest(folder: Path, with_meta: bool = True) -> str:
    """A digest of a bench folder's bench.json (its suite, split and suite hash: the one place a
    folder keeps its hash) and rows (every floor's runs.csv, in floor order): what a verdict was
    reached on. ``with_meta`` False: the rows alone, as verify.json before 0.4.0 digested them."""
    h = hashlib.sha256()
    meta = Path(folder) / "bench.json"
    if with_meta and meta.is_file():
        h.update(b"bench.json")
        h.update(meta.read_bytes())
    for f in sorted(Path(folder).glob("*/runs.csv")):
        h.update(f.parent.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def write_verdict(folder: Path, runs: int, verified: int, failed: int, unfinished: int = 0) -> None:
    """Record a verification of a bench folder beside its rows (``verify.json``): its counts, and
    the digest of bench.json and the rows it was reached on (the suite hash is bench.json's, kept
    there once); ``unfinished``: its error and timeout runs, which keep no record and claim no result."""
    atomic_text(Path(folder) / VERIFY_FILE, json.dumps({"runs": runs, "verified": verified, "failed": failed,
                                                        "unfinished": unfinished, "rows": rows_digest(folder)},
                                                       indent=1) + "\n")


MAX_VERIFY_BYTES = 1_000_000  # a verify.json semsearch writes is a few hundred bytes


def verdict_of(folder: Path, split_hash: str) -> str:
    """How a folder stands: ``verified`` (every run replayed, or did not finish and claims
    nothing, on these rows), ``N failed``, ``changed since verified`` (rows written since the
    verification), or ``not verified`` (no verify.json). A verify.json that is not the JSON object
    ``semsearch verify`` writes is a :class:`ScenarioError` naming it."""
    f = Path(folder) / VERIFY_FILE
    if not f.exists():
        return "not verified"
    bad = "not a verify.json semsearch wrote; run `semsearch verify` on the folder again"
    try:
        if f.stat().st_size > MAX_VERIFY_BYTES:
            raise ScenarioError(str(f), "", f"{bad} (larger than {MAX_VERIFY_BYTES:,} bytes)")
        v = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise ScenarioError(str(f), "", f"{bad} ({type(exc).__name__}: {str(exc)[:80]})") from None
    counts = ("runs", "verified", "failed")
    if not isinstance(v, dict) or not all(isinstance(v.get(k), int) and not isinstance(v.get(k), bool) for k in counts):
        raise ScenarioError(str(f), "", f"{bad} (not an object of its counts: runs, verified, failed)")
    if "hash" in v:  # written before 0.4.0: the suite hash copied in, the rows digested alone
        stale = v["hash"] != split_hash or v.get("rows") != rows_digest(folder, with_meta=False)
    else:
        stale = v.get("rows") != rows_digest(folder)
    if stale:
        return "changed since verified"
    unfinished = v.get("unfinished", 0) if isinstance(v.get("unfinished", 0), int) else 0
    return "verified" if v["failed"] == 0 and v["verified"] + unfinished == v["runs"] else f"{v['failed']} failed"


def load(folders) -> pd.DataFrame:
    """Every row of the bench folders' floors (the floors bench.json lists; a row must name its
    folder's floor and the folder's numbering), with ``unit`` (floor/episode), ``verdict``,
    ``official`` (its suite hash is the published one) and each floor's convention and
    predictability (bench.json, written at run time: the board needs no split at hand), and what a
    complete folder holds: ``split_episodes`` and ``split_runs`` (episodes x repeats; NaN when
    bench.json is older than the count, then its ``partial`` is taken as given: ``partial_meta``).
    Rows of runs that failed for a cause outside them (``unavailable:``, run again on resume)
    are kept with ``unavailable`` True; the tables leave them out of every statistic."""
    frames = []
    seen: dict[str, Path] = {}  # each folder's real path: the same folder given twice
    for folder in folders:
        folder = Path(folder)
        real = os.path.realpath(folder)
        if real in seen:
            raise ScenarioError(str(folder), "", f"is the folder {seen[real]} given again: the board counts each run once; "
                                "give each bench folder once")
        seen[real] = folder
        if not is_bench(folder):
            raise ScenarioError(str(folder), "", f"no {BENCH_FILE} here: give folders written by `semsearch bench run`")
        meta = read_bench(folder)
        floors = meta.get("floors")
        if not isinstance(floors, dict):
            raise ScenarioError(str(folder / BENCH_FILE), "floors", "lists no floors: written by an older semsearch; run the "
                                "bench into a fresh folder")
        verdict = verdict_of(folder, meta["hash"])
        counts = [(info or {}).get("episodes") for info in floors.values()]
        episodes = float(sum(counts)) if counts and all(isinstance(c, int) for c in counts) else np.nan
        for fid, info in floors.items():
            f = folder / fid / "runs.csv"
            if not f.is_file():
                continue
            r = read_runs(f)
            lacking = [c for c in ("suite", "split", "suite_hash", "numbering", "floor") if c not in r.columns]
            if lacking:
                raise ScenarioError(str(f), lacking[0], f"has no column {', '.join(lacking)}: not the rows of a bench run")
            r = r[(r["stage"] == "") & (r["floor"].astype(str) == fid) & (r["numbering"].astype(str) == meta["numbering"])]
            if not len(r):
                continue
            official = r["suite_hash"].astype(str).map(lambda h: is_official(str(meta["suite"]), str(meta["split"]), h))
            r = r.assign(verdict=verdict, official=official.astype(bool), folder=str(folder),
                         unit=r["floor"].astype(str) + "/" + r["episode"].astype(str),
                         convention=str((info or {}).get("convention", fid)),
                         predictability=float((info or {}).get("predictability") or np.nan),
                         split_episodes=episodes, split_runs=episodes * int(meta.get("repeats", 1)),
                         partial_meta=bool(meta.get("partial", False)),
                         unavailable=outside_the_run(r))
            frames.append(r)
    if not frames:
        raise ScenarioError(str(folders[0]), "", "the bench folders hold no rows")
    rows = pd.concat(frames, ignore_index=True)
    if PRIVILEGED in rows.columns:  # a folder that ran no privileged planner has no such column: its rows were told nothing
        rows[PRIVILEGED] = rows[PRIVILEGED].fillna("")
    _once(rows)
    return rows


RUN_KEY = ["suite", "split", "suite_hash", "engine", "numbering", "planner", "floor", "goal", "episode", "seed"]


def _once(rows: pd.DataFrame) -> None:
    """Refuse rows that hold one run twice (two folders, a copy of one, or a row repeated): the
    board would count it twice, and its intervals narrow as if there were twice the episodes. A
    :class:`ScenarioError` naming both folders (or the one)."""
    key = rows[RUN_KEY].astype(str).agg("|".join, axis=1)
    twice = key.duplicated(keep=False)
    if not twice.any():
        return
    first = key[twice].iloc[0]
    where = list(dict.fromkeys(rows.loc[key == first, "folder"]))
    n = int(key[twice].nunique())
    if len(where) > 1:
        raise ScenarioError(where[1], "", f"holds {n} of the runs {where[0]} holds too (the same suite, split, hash, "
                            f"numbering, planner, floor, episode and repeat; {where[0]} and {where[1]}): the board counts each run "
                            "once; give one of the two folders (a copy of a folder is the same runs)")
    raise ScenarioError(where[0], "", f"holds {n} run(s) twice (one planner, floor, episode and repeat in two rows): the "
                        "board counts each run once; `semsearch verify` names them")


def _ci(m, lo, hi, fmt="{:.3f}") -> str:
    if not np.isfinite(m):
        return ""
    return fmt.format(m) + ("" if not (np.isfinite(lo) and np.isfinite(hi)) else f" [{fmt.format(lo)}, {fmt.format(hi)}]")


def paired_diff(a: pd.DataFrame, b: pd.DataFrame, value: str = "spl") -> tuple[float, float, float, int]:
    """Mean over shared episodes of (a - b) in ``value`` (each side's repeats averaged per
    episode), its 95% BCa interval over episodes, and the number of episodes paired."""
    ma = a.groupby("unit")[value].mean()
    mb = b.groupby("unit")[value].mean()
    common = ma.index.intersection(mb.index)
    d = (ma[common] - mb[common]).to_numpy(float, copy=True)
    if not len(d):
        return np.nan, np.nan, np.nan, 0
    d[np.abs(d) <= GAIN_FLOOR] = 0.0  # float noise between two equal SPLs is no difference (GAIN_FLOOR)
    m, lo, hi = (0.0 if np.isfinite(x) and abs(x) <= GAIN_FLOOR else x for x in mean_ci(d, np.arange(len(d))))
    return m, lo, hi, len(d)


def completeness(d: pd.DataFrame) -> tuple[bool, str]:
    """Whether one planner's rows of the true numbering (``d``, unavailable runs left out) hold
    every run of the split, and what the board says when they do not."""
    want, eps = float(d["split_runs"].max()), float(d["split_episodes"].max())
    if not np.isfinite(want):  # bench.json older than the count: as it said
        return (not d["partial_meta"].any()), "partial (bench.json)"
    runs, units = len(d.drop_duplicates(["unit", "seed"])), d["unit"].nunique()
    return runs >= want, f"partial: {units} of {eps:.0f} episodes, {runs} of {want:.0f} runs"


def fallback_note(d: pd.DataFrame) -> str:
    """``, 12.3% of decisions fell back`` when more than FALLBACK_FLAG of a planner's decisions did."""
    for _, n, asked in fallback_shares(d):
        if asked and n / asked > FALLBACK_FLAG:
            return f", {n / asked:.1%} of decisions fell back"
    return ""


def told(rows: pd.DataFrame, lab: str) -> str:
    """What planner ``lab`` was told that a robot is not: its rows' ``privileged`` column, else its
    class's (when registered in this process); "" for a planner that sees only what a robot senses."""
    if PRIVILEGED in rows.columns:
        said = next((v for v in rows.loc[rows["planner"] == lab, PRIVILEGED].astype(str) if v), "")
        if said:
            return said
    cls = planner_named(lab)
    return getattr(cls, "privileged", "") if cls is not None else ""


def gap_closed(d: pd.DataFrame, low: pd.DataFrame, high: pd.DataFrame, value: str) -> tuple[float, float, float, int]:
    """The share of the gap from ``low`` (greedy) to ``high`` (oracle_goal) in ``value`` that the
    planner of rows ``d`` closes, over the episodes all three ran (each side's repeats averaged per
    episode): ``sum(d - low) / sum(high - low)``, its 95% BCa interval over episodes (the three
    resampled together) and the number of episodes."""
    m = [x.groupby("unit")[value].mean() for x in (d, low, high)]
    common = m[0].index.intersection(m[1].index).intersection(m[2].index)
    if not len(common):
        return np.nan, np.nan, np.nan, 0
    p, g, o = (x[common].to_numpy(float) for x in m)
    return (*(x + 0.0 for x in ratio_ci(p - g, o - g)), len(common))  # + 0.0: no -0.0% on the board


def tables(rows: pd.DataFrame) -> dict:
    """The board's tables of one suite and split (keys: planners, references (the privileged
    planners, never ranked with the others), conventions, numberings, floors)."""
    kind = str(rows["kind"].iloc[0])
    planners = list(dict.fromkeys(rows.loc[rows["numbering"] == "true", "planner"]))  # a planner all of whose runs could not run too
    gone = rows[rows["unavailable"]] if "unavailable" in rows.columns else rows.iloc[:0]
    rows = rows[~rows["unavailable"]] if "unavailable" in rows.columns else rows
    true = rows[rows["numbering"] == "true"]
    baseline = BASELINES.get(kind, "")
    out = []
    for lab in planners:
        d = true[true["planner"] == lab]
        if not len(d):  # every run of it could not run (a model that did not answer): no statistic, said so
            lost = int(((gone["planner"] == lab) & (gone["numbering"] == "true")).sum())
            out.append({"planner": lab, "episodes": "0", "runs": 0,
                        "verified": f"{lost} run(s) unavailable (left out; the same bench run runs them again)",
                        "official": "no (no run of it could run)"})
            continue
        s, slo, shi = rate_ci(d["success"].to_numpy(float), d["unit"].to_numpy())
        complete, why = completeness(d)
        eps = float(d["split_episodes"].max())
        row = {"planner": lab, "episodes": f"{d['unit'].nunique()}" + (f" of {eps:.0f}" if np.isfinite(eps) else ""),
               "runs": len(d),
               "success": _ci(s, slo, shi), "SPL": _ci(*mean_ci(d["spl"].to_numpy(float), d["unit"].to_numpy())),
               "SoftSPL": _ci(*mean_ci(d["soft_spl"].to_numpy(float), d["unit"].to_numpy())),
               "distance m": _ci(*mean_ci(d["distance_m"].to_numpy(float), d["unit"].to_numpy()), fmt="{:.1f}")}
        base = true[true["planner"] == baseline]
        if lab != baseline and len(base):
            m, lo, hi, n = paired_diff(d, base)
            row[f"SPL - {baseline}"] = _ci(m, lo, hi) + (f" (n={n})" if n else "")
        else:
            row[f"SPL - {baseline}"] = ""
        gap = GAPS.get(kind, ())
        low, high = (true[true["planner"] == g] for g in gap) if gap else (true.iloc[:0], true.iloc[:0])
        if len(low) and len(high) and lab not in gap:
            for value, col in (("spl", "SPL gap closed"), ("distance_m", "distance gap closed")):
                m, lo, hi, n = gap_closed(d, low, high, value)
                row[col] = _ci(m, lo, hi, fmt="{:.1%}") + (f" (n={n})" if n else "")
        sh = rows[(rows["numbering"] == "shuffled") & (rows["planner"] == lab)]
        m, lo, hi, n = paired_diff(d, sh) if len(sh) else (np.nan, np.nan, np.nan, 0)
        row["semantic gain"] = _ci(m, lo, hi) + (f" (n={n})" if n else "")
        row["told"] = told(rows, lab)
        cls = planner_named(lab)
        tuned = getattr(cls, "tuned_on", "") if cls is not None else ""
        split = f"{d['suite'].iloc[0]} {d['split'].iloc[0]}"
        row["tuned on"] = (tuned + (" -- TUNED ON THIS SPLIT: not held out" if tuned.startswith(split) else "")) if tuned else \
            ("not known (a planner not registered in this process)" if cls is None else "none")
        for c in COST_COLUMNS:  # what a planner that pays for its decisions reports (a language model): summed
            v = pd.to_numeric(d[c], errors="coerce") if c in d.columns else pd.Series(dtype=float)
            if v.notna().any():
                row[c] = f"{v.sum():.1f}" if c == "llm_s" else f"{int(v.sum()):,}"
                if c == "llm_calls":
                    row["calls per run"] = f"{v.mean():.1f}"
        for _, n, asked in fallback_shares(d):  # a planner with a fallback: the share of its decisions that took it
            row["fell back"] = f"{n / asked:.1%} of {asked:,}" if asked else "0"
        lost = int((gone["planner"] == lab).sum()) if len(gone) else 0
        row["verified"] = ", ".join(sorted(set(d["verdict"]))) + fallback_note(d) + \
            (f", {lost} run(s) unavailable (left out; the same bench run runs them again)" if lost else "")
        row["official"] = "yes" if d["official"].all() and complete else "no" + ("" if complete else f" ({why})")
        if row["told"]:  # a reference is never an official competitor, whatever its hash
            row["official"] = "no (a privileged reference)" + ("" if complete else f"; {why}")
        out.append(row)
    every = pd.DataFrame(out)
    privileged = every["told"].fillna("").astype(str) != "" if "told" in every.columns else pd.Series(False, every.index)

    def shown(df):
        return df.loc[:, [c for c in df.columns if (df[c].fillna("").astype(str) != "").any()]]

    planners_df = shown(every[~privileged].drop(columns="told", errors="ignore"))
    references = shown(every[privileged])
    conv, numb, floors = [], [], []
    for lab in planners:
        d = true[true["planner"] == lab]
        sh = rows[(rows["numbering"] == "shuffled") & (rows["planner"] == lab)]
        if len(sh):
            row = {"planner": lab}
            for c in sorted(set(d["convention"])):
                m, lo, hi, n = paired_diff(d[d["convention"] == c], sh)
                row[c] = _ci(m, lo, hi) + (f" (n={n})" if n else "")
            conv.append(row)
            for fid, g in d.groupby("floor"):
                m, _, _, n = paired_diff(g, sh)
                if n:
                    floors.append({"planner": lab, "floor": fid, "convention": g["convention"].iloc[0],
                                   "predictability": float(g["predictability"].iloc[0]), "gain": m, "episodes": n})
        row = {"planner": lab}
        for how in ("shuffled", "parity-flipped", "reversed"):
            other = rows[(rows["numbering"] == how) & (rows["planner"] == lab)]
            m, lo, hi, n = paired_diff(d, other) if len(other) else (np.nan, np.nan, np.nan, 0)
            row[f"true - {how}"] = _ci(m, lo, hi) + (f" (n={n})" if n else "")
        if any(row[k] for k in row if k != "planner"):
            numb.append(row)
    return {"planners": planners_df, "references": references, "conventions": pd.DataFrame(conv), "numberings": pd.DataFrame(numb),
            "floors": pd.DataFrame(floors)}


INDIRECT_BUDGETS = (60.0, 300.0)  # s: the two budgets every indirect claim is judged at


def times_to_find(d: pd.DataFrame) -> np.ndarray:
    """Each search's simulated time to find the target (s), infinite when it did not."""
    return np.where(d["success"].to_numpy(float) > 0, d["time_s"].to_numpy(float), np.inf)


def uis_budgets(true: pd.DataFrame) -> dict:
    """Per view scale, the budget (s) calibrated on UIS alone: the least time within which UIS's
    share of searches that found the target reaches the paper's UIS rate at that scale (Table 3);
    NaN where UIS never reaches it within the searches' time limit."""
    out = {}
    uis = true[true["method"] == "UIS"]
    for s in PAPER_SCALES:
        t = np.sort(times_to_find(uis[uis["scale"] == s]))
        p = PAPER_TABLE3["UIS"][PAPER_SCALES.index(s)] / 100.0
        k = int(np.ceil(round(p * len(t), 9))) - 1  # round: 0.28 * 100 is 28.000000000000004
        out[s] = float(t[k]) if len(t) and 0 <= k < len(t) and np.isfinite(t[k]) else np.nan
    return out


def at_budget(d: pd.DataFrame, budget) -> pd.DataFrame:
    """``d`` with ``success`` redefined as found within ``budget`` s (a number, or a dict per view scale)."""
    b = d["scale"].map(budget) if isinstance(budget, dict) else budget
    return d.assign(success=(times_to_find(d) <= np.asarray(b, float)).astype(int))


def indirect_tables(rows: pd.DataFrame) -> dict:
    """The indirect suites' tables: success within each budget per method (95% interval clustered
    on rooms), the UIS calibration, the other methods at the calibrated budget beside the paper's
    Table 3 (their mean absolute difference and rank agreement), and the paper's claims at every
    budget."""
    rows = rows[~rows["unavailable"]] if "unavailable" in rows.columns else rows
    true = rows[rows["numbering"] == "true"].assign(method=lambda d: d["planner"].astype(str).str.split("[").str[0],
                                                     scale=lambda d: d["goal"].astype(float))
    budgets = uis_budgets(true) if (true["method"] == "UIS").any() else {}
    methods = []
    for lab, d in true.groupby("planner", sort=False):
        row = {"planner": lab, "searches": len(d), "rooms": d["room"].nunique()}
        for b in INDIRECT_BUDGETS:
            row[f"success within {b:g} s"] = _ci(*rate_ci(at_budget(d, b)["success"].to_numpy(float), d["room"].to_numpy()))
        if budgets:  # over the view scales where UIS reaches the paper's rate at all
            dc = d[d["scale"].map(lambda x: np.isfinite(budgets.get(x, np.nan)))]
            row["success within the UIS budget"] = _ci(*rate_ci(at_budget(dc, budgets)["success"].to_numpy(float),
                                                                 dc["room"].to_numpy())) if len(dc) else ""
        row["SPL"] = _ci(*mean_ci(d["spl"].to_numpy(float), d["room"].to_numpy()))
        complete, why = completeness(d)
        row["verified"] = ", ".join(sorted(set(d["verdict"]))) + fallback_note(d)
        row["official"] = "yes" if d["official"].all() and complete else "no" + ("" if complete else f" ({why})")
        methods.append(row)
    cal, cells = [], []
    if budgets:
        uis = true[true["method"] == "UIS"]
        for s in PAPER_SCALES:
            u = uis[uis["scale"] == s]
            cal.append({"view scale m": s, "paper's UIS %": PAPER_TABLE3["UIS"][PAPER_SCALES.index(s)],
                        "ours within 60 s %": round(100 * float((times_to_find(u) <= 60.0).mean()), 1) if len(u) else np.nan,
                        "ours within 5 min %": round(100 * float((times_to_find(u) <= 300.0).mean()), 1) if len(u) else np.nan,
                        "calibrated budget s": round(budgets[s], 1) if np.isfinite(budgets[s]) else np.nan})
        for (m, s), d in true[true["method"] != "UIS"].groupby(["method", "scale"]):
            if m in PAPER_TABLE3 and s in PAPER_SCALES and np.isfinite(budgets.get(s, np.nan)):
                cells.append({"method": m, "scale": s, "ours": 100 * float((times_to_find(d) <= budgets[s]).mean()),
                              "paper": PAPER_TABLE3[m][PAPER_SCALES.index(s)]})
    cells = pd.DataFrame(cells, columns=["method", "scale", "ours", "paper"])
    agreement = {}
    if len(cells) >= 3:
        agreement["cells"] = len(cells)
        agreement["mean absolute difference (points)"] = round(float((cells["ours"] - cells["paper"]).abs().mean()), 1)
        agreement["Spearman rho over the cells"] = round(float(spearmanr(cells["ours"], cells["paper"]).statistic), 3)
        taus = [kendalltau(g["ours"], g["paper"]).statistic for _, g in cells.groupby("scale") if len(g) >= 3]
        agreement["Kendall tau of the methods per view scale (mean)"] = round(float(np.nanmean(taus)), 3) if taus else np.nan
    calibrated = true[true["scale"].map(lambda x: np.isfinite(budgets.get(x, np.nan)))] if budgets else true.iloc[:0]
    claims = []
    for name, b, d in [*((f"within {x:g} s", x, true) for x in INDIRECT_BUDGETS),
                       *((("within the UIS budget", budgets, calibrated),) if len(calibrated) else ())]:
        c = claims_table(at_budget(d, b))
        if isinstance(b, dict):  # a budget per view scale: growth with the scale is the calibration's, not a finding
            c = c[~c["claim"].str.startswith("success grows")]
        claims.append(c.assign(budget=name))
    wide = cells.assign(cell=[f"{o:.0f} ({p})" for o, p in zip(cells["ours"], cells["paper"])]).pivot(
        index="method", columns="scale", values="cell") if len(cells) else pd.DataFrame()
    return {"methods": pd.DataFrame(methods), "calibration": pd.DataFrame(cal), "cells": wide,
            "agreement": agreement, "claims": pd.concat(claims, ignore_index=True) if claims else pd.DataFrame()}


def _indirect_section(doc: Document, g: pd.DataFrame) -> None:
    t = indirect_tables(g)
    doc.table(t["methods"].set_index("planner"), fmt="{}")
    if len(t["calibration"]):
        doc.heading(3, "A budget calibrated on UIS alone")
        doc.para("UIS, the one uninformed method, sets the budget: at each view scale, the least simulated time within "
                 "which our UIS finds the target in as many searches as the paper's UIS did (Table 3). That is a "
                 "calibration of the simulator's speed to theirs, not a result; the other ten methods at that budget are "
                 "out-of-sample predictions of the paper's numbers.")
        doc.table(t["calibration"].set_index("view scale m"), fmt="{}")
    if len(t["cells"]):
        doc.heading(3, "The other methods at the calibrated budget: ours (the paper's), success %")
        doc.table(t["cells"], fmt="{}")
        doc.para("; ".join(f"{k}: {v}" for k, v in t["agreement"].items()) + ".")
    if len(t["claims"]):
        doc.heading(3, "The paper's claims at each budget")
        doc.para("Each claim as a paired difference of success (points, over the searches both methods ran from the same "
                 "start; 95% interval a bootstrap over rooms) beside the paper's (the mean over the view scales); reproduced "
                 "when our interval excludes 0 on the paper's side.")
        c = t["claims"]
        verdicts = c.pivot_table(index=["claim", "better", "worse"], columns="budget", values="verdict", aggfunc="first",
                                 sort=False)
        doc.table(verdicts, fmt="{}")
        counts = c.groupby("budget", sort=False)["verdict"].value_counts().unstack(fill_value=0)
        doc.table(counts, fmt="{}")


def board(folders, out: str | Path) -> list[Path]:
    """Write ``out/index.html`` and ``out/board.md`` (and the figure) for the bench folders."""
    out = output_folder(out)
    rows = load(folders)
    doc = Document()
    doc.heading(1, "semsearch-bench results")
    doc.para("Per suite and split: each planner over the episodes of its true numbering; intervals are 95% over episodes "
             "(a floor's start/goal problem; its repeats averaged). Success: Wilson's interval widened for clustered runs; "
             "SPL, SoftSPL, distance and every difference: the BCa bootstrap over episodes. Differences are paired: the two "
             "sides ran the same episodes. Semantic gain: SPL under the floor's true numbering minus SPL under its labels "
             "shuffled among its signs. Click a column's header to sort.")
    written = []
    engines = sorted(set(rows["engine"]))
    if len(engines) > 1:
        doc.para(f"These folders hold rows of simulator engines {', '.join(map(str, engines))}: each engine's rows are a board "
                 "of their own, never paired or pooled with another engine's (docs/engines.md).")
    for (suite, split, hash_, engine), g in rows.groupby(["suite", "split", "suite_hash", "engine"], sort=False):
        doc.heading(2, f"{suite} {split}" + ("" if g["official"].all() else f" ({hash_[:16]})") + f", engine {engine}")
        eps = float(g["split_episodes"].max())
        done = g[~g["unavailable"] & (g["numbering"] == "true")]
        ran = set(g.loc[g["numbering"] == "true", "planner"])  # a planner none of whose runs could run is not whole either
        whole = [completeness(d)[0] for _, d in done.groupby("planner")] + [False] * len(ran - set(done["planner"]))
        official = ("not official (no published hash matches)" if not g["official"].all() else
                    "official (the published hash)" if whole and all(whole) else
                    "the published hash, but partial: a planner lacks runs of the split (a --limit run), so not official")
        doc.para(f"simulator engine {engine}; suite hash {hash_[:16]}; the split: {f'{eps:.0f} episodes' if np.isfinite(eps) else 'episodes unknown'} "
                 f"(each planner's own count in its row); numberings run: {', '.join(sorted(set(g['numbering'])))}; {official}")
        if (g["kind"] == "indirect").all():
            _indirect_section(doc, g)
            continue
        t = tables(g)
        if len(t["planners"]):
            doc.table(t["planners"].set_index("planner"), fmt="{}")
        if len(t["references"]):
            doc.heading(3, "Privileged references (told what a robot is not; never ranked with the planners above)")
            low, high = GAPS.get(str(g["kind"].iloc[0]), ("the baseline", "the ceiling"))
            doc.para("Each is told something a robot does not know (its told column): a ceiling or a bound on what reasoning "
                     "over the signs can buy, not a competitor. The planners' gap closed is their share of the gap from "
                     f"{low} to {high} (sum over the episodes all three ran of the planner's gain over {low}, over "
                     f"{high}'s), with its 95% BCa interval over episodes.")
            doc.table(t["references"].set_index("planner"), fmt="{}")
        if len(t["conventions"]):
            doc.heading(3, "Semantic gain per numbering convention (SPL, true minus shuffled)")
            doc.table(t["conventions"].set_index("planner"), fmt="{}")
        if len(t["numberings"]):
            doc.heading(3, "SPL under the true numbering minus under each permutation")
            doc.table(t["numberings"].set_index("planner"), fmt="{}")
        if len(t["floors"]) and t["floors"]["predictability"].notna().any():
            stem = f"{suite}_{split}_{hash_[:8]}" + ("" if engine == 1 else f"_engine{engine}")
            fig = out / f"gain_vs_predictability_{stem}.png"
            written += plot_gain_vs_predictability(t["floors"], fig)
            doc.figure(fig, f"{suite} {split}: each floor's semantic gain (mean SPL over its episodes, true minus shuffled) "
                       "against its predictability (docs/bench.md), marked by numbering convention, with the least-squares "
                       "line over the floors.")
            t["floors"].to_csv(out / f"floors_{stem}.csv", index=False)
            written.append(out / f"floors_{stem}.csv")
    atomic_text(out / "board.md", doc.markdown(out))
    atomic_text(out / "index.html", doc.html("semsearch-bench results", sortable=True))
    return [out / "index.html", out / "board.md", *written]
