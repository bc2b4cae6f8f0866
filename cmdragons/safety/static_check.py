"""The braking trajectory against the static world (walls, defense areas, goal walls: a compiled
collision world's ``obs`` and ``inner``, :mod:`cmdragons.planning.collision`): the safety search's
check and the dynamic window's admissibility, so public; with its plain-numpy reference, by brute
force over dense samples."""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from cmdragons.control.acceleration import N_SEG, seg_at
from cmdragons.planning.collision import clearance
from cmdragons.planning.collision_reference import obstacle_dist
from cmdragons.safety._reference import positions

FloatArray = NDArray[np.float64]


@njit(cache=True)
def static_hits(tr: np.ndarray, obs: np.ndarray, inner: np.ndarray, margin: float, step: float) -> bool:
    """Does the trajectory come within ``margin`` of an obstacle of the compiled collision world
    (``obs``, ``inner``: see :mod:`cmdragons.planning.collision`; its clearance query)? Sampled so that
    consecutive samples lie at most ``step`` apart along the path, each held to ``margin + step / 2``
    (every point of the path is within step / 2 of a sample). A start already closer only fails
    deeper."""
    c0 = clearance(obs, inner, tr[0, 2], tr[0, 3])
    need = min(margin + 0.5 * step, c0 - 1e-9)
    for k in range(N_SEG - 1):
        t0, t1 = tr[k, 0], tr[k, 1]
        if t1 - t0 <= 0.0:
            continue
        vmax = max(math.hypot(tr[k, 4], tr[k, 5]), math.hypot(tr[k, 4] + tr[k, 6] * (t1 - t0),
                                                              tr[k, 5] + tr[k, 7] * (t1 - t0)))
        n = max(1, int(math.ceil(vmax * (t1 - t0) / step)))
        for i in range(1, n + 1):
            px, py, _, _ = seg_at(tr, k, t0 + (t1 - t0) * i / n)
            if clearance(obs, inner, px, py) < need:
                return True
    return False


def static_min_clearance(tr: FloatArray, obs: FloatArray, inner: FloatArray, n: int = 4001) -> float:
    """The least clearance of the trajectory from the walls and the obstacles of a compiled collision
    world (``obs``, ``inner``), by brute force over dense samples."""
    p = positions(tr, np.linspace(0.0, float(tr[-1, 0]), n))
    c = np.minimum.reduce([p[:, 0] - inner[0], inner[2] - p[:, 0], p[:, 1] - inner[1], inner[3] - p[:, 1]])
    if len(obs):
        c = np.minimum(c, np.min(obstacle_dist(obs, p) - obs[:, 5:6], axis=0))
    return float(np.min(c))
