"""numba kernels of the particle filter (:class:`cmdragons.estimation.filters.ParticleLocalisation`):
one step (move, weigh, resample and regularise, estimate) in one call, with its own random stream.

Poses (x, y, theta) in metres and radians, the world frame; odometry in the vehicle's frame, as in
:mod:`cmdragons.estimation.models`. The particles are a cloud (5, n): rows x, y, theta, cos theta,
sin theta, one particle per column, so that each loop over the particles reads and writes
contiguous rows and numba (LLVM) runs it in vector lanes. Each heading's cosine and sine are kept
beside it and turned with it (:func:`_turn`: a rotation by the turn's Taylor series, no library
call), the bearing's residual takes a polynomial arctangent (:func:`fast_atan2`), and the loops
divide with ``error_model="numpy"`` (IEEE division: numba's default tests every divisor for zero
to raise ZeroDivisionError, a branch that keeps a loop from vectorising; no divisor here is zero).
A ``numpy.random.Generator`` costs about 10 µs to hand to a kernel on every call, more than the step
itself, so the filter seeds a stream of its own from its generator once: xoshiro256** (Blackman and
Vigna 2018, "Scrambled linear pseudorandom number generators", §4), a uint64 state of four words,
normal deviates from it by the ziggurat (Marsaglia and Tsang 2000, "The ziggurat method for
generating random variables", 256 layers; the layer tables built once by :func:`ziggurat_tables`).

Plain-numpy references: :mod:`cmdragons.estimation._reference`, which draw the same deviates in
the same order from :func:`normals` and :func:`uniforms`; a test keeps them in agreement.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, uint64
from numpy.typing import NDArray

__all__ = [
    "ZIGGURAT_TAIL",
    "TAYLOR_TURN",
    "cloud_estimate",
    "correct",
    "exps",
    "fast_atan2",
    "gaussian_draws",
    "move",
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
    "wrap",
    "ziggurat_tables",
]

FloatArray = NDArray[np.float64]

# the ziggurat's 256 layers: the tail starts here and each layer (the bottom one with the tail) has
# the area of ZIGGURAT_TAIL * f(ZIGGURAT_TAIL) + the tail's (Marsaglia and Tsang 2000, table 1)
ZIGGURAT_TAIL = 3.6541528853610088
_LAYERS = 256

_TWO_PI = 2.0 * math.pi
# LLVM flags for the kernels that sum over the particles: sums reassociated into vector lanes (the
# result moves in the last bits with the lanes' count, the same on every run of one machine) and
# multiply-adds fused; no assumption that values are finite
_SUMS = {"reassoc", "contract"}


@njit(cache=True, inline="always")
def wrap(a: float) -> float:
    """:func:`cmdragons.geometry.wrap_angle` (to rounding; the ends: [-pi, pi]) through a
    floor: numba's float modulo, which that takes, runs through fmod at several times the cost, and
    the cloud wraps every heading on every step (a test keeps the two in agreement)."""
    return a - _TWO_PI * math.floor((a + math.pi) / _TWO_PI)


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
def _xoshiro(s0: np.uint64, s1: np.uint64, s2: np.uint64, s3: np.uint64) -> tuple[np.uint64, ...]:
    """xoshiro256**: the next 64 bits of the state (s0, s1, s2, s3), and the advanced state."""
    out = _rotl(s1 * uint64(5), 7) * uint64(9)
    t = s1 << uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    return out, s0, s1, s2, s3


@njit(cache=True, inline="always")
def _unit(bits: np.uint64) -> float:
    """A uniform deviate in [0, 1) from the top 53 of 64 bits."""
    return float(bits >> uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, inline="always")
def uniform(s: np.ndarray) -> float:
    """A uniform deviate in [0, 1) from the stream ``s`` (4,); advances it."""
    bits, s[0], s[1], s[2], s[3] = _xoshiro(s[0], s[1], s[2], s[3])
    return _unit(bits)


@njit(cache=True)
def normals(s: np.ndarray, zx: np.ndarray, zf: np.ndarray, n: int) -> np.ndarray:
    """``n`` standard normal deviates from the stream ``s``, in order, by the ziggurat over the
    tables ``zx``, ``zf`` of :func:`ziggurat_tables`: one 64-bit draw gives the layer (low 8 bits),
    the sign (bit 8) and the position along the layer (top 53 bits); about 99% land inside the curve
    at once, the others test the layer's wedge against the density with a second draw. A draw beyond
    the bottom layer's edge r goes to the tail, sampled by Marsaglia's (1964) method: a = -ln(U1) / r
    accepted when -2 ln(U2) > a^2 gives r + a. The stream's state is held in locals for the whole
    batch and written back at the end (read and written through the array on every draw, it costs
    about as much as the draw)."""
    out = np.empty(n)
    s0, s1, s2, s3 = s[0], s[1], s[2], s[3]
    k = 0
    tail = False
    while k < n:
        bits, s0, s1, s2, s3 = _xoshiro(s0, s1, s2, s3)
        u = _unit(bits)
        sign = -1.0 if (bits >> uint64(8)) & uint64(1) == uint64(1) else 1.0
        if tail:
            a = -math.log(1.0 - u) / ZIGGURAT_TAIL
            bits, s0, s1, s2, s3 = _xoshiro(s0, s1, s2, s3)
            if -2.0 * math.log(1.0 - _unit(bits)) > a * a:
                out[k] = sign * (ZIGGURAT_TAIL + a)
                k += 1
                tail = False
            continue
        i = int(bits & uint64(0xFF))
        x = u * zx[i]
        if x < zx[i + 1]:
            out[k] = sign * x
            k += 1
        elif i == 0:
            tail = True
        else:
            bits, s0, s1, s2, s3 = _xoshiro(s0, s1, s2, s3)
            if zf[i] + _unit(bits) * (zf[i + 1] - zf[i]) < math.exp(-0.5 * x * x):
                out[k] = sign * x
                k += 1
    s[0], s[1], s[2], s[3] = s0, s1, s2, s3
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


@njit(cache=True)
def gaussian_draws(low: np.ndarray, n: int, s: np.ndarray, zx: np.ndarray, zf: np.ndarray) -> np.ndarray:
    """n draws L z (3, n) of a 3-d Gaussian of lower-triangular factor L, z standard normal: one
    deviate per non-zero column of L (a zero pivot's column is all zero), draw after draw, in column
    order. The deviates are drawn in one loop first: drawn inside the loop over the draws, each
    would pay numba's reference counting of the stream's arrays, several times the deviate."""
    cols = np.zeros(3, dtype=np.int64)
    m = 0
    for j in range(3):
        if low[j, j] != 0.0:
            cols[m] = j
            m += 1
    z = normals(s, zx, zf, n * m)
    out = np.empty((3, n))
    l00, l10, l11, l20, l21, l22 = low[0, 0], low[1, 0], low[1, 1], low[2, 0], low[2, 1], low[2, 2]
    for k in range(n):
        z0 = z1 = z2 = 0.0
        for i in range(m):
            v = z[k * m + i]
            if cols[i] == 0:
                z0 = v
            elif cols[i] == 1:
                z1 = v
            else:
                z2 = v
        out[0, k] = l00 * z0
        out[1, k] = l10 * z0 + l11 * z1
        out[2, k] = l20 * z0 + l21 * z1 + l22 * z2
    return out


# atan(t) = t P(t^2) on |t| <= tan(pi/8): P's coefficients, lowest first, from the degree-9 Chebyshev
# interpolant of atan(sqrt v) / sqrt v over v in [0, tan^2(pi/8)] (near-minimax; see fast_atan2)
_ATAN_P = (0.9999999999999991, -0.3333333333321608, 0.19999999977656527, -0.14285712623685048,
           0.1111104783166958, -0.09089513851204174, 0.07673380890211737, -0.06505092777792344,
           0.050219307903911777, -0.025278269277016503)
_TAN_PI_8 = math.tan(math.pi / 8.0)
# the turn whose cosine and sine come from their Taylor series (to d^8 and d^9: the first omitted
# terms, d^10 / 10! and d^11 / 11!, are below 2.7e-10 and 1.2e-11 at |d| = 0.5; below 3e-20 at 0.05)
TAYLOR_TURN = 0.5  # rad


@njit(cache=True, inline="always")
def fast_atan2(y: float, x: float) -> float:
    """atan2(y, x) in [-pi, pi] without a library call, for the particle loops (which numba can then
    vectorise): the octant's symmetries reduce the angle to atan(t), t = min / max of |x|, |y| in
    [0, 1]; above tan(pi/8), atan(t) = pi/4 + atan((t - 1) / (t + 1)) brings t into [-tan(pi/8),
    tan(pi/8)] (both as one quotient of |x| and |y|), where an odd polynomial of degree 19 (the
    Chebyshev interpolant of atan, ``_ATAN_P``) is within 1e-15 rad of it. Error bound: 2e-15 rad
    against ``math.atan2`` over all angles (the polynomial's 6e-16 plus the reduction's rounding;
    the test measures it on a dense grid including the axes), for |x|, |y| below 1e307 (their sum
    must not overflow). The zero vector gives 0 (pi when x < 0, as ``math.atan2``); the
    choices are selects, not branches, so that a loop over particles can run them in vector lanes."""
    ax, ay = abs(x), abs(y)
    lo, hi = min(ax, ay), max(ax, ay)
    far = lo > _TAN_PI_8 * hi  # the reduced angle beyond pi/8
    num = lo - hi if far else lo
    den = lo + hi if far else (hi if hi > 0.0 else 1.0)
    t = num / den
    v = t * t
    p = _ATAN_P[9]
    p = p * v + _ATAN_P[8]
    p = p * v + _ATAN_P[7]
    p = p * v + _ATAN_P[6]
    p = p * v + _ATAN_P[5]
    p = p * v + _ATAN_P[4]
    p = p * v + _ATAN_P[3]
    p = p * v + _ATAN_P[2]
    p = p * v + _ATAN_P[1]
    p = p * v + _ATAN_P[0]
    a = t * p + (0.25 * math.pi if far else 0.0)
    a = 0.5 * math.pi - a if ay > ax else a
    a = math.pi - a if x < 0.0 else a
    return math.copysign(a, y)


@njit(cache=True, inline="always")
def _turn(cloud: np.ndarray, k: int, d: float) -> bool:
    """Particle ``k``'s heading turned by ``d`` (rad) and wrapped, its cosine and sine rotated by
    (cos d, sin d) from their Taylor series, then brought back to unit length by the first-order
    correction (3 - c^2 - s^2) / 2 (its error is the square of the length's, so rounding cannot
    drift). Returns False, the cosine and sine left stale, when |d| > ``TAYLOR_TURN``: the caller
    sets those by :func:`_recompute_turns` (a library call in this loop would keep numba from
    vectorising it)."""
    cloud[2, k] = wrap(cloud[2, k] + d)
    d2 = d * d
    cd = 1.0 + d2 * (-1.0 / 2.0 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0))))
    sd = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0 + d2 * (1.0 / 362880.0)))))
    c, s = cloud[3, k], cloud[4, k]
    c, s = c * cd - s * sd, s * cd + c * sd
    g = 0.5 * (3.0 - c * c - s * s)
    cloud[3, k], cloud[4, k] = c * g, s * g
    return abs(d) <= TAYLOR_TURN


@njit(cache=True)
def _recompute_turns(cloud: np.ndarray, turns: np.ndarray) -> None:
    """The cosine and sine of the headings of the particles whose turn ``turns`` (n,) exceeded
    ``TAYLOR_TURN``, from the library (rare: a turn that large is not a step's odometry)."""
    for k in range(cloud.shape[1]):
        if abs(turns[k]) > TAYLOR_TURN:
            cloud[3, k], cloud[4, k] = math.cos(cloud[2, k]), math.sin(cloud[2, k])


@njit(cache=True, error_model="numpy")
def move(cloud: np.ndarray, u: np.ndarray, low: np.ndarray, s: np.ndarray, zx: np.ndarray, zf: np.ndarray) -> None:
    """Each particle composed with the odometry ``u`` (3,) plus its own noise L z, z standard
    normal, one deviate per non-zero column of L in column order (none for a zero column)."""
    e = gaussian_draws(low, cloud.shape[1], s, zx, zf)
    small = True
    for k in range(cloud.shape[1]):
        dx, dy = u[0] + e[0, k], u[1] + e[1, k]
        c, sn = cloud[3, k], cloud[4, k]
        cloud[0, k] += c * dx - sn * dy
        cloud[1, k] += sn * dx + c * dy
        e[2, k] += u[2]
        small &= _turn(cloud, k, e[2, k])
    if not small:
        _recompute_turns(cloud, e[2])


@njit(cache=True, error_model="numpy")
def weigh(cloud: np.ndarray, log_l: np.ndarray, lx: float, ly: float, z_range: float, z_bearing: float,
          r_inv: np.ndarray) -> None:
    """Adds to ``log_l`` each particle's log-likelihood (less its constant) of a sighting of the
    landmark at (lx, ly) at range ``z_range`` (m) and bearing ``z_bearing`` (rad), the sensor's
    inverse covariance ``r_inv`` (2, 2): -e^T R^-1 e / 2, e the residual. The bearing's residual,
    z_bearing - (atan2(dy, dx) - theta), is the angle from the landmark's direction (dx, dy) to the
    sighting's, theta + z_bearing: one arctangent of their cross and dot products, already wrapped."""
    a, b, c = r_inv[0, 0], r_inv[0, 1] + r_inv[1, 0], r_inv[1, 1]
    cz, sz = math.cos(z_bearing), math.sin(z_bearing)
    for k in range(cloud.shape[1]):
        dx, dy = lx - cloud[0, k], ly - cloud[1, k]
        er = z_range - math.sqrt(dx * dx + dy * dy)
        cs, ss = cloud[3, k] * cz - cloud[4, k] * sz, cloud[4, k] * cz + cloud[3, k] * sz  # theta + z_bearing
        eb = fast_atan2(ss * dx - cs * dy, cs * dx + ss * dy)
        log_l[k] -= 0.5 * (a * er * er + b * er * eb + c * eb * eb)


# exp by 2^j exp(r), r = x - j ln 2 in [-ln 2 / 2, ln 2 / 2]: ln 2 in two parts, the first with
# trailing zero bits so that j times it is exact (Cody and Waite 1980, "Software manual for the
# elementary functions", ch. 6), and exp(r) by its Taylor series to r^13 (the first omitted term,
# r^14 / 14!, below 4.1e-18 of the result)
_LN2_HI, _LN2_LO = 6.93147180369123816490e-01, 1.90821492927058770002e-10
_EXP_LIMIT = 708.0  # |x| beyond: 2^j leaves the normal range; those few take the library's exp


@njit(cache=True, error_model="numpy")
def exps(x: np.ndarray, shift: float, out: np.ndarray) -> None:
    """``out`` = exp(``x`` - ``shift``), element by element, within 3 ulp (relative 7e-16) of the
    library's exp, in a loop numba vectorises: the reduction above and 2^j built from its bits
    (an int64 array viewed as float64); arguments beyond +-708 go to ``math.exp`` afterwards."""
    n = x.shape[0]
    powers = np.empty(n, dtype=np.int64)
    beyond = False
    for k in range(n):
        v = x[k] - shift
        beyond |= abs(v) > _EXP_LIMIT
        v = min(max(v, -_EXP_LIMIT), _EXP_LIMIT)
        j = math.floor(v * (1.0 / math.log(2.0)) + 0.5)
        r = (v - j * _LN2_HI) - j * _LN2_LO
        p = 1.0 / 6227020800.0
        p = p * r + 1.0 / 479001600.0
        p = p * r + 1.0 / 39916800.0
        p = p * r + 1.0 / 3628800.0
        p = p * r + 1.0 / 362880.0
        p = p * r + 1.0 / 40320.0
        p = p * r + 1.0 / 5040.0
        p = p * r + 1.0 / 720.0
        p = p * r + 1.0 / 120.0
        p = p * r + 1.0 / 24.0
        p = p * r + 1.0 / 6.0
        p = p * r + 0.5
        p = p * r + 1.0
        out[k] = p * r + 1.0
        powers[k] = (int(j) + 1023) << 52
    scale = powers.view(np.float64)
    for k in range(n):
        out[k] *= scale[k]
    if beyond:
        for k in range(n):
            if abs(x[k] - shift) > _EXP_LIMIT:
                out[k] = math.exp(x[k] - shift)


@njit(cache=True, error_model="numpy", fastmath=_SUMS)
def reweigh(weights: np.ndarray, log_l: np.ndarray) -> float:
    """``weights`` times the likelihoods exp(``log_l``), scaled to sum 1; returns their effective
    sample size 1 / sum w^2. Through the largest log-likelihood, and when the products underflow
    (the weight sits where the sightings say the vehicle is not) through the weights' logarithms."""
    n = weights.shape[0]
    top = np.max(log_l)
    product = np.empty(n)
    exps(log_l, top, product)
    total = 0.0
    for k in range(n):
        product[k] *= weights[k]
        total += product[k]
    if not total > 1e-250:
        for k in range(n):
            log_l[k] += math.log(max(weights[k], 1e-300))
        exps(log_l, np.max(log_l), product)
        total = 0.0
        for k in range(n):
            total += product[k]
    square, scale = 0.0, 1.0 / total
    for k in range(n):
        weights[k] = product[k] * scale
        square += weights[k] * weights[k]
    return 1.0 / square


@njit(cache=True, error_model="numpy")
def resample(cloud: np.ndarray, weights: np.ndarray, start: float, out: np.ndarray) -> None:
    """Systematic (low-variance) resampling into ``out``: the n positions (start + i) / n, ``start``
    uniform in [0, 1), each picks the particle whose cumulative weight first reaches it (the last
    particle if rounding leaves the total short of a position). Without a data-dependent branch
    (walking the positions and the weights side by side mispredicts about one branch a particle,
    more than the rest of the work): particle k's cumulative weight C_k reaches the positions
    i <= n C_k - start, so position i picks the number of particles with fewer, floor(n C_k -
    start) + 1 <= i, counted by a scatter of those counts and a running sum."""
    m, n = cloud.shape
    below = np.zeros(n + 1, dtype=np.int64)  # below[i]: particles whose reach ends at position i
    cum = 0.0
    for k in range(n - 1):
        cum += weights[k]
        reach = min(max(math.floor(n * cum - start) + 1.0, 0.0), float(n))
        below[int(reach)] += 1
    pick = np.empty(n, dtype=np.int64)
    count = 0
    for i in range(n):
        count += below[i]
        pick[i] = count
    for j in range(m):
        for i in range(n):
            out[j, i] = cloud[j, pick[i]]


@njit(cache=True, error_model="numpy", fastmath=_SUMS)
def cloud_estimate(cloud: np.ndarray, weights: np.ndarray, mean: np.ndarray, cov: np.ndarray) -> None:
    """The cloud's weighted mean pose into ``mean`` (3,) (the heading's circular mean) and its
    weighted covariance about it into ``cov`` (3, 3) (heading differences wrapped)."""
    sx = sy = ss = sc = 0.0
    for k in range(cloud.shape[1]):
        w = weights[k]
        sx += w * cloud[0, k]
        sy += w * cloud[1, k]
        sc += w * cloud[3, k]
        ss += w * cloud[4, k]
    theta = math.atan2(ss, sc)
    mean[0], mean[1], mean[2] = sx, sy, theta
    # sums in locals: written into cov in the loop, they would be stored and reloaded every pass
    # (cov might alias the cloud as far as the compiler knows), which keeps it from vectorising
    xx = xy = xt = yy = yt = tt = 0.0
    for k in range(cloud.shape[1]):
        w = weights[k]
        ex, ey, et = cloud[0, k] - sx, cloud[1, k] - sy, wrap(cloud[2, k] - theta)
        xx += w * ex * ex
        xy += w * ex * ey
        xt += w * ex * et
        yy += w * ey * ey
        yt += w * ey * et
        tt += w * et * et
    cov[0, 0], cov[0, 1], cov[0, 2], cov[1, 1], cov[1, 2], cov[2, 2] = xx, xy, xt, yy, yt, tt
    cov[1, 0], cov[2, 0], cov[2, 1] = cov[0, 1], cov[0, 2], cov[1, 2]


@njit(cache=True, error_model="numpy")
def regularise(cloud: np.ndarray, low: np.ndarray, s: np.ndarray, zx: np.ndarray, zf: np.ndarray) -> None:
    """Each particle moved by its own draw L z of the regularisation kernel (L L^T its covariance;
    one deviate per non-zero column of L)."""
    e = gaussian_draws(low, cloud.shape[1], s, zx, zf)
    small = True
    for k in range(cloud.shape[1]):
        cloud[0, k] += e[0, k]
        cloud[1, k] += e[1, k]
        small &= _turn(cloud, k, e[2, k])
    if not small:
        _recompute_turns(cloud, e[2])


@njit(cache=True)
def correct(cloud: np.ndarray, weights: np.ndarray, seen: np.ndarray, r_inv: np.ndarray, bandwidth: float,
            s: np.ndarray, zx: np.ndarray, zf: np.ndarray, scratch: np.ndarray) -> bool:
    """The measurement half of a step: :func:`weigh` by each row of ``seen`` (m, 4: landmark x, y,
    range, bearing), :func:`reweigh`, and when the effective sample size falls below n / 2
    :func:`resample` (``scratch`` the cloud's shape, its work space) and :func:`regularise` by
    ``bandwidth`` (h) times the factor of the cloud's covariance before resampling. Returns whether
    it resampled."""
    n = cloud.shape[1]
    if seen.shape[0] == 0:
        return False
    log_l = np.zeros(n)
    for i in range(seen.shape[0]):
        weigh(cloud, log_l, seen[i, 0], seen[i, 1], seen[i, 2], seen[i, 3], r_inv)
    if reweigh(weights, log_l) >= 0.5 * n:
        return False
    mean, cov = np.empty(3), np.empty((3, 3))
    cloud_estimate(cloud, weights, mean, cov)
    resample(cloud, weights, uniform(s), scratch)
    cloud[:] = scratch
    weights[:] = 1.0 / n
    if bandwidth > 0.0:
        regularise(cloud, psd_factor(bandwidth * bandwidth * cov), s, zx, zf)
    return True


@njit(cache=True)
def particle_step(cloud: np.ndarray, weights: np.ndarray, u: np.ndarray, u_cov: np.ndarray, seen: np.ndarray,
                  r_inv: np.ndarray, bandwidth: float, s: np.ndarray, zx: np.ndarray, zf: np.ndarray,
                  scratch: np.ndarray, mean: np.ndarray, cov: np.ndarray) -> bool:
    """One step of the regularised particle filter: :func:`move` by the odometry ``u`` (3,) of
    covariance ``u_cov`` (3, 3), :func:`correct` by the sightings ``seen``, and the cloud's
    estimate into ``mean`` (3,) and ``cov`` (3, 3). Returns whether it resampled."""
    move(cloud, u, psd_factor(u_cov), s, zx, zf)
    resampled = correct(cloud, weights, seen, r_inv, bandwidth, s, zx, zf, scratch)
    cloud_estimate(cloud, weights, mean, cov)
    return resampled
