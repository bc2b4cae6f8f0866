"""numba kernels of the local navigators: the dynamic window (Bruce 2006 §5.2, after Fox, Burgard
and Thrun 1997), for a holonomic robot; Bug2 on an occupancy grid, the whole path in one call.

Field frame, metres, seconds. Obstacles come as a compiled collision world (``obs``, ``inner``: see
:mod:`cmdragons.planning._kernels`), grown by the robot's radius, the moving ones where they stand
now; the robot's motion is the braking trajectory of :mod:`cmdragons.control._kernels`.

Plain-numpy references of these kernels live in :mod:`cmdragons.navigation._reference`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons._kernels import wrap_angle
from cmdragons.control._kernels import N_SEG, Limits, clip_accel, trajectory
from cmdragons.planning._kernels import _away, clearance, obstacle_clearance
from cmdragons.safety._kernels import feasible, static_hits

__all__ = [
    "BUG2_BLOCKED", "BUG2_INVALID_GOAL", "BUG2_INVALID_START", "BUG2_OUT_OF_STEPS", "BUG2_REACHED", "GAUSSIAN",
    "INVERSE", "EvadeConfig", "HistogramConfig", "PotentialConfig", "WindowConfig", "bug2_grid", "dynamic_window",
    "escape_vector", "evade_vector", "march", "path_offset", "polar_histogram", "potential", "ranges",
    "turning_limits", "window_velocity",
]


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
) -> tuple[float, float, int, int]:  # fmt: skip
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


# --- the reactive navigators (lecture notes 001 and 003) -------------------------------------------
# Every query below is about a robot centre in the compiled world of the robot's radius (the
# C-space) unless it says otherwise; ``radius`` where a method needs the real obstacles' cores.

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
def _wall(inner: np.ndarray, side: int, px: float, py: float) -> tuple[float, float, float]:
    # wall ``side`` (0 x0, 1 x1, 2 y0, 3 y1) of the C-space box: its clearance and the unit normal away from it
    if side == 0:
        return px - inner[0], 1.0, 0.0
    if side == 1:
        return inner[2] - px, -1.0, 0.0
    if side == 2:
        return py - inner[1], 0.0, 1.0
    return inner[3] - py, 0.0, -1.0


@njit(cache=True)
def potential(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, gx: float, gy: float, mx: float, my: float,
    cfg: PotentialConfig,
) -> tuple[float, float, float]:  # fmt: skip
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
        ax, ay = _away(obs, j, px, py)
        w = _weight(ax, ay, mx, my, cfg)
        if w == 0.0:
            continue
        u, du = _source(d, d + obs[j, 5], cfg)
        e += w * u
        ex += w * du * ax
        ey += w * du * ay
    for side in range(4):
        d, ax, ay = _wall(inner, side, px, py)
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


@njit(cache=True)
def march(
    obs: np.ndarray, inner: np.ndarray, px: float, py: float, theta: float, curvature: float, length: float,
    threshold: float, tol: float,
) -> float:  # fmt: skip
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
) -> np.ndarray:  # fmt: skip
    """A simulated range sensor: :func:`march` along straight rays at ``angles`` (rad), at most
    ``length`` (the sensor's range), until the clearance falls to ``threshold`` (0: contact)."""
    out = np.empty(angles.shape[0])
    for i in range(angles.shape[0]):
        out[i] = march(obs, inner, px, py, angles[i], 0.0, length, threshold, tol)
    return out


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
) -> tuple[float, float]:  # fmt: skip
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
                                     objects[j, 4])  # fmt: skip
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
) -> tuple[float, float]:  # fmt: skip
    """The velocity (wx, wy) with its component toward each obstacle and wall cut to the speed that
    still stops ``margin`` short of it (:func:`_stop_speed`), obstacle after obstacle; the
    components sideways and away stay."""
    for side in range(4):
        c, ax, ay = _wall(inner, side, px, py)
        closing = -(wx * ax + wy * ay)
        cap = _stop_speed(c, margin, decel, dt)
        if closing > cap:
            wx, wy = wx + (closing - cap) * ax, wy + (closing - cap) * ay
    for j in range(obs.shape[0]):
        c = obstacle_clearance(obs, j, px, py)
        ax, ay = _away(obs, j, px, py)
        closing = -(wx * ax + wy * ay)
        cap = _stop_speed(c, margin, decel, dt)
        if closing > cap:
            wx, wy = wx + (closing - cap) * ax, wy + (closing - cap) * ay
    return wx, wy


# --- Bug2 on an occupancy grid ------------------------------------------------------------------------
# The eight moves of a cell, counter-clockwise from east (x = column, y = row): E NE N NW W SW S SE.
RING_DX = np.array([1, 1, 0, -1, -1, -1, 0, 1], dtype=np.int64)
RING_DY = np.array([0, 1, 1, 1, 0, -1, -1, -1], dtype=np.int64)
BUG2_REACHED, BUG2_BLOCKED, BUG2_OUT_OF_STEPS, BUG2_INVALID_START, BUG2_INVALID_GOAL = 0, 1, 2, 3, 4


@njit(cache=True)
def _ring_index(dx: int, dy: int) -> int:
    for k in range(8):
        if RING_DX[k] == dx and RING_DY[k] == dy:
            return k
    return -1


@njit(cache=True)
def _blocked(occupied: np.ndarray, x: int, y: int) -> bool:
    """Occupied, or off the grid (the grid's outside is an obstacle)."""
    return x < 0 or y < 0 or y >= occupied.shape[0] or x >= occupied.shape[1] or occupied[y, x]


@njit(cache=True)
def bug2_line_step(px: int, py: int, sx: int, sy: int, gx: int, gy: int) -> tuple[int, int]:
    """The next move (one of the eight) along the m-line from cell (px, py) toward the goal: one
    cell along the axis on which the goal is farther, and on the other axis toward the m-line's cell
    there (rounded half up, at most one cell)."""
    ex, ey = gx - sx, gy - sy
    dx, dy = gx - px, gy - py
    if abs(dx) > abs(dy):
        stx = 1 if dx > 0 else -1
        sty = 0
        if ex != 0:
            sty = int(math.floor(sy + ey * (px + stx - sx) / ex - py + 0.5))
    else:
        sty = 1 if dy > 0 else -1
        stx = 0
        if ey != 0:
            stx = int(math.floor(sx + ex * (py + sty - sy) / ey - px + 0.5))
    return min(max(stx, -1), 1), min(max(sty, -1), 1)


@njit(cache=True)
def bug2_grid(occupied: np.ndarray, sx: int, sy: int, gx: int, gy: int, turn: int,
              max_steps: int) -> tuple[int, np.ndarray]:  # fmt: skip
    """Bug2 (lecture notes 001 "Obstacle Avoidance: Bug2", 004 §2.5; Lumelsky and Stepanov 1987) on
    the occupancy grid ``occupied`` (row = y, column = x; the outside is an obstacle), the robot
    moving one cell to one of its eight neighbours a step, from cell (sx, sy) to cell (gx, gy).

    Motion to goal: along the m-line (:func:`bug2_line_step`). Hitting: the next m-line cell is
    occupied; the cell where the robot stands is the hit point. Boundary following: the obstacle
    kept on the right (``turn`` +1, turning left at the hit) or on the left (-1) by tracing its
    boundary through the free cells around it: from the direction of the obstacle cell last touched,
    the robot turns through its eight neighbours away from the obstacle and moves to the first free
    one. Leaving: on the m-line (within sqrt(2)/2 cell of it, where a line at 45 degrees passes
    between two diagonal neighbours) strictly nearer the goal than the hit point; where the m-line's
    next cell is occupied (the same obstacle, or one touching it at a corner that the diagonal
    moves pass between), that cell is the next hit point, nearer the goal than the last. The goal
    cannot be reached (``BUG2_BLOCKED``) when the following comes back to its first move (the same
    cell and obstacle cell: round the whole boundary), when it meets a hit point again, or when the
    robot has no free neighbour.

    Returns (status, path): the cells visited as (x, y), start first, up to ``max_steps`` moves
    (``BUG2_OUT_OF_STEPS`` beyond). Distances are compared squared in whole cells, exactly."""
    path = np.empty((max_steps + 1, 2), dtype=np.int64)
    path[0, 0], path[0, 1] = sx, sy
    if _blocked(occupied, sx, sy):
        return BUG2_INVALID_START, path[:1]
    if _blocked(occupied, gx, gy):
        return BUG2_INVALID_GOAL, path[:1]
    hits = np.zeros(occupied.shape, dtype=np.bool_)
    ex, ey = gx - sx, gy - sy
    line2 = ex * ex + ey * ey
    px, py, n = sx, sy, 1
    following = False
    hit_d2 = 0
    b = 0  # following: the direction of the obstacle cell last touched
    first_x, first_y, first_b, moved = 0, 0, 0, False
    while px != gx or py != gy:
        if n > max_steps:
            return BUG2_OUT_OF_STEPS, path[:n]
        if not following:
            stx, sty = bug2_line_step(px, py, sx, sy, gx, gy)
            if _blocked(occupied, px + stx, py + sty):
                if hits[py, px]:
                    return BUG2_BLOCKED, path[:n]
                hits[py, px] = True
                hit_d2 = (gx - px) * (gx - px) + (gy - py) * (gy - py)
                b = _ring_index(stx, sty)
                following, moved = True, False
                continue
            px, py = px + stx, py + sty
        else:
            k = -1
            for i in range(1, 8):
                j = (b + turn * i) % 8
                if not _blocked(occupied, px + RING_DX[j], py + RING_DY[j]):
                    k = j
                    break
            if k < 0:
                return BUG2_BLOCKED, path[:n]
            kp = (k - turn) % 8  # the obstacle cell checked last, now beside the new cell
            b = _ring_index(RING_DX[kp] - RING_DX[k], RING_DY[kp] - RING_DY[k])
            px, py = px + RING_DX[k], py + RING_DY[k]
            if not moved:
                first_x, first_y, first_b, moved = px, py, b, True
            elif px == first_x and py == first_y and b == first_b:
                return BUG2_BLOCKED, path[:n]
            cross = (px - sx) * ey - (py - sy) * ex
            d2 = (gx - px) * (gx - px) + (gy - py) * (gy - py)
            if 2 * cross * cross <= line2 and d2 < hit_d2:
                following = False  # (an obstacle on the m-line's next cell is hit here, a new hit point)
        path[n, 0], path[n, 1] = px, py
        n += 1
    return BUG2_REACHED, path[:n]
