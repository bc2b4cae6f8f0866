"""Plain-numpy references of the collision kernels (:mod:`cmdragons.planning.collision`), for the tests
that check both agree, and for the references of the packages that share those kernels.

They favour the obvious over the fast: distances by dense sampling or by formulas over all pairs,
collision by scanning every obstacle.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cmdragons.planning.collision import EPS_M

FloatArray = NDArray[np.float64]


def point_segment_dist(p: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distances from points p (n, 2) to segments a-b (n, 2 each)."""
    d = b - a
    den = np.einsum("ij,ij->i", d, d)
    t = np.where(den > 0, np.einsum("ij,ij->i", p - a, d) / np.where(den > 0, den, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    out: FloatArray = np.hypot(*(a + t[:, None] * d - p).T)
    return out


def point_box_dist(p: FloatArray, box: FloatArray) -> FloatArray:
    """Distances from points p (n, 2) to boxes (n, 4) x0, y0, x1, y1."""
    ex = np.maximum.reduce([box[:, 0] - p[:, 0], np.zeros(len(p)), p[:, 0] - box[:, 2]])
    ey = np.maximum.reduce([box[:, 1] - p[:, 1], np.zeros(len(p)), p[:, 1] - box[:, 3]])
    out: FloatArray = np.hypot(ex, ey)
    return out


def sampled_segment_dist(a: FloatArray, b: FloatArray, dist_to_point, samples: int = 4001) -> float:  # type: ignore[no-untyped-def]
    """Distance from segment a-b to a set, as the minimum over ``samples`` points of the segment."""
    f = np.linspace(0.0, 1.0, samples)[:, None]
    return float(np.min(dist_to_point(a + f * (b - a))))


def obstacle_dist(obs: FloatArray, p: FloatArray) -> FloatArray:
    """Distances (m, n) from points p (n, 2) to the core of every obstacle row of ``obs`` (m, 6)."""
    a, b = obs[:, None, 1:3], obs[:, None, 3:5]
    d = b - a
    den = np.sum(d * d, axis=2)
    t = np.sum((p[None] - a) * d, axis=2) / np.where(den > 0, den, 1.0)
    seg = np.hypot(*np.moveaxis(a + np.clip(t, 0.0, 1.0)[..., None] * d - p[None], 2, 0))
    ex = np.maximum(np.maximum(obs[:, None, 1] - p[None, :, 0], 0.0), p[None, :, 0] - obs[:, None, 3])
    ey = np.maximum(np.maximum(obs[:, None, 2] - p[None, :, 1], 0.0), p[None, :, 1] - obs[:, None, 4])
    return np.where(obs[:, None, 0] == 0.0, seg, np.hypot(ex, ey))


def segment_clearance(obs: FloatArray, inner: FloatArray, a: FloatArray, b: FloatArray, samples: int = 1001) -> float:
    """The smallest clearance (m) of the robot centre moving from a to b, from the field walls and
    every grown obstacle, by sampling the segment densely; < 0 means a collision."""
    f = np.linspace(0.0, 1.0, samples)[:, None]
    pts = a + f * (b - a)
    walls = np.minimum.reduce([pts[:, 0] - inner[0], inner[2] - pts[:, 0], pts[:, 1] - inner[1], inner[3] - pts[:, 1]])
    clear = float(walls.min())
    if len(obs):
        clear = min(clear, float((obstacle_dist(obs, pts) - obs[:, 5:6]).min()))
    return clear


def segment_free(obs: FloatArray, inner: FloatArray, a: FloatArray, b: FloatArray, samples: int = 1001) -> bool:
    """Swept-circle check by sampling the segment densely against every obstacle."""
    return segment_clearance(obs, inner, a, b, samples) >= -EPS_M
