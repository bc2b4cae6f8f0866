"""numba kernels of escape and evade (lecture notes 003): the escape vector away from moving objects
near the robot, and the evade vector off their predicted paths. Field frame, metres, seconds."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons.angles import wrap_angle


class EvadeConfig(NamedTuple):
    """The escape and evade behaviours' numbers, by name (configs/team.yaml ``escape_evade``)."""

    r_max: float  # m: escape's area of influence around a moving object
    v_max: float  # m/s: object speed that counts fully
    dx_max: float  # m: evade's reach along an object's predicted path, d^max_X
    dy_max: float  # m: evade's reach across it, d^max_Y (grows with the variance and dX)
    min_speed: float  # m/s: objects slower than this do not move


@njit(cache=True)
def _saturate(sx: float, sy: float) -> tuple[float, float]:
    # F = S if |S| <= 1 else S / |S| (seed 003, (5.2) and (5.8))
    n = math.hypot(sx, sy)
    if n > 1.0:
        return sx / n, sy / n
    return sx, sy


@njit(cache=True)
def escape_vector(px: float, py: float, objects: np.ndarray, cfg: EvadeConfig) -> tuple[float, float]:
    """The escape behaviour's F_RO (seed 003 §5.1.1, (5.2)-(5.4)): for each moving object (rows x, y,
    vx, vy, ...) a vector from it toward the robot at (px, py), of length (r_max - d)+ / r_max times
    |v| / v_max, summed and held to length 1."""
    sx, sy = 0.0, 0.0
    for j in range(objects.shape[0]):
        dx, dy = px - objects[j, 0], py - objects[j, 1]
        d = math.hypot(dx, dy)
        v = math.hypot(objects[j, 2], objects[j, 3])
        if d >= cfg.r_max or d == 0.0 or v < cfg.min_speed:
            continue
        f = (cfg.r_max - d) / cfg.r_max * min(v / cfg.v_max, 1.0)
        sx += f * dx / d
        sy += f * dy / d
    return _saturate(sx, sy)


@njit(cache=True)
def path_offset(px: float, py: float, ox: float, oy: float, vx: float, vy: float, omega: float) -> tuple[float, float, float, float]:  # noqa: E501
    """The robot at (px, py) relative to the predicted path of an object at (ox, oy) moving at (vx,
    vy) and turning at ``omega`` (rad/s; 0: straight): (dX along the path ahead of the object, m,
    < 0 behind it; dY across it, m, >= 0; the unit vector across the path toward the robot)."""
    v = math.hypot(vx, vy)
    ux, uy = vx / v, vy / v
    rx, ry = px - ox, py - oy
    kappa = omega / v
    if abs(kappa) < 1e-6:
        dx = rx * ux + ry * uy
        cross = ux * ry - uy * rx
        sgn = 1.0 if cross >= 0.0 else -1.0
        return dx, abs(cross), -uy * sgn, ux * sgn
    rad = 1.0 / kappa  # signed: the centre lies to the left for omega > 0
    cx, cy = ox - uy * rad, oy + ux * rad
    qx, qy = px - cx, py - cy
    q = math.hypot(qx, qy)
    if q == 0.0:
        return 0.0, abs(rad), ux, uy
    # the arc length from the object to the robot's foot point, in the direction of motion
    a0 = math.atan2(oy - cy, ox - cx)
    a1 = math.atan2(qy, qx)
    da = a1 - a0
    da = wrap_angle(da)
    if kappa < 0.0:
        da = -da
    dist = q - abs(rad)
    sgn = 1.0 if dist >= 0.0 else -1.0
    return da * abs(rad), abs(dist), sgn * qx / q, sgn * qy / q


@njit(cache=True)
def evade_vector(px: float, py: float, objects: np.ndarray, cfg: EvadeConfig) -> tuple[float, float]:
    """The evade behaviour's F_RO (seed 003 §5.1.2, (5.8)-(5.15)): for each moving object (rows x, y,
    vx, vy, omega, V_X, V_Y: its movement model and that model's variance), a vector across its
    predicted path toward the robot, of length f(d, V) |v| / v_max with
    f = (1 - min(dX, D_X) / D_X) (1 - min(dY, D_Y) / D_Y), D_X = dx_max,
    D_Y = dy_max (V_Y + 1) (V_Y dX + 1); the robot behind the object (dX < 0) feels nothing."""
    sx, sy = 0.0, 0.0
    for j in range(objects.shape[0]):
        v = math.hypot(objects[j, 2], objects[j, 3])
        if v < cfg.min_speed:
            continue
        dx, dy, nx, ny = path_offset(px, py, objects[j, 0], objects[j, 1], objects[j, 2], objects[j, 3],
                                     objects[j, 4])
        if dx < 0.0:
            continue
        vy_var = objects[j, 6]
        dmx = cfg.dx_max
        dmy = cfg.dy_max * (vy_var + 1.0) * (vy_var * dx + 1.0)
        f = (1.0 - min(dx, dmx) / dmx) * (1.0 - min(dy, dmy) / dmy)
        k = f * min(v / cfg.v_max, 1.0)
        sx += k * nx
        sy += k * ny
    return _saturate(sx, sy)
