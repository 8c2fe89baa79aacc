"""Where signs pay (issue 53, docs/where-signs-pay.md): the semantic gain (SPL under the true labels
minus SPL under shuffled labels, paired over episodes) and the share of the greedy-to-oracle_goal
SPL gap closed, per sign-reading planner, as functions of the door cameras' range and read
probability (interventions: the doors-v1 val floors run again with one sensor parameter changed)
and of the floor's size, its longest stretch of wall carrying signs, signs per metre of such wall, skipped and lettered shares, numbering
convention and predictability (the 800 val episodes binned by their floor's value). Every
interval is a 95% BCa bootstrap over episodes (a floor's start/goal problem).

The default level of each intervention (range 3 m, p_read 0.95) is the val rows themselves,
restricted to the episodes the other levels ran (the first ``--starts`` starts of each goal): all
levels of a factor are paired on the same episodes.

Usage:
  python benchmarks/where_signs_pay.py run --out OUT [--starts 1] [--workers 2] [--readers wall_numbers]
  python benchmarks/where_signs_pay.py run --out OUT2 --readers numbering --no-references
  python benchmarks/where_signs_pay.py tables --val TRUE --shuffled SHUFFLED --levels OUT [OUT2] \\
      [--figures docs/figures/where-signs-pay] [--md FILE]

TRUE and SHUFFLED are bench folders of doors-v1 val (`semsearch bench run doors-v1 --planner
greedy --planner oracle_goal --planner wall_numbers --planner numbering --out TRUE`, and the
sign readers again with `--numbering shuffled --out SHUFFLED`).
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import yaml  # noqa: E402
from output import emit  # noqa: E402

from semsearch_cli import api, bench  # noqa: E402
from semsearch_cli.bench.board import gap_closed, load, paired_diff  # noqa: E402
from semsearch_cli.bench.run import materialise  # noqa: E402
from semsearch_cli.config.scenario import with_param  # noqa: E402
from semsearch_cli.metrics import outside_the_run  # noqa: E402
from semsearch_cli.runner import BatchOptions, Loaded, read_runs  # noqa: E402

READERS = ("wall_numbers", "numbering")  # the sign-reading planners measured
REFERENCES = ("greedy", "oracle_goal")  # the gap's ends
# the interventions: (parameter, the split's own value, the values run again)
LEVELS = (("door_camera.range", 3.0, (6.0, 10.0)), ("door_camera.p_read", 0.95, (0.5, 0.8)))


# ----------------------------------------------------------------------------------------------
# run: the interventions


def _one(task: tuple) -> str:
    """One floor, numbering and parameter value: the floor materialised as the bench runs it,
    the parameter set, the first ``starts`` starts per goal kept, its planners run (resumable)."""
    out, param, value, numbering, fid, starts, planners = task
    sp = bench.open_split("doors-v1", "val")
    dest = out / f"{param}={value:g}" / numbering / fid
    scen = materialise(sp, sp.floor(fid), numbering, dest / "scenario")
    doc = with_param(yaml.safe_load(scen.read_text()), param, value, scen)
    eps_file = scen.parent / doc["episodes"]["file"]
    eps = pd.read_csv(eps_file, dtype=str, keep_default_na=False)
    eps.groupby("goal", sort=False).head(starts).to_csv(eps_file, index=False, lineterminator="\n")
    doc["planners"] = [{"name": p} for p in planners]
    scen.write_text(f"# doors-v1 val {fid}, {numbering}, {param}={value:g} (benchmarks/where_signs_pay.py)\n"
                    + yaml.safe_dump(doc, sort_keys=False))
    res = api.run(scen, BatchOptions(out=dest / "rows", workers=1), plots=False)
    return f"{param}={value:g} {numbering} {fid}: {len(res.runs)} runs"


def run(out: Path, starts: int, workers: int, readers: tuple[str, ...], references: bool) -> int:
    """The interventions into ``out``: ``readers`` under both numberings, and greedy and
    oracle_goal under the true one when ``references`` (a folder of its own per set of planners)."""
    sp = bench.open_split("doors-v1", "val")
    planners = {"true": (REFERENCES if references else ()) + readers, "shuffled": readers}
    tasks = [(out, param, v, numbering, f.id, starts, planners[numbering]) for param, _, values in LEVELS for v in values
             for numbering in ("true", "shuffled") for f in sp.floors]
    with mp.get_context("spawn").Pool(workers) as pool:
        for i, said in enumerate(pool.imap_unordered(_one, tasks), 1):
            print(f"{i}/{len(tasks)} {said}", flush=True)
    return 0


# ----------------------------------------------------------------------------------------------
# tables: the statistics per factor level


def floor_factors() -> pd.DataFrame:
    """Each val floor's observed factors: free area (m^2), its longest stretch of wall carrying
    signs (m; the ground truth's walls), signs per metre of the walls that carry signs, the
    recipe's skipped and lettered shares, its convention and predictability."""
    sp = bench.open_split("doors-v1", "val")
    out = []
    for f in sp.floors:
        w = Loaded.load(f.scenario).task.world
        s = w.signs
        wall = s.walls()
        spacing = float(f.recipe.get("spacing", 2.5))
        lengths = []
        for k in np.unique(wall):  # along the wall as Signs.walls() measures it: its first sign's facing
            m = wall == k
            f0 = s.facing[m][0]
            lengths.append(np.ptp(-s.x[m] * np.sin(f0) + s.y[m] * np.cos(f0)) + spacing)
        lengths = np.array(lengths)
        r = f.recipe
        out.append({"floor": f.id, "free area (m²)": float(w.free.sum()) * w.frame.res ** 2,
                    "longest signed wall (m)": float(lengths.max()),
                    "signs per metre of signed wall": len(s) / float(lengths.sum()),
                    "skipped share": float(r["skip"]), "lettered share": float(r["letters"]),
                    "convention": str(r["numbering"]), "predictability": float(r["predictability"]["value"])})
    return pd.DataFrame(out)


def _mean(d: pd.DataFrame) -> float:
    """Mean SPL over episodes (each episode's repeats averaged), as the board's point estimate."""
    return float(d.groupby("unit")["spl"].mean().mean())


def stats(rows: pd.DataFrame, units, readers=READERS) -> list[dict]:
    """Per sign reader, on ``units`` (episodes): SPL, semantic gain, SPL and distance gap closed."""
    d = rows[rows["unit"].isin(units)]
    pick = {(p, n): d[(d["planner"] == p) & (d["numbering"] == n)] for p in REFERENCES + READERS for n in ("true", "shuffled")}
    res = []
    for p in readers:  # every column over the episodes all four sides ran
        sides = (pick[("greedy", "true")], pick[("oracle_goal", "true")], pick[(p, "true")], pick[(p, "shuffled")])
        common = set.intersection(*(set(x["unit"]) for x in sides))
        g, o, t, s = (x[x["unit"].isin(common)] for x in sides)
        res.append({"planner": p, "episodes": len(common),
                    "greedy SPL": _mean(g), "oracle SPL": _mean(o), "SPL": _mean(t),
                    "semantic gain": paired_diff(t, s, "spl")[:3],
                    "SPL gap closed": gap_closed(t, g, o, "spl")[:3],
                    "distance gap closed": gap_closed(t, g, o, "distance_m")[:3]})
    return res


def _bins(values: pd.Series, name: str) -> tuple[pd.Series, list[str]]:
    """Each floor's bin and the bins in order: thirds of the floors by value; the lettered share
    as none and the lettered floors' halves; the convention as itself."""
    if name == "convention":  # the schemes grouped: few val floors have any one parity scheme
        other = sorted(set(values) - {"loop", "random"})
        lab = f"parity, {len(other)} schemes"
        return values.map(lambda c: c if c in ("loop", "random") else lab), ["loop", lab, "random"]
    fmt = "{:.0f}" if values.max() > 20 else "{:.2f}"
    if name == "lettered share":  # a third of the floors have none
        has = values > 0
        med = values[has].median()
        lab = ["none", f"(0, {fmt.format(med)}]", f"> {fmt.format(med)}"]
        return pd.Series(np.where(~has, lab[0], np.where(values <= med, lab[1], lab[2])), values.index), lab
    if values.isna().any():
        raise ValueError(f"{name}: floors {', '.join(values.index[values.isna()])} have no value")
    q = values.quantile([1 / 3, 2 / 3]).to_numpy()
    lab = [f"≤ {fmt.format(q[0])}", f"{fmt.format(q[0])}–{fmt.format(q[1])}", f"> {fmt.format(q[1])}"]
    return pd.Series(np.select([values <= q[0], values <= q[1]], lab[:2], lab[2]), values.index), lab


def _fmt(ci, pct=False) -> str:
    m, lo, hi = ci
    if not np.isfinite(m):
        return ""
    f = (lambda x: f"{x:+.1%}") if pct else (lambda x: f"{x:+.3f}")
    return f"{f(m)} [{f(lo)}, {f(hi)}]" if np.isfinite(lo) else f(m)


def table(name: str, levels: list[tuple[str, list[dict]]]) -> str:
    head = "| " + name + " | planner | episodes | greedy SPL | oracle SPL | SPL | semantic gain (SPL) | SPL gap closed | distance gap closed |"
    lines = [head, "|" + "---|" * 9]
    for lev, res in levels:
        for r in res:
            lines.append(f"| {lev} | {r['planner']} | {r['episodes']} | {r['greedy SPL']:.3f} | {r['oracle SPL']:.3f} | "
                         f"{r['SPL']:.3f} | {_fmt(r['semantic gain'])} | {_fmt(r['SPL gap closed'], True)} | "
                         f"{_fmt(r['distance gap closed'], True)} |")
    return "\n".join(lines)


def figure(name: str, levels: list[tuple[str, list[dict]]], path: Path) -> None:
    """Three panels: the semantic gain, the SPL gap closed and the distance gap closed by level,
    one series per planner, 95% intervals as bars; a numeric factor (an intervention) on a
    numeric axis."""
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4), constrained_layout=True)
    try:
        x = np.array([float(lev) for lev, _ in levels])
        numeric = True
    except ValueError:
        x, numeric = np.arange(len(levels), dtype=float), False
    readers = [r["planner"] for r in levels[0][1]]
    panels = (("semantic gain", 1.0, "semantic gain (SPL, true − shuffled)"),
              ("SPL gap closed", 100.0, "SPL gap closed (%)"), ("distance gap closed", 100.0, "distance gap closed (%)"))
    for k, p in enumerate(readers):
        off = 0.0 if len(readers) == 1 else (k - (len(readers) - 1) / 2) * (0.02 * np.ptp(x) if numeric else 0.12)
        for ax, (key, scale, _) in zip(axes, panels):
            v = np.array([[next(r for r in res if r["planner"] == p)[key][j] for j in range(3)] for _, res in levels]) * scale
            err = [np.fmax(v[:, 0] - v[:, 1], 0), np.fmax(v[:, 2] - v[:, 0], 0)]  # a BCa bound past its point: no bar that side
            ax.errorbar(x + off, v[:, 0], yerr=err, fmt="o" if name == "convention" else "o-", capsize=3, label=p)
    for ax, (_, _, lab) in zip(axes, panels):
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_xticks(x, [lev for lev, _ in levels], rotation=0 if numeric else 15, fontsize=8)
        ax.set_xlabel(name)
        ax.set_ylabel(lab)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"doors-v1 val: where signs pay, by {name}; 95% BCa intervals over episodes", fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def level_rows(levels_dirs: list[Path], param: str, value: float) -> pd.DataFrame:
    frames = []
    for f in sorted(f for d in levels_dirs for f in (d / f"{param}={value:g}").glob("*/*/rows/runs.csv")):
        r = read_runs(f)
        r = r[(r["stage"] == "") & ~outside_the_run(r)]  # as the board: a run that failed for a cause outside it is no run
        numbering, fid = f.parts[-4], f.parts[-3]
        scen = f.parent.parent / "scenario"
        kept = pd.read_csv(scen / yaml.safe_load((scen / "scenario.yaml").read_text())["episodes"]["file"])["episode"]
        orig = kept.to_numpy()[r["episode"].to_numpy(int)]  # the runner numbers the kept episodes 0, 1, ...: the split's numbers
        frames.append(r.assign(numbering=numbering, floor=fid, unit=[f"{fid}/{e}" for e in orig]))
    if not frames:
        raise SystemExit(f"{', '.join(map(str, levels_dirs))}: no rows of {param}={value:g} (run `where_signs_pay.py run` first)")
    return pd.concat(frames, ignore_index=True)


def tables(val: Path, shuffled: Path, levels_dirs: list[Path] | None, figures: Path | None, md: Path | None) -> int:
    rows = load([val, shuffled])
    rows = rows[~rows["unavailable"]]
    out = [f"doors-v1 val: {rows['unit'].nunique()} episodes; sign readers {', '.join(READERS)}; "
           "[95% BCa over episodes]"]
    slug = {}
    if levels_dirs:
        for param, default, values in LEVELS:
            extra = {v: level_rows(levels_dirs, param, v) for v in values}
            ran = set.intersection(*({(p, n) for p, n in zip(e["planner"], e["numbering"])} for e in extra.values()))
            readers = tuple(p for p in READERS if {(p, "true"), (p, "shuffled")} <= ran)
            units = set.intersection(*(set(e["unit"]) for e in extra.values()))
            levels = ([(f"{default:g}", stats(rows, units, readers))]
                      + [(f"{v:g}", stats(e, units, readers)) for v, e in extra.items()])
            levels.sort(key=lambda t: float(t[0]))
            name = {"door_camera.range": "door camera range (m)", "door_camera.p_read": "p_read"}[param]
            out += ["", f"### {name}", "", table(name, levels)]
            slug[name] = levels
    ff = floor_factors()
    unit_floor = rows.drop_duplicates("unit").set_index("unit")["floor"].astype(str)
    for name in [c for c in ff.columns if c != "floor"]:
        b, order = _bins(ff.set_index("floor")[name], name)
        levels = []
        for lev in order:
            floors = set(b.index[b == lev])
            levels.append((f"{lev} ({len(floors)} floors)", stats(rows, set(unit_floor.index[unit_floor.isin(floors)]))))
        out += ["", f"### {name}", "", table(name, levels)]
        slug[name] = levels
    if figures is not None:
        for name, levels in slug.items():
            fname = name.split(" (")[0].replace(" ", "-").replace("_", "-").replace(".", "") + ".png"
            figure(name, levels, figures / fname)
            out.append(f"\n(figure: {figures / fname})")
    return emit("\n".join(out), md)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", type=Path, required=True)
    r.add_argument("--starts", type=int, default=1)
    r.add_argument("--workers", type=int, default=2)
    r.add_argument("--readers", default="wall_numbers", help="sign readers run at each level, comma-separated")
    r.add_argument("--no-references", action="store_true", help="leave greedy and oracle_goal out (another folder has them)")
    t = sub.add_parser("tables")
    t.add_argument("--val", type=Path, required=True)
    t.add_argument("--shuffled", type=Path, required=True)
    t.add_argument("--levels", type=Path, nargs="+", help="the folders of `run` (one per set of planners)")
    t.add_argument("--figures", type=Path)
    t.add_argument("--md", type=Path)
    a = ap.parse_args()
    if a.cmd == "run":
        return run(a.out, a.starts, a.workers, tuple(a.readers.split(",")), not a.no_references)
    return tables(a.val, a.shuffled, a.levels, a.figures, a.md)


if __name__ == "__main__":
    sys.exit(main())
