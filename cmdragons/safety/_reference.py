"""Plain-numpy references of the safety kernels, for the tests that check both agree.

They favour the obvious over the fast: trajectories sampled densely in time, minima by argmin over
the samples, quartic minima from numpy's polynomial roots.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def quartic_min(c: FloatArray, T: float) -> float:
    """Minimum of sum c[k] t^k over [0, T] from the real roots of the derivative."""
    poly = np.polynomial.Polynomial(c)
    crit = [float(r.real) for r in poly.deriv().roots() if abs(r.imag) < 1e-9 and 0.0 < float(r.real) < T]
    return float(min(poly(np.array([0.0, T, *crit]))))


def positions(tr: FloatArray, t: FloatArray) -> FloatArray:
    """Positions (len(t), 2) of a trajectory (segments as in the kernels) at times t."""
    t = np.asarray(t, dtype=np.float64)
    k = np.minimum(np.searchsorted(tr[:, 1], t, side="left"), len(tr) - 1)
    h = (t - tr[k, 0])[:, None]
    return np.asarray(tr[k, 2:4] + tr[k, 4:6] * h + 0.5 * tr[k, 6:8] * h * h)


def sample_times(*trs: FloatArray, n: int = 4001) -> FloatArray:
    """Dense times from 0 to the latest rest of the trajectories (and a little after)."""
    end = max(float(tr[-1, 0]) for tr in trs)
    return np.linspace(0.0, end * 1.01 + 1e-6, n)


def pair_min_distance(ta: FloatArray, tb: FloatArray, n: int = 4001) -> float:
    """The least distance between the two centres at equal times, by dense sampling."""
    t = sample_times(ta, tb, n=n)
    return float(np.min(np.linalg.norm(positions(ta, t) - positions(tb, t), axis=1)))


def pair_min_gap(ta: FloatArray, tb: FloatArray, radius: float, growth: float, n: int = 4001) -> float:
    """The least of |pa(t) - pb(t)| minus the kept distance min(radius + growth t, start distance),
    the growth stopping once both rest; by dense sampling."""
    t = sample_times(ta, tb, n=n)
    d = np.linalg.norm(positions(ta, t) - positions(tb, t), axis=1)
    rest = max(float(ta[-1, 0]), float(tb[-1, 0]))
    kept = np.minimum(radius + growth * np.minimum(t, rest), d[0])
    return float(np.min(d - kept))


def opponent_min_gap(tr: FloatArray, opponent: FloatArray, accel: float, n: int = 4001) -> float:
    """The least of |p(t) - (o + w t)| - accel t^2 / 2 until the trajectory rests, by sampling."""
    t = np.linspace(0.0, float(tr[-1, 0]), n)
    q = opponent[:2] + np.outer(t, opponent[2:4])
    return float(np.min(np.linalg.norm(positions(tr, t) - q, axis=1) - 0.5 * accel * t * t))
