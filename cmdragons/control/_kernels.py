"""numba kernels of motion control: the time-optimal 1D trapezoidal profile, its 2D split, the
heading's profile and the frame's motion commands (Bruce 2006 appendix B.4); the robot's
acceleration model and braking trajectory, which navigation and safety share, are
:mod:`cmdragons.control.acceleration`'s.

Units: metres, seconds, radians. A 1D problem is "move a distance ``d`` starting at velocity ``v0``
and arrive with velocity ``vt``" under a speed limit ``vmax``, an acceleration ``a`` while the speed
grows and a deceleration ``b`` while it shrinks. The optimal profile is bang-bang: a ramp from ``v0``
to a peak velocity ``vp``, a cruise at ``vp``, a ramp from ``vp`` to ``vt`` (a ramp through zero
velocity brakes at ``b`` first and speeds up at ``a`` after). A profile is stored as up to
``N_PHASES`` phases ``(duration_s, acceleration_m_s2)`` starting at ``v0``.

Plain-numpy references of these kernels live in :mod:`cmdragons.control._reference`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmdragons.angles import wrap_angle
from cmdragons.control.acceleration import limit_velocity
from cmdragons.sorting import sort_small

N_PHASES = 5  # ramp through zero (2) + cruise (1) + ramp through zero (2)
_EPS = 1e-12


@njit(cache=True)
def _ramp_same_sign(u: float, w: float, a: float, b: float) -> tuple[float, float]:
    # u and w on the same side of zero: one constant acceleration
    au, aw = abs(u), abs(w)
    if aw >= au:
        return (aw - au) / a, (w * aw - u * au) / (2.0 * a)
    return (au - aw) / b, (u * au - w * aw) / (2.0 * b)


@njit(cache=True)
def ramp(u: float, w: float, a: float, b: float) -> tuple[float, float]:
    """Time (s) and signed distance (m) to change velocity from ``u`` to ``w``: speeding up at ``a``,
    slowing down at ``b``, through zero (brake, then speed up) when the sign changes."""
    if u * w >= 0.0:
        return _ramp_same_sign(u, w, a, b)
    t1, s1 = _ramp_same_sign(u, 0.0, a, b)
    t2, s2 = _ramp_same_sign(0.0, w, a, b)
    return t1 + t2, s1 + s2


@njit(cache=True)
def _peak_time(d: float, v0: float, vt: float, vp: float, a: float, b: float) -> float:
    """Total time of the profile through peak ``vp`` (inf when the cruise would run backwards)."""
    t1, s1 = ramp(v0, vp, a, b)
    t2, s2 = ramp(vp, vt, a, b)
    cruise = d - s1 - s2
    tol = 1e-9 * (1.0 + abs(d))
    if abs(cruise) <= tol:
        return t1 + t2
    if vp == 0.0 or cruise * vp < 0.0:
        return math.inf
    return t1 + t2 + cruise / vp


@njit(cache=True)
def best_peak(d: float, v0: float, vt: float, vmax: float, a: float, b: float) -> tuple[float, float]:
    """The peak velocity of the time-optimal profile and its total time ``(vp, T)``.

    The distance covered by the two ramps, f(vp), is ``alpha * vp**2 + beta`` between the
    breakpoints {-vmax, 0, v0, vt, vmax}, and the total time is stationary exactly where
    f(vp) = d, so the optimum is a breakpoint or a root of f(vp) = d in one of the pieces."""
    if vmax <= _EPS or a <= _EPS or b <= _EPS:
        done = abs(d) <= 1e-12 and abs(v0 - vt) <= 1e-12
        return v0, (0.0 if done else math.inf)
    vt = min(max(vt, -vmax), vmax)
    pts = np.empty(5)
    pts[0], pts[1], pts[2] = -vmax, 0.0, vmax
    pts[3] = min(max(v0, -vmax), vmax)
    pts[4] = vt
    sort_small(pts, 5)
    best_v, best_t = 0.0, math.inf
    for i in range(5):
        t = _peak_time(d, v0, vt, pts[i], a, b)
        if t < best_t:
            best_v, best_t = pts[i], t
    for i in range(4):
        lo, hi = pts[i], pts[i + 1]
        if hi - lo <= _EPS:
            continue
        flo = ramp(v0, lo, a, b)[1] + ramp(lo, vt, a, b)[1]
        fhi = ramp(v0, hi, a, b)[1] + ramp(hi, vt, a, b)[1]
        den = hi * hi - lo * lo
        if abs(den) <= _EPS:
            continue
        alpha = (fhi - flo) / den
        if abs(alpha) <= _EPS:
            continue
        sq = (d - (flo - alpha * lo * lo)) / alpha
        if sq < 0.0:
            continue
        vp = math.sqrt(sq) if lo + hi > 0.0 else -math.sqrt(sq)
        if lo <= vp <= hi:
            t = _peak_time(d, v0, vt, vp, a, b)
            if t < best_t:
                best_v, best_t = vp, t
    return best_v, best_t


@njit(cache=True)
def _put_phase(ph: np.ndarray, k: int, u: float, w: float, a: float, b: float) -> int:
    # append one constant-acceleration phase u -> w (same sign); zero-length phases are skipped
    t = _ramp_same_sign(u, w, a, b)[0]
    if t > 0.0:
        ph[k, 0] = t
        ph[k, 1] = (w - u) / t
        return k + 1
    return k


@njit(cache=True)
def _put_ramp(ph: np.ndarray, k: int, u: float, w: float, a: float, b: float) -> int:
    # append the phases of a ramp u -> w: two when it passes through zero (no recursion: numba's
    # cache does not like recursive kernels)
    if u * w < 0.0:
        k = _put_phase(ph, k, u, 0.0, a, b)
        return _put_phase(ph, k, 0.0, w, a, b)
    return _put_phase(ph, k, u, w, a, b)


@njit(cache=True)
def profile_1d(d: float, v0: float, vt: float, vmax: float, a: float, b: float) -> tuple[np.ndarray, float]:
    """The time-optimal profile: phases (N_PHASES, 2) of (duration_s, acceleration) from ``v0``
    (unused phases have duration 0) and the total time (inf when the limits are zero and the robot
    must still move)."""
    ph = np.zeros((N_PHASES, 2))
    vp, total = best_peak(d, v0, vt, vmax, a, b)
    if not math.isfinite(total) or total <= 0.0:
        return ph, total
    vtc = min(max(vt, -vmax), vmax)
    k = _put_ramp(ph, 0, v0, vp, a, b)
    t1, s1 = ramp(v0, vp, a, b)
    t2, s2 = ramp(vp, vtc, a, b)
    cruise = total - t1 - t2
    if cruise > 0.0:
        ph[k, 0] = cruise
        k += 1
    _put_ramp(ph, k, vp, vtc, a, b)
    return ph, total


@njit(cache=True)
def phases_state(ph: np.ndarray, v0: float, t: float) -> tuple[float, float]:
    """Displacement (m) and velocity (m/s) after ``t`` seconds along the phases; after the last
    phase the velocity stays constant."""
    x, v, left = 0.0, v0, t
    for k in range(ph.shape[0]):
        dt = min(ph[k, 0], left)
        if dt <= 0.0:
            continue
        x += v * dt + 0.5 * ph[k, 1] * dt * dt
        v += ph[k, 1] * dt
        left -= dt
    return x + v * max(left, 0.0), v


@njit(cache=True)
def split_2d(
    dx: float, dy: float, v0x: float, v0y: float, vtx: float, vty: float,
    vmax: float, a: float, b: float, iterations: int,
) -> tuple[float, float, float]:
    """Split the limits between x and y (x gets cos(theta), y sin(theta) of every limit) so that both
    axes arrive together; binary search on theta in [0, pi/2]. Returns (theta, Tx, Ty)."""
    lo, hi = 0.0, 0.5 * math.pi
    theta, tx, ty = 0.25 * math.pi, 0.0, 0.0
    for _ in range(iterations):
        theta = 0.5 * (lo + hi)
        c, s = math.cos(theta), math.sin(theta)
        tx = best_peak(dx, v0x, vtx, vmax * c, a * c, b * c)[1]
        ty = best_peak(dy, v0y, vty, vmax * s, a * s, b * s)[1]
        if tx < ty:
            lo = theta  # x is early: give y more of the budget
        else:
            hi = theta
    return theta, tx, ty


@njit(cache=True)
def command_2d(
    dx: float, dy: float, v0x: float, v0y: float, vtx: float, vty: float,
    vmax: float, a: float, b: float, period: float, iterations: int,
) -> tuple[float, float, float]:
    """Velocity (vx, vy) at the end of the next control period along the 2D profile, and the
    arrival time (max of the axes)."""
    theta, tx, ty = split_2d(dx, dy, v0x, v0y, vtx, vty, vmax, a, b, iterations)
    c, s = math.cos(theta), math.sin(theta)
    phx, _ = profile_1d(dx, v0x, vtx, vmax * c, a * c, b * c)
    phy, _ = profile_1d(dy, v0y, vty, vmax * s, a * s, b * s)
    return phases_state(phx, v0x, period)[1], phases_state(phy, v0y, period)[1], max(tx, ty)


@njit(cache=True)
def heading_command(theta: float, omega: float, target_theta: float, wmax: float, alpha: float,
                    period: float) -> float:
    """The turn rate (rad/s) one ``period`` ahead on the heading's trapezoid from ``theta`` (rad),
    turning at ``omega``, to rest at ``target_theta``, under ``wmax`` and the angular ``alpha``."""
    dth: float = wrap_angle(target_theta - theta)
    ph, _ = profile_1d(dth, omega, 0.0, wmax, alpha, alpha)
    return phases_state(ph, omega, period)[1]


@njit(cache=True)
def motion_commands(
    states: np.ndarray, targets: np.ndarray, vmax: float, accel: float, brake: float, wmax: float, alpha: float,
    period: float, iterations: int,
) -> np.ndarray:
    """Commands (n, 3) vx, vy, omega for every robot: the 2D trapezoid toward the target position and
    velocity, the heading's trapezoid toward the target heading, both then held to the limits.

    ``states`` (n, 6): x, y, theta, vx, vy, omega; ``targets`` (n, 5): x, y, vx, vy, theta; the limits
    by name as in :class:`~cmdragons.control.acceleration.Limits` (scalars: the kernel runs once per
    robot and frame, and numba's dispatch is quickest on them)."""
    out = np.empty((states.shape[0], 3))
    for i in range(states.shape[0]):
        x, y, th, vx, vy, w = states[i, 0], states[i, 1], states[i, 2], states[i, 3], states[i, 4], states[i, 5]
        cx, cy, _ = command_2d(targets[i, 0] - x, targets[i, 1] - y, vx, vy, targets[i, 2], targets[i, 3],
                               vmax, accel, brake, period, iterations)
        out[i, 0], out[i, 1] = limit_velocity(vx, vy, cx, cy, vmax, accel, brake, period)
        out[i, 2] = heading_command(th, w, targets[i, 4], wmax, alpha, period)
    return out
