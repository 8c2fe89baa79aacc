import math

import numpy as np

from semsearch_cli.kernels.raycast import cast_ray, cast_rays, fold_free, himm_update, line_of_sight, mark_viewed


def slow_ray(occ, v0, u0, theta, max_cells, step=1e-4):
    """Obvious reference: march in tiny steps and report the first occupied cell's distance."""
    dv, du = -math.sin(theta), math.cos(theta)
    t = 0.0
    while t <= max_cells:
        r, c = int(math.floor(v0 + t * dv)), int(math.floor(u0 + t * du))
        if not (0 <= r < occ.shape[0] and 0 <= c < occ.shape[1]):
            return max_cells, False
        if occ[r, c]:
            return t, True
        t += step
    return max_cells, False


def test_exact_ranges_on_small_grid():
    occ = np.zeros((6, 8), bool)
    occ[:, 7] = True  # east wall
    occ[0, :] = True  # north wall
    d, h = cast_ray(occ, 3.5, 2.5, 0.0, 20.0)  # east from the centre of cell (3, 2)
    assert h and d == 4.5
    d, h = cast_ray(occ, 3.5, 2.5, math.pi / 2, 20.0)  # north: rows decrease
    assert h and d == 2.5
    d, h = cast_ray(occ, 3.5, 2.5, math.pi, 20.0)  # west: leaves the grid
    assert not h and d == 20.0
    d, h = cast_ray(occ, 3.5, 2.5, 0.0, 3.0)  # out of range
    assert not h and d == 3.0


def test_kernel_matches_slow_loop_beam_by_beam():
    rng = np.random.default_rng(3)
    occ = rng.random((30, 40)) < 0.08
    occ[15, 20] = False
    thetas = np.linspace(-math.pi, math.pi, 73) + 0.0123  # off the exact cell-corner diagonals
    dist, hit = cast_rays(occ, 15.5, 20.5, thetas, 25.0)
    for th, d, h in zip(thetas, dist, hit):
        ds, hs = slow_ray(occ, 15.5, 20.5, th, 25.0)
        assert h == hs
        assert abs(d - ds) < 1e-3


def test_himm_update_exact():
    occ = np.zeros((5, 8), bool)
    occ[2, 6] = True
    cv = np.zeros((5, 8), np.uint8)
    cv[2, 3] = 5  # a stale obstacle belief on the beam
    seen = np.zeros((5, 8), bool)
    th = np.array([0.0])
    d, h = cast_rays(occ, 2.5, 1.5, th, 10.0)
    touched = np.zeros(64, np.int64)
    free = np.zeros((5, 8), bool)
    free[2, 2] = True  # known free already: its state does not change
    n = himm_update(cv, seen, 2.5, 1.5, th, d, h, 3, 1, 15, free, 3, touched)
    assert cv[2].tolist() == [0, 0, 0, 4, 0, 0, 3, 0]
    assert seen[2].tolist() == [False, True, True, True, True, True, True, False]
    assert not seen[[0, 1, 3, 4]].any()
    # the cells whose free state now differs from ``free`` (flat indices, beam order): (2, 3) keeps
    # cv 4 >= 3 and the hit (2, 6) gets 3, so neither becomes free
    assert touched[:n].tolist() == [2 * 8 + 1, 2 * 8 + 4, 2 * 8 + 5]
    for _ in range(10):  # saturates at cv_max
        himm_update(cv, seen, 2.5, 1.5, th, d, h, 3, 1, 15, free, 3, touched)
    assert cv[2, 6] == 15 and cv[2, 3] == 0


def test_line_of_sight_stops_short_of_wall_target():
    occ = np.zeros((5, 5), bool)
    occ[:, 4] = True
    assert line_of_sight(occ, 2.5, 0.5, 2.5, 4.0, 0.75)  # sign on the wall face
    occ[2, 2] = True
    assert not line_of_sight(occ, 2.5, 0.5, 2.5, 4.0, 0.75)


def test_fold_free_matches_refresh_over_the_box():
    # a cell freed, a cell made occupied, and one that flips and flips back within the batch:
    # only the two net changes grow the dirty box, as refresh_free over the scan's box does
    free = np.zeros((6, 6), bool)
    seen = np.zeros((6, 6), bool)
    cv = np.zeros((6, 6), np.uint8)
    seen[1, 1] = seen[4, 5] = seen[3, 2] = True
    cv[4, 5] = 7
    free[3, 2] = True  # seen, cv 0: free already
    dirty = np.array([6, -1, 6, -1])
    cells = np.array([1 * 6 + 1, 4 * 6 + 5, 3 * 6 + 2, 1 * 6 + 1])
    fold_free(free, seen, cv, 3, cells, 4, dirty)
    assert free[1, 1] and not free[4, 5] and free[3, 2]
    assert dirty.tolist() == [1, 1, 1, 1]  # (4, 5) was not free and still is not
    cv[3, 2] = 9
    fold_free(free, seen, cv, 3, cells, 3, dirty)
    assert not free[3, 2] and dirty.tolist() == [1, 3, 1, 2]


def _viewed(free, rows, first=0, viewed=None, stamp=None):
    H, W = free.shape
    viewed = np.zeros((H, W), np.uint8) if viewed is None else viewed
    stamp = np.full((H, W), -1, np.int64) if stamp is None else stamp
    mark_viewed(free, viewed, stamp, first, np.asarray(rows, np.float64).reshape(-1, 4), math.radians(30), 40.0)
    return viewed, stamp


def test_a_row_of_views_counts_as_that_many_views_one_after_the_other():
    """A pose repeated back to back is one row with its count (the belief's buffer keeps a robot
    that dwells, or publishes its pose at 200 Hz, at one row): the same viewed counts as one row
    per view, saturating at 255, and later views still count once per view."""
    rng = np.random.default_rng(5)
    free = rng.random((60, 80)) > 0.08
    poses = [(rng.uniform(5, 55), rng.uniform(5, 75), rng.uniform(-math.pi, math.pi)) for _ in range(12)]
    times = [1, 3, 1, 7, 2, 300, 1, 1, 4, 9, 1, 2]
    runs = [(*p, n) for p, n in zip(poses, times)]
    one_by_one = [(*p, 1) for p, n in zip(poses, times) for _ in range(n)]
    a, sa = _viewed(free, runs, first=10)
    b, sb = _viewed(free, one_by_one, first=10)
    assert a.max() == 255 and np.array_equal(a, b)
    # the next fold numbers its views after all of those: it counts once per view, as it would have
    later = [(*poses[5], 1), (*poses[5], 1)]
    a2, _ = _viewed(free, [(*poses[5], 2)], first=10 + sum(times), viewed=a.copy(), stamp=sa)
    b2, _ = _viewed(free, later, first=10 + len(one_by_one), viewed=b.copy(), stamp=sb)
    assert np.array_equal(a2, b2)
