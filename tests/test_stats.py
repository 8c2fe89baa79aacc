"""Statistics at the level of the episode (report/stats.py): each interval and test checked
against SciPy applied by hand to the per-unit values it should use."""

import numpy as np
import pandas as pd
import pytest
from scipy.stats import binomtest, bootstrap, mannwhitneyu, wilcoxon

from semsearch_cli.report import stats as S
from semsearch_cli.report import tables as T
from semsearch_cli.report.indirect import success_table


def rows(planner, cells, goal=54, **extra):
    """Door-search rows from ``{(episode, seed): distance_m}``; success 1 unless ``extra`` says."""
    out = []
    for (ep, seed), d in cells.items():
        out.append({"scenario": "s", "goal": goal, "planner": planner, "episode": ep, "seed": seed, "outcome": "found",
                    "success": 1, "distance_m": float(d), "shortest_m": 10.0 + ep, "ratio": d / (10.0 + ep),
                    "spl": 0.5, "soft_spl": 0.6, "left_m": 0.0, "cause": "", "room": ""} | extra)
    return pd.DataFrame(out)


# unequal repeats: episode -> distances of its repeats
UNEQUAL = {0: [10.0], 1: [12.0, 14.0, 19.0], 2: [30.0, 20.0], 3: [8.0, 9.0, 10.0, 13.0], 4: [40.0], 5: [16.0, 18.0]}
UNEQUAL_MEANS = np.array([10.0, 15.0, 25.0, 10.0, 40.0, 17.0])  # by hand


def unequal_runs():
    return rows("greedy", {(ep, k): d for ep, ds in UNEQUAL.items() for k, d in enumerate(ds)})


def test_units_are_episodes_else_repeats_else_rooms():
    many = unequal_runs()
    assert list(S.units(many)[:4]) == ["e0", "e1", "e1", "e1"] and S.unit_kind(many) == "episodes"
    one = rows("greedy", {(3, 0): 1.0, (3, 1): 2.0, (3, 2): 3.0})
    assert list(S.units(one)) == ["e3/s0", "e3/s1", "e3/s2"] and S.unit_kind(one) == "repeats"
    old = one.drop(columns=["episode", "room"])  # folders written before episodes and rooms
    assert list(S.units(old)) == ["e0/s0", "e0/s1", "e0/s2"]
    assert list(S.units(old, cluster="room")) == ["e0/s0", "e0/s1", "e0/s2"] and S.unit_kind(old, "room") == "repeats"
    rooms = one.assign(room=["kitchen", "kitchen", "hall"])
    assert list(S.units(rooms, cluster="room")) == ["kitchen", "kitchen", "hall"] and S.unit_kind(rooms, "room") == "rooms"


def test_mean_ci_is_scipys_bca_bootstrap_over_the_episode_means():
    runs = unequal_runs()
    m, lo, hi = S.mean_ci(runs["distance_m"], S.units(runs))
    want = bootstrap((UNEQUAL_MEANS,), np.mean, confidence_level=0.95, n_resamples=9999, method="BCa",
                     rng=np.random.default_rng(0)).confidence_interval
    assert m == pytest.approx(UNEQUAL_MEANS.mean()) and m != pytest.approx(runs["distance_m"].mean())  # episodes weigh alike
    assert (lo, hi) == (pytest.approx(want.low, abs=1e-12), pytest.approx(want.high, abs=1e-12))
    assert lo < m < hi
    assert S.mean_ci(runs["distance_m"], S.units(runs)) == (m, lo, hi)  # deterministic
    assert S.mean_ci([5.0, 5.0, 7.0, 3.0], ["a", "a", "b", "b"]) == (5.0, 5.0, 5.0)  # every unit mean is 5
    m1, lo1, hi1 = S.mean_ci([1.0, 2.0, 6.0], ["a", "a", "a"])
    assert m1 == 3.0 and np.isnan(lo1) and np.isnan(hi1)


def test_rate_ci_is_plain_wilson_for_one_run_per_unit():
    y = [1, 0, 1, 1, 0, 1, 0, 1, 1, 1]
    p, lo, hi = S.rate_ci(y, np.arange(10))
    want = binomtest(7, 10).proportion_ci(confidence_level=0.95, method="wilson")
    assert (p, lo, hi) == (0.7, pytest.approx(want.low, abs=1e-12), pytest.approx(want.high, abs=1e-12))


def test_rate_ci_widens_for_clustered_outcomes():
    y = [1] * 20 + [0] * 20  # 4 units all found, 4 all failed, 5 runs each
    u = np.repeat(np.arange(8), 5)
    p, lo, hi = S.rate_ci(y, u)
    plain = binomtest(20, 40).proportion_ci(method="wilson")
    # perfectly clustered: deff = 5, the unit size, so the interval is Wilson's for 4 of 8
    eight = binomtest(4, 8).proportion_ci(method="wilson")
    assert p == 0.5 and (lo, hi) == (pytest.approx(eight.low, abs=1e-12), pytest.approx(eight.high, abs=1e-12))
    assert lo < plain.low and hi > plain.high
    # the same outcomes spread evenly over the units: no clustering, back to plain Wilson
    spread = np.tile(np.arange(8), 5)
    _, lo2, hi2 = S.rate_ci(y, spread)
    assert (lo2, hi2) == (pytest.approx(plain.low, abs=1e-12), pytest.approx(plain.high, abs=1e-12))
    # every run found: deff is 1 (nothing to estimate), Wilson over all runs
    _, lo3, hi3 = S.rate_ci([1] * 40, u)
    assert lo3 == pytest.approx(binomtest(40, 40).proportion_ci(method="wilson").low, abs=1e-12) and hi3 == 1.0
    assert np.isnan(S.rate_ci([1, 0, 1], ["a", "a", "a"])[1])  # one unit of three runs: no interval


def test_paired_on_episodes_matches_a_hand_computation():
    # A - B per episode, repeats averaged: 3, -1, 2, 5, 4, 0; B also ran episode 6 and A episode 7 (unpaired)
    b = rows("b", {(e, s): 20.0 for e in range(7) for s in range(2)})
    d = {0: 3.0, 1: -1.0, 2: 2.0, 3: 5.0, 4: 4.0, 5: 0.0, 7: 9.0}
    a = rows("a", {(e, s): 20.0 + d[e] + (1.0 if s else -1.0) for e in d for s in range(2)})
    r = S.paired(a, b)
    diffs = np.array([3.0, -1.0, 2.0, 5.0, 4.0, 0.0])
    assert r["unit"] == "episodes" and r["n_pairs"] == 6 and r["unpaired"] == 2
    assert r["mean_diff"] == pytest.approx(13 / 6)
    want = bootstrap((diffs,), np.mean, method="BCa", rng=np.random.default_rng(0)).confidence_interval
    assert (r["diff_lo"], r["diff_hi"]) == (pytest.approx(want.low), pytest.approx(want.high))
    assert r["p_value"] == pytest.approx(wilcoxon(diffs).pvalue)
    # ranks of |d| over the nonzero d: 3->3, 1->1, 2->2, 5->5, 4->4; R+ = 14, R- = 1
    assert r["effect_r"] == pytest.approx(13 / 15)
    assert S.paired(b, a)["effect_r"] == pytest.approx(-13 / 15)  # positive when the first travels more


def test_paired_degenerate_differences():
    b = rows("b", {(0, s): 10.0 for s in range(4)})
    same = S.paired(b.assign(planner="a"), b)
    assert same["unit"] == "repeats" and same["n_pairs"] == 4 and same["p_value"] == 1.0 and same["effect_r"] == 0.0
    assert (same["mean_diff"], same["diff_lo"], same["diff_hi"]) == (0.0, 0.0, 0.0)
    one = S.paired(b.assign(planner="a", distance_m=[10.0, 10.0, 10.0, 12.0]), b)
    assert np.isnan(one["p_value"]) and one["effect_r"] == 1.0


def test_significance_is_paired_when_episodes_are_shared_else_mann_whitney():
    cells = {(e, s): 30.0 + 3 * e + s for e in range(6) for s in range(2)}
    greedy = rows("greedy", cells)
    nsos = rows("nsos[alpha=0.9]", {k: v - 4.0 - k[0] for k, v in cells.items()})  # travels less on every episode
    bvp = rows("bvp", {(e + 10, s): v + 1.0 for (e, s), v in cells.items()})  # other episodes
    sig = T.significance(pd.concat([greedy, nsos, bvp], ignore_index=True)).set_index("planner")
    assert set(sig["baseline"]) == {"greedy"}
    row = sig.loc["nsos[alpha=0.9]"]
    assert row["test"] == "wilcoxon signed-rank, paired on episodes" and row["n_pairs"] == 6
    want = S.paired(nsos, greedy)
    assert row["p_value"] == pytest.approx(want["p_value"]) and row["mean_diff"] == pytest.approx(-6.5)
    assert row["effect_r"] == -1.0 and row["diff_hi"] < 0  # planner - baseline: negative, it travels less
    row = sig.loc["bvp"]
    assert row["test"] == "mann-whitney, unpaired" and np.isnan(row["n_pairs"]) and row["n"] == row["n_baseline"] == 6
    x = bvp.groupby("episode")["distance_m"].mean().to_numpy()
    y = greedy.groupby("episode")["distance_m"].mean().to_numpy()
    u, p = mannwhitneyu(x, y, alternative="two-sided")
    assert row["p_value"] == pytest.approx(p) and row["effect_r"] == pytest.approx(round(2 * u / 36 - 1, 3))
    assert row["mean_diff"] == pytest.approx(1.0)
    # without greedy the first planner of planner_order is the baseline
    sig = T.significance(pd.concat([nsos, bvp], ignore_index=True))
    assert list(sig["baseline"]) == ["bvp"] and list(sig["planner"]) == ["nsos[alpha=0.9]"]


def test_summary_success_and_causes():
    cells = {(e, s): 20.0 + e for e in range(4) for s in range(3)}
    runs = rows("greedy", cells)
    runs.loc[[0, 1, 2], ["success", "outcome", "cause", "left_m"]] = [0, "budget", "budget", 4.0]
    runs.loc[3, ["success", "outcome", "cause", "left_m"]] = [0, "stuck", "stuck", 7.0]
    runs.loc[4, ["success", "outcome", "cause", "left_m"]] = [0, "not_found", "", np.inf]  # older row: no cause
    s = T.summarise(runs).iloc[0]
    u = S.units(runs)
    assert s["n"] == 12 and s["episodes"] == 4 and s["unit"] == "episodes" and s["n_units"] == 4
    assert s["left_m"] == pytest.approx(4.75)  # (4 + 4 + 4 + 7) / 4; the unreachable one left out
    assert (s["success_lo"], s["success_hi"]) == pytest.approx(S.rate_ci(runs["success"], u)[1:], abs=1e-3)
    assert (s["mean_lo"], s["mean_hi"]) == pytest.approx(S.mean_ci(runs["distance_m"], u)[1:], abs=1e-3)
    assert s["shortest_m"] == pytest.approx(11.5) and s["soft_spl"] == pytest.approx(0.6)  # mean over episodes
    t = T.success_and_spl(runs).iloc[0]
    assert (t["budget"], t["stuck"], t["explored"], t["error"]) == (3, 1, 1, 0)
    assert T.summarise(rows("greedy", cells))["left_m"].isna().all()  # none failed
    cell = T.mean_ci(runs).iloc[0, 0]
    assert cell.startswith(f"{s['mean']:.2f} [") and cell.endswith("(4)")


def test_indirect_success_is_clustered_on_rooms():
    y = [1] * 10 + [0] * 10
    runs = rows("UIS", {(0, k): 5.0 for k in range(20)}, goal=1.0, time_s=30.0).assign(success=y)
    t = success_table(runs.assign(room=np.repeat(["r0", "r1", "r2", "r3"], 5))).iloc[0]
    assert t["unit"] == "rooms" and t["n_units"] == 4
    assert (t["ci_low"], t["ci_high"]) == pytest.approx(binomtest(2, 4).proportion_ci(method="wilson")[:2], abs=1e-4)
    old = success_table(runs).iloc[0]  # no rooms: each search its own unit, the plain Wilson interval
    assert old["unit"] == "repeats"
    assert (old["ci_low"], old["ci_high"]) == pytest.approx(binomtest(10, 20).proportion_ci(method="wilson")[:2], abs=1e-4)
