"""Plain-numpy reference of the dynamic window's kernel, for the test that checks both agree: a
trajectory's clearance by dense sampling and brute-force distances to every grown obstacle, every
candidate of the window scored."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cmdragons.control.acceleration import Limits, trajectory
from cmdragons.navigation._dynamic_window_kernels import WindowConfig, window_velocity
from cmdragons.safety.static_check import static_min_clearance

FloatArray = NDArray[np.float64]


def window_scores(
    obs: FloatArray, inner: FloatArray, px: float, py: float, vx: float, vy: float, dx: float, dy: float,
    window: FloatArray, lim: Limits, cfg: WindowConfig,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per candidate of the window (the desired velocity first): the velocity (k, 2), the least
    clearance of its trajectory minus the clearance it needs (k,; < 0 not admissible: it needs
    ``margin``, or to come no closer where it starts closer), and its score (k,)."""
    vel, slack, score = [], [], []
    for r in range(len(window) + 1):
        cx, cy = window_velocity(vx, vy, dx, dy, r, window, lim, cfg.dt)
        tr = trajectory(px, py, cx, cy, 0.0, 0.0, cfg.dt, lim.accel, lim.brake)
        start = static_min_clearance(tr[:1], obs, inner, n=1)
        low = static_min_clearance(tr, obs, inner)
        rest = static_min_clearance(tr[3:4], obs, inner, n=1)
        vel.append((cx, cy))
        slack.append(low - min(cfg.margin, start))
        score.append(-np.hypot(cx - dx, cy - dy) + cfg.clearance_weight * min(max(rest, 0.0), cfg.clearance_cap))
    return np.array(vel), np.array(slack), np.array(score)
