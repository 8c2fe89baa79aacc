"""The skeleton of the free space: Zhang and Suen's thinning of the whole map, kept up to date as
the map changes (engine 2).

Zhang and Suen (1984, "A fast parallel algorithm for thinning digital patterns") thin a binary
image in subiterations that alternate between two rules. A foreground cell P1 with neighbours P2
(north), P3 (north-east), ..., P9 (north-west), clockwise, is deleted in a subiteration when

- (a) 2 <= B(P1) <= 6, B the number of foreground neighbours;
- (b) A(P1) = 1, A the number of background-to-foreground steps in the sequence P2, P3, ..., P9, P2;
- (c) P2 * P4 * P6 = 0 in the first subiteration, P2 * P4 * P8 = 0 in the second;
- (d) P4 * P6 * P8 = 0 in the first subiteration, P2 * P6 * P8 = 0 in the second;

every cell judged on the image as the previous subiteration left it (in parallel), until a whole
iteration (both subiterations) deletes nothing. Cells outside the grid are background. The
skeleton is what is left. :func:`deletion_table` writes both rules as tables of the 256
neighbourhoods, from these conditions.

**Incremental, and exact.** :class:`Skeleton` keeps, for each cell, the subiteration that deleted it
(0: background; :data:`KEPT`: a skeleton cell): the whole history of the thinning of the current
map. When cells of the map change, only the part of that history that changes is computed again.
A cell's decision at a subiteration depends on its 3 x 3 neighbourhood after the one before, so
the new history can differ from the old only next to cells that already differ (the front); a
cell farther away sees the same neighbourhood in both histories and decides as it did. Each
subiteration is judged over the box of the front and one cell around it, on a copy of the history
around the changes (:func:`_thin_window`); it stops when the front is empty (the histories agree
again), or when nothing near it can change any more: no deletion, old or new, at the last two
subiterations and none to come in the box and the ring around it (then every cell of the box
decides as it did two subiterations before, and keeps). A quiet stretch before the old history's
next deletion there is skipped. The result is the skeleton of a thinning of the whole map from
scratch, cell for cell (tests/test_skeleton.py checks it against that brute force after random
changes), at the cost of the front's boxes, not of the map.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .memory import lazy_zeros

KEPT = np.int32(1 << 30)  # the deletion time of a cell no subiteration deletes: the skeleton
# P2 .. P9 as (row, col) offsets: north, north-east, east, south-east, south, south-west, west, north-west
_NR = np.array([-1, -1, 0, 1, 1, 1, 0, -1], np.int64)
_NC = np.array([0, 1, 1, 1, 0, -1, -1, -1], np.int64)


def deletion_table(second: bool) -> np.ndarray:
    """(256,) uint8: 1 where Zhang and Suen's rule of the first (or ``second``) subiteration deletes
    a foreground cell whose neighbours P2 .. P9 are the bits 0 .. 7 of the index."""
    out = np.zeros(256, np.uint8)
    for code in range(256):
        p = [0, 0] + [(code >> i) & 1 for i in range(8)]  # p[2] .. p[9]
        b = sum(p[2:])
        seq = p[2:] + [p[2]]
        a = sum(1 for i in range(8) if seq[i] == 0 and seq[i + 1] == 1)
        if second:
            c, d = p[2] * p[4] * p[8], p[2] * p[6] * p[8]
        else:
            c, d = p[2] * p[4] * p[6], p[4] * p[6] * p[8]
        out[code] = 2 <= b <= 6 and a == 1 and c == 0 and d == 0
    return out


TABLES = np.stack([deletion_table(False), deletion_table(True)])  # [0]: odd subiterations, [1]: even


@njit(cache=True)
def _grow(a, n):
    if n < a.shape[0]:
        return a
    b = np.empty(2 * a.shape[0], a.dtype)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def _seeds(free, tdel, W, r0, r1, c0, c1):
    """The cells of rows r0..r1-1, cols c0..c1-1 whose free state the history does not hold."""
    out = np.empty(64, np.int64)
    n = 0
    for r in range(r0, r1):
        for c in range(c0, c1):
            q = r * W + c
            if free[q] != (tdel[q] > 0):
                out = _grow(out, n)
                out[n] = q
                n += 1
    return out, n


class Skeleton:
    """Zhang and Suen's skeleton of a map's free space, kept up to date as the map changes (see
    the module's text). ``skeleton`` is the (H, W) bool map; :meth:`update` folds in the changes
    of a box of the free map and returns the cells that joined or left the skeleton."""

    MARGIN = 32  # cells of history copied around the changes; doubled while the front comes near its edge

    def __init__(self, shape):
        H, W = shape
        self.shape = (H, W)
        self.tdel = lazy_zeros(H * W, np.int32)  # per cell, the subiteration that deletes it (0: not free; KEPT)
        self.skeleton = lazy_zeros((H, W), bool)
        self.last = (0, 0, 0)  # the last update's subiterations, cells judged and copies made (for benchmarks)

    def update(self, free: np.ndarray, box) -> np.ndarray:
        """Fold in the changes of ``free`` ((H, W) bool) inside ``box`` = (rmin, rmax, cmin, cmax),
        inclusive (every cell whose free state changed since the last update lies in it). Returns
        the flat indices of the cells that joined or left the skeleton."""
        H, W = self.shape
        r0, r1, c0, c1 = max(0, int(box[0])), min(H - 1, int(box[1])), max(0, int(box[2])), min(W - 1, int(box[3]))
        if r1 < r0 or c1 < c0:
            return np.empty(0, np.int64)
        flat = free.reshape(-1)
        seeds, n = _seeds(flat, self.tdel, W, r0, r1 + 1, c0, c1 + 1)
        if n == 0:
            return np.empty(0, np.int64)
        margin, copies, judged = self.MARGIN, 0, 0
        while True:
            copies += 1
            changed, steps, jd = _thin_window(flat, self.tdel, H, W, seeds, n, r0, r1, c0, c1, margin, TABLES)
            judged += jd
            if steps >= 0:
                break
            margin *= 2
        self.skeleton.reshape(-1)[changed] = self.tdel[changed] == KEPT
        self.last = (int(steps), int(judged), copies)
        return changed


@njit(cache=True)
def _thin_window(free, tdel, H, W, seeds, n_seeds, br0, br1, bc0, bc1, margin, tables):
    """Thin again where the map changed. ``seeds`` (flat indices, the first ``n_seeds``, inside the
    box rows br0..br1, cols bc0..bc1) are the cells whose free state differs from the history
    ``tdel`` holds (``tdel > 0`` where a cell was free). Works on a copy of the history around the
    box (``margin`` cells; ``old``, and ``cur``, the new history as it is computed: a cell's value
    is the subiteration that deletes it, alive after subiteration ``s`` iff value > s) and writes
    the new history back into ``tdel``. Returns (the cells that joined or left the skeleton, the
    last subiteration, the cells judged), or an empty result with subiterations -1 when the front
    came within 2 cells of the copy's edge inside the grid (run again with a larger margin).

    Subiteration ``s`` judges every alive cell of the front's box grown by one cell (a cell of it
    that is not beside the front decides as in the old history anyway), in place: a cell deleted
    now holds ``s``, still alive after ``s - 1`` for the others. A cell the old history deletes at
    ``s`` and the new one keeps holds :data:`KEPT` until judged again; a cell of the last box
    outside this one, alive, takes its old value back (from here it decides as it did)."""
    w0, w1, v0, v1 = max(0, br0 - margin), min(H, br1 + margin + 1), max(0, bc0 - margin), min(W, bc1 + margin + 1)
    h, w = w1 - w0, v1 - v0
    old = np.empty((h + 2, w + 2), np.int32)  # padded: out of the grid is background
    old[:, :] = 0
    for r in range(h):
        for c in range(w):
            old[r + 1, c + 1] = tdel[(w0 + r) * W + v0 + c]
    cur = old.copy()
    r0, r1, c0, c1 = h + 2, -1, w + 2, -1
    for i in range(n_seeds):
        q = seeds[i]
        r = q // W - w0 + 1
        c = q % W - v0 + 1
        cur[r, c] = KEPT if free[q] else 0
        r0, r1, c0, c1 = min(r0, r), max(r1, r), min(c0, c), max(c1, c)
    # the copy's edges that lie inside the grid: the front may not come within 2 cells of them
    lo_r = 3 if w0 > 0 else 1
    hi_r = h - 2 if w1 < H else h
    lo_c = 3 if v0 > 0 else 1
    hi_c = w - 2 if v1 < W else w
    s = 0
    quiet = 0
    decided = 0
    pr0, pr1, pc0, pc1 = 1, 0, 1, 0
    while r1 >= r0:
        if r0 < lo_r or r1 > hi_r or c0 < lo_c or c1 > hi_c:
            return np.empty(0, np.int64), -1, decided
        s += 1
        a0, a1, b0, b1 = max(1, r0 - 1), min(h, r1 + 1), max(1, c0 - 1), min(w, c1 + 1)
        for r in range(pr0, pr1 + 1):
            for c in range(pc0, pc1 + 1):
                if a0 <= r <= a1 and b0 <= c <= b1:
                    continue
                if cur[r, c] > s - 1:
                    cur[r, c] = old[r, c]
        table = tables[(s - 1) % 2]
        deleted = 0
        t = s - 1
        r0, r1, c0, c1 = h + 2, -1, w + 2, -1  # the new front: where the histories differ after s
        for r in range(a0, a1 + 1):
            for c in range(b0, b1 + 1):
                v = cur[r, c]
                if v > t:
                    decided += 1
                    code = ((cur[r - 1, c] > t) | ((cur[r - 1, c + 1] > t) << 1) | ((cur[r, c + 1] > t) << 2)
                            | ((cur[r + 1, c + 1] > t) << 3) | ((cur[r + 1, c] > t) << 4) | ((cur[r + 1, c - 1] > t) << 5)
                            | ((cur[r, c - 1] > t) << 6) | ((cur[r - 1, c - 1] > t) << 7))
                    if table[code]:
                        v = cur[r, c] = s
                        deleted += 1
                    elif v == s:
                        v = cur[r, c] = KEPT
                if (v > s) != (old[r, c] > s):  # a cell's value is final once judged (judged in place)
                    r0, r1, c0, c1 = min(r0, r), max(r1, r), min(c0, c), max(c1, c)
        pr0, pr1, pc0, pc1 = a0, a1, b0, b1
        quiet = quiet + 1 if deleted == 0 else 0
        if r1 < r0 or quiet < 2:
            continue
        # nothing deleted at s - 1 and s: when does anything happen next near the front?
        recent = False
        nxt = KEPT
        for r in range(max(1, a0 - 1), min(h, a1 + 1) + 1):
            for c in range(max(1, b0 - 1), min(w, b1 + 1) + 1):
                for tv in (old[r, c], cur[r, c]):
                    if s - 2 < tv <= s:
                        recent = True
                    elif s < tv < nxt:
                        nxt = tv
        if recent:
            continue
        if nxt < KEPT:  # nothing happens before the old history's next deletion here: go to it
            s = nxt - 1
            quiet = 0
            continue
        for r in range(a0, a1 + 1):
            for c in range(b0, b1 + 1):
                if cur[r, c] > s:
                    cur[r, c] = KEPT
        pr0, pr1 = 1, 0
        break
    for r in range(pr0, pr1 + 1):
        for c in range(pc0, pc1 + 1):
            if cur[r, c] > s:
                cur[r, c] = old[r, c]
    out = np.empty(64, np.int64)
    n = 0
    for r in range(1, h + 1):
        for c in range(1, w + 1):
            nv = cur[r, c]
            ov = old[r, c]
            if nv != ov:
                q = (w0 + r - 1) * W + v0 + c - 1
                tdel[q] = nv
                if (ov == KEPT) != (nv == KEPT):
                    out = _grow(out, n)
                    out[n] = q
                    n += 1
    return out[:n], s, decided

