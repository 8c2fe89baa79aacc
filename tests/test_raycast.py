import math

import numpy as np

from semsearch_cli.kernels.raycast import cast_ray, cast_rays, himm_update, line_of_sight


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
    bbox = np.array([99, -1, 99, -1])
    th = np.array([0.0])
    d, h = cast_rays(occ, 2.5, 1.5, th, 10.0)
    himm_update(cv, seen, 2.5, 1.5, th, d, h, 3, 1, 15, bbox)
    assert cv[2].tolist() == [0, 0, 0, 4, 0, 0, 3, 0]
    assert seen[2].tolist() == [False, True, True, True, True, True, True, False]
    assert not seen[[0, 1, 3, 4]].any()
    assert bbox.tolist() == [2, 2, 1, 6]
    for _ in range(10):  # saturates at cv_max
        himm_update(cv, seen, 2.5, 1.5, th, d, h, 3, 1, 15, bbox)
    assert cv[2, 6] == 15 and cv[2, 3] == 0


def test_line_of_sight_stops_short_of_wall_target():
    occ = np.zeros((5, 5), bool)
    occ[:, 4] = True
    assert line_of_sight(occ, 2.5, 0.5, 2.5, 4.0, 0.75)  # sign on the wall face
    occ[2, 2] = True
    assert not line_of_sight(occ, 2.5, 0.5, 2.5, 4.0, 0.75)
