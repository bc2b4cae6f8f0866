"""numba kernels the reactive navigators share (lecture notes 001 and 003): marching a ray through
the C-space, the ranges of a ring of rays, and the brake guard that keeps a command able to stop
short of the nearest obstacle. Field frame, metres, seconds."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmdragons.planning.collision import away, clearance, obstacle_clearance

# Every query below is about a robot centre in the compiled world of the robot's radius (the
# C-space) unless it says otherwise; ``radius`` where a method needs the real obstacles' cores.


@njit(cache=True)
def wall(inner: np.ndarray, side: int, px: float, py: float) -> tuple[float, float, float]:
    # wall ``side`` (0 x0, 1 x1, 2 y0, 3 y1) of the C-space box: its clearance and the unit normal away from it
    if side == 0:
        return px - inner[0], 1.0, 0.0
    if side == 1:
        return inner[2] - px, -1.0, 0.0
    if side == 2:
        return py - inner[1], 0.0, 1.0
    return inner[3] - py, 0.0, -1.0


@njit(cache=True)
def march(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, theta: float, curvature: float, length: float,
    threshold: float, tol: float,
) -> float:
    """How far (m, along the arc) the robot's centre gets from (px, py) heading ``theta`` on an arc
    of ``curvature`` (1/m; 0 a straight ray) before its clearance falls to ``threshold``, at most
    ``length``. Sphere tracing: the clearance is 1-Lipschitz and an arc is never shorter than its
    chord, so a step of the clearance left over ``threshold`` never crosses it (within ``tol``)."""
    s = 0.0
    while s < length:
        if curvature == 0.0:
            x, y = px + s * math.cos(theta), py + s * math.sin(theta)
        else:
            a = theta + curvature * s
            x = px + (math.sin(a) - math.sin(theta)) / curvature
            y = py - (math.cos(a) - math.cos(theta)) / curvature
        c = clearance(obs, inner, x, y) - threshold
        if c <= 0.0:
            return s
        s += max(c, tol)
    return length


@njit(cache=True)
def ranges(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, angles: np.ndarray, length: float, threshold: float,
    tol: float,
) -> np.ndarray:
    """A simulated range sensor: :func:`march` along straight rays at ``angles`` (rad), at most
    ``length`` (the sensor's range), until the clearance falls to ``threshold`` (0: contact)."""
    out = np.empty(angles.shape[0])
    for i in range(angles.shape[0]):
        out[i] = march(obs, inner, px, py, angles[i], 0.0, length, threshold, tol)
    return out


@njit(cache=True)
def _stop_speed(c: float, margin: float, decel: float, dt: float) -> float:
    # the speed toward an obstacle at clearance c that still stops margin short of it, braking at
    # decel from the end of one period of dt at that speed
    room = max(c - margin, 0.0)
    return max(math.sqrt(decel * decel * dt * dt + 2.0 * decel * room) - decel * dt, 0.0)


@njit(cache=True)
def brake_guard(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, wx: float, wy: float, margin: float, decel: float,
    dt: float,
) -> tuple[float, float]:
    """The velocity (wx, wy) with its component toward each obstacle and wall cut to the speed that
    still stops ``margin`` short of it (:func:`_stop_speed`), obstacle after obstacle; the
    components sideways and away stay."""
    for side in range(4):
        c, ax, ay = wall(inner, side, px, py)
        closing = -(wx * ax + wy * ay)
        cap = _stop_speed(c, margin, decel, dt)
        if closing > cap:
            wx, wy = wx + (closing - cap) * ax, wy + (closing - cap) * ay
    for j in range(obs.shape[0]):
        c = obstacle_clearance(obs, j, px, py)
        ax, ay = away(obs, j, px, py)
        closing = -(wx * ax + wy * ay)
        cap = _stop_speed(c, margin, decel, dt)
        if closing > cap:
            wx, wy = wx + (closing - cap) * ax, wy + (closing - cap) * ay
    return wx, wy
