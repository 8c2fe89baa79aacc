"""Shortest paths along the skeleton on a contracted graph, repaired where the map changed
(engine 2).

**The graph.** Its cells are the skeleton cells where the robot fits (``skeleton & passable``). A
move joins two of them that are 8-neighbours (1 or sqrt(2) cells long); a diagonal move needs both
orthogonal cells passable, as on the grid (no corner cutting). A cell's degree is the number of
such moves. The nodes are the cells of degree other than 2 (ends, junctions, lone cells) and, on a
cycle of cells of degree 2 only, one cell of it; every other cell lies inside exactly one chain of
degree-2 cells between two nodes: an edge, whose length is the sum of its moves. A node keeps its
edges by the direction they leave it in (8 slots), an interior cell its edge and its position
along it (the length from the edge's first node), so nothing is stored per edge but its two ends.

**Repair.** When skeleton or passable cells change, the cells whose moves can have changed are the
graph cells (before or after) within one cell of them: the affected cells. Every edge through an
affected cell, or ending at one that was a node, is dropped (an interior cell's record is valid
only while its edge's serial number matches, so dropping costs nothing per cell), the affected
cells are judged again, and chains are traced again from every node that lost an edge and every
new node. A cycle left without a node gets its cell of least index as one. The cost is the
changed chains' length, not the map's.

**Searches.** The robot is joined to the graph by a Dijkstra over the passable cells 4-connected
to it within a radius (its join region, under the grid's cost); every graph cell there is a seed.
A Dijkstra over the nodes (edges cost their length: the cost of the skeleton is 1 per cell) then
gives every graph cell's distance: a node's own, or for an interior cell the best of its edge's two
nodes plus the way along the edge, and of the seeds on its edge. A target on the graph is reached
along it or directly in the robot's join region; a target off the graph is joined to it by a
Dijkstra toward the target over its own join region (and also reached through the robot's region
where the two overlap).

**Ties.** Nodes settle in the order of (cost, cell index); every choice between equal costs keeps
the first in a fixed order of evaluation (the direct way, then the graph; an edge's first node,
then its second, then seeds in order); so equal paths resolve alike on every machine.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .grid import heap_drop_top, heap_push, local_reach
from .memory import lazy_zeros

SQRT2 = math.sqrt(2.0)
# moves: north, south, west, east, north-west, north-east, south-west, south-east
_DR = np.array([-1, 1, 0, 0, -1, -1, 1, 1], np.int64)
_DC = np.array([0, 0, -1, 1, -1, 1, -1, 1], np.int64)
_OPP = np.array([1, 0, 3, 2, 7, 6, 5, 4], np.int64)
_STEP = np.array([1.0, 1.0, 1.0, 1.0, SQRT2, SQRT2, SQRT2, SQRT2])
# lengths along the graph are kept as whole numbers of moves, orthogonal + (diagonal << 32), so that
# they are the same bit for bit whichever end they were counted from (:func:`_len` gives cells)
_PK = np.array([1, 1, 1, 1, 1 << 32, 1 << 32, 1 << 32, 1 << 32], np.int64)
INF = np.inf


@njit(cache=True, inline="always")
def _len(v):
    """Cells in a packed count of moves (orthogonal + (diagonal << 32)), v >= 0."""
    return np.float64(v & 0xFFFFFFFF) + np.float64(v >> 32) * SQRT2


@njit(cache=True, inline="always")
def _move(gcell, passable, H, W, p, k):
    """The cell the move k leads to from graph cell p, or -1 when that is not an allowed move."""
    r = p // W
    c = p - r * W
    nr = r + _DR[k]
    nc = c + _DC[k]
    if nr < 0 or nr >= H or nc < 0 or nc >= W:
        return -1
    q = nr * W + nc
    if not gcell[q]:
        return -1
    if k >= 4 and not (passable[r * W + nc] and passable[nr * W + c]):
        return -1
    return q


@njit(cache=True)
def _degree(gcell, passable, H, W, p):
    n = 0
    for k in range(8):
        if _move(gcell, passable, H, W, p, k) >= 0:
            n += 1
    return n


@njit(cache=True, inline="always")
def _edge_at(gedge, gser, eser, q):
    """The live edge whose interior holds cell q, or -1."""
    e = gedge[q] - 1
    if e >= 0 and eser[e] == gser[q]:
        return e
    return -1


@njit(cache=True)
def _affected(gcell, skeleton, passable, H, W, changed, mark, gen):
    """Graph cells (as they were, or as they will be) within one cell of a changed cell, sorted."""
    out = np.empty(9 * changed.shape[0] + 1, np.int64)
    n = 0
    for i in range(changed.shape[0]):
        q0 = changed[i]
        r0 = q0 // W
        c0 = q0 - r0 * W
        for r in range(max(0, r0 - 1), min(H, r0 + 2)):
            for c in range(max(0, c0 - 1), min(W, c0 + 2)):
                q = r * W + c
                if mark[q] == gen:
                    continue
                mark[q] = gen
                if gcell[q] or (skeleton[q] and passable[q]):
                    out[n] = q
                    n += 1
    return np.sort(out[:n])


@njit(cache=True)
def _drop(aff, gcell, gnode, gedge, gser, ncell, nadj, nalive, nfree, ea, eb, ka, kb, eser, ealive, efree, st, redo):
    """Drop the nodes at affected cells and every edge through or at them; the nodes that keep
    going but lost an edge go to ``redo``. Returns how many."""
    nr = 0
    for i in range(aff.shape[0]):
        q = aff[i]
        u = gnode[q] - 1
        if u >= 0:
            for k in range(8):
                e = nadj[u, k]
                if e >= 0:
                    nr = _drop_edge(e, nadj, ea, eb, ka, kb, eser, ealive, efree, st, redo, nr)
            nalive[u] = False
            nfree[st[1]] = u
            st[1] += 1
            gnode[q] = 0
        else:
            e = _edge_at(gedge, gser, eser, q)
            if e >= 0:
                nr = _drop_edge(e, nadj, ea, eb, ka, kb, eser, ealive, efree, st, redo, nr)
    return nr


@njit(cache=True)
def _drop_edge(e, nadj, ea, eb, ka, kb, eser, ealive, efree, st, redo, nr):
    if not ealive[e]:
        return nr
    ealive[e] = False
    eser[e] = 0  # its cells' records no longer match any edge (serials start at 1)
    efree[st[3]] = e
    st[3] += 1
    nadj[ea[e], ka[e]] = -1
    nadj[eb[e], kb[e]] = -1
    redo[nr] = ea[e]
    redo[nr + 1] = eb[e]
    return nr + 2


@njit(cache=True, inline="always")
def _take(free, st, hwm, n_free, cap):
    """An id: the last freed one (``st[n_free]`` of them in ``free``), else the next never used
    (``st[hwm]``); -1 when ``cap`` are in use."""
    if st[n_free] > 0:
        st[n_free] -= 1
        return free[st[n_free]]
    u = st[hwm]
    if u >= cap:
        return -1
    st[hwm] += 1
    return u


@njit(cache=True)
def _new_node(q, gnode, ncell, nadj, nalive, nfree, st):
    u = _take(nfree, st, 0, 1, ncell.shape[0])
    if u < 0:
        return -1
    ncell[u] = q
    nadj[u, :] = -1
    nalive[u] = True
    gnode[q] = u + 1
    return u


@njit(cache=True)
def _trace(u, k, gcell, passable, H, W, gnode, gedge, gser, gpos, glink, ncell, nadj, ea, eb, ka, kb, elen, efirst, elast, eser,
           ealive, efree, st):
    """The edge leaving node u by move k (which must be allowed and free), traced to its other
    node; returns its id, or -1 when the chain ends at a cell that is no node (a broken graph)."""
    e = _take(efree, st, 2, 3, ea.shape[0])
    if e < 0:
        return -2
    st[4] += 1
    ser = st[4]
    prev = ncell[u]
    cur = _move(gcell, passable, H, W, prev, k)
    length = _PK[k]
    kdir = k
    first = -1
    last = -1
    while True:
        v = gnode[cur] - 1
        if v >= 0:
            break
        if first < 0:
            first = cur
        last = cur
        gedge[cur] = e + 1
        gser[cur] = ser
        gpos[cur] = length
        back = _OPP[kdir]  # the move back toward the edge's first node
        nxt = -1
        for j in range(8):
            q = _move(gcell, passable, H, W, cur, j)
            if q >= 0 and q != prev:
                nxt = q
                kdir = j
                break
        if nxt < 0:
            return -1
        glink[cur] = np.uint8(back | (kdir << 4))
        length += _PK[kdir]
        prev = cur
        cur = nxt
    ea[e] = u
    eb[e] = v
    ka[e] = k
    kb[e] = _OPP[kdir]
    elen[e] = length
    efirst[e] = first
    elast[e] = last
    eser[e] = ser
    ealive[e] = True
    nadj[u, k] = e
    nadj[v, _OPP[kdir]] = e
    # one orientation whatever the node it was traced from: the first node is the one of lesser
    # cell index; on a loop, the way whose first cell has the lesser index
    if ncell[v] < ncell[u] or (u == v and last < first):
        ea[e], eb[e], ka[e], kb[e], efirst[e], elast[e] = v, u, kb[e], k, last, first
        q = first
        while q >= 0:
            gpos[q] = length - gpos[q]
            lk = np.int64(glink[q])
            glink[q] = np.uint8((lk >> 4) | ((lk & 15) << 4))
            q = _walk(q, e, False, W, glink, gnode)  # on along the chain (its cells' links were swapped)
    return e


@njit(cache=True)
def _rebuild(aff, redo_in, n_redo, gcell, skeleton, passable, H, W, gnode, gedge, gser, gpos, glink, ncell, nadj, nalive, nfree,
             ea, eb, ka, kb, elen, efirst, elast, eser, ealive, efree, st):
    """Judge the affected cells again (membership, node or not), turn the nodes that lost an edge
    and now have degree 2 into chain cells, and trace the chains again from the nodes that lost an
    edge and the new ones; a cycle of degree-2 cells left without a node gets its cell of least
    index as one. So the graph is the same whatever the order of the repairs that made it.
    Returns 0, -1 when a chain ended nowhere, -2 when the storage ran out."""
    redo = np.empty(max(16, 2 * n_redo + aff.shape[0]), np.int64)
    redo[:n_redo] = redo_in[:n_redo]
    m = n_redo
    check = np.empty(16, np.int64)
    n_check = 0
    for i in range(aff.shape[0]):
        q = aff[i]
        gcell[q] = skeleton[q] and passable[q]
    for i in range(aff.shape[0]):
        q = aff[i]
        if gcell[q] and _degree(gcell, passable, H, W, q) != 2:
            u = _new_node(q, gnode, ncell, nadj, nalive, nfree, st)
            if u < 0:
                return -2
            redo, m = _emit(redo, m, u)
    i = 0
    while i < m:  # nodes left with degree 2 become chain cells (their edges go, their ends are traced again)
        u = redo[i]
        i += 1
        if not nalive[u] or _degree(gcell, passable, H, W, ncell[u]) != 2:
            continue
        for k in range(8):
            e = nadj[u, k]
            if e >= 0 and ealive[e]:
                redo, m = _emit(redo, m, ea[e])
                redo, m = _emit(redo, m, eb[e])
                _drop_edge(e, nadj, ea, eb, ka, kb, eser, ealive, efree, st, redo, m - 2)
        nalive[u] = False
        nfree[st[1]] = u
        st[1] += 1
        gnode[ncell[u]] = 0
        check, n_check = _emit(check, n_check, ncell[u])
    for i in range(m):
        u = redo[i]
        if nalive[u]:
            e = _trace_all(u, gcell, passable, H, W, gnode, gedge, gser, gpos, glink, ncell, nadj, ea, eb, ka, kb, elen, efirst,
                           elast, eser, ealive, efree, st)
            if e < 0:
                return e
    for j in range(aff.shape[0] + n_check):  # a cycle left without a node: its least cell becomes one
        q = aff[j] if j < aff.shape[0] else check[j - aff.shape[0]]
        if not gcell[q] or gnode[q] != 0 or _edge_at(gedge, gser, eser, q) >= 0:
            continue
        least = _least_of_cycle(q, gcell, passable, H, W, gnode)
        if least < 0:
            return -1
        u = _new_node(least, gnode, ncell, nadj, nalive, nfree, st)
        if u < 0:
            return -2
        e = _trace_all(u, gcell, passable, H, W, gnode, gedge, gser, gpos, glink, ncell, nadj, ea, eb, ka, kb, elen, efirst, elast,
                       eser, ealive, efree, st)
        if e < 0:
            return e
    return 0


@njit(cache=True)
def _trace_all(u, gcell, passable, H, W, gnode, gedge, gser, gpos, glink, ncell, nadj, ea, eb, ka, kb, elen, efirst, elast, eser,
               ealive, efree, st):
    """Trace the edges leaving node u by every allowed move that has none yet; 0, or
    :func:`_trace`'s error."""
    for k in range(8):
        if nadj[u, k] < 0 and _move(gcell, passable, H, W, ncell[u], k) >= 0:
            e = _trace(u, k, gcell, passable, H, W, gnode, gedge, gser, gpos, glink, ncell, nadj, ea, eb, ka, kb, elen, efirst,
                       elast, eser, ealive, efree, st)
            if e < 0:
                return e
    return 0


@njit(cache=True)
def _least_of_cycle(q, gcell, passable, H, W, gnode):
    """The cell of least index on the cycle of degree-2 cells through q, or -1 when the cells
    from q reach a node (not a cycle)."""
    least = q
    prev = -1
    cur = q
    while True:
        nxt = -1
        for j in range(8):
            x = _move(gcell, passable, H, W, cur, j)
            if x >= 0 and x != prev:
                nxt = x
                break
        if nxt < 0 or gnode[nxt] != 0:
            return -1
        if nxt == q:
            return least
        least = min(least, nxt)
        prev = cur
        cur = nxt


# ---- searches ---------------------------------------------------------------------------------

@njit(cache=True)
def _local(passable, cost, H, W, r0, c0, radius, reverse):
    """Dijkstra over the passable cells 4-connected to (r0, c0) within ``radius`` cells (a disk),
    8-connected moves inside that region (a diagonal needs both orthogonal cells in it), entering
    cell q costing step * cost[q]. With ``reverse``, costs are those of paths *toward* (r0, c0).

    Returns (R, S, inside, cst, lng, par): the window of side S = 2R + 1 centred on (r0, c0),
    (S*S,) arrays over it: region membership, cost, length and the previous cell (window index;
    with ``reverse``, the next cell toward the centre), -1 at the centre."""
    R = int(math.ceil(radius))
    S = 2 * R + 1
    inside = np.zeros(S * S, np.bool_)
    cst = np.full(S * S, np.inf)
    lng = np.full(S * S, np.inf)
    par = np.full(S * S, -1, np.int64)
    if r0 < 0 or r0 >= H or c0 < 0 or c0 >= W or not passable[r0 * W + c0]:
        return R, S, inside, cst, lng, par
    rr, cc = local_reach(passable.reshape(H, W), r0, c0, radius, False)
    for i in range(rr.shape[0]):
        inside[(rr[i] - r0 + R) * S + cc[i] - c0 + R] = True
    hk = np.empty(8 * S * S + 1)
    hi = np.empty(8 * S * S + 1, np.int64)
    done = np.zeros(S * S, np.bool_)
    n = 0
    cst[R * S + R] = 0.0
    lng[R * S + R] = 0.0
    heap_push(hk, hi, n, 0.0, R * S + R)
    n += 1
    while n > 0:
        d = hk[0]
        li = hi[0]
        heap_drop_top(hk, hi, n)
        n -= 1
        if done[li]:
            continue
        done[li] = True
        lr = li // S
        lc = li - lr * S
        for k in range(8):
            mr = lr + _DR[k]
            mc = lc + _DC[k]
            if mr < 0 or mr >= S or mc < 0 or mc >= S:
                continue
            lj = mr * S + mc
            if not inside[lj] or done[lj]:
                continue
            if k >= 4 and not (inside[lr * S + mc] and inside[mr * S + lc]):
                continue
            into = lj if not reverse else li  # the cell entered: lj going out; li on the way to the centre
            q = (r0 + (into // S) - R) * W + (c0 + (into % S) - R)
            nd = d + _STEP[k] * cost[q]
            if nd < cst[lj]:
                cst[lj] = nd
                lng[lj] = lng[li] + _STEP[k]
                par[lj] = li
                heap_push(hk, hi, n, nd, lj)
                n += 1
    return R, S, inside, cst, lng, par


@njit(cache=True)
def _nodes(seeds, scost, slen, gnode, gedge, gser, gpos, ncell, nadj, ea, eb, elen, eser, dc, dl, dpar, dedge, dseed, dend,
           dgen, gen, hk, hi):
    """Dijkstra over the nodes from the seeds (graph cells with a cost and length), settling them
    in the order of (cost, cell index). A node's record: cost, length, the node before it (-1: it
    was reached from a seed), the edge used (-1: the seed is the node), the seed and, for a seed on
    an edge, the end it entered the node by (0: the edge's first node, 1: its second). Returns 0, or
    -1 when the heap is full (the caller grows it and searches again)."""
    n = 0
    cap = hk.shape[0]
    for s in range(seeds.shape[0]):
        q = seeds[s]
        u = gnode[q] - 1
        if u >= 0:
            if _relax(u, scost[s], slen[s], -1, -1, s, 0, dc, dl, dpar, dedge, dseed, dend, dgen, gen):
                if n == cap:
                    return -1
                heap_push(hk, hi, n, scost[s], ncell[u])
                n += 1
            continue
        e = _edge_at(gedge, gser, eser, q)
        if e < 0:
            continue
        for end in range(2):
            v = ea[e] if end == 0 else eb[e]
            w = _len(gpos[q]) if end == 0 else _len(elen[e] - gpos[q])
            if _relax(v, scost[s] + w, slen[s] + w, -1, e, s, end, dc, dl, dpar, dedge, dseed, dend, dgen, gen):
                if n == cap:
                    return -1
                heap_push(hk, hi, n, scost[s] + w, ncell[v])
                n += 1
    while n > 0:
        d = hk[0]
        u = gnode[hi[0]] - 1
        heap_drop_top(hk, hi, n)
        n -= 1
        if d > dc[u]:  # a stale entry
            continue
        for k in range(8):
            e = nadj[u, k]
            if e < 0:
                continue
            v = eb[e] if ea[e] == u else ea[e]
            if v == u:
                continue
            L = _len(elen[e])
            if _relax(v, d + L, dl[u] + L, u, e, -1, 0, dc, dl, dpar, dedge, dseed, dend, dgen, gen):
                if n == cap:
                    return -1
                heap_push(hk, hi, n, d + L, ncell[v])
                n += 1
    return 0


@njit(cache=True)
def _relax(v, c, ln, u, e, s, end, dc, dl, dpar, dedge, dseed, dend, dgen, gen):
    if dgen[v] == gen and not c < dc[v]:
        return False
    dgen[v] = gen
    dend[v] = end
    dc[v] = c
    dl[v] = ln
    dpar[v] = u
    dedge[v] = e
    dseed[v] = s
    return True


@njit(cache=True)
def _at(q, seeds, scost, slen, gnode, gedge, gser, gpos, ea, eb, elen, eser, dc, dl, dgen, gen):
    """A graph cell's cost and length from the robot, and how: (cost, length, way, seed) with way
    0 the node itself, 1 through the edge's first node, 2 its second, 3 from a seed on its edge."""
    u = gnode[q] - 1
    if u >= 0:
        if dgen[u] == gen:
            return dc[u], dl[u], 0, -1
        return INF, INF, 0, -1
    e = _edge_at(gedge, gser, eser, q)
    if e < 0:
        return INF, INF, 0, -1
    p = _len(gpos[q])
    pb = _len(elen[e] - gpos[q])
    bc, bl, way, seed = INF, INF, 0, -1
    a, b = ea[e], eb[e]
    if dgen[a] == gen and dc[a] + p < bc:
        bc, bl, way = dc[a] + p, dl[a] + p, 1
    if dgen[b] == gen and dc[b] + pb < bc:
        bc, bl, way = dc[b] + pb, dl[b] + pb, 2
    for s in range(seeds.shape[0]):
        if _edge_at(gedge, gser, eser, seeds[s]) == e:
            dv = gpos[seeds[s]] - gpos[q]  # both counts move the same way along an edge
            w = _len(dv if dv >= 0 else -dv)
            if scost[s] + w < bc:
                bc, bl, way, seed = scost[s] + w, slen[s] + w, 3, s
    return bc, bl, way, seed


@njit(cache=True)
def _targets(tq, r0, c0, R, S, rin, rcst, rlen, passable, cost, H, W, radius, seeds, scost, slen, gcell, gnode, gedge, gser,
             gpos, ea, eb, elen, eser, dc, dl, dgen, gen):
    """Each target's cost and length from the robot, and how: kind 0 directly in the robot's join
    region, 1 along the graph to cell y (then, off the graph, through the target's join region),
    2 through the robot's region to cell y of the target's."""
    n = tq.shape[0]
    tc = np.full(n, np.inf)
    tl = np.full(n, np.inf)
    kind = np.zeros(n, np.int64)
    ty = np.full(n, -1, np.int64)
    for i in range(n):
        t = tq[i]
        li = _win(t, r0, c0, R, S, W)
        if li >= 0 and rin[li] and rcst[li] < tc[i]:
            tc[i], tl[i], kind[i], ty[i] = rcst[li], rlen[li], 0, t
        if gcell[t]:
            c, ln, _, _ = _at(t, seeds, scost, slen, gnode, gedge, gser, gpos, ea, eb, elen, eser, dc, dl, dgen, gen)
            if c < tc[i]:
                tc[i], tl[i], kind[i], ty[i] = c, ln, 1, t
            continue
        TR, TS, tin, tcst, tlen, _ = _local(passable, cost, H, W, t // W, t % W, radius, True)
        for lj in range(TS * TS):
            if not tin[lj] or not tcst[lj] < np.inf:
                continue
            y = (t // W + lj // TS - TR) * W + (t % W + lj % TS - TR)
            li = _win(y, r0, c0, R, S, W)
            if li >= 0 and rin[li] and rcst[li] + tcst[lj] < tc[i]:
                tc[i], tl[i], kind[i], ty[i] = rcst[li] + tcst[lj], rlen[li] + tlen[lj], 2, y
            if gcell[y]:
                c, ln, _, _ = _at(y, seeds, scost, slen, gnode, gedge, gser, gpos, ea, eb, elen, eser, dc, dl, dgen, gen)
                if c + tcst[lj] < tc[i]:
                    tc[i], tl[i], kind[i], ty[i] = c + tcst[lj], ln + tlen[lj], 1, y
    return tc, tl, kind, ty


@njit(cache=True, inline="always")
def _win(q, r0, c0, R, S, W):
    """Index of flat cell q in the window of side S centred on (r0, c0), or -1 outside it."""
    lr = q // W - r0 + R
    lc = q % W - c0 + R
    if lr < 0 or lr >= S or lc < 0 or lc >= S:
        return -1
    return lr * S + lc


@njit(cache=True, inline="always")
def _walk(q, e, up, W, glink, gnode):
    """The cell after interior cell q along its edge, toward the edge's second node (``up``) or
    its first; -1 when that is the node."""
    v = np.int64(glink[q])
    k = (v >> 4) if up else (v & 15)
    x = q + _DR[k] * W + _DC[k]
    return -1 if gnode[x] > 0 else x


@njit(cache=True)
def _back(y, seeds, scost, slen, H, W, gnode, gedge, gser, gpos, glink, ncell, ea, eb, elen, efirst, elast, eser, dc, dl, dpar, dedge,
          dseed, dend, dgen, gen):
    """The graph part of the path to graph cell y, from y back to the seed it starts at: (cells,
    seed index)."""
    buf = np.empty(256, np.int64)
    n = 0
    _, _, way, seed = _at(y, seeds, scost, slen, gnode, gedge, gser, gpos, ea, eb, elen, eser, dc, dl, dgen, gen)
    buf, n = _emit(buf, n, y)
    if way == 0:
        u = gnode[y] - 1
    else:
        e = _edge_at(gedge, gser, eser, y)
        if way == 3:
            qs = seeds[seed]
            up = gpos[qs] > gpos[y]
            q = y
            while q != qs:
                q = _walk(q, e, up, W, glink, gnode)
                buf, n = _emit(buf, n, q)
            return buf[:n], seed
        up = way == 2
        q = _walk(y, e, up, W, glink, gnode)
        while q >= 0:
            buf, n = _emit(buf, n, q)
            q = _walk(q, e, up, W, glink, gnode)
        u = eb[e] if up else ea[e]
        buf, n = _emit(buf, n, ncell[u])
    while dpar[u] >= 0:
        e = dedge[u]
        p = dpar[u]
        at_b = eb[e] == u
        q = elast[e] if at_b else efirst[e]
        while q >= 0:
            buf, n = _emit(buf, n, q)
            q = _walk(q, e, not at_b, W, glink, gnode)
        buf, n = _emit(buf, n, ncell[p])
        u = p
    seed = dseed[u]
    e = dedge[u]
    if e >= 0:
        qs = seeds[seed]
        at_b = dend[u] == 1
        q = elast[e] if at_b else efirst[e]
        buf, n = _emit(buf, n, q)
        while q != qs:
            q = _walk(q, e, not at_b, W, glink, gnode)
            buf, n = _emit(buf, n, q)
    return buf[:n], seed


@njit(cache=True, inline="always")
def _emit(buf, n, q):
    if n == buf.shape[0]:
        b = np.empty(2 * n, np.int64)
        b[:n] = buf
        buf = b
    buf[n] = q
    return buf, n + 1


@njit(cache=True)
def _unwind(li, par, r0, c0, R, S, W):
    """Flat cells of a join region's path from window cell li along ``par`` to the centre."""
    n = 0
    j = li
    while j >= 0:
        n += 1
        j = par[j]
    out = np.empty(n, np.int64)
    j = li
    k = 0
    while j >= 0:
        out[k] = (r0 + j // S - R) * W + (c0 + j % S - R)
        k += 1
        j = par[j]
    return out


@njit(cache=True)
def rank_targets(q, cost, need):
    """The first ``need`` distinct cells of ``q`` (flat indices) with a finite ``cost``, in the
    order of (cost, cell index) (a cell listed twice counts once, at its least cost), sorted by
    cell index."""
    fin = np.flatnonzero(np.isfinite(cost))
    if fin.shape[0] == 0 or need <= 0:
        return np.empty(0, np.int64)
    keys = cost[fin]
    cells = q[fin]
    order = np.argsort(cells, kind="mergesort")
    order = order[np.argsort(keys[order], kind="mergesort")]  # by cost, then cell (a stable sort of a sort by cell)
    out = np.empty(min(need, order.shape[0]), np.int64)
    n = 0
    for i in range(order.shape[0]):
        x = cells[order[i]]
        seen = False
        for j in range(n):
            if out[j] == x:
                seen = True
                break
        if not seen:
            out[n] = x
            n += 1
            if n == out.shape[0]:
                break
    return np.sort(out[:n])


@njit(cache=True)
def _seeds_of(rin, rcst, rlen, r, c, R, S, W, gcell):
    """The graph cells of the robot's join region, with their cost and length, in window order."""
    n = 0
    for li in range(S * S):
        if rin[li] and rcst[li] < np.inf and gcell[(r + li // S - R) * W + (c + li % S - R)]:
            n += 1
    seeds = np.empty(n, np.int64)
    scost = np.empty(n)
    slen = np.empty(n)
    k = 0
    for li in range(S * S):
        if rin[li] and rcst[li] < np.inf:
            q = (r + li // S - R) * W + (c + li % S - R)
            if gcell[q]:
                seeds[k] = q
                scost[k] = rcst[li]
                slen[k] = rlen[li]
                k += 1
    return seeds, scost, slen


class SkeletonGraph:
    """The contracted skeleton graph of one grid shape (see the module's text): :meth:`repair`
    after the skeleton or passable cells change, :meth:`search` from the robot."""

    def __init__(self, shape):
        H, W = shape
        self.shape = (H, W)
        N = H * W
        self.gcell = lazy_zeros(N, bool)  # graph cells, as of the last repair
        self.gnode = lazy_zeros(N, np.int32)  # node id + 1 at nodes, 0 elsewhere
        self.gedge = lazy_zeros(N, np.int32)  # at interior cells: edge id + 1 (valid while gser matches)
        self.gser = lazy_zeros(N, np.int64)
        self.gpos = lazy_zeros(N, np.int64)  # at interior cells: moves from the edge's first node (packed: _len)
        self.glink = lazy_zeros(N, np.uint8)  # at interior cells: the moves to the previous (low 4 bits) and next cell
        self._mark = lazy_zeros(N, np.int64)
        self._mgen = 0
        self.st = np.zeros(8, np.int64)  # node high-water mark, free nodes, edge high-water mark, free edges, serial
        self._nodes_cap(0)
        self._edges_cap(0)
        self.gen = 0

    # ---- storage ---------------------------------------------------------------------------
    _NODE_FIELDS = {"ncell": (np.int64, 0), "nadj": (np.int32, -1), "nalive": (bool, False), "nfree": (np.int64, 0),
                    "dc": (np.float64, np.inf), "dl": (np.float64, np.inf), "dpar": (np.int64, -1), "dedge": (np.int64, -1),
                    "dseed": (np.int64, -1), "dend": (np.int64, 0), "dgen": (np.int64, 0)}
    _EDGE_FIELDS = {name: (dt, 0) for name, dt in (("ea", np.int64), ("eb", np.int64), ("ka", np.int64), ("kb", np.int64),
                                                   ("elen", np.int64), ("efirst", np.int64), ("elast", np.int64),
                                                   ("eser", np.int64), ("ealive", bool), ("efree", np.int64))}

    def _room(self, fields: dict, need: int, first: int) -> bool:
        """Grow the arrays ``fields`` (name: (dtype, fill); ``nadj`` has 8 slots a row) to hold at
        least ``need`` rows, doubling; returns whether they grew."""
        old = getattr(self, next(iter(fields)), None)
        cap = first if old is None else old.shape[0]
        if old is not None and cap >= need:
            return False
        while cap < need:
            cap *= 2
        for name, (dt, fill) in fields.items():
            a = np.full((cap, 8) if name == "nadj" else (cap,), fill, dt)
            if old is not None:
                a[: old.shape[0]] = getattr(self, name)
            setattr(self, name, a)
        return True

    def _nodes_cap(self, need: int) -> None:
        self._room(self._NODE_FIELDS, need, 256)

    def _edges_cap(self, need: int) -> None:
        if self._room(self._EDGE_FIELDS, need, 512):
            cap = self.ea.shape[0]
            self._heap = (np.empty(4 * cap + 64), np.empty(4 * cap + 64, np.int64))

    @property
    def n_nodes(self) -> int:
        return int(self.st[0] - self.st[1])

    @property
    def n_edges(self) -> int:
        return int(self.st[2] - self.st[3])

    # ---- repair ------------------------------------------------------------------------------
    def repair(self, skeleton: np.ndarray, passable: np.ndarray, changed: np.ndarray) -> int:
        """Bring the graph up to date after the cells ``changed`` (flat indices) changed in
        ``skeleton`` or ``passable`` ((H, W) bool, as they are now). Returns the number of
        affected cells."""
        if len(changed) == 0:
            return 0
        self.gen += 1  # a search made before this repair answers no more paths
        H, W = self.shape
        sk, pa = skeleton.reshape(-1), passable.reshape(-1)
        self._mgen += 1
        aff = _affected(self.gcell, sk, pa, H, W, np.asarray(changed, np.int64), self._mark, self._mgen)
        if aff.shape[0] == 0:
            return 0
        redo = np.empty(18 * aff.shape[0] + 16, np.int64)
        n_redo = _drop(aff, self.gcell, self.gnode, self.gedge, self.gser, self.ncell, self.nadj, self.nalive, self.nfree,
                       self.ea, self.eb, self.ka, self.kb, self.eser, self.ealive, self.efree, self.st, redo)
        self._nodes_cap(int(self.st[0]) + 2 * aff.shape[0])
        self._edges_cap(int(self.st[2]) + 8 * (n_redo + 2 * aff.shape[0]))
        ok = _rebuild(aff, redo, n_redo, self.gcell, sk, pa, H, W, self.gnode, self.gedge, self.gser, self.gpos, self.glink,
                      self.ncell,
                      self.nadj, self.nalive, self.nfree, self.ea, self.eb, self.ka, self.kb, self.elen, self.efirst, self.elast,
                      self.eser, self.ealive, self.efree, self.st)
        if ok == -2:  # pragma: no cover - the bounds above hold: say so rather than write past the storage
            raise RuntimeError("skeleton graph: node or edge storage ran out during a repair")
        if ok < 0:  # pragma: no cover - an invariant broken: say so rather than search a wrong graph
            raise RuntimeError("skeleton graph: a chain ended at a cell that is not a node")
        return int(aff.shape[0])

    # ---- searches ----------------------------------------------------------------------------
    def search(self, r: int, c: int, robot_passable: np.ndarray, passable: np.ndarray, cost: np.ndarray, t_rows, t_cols,
               n_stop: int, radius: float) -> "GraphSearch":
        """Costs and lengths (cells) from the robot cell (r, c) to the targets (see the module's
        text): the robot joined over ``robot_passable``, off-graph targets over ``passable``,
        both under ``cost`` (which must be 1 on the skeleton). Only the first ``n_stop`` targets
        (0: all) in the order of (cost, cell index) count as reached."""
        H, W = self.shape
        rp, pa, co = robot_passable.reshape(-1), passable.reshape(-1), cost.reshape(-1)
        R, S, rin, rcst, rlen, rpar = _local(rp, co, H, W, int(r), int(c), radius, False)
        seeds, scost, slen = _seeds_of(rin, rcst, rlen, int(r), int(c), R, S, W, self.gcell)
        while True:
            self.gen += 1
            hk, hi = self._heap
            if _nodes(seeds, scost, slen, self.gnode, self.gedge, self.gser, self.gpos, self.ncell, self.nadj, self.ea, self.eb,
                      self.elen, self.eser, self.dc, self.dl, self.dpar, self.dedge, self.dseed, self.dend, self.dgen, self.gen,
                      hk, hi) == 0:
                break
            self._heap = (np.empty(2 * hk.shape[0]), np.empty(2 * hi.shape[0], np.int64))
        tq = np.asarray(t_rows, np.int64) * W + np.asarray(t_cols, np.int64)
        tc, tl, kind, ty = _targets(tq, int(r), int(c), R, S, rin, rcst, rlen, pa, co, H, W, radius, seeds, scost, slen,
                                    self.gcell, self.gnode, self.gedge, self.gser, self.gpos, self.ea, self.eb, self.elen,
                                    self.eser, self.dc, self.dl, self.dgen, self.gen)
        if n_stop > 0:  # reached: the first n_stop distinct target cells in the order of (cost, cell index)
            kept = rank_targets(tq, tc, int(n_stop))
            off = ~np.isin(tq, kept)
            tc, tl = np.where(off, np.inf, tc), np.where(off, np.inf, tl)
        need = int(np.unique(tq[np.isfinite(tc)]).size)
        return GraphSearch(self, (int(r), int(c)), tq, tc, tl, kind, ty, (R, S, rpar), (seeds, scost, slen), (pa, co, radius), need)


class GraphSearch:
    """One search's answer (:meth:`SkeletonGraph.search`): :meth:`lengths`, :meth:`costs`,
    :meth:`settled` and :meth:`path` for its targets, as :class:`~semsearch_cli.kernels.grid.GridSearch`
    answers them; valid until the graph's next search or repair."""

    def __init__(self, graph, source, tq, tc, tl, kind, ty, robot, seeds, join, reached):
        self.graph, self.source, self.gen = graph, source, graph.gen
        order = np.argsort(tq, kind="stable")
        self._tq, self._tc, self._tl, self._kind, self._ty = tq[order], tc[order], tl[order], kind[order], ty[order]
        self._robot, self._seeds, self._join = robot, seeds, join
        self.reached = reached  # distinct targets reached

    def _find(self, rows, cols):
        q = np.asarray(rows, np.int64) * self.graph.shape[1] + np.asarray(cols, np.int64)
        i = np.clip(np.searchsorted(self._tq, q), 0, max(len(self._tq) - 1, 0))
        hit = (self._tq[i] == q) if len(self._tq) else np.zeros(q.shape, bool)
        return i, hit

    def lengths(self, rows, cols) -> np.ndarray:
        """Path length (cells) to each given cell, inf where it is not a reached target."""
        i, hit = self._find(rows, cols)
        return np.where(hit, self._tl[i] if len(self._tl) else np.inf, np.inf)

    def costs(self, rows, cols) -> np.ndarray:
        i, hit = self._find(rows, cols)
        return np.where(hit, self._tc[i] if len(self._tc) else np.inf, np.inf)

    def settled(self, rows, cols) -> np.ndarray:
        return np.isfinite(self.costs(rows, cols))

    def path(self, r, c):
        """Cells (rows, cols) from the robot to the reached target (r, c), or None."""
        i, hit = self._find(np.int64(r), np.int64(c))
        i = int(i)
        if not bool(hit) or not np.isfinite(self._tc[i]):
            return None
        g = self.graph
        if g.gen != self.gen:
            raise RuntimeError("a skeleton-graph search's path asked for after another search or a repair")
        H, W = g.shape
        r0, c0 = self.source
        R, S, rpar = self._robot
        seeds, scost, slen = self._seeds
        t, y, kind = int(self._tq[i]), int(self._ty[i]), int(self._kind[i])
        if kind == 1:
            back, s = _back(y, seeds, scost, slen, H, W, g.gnode, g.gedge, g.gser, g.gpos, g.glink, g.ncell, g.ea, g.eb, g.elen, g.efirst,
                            g.elast, g.eser, g.dc, g.dl, g.dpar, g.dedge, g.dseed, g.dend, g.dgen, g.gen)
            head = _unwind(_win(int(seeds[s]), r0, c0, R, S, W), rpar, r0, c0, R, S, W)[::-1]
            cells = np.concatenate([head[:-1], back[::-1]])
        else:
            cells = _unwind(_win(y, r0, c0, R, S, W), rpar, r0, c0, R, S, W)[::-1]
        if y != t:  # through the target's join region, from y on toward it
            pa, co, radius = self._join
            TR, TS, _, _, _, tpar = _local(pa, co, H, W, t // W, t % W, radius, True)
            tail = _unwind(_win(y, t // W, t % W, TR, TS, W), tpar, t // W, t % W, TR, TS, W)
            cells = np.concatenate([cells[:-1], tail])
        return cells // W, cells % W
