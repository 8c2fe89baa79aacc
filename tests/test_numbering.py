"""The numbering model (planners/doors/numbering.py, docs/numbering.md): each factor with exact
values, and the planner on a small floor."""

import math

import numpy as np
import pytest

from semsearch_cli.planners import Variant
from semsearch_cli.planners.doors.numbering import (SPACINGS, NumberingParams, beyond, expected_travel, linear_posterior,
                                                    shares, target_terms)

from .test_nsos import _junction_context


def test_without_signs_the_posterior_is_the_prior():
    w0, w, a = linear_posterior([], [], sigma=1.5, R=200.0, p_none=0.2)
    assert w0 == pytest.approx(0.2, abs=1e-15)
    assert w.shape == (2, len(SPACINGS))
    assert np.allclose(w, 0.8 / (2 * len(SPACINGS)), rtol=0, atol=1e-15)


def test_two_signs_evidence_with_the_offset_integrated_out():
    # signs 10 and 12, 2 m apart along the axis: 1 number per metre, rising along +e
    n, t, sigma, R, p0 = [10, 12], [0.0, 2.0], 1.5, 200.0, 0.2
    w0, w, a = linear_posterior(n, t, sigma, R, p0)
    # the equations written out independently, for every hypothesis
    B = len(SPACINGS)
    log_lin = {}
    for s_i, s in enumerate((1, -1)):
        for b_i, b in enumerate(SPACINGS):
            r = [n[i] - s * b * t[i] for i in range(2)]
            m = sum(r) / 2
            S = sum((ri - m) ** 2 for ri in r)
            log_lin[s_i, b_i] = (math.log(0.8 / (2 * B)) - math.log(R) - 0.5 * math.log(2 * math.pi * sigma ** 2)
                                 - 0.5 * math.log(2) - S / (2 * sigma ** 2))
            assert a[s_i, b_i] == pytest.approx(m, abs=1e-12)
    log0 = math.log(p0) - 2 * math.log(R)
    z = math.exp(log0) + sum(math.exp(v) for v in log_lin.values())
    assert w0 == pytest.approx(math.exp(log0) / z, rel=1e-12)
    for key, v in log_lin.items():
        assert w[key] == pytest.approx(math.exp(v) / z, rel=1e-12)
    # the exact fit wins: rising at 1 number per metre, offset 10
    assert np.unravel_index(np.argmax(w), w.shape) == (0, SPACINGS.index(1.0))
    assert a[0, SPACINGS.index(1.0)] == 10.0


def test_scattered_numbers_favour_no_pattern():
    w0, w, _ = linear_posterior([10, 190, 40, 150], [0.0, 1.0, 2.0, 3.0], 1.5, 200.0, 0.2)
    assert w0 > 0.99


def test_where_the_goal_is_under_one_numbering():
    B = len(SPACINGS)
    w = np.zeros((2, B))
    w[0, SPACINGS.index(1.0)] = 1.0  # certain: n = 10 + 1 * t
    a = np.full((2, B), 10.0)
    # goal 20 sits at t = 10: 5 m past a target at t = 5
    assert beyond(0.0, w, a, goal=20, t_c=5.0, horizon=30.0) == (1.0, 5.0)
    # behind the target at t = 12
    assert beyond(0.0, w, a, goal=20, t_c=12.0, horizon=30.0) == (0.0, 15.0)
    # 45 m past it: capped at the horizon
    assert beyond(0.0, w, a, goal=60, t_c=5.0, horizon=30.0) == (1.0, 30.0)
    # no pattern: even odds, half the horizon
    assert beyond(1.0, np.zeros((2, B)), a, goal=20, t_c=5.0, horizon=30.0) == (0.5, 15.0)
    # half and half: P = 1/2 + 1/4, E = (1/2 * 5 + 1/4 * 15) / (3/4)
    P, E = beyond(0.5, w * 0.5, a, goal=20, t_c=5.0, horizon=30.0)
    assert P == 0.75 and E == pytest.approx((2.5 + 3.75) / 0.75, abs=1e-12)


def test_prefix_and_parity_shares():
    # four signs on the segment, three with the goal's prefix, all odd; the goal 102 is even
    assert shares([101, 103, 105], 4, 102) == (4 / 5, 1 / 2.5)
    # a corridor numbered on both walls is no evidence against the goal's parity
    assert shares([101, 102, 103, 104], 4, 102) == (1.0, 1.0)
    # no sign at all: no evidence
    assert shares([], 0, 7) == (1.0, 1.0)


def test_expected_travel():
    d = np.array([2.0, 4.0, np.inf])
    P = np.array([1.0, 0.5, 0.5])
    E = np.array([3.0, 10.0, 0.0])
    # d_mean over the reachable = 3: 2 + 3; 4 + 5 + 0.5 (4 + 3 + 15); unreachable: inf
    assert expected_travel(d, P, E, horizon=30.0).tolist() == [5.0, 20.0, math.inf]


def test_terms_on_a_junction():
    # signs 1, 3, 5 read along the east arm (x = 4.0, 4.4, 4.8 m), rising eastward; the goal 21
    # lies about 3 m east of them, past the east target (x = 5.85 m)
    b, cands, ctx = _junction_context(goal=21)
    params = NumberingParams()
    P, E = target_terms(ctx, cands, np.ones(len(cands), bool), params)
    xs, ys = b.frame.to_world(cands.rows, cands.cols)
    # the junction and its arms are one visited segment: every target sees the three signs, on
    # the axis of its own branch direction, with the posterior written out again here
    for i, th in enumerate(cands.theta):
        e = (math.cos(th), math.sin(th))
        t = [x * e[0] + 3.0 * e[1] for x in (4.0, 4.4, 4.8)]
        w0, w, a = linear_posterior([1, 3, 5], t, params.sigma, params.number_range, params.p_none)
        expected = beyond(w0, w, a, 21, float(xs[i] * e[0] + ys[i] * e[1]), params.horizon)
        assert (P[i], E[i]) == pytest.approx(expected, abs=1e-12)
    east = int(np.flatnonzero(np.isclose(cands.theta, 0.0))[0])
    west = int(np.flatnonzero(np.isclose(np.abs(cands.theta), math.pi))[0])
    assert P[east] > 0.8 and P[west] < 0.2  # across the axis (north, south): even odds
    assert np.allclose(np.delete(P, [east, west]), 0.5, rtol=0, atol=1e-9)
    # and the planner goes east
    d = Variant("numbering", ()).build().choose(ctx, cands)
    assert d.info["chosen"] == east and d.info["P"] == round(float(P[east]), 4)


def test_a_text_goal_keeps_the_prior():
    b, cands, ctx = _junction_context(goal="LAB")
    P, E = target_terms(ctx, cands, np.ones(len(cands), bool), NumberingParams())
    assert (P == 0.5).all() and (E == 15.0).all()
