"""Engine 2's skeleton (semsearch_cli/kernels/skeleton.py): Zhang and Suen's thinning of the whole
map, kept up to date cell by cell, is the thinning of the whole map from scratch after every change.

The brute force below is the paper's rule written out over whole arrays (no table, no front): each
subiteration judges every cell on the image the previous one left, until an iteration deletes
nothing."""

import numpy as np
import pytest

from semsearch_cli.kernels.skeleton import KEPT, Skeleton, deletion_table


def brute_thin(free: np.ndarray) -> np.ndarray:
    img = np.pad(free.astype(np.int64), 1)
    while True:
        deleted = 0
        for second in (False, True):
            c = img[1:-1, 1:-1]
            p2, p3, p4, p5 = img[:-2, 1:-1], img[:-2, 2:], img[1:-1, 2:], img[2:, 2:]
            p6, p7, p8, p9 = img[2:, 1:-1], img[2:, :-2], img[1:-1, :-2], img[:-2, :-2]
            seq = [p2, p3, p4, p5, p6, p7, p8, p9, p2]
            b = sum(seq[:8])
            a = sum(((seq[i] == 0) & (seq[i + 1] == 1)).astype(np.int64) for i in range(8))
            if second:
                cond = (p2 * p4 * p8 == 0) & (p2 * p6 * p8 == 0)
            else:
                cond = (p2 * p4 * p6 == 0) & (p4 * p6 * p8 == 0)
            m = (c == 1) & (b >= 2) & (b <= 6) & (a == 1) & cond
            deleted += int(m.sum())
            img[1:-1, 1:-1] = np.where(m, 0, c)
        if deleted == 0:
            return img[1:-1, 1:-1].astype(bool)


def rooms(rng, H, W, n):
    """Free rectangles (rooms, corridors, halls) on a blocked grid, some touching."""
    free = np.zeros((H, W), bool)
    for _ in range(n):
        h, w = int(rng.integers(1, H // 2)), int(rng.integers(1, W // 2))
        r, c = int(rng.integers(0, H - h)), int(rng.integers(0, W - w))
        free[r:r + h, c:c + w] = True
    return free


def test_the_tables_are_the_papers_conditions():
    t1, t2 = deletion_table(False), deletion_table(True)
    # an isolated cell, an end point and a cell inside a block are never deleted
    assert t1[0] == t2[0] == 0 and t1[1] == t2[1] == 0 and t1[255] == t2[255] == 0
    # a corner cell with its north, north-east and east neighbours (P2, P3, P4): B = 3, A = 1, and
    # both rules' products vanish (P6 = P8 = 0)
    code = 0b111
    assert t1[code] == 1 and t2[code] == 1
    # a cell between north and south neighbours only (a line): A = 2, kept by both
    assert t1[0b10001] == t2[0b10001] == 0
    code = 0b11100  # P4, P5, P6: the first rule's (c) P2*P4*P6 = 0 holds, (d) P4*P6*P8 = 0 holds
    assert t1[code] == 1
    code = 0b1110000  # P6, P7, P8: (d) of the second rule P2*P6*P8 = 0 holds, (c) P2*P4*P8 = 0 holds
    assert t2[code] == 1
    # the rules differ: P2, P4, P6 and their corners (a west edge cell of a vertical band) is deleted by
    # the second rule only (the first's P2 * P4 * P6 = 1)
    code = 0b11111  # P2, P3, P4, P5, P6
    assert t1[code] == 0 and t2[code] == 1


@pytest.mark.parametrize("seed", range(12))
def test_the_kept_skeleton_is_the_thinning_of_the_whole_map_after_every_change(seed):
    rng = np.random.default_rng(seed)
    H, W = int(rng.integers(12, 48)), int(rng.integers(12, 48))
    free = np.zeros((H, W), bool)
    sk = Skeleton((H, W))
    for step in range(40):
        before = free.copy()
        kind = rng.integers(4)
        if kind == 0:  # a room seen
            free |= rooms(rng, H, W, 1)
        elif kind == 1:  # a wall seen where the map had free space
            h, w = int(rng.integers(1, 4)), int(rng.integers(1, 8))
            r, c = int(rng.integers(0, H - h)), int(rng.integers(0, W - w))
            free[r:r + h, c:c + w] = False
        elif kind == 2:  # single cells flipped (laser noise)
            for _ in range(int(rng.integers(1, 6))):
                r, c = int(rng.integers(H)), int(rng.integers(W))
                free[r, c] = not free[r, c]
        else:  # a scan's worth: free cells grown around a point
            r, c = int(rng.integers(H)), int(rng.integers(W))
            rr, cc = np.ogrid[:H, :W]
            free |= (rr - r) ** 2 + (cc - c) ** 2 <= int(rng.integers(2, 9)) ** 2
        diff = np.argwhere(free != before)
        box = (diff[:, 0].min(), diff[:, 0].max(), diff[:, 1].min(), diff[:, 1].max()) if len(diff) else (0, -1, 0, -1)
        old = sk.skeleton.copy()
        changed = sk.update(free, box)
        want = brute_thin(free)
        assert np.array_equal(sk.skeleton, want), f"seed {seed} step {step}: {int((sk.skeleton != want).sum())} cells differ"
        assert set(changed.tolist()) == set(np.flatnonzero(old.ravel() != want.ravel()).tolist())
        assert np.array_equal(sk.tdel.reshape(H, W) > 0, free)


def test_a_change_far_away_moves_only_its_own_part_of_the_history():
    """Two halls apart: a door opened in one does not reach the other's history."""
    H, W = 60, 160
    free = np.zeros((H, W), bool)
    free[5:55, 5:60] = True
    free[5:55, 100:155] = True
    sk = Skeleton((H, W))
    sk.update(free, (0, H - 1, 0, W - 1))
    left = sk.tdel.reshape(H, W)[:, :80].copy()
    free[30, 130:133] = False  # a pillar in the right hall
    sk.update(free, (30, 30, 130, 132))
    assert np.array_equal(sk.tdel.reshape(H, W)[:, :80], left)
    assert np.array_equal(sk.skeleton, brute_thin(free))
    assert (sk.tdel.reshape(H, W)[sk.skeleton] == KEPT).all()


def test_a_front_that_outgrows_its_copy_is_thinned_again_on_a_larger_one(monkeypatch):
    """A copy of two cells around the changes: every update of a hall outgrows it and runs again."""
    monkeypatch.setattr(Skeleton, "MARGIN", 2)
    H, W = 50, 70
    free = np.zeros((H, W), bool)
    sk = Skeleton((H, W))
    free[5:45, 5:65] = True
    sk.update(free, (5, 44, 5, 64))
    free[20:22, 30:33] = False  # a pillar: the hall's history changes far from it
    sk.update(free, (20, 21, 30, 32))
    assert sk.last[2] > 1
    assert np.array_equal(sk.skeleton, brute_thin(free))
