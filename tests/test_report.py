"""Reports rebuilt from rows: statistics agree with pandas, half-finished files work."""

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.stats import wilcoxon
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.metrics import COLUMNS
from semsearch_cli.report import tables as T
from semsearch_cli.report.document import markdown_table
from semsearch_cli.runner import read_runs


def fixed_runs(n=6):
    rng = np.random.default_rng(4)
    rows = []
    for goal, shortest in ((54, 17.5), (124, 32.0)):
        for label, params, scale in (("greedy", "{}", 6.0), ("nsos[alpha=0.9]", '{"alpha": 0.9}', 3.0), ("bvp", "{}", 7.0)):
            for seed in range(n):
                d = round(float(shortest * scale * rng.uniform(0.6, 1.4)), 1)
                rows.append({"scenario": "s", "planner": label, "params": params, "goal": goal, "seed": seed,
                             "outcome": "found", "success": 1, "distance_m": d, "shortest_m": shortest,
                             "ratio": d / shortest, "spl": shortest / d, "steps": int(d * 10), "decisions": 5,
                             "navigator": "geodesic", "wall_s": 0.1})
    return pd.DataFrame(rows, columns=COLUMNS)


def test_statistics_match_pandas():
    runs = fixed_runs()
    five = T.five_statistics(runs)
    for (goal, lab), g in runs.groupby(["goal", "planner"]):
        d = g["distance_m"]
        for stat, want in (("median", d.median()), ("mean", d.mean()), ("std", d.std()), ("min", d.min()), ("max", d.max())):
            assert five.loc[("s", goal, stat), lab] == pytest.approx(want, abs=1e-3)
    pct = T.percent_of_optimal(runs)
    g = runs[(runs.goal == 54) & (runs.planner == "bvp")]
    assert pct.loc[("s", 54), "bvp"] == pytest.approx(100 * g["distance_m"].mean() / 17.5, abs=0.01)  # one start: both readings agree
    assert list(five.columns) == ["greedy", "bvp", "nsos[alpha=0.9]"]


def test_table_4_10_and_the_alpha_figure_show_one_ratio_the_mean_of_each_runs_own():
    """From two starts of shortest paths 10 m and 40 m, runs of 20 m and 40 m: the ratios are 2
    and 1, their mean 1.5 (150 %); the mean distance over the mean shortest path would be 30 / 25
    = 120 %. Table 4.10 and the summary's mean_ratio (which the alpha figure draws) both give 150."""
    rows = [{"scenario": "s", "planner": "greedy", "params": "{}", "goal": 7, "episode": e, "seed": 0, "outcome": "found",
             "success": 1, "distance_m": d, "shortest_m": sp, "ratio": d / sp, "spl": sp / d, "steps": 1, "decisions": 1,
             "navigator": "geodesic", "wall_s": 0.1} for e, d, sp in ((0, 20.0, 10.0), (1, 40.0, 40.0))]
    runs = pd.DataFrame(rows, columns=COLUMNS)
    assert T.percent_of_optimal(runs).loc[("s", 7), "greedy"] == 150.0
    assert T.summarise(runs)["mean_ratio"].tolist() == [1.5]


def test_significance_is_paired_on_shared_seeds():
    """Planners that ran the same (episode, seed) are compared pair by pair: Wilcoxon's
    signed-rank test on the differences, their mean, and the rank-biserial effect."""
    runs = fixed_runs()
    sig = T.significance(runs).set_index(["goal", "planner"])
    pick = lambda lab: runs[(runs.goal == 124) & (runs.planner == lab)].sort_values("seed")["distance_m"].to_numpy()  # noqa: E731
    d = pick("nsos[alpha=0.9]") - pick("greedy")
    row = sig.loc[(124, "nsos[alpha=0.9]")]
    assert row["test"] == "wilcoxon signed-rank, paired on repeats" and row["n_pairs"] == 6
    assert row["p_value"] == pytest.approx(wilcoxon(d).pvalue)
    assert row["mean_diff"] == pytest.approx(d.mean(), abs=1e-3) and row["effect_r"] < -0.5  # nsos travels less
    assert row["note"] == ""
    assert T.significance(fixed_runs(3))["note"].str.contains("too few").all()


def test_best_and_worst_are_marked():
    md = markdown_table(pd.DataFrame({"a": [1.0, 5.0], "b": [2.0, 3.0]}, index=pd.Index(["x", "y"], name="row")), mark_rows=True)
    assert "| x | **1.00** | _2.00_ |" in md and "| y | _5.00_ | **3.00** |" in md


def test_report_from_a_half_finished_runs_csv(demo_dir, tmp_path):
    out = tmp_path / "r"
    res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "2", "--goal", "452", "--workers", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert (out / "report.md").is_file() and (out / "report.html").is_file()  # run writes the report too
    text = (out / "runs.csv").read_text().splitlines()
    (out / "runs.csv").write_text("\n".join(text[:3]) + "\n" + text[3][:20])  # two rows and a torn one
    res = CliRunner().invoke(app, ["report", str(out), "--out", str(tmp_path / "rep"), "--no-replay"])
    assert res.exit_code == 0, res.output
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "; 2 rows from" in md and "Mann-Whitney" in md
    html = (tmp_path / "rep" / "report.html").read_text()
    assert "data:image/png;base64," in html  # figures inlined: the page stands alone
    t = pd.read_csv(tmp_path / "rep" / "tables" / "summary.csv")
    assert t["n"].sum() == 2


def test_report_with_replay_and_several_folders(demo_dir, tmp_path):
    for k in ("a", "b"):
        res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "1", "--goal", "304", "--workers", "1", "--out", str(tmp_path / k)])
        assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, ["report", str(tmp_path / "a"), str(tmp_path / "b"), "--out", str(tmp_path / "both")])
    assert res.exit_code == 0, res.output
    md = (tmp_path / "both" / "report.md").read_text()  # one document over both folders
    assert "; 4 rows from" in md and md.count("## Door search (4 runs)") == 1
    assert all(f"How ../{k} was produced" in md for k in ("a", "b"))  # relative to the report's folder
    assert str(tmp_path) not in md
    assert list((tmp_path / "both" / "figures").glob("replay_*.gif"))


def test_report_errors(tmp_path):
    res = CliRunner().invoke(app, ["report", str(tmp_path)])
    assert res.exit_code == 2 and "runs.csv" in res.output


def test_a_scenario_with_a_numeric_name_runs_and_reports(demo_dir, tmp_path):
    """A KTH floor is named by its number (50045233): pandas must not read the scenario column as
    integers anywhere from the run to the report."""
    d = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    d["name"] = "50045233"
    d["map"]["image"] = str(demo_dir / d["map"]["image"])
    d["doors"] = str(demo_dir / d["doors"])
    p = tmp_path / "floor.yaml"
    p.write_text(yaml.safe_dump(d))
    res = CliRunner().invoke(app, ["run", str(p), "--seeds", "1", "--goal", "304", "--workers", "1", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, ["report", str(tmp_path / "o"), "--out", str(tmp_path / "r")])
    assert res.exit_code == 0 and "Traceback" not in res.output, res.output
    assert (tmp_path / "r" / "figures" / "boxes_50045233.png").is_file()
    assert set(read_runs(tmp_path / "o" / "runs.csv")["scenario"]) == {"50045233"}


# ---- no path of the machine in the report; every blank p-value explained (issue: new user) --------
def test_report_names_no_absolute_path(demo_dir, tmp_path):
    """report.md and report.html name the results folder, the scenario and the commands relative
    to the report's folder, also when meta.json holds absolute paths (earlier versions, commands
    typed with them) and when a folder's scenario is gone (the note)."""
    out = tmp_path / "res"
    res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "1", "--goal", "304", "--workers", "1",
                                   "--out", str(out)])
    assert res.exit_code == 0, res.output
    meta = json.loads((out / "meta.json").read_text())
    meta["commands"].append(f"semsearch run {demo_dir / 'scenario.yaml'} --out={out} --workers 1")
    meta["scenario"] = str((demo_dir / "scenario.yaml").resolve())  # as earlier versions wrote it
    (out / "meta.json").write_text(json.dumps(meta))
    gone = tmp_path / "gone"
    shutil.copytree(out, gone)
    meta["scenario"] = str(tmp_path / "nowhere" / "scenario.yaml")
    (gone / "meta.json").write_text(json.dumps(meta))
    broken = tmp_path / "broken"  # a scenario whose map has gone: its error names where the map was looked for
    shutil.copytree(demo_dir, broken)
    (broken / "map.png").unlink()
    lost = tmp_path / "lost"
    shutil.copytree(out, lost)
    meta["scenario"] = str(broken / "scenario.yaml")
    (lost / "meta.json").write_text(json.dumps(meta))
    base = str(tmp_path.parent.parent)  # the session's temporary folder: demo_dir is under it too
    assert str(demo_dir).startswith(base)
    for args, where in (([out], out), ([out, gone, lost, "--out", tmp_path / "both"], tmp_path / "both")):
        res = CliRunner().invoke(app, ["report", *map(str, args), "--format", "md,html,png", "--no-replay"])
        assert res.exit_code == 0, res.output
        for name in ("report.md", "report.html"):
            text = (where / name).read_text()
            assert base not in text, name
    md = (out / "report.md").read_text()
    assert "rows from `runs.csv`" in md and "## How these rows were produced" in md
    assert "--out=. --workers 1" in md and "Rebuild this report, from its folder: `semsearch report .`" in md
    rel = os.path.relpath(demo_dir / "scenario.yaml", out)
    assert f"| scenario | {Path(rel).as_posix()} |" in md
    both = (tmp_path / "both" / "report.md").read_text()
    assert "## How ../res was produced" in both and "`semsearch report ../res ../gone ../lost --out .`" in both
    assert "map image ../broken/map.png not found (looked for ../broken/map.png;" in " ".join(both.split())
    assert "of ../gone were skipped: the scenario file named in ../gone/meta.json is not available" in both


def paired_rows(diffs):
    """greedy and nsos on one episode, seed by seed: nsos travels greedy's distance plus ``diffs``."""
    out = []
    for seed, d in enumerate(diffs):
        for label, params, dist in (("greedy", "{}", 50.0 + seed), ("nsos[alpha=0.9]", '{"alpha": 0.9}', 50.0 + seed + d)):
            out.append({"kind": "doors", "scenario": "s", "planner": label, "params": params, "goal": 54, "seed": seed,
                        "outcome": "found", "success": 1, "distance_m": dist, "shortest_m": 20.0, "ratio": dist / 20,
                        "spl": 20 / dist, "steps": 10, "decisions": 2, "navigator": "geodesic", "wall_s": 0.1})
    return pd.DataFrame(out, columns=COLUMNS)


@pytest.mark.parametrize("diffs,p,says", [
    ([0, 0, 0, 0, 0, 7.0], None, "fewer than 2 non-zero paired differences (1): no test"),
    ([0.0] * 6, 1.0, "every paired difference is 0: p = 1 by convention (nothing to rank)"),
    ([1.0, -2.0, 3.0, 4.0, 5.0, 6.0], "wilcoxon", ""),
])
def test_a_blank_p_value_carries_a_note(tmp_path, diffs, p, says):
    runs = paired_rows(diffs)
    row = T.significance(runs).iloc[0]
    assert row["n_pairs"] == 6 and row["note"] == says
    if p is None:
        assert np.isnan(row["p_value"])
    elif p == "wilcoxon":
        assert row["p_value"] == pytest.approx(wilcoxon(np.array(diffs)).pvalue)
    else:
        assert row["p_value"] == p
    if says:  # and in the report: the table's row, and the caption saying what a blank means
        folder = tmp_path / "f"
        folder.mkdir()
        runs.to_csv(folder / "runs.csv", index=False)
        res = CliRunner().invoke(app, ["report", str(folder), "--format", "md", "--no-replay"])
        assert res.exit_code == 0, res.output
        md = (folder / "report.md").read_text()
        line = next(x for x in md.splitlines() if x.startswith("| s | 54 | nsos[alpha=0.9] | greedy | wilcoxon"))
        assert line.rstrip(" |").endswith(says)
        assert "A blank p_value or interval is explained in the note column" in md


def test_too_few_pairs_and_one_pair():
    one = T.significance(paired_rows([3.0])).iloc[0]
    assert one["note"] == "fewer than 2 non-zero paired differences (1): no test; 1 pair: no interval; n < 5: too few units to judge"
    assert np.isnan(one["p_value"]) and np.isnan(one["diff_lo"])
