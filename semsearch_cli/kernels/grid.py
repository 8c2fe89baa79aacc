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
def _before(k1, i1, k2, i2):
    """Heap order: by cost, then by cell index (so that every heap pops cells in one order)."""
    return k1 < k2 or (k1 == k2 and i1 < i2)


@njit(cache=True, inline="always")
def _heap_push(hk, hi, n, k, i):
    """Put (k, i) into the binary heap of the first ``n`` entries of (hk, hi)."""
    j = n
    while j > 0:
        p = (j - 1) >> 1
        if not _before(k, i, hk[p], hi[p]):
            break
        hk[j] = hk[p]
        hi[j] = hi[p]
        j = p
    hk[j] = k
    hi[j] = i


@njit(cache=True, inline="always")
def _heap_drop_top(hk, hi, n):
    """Remove the top of the heap of ``n`` entries (it then holds n - 1)."""
    n -= 1
    k = hk[n]
    i = hi[n]
    j = 0
    while True:
        ch = 2 * j + 1
        if ch >= n:
            break
        if ch + 1 < n and _before(hk[ch + 1], hi[ch + 1], hk[ch], hi[ch]):
            ch += 1
        if not _before(hk[ch], hi[ch], k, i):
            break
        hk[j] = hk[ch]
        hi[j] = hi[ch]
        j = ch
    hk[j] = k
    hi[j] = i


@njit(cache=True)
def _dijkstra(passable, cost, src_r, src_c, tmark, n_stop, max_cost, dist, length, parent, touched, closed, gen, hk, hi,
              stop_idx):
    """Multi-source Dijkstra on an 8-connected grid with per-cell cost multipliers.

    Moving into cell q costs ``step * cost[q]`` with step 1 or sqrt(2); ``cost`` of shape (1, 1)
    means a uniform cost of 1. Cells with ``tmark == gen`` are targets; the search stops once
    ``n_stop`` of them are settled (0: never), once the cell of index ``stop_idx`` is settled (-1:
    no such cell), or when the cost exceeds ``max_cost``. A settled cell's parent is final, so a
    search stopped at a cell holds the same path to it as the search run on. The state arrays
    are reused across searches: a value is valid only where its stamp (``touched`` / ``closed``)
    equals ``gen``, so a search costs what it explores, not the grid size.

    The queue is a binary heap in (hk, hi) (cost, cell index), ordered by cost and then by cell
    index, so ties settle in one fixed order. Returns the number of targets settled, or -1 when
    the heap is full (the caller grows it and searches again).
    """
    H, W = passable.shape
    uniform = cost.shape[0] == 1
    cap = hk.shape[0]
    n = 0
    for s in range(src_r.shape[0]):
        r = src_r[s]
        c = src_c[s]
        if 0 <= r < H and 0 <= c < W and passable[r, c]:
            if n == cap:
                return -1
            dist[r, c] = 0.0
            length[r, c] = 0.0
            parent[r, c] = -1
            touched[r, c] = gen
            _heap_push(hk, hi, n, 0.0, r * W + c)
            n += 1
    settled_targets = 0
    while n > 0:
        d = hk[0]
        idx = hi[0]
        _heap_drop_top(hk, hi, n)
        n -= 1
        r = idx // W
        c = idx - r * W
        if closed[r, c] == gen:
            continue
        if d > max_cost:
            break
        closed[r, c] = gen
        if tmark[r, c] == gen:
            settled_targets += 1
            if n_stop > 0 and settled_targets >= n_stop:
                break
        if idx == stop_idx:
            break
        for k in range(8):
            nr = r + _DR8[k]
            nc = c + _DC8[k]
            if nr < 0 or nr >= H or nc < 0 or nc >= W or closed[nr, nc] == gen or not passable[nr, nc]:
                continue
            if k >= 4:
                if not passable[r, nc] or not passable[nr, c]:
                    continue
                step = SQRT2
            else:
                step = 1.0
            nd = d + (step if uniform else step * cost[nr, nc])
            if touched[nr, nc] != gen or nd < dist[nr, nc]:
                if n == cap:
                    return -1
                touched[nr, nc] = gen
                dist[nr, nc] = nd
                length[nr, nc] = length[r, c] + step
                parent[nr, nc] = idx
                _heap_push(hk, hi, n, nd, nr * W + nc)
                n += 1
    return settled_targets


class GridSearch:
    """Reusable Dijkstra state for one grid shape (see :func:`_dijkstra`).

    After :meth:`run`, :meth:`lengths` and :meth:`path` read the settled cells of that search.
    """

    def __init__(self, shape):
        # never filled: a value counts only where its stamp says so, and pages never written are
        # never resident (a search touches a band, not the map); int32 cell indices (maps are at
        # most 25 M cells)
        self.dist = lazy_zeros(shape)
        self.length_ = lazy_zeros(shape)
        self.parent = lazy_zeros(shape, np.int32)
        self.touched = lazy_zeros(shape, np.int32)
        self.closed = lazy_zeros(shape, np.int32)
        self.tmark = lazy_zeros(shape, np.int32)
        self.gen = 0
        self.source = None
        self._hk = np.empty(4096)  # the search's heap (cost, cell), grown when a search fills it
        self._hi = np.empty(4096, np.int64)

    def run(self, passable, cost, src_r, src_c, t_rows, t_cols, n_stop=0, max_cost=np.inf, stop=None) -> int:
        """Search from the source cells; returns the number of targets settled. ``stop``: a cell
        (row, col) at which to stop as soon as it is settled (the path to it is then the one the
        whole search gives)."""
        src_r = np.atleast_1d(np.asarray(src_r, np.int64))
        src_c = np.atleast_1d(np.asarray(src_c, np.int64))
        self.source = (tuple(src_r), tuple(src_c))
        while True:  # a search that fills the heap runs again, from scratch, with a larger one
            self.gen += 1
            self.tmark[t_rows, t_cols] = self.gen
            stop_idx = -1 if stop is None else int(stop[0]) * passable.shape[1] + int(stop[1])
            settled = _dijkstra(passable, cost, src_r, src_c, self.tmark, n_stop, max_cost, self.dist, self.length_,
                                self.parent, self.touched, self.closed, self.gen, self._hk, self._hi, stop_idx)
            if settled >= 0:
                return settled
            self._hk, self._hi = np.empty(2 * self._hk.size), np.empty(2 * self._hi.size, np.int64)

    def settled(self, rows, cols) -> np.ndarray:
        return self.closed[rows, cols] == self.gen

    def lengths(self, rows, cols) -> np.ndarray:
        """Path length (cells) to each given cell, inf where it was not settled."""
        return np.where(self.settled(rows, cols), self.length_[rows, cols], np.inf)

    def costs(self, rows, cols) -> np.ndarray:
        return np.where(self.settled(rows, cols), self.dist[rows, cols], np.inf)

    def path(self, r, c):
        """Cells (rows, cols) from the source to (r, c), or None if (r, c) was not settled."""
        if self.closed[r, c] != self.gen:
            return None
        return backtrack(self.parent, r, c)


def dijkstra(passable, cost, src_r, src_c, target, n_stop, max_cost):
    """One-off search returning full arrays (cost, length, parent); inf / -1 where not settled.

    ``target`` is an (H, W) bool mask. For repeated searches on one grid use :class:`GridSearch`.
    """
    gs = GridSearch(passable.shape)
    tr, tc = np.nonzero(target)
    gs.run(passable, cost, src_r, src_c, tr, tc, n_stop, max_cost)
    done = gs.closed == gs.gen
    return np.where(done, gs.dist, np.inf), np.where(done, gs.length_, np.inf), np.where(done, gs.parent, -1)


@njit(cache=True)
def backtrack(parent, r, c):
    """Cells (rows, cols) from the Dijkstra source to (r, c), following ``parent``."""
    W = parent.shape[1]
    n = 0
    idx = r * W + c
    while idx >= 0:
        n += 1
        idx = parent[idx // W, idx % W]
    rows = np.empty(n, np.int64)
    cols = np.empty(n, np.int64)
    idx = r * W + c
    k = n - 1
    while idx >= 0:
        rows[k] = idx // W
        cols[k] = idx % W
        k -= 1
        idx = parent[idx // W, idx % W]
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
