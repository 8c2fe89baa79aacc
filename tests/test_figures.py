"""Figures for papers: every image format, the success-vs-budget curve, the
alpha figure only for two alphas or more, the replay chosen on the command line."""

import json
from pathlib import Path
from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.metrics import COLUMNS
from semsearch_cli.planners import Variant
from semsearch_cli.report import plots, stats
from semsearch_cli.report import tables as T
from semsearch_cli.report.figures import indirect as fig_indirect
from semsearch_cli.report.plots import PALETTE, budget_curve, image_formats, swept_values, planner_colors, thin_boxes
from semsearch_cli.report.runfiles import load_paths, median_label, median_panel, stems
from semsearch_cli.runner import Loaded
from semsearch_cli.tasks import FrameRecorder
from semsearch_cli.world.ground_truth import Signs

MAGIC = {"png": b"\x89PNG", "pdf": b"%PDF", "svg": b"<?xml"}


@pytest.fixture(scope="module")
def demo_runs(demo_dir, tmp_path_factory):
    """The demo, two seeds: a results folder with its paths and meta.json."""
    out = tmp_path_factory.mktemp("figs") / "demo"
    res = CliRunner().invoke(app, ["run", str(demo_dir / "scenario.yaml"), "--seeds", "2", "--workers", "1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    return out


def report(*args):
    return CliRunner().invoke(app, ["report", *map(str, args)])


def test_every_format_is_written(demo_runs, tmp_path):
    out = tmp_path / "r"
    res = report(demo_runs, "--out", out, "--format", "md,csv,png,pdf,svg,html", "--no-replay")
    assert res.exit_code == 0, res.output
    figs = out / "figures"
    stems_ = {f.stem for f in figs.iterdir()}
    assert stems_ == {"boxes_demo", "budget_demo", "paths_demo_goal304", "paths_demo_goal452"}  # one alpha: no alpha figure
    for stem in stems_:
        for fmt, magic in MAGIC.items():
            assert (figs / f"{stem}.{fmt}").read_bytes()[:5].startswith(magic), (stem, fmt)
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == 4
    md = (out / "report.md").read_text()
    assert "](figures/budget_demo.png)" in md and ".pdf)" not in md
    assert (out / "tables" / "budget_demo.csv").is_file()


def test_vector_formats_alone(demo_runs, tmp_path):
    """pdf,svg (refused before): the figures in those formats only, no documents, no PNG."""
    out = tmp_path / "r"
    res = report(demo_runs, "--out", out, "--format", "pdf,svg", "--no-replay")
    assert res.exit_code == 0, res.output
    suffixes = {f.suffix for f in (out / "figures").iterdir()}
    assert suffixes == {".pdf", ".svg"}
    assert not (out / "report.md").exists() and not list((out / "tables").glob("*.csv"))


def test_image_formats():
    assert image_formats(["md"]) == ("png",)
    assert image_formats(["csv"]) == ()
    assert image_formats(["svg", "html", "pdf"]) == ("png", "pdf", "svg")
    assert image_formats(["pdf"]) == ("pdf",)


@pytest.mark.parametrize("fmt", ["png,tiff", "jpg", ","])
def test_an_unknown_format_is_refused(demo_runs, tmp_path, fmt):
    res = report(demo_runs, "--out", tmp_path / "r", "--format", fmt)
    assert res.exit_code == 2 and "--format" in res.output and "Traceback" not in res.output, res.output
    assert "md, csv, png, pdf, svg, html" in res.output
    assert not list((tmp_path / "r").rglob("*"))


# ---- success against the distance budget --------------------------------------------------------
def wilson(k, n, z=norm.ppf(0.975)):
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, c - h), min(1.0, c + h)


def rows(spec):
    """(planner, goal, seed, success, distance_m[, episode]) -> a runs table."""
    cols = ["planner", "goal", "seed", "success", "distance_m", "episode"]
    return pd.DataFrame([s if len(s) == 6 else (*s, 0) for s in spec], columns=cols)


def test_budget_curve_is_exact():
    runs = rows([("greedy", 7, 0, 1, 10.0), ("greedy", 7, 1, 1, 20.0), ("greedy", 7, 2, 0, 30.0),
                 ("bvp", 7, 0, 1, 15.0), ("bvp", 7, 1, 1, 15.0)])
    before = runs.copy()
    c = budget_curve(runs)
    pd.testing.assert_frame_equal(runs, before)  # the input is not modified
    assert list(c.columns) == ["goal", "planner", "budget_m", "n", "successes", "rate", "lo", "hi"]
    assert list(dict.fromkeys(c["planner"])) == ["greedy", "bvp"]
    g = c[c["planner"] == "greedy"]
    # budgets: 0, the distances of the runs that found the goal, the longest run (a failure)
    assert g["budget_m"].tolist() == [0.0, 10.0, 15.0, 20.0, 30.0]
    assert g["successes"].tolist() == [0, 1, 1, 2, 2]  # the run that failed at 30 m never counts
    assert g["rate"].tolist() == pytest.approx([0, 1 / 3, 1 / 3, 2 / 3, 2 / 3])
    assert (g["n"] == 3).all()
    b = c[c["planner"] == "bvp"]
    assert b["successes"].tolist() == [0, 0, 2, 2, 2] and b["rate"].tolist() == [0, 0, 1, 1, 1]
    # one episode: each run is its own unit, so the band is the plain Wilson interval
    for k, lo, hi in zip(g["successes"], g["lo"], g["hi"]):
        assert (lo, hi) == pytest.approx(wilson(k, 3))
    c2 = budget_curve(runs, budgets=[25.0, 12.0])
    assert c2[c2["planner"] == "greedy"][["budget_m", "successes"]].values.tolist() == [[12.0, 1], [25.0, 2]]


def test_budget_curve_counts_episodes_as_units():
    """Two episodes, two repeats each: the interval is rate_ci over the episodes, per goal."""
    runs = rows([("greedy", 7, 0, 1, 10.0, 0), ("greedy", 7, 1, 1, 12.0, 0), ("greedy", 7, 0, 1, 40.0, 1),
                 ("greedy", 7, 1, 0, 50.0, 1), ("greedy", 9, 0, 1, 5.0, 2)])
    c = budget_curve(runs, budgets=[20.0])
    r = c[c["goal"] == 7].iloc[0]
    ok = np.array([1, 1, 0, 0], float)
    want = stats.rate_ci(ok, ["e0", "e0", "e1", "e1"])
    assert (r["rate"], r["lo"], r["hi"]) == pytest.approx(want, nan_ok=True) and r["rate"] == 0.5
    assert c["goal"].tolist() == [7, 9]


def test_thin_boxes_drops_overlaps_in_order():
    x, y = np.array([0.0, 0.5, 3.0, 0.0]), np.array([0.0, 0.0, 0.0, 2.0])
    boxes = [(x[i], y[i], 0.9, 1.0) for i in range(4)]  # a two-digit number and its margin: 3 x 0.3 wide
    assert thin_boxes(boxes) == [0, 2, 3]
    assert thin_boxes(boxes, fixed=[(0.5, 0.0, 1.0, 1.0)]) == [2, 3]


def test_planner_colours_are_fixed_and_colour_blind_safe():
    order = ["greedy", "bvp", "nsos[alpha=0.8]"]
    assert planner_colors(order) == {"greedy": PALETTE[0], "bvp": PALETTE[1], "nsos[alpha=0.8]": PALETTE[2]}
    assert "#F0E442" not in PALETTE  # yellow marks goals only


# ---- the alpha figure -------------------------------------------------------------------------
def synthetic_folder(path, alphas):
    """A results folder of greedy and nsos at ``alphas`` (rows only: no scenario, so no maps)."""
    rng = np.random.default_rng(1)
    out = []
    for goal in (54, 124):
        for label, params in [("greedy", "{}")] + [(f"nsos[alpha={a}]", json.dumps({"alpha": a})) for a in alphas]:
            for seed in range(4):
                d = round(float(20 * rng.uniform(1, 3)), 1)
                out.append({"kind": "doors", "scenario": "s", "planner": label, "params": params, "goal": goal, "seed": seed,
                            "stage": "", "map": "", "outcome": "found", "success": 1, "distance_m": d, "shortest_m": 20.0,
                            "ratio": d / 20, "spl": 20 / d, "steps": int(d * 10), "decisions": 3, "navigator": "geodesic",
                            "wall_s": 0.1})
    path.mkdir()
    pd.DataFrame(out).reindex(columns=COLUMNS).to_csv(path / "runs.csv", index=False)
    return path


@pytest.mark.parametrize("alphas,drawn", [((0.9,), False), ((0.8, 0.9), True)])
def test_alpha_figure_only_for_two_alphas(tmp_path, alphas, drawn):
    folder = synthetic_folder(tmp_path / "s", alphas)
    assert swept_values(pd.read_csv(folder / "runs.csv")) == list(alphas)
    res = report(folder, "--format", "png,md", "--no-replay")
    assert res.exit_code == 0, res.output
    assert (folder / "figures" / "alpha_s.png").is_file() == drawn
    assert ("figures/alpha_s.png" in (folder / "report.md").read_text()) == drawn
    assert (folder / "figures" / "boxes_s.png").is_file() and (folder / "figures" / "budget_s.png").is_file()


# ---- the replay ---------------------------------------------------------------------------------
def test_replay_default_and_chosen(demo_runs, tmp_path):
    runs = pd.read_csv(demo_runs / "runs.csv")
    ep = stats.episodes(runs)
    res = report(demo_runs, "--out", tmp_path / "d", "--format", "png")
    assert res.exit_code == 0, res.output
    gif = [f.name for f in (tmp_path / "d" / "figures").glob("replay_*.gif")]
    bvp304 = runs[(runs["planner"] == "bvp") & (runs["goal"] == 304)]
    med = bvp304.loc[median_label(bvp304)]  # default: the median run of the last planner, first goal
    assert gif == [f"replay_demo_{stems('bvp', 304, int(med['seed']), int(ep[med.name]))[0]}.gif"]
    e452 = int(ep[runs["goal"] == 452].iloc[0])
    res = report(demo_runs, "--out", tmp_path / "c", "--format", "png,md", "--replay", f"greedy,452,{e452},1")
    assert res.exit_code == 0, res.output
    gif = [f.name for f in (tmp_path / "c" / "figures").glob("replay_*.gif")]
    assert gif == [f"replay_demo_{stems('greedy', 452, 1, e452)[0]}.gif"]
    assert "greedy__goal452" in gif[0] and gif[0].endswith("seed1.gif")
    md = (tmp_path / "c" / "report.md").read_text()
    assert f"Replay of greedy, goal 452, episode {e452}, seed 1" in md


@pytest.mark.parametrize("value,says", [("nsos,304,0,0", "no such planner"), ("greedy,304,0,7", "seeds 0, 1"),
                                        ("greedy,304", "PLANNER,GOAL,EPISODE,SEED"), ("greedy,304,x,0", "whole numbers")])
def test_a_bad_replay_exits_2(demo_runs, tmp_path, value, says):
    res = report(demo_runs, "--out", tmp_path / "r", "--replay", value)
    assert res.exit_code == 2 and "--replay" in res.output and "Traceback" not in res.output, res.output
    assert says in res.output
    if "no such" in says:
        assert "greedy, bvp" in res.output and "goals 304, 452" in res.output
    assert not list((tmp_path / "r").rglob("*"))  # refused before anything is written


def test_replay_and_no_replay_together_exit_2(demo_runs, tmp_path):
    res = report(demo_runs, "--out", tmp_path / "r", "--replay", "greedy,304,0,0", "--no-replay")
    assert res.exit_code == 2 and "--no-replay" in res.output


# ---- path files -------------------------------------------------------------------------------
def test_path_files_new_stem_then_old(demo_runs, tmp_path):
    """A folder from before episodes names its path files without ``__ep``: they are still found."""
    runs = pd.read_csv(demo_runs / "runs.csv")
    some = runs[runs["planner"] == "greedy"]
    assert len(load_paths(demo_runs, some)) == len(some)
    old = tmp_path / "old"
    (old / "paths").mkdir(parents=True)
    r = some.iloc[0]
    np.savez(old / "paths" / f"{stems('greedy', r['goal'], int(r['seed']))[-1]}.npz", path=np.zeros((3, 2)))
    got = load_paths(old, some.drop(columns=["episode"], errors="ignore").iloc[:1])
    assert len(got) == 1 and got[0][1].shape == (3, 2)


# ---- figures that agree with their tables, and labels that do not collide (issue: new user) ------


def has_data(ax) -> bool:
    return bool(ax.lines or ax.images or ax.collections or ax.patches)


def legend_only(ax) -> bool:
    """A grid cell holding the figure's legend: no frame, no data."""
    return not ax.axison and ax.get_legend() is not None and not has_data(ax)


def test_the_bold_run_is_the_median_or_the_title_says_which_it_is():
    """An even count has no median run: the lower middle run is drawn and the title gives the
    table's median beside that run's distance (the issue: "median 137 m" under a table's 226.5)."""

    runs = rows([("nsos[alpha=1.0]", 135, s, 1, d) for s, d in enumerate([400.0, 136.8, 316.2, 100.0])])
    found = [(i, np.full((2, 2), float(i))) for i in runs.index]
    paths, k, note = median_panel(runs, found, "n=4")
    table = T.summarise(runs.assign(scenario="s", ratio=1.0, shortest_m=10.0))
    assert table["median"].iloc[0] == 226.5
    assert note == "median 226.5 m, n=4\nbold: lower middle run, 136.8 m"
    assert k == 1 and paths[k][0, 0] == 1.0  # the row at 136.8 m
    # odd count: the median run itself; a tie in the middle: the run is at the median
    odd = rows([("g", 1, s, 1, d) for s, d in enumerate([30.0, 10.0, 20.0])])
    assert median_panel(odd, [(i, np.zeros((2, 2))) for i in odd.index], "n=3")[1:] == (2, "median 20 m, n=3")
    tie = rows([("g", 1, s, 1, d) for s, d in enumerate([10.0, 20.0, 20.0, 40.0])])
    assert median_panel(tie, [(i, np.zeros((2, 2))) for i in tie.index], "n=4")[2] == "median 20 m, n=4"
    # its path file missing: nothing drawn bold, the title names no run
    assert median_panel(runs, [f for f in found if f[0] != 1], "n=4")[1:] == (-1, "median 226.5 m, n=4")


def test_path_panels_leave_no_empty_cell_and_show_every_run(demo_loaded, drawn):
    w = demo_loaded.world
    line = lambda k: np.array([[3.0, 10.0 + 0.1 * k], [26.0, 10.0 + 0.1 * k]])  # noqa: E731
    labels = ["greedy", "bvp", "nsos[alpha=0.8]", "nsos[alpha=0.9]", "nsos[alpha=1.0]"]
    panels = {lab: ([line(k) for k in range(10)], 4, f"median 25 m, n=10\nbold: lower middle run, {20 + j} m")
              for j, lab in enumerate(labels)}
    plots.plot_path_panels(w, panels, [("goal 304", 9.0, 16.0)], "", Path("x.png"))
    fig = drawn[0]
    data = [ax for ax in fig.axes if has_data(ax)]
    assert [ax.get_title() for ax in data] == [f"{lab}: {panels[lab][2]}" for lab in labels]
    assert all(ax in data or legend_only(ax) for ax in fig.axes) and len(fig.axes) == 6  # the sixth cell: the legend
    assert all(ax.get_visible() for ax in fig.axes)
    fig.canvas.draw()
    above_the_gap = data[3]  # nsos[alpha=0.9], right column, nothing under it: it carries the x axis
    assert above_the_gap.xaxis.get_major_ticks()[0].label1.get_visible()
    assert not data[1].xaxis.get_major_ticks()[0].label1.get_visible()
    faint = [ln for ln in data[0].lines if ln.get_linewidth() == plots.EVERY_RUN_LW]
    assert len(faint) == 9 and all(ln.get_alpha() >= 0.4 for ln in faint)  # visible, not 0.3 x 0.7 pt


def test_boxes_leave_no_empty_cell(drawn):
    runs = rows([(lab, g, s, 1, 10.0 + s + g) for g in (1, 2, 3) for lab in ("greedy", "bvp") for s in range(4)])
    runs = runs.assign(scenario="s", shortest_m=5.0)
    plots.plot_boxes(runs, "s", ["greedy", "bvp"], Path("x.png"))
    fig = drawn[0]
    assert sum(has_data(ax) for ax in fig.axes) == 3
    assert all(has_data(ax) or legend_only(ax) for ax in fig.axes)


def test_indirect_panels_leave_no_empty_axes(drawn):
    order = ["a", "b", "c", "d", "e"]
    table = pd.DataFrame([{"planner": m, "view_scale": v, "success": 0.5, "ci_low": 0.3, "ci_high": 0.7, "n": 8}
                          for m in order for v in (1.0, 2.0)])
    plots.plot_success_by_scale(table, order, {}, [1.0, 2.0], Path("x.png"))
    fig = drawn[0]
    assert sum(has_data(ax) for ax in fig.axes) == 5
    assert all(has_data(ax) or legend_only(ax) for ax in fig.axes)
    assert all(ax.get_visible() for ax in fig.axes)


def test_the_budget_axis_runs_past_the_longest_run(drawn):
    """A planner that found the goal every time, the last time on the longest run, is drawn
    reaching 1.0 (the axis used to end at that run, so the curve seemed to stop at 0.9)."""
    runs = rows([("greedy", 7, s, 1, 10.0 * (s + 1)) for s in range(10)]
                + [("bvp", 7, s, 1 if s < 9 else 0, 5.0 * (s + 1)) for s in range(10)])
    curve = budget_curve(runs)
    longest = runs["distance_m"].max()
    assert longest == 100.0
    plots.plot_budget(curve, ["greedy", "bvp"], Path("x.png"))
    fig = drawn[0]
    greedy = fig.axes[0]
    assert all(ax.get_xlim()[1] > longest for ax in fig.axes)
    right = greedy.get_xlim()[1]
    step = [ln for ln in greedy.lines if ln.get_color() == PALETTE[0]][-1]
    x, y = np.asarray(step.get_xdata(), float), np.asarray(step.get_ydata(), float)
    assert y[-1] == 1.0 and x[-1] == right and x[np.argmax(y == 1.0)] == longest  # reaches 1 at 100 m, then level


def stub_world():
    """A 130 m x 70 m floor (1 m cells) with a corridor whose walls carry three-digit numbers
    every 2.5 m (the Hotel's density, where a replay wrote "109121"); goal: sign 109."""
    xs = 40.0 + 2.5 * np.arange(14)
    num = [str(100 + 3 * k) for k in range(14)] + [str(101 + 3 * k) for k in range(14)]
    x = np.r_[xs, xs]
    y = np.r_[np.full(14, 60.0), np.full(14, 56.0)]
    facing = np.r_[np.full(14, -np.pi / 2), np.full(14, np.pi / 2)]  # top wall faces down, bottom up
    signs = Signs(tuple(num), np.array([int(n) for n in num]), x, y, facing)
    frame = SimpleNamespace(origin_x=0.0, origin_y=0.0, width=130, height=70, res=1.0)
    return SimpleNamespace(frame=frame, signs=signs, start_xy=(45.0, 58.0))


def overlapping(texts, renderer):
    boxes = [t.get_window_extent(renderer) for t in texts]
    return [(texts[i].get_text(), texts[j].get_text()) for i in range(len(boxes)) for j in range(i)
            if boxes[i].overlaps(boxes[j])]


def test_replay_numbers_do_not_collide_and_the_goal_keeps_its_own():
    w = stub_world()
    goal = ("goal 109", float(w.signs.x[3]), float(w.signs.y[3]))
    frame = {"map": np.full((70, 130), 2, np.uint8), "path": np.array([[40.0, 58.0], [75.0, 58.0]]), "distance": 35.0,
             "cands": np.zeros((0, 2)), "target": None, "read": list(range(len(w.signs)))}
    with plt.rc_context(plots.PAPER_RC):
        fig, draw_frame = plots.replay_figure(w, goal)
        try:
            draw_frame(frame, "t")
            fig.canvas.draw()
            ax = fig.axes[0]
            texts = [t for t in ax.texts if t.get_text()]
            words = [t.get_text() for t in texts]
            assert overlapping(texts, fig.canvas.get_renderer()) == []
            assert "goal 109" in words and "109" not in words  # not under its own star
            assert len(words) - 1 >= 20  # most of the 27 other numbers fit
        finally:
            plt.close(fig)


def test_the_scenario_figure_writes_no_number_under_a_goal_star(demo_loaded, drawn):
    w = demo_loaded.world
    plots.plot_scenario(w, [304, 452], "demo", Path("x.png"))
    fig = drawn[0]
    fig.canvas.draw()
    ax = fig.axes[0]
    texts = [t for t in ax.texts if t.get_text()]
    words = [t.get_text() for t in texts]
    assert {"goal 304", "goal 452"} <= set(words) and "304" not in words and "452" not in words
    assert len(words) == len(w.signs) - 2 + 2  # every other number is shown
    assert overlapping(texts, fig.canvas.get_renderer()) == []


def test_the_indirect_replay_has_a_key(monkeypatch, tmp_path):
    """The probability replay says what its marks are (the robot's dot, the goal's cross, A's ring)."""

    L = Loaded.load(Path(__file__).resolve().parents[1] / "configs" / "indirect_quick.yaml")
    rec = FrameRecorder()
    L.task.run(Variant("ISCG-PN-SM", ()), L.task.episodes[0], 0, rec)
    figs = []
    monkeypatch.setattr(fig_indirect, "_animate", lambda fig, draw, n, out, fps: (draw(n - 1), figs.append(fig)))
    fig_indirect.animate_probability(L.task.grids[0].room, L.task.spec.target, rec.frames, "t", tmp_path / "r.gif")
    labels = [t.get_text() for t in figs[0].legends[0].get_texts()]
    assert labels == ["path", "robot", "objects seen", "goal", "A, the target"]
    plt.close(figs[0])


def test_the_swept_value_comes_from_the_rows_params_not_the_label():
    """A row's params hold its planner's parameters; the label is only a name (a --param sweep or a
    label of one's own need not spell alpha): params {"alpha": 0.8} under the label "nsos" is 0.8."""
    runs = pd.DataFrame({"planner": ["nsos", "nsos[alpha=1.0]", "nsos[alpha=0.9]", "greedy"],
                         "params": ['{"alpha": 0.8}', '{"alpha": 1.0}', "{}", "{}"]})
    assert swept_values(runs) == [0.8, 0.9, 1.0]  # "{}": nsos's default, 0.9
    assert swept_values(runs.drop(columns="params")) == [0.9, 1.0]  # no params: the labels ("nsos": the default)
