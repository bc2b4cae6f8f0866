"""numba kernels of the vector field histogram (VFH, VFH+; lecture notes 001): the polar histogram of
obstacle density around the robot and VFH+'s turning limits. Field frame, metres, radians."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons.angles import wrap_angle
from cmdragons.planning.collision import clearance


class HistogramConfig(NamedTuple):
    """The vector field histogram's numbers, by name (configs/team.yaml ``vfh`` and ``vfh_plus``)."""

    window: float  # m, radius of the active window around the robot
    cell: float  # m, side of a histogram-grid cell
    sectors: int  # of the polar histogram (alpha = 2 pi / sectors)
    enlarge: float  # m, VFH+: each cell fills the sectors within asin(enlarge / d) of it; 0: VFH's one sector


@njit(cache=True)
def polar_histogram(obs: np.ndarray, inner: np.ndarray, px: float, py: float, cfg: HistogramConfig) -> np.ndarray:
    """The primary polar histogram (Borenstein and Koren 1991; VFH+, Ulrich and Borenstein 1998):
    the histogram grid's occupied cells (certainty 1 where the cell's centre lies in an obstacle of
    the world as compiled, or beyond the walls: clearance <= 0, a box's inside reading 0 compiled
    without a radius) within ``window`` of the robot, each adding
    c^2 (a - b d) with a - b window = 0 (a = 1) to its sector, or with ``enlarge`` to every sector
    within the enlargement angle of it."""
    n = cfg.sectors
    h = np.zeros(n)
    alpha = 2.0 * math.pi / n
    half = int(math.ceil(cfg.window / cfg.cell))
    for i in range(-half, half + 1):
        cy = py + i * cfg.cell
        for k in range(-half, half + 1):
            if i == 0 and k == 0:
                continue
            cx = px + k * cfg.cell
            d = math.hypot(cx - px, cy - py)
            if d > cfg.window or clearance(obs, inner, cx, cy) > 0.0:
                continue
            m = 1.0 - d / cfg.window
            beta = math.atan2(cy - py, cx - px)
            s = int(math.floor((beta + math.pi) / alpha)) % n
            if cfg.enlarge <= 0.0:
                h[s] += m
                continue
            gam = math.asin(min(1.0, cfg.enlarge / d))
            lo = int(math.floor((beta - gam + math.pi) / alpha))
            hi = int(math.floor((beta + gam + math.pi) / alpha))
            for t in range(lo, hi + 1):
                h[t % n] += m
    return h


@njit(cache=True)
def turning_limits(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, theta: float, r_turn: float, enlarge: float,
    cfg: HistogramConfig,
) -> tuple[float, float]:
    """VFH+'s masked histogram: the limits (rad from the direction of motion ``theta``, left >= 0,
    right <= 0) of the directions the robot can still turn into, moving on circles of radius
    ``r_turn``, left and right of it, when an occupied cell within ``r_turn + enlarge`` of a circle's
    centre blocks every direction beyond it on that side. (pi, -pi): nothing blocks."""
    left, right = math.pi, -math.pi
    clx, cly = px - r_turn * math.sin(theta), py + r_turn * math.cos(theta)
    crx, cry = px + r_turn * math.sin(theta), py - r_turn * math.cos(theta)
    half = int(math.ceil(cfg.window / cfg.cell))
    reach = (r_turn + enlarge) ** 2
    for i in range(-half, half + 1):
        cy = py + i * cfg.cell
        for k in range(-half, half + 1):
            cx = px + k * cfg.cell
            if (i == 0 and k == 0) or math.hypot(cx - px, cy - py) > cfg.window:
                continue
            if clearance(obs, inner, cx, cy) > 0.0:
                continue
            b = math.atan2(cy - py, cx - px) - theta
            b = wrap_angle(b)
            if b >= 0.0 and b < left and (cx - clx) ** 2 + (cy - cly) ** 2 < reach:
                left = b
            if b <= 0.0 and b > right and (cx - crx) ** 2 + (cy - cry) ** 2 < reach:
                right = b
    return left, right
