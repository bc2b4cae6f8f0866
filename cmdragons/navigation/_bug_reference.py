"""Plain-numpy reference of Bug2 on an occupancy grid, for the test that checks it agrees with the
kernel: the same moves, written out step by step."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def bug2_grid(occupied: NDArray[np.bool_], start: tuple[int, int], goal: tuple[int, int], turn: int,
              max_steps: int) -> tuple[str, list[tuple[int, int]]]:
    """Bug2 on the occupancy grid as :func:`cmdragons.navigation._bug_kernels.bug2_grid` states it,
    written the obvious way: a neighbour's direction by its angle, the boundary followed by sorting
    the eight neighbours by their angle from the obstacle cell last touched, a loop found by a set of
    the (cell, obstacle cell) states seen, distances in floats. Returns the status's name
    (``reached``, ``blocked``, ``out_of_steps``, ``invalid_start``, ``invalid_goal``) and the cells."""
    rows, cols = occupied.shape

    def blocked(c: tuple[int, int]) -> bool:
        return not (0 <= c[0] < cols and 0 <= c[1] < rows) or bool(occupied[c[1], c[0]])

    def on_line(c: tuple[int, int]) -> bool:
        e, v = np.subtract(goal, start), np.subtract(c, start)
        return bool(abs(float(e[0] * v[1] - e[1] * v[0])) / float(np.hypot(*e)) <= np.sqrt(0.5) + 1e-12)

    def line_move(c: tuple[int, int]) -> tuple[int, int]:
        # one cell along the axis the goal is farther on, toward the m-line's cell on the other
        e, d = np.subtract(goal, start), np.subtract(goal, c)
        a = 0 if abs(d[0]) > abs(d[1]) else 1  # the axis stepped
        o = 1 - a
        step = [0, 0]
        step[a] = int(np.sign(d[a]))
        if e[a] != 0:
            on = start[o] + e[o] * (c[a] + step[a] - start[a]) / e[a]
            step[o] = int(np.clip(np.floor(on - c[o] + 0.5), -1, 1))
        return c[0] + step[0], c[1] + step[1]

    def dist(c: tuple[int, int]) -> float:
        return float(np.hypot(goal[0] - c[0], goal[1] - c[1]))

    path = [start]
    if blocked(start):
        return "invalid_start", path
    if blocked(goal):
        return "invalid_goal", path
    here, hits = start, set()
    while here != goal:
        if len(path) > max_steps:
            return "out_of_steps", path
        nxt = line_move(here)
        if not blocked(nxt):
            here = nxt
        else:
            if here in hits:
                return "blocked", path
            hits.add(here)
            hit_d, wall, seen = dist(here), nxt, set()
            while True:
                if len(path) > max_steps:
                    return "out_of_steps", path
                base = np.arctan2(wall[1] - here[1], wall[0] - here[0])
                around = [(here[0] + dx, here[1] + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy]
                # counter-clockwise (turn +1) or clockwise from the obstacle cell, the obstacle cell itself last
                turned = sorted(around, key=lambda c: (turn * (np.arctan2(c[1] - here[1], c[0] - here[0]) - base)
                                                       - 1e-9) % (2 * np.pi))
                free = [i for i, c in enumerate(turned) if not blocked(c)]
                if not free:
                    return "blocked", path
                wall, here = turned[free[0] - 1], turned[free[0]]
                if (here, wall) in seen:
                    return "blocked", path
                seen.add((here, wall))
                path.append(here)
                if here == goal:
                    return "reached", path
                if on_line(here) and dist(here) < hit_d:
                    break
            continue
        path.append(here)
    return "reached", path
