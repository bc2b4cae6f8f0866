"""Plain-Python references of the grid kernels, for the agreement tests: BFS wavefronts, Dijkstra
on 8-connected moves without cut corners, and fast marching from scratch (heapq, no repair)."""

from __future__ import annotations

import heapq
import math
from collections import deque

import numpy as np
from numpy.typing import NDArray


def bfs(free: NDArray[np.bool_], goal: tuple[int, int], eight: bool) -> NDArray[np.int64]:
    h, w = free.shape
    dist = np.full((h, w), -1, np.int64)
    if not free[goal]:
        return dist
    moves = [(-1, 0), (1, 0), (0, -1), (0, 1)] + ([(-1, -1), (-1, 1), (1, -1), (1, 1)] if eight else [])
    dist[goal] = 0
    q = deque([goal])
    while q:
        r, c = q.popleft()
        for dr, dc in moves:
            rr, cc = r + dr, c + dc
            if 0 <= rr < h and 0 <= cc < w and free[rr, cc] and dist[rr, cc] < 0:
                dist[rr, cc] = dist[r, c] + 1
                q.append((rr, cc))
    return dist


def octile_dijkstra(cost: NDArray[np.float64], start: tuple[int, int], goal: tuple[int, int]) -> float:
    h, w = cost.shape
    g = {start: 0.0}
    heap = [(0.0, start)]
    done = set()
    while heap:
        d, (r, c) = heapq.heappop(heap)
        if (r, c) in done:
            continue
        done.add((r, c))
        if (r, c) == goal:
            return d
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                rr, cc = r + dr, c + dc
                if (dr, dc) == (0, 0) or not (0 <= rr < h and 0 <= cc < w) or not math.isfinite(cost[rr, cc]):
                    continue
                step = 0.5 * (cost[r, c] + cost[rr, cc])
                if dr and dc:
                    if not (math.isfinite(cost[r, cc]) and math.isfinite(cost[rr, c])):
                        continue
                    step *= math.sqrt(2.0)
                nd = d + step
                if nd < g.get((rr, cc), math.inf):
                    g[(rr, cc)] = nd
                    heapq.heappush(heap, (nd, (rr, cc)))
    return math.inf


def _upwind(a: float, b: float, c: float) -> float:
    a, b = min(a, b), max(a, b)
    if math.isinf(a):
        return math.inf
    return a + c if b - a >= c else min(0.5 * (a + b + math.sqrt(2 * c * c - (a - b) ** 2)), a + c)


def fast_marching(cost: NDArray[np.float64], goals: list[tuple[int, int]], eight: bool = False) -> NDArray[np.float64]:
    """Fast marching with cell costs as slowness: the first-order update on the 4-neighbourhood, and
    with ``eight`` the smaller of it and the same on the diagonals (spacing sqrt 2, only past free
    corners)."""
    h, w = cost.shape
    v = np.full((h, w), np.inf)
    known = np.zeros((h, w), bool)
    heap: list[tuple[float, tuple[int, int]]] = []
    for gcell in goals:
        v[gcell] = 0.0
        heapq.heappush(heap, (0.0, gcell))
    while heap:
        d, (r, c) = heapq.heappop(heap)
        if known[r, c] or d > v[r, c]:
            continue
        known[r, c] = True
        nbrs = [(r + dr, c + dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr or dc) and (eight or not (dr and dc))]
        for rr, cc in nbrs:
            if not (0 <= rr < h and 0 <= cc < w) or known[rr, cc] or not math.isfinite(cost[rr, cc]):
                continue

            def val(y: int, x: int) -> float:
                return float(v[y, x]) if 0 <= y < h and 0 <= x < w else math.inf

            def free(y: int, x: int) -> bool:
                return 0 <= y < h and 0 <= x < w and math.isfinite(cost[y, x])

            ci = cost[rr, cc]
            x = _upwind(min(val(rr, cc - 1), val(rr, cc + 1)), min(val(rr - 1, cc), val(rr + 1, cc)), ci)
            if eight:
                ne = val(rr - 1, cc + 1) if free(rr - 1, cc) and free(rr, cc + 1) else math.inf
                sw = val(rr + 1, cc - 1) if free(rr + 1, cc) and free(rr, cc - 1) else math.inf
                nw = val(rr - 1, cc - 1) if free(rr - 1, cc) and free(rr, cc - 1) else math.inf
                se = val(rr + 1, cc + 1) if free(rr + 1, cc) and free(rr, cc + 1) else math.inf
                x = min(x, _upwind(min(ne, sw), min(nw, se), math.sqrt(2.0) * ci))
            if x < v[rr, cc]:
                v[rr, cc] = x
                heapq.heappush(heap, (x, (rr, cc)))
    return v
