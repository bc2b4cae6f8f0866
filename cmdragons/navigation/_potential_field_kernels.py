"""numba kernel of the potential fields (lecture notes 001): the goal's well and the obstacles'
sources, plain and extended (Khatib and Chatila's rotation and task potentials), and the walls.
Field frame, metres; every query about a robot centre in the C-space."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons.navigation._reactive_kernels import wall
from cmdragons.planning.collision import away, obstacle_clearance

GAUSSIAN = 0  # PotentialConfig.kind: a Gaussian source on the distance to the obstacle's core
INVERSE = 1  # ... the inverse-distance (FIRAS) potential on the clearance, zero beyond the influence


class PotentialConfig(NamedTuple):
    """The potential field's numbers, by name (configs/team.yaml ``potential_field`` and
    ``extended_potential_field``)."""

    goal_gain: float  # k of the parabolic well 1/2 k |x - goal|^2 (E in m^2: dimensionless)
    goal_well: float  # m: the well is parabolic within this of the goal, conic (slope k * well) beyond
    kind: int  # GAUSSIAN or INVERSE
    height: float  # m^2, beta of the Gaussian source
    gamma: float  # 1/m^2, gamma = 1 / sigma^2 of the Gaussian source
    inverse_gain: float  # m^4, eta of the inverse-distance potential 1/2 eta (1/d - 1/d0)^2
    influence: float  # m, d0: obstacles (and walls) farther than this from the robot's disc exert nothing
    min_distance: float  # m: the inverse potential's distance is held above this (finite in contact)
    radius: float  # m, the robot's radius: a wall's core is the boundary, this beyond the C-space box
    rotation_floor: float  # extended field: the weight of an obstacle abeam or behind (1: plain field)
    cos_sector: float  # extended field: obstacles outside the task sector (cos of its half angle) are left out


@njit(cache=True)
def _source(d: float, core: float, cfg: PotentialConfig) -> tuple[float, float]:
    # one obstacle's potential and its derivative along the clearance, at clearance d and core distance core
    if d > cfg.influence:
        return 0.0, 0.0
    if cfg.kind == GAUSSIAN:
        u = cfg.height * math.exp(-0.5 * cfg.gamma * core * core)
        return u, -cfg.gamma * core * u
    dd = max(d, cfg.min_distance)
    s = 1.0 / dd - 1.0 / cfg.influence
    return 0.5 * cfg.inverse_gain * s * s, -cfg.inverse_gain * s / (dd * dd)


@njit(cache=True)
def _weight(ax: float, ay: float, mx: float, my: float, cfg: PotentialConfig) -> float:
    # the extended field's weight of an obstacle in direction -away from a robot moving along unit m
    if mx == 0.0 and my == 0.0:
        return 1.0
    c = -(ax * mx + ay * my)  # cos of the angle between the motion and the direction to the obstacle
    if c < cfg.cos_sector:
        return 0.0  # the task potential: outside the sector ahead
    return cfg.rotation_floor + (1.0 - cfg.rotation_floor) * max(c, 0.0)


@njit(cache=True)
def potential(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, gx: float, gy: float, mx: float, my: float,
    cfg: PotentialConfig,
) -> tuple[float, float, float]:
    """The potential E (m^2) at (px, py) and its gradient (ex, ey) (m): the goal's well at (gx, gy)
    plus every obstacle's and wall's source (lecture notes 001, "Potential Field Path Planning").
    (mx, my): the unit direction of motion for the extended field's rotation and task weights
    (Khatib and Chatila); (0, 0) weighs every source 1."""
    dx, dy = px - gx, py - gy
    dg = math.hypot(dx, dy)
    if dg <= cfg.goal_well:
        e = 0.5 * cfg.goal_gain * dg * dg
        ex, ey = cfg.goal_gain * dx, cfg.goal_gain * dy
    else:
        e = cfg.goal_gain * cfg.goal_well * (dg - 0.5 * cfg.goal_well)
        ex, ey = cfg.goal_gain * cfg.goal_well * dx / dg, cfg.goal_gain * cfg.goal_well * dy / dg
    for j in range(obs.shape[0]):
        d = obstacle_clearance(obs, j, px, py)
        if d > cfg.influence:
            continue
        ax, ay = away(obs, j, px, py)
        w = _weight(ax, ay, mx, my, cfg)
        if w == 0.0:
            continue
        u, du = _source(d, d + obs[j, 5], cfg)
        e += w * u
        ex += w * du * ax
        ey += w * du * ay
    for side in range(4):
        d, ax, ay = wall(inner, side, px, py)
        if d > cfg.influence:
            continue
        w = _weight(ax, ay, mx, my, cfg)
        if w == 0.0:
            continue
        u, du = _source(d, d + cfg.radius, cfg)
        e += w * u
        ex += w * du * ax
        ey += w * du * ay
    return e, ex, ey
