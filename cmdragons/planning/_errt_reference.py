"""Plain-numpy references of the ERRT kernels (:mod:`cmdragons.planning._errt_kernels`): nearest
neighbours by argmin, the waypoint cache with slices."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def nearest(nodes: FloatArray, q: FloatArray) -> int:
    """Index of the row of ``nodes`` nearest to q."""
    return int(np.argmin(np.hypot(*(nodes - q).T)))


def cache_add(points: FloatArray, count: int, nxt: int, pts: FloatArray, u: FloatArray, fifo: bool) -> tuple[int, int]:
    """The waypoint cache's replacement with numpy slices: fill the free slots, then overwrite the
    oldest (fifo) or the slots ``u * size`` picks. Returns the new (count, next)."""
    size = len(points)
    pts = pts[-size:]
    room = min(size - count, len(pts))
    points[count : count + room] = pts[:room]
    count += room
    rest = pts[room:]
    if len(rest) == 0:
        return count, nxt
    if fifo:
        idx = (nxt + np.arange(len(rest))) % size
        nxt = int((nxt + len(rest)) % size)
    else:
        idx = np.minimum(size - 1, (u[: len(rest)] * size).astype(np.int64))
    for i, k in zip(idx, rest, strict=True):  # in order: a later point wins a slot drawn twice
        points[i] = k
    return count, nxt
