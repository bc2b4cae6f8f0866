"""numba kernels of the particle filter (:class:`cmdragons.estimation.filters.ParticleLocalisation`):
one step (move, weigh, resample and regularise, estimate) in one call, with its own random stream.

Poses (x, y, theta) in metres and radians, the world frame; odometry in the vehicle's frame, as in
:mod:`cmdragons.estimation.models`. A ``numpy.random.Generator`` costs microseconds to hand to a
kernel on every call, more than the step itself, so the filter seeds a stream of its own from its
generator once: xoshiro256** (Blackman and Vigna 2018, "Scrambled linear pseudorandom number
generators", §4), a uint64 state of four words, normal deviates from it by the ziggurat
(Marsaglia and Tsang 2000, "The ziggurat method for generating random variables", 256 layers; the
layer tables built once by :func:`ziggurat_tables`).

Plain-numpy references: :mod:`cmdragons.estimation._reference`, which draw the same deviates in
the same order from :func:`normals` and :func:`uniforms`; a test keeps them in agreement.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, uint64
from numpy.typing import NDArray

from cmdragons.geometry import wrap_angle

__all__ = [
    "ZIGGURAT_TAIL",
    "cloud_estimate",
    "correct",
    "move",
    "normal",
    "normals",
    "particle_step",
    "psd_factor",
    "regularise",
    "resample",
    "reweigh",
    "seed_stream",
    "uniform",
    "uniforms",
    "weigh",
    "ziggurat_tables",
]

FloatArray = NDArray[np.float64]

# the ziggurat's 256 layers: the tail starts here and each layer (the bottom one with the tail) has
# the area of ZIGGURAT_TAIL * f(ZIGGURAT_TAIL) + the tail's (Marsaglia and Tsang 2000, table 1)
ZIGGURAT_TAIL = 3.6541528853610088
_LAYERS = 256

_wrap = njit(cache=True, inline="always")(wrap_angle)


def ziggurat_tables() -> tuple[FloatArray, FloatArray]:
    """The layers' right edges x (257,), x[0] the bottom layer's width (area / f(r)), x[1] = r,
    down to x[256] = 0 at the top, and f(x) = exp(-x^2 / 2) at each (unnormalised density)."""
    r = ZIGGURAT_TAIL
    f_r = math.exp(-0.5 * r * r)
    area = r * f_r + math.sqrt(math.pi / 2.0) * math.erfc(r / math.sqrt(2.0))
    x = np.empty(_LAYERS + 1)
    x[0], x[1] = area / f_r, r
    for i in range(1, _LAYERS - 1):
        x[i + 1] = math.sqrt(-2.0 * math.log(area / x[i] + math.exp(-0.5 * x[i] * x[i])))
    x[_LAYERS] = 0.0
    return x, np.exp(-0.5 * x * x)


def seed_stream(rng: np.random.Generator) -> NDArray[np.uint64]:
    """A xoshiro256** state (4,) drawn from ``rng`` (never all zero)."""
    state = rng.integers(0, np.iinfo(np.uint64).max, size=4, dtype=np.uint64, endpoint=True)
    if not state.any():
        state[0] = 1
    return state


@njit(cache=True, inline="always")
def _rotl(x: np.uint64, k: int) -> np.uint64:
    return (x << uint64(k)) | (x >> uint64(64 - k))


@njit(cache=True, inline="always")
def _next(s: np.ndarray) -> np.uint64:
    """The stream's next 64 bits (xoshiro256**); advances ``s``."""
    out = _rotl(s[1] * uint64(5), 7) * uint64(9)
    t = s[1] << uint64(17)
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = _rotl(s[3], 45)
    return out


@njit(cache=True, inline="always")
def uniform(s: np.ndarray) -> float:
    """A uniform deviate in [0, 1) from the stream's top 53 bits."""
    return float(_next(s) >> uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, inline="always")
def normal(s: np.ndarray, zx: np.ndarray, zf: np.ndarray) -> float:
    """A standard normal deviate by the ziggurat over the tables ``zx``, ``zf`` of
    :func:`ziggurat_tables`: one 64-bit draw gives the layer (low 8 bits), the sign (bit 8) and the
    position along the layer (top 53 bits); about 99% land inside the curve at once. A draw beyond
    the bottom layer's edge r goes to the tail, sampled by Marsaglia's (1964) method: a = -ln(U1) / r
    accepted when -2 ln(U2) > a^2 gives r + a. (One loop for both: numba keeps reference-count
    calls on the arrays in every pass of a loop nested in an inlined kernel, ten times the draw.)"""
    tail = False
    while True:
        bits = _next(s)
        u = float(bits >> uint64(11)) * (1.0 / 9007199254740992.0)
        negative = (bits >> uint64(8)) & uint64(1) == uint64(1)
        if tail:
            a = -math.log(1.0 - u) / ZIGGURAT_TAIL
            if -2.0 * math.log(1.0 - uniform(s)) > a * a:
                return -(ZIGGURAT_TAIL + a) if negative else ZIGGURAT_TAIL + a
            continue
        i = int(bits & uint64(0xFF))
        x = u * zx[i]
        if x < zx[i + 1]:
            return -x if negative else x
        if i == 0:
            tail = True
        elif zf[i] + uniform(s) * (zf[i + 1] - zf[i]) < math.exp(-0.5 * x * x):
            return -x if negative else x


@njit(cache=True)
def normals(s: np.ndarray, zx: np.ndarray, zf: np.ndarray, n: int) -> np.ndarray:
    """``n`` standard normal deviates from the stream, in order (for the references and tests)."""
    out = np.empty(n)
    for k in range(n):
        out[k] = normal(s, zx, zf)
    return out


@njit(cache=True)
def uniforms(s: np.ndarray, n: int) -> np.ndarray:
    """``n`` uniform deviates in [0, 1) from the stream, in order (for the references and tests)."""
    out = np.empty(n)
    for k in range(n):
        out[k] = uniform(s)
    return out


@njit(cache=True)
def psd_factor(cov: np.ndarray) -> np.ndarray:
    """A lower-triangular L (d, d) with L L^T = ``cov`` for a symmetric positive semi-definite
    ``cov``: Cholesky, a pivot at or below 1e-12 of the largest variance taken as zero with its
    column (the noise has no component there, as the odometry's sideways one)."""
    d = cov.shape[0]
    low = np.zeros((d, d))
    tiny = 0.0
    for i in range(d):
        tiny = max(tiny, cov[i, i])
    tiny *= 1e-12
    for j in range(d):
        pivot = cov[j, j]
        for k in range(j):
            pivot -= low[j, k] * low[j, k]
        if pivot <= tiny:
            continue
        low[j, j] = math.sqrt(pivot)
        for i in range(j + 1, d):
            v = cov[i, j]
            for k in range(j):
                v -= low[i, k] * low[j, k]
            low[i, j] = v / low[j, j]
    return low


@njit(cache=True, inline="always")
def _add_noise(low: np.ndarray, j: int, z: float, e: np.ndarray) -> None:
    for i in range(j, 3):
        e[i] += low[i, j] * z


@njit(cache=True)
def move(particles: np.ndarray, u: np.ndarray, low: np.ndarray, s: np.ndarray, zx: np.ndarray,
         zf: np.ndarray) -> None:  # fmt: skip
    """Each particle composed with the odometry ``u`` (3,) plus its own noise L z, z standard
    normal, one deviate per non-zero column of L in column order (none for a zero column)."""
    e = np.empty(3)
    for k in range(particles.shape[0]):
        e[0], e[1], e[2] = u[0], u[1], u[2]
        for j in range(3):
            if low[j, j] != 0.0:
                _add_noise(low, j, normal(s, zx, zf), e)
        t = particles[k, 2]
        c, sn = math.cos(t), math.sin(t)
        particles[k, 0] += c * e[0] - sn * e[1]
        particles[k, 1] += sn * e[0] + c * e[1]
        particles[k, 2] = _wrap(t + e[2])


@njit(cache=True)
def weigh(particles: np.ndarray, log_w: np.ndarray, lx: float, ly: float, z_range: float, z_bearing: float,
          r_inv: np.ndarray) -> None:  # fmt: skip
    """Adds to ``log_w`` each particle's log-likelihood (less its constant) of a sighting of the
    landmark at (lx, ly) at range ``z_range`` (m) and bearing ``z_bearing`` (rad), the sensor's
    inverse covariance ``r_inv`` (2, 2): -e^T R^-1 e / 2, e the residual (the bearing's wrapped)."""
    a, b, c = r_inv[0, 0], r_inv[0, 1] + r_inv[1, 0], r_inv[1, 1]
    for k in range(particles.shape[0]):
        dx, dy = lx - particles[k, 0], ly - particles[k, 1]
        er = z_range - math.sqrt(dx * dx + dy * dy)
        eb = _wrap(z_bearing - (math.atan2(dy, dx) - particles[k, 2]))
        log_w[k] -= 0.5 * (a * er * er + b * er * eb + c * eb * eb)


@njit(cache=True)
def reweigh(weights: np.ndarray, log_l: np.ndarray) -> float:
    """``weights`` times the likelihoods exp(``log_l``), scaled to sum 1; returns their effective
    sample size 1 / sum w^2. Through the largest log-likelihood, and when the products underflow
    (the weight sits where the sightings say the vehicle is not) through the weights' logarithms."""
    n = weights.shape[0]
    top = np.max(log_l)
    product = np.empty(n)
    total = 0.0
    for k in range(n):
        product[k] = weights[k] * math.exp(log_l[k] - top)
        total += product[k]
    if not total > 1e-250:
        for k in range(n):
            log_l[k] += math.log(max(weights[k], 1e-300))
        top = np.max(log_l)
        total = 0.0
        for k in range(n):
            product[k] = math.exp(log_l[k] - top)
            total += product[k]
    square, scale = 0.0, 1.0 / total
    for k in range(n):
        weights[k] = product[k] * scale
        square += weights[k] * weights[k]
    return 1.0 / square


@njit(cache=True)
def resample(particles: np.ndarray, weights: np.ndarray, start: float, out: np.ndarray) -> None:
    """Systematic (low-variance) resampling into ``out``: the n positions (start + i) / n, ``start``
    uniform in [0, 1), each picks the particle whose cumulative weight first reaches it."""
    n = particles.shape[0]
    k, cum = 0, weights[0]
    for i in range(n):
        pos = (start + i) / n
        while cum < pos and k < n - 1:
            k += 1
            cum += weights[k]
        out[i, 0], out[i, 1], out[i, 2] = particles[k, 0], particles[k, 1], particles[k, 2]


@njit(cache=True)
def cloud_estimate(particles: np.ndarray, weights: np.ndarray, mean: np.ndarray, cov: np.ndarray) -> None:
    """The cloud's weighted mean pose into ``mean`` (3,) (the heading's circular mean) and its
    weighted covariance about it into ``cov`` (3, 3) (heading differences wrapped)."""
    sx = sy = ss = sc = 0.0
    for k in range(particles.shape[0]):
        w = weights[k]
        sx += w * particles[k, 0]
        sy += w * particles[k, 1]
        ss += w * math.sin(particles[k, 2])
        sc += w * math.cos(particles[k, 2])
    mean[0], mean[1], mean[2] = sx, sy, math.atan2(ss, sc)
    cov[:, :] = 0.0
    for k in range(particles.shape[0]):
        w = weights[k]
        ex, ey, et = particles[k, 0] - sx, particles[k, 1] - sy, _wrap(particles[k, 2] - mean[2])
        cov[0, 0] += w * ex * ex
        cov[0, 1] += w * ex * ey
        cov[0, 2] += w * ex * et
        cov[1, 1] += w * ey * ey
        cov[1, 2] += w * ey * et
        cov[2, 2] += w * et * et
    cov[1, 0], cov[2, 0], cov[2, 1] = cov[0, 1], cov[0, 2], cov[1, 2]


@njit(cache=True)
def regularise(particles: np.ndarray, low: np.ndarray, s: np.ndarray, zx: np.ndarray, zf: np.ndarray) -> None:
    """Each particle moved by its own draw L z of the regularisation kernel (L L^T its covariance;
    one deviate per non-zero column of L), headings wrapped."""
    e = np.empty(3)
    for k in range(particles.shape[0]):
        e[0] = e[1] = e[2] = 0.0
        for j in range(3):
            if low[j, j] != 0.0:
                _add_noise(low, j, normal(s, zx, zf), e)
        particles[k, 0] += e[0]
        particles[k, 1] += e[1]
        particles[k, 2] = _wrap(particles[k, 2] + e[2])


@njit(cache=True)
def correct(particles: np.ndarray, weights: np.ndarray, seen: np.ndarray, r_inv: np.ndarray, bandwidth: float,
            s: np.ndarray, zx: np.ndarray, zf: np.ndarray, scratch: np.ndarray) -> bool:  # fmt: skip
    """The measurement half of a step: :func:`weigh` by each row of ``seen`` (m, 4: landmark x, y,
    range, bearing), :func:`reweigh`, and when the effective sample size falls below n / 2
    :func:`resample` (``scratch`` (n, 3) its work space) and :func:`regularise` by ``bandwidth`` (h)
    times the factor of the cloud's covariance before resampling. Returns whether it resampled."""
    n = particles.shape[0]
    if seen.shape[0] == 0:
        return False
    log_l = np.zeros(n)
    for i in range(seen.shape[0]):
        weigh(particles, log_l, seen[i, 0], seen[i, 1], seen[i, 2], seen[i, 3], r_inv)
    if reweigh(weights, log_l) >= 0.5 * n:
        return False
    mean, cov = np.empty(3), np.empty((3, 3))
    cloud_estimate(particles, weights, mean, cov)
    resample(particles, weights, uniform(s), scratch)
    particles[:] = scratch
    weights[:] = 1.0 / n
    if bandwidth > 0.0:
        regularise(particles, psd_factor(bandwidth * bandwidth * cov), s, zx, zf)
    return True


@njit(cache=True)
def particle_step(particles: np.ndarray, weights: np.ndarray, u: np.ndarray, u_cov: np.ndarray,
                  seen: np.ndarray, r_inv: np.ndarray, bandwidth: float, s: np.ndarray, zx: np.ndarray,
                  zf: np.ndarray, scratch: np.ndarray, mean: np.ndarray, cov: np.ndarray) -> bool:  # fmt: skip
    """One step of the regularised particle filter: :func:`move` by the odometry ``u`` (3,) of
    covariance ``u_cov`` (3, 3), :func:`correct` by the sightings ``seen``, and the cloud's
    estimate into ``mean`` (3,) and ``cov`` (3, 3). Returns whether it resampled."""
    move(particles, u, psd_factor(u_cov), s, zx, zf)
    resampled = correct(particles, weights, seen, r_inv, bandwidth, s, zx, zf, scratch)
    cloud_estimate(particles, weights, mean, cov)
    return resampled
