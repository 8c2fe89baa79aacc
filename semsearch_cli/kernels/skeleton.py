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
the new history can differ from the old only next to cells that already differ; the update
follows that front (the cells whose state differs, and their neighbours), subiteration by
subiteration, and stops when the front is empty or when nothing near it can change any more
(no event, old or new, at the last two subiterations or later in the front and the ring around
it; see :func:`_propagate`). The result is the skeleton of a thinning of the whole map from
scratch, cell for cell (tests/test_skeleton.py checks it against that brute force after random
changes), at the cost of the cells whose history changed.
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
def _value(tdel, newv, touched, gen, q):
    return newv[q] if touched[q] == gen else tdel[q]


@njit(cache=True)
def _grow(a, n):
    if n < a.shape[0]:
        return a
    b = np.empty(2 * a.shape[0], a.dtype)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def _push(lst, n, x):
    lst = _grow(lst, n)
    lst[n] = x
    return lst, n + 1


@njit(cache=True)
def _propagate(free, tdel, newv, touched, gen, ind, dcnt, dst, entry, queued, cmark, mgen, H, W, seeds, n_seeds,
               tables):
    """Thin again where the map changed. ``seeds`` (flat indices, the first ``n_seeds``) are the
    cells whose free state differs from the history ``tdel`` holds (``tdel > 0`` where a cell was
    free). Writes the new history into ``tdel``; returns (the cells that joined or left the
    skeleton, the last candidate stamp, the last subiteration, the cells decided).

    The new history is held apart while it is computed (``newv`` where ``touched == gen``; the old
    value, ``tdel``, stands for a cell elsewhere): a cell's value is the subiteration that deletes
    it (alive after subiteration ``s`` iff value > s). Three facts keep the work to the cells whose
    history changes:

    - **The front.** ``D`` holds the cells whose state differs between the two histories. A cell
      outside ``C``, the 3 x 3 neighbourhoods of ``D`` (``dcnt``: its cells in ``D``), sees the same
      neighbourhood in both, so decides as in the old history: its old value stands. A cell that
      leaves ``C`` alive takes its old value back.
    - **Events.** A cell's decision at ``s`` is the decision of ``s - 2`` (the same rule) unless a
      neighbour was deleted at ``s - 1`` or ``s - 2``; a cell kept at ``s - 2`` is kept at ``s``. So
      only the neighbours of the last two subiterations' deletions are judged, and each cell of
      ``C`` at the first two subiterations after it joined ``C`` (before that it followed the old
      history, whose deletions next to it are not all in the lists).
    - **The old history's events** near ``C`` (a cell of ``C`` or its ring that the old history
      deletes later) are queued by time when the cell comes near ``C`` (``queued``), so the front
      learns of them without a scan: such a deletion changes ``D``, and beside ``C`` it is a
      deletion of the new history too.

    It ends when ``D`` is empty, or when nothing is left to happen: no deletion in the last two
    subiterations, no cell just joined, nothing queued. Then every cell of ``C`` alive is kept for
    ever."""
    T = np.empty(max(64, 4 * n_seeds), np.int64)  # every cell touched, once
    nT = 0
    # events of the new history (deletions) at s - 2, s - 1 and s, beside C
    E2 = np.empty(256, np.int64)
    E1 = np.empty(256, np.int64)
    E0 = np.empty(256, np.int64)
    n2 = n1 = n0 = 0
    # cells that joined C for subiteration s + 1 (F0: filled while s is processed), s (F1) and s - 1 (F2)
    F2 = np.empty(256, np.int64)
    F1 = np.empty(256, np.int64)
    F0 = np.empty(max(256, 9 * n_seeds), np.int64)
    f2 = f1 = f0 = 0
    # the old history's deletions near C, by time: a linked list per time
    head = np.full(256, -1, np.int64)
    bcell = np.empty(1024, np.int64)
    bnext = np.empty(1024, np.int64)
    nb = 0
    pending = 0  # queued deletions not yet reached
    CH = np.empty(256, np.int64)  # cells whose D membership to check after a subiteration
    nch = 0
    cand = np.empty(256, np.int64)
    decided = 0
    s = 0
    nD = 0
    # ---- s = 0: the seeds take their new free state and join D
    for i in range(n_seeds):
        q = seeds[i]
        if touched[q] != gen:
            touched[q] = gen
            T, nT = _push(T, nT, q)
        newv[q] = KEPT if free[q] else 0
        CH, nch = _push(CH, nch, q)
    while True:
        # ---- D after subiteration s: of the cells whose state may have changed (CH), those that join
        # D (first, all of them) and those that leave it (then: a cell of C whose count falls to 0 has
        # left C for good at this subiteration, and takes its old value back)
        nj = 0
        for i in range(nch):
            x = CH[i]
            v = newv[x] if touched[x] == gen else tdel[x]
            differ = (v > s) != (tdel[x] > s)
            if differ != (ind[x] == gen):
                ind[x] = gen if differ else -1  # -1: left D at this update (never a stamp)
                CH[nj] = x if differ else -x - 1
                nj += 1
        for phase in range(2):
            for i in range(nj):
                joins = CH[i] >= 0
                if joins != (phase == 0):
                    continue
                x = CH[i] if joins else -CH[i] - 1
                nD += 1 if joins else -1
                r = x // W
                c = x - r * W
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= H:
                        continue
                    for dc in range(-1, 2):
                        cc = c + dc
                        if cc < 0 or cc >= W:
                            continue
                        y = rr * W + cc
                        if dst[y] != gen:
                            dst[y] = gen
                            dcnt[y] = 0
                        if joins:
                            dcnt[y] += 1
                            if dcnt[y] == 1:  # y joins C: judged at the next two subiterations; it and its ring queued
                                entry[y] = s + 1
                                F0, f0 = _push(F0, f0, y)
                                for er in range(-1, 2):
                                    zr = rr + er
                                    if zr < 0 or zr >= H:
                                        continue
                                    for ec in range(-1, 2):
                                        zc = cc + ec
                                        if zc < 0 or zc >= W:
                                            continue
                                        z = zr * W + zc
                                        if queued[z] == gen:
                                            continue
                                        queued[z] = gen
                                        t = tdel[z]
                                        if s < t < KEPT:
                                            while t >= head.shape[0]:
                                                bigger = np.full(2 * head.shape[0], -1, np.int64)
                                                bigger[: head.shape[0]] = head
                                                head = bigger
                                            bcell, _ = _push(bcell, nb, z)
                                            bnext, _ = _push(bnext, nb, head[t])
                                            head[t] = nb
                                            nb += 1
                                            pending += 1
                        else:
                            dcnt[y] -= 1
                            if dcnt[y] == 0 and touched[y] == gen and newv[y] > s:  # y leaves C alive: the old history from here
                                newv[y] = tdel[y]
        nch = 0
        if nD == 0:
            break
        if n0 == 0 and n1 == 0 and f0 == 0 and f1 == 0:
            if pending == 0:  # nothing left to happen: C is kept as it is, for ever
                break
            t = s + 1  # nothing happens before the next queued deletion: go to it
            while head[t] < 0:
                t += 1
            s = t - 1
            f1 = 0
        # ---- subiteration s + 1
        s += 1
        E2, E1, E0 = E1, E0, E2
        n2, n1, n0 = n1, n0, 0
        F2, F1, F0 = F1, F0, F2
        f2, f1, f0 = f1, f0, 0
        # the cells to judge: C's cells beside a deletion of s - 1 or s - 2, and those that joined C lately
        mgen += 1
        nc = 0
        for part in range(4):
            lst = E1 if part == 0 else E2 if part == 1 else F1 if part == 2 else F2
            m = n1 if part == 0 else n2 if part == 1 else f1 if part == 2 else f2
            for i in range(m):
                x = lst[i]
                if part >= 2:
                    if cmark[x] != mgen and dst[x] == gen and dcnt[x] > 0 and entry[x] >= s - 1:
                        cmark[x] = mgen
                        cand, nc = _push(cand, nc, x)
                    continue
                r = x // W
                c = x - r * W
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= H:
                        continue
                    for dc in range(-1, 2):
                        cc = c + dc
                        if cc < 0 or cc >= W:
                            continue
                        y = rr * W + cc
                        if cmark[y] != mgen and dst[y] == gen and dcnt[y] > 0:
                            cmark[y] = mgen
                            cand, nc = _push(cand, nc, y)
        table = tables[(s - 1) % 2]
        for i in range(nc):
            q = cand[i]
            v = newv[q] if touched[q] == gen else tdel[q]
            if v <= s - 1:
                continue
            decided += 1
            r = q // W
            c = q - r * W
            code = 0
            for k in range(8):
                rr = r + _NR[k]
                cc = c + _NC[k]
                if 0 <= rr < H and 0 <= cc < W:
                    y = rr * W + cc
                    if (newv[y] if touched[y] == gen else tdel[y]) > s - 1:
                        code |= 1 << k
            if table[code]:
                if touched[q] != gen:
                    touched[q] = gen
                    T, nT = _push(T, nT, q)
                newv[q] = s
                E0, n0 = _push(E0, n0, q)
                CH, nch = _push(CH, nch, q)
            elif v == s:  # the old history deletes it here; the new one keeps it
                if touched[q] != gen:
                    touched[q] = gen
                    T, nT = _push(T, nT, q)
                newv[q] = KEPT
        # the old history's deletions at s near C
        if s < head.shape[0]:
            j = head[s]
            head[s] = -1
            while j >= 0:
                x = bcell[j]
                j = bnext[j]
                pending -= 1
                CH, nch = _push(CH, nch, x)
                if dst[x] == gen and dcnt[x] > 0:  # in C: the new history keeps it unless it was judged and deleted
                    v = newv[x] if touched[x] == gen else tdel[x]
                    if v == s and cmark[x] != mgen:
                        if touched[x] != gen:
                            touched[x] = gen
                            T, nT = _push(T, nT, x)
                        newv[x] = KEPT
                elif (newv[x] if touched[x] == gen else tdel[x]) == s:  # beside C: deleted in both histories
                    E0, n0 = _push(E0, n0, x)
    # write the new history back; the cells that joined or left the skeleton
    out = np.empty(max(16, nT), np.int64)
    n = 0
    for i in range(nT):
        q = T[i]
        old = tdel[q]
        nv = newv[q]
        if (old == KEPT) != (nv == KEPT):
            out[n] = q
            n += 1
        tdel[q] = nv
    return out[:n], mgen, s, decided


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

    def __init__(self, shape):
        H, W = shape
        self.shape = (H, W)
        self.tdel = lazy_zeros(H * W, np.int32)  # per cell, the subiteration that deletes it (0: not free; KEPT)
        self._newv = lazy_zeros(H * W, np.int32)
        self._touched = lazy_zeros(H * W, np.int32)
        self._ind = lazy_zeros(H * W, np.int32)  # per update (stamped with its number): in the front D
        self._dcnt = lazy_zeros(H * W, np.int32)  # cells of D around a cell (valid where _dst is the stamp)
        self._dst = lazy_zeros(H * W, np.int32)
        self._entry = lazy_zeros(H * W, np.int32)  # the subiteration a cell joined C
        self._queued = lazy_zeros(H * W, np.int32)
        self._mark = lazy_zeros(H * W, np.int64)  # per subiteration: judged
        self._gen = 0
        self._mgen = 0
        self.skeleton = lazy_zeros((H, W), bool)
        self.last = (0, 0)  # the last update's subiterations and cells decided (for benchmarks)

    def update(self, free: np.ndarray, box) -> np.ndarray:
        """Fold in the changes of ``free`` ((H, W) bool) inside ``box`` = (rmin, rmax, cmin, cmax),
        inclusive (every cell whose free state changed since the last update lies in it). Returns
        the flat indices of the cells that joined or left the skeleton."""
        H, W = self.shape
        r0, r1, c0, c1 = max(0, int(box[0])), min(H, int(box[1]) + 1), max(0, int(box[2])), min(W, int(box[3]) + 1)
        if r1 <= r0 or c1 <= c0:
            return np.empty(0, np.int64)
        flat = free.reshape(-1)
        seeds, n = _seeds(flat, self.tdel, W, r0, r1, c0, c1)
        if n == 0:
            return np.empty(0, np.int64)
        self._gen += 1
        changed, self._mgen, steps, evaluated = _propagate(flat, self.tdel, self._newv, self._touched, self._gen, self._ind,
                                                           self._dcnt, self._dst, self._entry, self._queued, self._mark,
                                                           self._mgen, H, W, seeds, n, TABLES)
        self.last = (int(steps), int(evaluated))
        sk = self.skeleton.reshape(-1)
        sk[changed] = self.tdel[changed] == KEPT
        return changed
