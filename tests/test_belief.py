import heapq
import math
import os

import numpy as np
import pytest

from semsearch_cli.belief import DoorBelief
from semsearch_cli.config import BeliefSpec
from semsearch_cli.geometry import GridFrame
from semsearch_cli.kernels.grid import BUCKETS, GridSearch, _dijkstra, dijkstra, local_reach
from semsearch_cli.kernels.memory import lazy_zeros
from semsearch_cli.kernels.raycast import cast_rays
from tests.test_skeleton import brute_thin


def make_belief(free):
    H, W = free.shape
    b = DoorBelief(GridFrame(0.1, 0.0, 0.0, H, W), BeliefSpec(), robot_radius=0.05)
    b.seen[:] = True
    b.cv[~free] = 10
    b.refresh_free(np.array([0, H - 1, 0, W - 1]))
    b.refresh_derived()
    return b


def test_skeleton_of_corridor_is_its_centre_line():
    free = np.zeros((7, 12), bool)
    free[2:5, 1:11] = True  # a 3-cell corridor
    b = make_belief(free)
    expected = np.zeros_like(free)
    expected[3, 2:9] = True  # Zhang and Suen's thinning keeps the centre row, short of both ends
    assert (b.skeleton == expected).all()
    assert b.graph.n_nodes == 2 and b.graph.n_edges == 1


def test_skeleton_refresh_matches_thinning_the_whole_map():
    # a corridor grid (corridors 20 cells wide)
    free = np.zeros((120, 160), bool)
    for k in range(10, 110, 40):
        free[k : k + 20, 10:150] = True
    for k in range(10, 150, 45):
        free[10:110, k : k + 20] = True
    b = make_belief(free)
    # an obstacle appears in one corridor: only the part of the thinning that changes is redone
    b.cv[55:58, 80:83] = 10
    b.refresh_free(np.array([55, 57, 80, 82]))
    b.refresh_derived()
    assert (b.skeleton == brute_thin(b.free)).all()


def test_local_reach_does_not_leak_through_diagonal_wall():
    free = np.ones((6, 6), bool)
    for k in range(6):
        free[k, 5 - k] = False  # an 8-connected diagonal wall
    rr, cc = local_reach(free, 0, 0, 10.0, False)
    assert len(rr) == 15  # the upper-left triangle only
    assert (rr + cc < 5).all()


def test_dijkstra_lengths_and_no_corner_cutting():
    p = np.ones((3, 3), bool)
    p[0, 1] = False
    p[1, 0] = False
    t = np.zeros_like(p)
    t[2, 2] = True
    dist, length, _ = dijkstra(p, np.ones((1, 1), np.float32), np.array([0]), np.array([0]), t, 0, np.inf)
    assert np.isinf(dist[1, 1])  # (0,0) -> (1,1) would cut two blocked corners
    p[1, 0] = True
    dist, length, _ = dijkstra(p, np.ones((1, 1), np.float32), np.array([0]), np.array([0]), t, 0, np.inf)
    assert length[2, 2] == 1 + 2 ** 0.5 + 1 or abs(length[2, 2] - (2 + 2 ** 0.5)) < 1e-12


def plus_belief():
    """A plus-shaped junction of 5-cell-wide corridors, visited in the middle."""
    free = np.zeros((61, 61), bool)
    free[28:33, 2:59] = True
    free[2:59, 28:33] = True
    b = make_belief(free)
    b.visit(30, 30)  # visited radius 1.2 m = 12 cells: rows/cols 18..42 on the arms
    return b


def test_frontier_candidates_and_theta_f_on_a_junction():
    b = plus_belief()
    c = b.candidates()
    assert len(c) == 4
    got = sorted((int(r), int(cc), round(float(np.degrees(t)))) for r, cc, t in zip(c.rows, c.cols, c.theta))
    # one candidate per branch, on the centre line, just outside the visited disk, pointing out
    assert got == [(17, 30, 90), (30, 17, -180), (30, 43, 0), (43, 30, -90)]  # theta in [-180, 180)
    # each touches a visited cell
    assert b.visited[c.seg_rows, c.seg_cols].all()


def test_candidates_drop_explored_dead_end():
    b = plus_belief()
    for r in range(30, 60):
        b.visit(r, 30)  # walk down the south branch to its end
    c = b.candidates()
    dirs = sorted(round(float(np.degrees(t))) for t in c.theta)
    assert dirs == [-180, 0, 90]


def test_density_class_of_corridor_and_junction():
    b = plus_belief()
    # Manhattan kernel r = 2.4 m (24 cells) at the junction: 5 x (24+24+1) cells in each arm, minus overlap
    assert b.seg_class[30, 30] == int(np.floor((2 * 5 * 49 - 25) * 0.01 / 2.5))
    lab = b.segment_labels()
    assert lab[30, 30] > 0 and lab[0, 0] == 0


def test_door_lists_count_min_reads_and_follow_segments():
    b = plus_belief()
    W = b.free.shape[1]
    b.visit(30, 55)  # far down the east arm: a corridor segment, class lower than the junction's
    junction, east = 30 * W + 30, 30 * W + 55
    for _ in range(3):
        b.reads.add(101, junction, 3.0, 3.0, 0.0)
    b.reads.add(102, junction, 3.0, 3.0, 0.0)  # read twice only: below min_reads = 3
    b.reads.add(102, junction, 3.0, 3.0, 0.0)
    b.reads.add(103, east, 4.4, 3.0, 0.0)
    b.reads.add(103, east, 4.6, 3.0, 0.0)
    b.reads.add(103, junction, 3.0, 3.0, 0.0)
    lists = b.door_lists()
    seg = b.segment_labels()
    sj, se = int(seg[30, 30]), int(seg[30, 55])
    assert sj != se
    assert lists[sj] == {101: (3, 3.0, 3.0), 103: (1, 3.0, 3.0)}
    assert lists[se] == {103: (2, 4.5, 3.0)}
    # the planners' flood-fill view agrees, and cells of one segment share its lists
    seg_i, seg_lists = b.segment_door_lists(np.array([30, 30, 30, 0]), np.array([30, 55, 50, 0]))
    assert seg_i.tolist() == [0, 1, 1, -1]
    assert seg_lists == [lists[sj], lists[se]]


def test_segments_kept_while_visiting_match_labelling_the_map():
    # a walk through a grid of corridors and rooms: the union-find segments kept by visit() are
    # exactly the connected components of each density class (what segment_labels labels)
    rng = np.random.default_rng(3)
    free = np.zeros((90, 120), bool)
    free[10:16, 5:115] = True
    free[50:58, 5:115] = True
    free[5:85, 20:26] = True
    free[5:85, 80:95] = True  # a wide corridor: another density class
    free[62:80, 40:70] = True  # a room off the lower corridor
    free[58:62, 50:53] = True
    b = make_belief(free)
    rr, cc = np.nonzero(free)
    for i in rng.choice(len(rr), 60, replace=False):
        b.visit(int(rr[i]), int(cc[i]))
    lab = b.segment_labels()
    vr, vc = np.nonzero(b.visited)
    seg, _ = b.segment_door_lists(vr, vc)
    assert (seg >= 0).all()
    # one segment index per label and one label per segment index
    pairs = set(zip(seg.tolist(), lab[vr, vc].tolist()))
    assert len(pairs) == len(set(seg.tolist())) == len(set(lab[vr, vc].tolist())) > 3


def test_search_heap_grows_without_changing_the_result():
    rng = np.random.default_rng(0)
    p = rng.random((80, 80)) > 0.2
    p[0, 0] = True
    cost = (1 + rng.random((80, 80))).astype(np.float32)
    tr, tc = np.nonzero(p)
    small, big = GridSearch(p.shape), GridSearch(p.shape)
    small._hk, small._hi = np.empty(2), np.empty(2, np.int64)  # full at once: grown and searched again
    assert small.run(p, cost, 0, 0, tr, tc) == big.run(p, cost, 0, 0, tr, tc)
    assert small._hk.size > 2
    assert np.array_equal(small.costs(tr, tc), big.costs(tr, tc))
    assert np.array_equal(small.lengths(tr, tc), big.lengths(tr, tc))
    far = int(np.argmax(np.where(np.isfinite(big.costs(tr, tc)), big.costs(tr, tc), -1)))
    assert big.costs(tr, tc)[far] > 50
    assert np.array_equal(np.stack(small.path(int(tr[far]), int(tc[far]))), np.stack(big.path(int(tr[far]), int(tc[far]))))


def _heap_only(gs, p, cost, tr, tc):
    """A search with the heap alone (no Dial buckets), as GridSearch.run falls back to."""
    H, W = p.shape
    gs.gen += 1
    gs.tmark[tr * W + tc] = gs.gen
    hk, hi = np.empty(1 << 16), np.empty(1 << 16, np.int64)
    return _dijkstra(p.ravel(), cost.ravel(), H, W, np.array([0], np.int64), gs.tmark, 0, np.inf, gs.state, gs.parent,
                     gs.stamp, gs.gen, hk, hi, gs._bk, gs._bi, gs._bn, False, -1)


@pytest.mark.parametrize("low", [1.0, 0.5])
def test_dial_buckets_settle_as_the_heap_does(low):
    """Dial's buckets give the heap's costs, lengths and parents bit for bit (ties included: costs
    drawn from a few values); a step cheaper than one cell (low 0.5) falls back to the heap, and
    buckets too small for a search grow."""
    rng = np.random.default_rng(3)
    p = rng.random((70, 90)) > 0.15
    p[0, 0] = True
    cost = rng.choice(np.array([low, 1.0, 1.5, 2.0, 3.5], np.float32), size=p.shape)
    tr, tc = np.nonzero(p)
    dial, heap = GridSearch(p.shape), GridSearch(p.shape)
    dial._bk, dial._bi = np.empty((BUCKETS, 2)), np.empty((BUCKETS, 2), np.int64)
    assert dial.run(p, cost, 0, 0, tr, tc) == _heap_only(heap, p, cost, tr, tc) > 5000
    assert dial._bk.shape[1] > 2  # grown
    H, W = p.shape
    dial.gen += 1  # the buckets alone, as the first try: a step under one cell ends it
    with_buckets = _dijkstra(p.ravel(), cost.ravel(), H, W, np.array([0], np.int64), dial.tmark, 0, np.inf, dial.state,
                             dial.parent, dial.stamp, dial.gen, dial._hk, dial._hi, dial._bk, dial._bi, dial._bn, True, -1)
    assert (with_buckets == -2) == (low < 1.0)
    dial.run(p, cost, 0, 0, tr, tc)
    for a in (dial, heap):
        assert a.stamp.max() == 2 * a.gen + 1
    done = dial.stamp == 2 * dial.gen + 1
    assert np.array_equal(done, heap.stamp == 2 * heap.gen + 1)
    assert np.array_equal(dial.state[done], heap.state[done]) and np.array_equal(dial.parent[done], heap.parent[done])


def _reference_dijkstra(p, cost, sources, targets, n_stop, max_cost, stop):
    """Dijkstra as a textbook writes it: heapq over (cost, cell index), a cell's cost and parent
    changed only by a strictly cheaper offer, the same 8 moves without corner cutting."""
    H, W = p.shape
    moves = ((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1))
    dist, length, parent, done, heap = {}, {}, {}, set(), []
    for r, c in sources:
        if p[r, c]:
            q = r * W + c
            dist[q], length[q], parent[q] = 0.0, 0.0, -1
            heapq.heappush(heap, (0.0, q))
    wanted, hit = {r * W + c for r, c in targets}, 0
    while heap:
        d, q = heapq.heappop(heap)
        if q in done:
            continue
        if d > max_cost:
            break
        done.add(q)
        if q in wanted:
            hit += 1
            if n_stop and hit >= n_stop:
                break
        if stop is not None and q == stop[0] * W + stop[1]:
            break
        r, c = divmod(q, W)
        for k, (dr, dc) in enumerate(moves):
            nr, nc = r + dr, c + dc
            if not (0 <= nr < H and 0 <= nc < W) or nr * W + nc in done or not p[nr, nc]:
                continue
            if k >= 4 and (not p[r, nc] or not p[nr, c]):
                continue
            step = math.sqrt(2.0) if k >= 4 else 1.0
            nd, n = d + step * float(cost[nr, nc]), nr * W + nc
            if n not in dist or nd < dist[n]:
                dist[n], length[n], parent[n] = nd, length[q] + step, q
                heapq.heappush(heap, (nd, n))
    return hit, done, dist, length, parent


@pytest.mark.parametrize("low, n_stop, max_cost, stop", [(1.0, 0, np.inf, None), (1.0, 6, np.inf, None), (1.0, 0, 25.0, None),
                                                         (1.0, 0, np.inf, (30, 40)), (0.5, 0, 30.0, None)])
def test_the_search_settles_as_a_textbook_heap_does(low, n_stop, max_cost, stop):
    """Several sources, a stop after n targets, at a cost, or at a cell; costs from a few values
    (ties everywhere): the same cells settled, with the same costs, lengths and parents bit for
    bit, as heapq's Dijkstra over (cost, cell index) (low 0.5: steps under one cell, the heap alone)."""
    rng = np.random.default_rng(11)
    p = rng.random((45, 60)) > 0.2
    cost = rng.choice(np.array([low, 1.0, 1.5, 2.0, 3.5], np.float32), size=p.shape)
    sources = [(2, 3), (40, 55), (20, 30)]
    for r, c in sources + [stop or (0, 0)]:
        p[r, c] = True
    tr, tc = np.nonzero(p & (rng.random(p.shape) < 0.05))
    gs = GridSearch(p.shape)
    got = gs.run(p, cost, [r for r, _ in sources], [c for _, c in sources], tr, tc, n_stop, max_cost, stop)
    hit, done, dist, length, parent = _reference_dijkstra(p, cost, sources, list(zip(tr, tc)), n_stop, max_cost, stop)
    assert got == hit and len(done) > 50
    W = p.shape[1]
    settled = np.flatnonzero(gs.stamp == 2 * gs.gen + 1)
    assert set(settled.tolist()) == done
    q = np.array(sorted(done))
    assert np.array_equal(gs.state[q, 0], [dist[i] for i in q]) and np.array_equal(gs.state[q, 1], [length[i] for i in q])
    assert np.array_equal(gs.parent[q], [parent[i] for i in q])
    far = int(q[np.argmax(gs.state[q, 0])])
    rows, cols = gs.path(far // W, far % W)
    assert rows[0] * W + cols[0] in {r * W + c for r, c in sources} and (rows[-1], cols[-1]) == (far // W, far % W)


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_lazy_grids_are_zero_and_private_to_each_process():
    a = lazy_zeros((300, 400), np.int32)
    assert a.shape == (300, 400) and a.dtype == np.int32 and a.flags.c_contiguous and not a.any()
    pid = os.fork()
    if pid == 0:  # a forked worker writes into its copy
        a[:] = 7
        os._exit(0)
    os.waitpid(pid, 0)
    assert not a.any()  # the parent's grid is untouched (a shared map would show the 7s)
    assert lazy_zeros((0, 5), bool).shape == (0, 5)


def test_fold_scan_with_a_full_change_buffer_matches_a_roomy_one():
    # a scan that frees many cells at once overflows a small buffer: the belief refreshes over the
    # scan's box instead, with the same free map and dirty box, and makes room for the next scan
    occ = np.zeros((80, 90), bool)
    occ[:, 85:] = True
    occ[10, 20:60] = True
    thetas = np.linspace(-np.pi / 2, np.pi / 2, 91)
    dist, hit = cast_rays(occ, 40.5, 30.5, thetas, 50.0)
    beliefs = []
    for size in (1, 100_000):
        b = DoorBelief(GridFrame(0.1, 0.0, 0.0, 80, 90), BeliefSpec(), robot_radius=0.05)
        b._touched = np.empty(size, np.int64)
        b.fold_scan(40.5, 30.5, thetas, dist, hit)
        beliefs.append(b)
    small, roomy = beliefs
    assert roomy.free.sum() > 500
    assert np.array_equal(small.free, roomy.free) and np.array_equal(small.cv, roomy.cv)
    assert small.dirty.tolist() == roomy.dirty.tolist()
    assert small._touched.shape[0] > 500  # room for as many changes next time


@pytest.mark.parametrize("buffer", [1, 100_000])
def test_lost_counts_the_free_cells_a_scan_turns_to_walls(buffer):
    # an open room scanned, then a wall appearing across free space (a door closed): the cells it
    # covers stop being free, and DoorBelief.lost (the events re-planning policy's trigger) counts
    # them, through the kernel and through the refresh of a whole box alike
    occ = np.zeros((80, 90), bool)
    occ[:, 85:] = True
    thetas = np.linspace(-np.pi / 2, np.pi / 2, 181)
    b = DoorBelief(GridFrame(0.1, 0.0, 0.0, 80, 90), BeliefSpec(), robot_radius=0.05)
    b.fold_scan(40.5, 30.5, thetas, *cast_rays(occ, 40.5, 30.5, thetas, 50.0))
    assert b.lost == 0 and b.free[40, 60]
    occ[:, 60] = True
    b._touched = np.empty(buffer, np.int64)
    for _ in range(10):  # HIMM needs several hits before a cell counts as occupied
        b.fold_scan(40.5, 30.5, thetas, *cast_rays(occ, 40.5, 30.5, thetas, 50.0))
    lost = int((~b.free[:, 60] & b.seen[:, 60]).sum())
    assert not b.free[40, 60] and lost > 10 and b.lost == lost


def test_fold_grid_takes_a_window_of_another_mapper_and_marks_what_changed():
    H, W = 12, 16
    b = DoorBelief(GridFrame(0.1, 0.0, 0.0, H, W), BeliefSpec(), robot_radius=0.05)
    seen = np.ones((3, 4), bool)
    free = np.array([[1, 1, 0, 1], [1, 1, 1, 1], [0, 0, 1, 1]], bool)
    b.fold_grid(5, 6, seen, free)
    assert b.seen.sum() == 12 and np.array_equal(b.free[5:8, 6:10], free) and b.free.sum() == 9
    assert b.lost == 0 and b.dirty.tolist() == [5, 7, 6, 9]  # the free cells' rows 5-7, columns 6-9
    b.dirty[:] = (H, -1, W, -1)
    gone = free.copy()
    gone[1, 2] = False  # a wall seen where the map had free space
    b.fold_grid(5, 6, seen, gone)
    assert b.lost == 1 and b.dirty.tolist() == [6, 6, 8, 8] and not b.free[6, 8]
    b.dirty[:] = (H, -1, W, -1)
    b.fold_grid(5, 6, seen, gone)  # nothing new: nothing dirty
    assert b.lost == 1 and b.dirty.tolist() == [H, -1, W, -1]


def test_views_waiting_are_one_row_per_pose_and_fold_as_every_view():
    """200 copies of one pose (a robot standing while its stack publishes) wait as one row; 100
    poses that differ as 100 rows (the buffer grows past its first 64); the viewed counts after the
    fold are those of a belief given the same poses with no two alike back to back."""
    free = np.ones((40, 60), bool)
    free[:, 0] = free[:, -1] = free[0] = free[-1] = False
    a, b = make_belief(free), make_belief(free)
    for _ in range(200):
        a.add_view(20.0, 30.0, 0.0)
    for k in range(100):
        a.add_view(20.0, 10.0 + 0.4 * k, 0.5)
        b.add_view(20.0, 10.0 + 0.4 * k, 0.5)
    assert a._n_pending == 101
    a.unread_walls(2.0, np.radians(30), 0.3, 3)
    b.unread_walls(2.0, np.radians(30), 0.3, 3)
    seen_from_the_standing_pose = a.viewed.astype(int) - b.viewed.astype(int)
    assert seen_from_the_standing_pose.max() == 200 and seen_from_the_standing_pose.min() == 0
    assert a._n_views == 300 and a._n_pending == 0
