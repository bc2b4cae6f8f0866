"""numba kernels of strategy: the goal mouth's shadows for the shot evaluation (Bruce 2006, B.5).

Field frame, metres, radians; the numpy reference is :func:`strategy.evaluation.goal_samples_free_reference`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmdragons.geometry import wrap_angle as _wrap_angle

wrap_angle = njit(cache=True)(_wrap_angle)  # the project's one angle wrap, compiled for the kernel


@njit(cache=True)
def goal_samples_free(points: np.ndarray, ys: np.ndarray, gx: float, obstacles: np.ndarray,
                      radius: float) -> np.ndarray:  # fmt: skip
    """Per point (N, 2) and goal-line sample (x = gx, y = ys[k]): whether no obstacle (M, 2) of
    ``radius`` shadows it, an obstacle nearer than the sample and farther than ``radius`` (the
    shooter itself) whose angular half-width covers the sample's direction."""
    n, k, m = len(points), len(ys), len(obstacles)
    free = np.ones((n, k), dtype=np.bool_)
    d = np.empty(m)
    phi = np.empty(m)
    alpha = np.empty(m)
    for i in range(n):
        px, py = points[i, 0], points[i, 1]
        for j in range(m):
            rx, ry = obstacles[j, 0] - px, obstacles[j, 1] - py
            d[j] = math.hypot(rx, ry)
            phi[j] = math.atan2(ry, rx)
            alpha[j] = math.asin(min(max(radius / max(d[j], 1e-9), 0.0), 1.0))
        dx = gx - px
        for s in range(k):
            dy = ys[s] - py
            theta = math.atan2(dy, dx)
            dist = math.hypot(dx, dy)
            for j in range(m):
                if d[j] < dist and d[j] > radius and abs(wrap_angle(theta - phi[j])) <= alpha[j]:
                    free[i, s] = False
                    break
    return free
