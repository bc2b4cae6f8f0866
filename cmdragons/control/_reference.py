"""Plain-numpy references of the motion-control kernels, for the tests that check both agree.

They favour the obvious over the fast: the optimal peak velocity by scanning a dense grid of peaks,
the 2D split by scanning angles.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def ramp(u: FloatArray, w: FloatArray, a: float, b: float) -> tuple[FloatArray, FloatArray]:
    """Time and signed distance from velocity u to w (arrays), speeding up at a, slowing at b."""
    u, w = np.asarray(u, dtype=np.float64), np.asarray(w, dtype=np.float64)
    cross = u * w < 0
    # through zero: brake u -> 0 then speed up 0 -> w
    t_cross = np.abs(u) / b + np.abs(w) / a
    s_cross = u * np.abs(u) / (2 * b) + w * np.abs(w) / (2 * a)
    up = np.abs(w) >= np.abs(u)
    t_same = np.where(up, (np.abs(w) - np.abs(u)) / a, (np.abs(u) - np.abs(w)) / b)
    # the distance is |w|^2 - |u|^2 over 2a speeding up, |u|^2 - |w|^2 over 2b slowing down, signed
    s_same = np.where(up, (w * np.abs(w) - u * np.abs(u)) / (2 * a), (u * np.abs(u) - w * np.abs(w)) / (2 * b))
    return np.where(cross, t_cross, t_same), np.where(cross, s_cross, s_same)


def profile_time(d: float, v0: float, vt: float, vmax: float, a: float, b: float, n: int = 200001) -> float:
    """The least total time over a dense grid of peak velocities in [-vmax, vmax]."""
    vt = float(np.clip(vt, -vmax, vmax))
    vp = np.linspace(-vmax, vmax, n)
    t1, s1 = ramp(np.full(n, v0), vp, a, b)
    t2, s2 = ramp(vp, np.full(n, vt), a, b)
    cruise = d - s1 - s2
    with np.errstate(divide="ignore", invalid="ignore"):
        tc = np.where(np.abs(cruise) < 1e-12, 0.0, cruise / vp)
    tc = np.where(np.isfinite(tc) & (tc >= 0), tc, np.inf)
    return float(np.min(t1 + t2 + tc))


def simulate_1d(d: float, v0: float, phases: FloatArray, steps_per_s: int = 20000) -> tuple[float, float, float]:
    """Integrate the phases with small steps: (distance left, final velocity, max |acceleration|)."""
    x, v, amax = 0.0, v0, 0.0
    for duration, acc in phases:
        n = int(np.ceil(duration * steps_per_s))
        if n == 0:
            continue
        h = duration / n
        for _ in range(n):
            x += v * h + 0.5 * acc * h * h
            v += acc * h
        amax = max(amax, abs(acc))
    return d - x, v, amax


def clip_accel(v: FloatArray, a: FloatArray, accel: float, brake: float) -> FloatArray:
    """Accelerations (n, 2) scaled into A(v) for velocities (n, 2), as
    :func:`cmdragons.control.acceleration.clip_accel`."""
    speed = np.linalg.norm(v, axis=1)
    unit = np.where(speed[:, None] > 1e-9, v / np.maximum(speed, 1e-300)[:, None], 0.0)
    along = np.einsum("ij,ij->i", a, unit)
    across = np.linalg.norm(a - along[:, None] * unit, axis=1)
    k = np.where(along >= 0, np.linalg.norm(a, axis=1) / accel, np.hypot(along / brake, across / accel))
    return np.asarray(a / np.maximum(k, 1.0)[:, None], dtype=np.float64)
