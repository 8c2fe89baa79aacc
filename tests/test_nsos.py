"""NSOS factors against values computed by hand (thesis 4.3, paper Eq. 16)."""

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.planners.doors.nsos import (
    closeness,
    growing_direction,
    heading_histogram,
    histogram_lookup,
    increasing_direction,
    parity,
)

D2R = math.pi / 180


def test_signs_all_smaller_favour_the_increasing_direction():
    nums, xs, ys = np.array([1, 2, 3]), np.array([0.0, 2.0, 4.0]), np.zeros(3)  # increasing toward +x
    phi, zeta, gamma = growing_direction(nums, xs, ys, goal=10, theta_f=0.0, w_g=8)
    assert zeta == 3 / 8  # w_g caps the confidence while fewer than 8 signs are known
    assert gamma == 1.0
    assert phi == (3 / 8 + 1) / 2
    phi_back, _, gamma_back = growing_direction(nums, xs, ys, goal=10, theta_f=math.pi, w_g=8)
    assert gamma_back == -1.0 and phi_back == (1 - 3 / 8) / 2
    # with enough signs the confidence is full: zeta = 1
    nums9 = np.arange(1, 10)
    phi9, zeta9, _ = growing_direction(nums9, nums9 * 2.0, np.zeros(9), goal=50, theta_f=0.0, w_g=8)
    assert zeta9 == 1.0 and phi9 == 1.0
    # all bigger: the goal lies the other way
    phi_big, zeta_big, _ = growing_direction(nums, xs, ys, goal=0, theta_f=math.pi, w_g=2)
    assert zeta_big == -1.0 and phi_big == 1.0


def test_gamma_is_minus_one_across_the_pi_seam():
    # signs 5 -> 7 increase toward 179 degrees
    xs, ys = np.array([0.0, math.cos(179 * D2R)]), np.array([0.0, math.sin(179 * D2R)])
    assert increasing_direction(np.array([5, 7]), xs, ys) == pytest.approx(179 * D2R)
    # a candidate pointing at -1 degrees is opposite (the difference wraps to 180 degrees)
    _, _, gamma = growing_direction(np.array([5, 7]), xs, ys, goal=9, theta_f=-1 * D2R, w_g=8)
    assert gamma == pytest.approx(-1.0)
    # one pointing at -179 degrees is 2 degrees away, across the seam
    _, _, gamma_same = growing_direction(np.array([5, 7]), xs, ys, goal=9, theta_f=-179 * D2R, w_g=8)
    assert gamma_same == pytest.approx(1.0 - 2 * 2 / 180)


def test_fewer_than_two_numbers_gives_one_half():
    assert growing_direction(np.array([4]), np.array([0.0]), np.array([0.0]), 9, 0.3, 8)[0] == 0.5
    assert growing_direction(np.array([4, 4]), np.array([0.0, 1.0]), np.zeros(2), 9, 0.3, 8)[0] == 0.5
    assert growing_direction(np.array([], np.int64), np.array([]), np.array([]), 9, 0.3, 8)[0] == 0.5


def test_unit_vectors_per_pair():
    # 1 -> 2 points +x (length 10), 1 -> 3 and 2 -> 3 point +y (short): unit vectors, not lengths
    xs, ys = np.array([0.0, 10.0, 0.0]), np.array([0.0, 0.0, 1.0])
    th = increasing_direction(np.array([1, 2, 3]), xs, ys)
    v = np.array([1.0, 0.0]) + np.array([0.0, 1.0]) + np.array([-10.0, 1.0]) / math.hypot(10, 1)
    assert th == pytest.approx(math.atan2(v[1], v[0]))


def test_parity():
    assert parity(np.array([1, 2]), 4, 8) == 0.5  # mixed parity
    assert parity(np.array([2, 4, 6]), 8, 8) == 0.5 + 0.5 * 3 / 8  # capped by w_p
    assert parity(np.array([1, 3, 5, 7, 9, 11, 13, 15]), 8, 8) == 0.0
    assert parity(np.array([], np.int64), 8, 8) == 0.5


def test_door_histogram_folds_modulo_180():
    h = heading_histogram(np.radians([0.0, 180.0, 90.0, -90.0, 44.0, 46.0]), 4, fold=True)
    # bins centred on 0, 45, 90, 135: {0, 180} -> 0; {90, -90} -> 90; 44, 46 -> 45
    assert h.tolist() == [2 / 6, 2 / 6, 2 / 6, 0.0]
    assert histogram_lookup(h, math.pi, fold=True) == 2 / 6  # theta_f = 180 reads bin 0
    assert histogram_lookup(h, -3 * math.pi / 4, fold=True) == 2 / 6  # -135 = 45 mod 180
    assert heading_histogram([], 4, fold=True).tolist() == [0.0] * 4


def test_robot_histogram_keeps_direction():
    h = heading_histogram(np.radians([0.0, 0.0, 0.0, 180.0]), 18, fold=False)
    assert h[0] == 0.75 and h[9] == 0.25 and h.sum() == pytest.approx(1.0)
    assert histogram_lookup(h, math.radians(9.0), fold=False) == 0.75  # bin centred on 0 spans +-10
    assert histogram_lookup(h, math.radians(-170.0), fold=False) == 0.0  # 190 -> bin 10 (200)
    assert histogram_lookup(h, math.radians(-171.0), fold=False) == 0.25


def test_closeness_eq16():
    phi = closeness(np.array([10.0, 20.0, 40.0]))
    assert phi.tolist() == [1.0, 1 - 0.5**4, 1 - 0.75**4]


def test_trace_and_sweep_alpha(demo_dir, tmp_path):
    out = tmp_path / "sweep"
    res = CliRunner().invoke(app, ["sweep-alpha", str(demo_dir / "scenario.yaml"), "--alphas", "0.8,1.0", "--seeds", "1",
                                   "--goal", "452", "--workers", "1", "--out", str(out), "--trace"])
    assert res.exit_code == 0, res.output
    import pandas as pd

    runs = pd.read_csv(out / "runs.csv")
    assert sorted(runs["planner"]) == ["greedy", "nsos[alpha=0.8]", "nsos[alpha=1.0]"]
    assert (out / "plots" / "alpha_sweep.png").is_file()
    lines = (out / "traces" / "nsos_alpha0.8__goal452__ep1__seed0.jsonl").read_text().splitlines()
    assert len(lines) == runs[runs.planner == "nsos[alpha=0.8]"]["decisions"].iloc[0]
    d = json.loads(lines[-1])
    for key in ("step", "x", "y", "heading_deg", "chosen", "candidates"):
        assert key in d
    c = d["candidates"][d["chosen"]]
    for key in ("phi_g", "phi_p", "phi_o", "phi_r", "phi_c", "SF", "GF", "phi"):
        assert 0.0 <= c[key] <= 1.0
    assert c["phi"] == max(x["phi"] for x in d["candidates"] if x["phi"] is not None)
    assert c["phi"] == pytest.approx(0.8 * c["SF"] + 0.2 * c["GF"], abs=2e-4)


def test_bad_alphas(demo_dir):
    res = CliRunner().invoke(app, ["sweep-alpha", str(demo_dir / "scenario.yaml"), "--alphas", "0.5,2"])
    assert res.exit_code == 2 and "--alphas" in res.output


def _junction_context(goal=7):
    from semsearch_cli.planners import DoorContext

    from .test_belief import make_belief

    free = np.zeros((61, 121), bool)
    free[28:33, 2:119] = True  # a long east-west corridor
    free[2:59, 28:33] = True  # crossed by a north-south one
    b = make_belief(free)
    W = free.shape[1]
    b.visit(30, 30)
    b.visit(30, 45)  # the robot went east and came back to the junction
    # signs 1, 3, 5 read in the east arm, rising eastward: the goal 7 lies further east
    for k, lab in enumerate((1, 3, 5)):
        for _ in range(3):
            b.reads.add(lab, 30 * W + 40 + 4 * k, (40 + 4 * k) * 0.1, 3.0, 0.0)
    cands = b.candidates()
    ctx = DoorContext(b, 30, 30, 3.05, 3.05, 0.0, goal, np.random.default_rng(0), [0.0] * 10)
    return b, cands, ctx


def test_nsos_on_a_junction_follows_the_signs():
    from semsearch_cli.planners import Variant

    b, cands, ctx = _junction_context()
    planner = Variant("nsos", (("alpha", 1.0),)).build()
    d = planner.choose(ctx, cands)
    chosen = d.info["candidates"][d.info["chosen"]]
    assert chosen["theta_f_deg"] == 0.0  # east, where the numbers rise toward 7
    assert chosen["zeta"] == 3 / 8 and chosen["gamma"] == 1.0 and chosen["phi_p"] == 0.5 + 0.5 * 3 / 8
    # the robot moves a cell; the same target is chosen again
    ctx.row, ctx.col = 30, 31
    again = planner.choose(ctx, cands)
    assert (again.row, again.col) == (d.row, d.col)


def test_hysteresis_keeps_a_near_best_target_until_signs_change():
    from semsearch_cli.planners import Variant

    b, cands, ctx = _junction_context()
    north = int(np.flatnonzero(np.degrees(cands.theta).round() == 90)[0])
    east = int(np.flatnonzero(np.degrees(cands.theta).round() == 0)[0])
    wide = Variant("nsos", (("alpha", 1.0), ("hysteresis", 0.2))).build()
    wide._last = ((int(cands.rows[north]), int(cands.cols[north])), 3)  # last choice: north, 3 signs counted
    d = wide.choose(ctx, cands)  # north scores 0.3438, east 0.4727: within 0.2, kept
    assert d.info["chosen"] == north
    narrow = Variant("nsos", (("alpha", 1.0), ("hysteresis", 0.01))).build()
    narrow._last = wide._last
    assert narrow.choose(ctx, cands).info["chosen"] == east
    # a sign reaching min_reads is new evidence: choose afresh even within the hysteresis
    for _ in range(3):
        b.reads.add(9, 30 * b.free.shape[1] + 50, 5.0, 3.0, 0.0)
    wide._last = ((int(cands.rows[north]), int(cands.cols[north])), 3)
    assert wide.choose(ctx, cands).info["chosen"] == east


def test_geometric_is_eq_4_6_alone():
    from semsearch_cli.planners import Variant

    _, cands, ctx = _junction_context()
    d = Variant("geometric", ()).build().choose(ctx, cands)
    for c in d.info["candidates"]:
        assert c["phi"] == pytest.approx(c["GF"], abs=1e-4)
        assert c["GF"] == pytest.approx(((c["phi_o"] + c["phi_r"]) * c["phi_c"] + c["phi_c"]) / 3, abs=2e-4)


def test_rolling_histogram_matches_the_plain_one():
    from semsearch_cli.planners.doors.nsos import RollingHistogram

    rng = np.random.default_rng(1)
    items: list = []
    rh = RollingHistogram(18, False, window=50)
    for _ in range(12):
        items.extend(rng.uniform(-math.pi, math.pi, int(rng.integers(0, 30))).tolist())
        assert np.allclose(rh.update(items), heading_histogram(items[-50:], 18, fold=False))


# ---- the draft paper's planner (tau + Omega + alpha Gamma) ------------------------------
def test_draft_parity_attraction_follows_the_authors_code():
    from semsearch_cli.planners.doors.draft import parity_attraction

    assert parity_attraction([], 101, 0.1) == 0.5  # no sign counts: neutral
    assert parity_attraction([101, 103, 105], 101, 0.1) == pytest.approx(0.65)  # bel 0.3, diff 0
    # only the other parity: bel 0, diff = -0.2, 0.5 + (0 - 0.04) / 2
    assert parity_attraction([102, 104], 101, 0.1) == pytest.approx(0.48)
    assert parity_attraction(list(range(101, 121, 2)), 101, 0.1) == 1.0  # ten of the goal's parity: full belief
    assert parity_attraction(list(range(102, 122, 2)), 101, 0.1) == 0.0  # ten of the other: none
    assert parity_attraction([102], 102, 0.1) == pytest.approx(0.55)  # even goals alike


def test_draft_growing_attraction_eqs_9_10():
    from semsearch_cli.planners.doors.draft import growing_attraction

    nums, xs, ys = np.array([101, 103]), np.array([0.0, 3.0]), np.zeros(2)  # increasing toward +x
    # goal bigger than every sign: toward FF; one vector over max(w_g = 8, 1): GG = 1/8
    assert growing_attraction(nums, xs, ys, 107, 0.0, 8) == pytest.approx(0.5 + 1 / 16)
    assert growing_attraction(nums, xs, ys, 107, math.pi, 8) == pytest.approx(0.5 - 1 / 16)
    assert growing_attraction(nums, xs, ys, 107, math.pi / 2, 8) == pytest.approx(0.5)  # TT = pi/2: TT' = 0
    # goal smaller than every sign: toward FF - pi
    assert growing_attraction(nums, xs, ys, 99, math.pi, 8) == pytest.approx(0.5 + 1 / 16)
    # SMALLER < g < BIGGER: 0.5 whatever the direction
    assert growing_attraction(np.array([101, 109]), xs, ys, 105, 0.0, 8) == 0.5
    assert growing_attraction(np.array([101]), np.zeros(1), np.zeros(1), 107, 0.0, 8) == 0.5  # no direction
    # with w_g = 1 and one vector, full strength: Omega is 1 straight on
    assert growing_attraction(nums, xs, ys, 107, 0.0, 1) == pytest.approx(1.0)
