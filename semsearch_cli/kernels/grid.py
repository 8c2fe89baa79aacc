"""Pure grid kernels (numba): local flood fill, Dijkstra, skeleton branch walks.

Free-space connectivity is 4-connected (walls rasterised as 8-connected lines must not leak);
path moves are 8-connected, a diagonal move needing both orthogonal cells passable (no corner
cutting). All distances are in cells unless a name says otherwise.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .memory import lazy_zeros

SQRT2 = math.sqrt(2.0)
_DR8 = np.array([-1, 1, 0, 0, -1, -1, 1, 1], np.int64)
_DC8 = np.array([0, 0, -1, 1, -1, 1, -1, 1], np.int64)


@njit(cache=True)
def local_reach(free, r0, c0, radius, manhattan):
    """Free cells 4-connected to (r0, c0) without leaving a kernel of ``radius`` cells.

    Parameters
    ----------
    free : (H, W) bool
    r0, c0 : int
        Seed cell; if it is not free the result is empty.
    radius : float
        Kernel radius, cells (Euclidean disk, or Manhattan diamond when ``manhattan``).

    Returns
    -------
    rows, cols : (n,) int64
        The reached cells (the thesis' T with Q = 1, Eqs. 4.1-4.3).
    """
    H, W = free.shape
    R = int(math.ceil(radius))
    S = 2 * R + 1
    mark = np.zeros((S, S), np.bool_)
    qr = np.empty(S * S, np.int64)
    qc = np.empty(S * S, np.int64)
    if r0 < 0 or r0 >= H or c0 < 0 or c0 >= W or not free[r0, c0]:
        return qr[:0], qc[:0]
    head = 0
    tail = 1
    qr[0] = r0
    qc[0] = c0
    mark[R, R] = True
    rad2 = radius * radius
    while head < tail:
        r = qr[head]
        c = qc[head]
        head += 1
        for k in range(4):
            nr = r + _DR8[k]
            nc = c + _DC8[k]
            if nr < 0 or nr >= H or nc < 0 or nc >= W:
                continue
            lr = nr - r0 + R
            lc = nc - c0 + R
            if lr < 0 or lr >= S or lc < 0 or lc >= S or mark[lr, lc]:
                continue
            dr = nr - r0
            dc = nc - c0
            if manhattan:
                if abs(dr) + abs(dc) > radius:
                    continue
            elif dr * dr + dc * dc > rad2:
                continue
            if not free[nr, nc]:
                continue
            mark[lr, lc] = True
            qr[tail] = nr
            qc[tail] = nc
            tail += 1
    return qr[:tail], qc[:tail]


@njit(cache=True)
def set_joins(passable, mask, rows, cols, radius, out):
    """Set ``mask`` at the cells of ``passable`` 4-connected to each (rows[i], cols[i]) within
    ``radius`` cells (see :func:`local_reach`); the flat indices of the cells it set (those not
    set before) go to ``out``, whose size must be at least len(rows) * (2 ceil(radius) + 1)^2.
    Returns how many."""
    W = mask.shape[1]
    n = 0
    for i in range(rows.shape[0]):
        jr, jc = local_reach(passable, rows[i], cols[i], radius, False)
        for k in range(jr.shape[0]):
            if not mask[jr[k], jc[k]]:
                mask[jr[k], jc[k]] = True
                out[n] = jr[k] * W + jc[k]
                n += 1
    return n


@njit(cache=True)
def mark_visited(free, visited, seg_class, seg_parent, r0, c0, radius, density_radius, res, delta):
    """Mark visited the free cells 4-connected to (r0, c0) within ``radius`` cells (a disk) and
    give the newly visited ones the density class ``floor(n res^2 / delta)`` (m^2 over delta), n
    the free cells 4-connected to (r0, c0) within a Manhattan kernel of ``density_radius`` cells
    (thesis Eqs. 4.1-4.4); cells visited before keep their class.

    Segments (thesis 4.2.2: visited cells 8-connected through cells of one density class) are kept
    as a union-find forest over flat cell indices in ``seg_parent`` (H * W,) int32: each newly
    visited cell joins the segments of its visited neighbours of its class (see
    :func:`segment_roots`). A cell's class never changes, so segments only ever merge.

    Returns (number of cells newly visited, rmin, rmax, cmin, cmax of them).
    """
    H, W = free.shape
    vr, vc = local_reach(free, r0, c0, radius, False)
    new = np.empty(vr.shape[0], np.int64)
    n_new = 0
    for i in range(vr.shape[0]):
        if not visited[vr[i], vc[i]]:
            new[n_new] = i
            n_new += 1
    if n_new == 0:
        return 0, 0, -1, 0, -1
    dr, _ = local_reach(free, r0, c0, density_radius, True)
    cls = math.floor(dr.shape[0] * res * res / delta)
    rmin, rmax, cmin, cmax = H, -1, W, -1
    for j in range(n_new):
        r = vr[new[j]]
        c = vc[new[j]]
        visited[r, c] = True
        seg_class[r, c] = cls
        seg_parent[r * W + c] = r * W + c
        rmin = min(rmin, r)
        rmax = max(rmax, r)
        cmin = min(cmin, c)
        cmax = max(cmax, c)
    for j in range(n_new):  # each new cell joins the segments of its neighbours of its class
        r = vr[new[j]]
        c = vc[new[j]]
        for k in range(8):
            nr = r + _DR8[k]
            nc = c + _DC8[k]
            if 0 <= nr < H and 0 <= nc < W and visited[nr, nc] and seg_class[nr, nc] == seg_class[r, c]:
                a = _root(seg_parent, r * W + c)
                b = _root(seg_parent, nr * W + nc)
                if a != b:
                    seg_parent[max(a, b)] = min(a, b)
    return n_new, rmin, rmax, cmin, cmax


@njit(cache=True, inline="always")
def _root(parent, q):
    while parent[q] != q:
        parent[q] = parent[parent[q]]  # path halving
        q = parent[q]
    return q


@njit(cache=True)
def segment_roots(seg_parent, visited, cells):
    """The segment of each flat cell index in ``cells`` (its union-find root, see
    :func:`mark_visited`), -1 where the cell is not visited."""
    W = visited.shape[1]
    out = np.full(cells.shape[0], -1, np.int64)
    for i in range(cells.shape[0]):
        q = cells[i]
        if visited[q // W, q % W]:
            out[i] = _root(seg_parent, q)
    return out


@njit(cache=True, inline="always")
def heap_before(k1, i1, k2, i2):
    """Heap order: by cost, then by cell index (so that every heap pops cells in one order)."""
    return k1 < k2 or (k1 == k2 and i1 < i2)


@njit(cache=True, inline="always")
def heap_push(hk, hi, n, k, i):
    """Put (k, i) into the 4-ary heap of the first ``n`` entries of (hk, hi) (a 4-ary heap is half
    as deep as a binary one, and its four children share a cache line)."""
    j = n
    while j > 0:
        p = (j - 1) >> 2
        if not heap_before(k, i, hk[p], hi[p]):
            break
        hk[j] = hk[p]
        hi[j] = hi[p]
        j = p
    hk[j] = k
    hi[j] = i


@njit(cache=True, inline="always")
def heap_drop_top(hk, hi, n):
    """Remove the top of the heap of ``n`` entries (it then holds n - 1)."""
    n -= 1
    k = hk[n]
    i = hi[n]
    j = 0
    while True:
        ch = 4 * j + 1
        if ch >= n:
            break
        best = ch
        for q in range(ch + 1, min(ch + 4, n)):
            if heap_before(hk[q], hi[q], hk[best], hi[best]):
                best = q
        if not heap_before(hk[best], hi[best], k, i):
            break
        hk[j] = hk[best]
        hi[j] = hi[best]
        j = best
    hk[j] = k
    hi[j] = i


BUCKETS = 8  # Dial's buckets of unit width, used in turn: a step may cost up to 7 cells (the maps' costs reach sqrt(2) x 3.5)


@njit(cache=True)
def _dijkstra(passable, cost, H, W, src, tmark, n_stop, max_cost, state, parent, stamp, gen, hk, hi, bk, bi, bn, dial,
              stop_idx):
    """Multi-source Dijkstra on an 8-connected grid with per-cell cost multipliers.

    Every grid is flat (index ``r * W + c``). Moving into cell q costs ``step * cost[q]`` with
    step 1 or sqrt(2); ``cost`` of size 1 means a uniform cost of 1. Cells with ``tmark == gen``
    are targets; the search stops once ``n_stop`` of them are settled (0: never), once the cell
    ``stop_idx`` is settled (-1: no such cell), or when the cost exceeds ``max_cost``. A settled
    cell's parent is final, so a search stopped at a cell holds the same path to it as the search
    run on.

    The state is reused across searches and never cleared: ``state[q]`` holds (cost, length) and
    ``parent[q]`` the previous cell, valid only where ``stamp[q]`` says this search reached q
    (``2 gen``, queued) or settled it (``2 gen + 1``), so a search costs what it explores, not the
    grid size; one cell's numbers share a cache line.

    Cells settle in the order of (cost, cell index): the order of any correct priority queue over
    these keys (they are distinct), so ties resolve alike whatever the queue. The queue is a 4-ary
    heap in (hk, hi); with ``dial``, Dial's buckets in front of it: a cell queued at cost d waits
    in bucket floor(d) (``bk``, ``bi``, ``bn``: :data:`BUCKETS` rows used in turn) and the heap
    holds only the bucket being settled. When every step costs at least 1, a cell settled from
    bucket k queues its neighbours in bucket k + 1 or later, so a bucket is complete before its
    turn and the heap settles it in key order: the same order as the heap alone, at a fraction of
    its cost. A step cheaper than 1, or so dear that it skips every bucket, ends the search with
    -2 (the caller runs it again without ``dial``). Returns the number of targets settled, -1 when
    the heap is full and -3 when a bucket is (the caller grows it and searches again), -2 as said.
    """
    uniform = cost.shape[0] == 1
    hcap = hk.shape[0]
    bcap = bk.shape[1]
    reached = 2 * gen
    done = reached + 1
    off = np.array([-W, W, -1, 1, -W - 1, -W + 1, W - 1, W + 1], np.int64)
    bn[:] = 0
    n = 0  # entries in the heap
    for s in range(src.shape[0]):
        q = src[s]
        if q >= 0 and passable[q]:
            if n == hcap:
                return -1
            state[q, 0] = 0.0
            state[q, 1] = 0.0
            parent[q] = -1
            stamp[q] = reached
            heap_push(hk, hi, n, 0.0, q)
            n += 1
    cur = 0  # with dial: the bucket the heap holds (costs in [cur, cur + 1))
    waiting = 0  # with dial: entries in the buckets after it
    settled_targets = 0
    while True:
        if n == 0:
            if waiting == 0:
                break
            cur += 1  # the next bucket into the heap
            b = cur % BUCKETS
            m = bn[b]
            if m > hcap:
                return -1
            for j in range(m):
                heap_push(hk, hi, n, bk[b, j], bi[b, j])
                n += 1
            waiting -= m
            bn[b] = 0
            continue
        d = hk[0]
        idx = hi[0]
        heap_drop_top(hk, hi, n)
        n -= 1
        if stamp[idx] == done:
            continue
        if d > max_cost:
            break
        stamp[idx] = done
        if tmark[idx] == gen:
            settled_targets += 1
            if n_stop > 0 and settled_targets >= n_stop:
                break
        if idx == stop_idx:
            break
        r = idx // W
        c = idx - r * W
        inner = 0 < r < H - 1 and 0 < c < W - 1
        length = state[idx, 1]
        for k in range(8):
            if not inner:
                nr = r + _DR8[k]
                nc = c + _DC8[k]
                if nr < 0 or nr >= H or nc < 0 or nc >= W:
                    continue
            q = idx + off[k]
            if stamp[q] == done or not passable[q]:
                continue
            if k >= 4:  # no corner cutting: both orthogonal cells, (r, nc) and (nr, c), passable
                if not passable[idx + _DC8[k]] or not passable[idx + _DR8[k] * W]:
                    continue
                step = SQRT2
            else:
                step = 1.0
            inc = step if uniform else step * cost[q]
            nd = d + inc
            if stamp[q] != reached or nd < state[q, 0]:
                if dial:
                    if not inc >= 1.0 or not nd < cur + BUCKETS:  # NaN and inf too: the heap alone
                        return -2
                    b = int(math.floor(nd)) % BUCKETS
                    if bn[b] == bcap:
                        return -3
                    bk[b, bn[b]] = nd
                    bi[b, bn[b]] = q
                    bn[b] += 1
                    waiting += 1
                else:
                    if n == hcap:
                        return -1
                    heap_push(hk, hi, n, nd, q)
                    n += 1
                stamp[q] = reached
                state[q, 0] = nd
                state[q, 1] = length + step
                parent[q] = idx
    return settled_targets


class GridSearch:
    """Reusable Dijkstra state for one grid shape (see :func:`_dijkstra`).

    After :meth:`run`, :meth:`settled`, :meth:`lengths`, :meth:`costs` and :meth:`path` read the
    cells that search settled; :meth:`length_grid` gives its lengths over the whole grid.
    """

    def __init__(self, shape):
        # never filled: a value counts only where its stamp says so, and pages never written are
        # never resident (a search touches a band, not the map); int32 cell indices (maps are at
        # most 25 M cells)
        self.shape = tuple(shape)
        n = int(np.prod(self.shape))
        self.state = lazy_zeros((n, 2))  # (cost, length) per cell
        self.parent = lazy_zeros(n, np.int32)
        self.stamp = lazy_zeros(n, np.int32)
        self.tmark = lazy_zeros(n, np.int32)
        self.gen = 0
        self.source = None
        self._hk = np.empty(4096)  # the search's heap (cost, cell), grown when a search fills it
        self._hi = np.empty(4096, np.int64)
        self._bk = np.empty((BUCKETS, 1024))  # Dial's buckets (cost, cell), grown alike
        self._bi = np.empty((BUCKETS, 1024), np.int64)
        self._bn = np.zeros(BUCKETS, np.int64)

    def run(self, passable, cost, src_r, src_c, t_rows, t_cols, n_stop=0, max_cost=np.inf, stop=None) -> int:
        """Search from the source cells; returns the number of targets settled. ``stop``: a cell
        (row, col) at which to stop as soon as it is settled (the path to it is then the one the
        whole search gives)."""
        src_r = np.atleast_1d(np.asarray(src_r, np.int64))
        src_c = np.atleast_1d(np.asarray(src_c, np.int64))
        self.source = (tuple(src_r), tuple(src_c))
        H, W = passable.shape
        inside = (src_r >= 0) & (src_r < H) & (src_c >= 0) & (src_c < W)
        src = np.where(inside, src_r * W + src_c, -1)
        stop_idx = -1 if stop is None else int(stop[0]) * W + int(stop[1])
        t_idx = np.asarray(t_rows, np.int64) * W + np.asarray(t_cols, np.int64)
        passable, cost = passable.ravel(), cost.ravel()
        dial = True
        while True:  # a search that fills the heap or a bucket runs again, from scratch, with larger ones
            self.gen += 1
            self.tmark[t_idx] = self.gen
            settled = _dijkstra(passable, cost, H, W, src, self.tmark, n_stop, max_cost, self.state, self.parent,
                                self.stamp, self.gen, self._hk, self._hi, self._bk, self._bi, self._bn, dial, stop_idx)
            if settled >= 0:
                return settled
            if settled == -2:  # a step outside what Dial's buckets hold: the heap alone
                dial = False
            elif settled == -3:
                self._bk, self._bi = np.empty((BUCKETS, 2 * self._bk.shape[1])), np.empty((BUCKETS, 2 * self._bi.shape[1]), np.int64)
            else:
                self._hk, self._hi = np.empty(2 * self._hk.size), np.empty(2 * self._hi.size, np.int64)

    def _flat(self, rows, cols):
        return np.asarray(rows, np.int64) * self.shape[1] + np.asarray(cols, np.int64)

    def settled(self, rows, cols) -> np.ndarray:
        return self.stamp[self._flat(rows, cols)] == 2 * self.gen + 1

    def lengths(self, rows, cols) -> np.ndarray:
        """Path length (cells) to each given cell, inf where it was not settled."""
        q = self._flat(rows, cols)
        return np.where(self.stamp[q] == 2 * self.gen + 1, self.state[q, 1], np.inf)

    def costs(self, rows, cols) -> np.ndarray:
        q = self._flat(rows, cols)
        return np.where(self.stamp[q] == 2 * self.gen + 1, self.state[q, 0], np.inf)

    def length_grid(self) -> np.ndarray:
        """(H, W) path length (cells) to every cell, inf where the last search did not settle it."""
        done = self.stamp == 2 * self.gen + 1
        return np.where(done, self.state[:, 1], np.inf).reshape(self.shape)

    def path(self, r, c):
        """Cells (rows, cols) from the source to (r, c), or None if (r, c) was not settled."""
        if not self.settled(r, c):
            return None
        return backtrack(self.parent, self.shape[1], int(r), int(c))


def dijkstra(passable, cost, src_r, src_c, target, n_stop, max_cost):
    """One-off search returning full arrays (cost, length, parent); inf / -1 where not settled.

    ``target`` is an (H, W) bool mask. For repeated searches on one grid use :class:`GridSearch`.
    """
    gs = GridSearch(passable.shape)
    tr, tc = np.nonzero(target)
    gs.run(passable, cost, src_r, src_c, tr, tc, n_stop, max_cost)
    done = (gs.stamp == 2 * gs.gen + 1).reshape(gs.shape)
    return (np.where(done, gs.state[:, 0].reshape(gs.shape), np.inf), gs.length_grid(),
            np.where(done, gs.parent.reshape(gs.shape), -1))


@njit(cache=True)
def backtrack(parent, W, r, c):
    """Cells (rows, cols) from the Dijkstra source to (r, c), following the flat ``parent``."""
    n = 0
    idx = r * W + c
    while idx >= 0:
        n += 1
        idx = parent[idx]
    rows = np.empty(n, np.int64)
    cols = np.empty(n, np.int64)
    idx = r * W + c
    k = n - 1
    while idx >= 0:
        rows[k] = idx // W
        cols[k] = idx % W
        k -= 1
        idx = parent[idx]
    return rows, cols


@njit(cache=True)
def widest_of_groups(lab, n, clearance, r0, c0):
    """One cell per group of the label image ``lab`` (labels 1..n-1, 0 is background): the one
    with the largest ``clearance[r0 + r, c0 + c]``, the first in row-major order among equals.
    Returns (rows, cols) in the full grid's coordinates, in label order."""
    best = np.full(n, -np.inf)
    rows = np.zeros(n, np.int64)
    cols = np.zeros(n, np.int64)
    H, W = lab.shape
    for r in range(H):
        for c in range(W):
            k = lab[r, c]
            if k > 0:
                v = clearance[r0 + r, c0 + c]
                if v > best[k]:
                    best[k] = v
                    rows[k] = r0 + r
                    cols[k] = c0 + c
    return rows[1:], cols[1:]


@njit(cache=True)
def nearest_visited(visited, r, c, max_rad):
    """The visited cell nearest to (r, c) (Euclidean, the first in row-major order among equals)
    within the smallest square of half-side 1..``max_rad`` that holds one; (r, c) when none does."""
    H, W = visited.shape
    for rad in range(1, max_rad + 1):
        best = -1
        br = r
        bc = c
        for rr in range(max(0, r - rad), min(H, r + rad + 1)):
            for cc in range(max(0, c - rad), min(W, c + rad + 1)):
                if visited[rr, cc]:
                    d = (rr - r) * (rr - r) + (cc - c) * (cc - c)
                    if best < 0 or d < best:
                        best = d
                        br = rr
                        bc = cc
        if best >= 0:
            return br, bc
    return r, c


@njit(cache=True)
def branch_walk(skel, visited, r0, c0, depth):
    """Walk the skeleton out of the visited region from candidate (r0, c0).

    Breadth-first over 8-connected skeleton cells that are not visited, up to ``depth`` steps.

    Returns
    -------
    dr, dc : float
        Mean offset (cells, row and col) of the reached cells from (r0, c0): the branch direction.
    n : int
        Number of reached cells (excluding the start).
    """
    H, W = skel.shape
    S = 2 * depth + 1
    mark = np.zeros((S, S), np.bool_)
    qr = np.empty(S * S, np.int64)
    qc = np.empty(S * S, np.int64)
    qd = np.empty(S * S, np.int64)
    qr[0] = r0
    qc[0] = c0
    qd[0] = 0
    mark[depth, depth] = True
    head = 0
    tail = 1
    sr = 0.0
    sc = 0.0
    while head < tail:
        r = qr[head]
        c = qc[head]
        d = qd[head]
        head += 1
        if d >= depth:
            continue
        for k in range(8):
            nr = r + _DR8[k]
            nc = c + _DC8[k]
            if nr < 0 or nr >= H or nc < 0 or nc >= W:
                continue
            lr = nr - r0 + depth
            lc = nc - c0 + depth
            if mark[lr, lc] or not skel[nr, nc] or visited[nr, nc]:
                continue
            mark[lr, lc] = True
            qr[tail] = nr
            qc[tail] = nc
            qd[tail] = d + 1
            tail += 1
            sr += nr - r0
            sc += nc - c0
    n = tail - 1
    if n == 0:
        return 0.0, 0.0, 0
    return sr / n, sc / n, n
