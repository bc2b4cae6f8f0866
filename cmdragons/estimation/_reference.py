"""Plain-numpy reference of the particle filter's step kernel (:func:`cmdragons.estimation._kernels.
particle_step`), for the test that checks both agree: the same deviates, drawn in the same order
from the kernels' stream (:func:`~cmdragons.estimation._kernels.normals`, ``uniforms``), used by
array operations, the estimate by :func:`cmdragons.estimation.filters.particle_estimate`."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cmdragons.estimation import _kernels as K
from cmdragons.estimation.filters import particle_estimate
from cmdragons.geometry import wrap_angle

FloatArray = NDArray[np.float64]


def _noise(low: FloatArray, n: int, s: NDArray[np.uint64], zx: FloatArray, zf: FloatArray) -> FloatArray:
    """n draws L z (n, 3), one deviate per non-zero column of L, particle after particle."""
    cols = np.flatnonzero(np.diag(low))
    z = K.normals(s, zx, zf, n * len(cols)).reshape(n, len(cols))
    return np.asarray(z @ low[:, cols].T, dtype=np.float64)


def particle_step(particles: FloatArray, weights: FloatArray, u: FloatArray, u_cov: FloatArray, seen: FloatArray,
                  r_inv: FloatArray, bandwidth: float, s: NDArray[np.uint64], zx: FloatArray,
                  zf: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, bool]:
    """The step on copies: new particles and weights, the estimate (mean, covariance) and whether
    it resampled; advances the stream ``s``."""
    p, w = particles.copy(), weights.copy()
    n = len(p)
    e = u + _noise(K.psd_factor(u_cov), n, s, zx, zf)  # a semi-definite factor: the test checks it alone
    c, sn = np.cos(p[:, 2]), np.sin(p[:, 2])
    p[:, 0] += c * e[:, 0] - sn * e[:, 1]
    p[:, 1] += sn * e[:, 0] + c * e[:, 1]
    p[:, 2] = wrap_angle(p[:, 2] + e[:, 2])
    resampled = False
    if len(seen):
        log_l = np.zeros(n)
        for lx, ly, zr, zb in seen:
            dx, dy = lx - p[:, 0], ly - p[:, 1]
            res = np.stack([zr - np.hypot(dx, dy), wrap_angle(zb - (np.arctan2(dy, dx) - p[:, 2]))], axis=1)
            log_l -= 0.5 * np.einsum("ni,ij,nj->n", res, r_inv, res)
        w = w * np.exp(log_l - log_l.max())
        w /= w.sum()
        if 1.0 / np.sum(w**2) < 0.5 * n:
            _, cov = particle_estimate(p, w)
            positions = (K.uniforms(s, 1)[0] + np.arange(n)) / n
            p = p[np.minimum(np.searchsorted(np.cumsum(w), positions), n - 1)]
            w = np.full(n, 1.0 / n)
            if bandwidth > 0.0:
                p += _noise(np.asarray(np.linalg.cholesky(bandwidth * bandwidth * cov), dtype=np.float64), n, s, zx, zf)
                p[:, 2] = wrap_angle(p[:, 2])
            resampled = True
    mean, cov = particle_estimate(p, w)
    return p, w, mean, cov, resampled
