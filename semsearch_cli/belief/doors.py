"""The robot's belief, built from sensing only: HIMM occupancy, visited region and its
density classes, skeleton, clearance, door reads, frontier candidates.

Per-step updates touch only a window around the robot; the derived maps (clearance, skeleton) are
refreshed at re-plan time inside the bounding box of what changed since the last refresh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..config import BeliefSpec
from ..geometry import GridFrame, wrap_angle
from ..kernels.grid import GridSearch, branch_walk, local_reach, mark_visited, nearest_visited, segment_roots, widest_of_groups
from ..kernels.memory import lazy_zeros
from ..kernels.raycast import fold_free, himm_update, mark_viewed
from ..kernels.skelgraph import SkeletonGraph, rank_targets
from ..kernels.skeleton import Skeleton

CLEARANCE_CAP_M = 1.0
CONNECT_M = 1.5
BRANCH_DEPTH = 10
MIN_BRANCH_CELLS = 3


@dataclass
class Candidates:
    """Frontier candidates C: one skeleton cell per branch leaving the visited region, k of them
    (``len(cands)``), as parallel arrays.

    - ``rows``, ``cols``: (k,) int64, the candidate cells (grid indices; ``belief.frame.to_world``
      gives metres);
    - ``theta``: (k,) float64, radians counter-clockwise from +x, the branch direction theta_f
      pointing out of the visited region;
    - ``seg_rows``, ``seg_cols``: (k,) int64, a visited cell the candidate touches: its segment
      S(c) is that cell's corridor segment (``belief.segment_door_lists`` gives the signs read
      there).

    ``take(idx)`` selects candidates; ``concat(other)`` joins two sets.
    """

    rows: np.ndarray
    cols: np.ndarray
    theta: np.ndarray
    seg_rows: np.ndarray
    seg_cols: np.ndarray

    def __len__(self) -> int:
        return int(self.rows.shape[0])

    def take(self, idx) -> "Candidates":
        return Candidates(self.rows[idx], self.cols[idx], self.theta[idx], self.seg_rows[idx], self.seg_cols[idx])

    def concat(self, other: "Candidates") -> "Candidates":
        return Candidates(*(np.concatenate([getattr(self, f), getattr(other, f)]) for f in ("rows", "cols", "theta", "seg_rows", "seg_cols")))


class DoorReads:
    """Every sign read, kept so door lists can be rebuilt when segments change.

    Reads are aggregated per (label, robot cell): ``cell``, ``label`` (index into ``labels``),
    ``count``, ``sx``, ``sy`` (sums of robot x, y in m), ``sbx``, ``sby`` (sums of the unit
    vector from the robot toward the sign, its bearing), ``snx``, ``sny`` (sums of the unit vector
    of the camera's axis that saw it: the heading turned 90 degrees toward the sign's side) and
    ``bearings`` (reads that gave a bearing; the others add 0 to those sums) are arrays of the
    first ``n`` rows. ``total`` counts reads per label; ``headings`` is the robot
    heading (radians) at each read.
    """

    def __init__(self):
        self.labels: list = []  # label values in order of first read
        self._label_id: dict = {}
        self._row: dict = {}
        self.n = 0
        self.cell = np.zeros(256, np.int64)
        self.label = np.zeros(256, np.int64)
        self.count = np.zeros(256, np.int64)
        self.sx = np.zeros(256)
        self.sy = np.zeros(256)
        self.sbx = np.zeros(256)
        self.sby = np.zeros(256)
        self.snx = np.zeros(256)
        self.sny = np.zeros(256)
        self.bearings = np.zeros(256, np.int64)
        self.total: dict = {}
        self.headings: list = []

    def add(self, label, cell: int, x: float, y: float, heading: float, bearing: float | None = None) -> int:
        """Record one read of ``label`` from robot cell ``cell`` at robot pose (x, y, heading),
        the sign seen in direction ``bearing`` (radians; None: not known); returns the label's
        total read count."""
        row = self._row.get((label, cell))
        if row is None:
            lid = self._label_id.get(label)
            if lid is None:
                lid = self._label_id[label] = len(self.labels)
                self.labels.append(label)
            if self.n == self.cell.shape[0]:
                for f in ("cell", "label", "count", "sx", "sy", "sbx", "sby", "snx", "sny", "bearings"):
                    a = getattr(self, f)
                    setattr(self, f, np.concatenate([a, np.zeros_like(a)]))
            row = self._row[(label, cell)] = self.n
            self.cell[row], self.label[row] = cell, lid
            self.n += 1
        self.count[row] += 1
        self.sx[row] += x
        self.sy[row] += y
        if bearing is not None:
            self.sbx[row] += math.cos(bearing)
            self.sby[row] += math.sin(bearing)
            axis = heading + math.copysign(math.pi / 2, math.sin(bearing - heading))
            self.snx[row] += math.cos(axis)
            self.sny[row] += math.sin(axis)
            self.bearings[row] += 1
        n = self.total.get(label, 0) + 1
        self.total[label] = n
        self.headings.append(heading)
        return n

    def lists(self, rows: np.ndarray, min_reads: int) -> dict:
        """``{label: (count, x, y)}`` over the given aggregate rows, for labels read at least
        ``min_reads`` times in all; x, y the mean robot position (m) at those reads."""
        out = {}
        if rows.size == 0:
            return out
        lid = self.label[rows]
        cnt = np.bincount(lid, self.count[rows])
        sx = np.bincount(lid, self.sx[rows])
        sy = np.bincount(lid, self.sy[rows])
        for i in np.flatnonzero(cnt):
            lab = self.labels[i]
            if self.total[lab] >= min_reads:
                out[lab] = (int(cnt[i]), sx[i] / cnt[i], sy[i] / cnt[i])
        return out


class DoorBelief:
    """What the robot knows. Arrays are (H, W) and share the world's :class:`GridFrame`.

    Attributes
    ----------
    cv : uint8, HIMM certainty; seen : bool; free : bool (seen and below the occupied threshold);
    visited : bool; seg_class : int16 (density class of visited cells, Eq. 4.4; 0 elsewhere);
    clearance : float32 m (to the nearest cell that is not known free, capped);
    skeleton : bool.
    """

    def __init__(self, frame: GridFrame, spec: BeliefSpec, robot_radius: float):
        H, W = frame.height, frame.width
        self.frame, self.spec = frame, spec
        self.cv = lazy_zeros((H, W), np.uint8)
        self.seen = lazy_zeros((H, W), bool)
        self.free = lazy_zeros((H, W), bool)
        self.visited = lazy_zeros((H, W), bool)
        self.seg_class = lazy_zeros((H, W), np.int16)  # meaningful where visited
        self.clearance = lazy_zeros((H, W), np.float32)
        self._thinning = Skeleton((H, W))  # Zhang and Suen's thinning of the whole map, kept up to date
        self.skeleton = self._thinning.skeleton
        self.passable = lazy_zeros((H, W), bool)
        self.cost = lazy_zeros((H, W), np.float32)  # read only where passable, which refresh_derived writes with it
        self.graph = SkeletonGraph((H, W))  # the skeleton where the robot fits, contracted to its junctions and ends
        self.search_state = GridSearch((H, W))  # for searches the graph cannot answer (every cell where the robot fits)
        self._result = None  # the last search's answer: the graph's, or search_state
        self.version = 0  # bumped whenever passable/cost change
        self.lost = 0  # cells that were free and are no longer (a wall seen where the map had free space)
        self._search_key = None  # (r, c, version) of the search search_state holds
        self._search_of = None  # its (target rows, target cols, n_stop, whether it searched again over every cell)
        self._stopped_at = None  # the target cell a replayed search was stopped at (search_again), or None
        self._again = None  # a search to run again at the next path from its cell (search_again), or None
        self.dirty = np.array([H, -1, W, -1], np.int64)  # rmin, rmax, cmin, cmax since last refresh
        self.min_clear = robot_radius + 0.5 * frame.res - 1e-6
        self.reads = DoorReads()
        self._faces = np.full((0, 2), np.nan)  # per read row: where its ray meets a wall (sign_faces), NaN: not yet
        self._seg_parent = lazy_zeros(H * W, np.int32)  # segments as a union-find forest (see kernels.grid.mark_visited)
        self.vbox = [H, -1, W, -1]
        self.cdirty = [H, -1, W, -1]  # where candidates may have changed since the last call
        self._cands = None
        self._seg_labels = None
        self._views = np.empty((64, 4), np.float64)  # camera poses (v, u, heading, times) not yet folded into ``viewed``
        self._n_pending = 0  # rows of ``_views`` in use: a pose repeated back to back is one row, counted
        self.viewed = None  # (H, W) uint8: how many poses a side camera looked at each free cell from (lazy)
        self.examined = None  # (H, W) bool: wall faces given up on after a look from close by (lazy)
        self._view_stamp = None  # (H, W) int64: the last pose that counted for each cell
        self._n_views = 0
        self._touched = np.empty(1024, np.int64)  # cells whose free state the last scan may have changed (flat)

    # ---- per-step updates -------------------------------------------------------------
    def add_view(self, v: float, u: float, heading: float) -> None:
        """A camera pose (continuous cell coordinates, radians), folded into ``viewed`` when wall
        faces are next asked for (:meth:`unread_walls`). The same pose again, back to back (a robot
        that dwells, or a robot stack publishing its pose at 200 Hz while it stands), is counted
        on its row: 32 bytes for each pose that differs from the one before, not for each frame."""
        n = self._n_pending
        if n:
            last = self._views[n - 1]
            if last[0] == v and last[1] == u and last[2] == heading:
                last[3] += 1.0
                return
        if n == len(self._views):
            self._views = np.concatenate([self._views, np.empty_like(self._views)])
        self._views[n] = (v, u, heading, 1.0)
        self._n_pending = n + 1

    def fold_scan(self, v: float, u: float, thetas: np.ndarray, dist: np.ndarray, hit: np.ndarray) -> None:
        """Fold one laser scan from continuous cell position (v, u) into HIMM (``cv``, ``seen``),
        re-derive ``free`` where the scan changed it and grow the dirty box by those cells (what
        :meth:`refresh_free` does over a box, at the few cells that can have changed)."""
        sp = self.spec
        n = himm_update(self.cv, self.seen, v, u, thetas, dist, hit, sp.himm_inc, sp.himm_dec, sp.himm_max, self.free,
                        sp.occupied_threshold, self._touched)
        if n <= self._touched.shape[0]:
            self.lost += fold_free(self.free, self.seen, self.cv, sp.occupied_threshold, self._touched, n, self.dirty)
            return
        # more changes than the buffer holds (the first scans, or a long-range laser in the open):
        # refresh over the scan's whole box, which holds every cell a beam touched, and make room
        reach = (float(dist.max()) if dist.size else 0.0) + 2.0
        H, W = self.free.shape
        self.refresh_free(np.array([max(0, int(v - reach)), min(H - 1, int(v + reach)), max(0, int(u - reach)), min(W - 1, int(u + reach))]))
        self._touched = np.empty(2 * n, np.int64)

    def refresh_free(self, bbox: np.ndarray) -> None:
        """Re-derive ``free`` inside a scan's bounding box and grow the dirty box by the cells
        whose state changed (so the derived maps are refreshed where the map changed, not
        wherever the robot looked: a re-thinned window whose seam moves with the robot would
        change the skeleton of open areas under it)."""
        r0, r1, c0, c1 = int(bbox[0]), int(bbox[1]) + 1, int(bbox[2]), int(bbox[3]) + 1
        if r1 <= r0:
            return
        new = self.seen[r0:r1, c0:c1] & (self.cv[r0:r1, c0:c1] < self.spec.occupied_threshold)
        changed = new != self.free[r0:r1, c0:c1]
        if not changed.any():
            return
        self.lost += int((changed & ~new).sum())
        self.free[r0:r1, c0:c1] = new
        rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
        _grow(self.dirty, (r0 + int(rows[0]), r0 + int(rows[-1]), c0 + int(cols[0]), c0 + int(cols[-1])))

    def fold_grid(self, r0: int, c0: int, seen: np.ndarray, free: np.ndarray) -> None:
        """Take another mapper's word for a window of the map (a bag's map update, a robot's SLAM
        map): ``seen`` and ``free`` (h, w) bool from cell (r0, c0); as :meth:`fold_scan` does, count
        the cells that stopped being free and grow the dirty box by those whose free state
        changed."""
        h, w = seen.shape
        win = (slice(r0, r0 + h), slice(c0, c0 + w))
        new = seen & free
        changed = new != self.free[win]
        self.seen[win] = seen
        if not changed.any():
            return
        self.lost += int((changed & ~new).sum())
        self.free[win] = new
        rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
        _grow(self.dirty, (r0 + int(rows[0]), r0 + int(rows[-1]), c0 + int(cols[0]), c0 + int(cols[-1])))

    def visit(self, r: int, c: int) -> None:
        """Mark the visited kernel around the robot and give its newly visited cells the local
        density class.

        Density (Eqs. 4.1-4.4): the free area (m^2) 4-connected to the robot inside a Manhattan
        kernel of ``density_radius``, divided by ``density_delta`` and floored. A cell keeps the
        class of its first visit: overwriting the classes around the robot at every step makes
        segments change under it as it passes a junction, moving signs between segments and, at
        alpha = 1, sending the robot back and forth between two candidates for ever (seen on Hotel
        goal 148).

        Only newly visited cells mark the candidates for recomputation: a window that moved with
        the robot over cells it had visited already would recompute candidates near its seam
        differently at each pose, and a candidate that appears and vanishes as the robot goes
        back and forth keeps it going back and forth.
        """
        res = self.frame.res
        n, *box = mark_visited(self.free, self.visited, self.seg_class, self._seg_parent, r, c, self.spec.visited_radius / res + 1e-6,
                               self.spec.density_radius / res + 1e-6, res, self.spec.density_delta)
        if n == 0:
            return
        _grow(self.vbox, box)
        _grow(self.cdirty, box)
        self._seg_labels = None

    # ---- derived maps, refreshed at re-plan time ---------------------------------------
    def refresh_derived(self) -> None:
        """Bring clearance, skeleton, passable, cost and the skeleton graph up to date with the
        cells whose free state changed since the last refresh (the dirty box).

        Clearance is exact (it is capped at ``CLEARANCE_CAP_M``), so it changes only within that
        cap of the dirty box. The skeleton is Zhang and Suen's thinning of the whole map, kept up
        to date where it changes (:class:`~semsearch_cli.kernels.skeleton.Skeleton`: the same as
        thinning the map from scratch), and the graph is repaired at the cells whose skeleton or
        passable state changed (:class:`~semsearch_cli.kernels.skelgraph.SkeletonGraph`).
        """
        d = self.dirty
        if d[1] < d[0]:
            return
        H, W = self.free.shape
        res = self.frame.res
        cap = int(np.ceil(CLEARANCE_CAP_M / res))
        # clearance: write dirty+cap, compute on dirty+2cap
        w0, w1, w2, w3 = max(0, d[0] - cap), min(H, d[1] + cap + 1), max(0, d[2] - cap), min(W, d[3] + cap + 1)
        c0, c1, c2, c3 = max(0, d[0] - 2 * cap), min(H, d[1] + 2 * cap + 1), max(0, d[2] - 2 * cap), min(W, d[3] + 2 * cap + 1)
        sub = np.zeros((c1 - c0 + 2, c3 - c2 + 2), np.uint8)  # a border of walls
        sub[1:-1, 1:-1] = self.free[c0:c1, c2:c3]
        dist = cv2.distanceTransform(sub, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
        np.minimum(dist * np.float32(res), np.float32(CLEARANCE_CAP_M), out=dist)
        win = (slice(w0, w1), slice(w2, w3))
        clear = self.clearance[win] = dist[w0 - c0 : w1 - c0, w2 - c2 : w3 - c2]
        fits = clear >= self.min_clear
        moved = np.flatnonzero(fits != self.passable[win])
        self.passable[win] = fits
        moved = (w0 + moved // (w3 - w2)) * W + w2 + moved % (w3 - w2)
        changed = self._thinning.update(self.free, d)  # the cells that joined or left the skeleton
        # cost over the clearance's window, and where the skeleton changed outside it
        self.cost[win] = _cost(clear, self.skeleton[win])
        if changed.size:
            self.cost.reshape(-1)[changed] = _cost(self.clearance.reshape(-1)[changed], self.skeleton.reshape(-1)[changed])
            rr, cc = changed // W, changed % W
            _grow(self.cdirty, (int(rr.min()), int(rr.max()), int(cc.min()), int(cc.max())))
        self.graph.repair(self.skeleton, self.passable, np.concatenate([changed, moved]))
        _grow(self.cdirty, (w0, w1 - 1, w2, w3 - 1))
        self.version += 1
        d[:] = (H, -1, W, -1)

    # passable : (H, W) bool, known free cells where the robot disk fits.
    # cost : (H, W) float32 per-cell cost multiplier, 1 on the skeleton and 1.5 (open space) to
    # 3.5 (against a wall) elsewhere. Shortest paths under this cost run along the skeleton where
    # it connects (so their length counts skeleton cells, as the closeness factor of Eq. 16 does)
    # and cut across open space or skeleton gaps only where that is much shorter.

    # ---- frontier candidates -----------------------------------------------------------
    def candidates(self) -> Candidates:
        """Candidates C: per 8-connected group of skeleton cells on the frontier (known free, not
        visited, touching a visited cell, where the robot fits), the one farthest from walls;
        groups whose branch does not lead on (fewer than 3 unvisited skeleton cells) are dropped.
        Where the skeleton crosses no frontier at all, each frontier group gives its widest cell
        instead, and where no known free space is left unvisited, the classic frontier (cells next
        to never-seen ones, see :meth:`_unknown_frontier`) is used, so a search never stops while
        reachable space remains unexplored.

        Incremental: only a window around what changed since the last call (visited kernels,
        refreshed maps) is recomputed; candidates elsewhere cannot have changed and are kept.
        """
        H, W = self.free.shape
        b, d = self.vbox, self.cdirty
        if b[1] < b[0]:
            return _empty()
        if self._cands is not None and d[1] < d[0]:
            out = self._cands
        else:
            m = BRANCH_DEPTH + 3
            if self._cands is None:
                r0, r1, c0, c1 = max(0, b[0] - 2), min(H, b[1] + 3), max(0, b[2] - 2), min(W, b[3] + 3)
            else:
                r0, r1 = max(0, b[0] - 2, d[0] - m), min(H, b[1] + 3, d[1] + m + 1)
                c0, c1 = max(0, b[2] - 2, d[2] - m), min(W, b[3] + 3, d[3] + m + 1)
            if r1 <= r0 or c1 <= c0:  # what changed lies away from the visited region: nothing to redo
                new = self._cands
            else:
                new = self._groups(self._front(r0, r1, c0, c1) & self.skeleton[r0:r1, c0:c1], r0, c0, need_branch=True)
            if self._cands is not None and new is not self._cands:
                old = self._cands
                out_w = ~((old.rows >= r0) & (old.rows < r1) & (old.cols >= c0) & (old.cols < c1))
                kept = old.take(np.flatnonzero(out_w))
                if len(kept) and len(new):  # a group straddling the window border: keep one
                    near = (np.abs(new.rows[:, None] - kept.rows[None]) <= 2) & (np.abs(new.cols[:, None] - kept.cols[None]) <= 2)
                    new = new.take(np.flatnonzero(~near.any(axis=1)))
                new = kept.concat(new)
            self._cands = out = new
            d[:] = (H, -1, W, -1)
        if len(out) == 0:
            r0, r1, c0, c1 = max(0, b[0] - 2), min(H, b[1] + 3), max(0, b[2] - 2), min(W, b[3] + 3)
            out = self._groups(self._front(r0, r1, c0, c1), r0, c0, need_branch=False)
        if len(out) == 0:
            out = self._unknown_frontier()
        return out

    def _unknown_frontier(self) -> Candidates:
        """Last resort, the classic frontier: cells where the robot fits within reach of cells
        never seen. The forward laser never looks back, so a robot that starts mid-corridor and
        drives to one end has seen nothing behind its start and, with every known cell visited,
        would otherwise stop there."""
        rr, cc = np.nonzero(self.seen)
        if rr.size == 0:
            return _empty()
        H, W = self.seen.shape
        k = int(np.ceil(self.min_clear / self.frame.res)) + 2
        r0, r1, c0, c1 = max(0, rr.min() - k), min(H, rr.max() + k + 1), max(0, cc.min() - k), min(W, cc.max() + k + 1)
        unseen = (~self.seen[r0:r1, c0:c1]).astype(np.uint8)
        cross = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8)
        edge = cv2.dilate(unseen, cross).astype(bool) & self.free[r0:r1, c0:c1]  # free, 4-adjacent to unseen
        near = cv2.dilate(edge.astype(np.uint8), np.ones((2 * k + 1, 2 * k + 1), np.uint8)).astype(bool)
        return self._groups(near & self.passable[r0:r1, c0:c1], r0, c0, need_branch=False)

    # ---- completeness: walls not yet looked at from close enough to read signs ---------------
    def unread_walls(self, cam_range: float, half_fov: float, approach: float, need: int = 1) -> Candidates:
        """Where to go once no frontier is left: the known free space within ``approach`` m
        (through free space) of a wall face that a side camera has looked at from fewer than
        ``need`` poses within its range ``cam_range`` m (``half_fov`` radians either side of the
        perpendicular). A sign anywhere on such a face may be unread (passed at an angle, with the
        robot turning on the spot, or missed by a camera that reads a visible sign only with some
        probability), so a complete search goes back to look at it. One candidate per group of such
        cells, the widest; empty when every wall face has been looked at (or given up on, see
        :meth:`mark_examined`)."""
        H, W = self.free.shape
        if self.viewed is None:
            self.viewed = np.zeros((H, W), np.uint8)
            self.examined = np.zeros((H, W), bool)
            self._view_stamp = np.full((H, W), -1, np.int64)
        if self._n_pending:
            pending = self._views[:self._n_pending]
            mark_viewed(self.free, self.viewed, self._view_stamp, self._n_views, pending, half_fov, cam_range / self.frame.res)
            self._n_views += int(pending[:, 3].sum())
            self._n_pending = 0
        rr, cc = np.nonzero(self.seen)
        if rr.size == 0:
            return _empty()
        k = int(np.ceil(approach / self.frame.res)) + 1
        r0, r1, c0, c1 = max(0, rr.min() - k), min(H, rr.max() + k + 1), max(0, cc.min() - k), min(W, cc.max() + k + 1)
        free = self.free[r0:r1, c0:c1]
        wall = (self.seen[r0:r1, c0:c1] & ~free).astype(np.uint8)
        cross = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8)
        face = cv2.dilate(wall, cross).astype(bool) & free
        todo = face & (self.viewed[r0:r1, c0:c1] < need) & ~self.examined[r0:r1, c0:c1]
        if not todo.any():
            return _empty()
        near = todo.astype(np.uint8)  # grown through free space only, so it stays on the face's side of the wall
        free8 = free.astype(np.uint8)
        for _ in range(k - 1):
            near = cv2.dilate(near, cross) & free8
        return self._groups(near.astype(bool) & self.passable[r0:r1, c0:c1], r0, c0, need_branch=False)

    def mark_examined(self, r: int, c: int, radius: float) -> None:
        """Give up on the unviewed wall faces within ``radius`` m of (r, c) through free space:
        the robot has looked around there (so a search that cannot read a sign in a spot its
        cameras cannot see still ends)."""
        pr, pc = local_reach(self.free, r, c, radius / self.frame.res + 1.0, False)
        self.examined[pr, pc] = True

    def _front(self, r0, r1, c0, c1) -> np.ndarray:
        vis = self.visited[r0:r1, c0:c1]
        grown = cv2.dilate(vis.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
        return grown & ~vis & self.passable[r0:r1, c0:c1]

    def _groups(self, mask, r0, c0, need_branch):
        n, lab = cv2.connectedComponents(mask.astype(np.uint8), connectivity=8)
        if n <= 1:
            return _empty()
        rows, cols = widest_of_groups(lab, n, self.clearance, r0, c0)  # per group, the widest cell
        keep, theta, sr, sc = [], [], [], []
        for k in range(rows.shape[0]):
            r, c = int(rows[k]), int(cols[k])
            dr, dc, cnt = branch_walk(self.skeleton if need_branch else self.free, self.visited, r, c, BRANCH_DEPTH)
            if need_branch and cnt < MIN_BRANCH_CELLS:
                continue
            vr, vc = nearest_visited(self.visited, r, c, 3)
            if cnt == 0:  # point away from the visited neighbour
                dr, dc = r - vr, c - vc
            keep.append(k)
            theta.append(np.arctan2(-dr, dc))
            sr.append(vr)
            sc.append(vc)
        keep = np.array(keep, np.int64)
        return Candidates(rows[keep], cols[keep], wrap_angle(np.array(theta, float)), np.array(sr, np.int64), np.array(sc, np.int64))

    # ---- distances and segments ----------------------------------------------------------
    def search(self, r: int, c: int, t_rows, t_cols, n_stop: int):
        """Shortest paths from the robot cell (r, c) to target cells along the skeleton; the
        answer gives ``lengths`` (cells) and ``path`` for the targets reached. Stops after
        ``n_stop`` targets (0: all), in the order of (cost, cell index).

        The search runs on the skeleton graph (:class:`~semsearch_cli.kernels.skelgraph.SkeletonGraph`:
        the skeleton where the robot fits), joined to the robot and to each target off it by the
        cells within ``CONNECT_M`` of them, under ``cost``; so the path runs on the skeleton
        itself (the thesis counts only Voronoi cells for D). When fewer targets than asked for
        are reached that way (a gap in the skeleton where the robot does not fit), every target
        is searched for again over every cell where the robot fits, under ``cost``.
        """
        self._again = None
        return self._search(r, c, np.asarray(t_rows, np.int64), np.asarray(t_cols, np.int64), n_stop)

    def _search(self, r: int, c: int, t_rows, t_cols, n_stop: int, again: bool | None = None, stop=None):
        """:meth:`search`; ``again`` (a replay: whether the search went on over every cell, as the
        record says) runs that search or not without deciding it again, and ``stop`` ends the
        search over every cell at that cell (its path is the whole search's: a settled cell's
        parent is final)."""
        distinct = int(np.unique(t_rows * self.free.shape[1] + t_cols).size)
        need = min(n_stop, distinct) if n_stop > 0 else distinct
        passable = self.passable
        if not passable[r, c]:  # robot squeezed near a wall: let it leave
            passable = passable.copy()
            pr, pc = local_reach(self.free, r, c, max(2.0, self.min_clear / self.frame.res + 1), False)
            passable[pr, pc] = True
        W = self.free.shape[1]
        graph = self.graph.search(r, c, passable, self.passable, self.cost, t_rows, t_cols, 0, CONNECT_M / self.frame.res)
        on_graph = graph.settled(t_rows, t_cols)
        reached = graph.reached
        grid = None
        if again or (again is None and reached < need):
            # the targets the graph does not reach, over every cell where the robot fits
            rest = ~on_graph
            self.search_state.run(passable, self.cost, r, c, t_rows[rest], t_cols[rest], max(need - reached, 1) if n_stop > 0 else 0,
                                  stop=stop)
            grid, again = self.search_state, True
        result = SearchAnswer(graph, grid, t_rows, t_cols, need, W)
        self._result = result
        self._search_key = (r, c, self.version)
        self._search_of = (t_rows, t_cols, n_stop, bool(again))
        self._stopped_at = stop if again else None
        return result

    def held_search(self, r: int, c: int):
        """The search :meth:`path` would reuse from (r, c) on the current maps, as (target rows,
        target cols, n_stop, whether it went on over every cell), or None: what a planner's own
        search leaves for the path to its target (a decisions record keeps it, so that a replay
        without the planner runs it again: :meth:`search_again`)."""
        return self._search_of if self._search_key == (r, c, self.version) else None

    def search_again(self, r: int, c: int, t_rows, t_cols, n_stop: int, again: bool | None = None) -> None:
        """Put back the search a planner ran from (r, c) (a replay, from its record). With
        ``again`` (whether it went on over every cell) known, it is run at the next :meth:`path`
        from (r, c), stopped at that path's target: the same path at a fraction of the cost;
        without (an older record), at once and in whole."""
        t_rows, t_cols = np.asarray(t_rows, np.int64), np.asarray(t_cols, np.int64)
        if again is None:
            self.search(r, c, t_rows, t_cols, n_stop)
            return
        self._again = ((r, c, self.version), (t_rows, t_cols, n_stop, bool(again)))
        self._search_key = None

    def path(self, r: int, c: int, tr: int, tc: int):
        """Cheapest path (rows, cols) from (r, c) to (tr, tc), reusing the last search when it
        started here on the current maps and reached the target; None when unreachable."""
        key = (r, c, self.version)
        if self._again is not None and self._again[0] == key:  # a replayed search: run now, up to this target
            spec, self._again = self._again[1], None
            self._search(r, c, *spec[:3], again=spec[3], stop=(tr, tc))
        elif self._search_key == key and self._stopped_at is not None and self._stopped_at != (tr, tc):
            rows, cols, n_stop, again = self._search_of  # stopped at another target: run it in whole, as it ran
            self._search(r, c, rows, cols, n_stop, again=again)
        if self._search_key != key or not self._result.settled(tr, tc):
            self.search(r, c, [tr], [tc], 1)
        return self._result.path(tr, tc)

    def door_lists(self) -> dict:
        """Door list of each visited segment (thesis 4.2.3), rebuilt from every read.

        Returns ``{segment: {label: (count, x, y)}}``: the signs read at least ``min_reads`` times
        in all, attached to the segment of the robot's cell at each read, with the number of reads
        made from that segment and the mean robot position (m) at them, which lies on the
        corridor's axis.
        """
        rd = self.reads
        seg = self.segment_labels().ravel()[rd.cell[: rd.n]]
        out = {}
        for s in np.unique(seg[seg > 0]):
            lists = rd.lists(np.flatnonzero(seg == s), self.spec.min_reads)
            if lists:
                out[int(s)] = lists
        return out

    def sign_faces(self, min_reads: int | None = None, reach: float = 10.0) -> tuple[list, np.ndarray, np.ndarray]:
        """Where the signs read are, as far as the robot can tell: every label read at least
        ``min_reads`` times with a bearing, as (labels, ``face`` (k, 2) m, ``axis`` (k, 2)).
        Each read's ray (from the mean robot position of its reads from one cell, along their mean
        bearing) ends where it first leaves the known free space within ``reach`` m: the face of
        the wall the sign hangs on (the camera reads a sign only in line of sight). ``face`` is the
        mean of a label's ray ends (weighted by reads), ``axis`` the mean unit vector of the
        cameras that read it (toward its wall). A ray is followed once, when its row is first
        asked for, and again while it ends nowhere (its wall not yet in the map)."""
        min_reads = self.spec.min_reads if min_reads is None else min_reads
        rd, n = self.reads, self.reads.n
        if self._faces.shape[0] < n:
            grow = np.full((max(n, 2 * self._faces.shape[0]), 2), np.nan)
            grow[: self._faces.shape[0]] = self._faces
            self._faces = grow
        todo = np.flatnonzero((rd.bearings[:n] > 0) & np.isnan(self._faces[:n, 0]))
        if todo.size:
            cnt = rd.count[todo].astype(float)
            p = np.column_stack([rd.sx[todo], rd.sy[todo]]) / cnt[:, None]
            v = np.column_stack([rd.sbx[todo], rd.sby[todo]])
            v /= np.maximum(np.hypot(v[:, 0], v[:, 1]), 1e-12)[:, None]
            fr = self.frame
            step = np.arange(0.0, reach, fr.res / 2)
            r, c = fr.to_index(p[:, 0, None] + v[:, 0, None] * step, p[:, 1, None] + v[:, 1, None] * step)
            H, W = self.free.shape
            inside = (r >= 0) & (r < H) & (c >= 0) & (c < W)
            out = ~inside | ~self.free[np.clip(r, 0, H - 1), np.clip(c, 0, W - 1)]
            hit = out.any(axis=1)
            k = np.argmax(out, axis=1)
            ends = p + v * step[k][:, None]
            self._faces[todo[hit]] = ends[hit]
        rows = np.flatnonzero(np.isfinite(self._faces[:n, 0]))
        labels = []
        if rows.size == 0:
            return labels, np.zeros((0, 2)), np.zeros((0, 2))
        lid = rd.label[rows]
        w = rd.count[rows].astype(float)
        m = len(rd.labels)
        cnt = np.bincount(lid, w, minlength=m)
        fx = np.bincount(lid, w * self._faces[rows, 0], minlength=m)
        fy = np.bincount(lid, w * self._faces[rows, 1], minlength=m)
        ax = np.bincount(lid, rd.snx[rows], minlength=m)
        ay = np.bincount(lid, rd.sny[rows], minlength=m)
        keep = np.array([cnt[i] > 0 and rd.total[lab] >= min_reads for i, lab in enumerate(rd.labels)], bool)
        idx = np.flatnonzero(keep)
        face = np.column_stack([fx[idx], fy[idx]]) / cnt[idx, None]
        axis = np.column_stack([ax[idx], ay[idx]])
        axis /= np.maximum(np.hypot(axis[:, 0], axis[:, 1]), 1e-12)[:, None]
        return [rd.labels[i] for i in idx], face, axis

    def segment_door_lists(self, rows: np.ndarray, cols: np.ndarray, min_reads: int | None = None):
        """Door lists of the segments of the given visited cells, without labelling the map.

        Segments are kept up to date as cells are visited (a union-find forest), so this costs
        the number of cells and reads, not the segments' size; planners use it at re-plan time.
        Returns (``seg`` (k,) int64 segment index per cell, in order of first appearance, -1 when
        the cell is not visited; ``lists``, one ``{label: (count, x, y)}`` per segment index), as
        :meth:`door_lists`.
        """
        min_reads = self.spec.min_reads if min_reads is None else min_reads
        rd = self.reads
        W = self.visited.shape[1]
        roots = segment_roots(self._seg_parent, self.visited, np.asarray(rows, np.int64) * W + np.asarray(cols, np.int64))
        read_roots = segment_roots(self._seg_parent, self.visited, rd.cell[: rd.n])
        seg = np.full(len(roots), -1, np.int64)
        lists, index = [], {}
        for i, root in enumerate(roots.tolist()):
            if root < 0:
                continue
            j = index.get(root)
            if j is None:
                j = index[root] = len(lists)
                lists.append(rd.lists(np.flatnonzero(read_roots == root), min_reads))
            seg[i] = j
        return seg, lists

    def segment_labels(self) -> np.ndarray:
        """(H, W) int32: visited segments (connected cells of one density class), 0 elsewhere."""
        if self._seg_labels is not None:
            return self._seg_labels
        out = np.zeros(self.visited.shape, np.int32)
        b = self.vbox
        if b[1] >= b[0]:
            sl = (slice(b[0], b[1] + 1), slice(b[2], b[3] + 1))
            cls = np.where(self.visited[sl], self.seg_class[sl], -1)
            sub = out[sl]
            nxt = 1
            for k in np.unique(cls[cls >= 0]):
                n, lab = cv2.connectedComponents((cls == k).astype(np.uint8), connectivity=8)
                m = lab > 0
                sub[m] = lab[m] + (nxt - 1)
                nxt += n - 1
        self._seg_labels = out
        return out


class SearchAnswer:
    """What :meth:`DoorBelief.search` answers: ``lengths``, ``costs``, ``settled`` and ``path`` for
    the targets it reached. A target's numbers and path are the skeleton graph's when the graph
    reaches it, else those of the search over every cell where the robot fits (run only when the
    graph reached fewer targets than asked for); so they never depend on what other targets were
    searched with it. Of those reached, the first ``need`` in the order of (cost, cell index)
    count."""

    def __init__(self, graph, grid, t_rows, t_cols, need: int, W: int):
        self.graph, self.grid, self._W = graph, grid, W
        q = t_rows * W + t_cols
        cost = graph.costs(t_rows, t_cols)
        if grid is not None:
            cost = np.where(np.isfinite(cost), cost, grid.costs(t_rows, t_cols))
        self._kept = rank_targets(q, cost, need)

    def _in(self, rows, cols) -> np.ndarray:
        q = np.asarray(rows, np.int64) * self._W + np.asarray(cols, np.int64)
        if self._kept.size == 0:
            return np.zeros(q.shape, bool)
        i = np.clip(np.searchsorted(self._kept, q), 0, self._kept.size - 1)
        return self._kept[i] == q

    def _pick(self, name, rows, cols) -> np.ndarray:
        v = getattr(self.graph, name)(rows, cols)
        if self.grid is not None:
            v = np.where(np.isfinite(v), v, getattr(self.grid, name)(rows, cols))
        return np.where(self._in(rows, cols), v, np.inf)

    def lengths(self, rows, cols) -> np.ndarray:
        """Path length (cells) to each given cell, inf where it is not a target reached."""
        return self._pick("lengths", rows, cols)

    def costs(self, rows, cols) -> np.ndarray:
        return self._pick("costs", rows, cols)

    def settled(self, rows, cols) -> np.ndarray:
        return self._in(rows, cols)

    def path(self, r, c):
        """Cells (rows, cols) from the robot to the target reached (r, c), or None."""
        if not bool(self._in(r, c)):
            return None
        if bool(self.graph.settled(r, c)):
            return self.graph.path(r, c)
        return self.grid.path(r, c)


def _cost(clear: np.ndarray, on_skeleton: np.ndarray) -> np.ndarray:
    """The cost multiplier of cells of clearance ``clear`` (m): 1 on the skeleton, else 3.5 against a
    wall down to 1.5 at ``CLEARANCE_CAP_M`` (see ``cost`` above)."""
    return np.where(on_skeleton, np.float32(1.0), np.float32(3.5) - np.float32(2.0 / CLEARANCE_CAP_M) * clear).astype(np.float32)


def _grow(box, other) -> None:
    """Grow bounding box ``box`` = [rmin, rmax, cmin, cmax] (in place) to contain ``other``."""
    box[0], box[1] = min(box[0], other[0]), max(box[1], other[1])
    box[2], box[3] = min(box[2], other[2]), max(box[3], other[3])


def _empty() -> Candidates:
    z = np.zeros(0, np.int64)
    return Candidates(z, z.copy(), np.zeros(0), z.copy(), z.copy())

