"""The report at scale and on odd labels (issue 35): the bootstrap in bounded memory, equal to
SciPy's on small exact cases; budget curves in one pass, equal to the per-budget rate_ci; goals
summarised by the text they were written with; figures that take limits from finite values only."""

import tracemalloc

import numpy as np
import pandas as pd
import pytest
from scipy.stats import bootstrap

from semsearch_cli.metrics import COLUMNS
from semsearch_cli.report import plots
from semsearch_cli.report import stats as S
from semsearch_cli.report import tables as T
from semsearch_cli.runner.store import read_runs


# ---- the bootstrap over unit means, in blocks -----------------------------------------------------
REPEATS = {0: [10.0], 1: [12.0, 14.0, 19.0], 2: [30.0, 20.0], 3: [8.0, 9.0, 10.0, 13.0], 4: [40.0], 5: [16.0, 18.0]}
UNIT_MEANS = np.array([10.0, 15.0, 25.0, 10.0, 40.0, 17.0])  # by hand


def repeats():
    values = np.array([d for ds in REPEATS.values() for d in ds])
    units = np.array([f"e{e}" for e, ds in REPEATS.items() for _ in ds])
    return values, units


def scipy_ci(samples, statistic, n_resamples=9999):
    res = bootstrap(samples, statistic, n_resamples=n_resamples, method="BCa", rng=np.random.default_rng(0))
    return res.confidence_interval.low, res.confidence_interval.high


def mean_diff(x, y, axis=-1):
    return np.mean(x, axis=axis) - np.mean(y, axis=axis)


def test_mean_ci_is_scipys_bca_over_the_unit_means_whatever_the_block(monkeypatch):
    values, units = repeats()
    m, lo, hi = S.mean_ci(values, units)
    want = scipy_ci((UNIT_MEANS,), np.mean)
    assert m == UNIT_MEANS.mean() and (lo, hi) == (pytest.approx(want[0], abs=1e-12), pytest.approx(want[1], abs=1e-12))
    monkeypatch.setattr(S, "RESAMPLE_BLOCK", 7)  # one resample per block (6 units), then 1 ...
    assert S.mean_ci(values, units) == (m, lo, hi)  # ... the same draws: the same interval, to the bit
    monkeypatch.setattr(S, "RESAMPLE_BLOCK", 6 * 1000 + 3)  # blocks of 1000 resamples, the last one shorter
    assert S.mean_ci(values, units) == (m, lo, hi)


@pytest.mark.parametrize("n", [2, 3, 17, 250])
def test_one_and_two_sample_intervals_match_scipy(n):
    rng = np.random.default_rng(n)
    x, y = rng.exponential(5.0, n), rng.normal(9.0, 2.0, n + 3)  # skewed: the acceleration matters
    _, lo, hi = S._boot((x,), float(x.mean()), 0.95, 999, 0)
    assert (lo, hi) == pytest.approx(scipy_ci((x,), np.mean, 999), abs=1e-12)
    _, lo, hi = S._boot((x, y), 0.0, 0.95, 9999, 0)
    assert (lo, hi) == pytest.approx(scipy_ci((x, y), mean_diff), abs=1e-12)
    a = pd.DataFrame({"goal": 1, "episode": np.arange(n), "seed": 0, "distance_m": x})
    b = pd.DataFrame({"goal": 1, "episode": np.arange(n + 3) + 100, "seed": 0, "distance_m": y})
    r = S.unpaired(a, b)  # episodes are the units: the two-sample bootstrap over their means, in the units' order
    xs, ys = (S._unit_means(d["distance_m"], S.units(d)).to_numpy() for d in (a, b))
    assert (r["diff_lo"], r["diff_hi"]) == pytest.approx(scipy_ci((xs, ys), mean_diff), abs=1e-12)


def test_the_bootstrap_of_100k_units_holds_little_memory():
    """Every row its own unit (one episode, 100,000 seeds): SciPy's bootstrap held all resamples
    at once (999 x 100,000 indices and values, 1.6 GB; 9999 x 20,000 ran out of memory), and its
    BCa jackknife 100,000 x 99,999 more."""
    n = 100_000
    v = np.random.default_rng(1).gamma(2.0, 10.0, n)
    tracemalloc.start()
    try:
        m, lo, hi = S.mean_ci(v, np.arange(n), n_resamples=999)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 * 2**20, f"{peak / 2**20:.0f} MiB"
    se = v.std(ddof=1) / np.sqrt(n)
    assert m == pytest.approx(v.mean()) and lo < m < hi and hi - lo == pytest.approx(2 * 1.96 * se, rel=0.1)


def test_intervals_of_infinite_values_are_blank():
    assert S.mean_ci([1.0, np.inf, 3.0], ["a", "b", "c"])[1:] == pytest.approx((np.nan, np.nan), nan_ok=True)
    a = pd.DataFrame({"episode": [0, 1, 2], "seed": 0, "distance_m": [1.0, np.inf, 2.0]})
    b = a.assign(distance_m=[1.0, 2.0, 3.0], episode=[5, 6, 7])
    r = S.unpaired(a, b)
    assert np.isnan(r["diff_lo"]) and np.isnan(r["diff_hi"])


# ---- the budget curve in one pass ---------------------------------------------------------------
def test_rate_ci_by_budget_is_rate_ci_at_each_budget():
    rng = np.random.default_rng(7)
    for _ in range(60):
        n = int(rng.integers(1, 40))
        units = rng.integers(0, int(rng.integers(1, n + 1)), n).astype(str)  # clustered, unequal units
        found = (rng.random(n) < rng.random()).astype(float)
        dist = np.round(rng.uniform(0.0, 10.0, n))  # ties
        dist[rng.random(n) < 0.1] = np.nan
        budgets = np.r_[-1.0, 0.0, np.unique(dist), 3.5, 11.0]
        got = S.rate_ci_by_budget(found, dist, units, budgets)
        for j, b in enumerate(budgets):
            ok = (found == 1) & (dist <= b)
            assert got["successes"][j] == ok.sum()
            want = S.rate_ci(ok.astype(float), units)
            assert (got["rate"][j], got["lo"][j], got["hi"][j]) == pytest.approx(want, abs=1e-12, nan_ok=True)


def test_budget_curve_of_many_runs_is_fast():
    n = 20_000
    rng = np.random.default_rng(2)
    runs = pd.DataFrame({"goal": 7, "planner": "greedy", "episode": 0, "seed": np.arange(n),
                         "success": (rng.random(n) < 0.9).astype(int), "distance_m": np.round(rng.uniform(10, 120, n), 2)})
    c = plots.budget_curve(runs)  # one rate_ci per distinct distance took minutes
    grid = np.unique(np.r_[0.0, runs.loc[runs["success"] == 1, "distance_m"], runs["distance_m"].max()])
    assert c["budget_m"].tolist() == grid.tolist()  # 0, each success's distance, the longest run
    assert c["successes"].iloc[-1] == runs["success"].sum() and c["rate"].is_monotonic_increasing


# ---- goals summarised as written ------------------------------------------------------------------
def runs_csv(path, goals):
    """A runs.csv of door-search rows, two planners x 3 seeds per goal label (written as given)."""
    rows = []
    for g in goals:
        for planner in ("greedy", "bvp"):
            for seed in range(3):
                d = 20.0 + seed + (5.0 if planner == "bvp" else 0.0)
                rows.append({"kind": "doors", "scenario": "s", "planner": planner, "params": "{}", "goal": g, "episode": 0,
                             "seed": seed, "outcome": "found", "success": 1, "distance_m": d, "shortest_m": 10.0,
                             "ratio": d / 10.0, "spl": 10.0 / d, "soft_spl": 10.0 / d, "left_m": 0.0, "steps": 10,
                             "decisions": 2, "navigator": "geodesic", "wall_s": 0.1})
    pd.DataFrame(rows, columns=COLUMNS).to_csv(path, index=False)
    return path


def test_goals_are_summarised_as_written(tmp_path):
    f = runs_csv(tmp_path / "runs.csv", ["NA", "4.50", "4.5", "1e3", "54", "kitchen"])
    s = T.summarise(read_runs(f, as_written=True))
    assert list(zip(s["goal"], s["planner"]))[::2] == [("4.5", "bvp"), ("4.50", "bvp"), ("54", "bvp"), ("1e3", "bvp"),
                                                       ("NA", "bvp"), ("kitchen", "bvp")]  # numbers by value, then text
    assert (s["n"] == 3).all() and len(s) == 12
    greedy = s[s["planner"] == "greedy"].set_index("goal")
    assert (greedy["mean"] == 21.0).all() and (greedy["unit"] == "repeats").all() and (greedy["n_units"] == 3).all()
    assert greedy["mean_lo"].notna().all()


def test_a_goal_labelled_na_is_that_label_and_a_missing_goal_is_kept_not_a_crash(tmp_path):
    """read_runs keeps a goal NA as the label "NA" (key columns are numbers only when lossless);
    a DataFrame whose goal is missing (NaN) still summarises, the missing goal a group of its own:
    summary.csv (write_summary) and the success table used to end in 'You are trying to merge on
    float64 and object columns'."""
    f = runs_csv(tmp_path / "runs.csv", ["NA"])
    runs = read_runs(f)
    assert (runs["goal"] == "NA").all()
    for goals in (runs, runs.assign(goal=np.nan)):
        s = T.summarise(goals)
        assert len(s) == 2 and list(s["planner"]) == ["bvp", "greedy"] and (s["n"] == 3).all()
        assert s.loc[s["planner"] == "bvp", "mean"].item() == 26.0
        t = T.success_and_spl(goals)
        assert len(t) == 2 and (t["n"] == 3).all()
        sig = T.significance(goals)
        assert len(sig) == 1 and sig["n_pairs"].item() == 3  # bvp against greedy, seed by seed
    mixed = read_runs(runs_csv(tmp_path / "mixed.csv", ["NA", "54"]))  # a number, then the text label
    assert list(T.summarise(mixed)["goal"])[::2] == ["54", "NA"]


# ---- figures from finite values -------------------------------------------------------------------


def doors(distances, success=1):
    return pd.DataFrame({"scenario": "s", "goal": 7, "planner": "greedy", "episode": 0, "seed": range(len(distances)),
                         "success": success, "distance_m": distances, "shortest_m": 10.0})


def texts(fig):
    return [t.get_text() for ax in fig.axes for t in ax.texts]


def test_budget_figure_takes_its_axis_from_finite_budgets(drawn, tmp_path):
    runs = doors([10.0, 20.0, np.inf, 30.0])
    curve = plots.budget_curve(runs)
    assert np.isinf(curve["budget_m"]).any()  # the curve says it; the axis cannot
    plots.plot_budget(curve, ["greedy"], tmp_path / "b.png", shortest={7: np.inf})  # was: Axis limits cannot be NaN or Inf
    ax = drawn[0].axes[0]
    assert ax.get_xlim() == pytest.approx((0.0, plots.budget_limit(30.0)))
    assert "no finite distance" not in texts(drawn[0])


@pytest.mark.parametrize("value", [np.inf, np.nan])
def test_a_figure_without_a_finite_distance_says_so(drawn, tmp_path, value):
    runs = doors([value, value, value], success=[1, 1, 0])
    plots.plot_budget(plots.budget_curve(runs), ["greedy"], tmp_path / "b.png")
    plots.plot_boxes(runs, "s", ["greedy"], tmp_path / "x.png")
    assert all("no finite distance" in texts(fig) for fig in drawn)
    assert all(np.isfinite(ax.get_xlim()).all() for fig in drawn for ax in fig.axes)
    assert plots.budget_limit(np.inf) == plots.budget_limit(np.nan) == 1.0
