"""numba kernel of the dynamic PRM (Bruce 2006 §4.4): the sector connection of new nodes (its A*
with lazy edge validation is the graph search's, :mod:`cmdragons.planning._graphsearch_kernels`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmdragons.planning.collision import CW, segment_free


@njit(cache=True)
def connect_sectors(
    cw: CW, pts: np.ndarray, first_new: int, n_sectors: int, radius_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Dynamic PRM connection by radial directions (Bruce 2006 §4.4): every node from ``first_new`` on
    links, in each of ``n_sectors`` equal angular sectors around it, to the nearest node within
    ``radius_m`` that it sees free. Returns the new undirected edges (a, b) and their lengths."""
    n = pts.shape[0]
    best = np.empty(n_sectors, dtype=np.int64)
    bestd = np.empty(n_sectors)
    ea = np.empty((max(1, (n - first_new)) * n_sectors, 2), dtype=np.int64)
    ew = np.empty(max(1, (n - first_new)) * n_sectors)
    m = 0
    r2 = radius_m * radius_m
    for i in range(first_new, n):
        best[:] = -1
        bestd[:] = np.inf
        for j in range(n):
            if j == i:
                continue
            dx, dy = pts[j, 0] - pts[i, 0], pts[j, 1] - pts[i, 1]
            d2 = dx * dx + dy * dy
            if d2 > r2:
                continue
            s = int((math.atan2(dy, dx) + math.pi) / (2.0 * math.pi) * n_sectors) % n_sectors
            if d2 < bestd[s]:
                bestd[s], best[s] = d2, j
        for s in range(n_sectors):
            j = best[s]
            if j < 0:
                continue
            if segment_free(cw, pts[i, 0], pts[i, 1], pts[j, 0], pts[j, 1]):
                ea[m, 0], ea[m, 1], ew[m] = i, j, math.sqrt(bestd[s])
                m += 1
    return ea[:m].copy(), ew[:m].copy()
