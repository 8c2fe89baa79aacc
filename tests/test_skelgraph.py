"""The contracted skeleton graph (engine 2) against a brute-force search over the cells, after
random sequences of repairs."""

import heapq
import math

import numpy as np
import pytest

from semsearch_cli.kernels.skelgraph import SkeletonGraph

DR = [-1, 1, 0, 0, -1, -1, 1, 1]
DC = [0, 0, -1, 1, -1, 1, -1, 1]


def region(passable, r0, c0, radius):
    """Passable cells 4-connected to (r0, c0) within a disk of ``radius`` cells."""
    H, W = passable.shape
    if not passable[r0, c0]:
        return set()
    seen, todo = {(r0, c0)}, [(r0, c0)]
    while todo:
        r, c = todo.pop()
        for k in range(4):
            q = (r + DR[k], c + DC[k])
            if 0 <= q[0] < H and 0 <= q[1] < W and q not in seen and passable[q] and (q[0] - r0) ** 2 + (q[1] - c0) ** 2 <= radius * radius:
                seen.add(q)
                todo.append(q)
    return seen


def brute(gcell, passable, robot_passable, cost, r0, c0, t, radius):
    """Least cost from (r0, c0) to t over three layers: the robot's join region, the graph cells,
    the target's join region (when t is off the graph), joined at shared cells for free."""
    H, W = gcell.shape
    jr = region(robot_passable, r0, c0, radius)
    on_graph = bool(gcell[t])
    jt = set() if on_graph else region(passable, t[0], t[1], radius)
    layer_cells = {0: jr, 2: jt}

    def moves(layer, q):
        r, c = q
        for k in range(8):
            n = (r + DR[k], c + DC[k])
            if not (0 <= n[0] < H and 0 <= n[1] < W):
                continue
            step = 1.0 if k < 4 else math.sqrt(2)
            if layer == 1:
                if not gcell[n] or (k >= 4 and not (passable[r, n[1]] and passable[n[0], c])):
                    continue
                yield n, step
            else:
                cells = layer_cells[layer]
                if n not in cells or (k >= 4 and not ((r, n[1]) in cells and (n[0], c) in cells)):
                    continue
                yield n, step * cost[n]

    best = {}
    heap = [(0.0, 0, (r0, c0))] if (r0, c0) in jr else []
    while heap:
        d, layer, q = heapq.heappop(heap)
        if (layer, q) in best:
            continue
        best[(layer, q)] = d
        if q == t and (layer == 0 or (layer == 1 and on_graph) or (layer == 2 and not on_graph)):
            return d
        nxt = [(layer, n, s) for n, s in moves(layer, q)]
        if layer == 0 and gcell[q]:
            nxt.append((1, q, 0.0))
        if layer in (0, 1) and q in jt:
            nxt.append((2, q, 0.0))
        for lay, n, s in nxt:
            if (lay, n) not in best:
                heapq.heappush(heap, (d + s, lay, n))
    return math.inf


def random_maps(rng, H, W):
    skeleton = rng.random((H, W)) < 0.35
    passable = rng.random((H, W)) < 0.85
    return skeleton, passable


def costs_for(skeleton, rng):
    cost = 1.5 + 2.0 * rng.random(skeleton.shape)
    cost[skeleton] = 1.0
    return cost


def check_paths(g, res, gcell, passable, robot_passable, cost, r0, c0, targets):
    H, W = gcell.shape
    for (tr, tc) in targets:
        want_c = res.costs([tr], [tc])[0]
        want_l = res.lengths([tr], [tc])[0]
        p = res.path(tr, tc)
        if not np.isfinite(want_c):
            assert p is None
            continue
        rows, cols = p
        assert (rows[0], cols[0]) == (r0, c0) and (rows[-1], cols[-1]) == (tr, tc)
        dr, dc = np.diff(rows), np.diff(cols)
        assert np.all(np.maximum(np.abs(dr), np.abs(dc)) == 1), "a path of neighbouring cells"
        steps = np.hypot(dr, dc)
        assert abs(steps.sum() - want_l) < 1e-9
        assert abs((steps * np.where(gcell[rows[1:], cols[1:]], 1.0, cost[rows[1:], cols[1:]])).sum() - want_c) < 1e-9
        assert all(passable[r, c] or robot_passable[r, c] for r, c in zip(rows, cols))


@pytest.mark.parametrize("seed", range(6))
def test_graph_distances_match_brute_force_after_repairs(seed):
    rng = np.random.default_rng(seed)
    H, W = 22, 26
    g = SkeletonGraph((H, W))
    skeleton = np.zeros((H, W), bool)
    passable = np.zeros((H, W), bool)
    base_sk, base_pa = random_maps(rng, H, W)
    for step in range(6):
        # change a random box: first the whole map, then small windows (as a robot's map grows)
        if step == 0:
            r0, r1, c0, c1 = 0, H, 0, W
        else:
            r0, c0 = rng.integers(0, H - 4), rng.integers(0, W - 4)
            r1, c1 = r0 + rng.integers(2, 8), c0 + rng.integers(2, 8)
        new_sk, new_pa = skeleton.copy(), passable.copy()
        sk2, pa2 = random_maps(rng, H, W)
        new_sk[r0:r1, c0:c1] = (base_sk if step == 0 else sk2)[r0:r1, c0:c1]
        new_pa[r0:r1, c0:c1] = (base_pa if step == 0 else pa2)[r0:r1, c0:c1]
        new_pa |= new_sk & (rng.random((H, W)) < 0.5)  # most skeleton cells passable
        changed = np.flatnonzero((new_sk != skeleton) | (new_pa != passable))
        skeleton, passable = new_sk, new_pa
        g.repair(skeleton, passable, changed)
        fresh = SkeletonGraph((H, W))
        fresh.repair(skeleton, passable, np.arange(H * W))
        gcell = skeleton & passable
        cost = costs_for(skeleton, rng)
        for _ in range(3):
            pr, pc = np.nonzero(passable)
            i = rng.integers(len(pr))
            r, c = int(pr[i]), int(pc[i])
            tr, tc = np.nonzero(passable | gcell)
            pick = rng.choice(len(tr), size=min(25, len(tr)), replace=False)
            targets = list(zip(tr[pick].tolist(), tc[pick].tolist()))
            radius = 2.5
            res = g.search(r, c, passable, passable, cost, tr[pick], tc[pick], 0, radius)
            ref = fresh.search(r, c, passable, passable, cost, tr[pick], tc[pick], 0, radius)
            got = res.costs(tr[pick], tc[pick])
            # the graph is the same whatever the repairs that made it: the same numbers and paths, bit for bit
            assert g.n_nodes == fresh.n_nodes and g.n_edges == fresh.n_edges
            assert np.array_equal(got, ref.costs(tr[pick], tc[pick]))
            assert np.array_equal(res.lengths(tr[pick], tc[pick]), ref.lengths(tr[pick], tc[pick]))
            want = np.array([brute(gcell, passable, passable, cost, r, c, t, radius) for t in targets])
            assert np.array_equal(np.isfinite(got), np.isfinite(want))
            fin = np.isfinite(want)
            assert np.allclose(got[fin], want[fin], rtol=0, atol=1e-9)
            check_paths(g, res, gcell, passable, passable, cost, r, c, targets)
            for t in targets:
                a, b = res.path(*t), None
                ref = fresh.search(r, c, passable, passable, cost, tr[pick], tc[pick], 0, radius)
                b = ref.path(*t)
                assert (a is None) == (b is None) and (a is None or (np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])))
                res = g.search(r, c, passable, passable, cost, tr[pick], tc[pick], 0, radius)


def test_n_stop_keeps_the_cheapest_targets_by_cost_then_cell():
    H, W = 5, 12
    skeleton = np.zeros((H, W), bool)
    skeleton[2, 1:11] = True
    passable = np.zeros((H, W), bool)
    passable[1:4, :] = True
    g = SkeletonGraph((H, W))
    g.repair(skeleton, passable, np.arange(H * W))
    assert g.n_nodes == 2 and g.n_edges == 1  # one corridor: two ends, one chain
    cost = np.where(skeleton, 1.0, 2.0)
    # from the middle, cells 3 left and 3 right are equally far: the lower cell index wins
    res = g.search(2, 5, passable, passable, cost, [2, 2, 2], [8, 2, 10], 1, 1.5)
    assert list(np.isfinite(res.lengths([2, 2, 2], [8, 2, 10]))) == [False, True, False]
    res = g.search(2, 5, passable, passable, cost, [2, 2, 2], [8, 2, 10], 2, 1.5)
    assert list(res.lengths([2, 2, 2], [8, 2, 10])) == [3.0, 3.0, np.inf]


def test_a_cycle_without_junctions_and_its_repair():
    H, W = 7, 7
    skeleton = np.zeros((H, W), bool)
    skeleton[1, 2:5] = skeleton[5, 2:5] = skeleton[2:5, 1] = skeleton[2:5, 5] = True  # a ring with cut corners
    passable = np.ones((H, W), bool)
    g = SkeletonGraph((H, W))
    g.repair(skeleton, passable, np.arange(H * W))
    assert g.n_nodes == 1 and g.n_edges == 1  # one node on the ring, one loop edge
    cost = np.where(skeleton, 1.0, 3.0)
    res = g.search(1, 3, passable, passable, cost, [5], [3], 0, 0.5)
    assert res.lengths([5], [3])[0] == pytest.approx(4 + 2 * math.sqrt(2))
    skeleton[3, 5] = False  # cut the ring: a path with two ends
    g.repair(skeleton, passable, np.array([3 * W + 5]))
    assert g.n_nodes == 2 and g.n_edges == 1  # a path: its two ends
    res = g.search(2, 5, passable, passable, cost, [4], [5], 0, 0.5)
    assert res.lengths([4], [5])[0] == pytest.approx(6 + 4 * math.sqrt(2))  # the long way round
    rows, cols = res.path(4, 5)
    assert len(rows) == 11


def test_a_dropped_edge_leaves_no_record_that_passes_for_a_live_one():
    """Review's case: a ring with a spur; the spur goes (the ring's node is reused), then a
    passable cell off the skeleton changes beside the ring. A dropped edge's cells once still read
    as that edge, so the ring was left without a node and its path walked for ever."""
    H, W = 12, 12
    skeleton = np.zeros((H, W), bool)
    skeleton[2, 2:7] = skeleton[6, 2:7] = skeleton[2:7, 2] = skeleton[2:7, 6] = True
    skeleton[7:10, 4] = True
    passable = skeleton.copy()
    passable[1, 4] = True
    g = SkeletonGraph((H, W))
    g.repair(skeleton, passable, np.arange(H * W))
    skeleton[7:10, 4] = False
    passable[7:10, 4] = False
    g.repair(skeleton, passable, np.array([7 * W + 4, 8 * W + 4, 9 * W + 4]))
    passable[1, 4] = False
    g.repair(skeleton, passable, np.array([1 * W + 4]))
    fresh = SkeletonGraph((H, W))
    fresh.repair(skeleton, passable, np.arange(H * W))
    assert (g.n_nodes, g.n_edges) == (fresh.n_nodes, fresh.n_edges) and g.n_nodes > 0
    cost = np.where(skeleton, 1.0, 3.0)
    a = g.search(2, 4, passable, passable, cost, [5], [2], 0, 0.5)
    b = fresh.search(2, 4, passable, passable, cost, [5], [2], 0, 0.5)
    assert np.array_equal(a.lengths([5], [2]), b.lengths([5], [2]))
    pa, pb = a.path(5, 2), b.path(5, 2)
    assert np.array_equal(pa[0], pb[0]) and np.array_equal(pa[1], pb[1])
