"""numba kernels of the robot's acceleration model and its braking trajectory (Bruce 2006 §5.1, §5.3):
what a velocity command can reach in one period, and where a robot that holds a command for a period
and then brakes will be. Shared by motion control, the navigators and the safety search, so public.

Units: metres, seconds. Plain-numpy references live in :mod:`cmdragons.control._reference`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

N_SEG = 4  # segments of a braking trajectory: reaching the command, holding it to the period's end, braking, rest


class Limits(NamedTuple):
    """The robot's limits, by name (configs/control.yaml ``motion``)."""

    vmax: float  # m/s
    accel: float  # m/s^2 speeding up or turning the velocity
    brake: float  # m/s^2 slowing down
    omega_max: float  # rad/s
    alpha_max: float  # rad/s^2


# --- the robot's acceleration model, Bruce 2006 §5.1 ------------------------------------------------
@njit(cache=True)
def clip_accel(vx: float, vy: float, ax: float, ay: float, accel: float, brake: float) -> tuple[float, float]:
    """Scale the acceleration (ax, ay) into A(v): a disc of radius ``accel`` on the half that does
    not oppose the velocity; on the braking half an ellipse with semi-axis ``brake`` against v and
    ``accel`` across it (Bruce 2006 fig. 5.2). The direction is kept."""
    speed = math.hypot(vx, vy)
    mag = math.hypot(ax, ay)
    if mag <= 0.0:
        return 0.0, 0.0
    along = (ax * vx + ay * vy) / speed if speed > 1e-9 else 0.0
    if along >= 0.0:
        k = mag / accel if accel > 0.0 else math.inf
    else:
        across2 = max(mag * mag - along * along, 0.0)
        ka = along / brake if brake > 0.0 else math.inf
        kc2 = across2 / (accel * accel) if accel > 0.0 else (0.0 if across2 == 0.0 else math.inf)
        k = math.sqrt(ka * ka + kc2)
    if k <= 1.0:
        return ax, ay
    if not math.isfinite(k):
        return 0.0, 0.0
    return ax / k, ay / k


@njit(cache=True)
def limit_velocity(
    v0x: float, v0y: float, vx: float, vy: float, vmax: float, accel: float, brake: float, period: float
) -> tuple[float, float]:
    """The velocity command nearest in direction to (vx, vy) that keeps within the speed limit (or
    does not speed up past it when the robot is already faster) and reaches it from (v0x, v0y) within
    A(v) in one ``period``."""
    speed = math.hypot(vx, vy)
    cap = max(vmax, math.hypot(v0x, v0y))
    if speed > cap:
        vx, vy = vx * cap / speed, vy * cap / speed
    ax, ay = clip_accel(v0x, v0y, (vx - v0x) / period, (vy - v0y) / period, accel, brake)
    return v0x + ax * period, v0y + ay * period


@njit(cache=True)
def feasible(vx: float, vy: float, ax: float, ay: float, lim: Limits, dt: float) -> tuple[float, float]:
    """The acceleration (ax, ay) held to A(v) and the speed limit for one period ``dt``."""
    cx, cy = limit_velocity(vx, vy, vx + ax * dt, vy + ay * dt, lim.vmax, lim.accel, lim.brake, dt)
    return (cx - vx) / dt, (cy - vy) / dt


# --- the robot's braking trajectory (Bruce 2006 §5.1, §5.3): where it will be ---------------------------
@njit(cache=True)
def _put(tr: np.ndarray, k: int, t0: float, t1: float, px: float, py: float, vx: float, vy: float,
         ax: float, ay: float) -> tuple[float, float, float, float]:
    # write segment k and return the position and velocity at its end
    tr[k, 0], tr[k, 1], tr[k, 2], tr[k, 3], tr[k, 4], tr[k, 5], tr[k, 6], tr[k, 7] = t0, t1, px, py, vx, vy, ax, ay
    h = t1 - t0
    return px + vx * h + 0.5 * ax * h * h, py + vy * h + 0.5 * ay * h * h, vx + ax * h, vy + ay * h


@njit(cache=True)
def trajectory(
    px: float, py: float, vx: float, vy: float, ax: float, ay: float, dt: float, accel: float, brake: float
) -> np.ndarray:
    """Segments (N_SEG, 8) of the command v + a dt held for one period ``dt``, then braking at
    ``brake`` to rest. The motors reach a commanded velocity as fast as they can (at ``brake`` when
    it slows the robot against its motion, else at ``accel``) and then hold it, as the simulator's
    motor model does; the stop command (a = -v / dt) thus brakes at full strength."""
    tr = np.zeros((N_SEG, 8))
    cx, cy = vx + ax * dt, vy + ay * dt
    dvx, dvy = cx - vx, cy - vy
    dv = math.hypot(dvx, dvy)
    slowing = dvx * vx + dvy * vy < 0.0 and cx * cx + cy * cy < vx * vx + vy * vy
    rate = brake if slowing else accel
    t_reach = min(dv / rate, dt) if rate > 0.0 and dv > 0.0 else 0.0
    ux, uy = (dvx / dv * rate, dvy / dv * rate) if dv > 0.0 and rate > 0.0 else (0.0, 0.0)
    qx, qy, wx, wy = _put(tr, 0, 0.0, t_reach, px, py, vx, vy, ux, uy)
    qx, qy, wx, wy = _put(tr, 1, t_reach, dt, qx, qy, wx, wy, 0.0, 0.0)
    w = math.hypot(wx, wy)
    t_brake = w / brake if brake > 0.0 else 0.0
    bx, by = (-brake * wx / w, -brake * wy / w) if w > 0.0 else (0.0, 0.0)
    qx, qy, _, _ = _put(tr, 2, dt, dt + t_brake, qx, qy, wx, wy, bx, by)
    _put(tr, 3, dt + t_brake, math.inf, qx, qy, 0.0, 0.0, 0.0, 0.0)
    return tr


@njit(cache=True)
def stop_accel(vx: float, vy: float, dt: float) -> tuple[float, float]:
    """The acceleration that names the stop command (velocity zero): the motors brake at full
    strength until the robot rests (see :func:`trajectory`)."""
    return -vx / dt, -vy / dt


@njit(cache=True)
def seg_at(tr: np.ndarray, k: int, t: float) -> tuple[float, float, float, float]:
    """Position and velocity of segment k of a trajectory at absolute time t (inside the segment)."""
    h = t - tr[k, 0]
    return (tr[k, 2] + tr[k, 4] * h + 0.5 * tr[k, 6] * h * h, tr[k, 3] + tr[k, 5] * h + 0.5 * tr[k, 7] * h * h,
            tr[k, 4] + tr[k, 6] * h, tr[k, 5] + tr[k, 7] * h)


@njit(cache=True)
def trajectory_state(tr: np.ndarray, t: float) -> tuple[float, float, float, float]:
    """Position and velocity (x, y, vx, vy) of a trajectory at time ``t`` >= 0 (at rest after it)."""
    for k in range(N_SEG - 1):
        if t <= tr[k, 1]:
            return seg_at(tr, k, max(t, tr[k, 0]))
    return tr[N_SEG - 1, 2], tr[N_SEG - 1, 3], 0.0, 0.0
