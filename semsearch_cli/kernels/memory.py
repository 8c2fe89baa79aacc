"""Map-sized grids whose untouched cells cost no memory.

``np.zeros`` of a large array returns fresh zero pages from the operating system the first time,
but once a run has freed its grids, glibc serves the next run's from the heap and ``calloc``
clears them byte by byte: every page becomes resident and every run pays for clearing grids of
which it writes a thin band (on a 3.7 M-cell map a worker's second run peaked at 461 MB against
367 MB for its first). :func:`lazy_zeros` maps anonymous memory for each grid instead, so a grid
costs the pages a run writes, whichever run it is, and is unmapped when the array goes.
"""

from __future__ import annotations

import mmap

import numpy as np


def lazy_zeros(shape, dtype=np.float64) -> np.ndarray:
    """A C-contiguous array of zeros of ``shape`` and ``dtype`` backed by its own anonymous
    memory map: pages are resident only once written."""
    dtype = np.dtype(dtype)
    n = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    if n == 0:
        return np.zeros(shape, dtype)
    # private: Python maps anonymous memory shared by default, and a process forked while the grid
    # exists (a pool's worker) would then write into the parent's grid and every sibling's
    private = {"flags": mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS} if hasattr(mmap, "MAP_PRIVATE") else {}
    return np.frombuffer(mmap.mmap(-1, n, **private), dtype).reshape(shape)
