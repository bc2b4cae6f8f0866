"""numba kernels of path smoothing (Bruce 2006 §4.6.1): greedy shortcuts, then passes that pull the
path taut against the collision world."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmdragons.planning.collision import CW, segment_free


@njit(cache=True)
def shortcut(cw: CW, path: np.ndarray) -> np.ndarray:
    """Greedy shortcutting: from each kept vertex, jump to the farthest later vertex in free sight."""
    n = path.shape[0]
    keep = np.empty(n, dtype=np.int64)
    keep[0] = 0
    m, i = 1, 0
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not segment_free(cw, path[i, 0], path[i, 1], path[j, 0], path[j, 1]):
            j -= 1
        keep[m] = j
        m += 1
        i = j
    out = np.empty((m, 2))
    for k in range(m):
        out[k, 0], out[k, 1] = path[keep[k], 0], path[keep[k], 1]
    return out


@njit(cache=True)
def pull_taut(cw: CW, path: np.ndarray, passes: int, bisections: int, subdivide_m: float) -> np.ndarray:
    """Path smoothing (Bruce 2006 §4.6.1, in the spirit of its leader-follower smoother): each pass
    subdivides segments longer than ``subdivide_m``, then moves every interior vertex as far as the
    swept check allows (bisection) toward the chord of its neighbours, and drops vertices that reach
    it. The polyline tightens around the obstacles toward the locally shortest path; the ends stay."""
    cur = path.copy()
    for _ in range(passes):
        n = cur.shape[0]
        if n < 3:
            return cur
        if subdivide_m > 0.0:
            extra = 0
            for i in range(n - 1):
                seg = math.hypot(cur[i + 1, 0] - cur[i, 0], cur[i + 1, 1] - cur[i, 1])
                extra += max(0, int(math.ceil(seg / subdivide_m)) - 1)
            fine = np.empty((n + extra, 2))
            m = 0
            for i in range(n - 1):
                seg = math.hypot(cur[i + 1, 0] - cur[i, 0], cur[i + 1, 1] - cur[i, 1])
                parts = max(1, int(math.ceil(seg / subdivide_m)))
                for p in range(parts):
                    f = p / parts
                    fine[m, 0] = cur[i, 0] + f * (cur[i + 1, 0] - cur[i, 0])
                    fine[m, 1] = cur[i, 1] + f * (cur[i + 1, 1] - cur[i, 1])
                    m += 1
            fine[m, 0], fine[m, 1] = cur[n - 1, 0], cur[n - 1, 1]
            cur = fine[: m + 1]
            n = cur.shape[0]
        keep = np.ones(n, dtype=np.bool_)
        prev = 0
        for i in range(1, n - 1):
            ax, ay = cur[prev, 0], cur[prev, 1]
            bx, by = cur[i + 1, 0], cur[i + 1, 1]
            vx, vy = cur[i, 0], cur[i, 1]
            # the point of chord a-b nearest to v is where v would sit on a straight path
            dx, dy = bx - ax, by - ay
            den = dx * dx + dy * dy
            t = 0.5 if den == 0.0 else min(1.0, max(0.0, ((vx - ax) * dx + (vy - ay) * dy) / den))
            mx, my = ax + t * dx, ay + t * dy
            if segment_free(cw, ax, ay, bx, by):
                keep[i] = False
                continue
            lo, hi = 0.0, 1.0
            for _b in range(bisections):
                f = 0.5 * (lo + hi)
                qx, qy = vx + f * (mx - vx), vy + f * (my - vy)
                if segment_free(cw, ax, ay, qx, qy) and segment_free(cw, qx, qy, bx, by):
                    lo = f
                else:
                    hi = f
            cur[i, 0], cur[i, 1] = vx + lo * (mx - vx), vy + lo * (my - vy)
            prev = i
        m = 0
        for i in range(n):
            if keep[i]:
                cur[m, 0], cur[m, 1] = cur[i, 0], cur[i, 1]
                m += 1
        cur = cur[:m].copy()
    return cur
