"""numba kernels of the dynamic window (Bruce 2006 §5.2, after Fox, Burgard and Thrun 1997), for a
holonomic robot: the velocities reachable in one period, each admissible when its braking trajectory
(:mod:`cmdragons.control.acceleration`) keeps clear of the compiled collision world
(:mod:`cmdragons.planning.collision`: ``obs``, ``inner``, grown by the robot's radius, the moving
obstacles where they stand now). Field frame, metres, seconds. Plain-numpy reference:
:mod:`cmdragons.navigation._dynamic_window_reference`."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons.control.acceleration import N_SEG, Limits, clip_accel, feasible, trajectory
from cmdragons.planning.collision import clearance
from cmdragons.safety.static_check import static_hits


class WindowConfig(NamedTuple):
    """The window's numbers, by name (configs/team.yaml ``dynamic_window``)."""

    dt: float  # control period, s: a velocity is reached within it
    margin: float  # m kept from every obstacle
    step: float  # m, sample spacing of the admissibility check
    clearance_weight: float  # m/s of score per metre of clearance (1/s)
    clearance_cap: float  # m: clearance beyond this earns nothing


@njit(cache=True)
def window_velocity(
    vx: float, vy: float, dx: float, dy: float, r: int, window: np.ndarray, lim: Limits, dt: float
) -> tuple[float, float]:
    """Candidate ``r`` of the window for a robot at velocity (vx, vy): r = 0 the desired velocity
    (dx, dy) held to the limits, r >= 1 the unit-disc point ``window[r - 1]`` mapped into the
    velocities A(v) reaches in one period."""
    if r == 0:
        ax, ay = feasible(vx, vy, (dx - vx) / dt, (dy - vy) / dt, lim, dt)
    else:
        ux, uy = window[r - 1, 0], window[r - 1, 1]
        un = math.hypot(ux, uy)
        ax, ay = 0.0, 0.0
        if un > 0.0:
            ex, ey = clip_accel(vx, vy, ux * 1e6 / un, uy * 1e6 / un, lim.accel, lim.brake)
            ax, ay = feasible(vx, vy, ex * un, ey * un, lim, dt)
    return vx + ax * dt, vy + ay * dt


@njit(cache=True)
def dynamic_window(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, vx: float, vy: float, dx: float, dy: float,
    window: np.ndarray, lim: Limits, cfg: WindowConfig, limit: int,
) -> tuple[float, float, int, int]:
    """The dynamic window for one robot at (px, py) moving at (vx, vy) that wants (dx, dy).

    A candidate velocity (:func:`window_velocity`, the desired one first) is admissible when the
    robot, moving at it for one period and then braking at full strength, keeps ``cfg.margin`` from
    every obstacle as it stands now (a start already closer only fails deeper). Among the admissible
    ones it takes the one maximising ``-|v - desired| + clearance_weight * min(clearance at rest,
    clearance_cap)``. At most ``limit`` candidates are evaluated (the work budget).

    Returns (vx, vy, evaluated, chosen): the velocity, the candidates evaluated, and the chosen
    candidate's index (-1: none admissible, the velocity is the stop)."""
    best, best_score = -1, -math.inf
    bvx, bvy = 0.0, 0.0
    n = min(window.shape[0] + 1, limit)
    for r in range(n):
        cx, cy = window_velocity(vx, vy, dx, dy, r, window, lim, cfg.dt)
        tr = trajectory(px, py, cx, cy, 0.0, 0.0, cfg.dt, lim.accel, lim.brake)
        if static_hits(tr, obs, inner, cfg.margin, cfg.step):
            continue
        rest = clearance(obs, inner, tr[N_SEG - 1, 2], tr[N_SEG - 1, 3])
        score = -math.hypot(cx - dx, cy - dy) + cfg.clearance_weight * min(max(rest, 0.0), cfg.clearance_cap)
        if score > best_score:
            best, best_score, bvx, bvy = r, score, cx, cy
    return bvx, bvy, n, best
