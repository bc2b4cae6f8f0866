"""numba kernel of Bug2 on an occupancy grid, the whole path in one call (lecture notes 001).
Plain-numpy reference: :mod:`cmdragons.navigation._bug_reference`."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

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
              max_steps: int) -> tuple[int, np.ndarray]:
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
