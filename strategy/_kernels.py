"""numba kernels of strategy: the goal mouth's shadows for the shot evaluation (Bruce 2006, B.5).

Field frame, metres, radians; the numpy reference is :func:`strategy.evaluation.goal_samples_free_reference`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmdragons.angles import wrap_angle


@njit(cache=True)
def goal_samples_free(points: np.ndarray, ys: np.ndarray, gx: float, obstacles: np.ndarray,
                      radius: float) -> np.ndarray:
    """Per point (N, 2) and goal-line sample (x = gx, y = ys[k]): whether no obstacle (M, 2) of
    ``radius`` shadows it, an obstacle nearer than the sample and farther than ``radius`` (the
    shooter itself) whose angular half-width covers the sample's direction."""
    n, k, m = len(points), len(ys), len(obstacles)
    free = np.ones((n, k), dtype=np.bool_)
    d = np.empty(m)
    phi = np.empty(m)
    alpha = np.empty(m)
    theta = np.empty(k)
    dist = np.empty(k)
    cone = np.empty(m, dtype=np.bool_)
    for i in range(n):
        px, py = points[i, 0], points[i, 1]
        dx = gx - px
        for s in range(k):
            dy = ys[s] - py
            theta[s] = math.atan2(dy, dx)
            dist[s] = math.hypot(dx, dy)
        # the mouth as seen from the point: its middle sample's direction and the widest offset
        mid = theta[k // 2]
        half = 0.0
        for s in range(k):
            half = max(half, abs(wrap_angle(theta[s] - mid)))
        any_cone = False
        for j in range(m):
            rx, ry = obstacles[j, 0] - px, obstacles[j, 1] - py
            d[j] = math.hypot(rx, ry)
            phi[j] = math.atan2(ry, rx)
            alpha[j] = math.asin(min(max(radius / max(d[j], 1e-9), 0.0), 1.0))
            # an obstacle whose shadow misses the mouth's directions by more than rounding can shadow
            # no sample (on the circle |theta - phi| >= |mid - phi| - |theta - mid|): it is not checked
            cone[j] = d[j] > radius and abs(wrap_angle(phi[j] - mid)) <= half + alpha[j] + 1e-9
            any_cone = any_cone or cone[j]
        if not any_cone:
            continue
        for s in range(k):
            for j in range(m):
                if cone[j] and d[j] < dist[s] and abs(wrap_angle(theta[s] - phi[j])) <= alpha[j]:
                    free[i, s] = False
                    break
    return free


@njit(cache=True)
def free_runs(free: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per row of ``free`` (N, K): the longest run of free samples (its length and last index, the
    first such run on ties) and the free samples leading from the first and trailing from the last."""
    n, k = free.shape
    best_len = np.zeros(n, dtype=np.int64)
    best_end = np.zeros(n, dtype=np.int64)
    lead = np.zeros(n, dtype=np.int64)
    trail = np.zeros(n, dtype=np.int64)
    for i in range(n):
        run = 0
        for j in range(k):
            run = run + 1 if free[i, j] else 0
            if run > best_len[i]:
                best_len[i], best_end[i] = run, j
        while lead[i] < k and free[i, lead[i]]:
            lead[i] += 1
        while trail[i] < k and free[i, k - 1 - trail[i]]:
            trail[i] += 1
    return best_len, best_end, lead, trail
