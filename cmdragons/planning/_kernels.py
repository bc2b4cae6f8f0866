"""numba kernels of motion planning: collision queries, broad phases, nearest neighbour, ERRT growth,
path smoothing, the visibility graph and the roadmap search.

Everything here works in the field frame (metres) on plain numpy arrays. A compiled collision world
("cw") is one named tuple (:class:`CW`), built by :mod:`cmdragons.planning.world`, for one robot radius and time window:

    cw = CW(obs, aabb, inner, mode, grid, xmask, ymask, tbox, tchild, tleaf)

* ``obs`` (k, 6): ``kind, p0, p1, p2, p3, R`` per obstacle, already grown by the robot's radius, so
  a robot *centre* is in collision when its distance to the obstacle's core is below ``R``.
  ``kind == 0``: a capsule, the segment (p0, p1)-(p2, p3) a moving circle sweeps over the query's
  time window (a point when the circle stands still); ``kind == 1``: an axis-aligned box
  (x0, y0, x1, y1) with clearance ``R``.
* ``aabb`` (k, 4): each obstacle's grown bounding box (x0, y0, x1, y1).
* ``inner`` (4,): the box the robot centre must stay in (the field boundary shrunk by the radius).
* ``mode``: broad phase, 0 linear scan, 1 extent masks, 2 AABB tree (Bruce 2006 §3.2.1, §3.2.2).
* ``grid, xmask, ymask``: extent masks: ``grid = (x0, y0, 1/dx, 1/dy)``, one bit per obstacle in
  each x and y bin of the obstacle's extent, ``ceil(k / 64)`` uint64 words a bin.
* ``tbox, tchild, tleaf``: the AABB tree, node boxes, children (-1 for a leaf), leaf obstacle.

A contact within ``EPS_M`` counts as free: exact tangents (the visibility graph) touch their
obstacle at distance ``R`` up to rounding, and a micrometre is far below anything a robot can hold.
"""

from __future__ import annotations

import heapq
import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit


class CW(NamedTuple):
    """A compiled collision world, by name (see the module docstring)."""

    obs: np.ndarray  # (k, 6) kind, p0, p1, p2, p3, R
    aabb: np.ndarray  # (k, 4) grown bounding boxes
    inner: np.ndarray  # (4,) the box the robot centre stays in
    mode: int  # MODE_LINEAR, MODE_MASKS or MODE_AABB_TREE
    grid: np.ndarray  # (4,) x0, y0, bins per metre in x and y of the extent masks
    xmask: np.ndarray  # (bins, words) uint64
    ymask: np.ndarray  # (bins, words) uint64
    tbox: np.ndarray  # (nodes, 4) AABB tree node boxes
    tchild: np.ndarray  # (nodes, 2) children, -1 for a leaf
    tleaf: np.ndarray  # (nodes,) a leaf's obstacle



EPS_M = 1e-6  # contact tolerance of every collision query, metres

MODE_LINEAR = 0
MODE_MASKS = 1
MODE_AABB_TREE = 2

NN_BRUTE = 0
NN_KDTREE = 1

# ERRT kernel return codes
GROW_RUNNING = 0  # the iteration chunk is used up; call again
GROW_DONE = 1  # enough bridges between the trees (or to the goal)
GROW_FULL = 2  # the node budget is used up


# --- distance primitives --------------------------------------------------------------------------
@njit(cache=True)
def point_segment_dist2(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Squared distance from point p to segment ab (a point when a == b)."""
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0
    if den > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / den
        t = min(1.0, max(0.0, t))
    ex, ey = ax + t * dx - px, ay + t * dy - py
    return ex * ex + ey * ey


@njit(cache=True)
def segment_segment_dist2(
    ax: float, ay: float, bx: float, by: float, cx: float, cy: float, dx: float, dy: float
) -> float:
    """Squared distance between segments ab and cd (either may be a point)."""
    ux, uy = bx - ax, by - ay
    vx, vy = dx - cx, dy - cy
    cross = ux * vy - uy * vx
    if cross != 0.0:
        # a proper crossing has distance 0; otherwise the minimum is at one of the four endpoints
        wx, wy = cx - ax, cy - ay
        s = (wx * vy - wy * vx) / cross
        t = (wx * uy - wy * ux) / cross
        if 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0:
            return 0.0
    d = point_segment_dist2(ax, ay, cx, cy, dx, dy)
    d = min(d, point_segment_dist2(bx, by, cx, cy, dx, dy))
    d = min(d, point_segment_dist2(cx, cy, ax, ay, bx, by))
    return min(d, point_segment_dist2(dx, dy, ax, ay, bx, by))


@njit(cache=True)
def point_box_dist2(px: float, py: float, x0: float, y0: float, x1: float, y1: float) -> float:
    """Squared distance from a point to the axis-aligned box [x0, x1] x [y0, y1] (0 inside)."""
    ex = max(x0 - px, 0.0, px - x1)
    ey = max(y0 - py, 0.0, py - y1)
    return ex * ex + ey * ey


@njit(cache=True)
def segment_box_dist2(ax: float, ay: float, bx: float, by: float, x0: float, y0: float, x1: float, y1: float) -> float:
    """Squared distance from segment ab to an axis-aligned box (0 when they touch)."""
    # Liang-Barsky clipping: does the segment enter the box?
    t0, t1 = 0.0, 1.0
    dx, dy = bx - ax, by - ay
    inside = True
    for k in range(4):
        if k == 0:
            p, q = -dx, ax - x0
        elif k == 1:
            p, q = dx, x1 - ax
        elif k == 2:
            p, q = -dy, ay - y0
        else:
            p, q = dy, y1 - ay
        if p == 0.0:
            if q < 0.0:
                inside = False
                break
        else:
            r = q / p
            if p < 0.0:
                t0 = max(t0, r)
            else:
                t1 = min(t1, r)
            if t0 > t1:
                inside = False
                break
    if inside:
        return 0.0
    # two disjoint convex sets: the closest pair has a vertex of one of them
    d = min(point_box_dist2(ax, ay, x0, y0, x1, y1), point_box_dist2(bx, by, x0, y0, x1, y1))
    d = min(d, point_segment_dist2(x0, y0, ax, ay, bx, by))
    d = min(d, point_segment_dist2(x1, y0, ax, ay, bx, by))
    d = min(d, point_segment_dist2(x0, y1, ax, ay, bx, by))
    return min(d, point_segment_dist2(x1, y1, ax, ay, bx, by))


# --- narrow phase -----------------------------------------------------------------------------------
@njit(cache=True)
def _hits_segment(obs: np.ndarray, j: int, ax: float, ay: float, bx: float, by: float) -> bool:
    r = obs[j, 5] - EPS_M
    if obs[j, 0] == 0.0:
        d2 = segment_segment_dist2(ax, ay, bx, by, obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4])
    else:
        d2 = segment_box_dist2(ax, ay, bx, by, obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4])
    return bool(d2 < r * r)


@njit(cache=True)
def obstacle_clearance(obs: np.ndarray, j: int, px: float, py: float) -> float:
    """Signed clearance of a robot centre at p from obstacle j, metres (< 0 inside)."""
    if obs[j, 0] == 0.0:
        ax, ay, bx, by = obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4]
        dx, dy = bx - ax, by - ay
        den = dx * dx + dy * dy
        t = 0.0 if den == 0.0 else min(1.0, max(0.0, ((px - ax) * dx + (py - ay) * dy) / den))
        return float(math.hypot(px - (ax + t * dx), py - (ay + t * dy)) - obs[j, 5])
    ex = max(obs[j, 1] - px, 0.0, px - obs[j, 3])
    ey = max(obs[j, 2] - py, 0.0, py - obs[j, 4])
    return float(math.hypot(ex, ey) - obs[j, 5])


@njit(cache=True)
def clearance(obs: np.ndarray, inner: np.ndarray, px: float, py: float) -> float:
    """Signed clearance (m) of a robot centre at p from the nearest obstacle (grown by the robot's
    radius) or wall; < 0 in collision. The one distance query of planners, navigators and safety."""
    c = min(px - inner[0], inner[2] - px, py - inner[1], inner[3] - py)
    for j in range(obs.shape[0]):
        c = min(c, obstacle_clearance(obs, j, px, py))
    return float(c)


@njit(cache=True)
def _away(obs: np.ndarray, j: int, px: float, py: float) -> tuple[float, float]:
    # the unit direction in which the clearance from obstacle j grows fastest at p
    if obs[j, 0] == 0.0:
        ax, ay, bx, by = obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4]
        dx, dy = bx - ax, by - ay
        den = dx * dx + dy * dy
        t = 0.0 if den == 0.0 else min(1.0, max(0.0, ((px - ax) * dx + (py - ay) * dy) / den))
        ux, uy = px - (ax + t * dx), py - (ay + t * dy)
    else:
        x0, y0, x1, y1 = obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4]
        ux, uy = px - min(max(px, x0), x1), py - min(max(py, y0), y1)
        if ux == 0.0 and uy == 0.0:  # inside the box's core: out through the nearest face
            m = min(px - x0, x1 - px, py - y0, y1 - py)
            if m == px - x0:
                return -1.0, 0.0
            if m == x1 - px:
                return 1.0, 0.0
            if m == py - y0:
                return 0.0, -1.0
            return 0.0, 1.0
    n = math.hypot(ux, uy)
    if n == 0.0:
        return 0.0, 0.0  # on a capsule's core: every direction is as good
    return ux / n, uy / n


@njit(cache=True)
def clearance_gradient(obs: np.ndarray, inner: np.ndarray, px: float, py: float) -> tuple[float, float, float]:
    """:func:`clearance` at p and its gradient (the unit direction away from the nearest obstacle or
    wall; (0, 0) where it is undefined): (c, gx, gy)."""
    c, gx, gy = px - inner[0], 1.0, 0.0
    if inner[2] - px < c:
        c, gx, gy = inner[2] - px, -1.0, 0.0
    if py - inner[1] < c:
        c, gx, gy = py - inner[1], 0.0, 1.0
    if inner[3] - py < c:
        c, gx, gy = inner[3] - py, 0.0, -1.0
    for j in range(obs.shape[0]):
        cj = obstacle_clearance(obs, j, px, py)
        if cj < c:
            c = cj
            gx, gy = _away(obs, j, px, py)
    return float(c), gx, gy


@njit(cache=True)
def clearance_gradients(obs: np.ndarray, inner: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`clearance_gradient` at each point of ``pts`` (n, 2): clearances (n,) and gradients (n, 2)."""
    n = pts.shape[0]
    c = np.empty(n)
    g = np.empty((n, 2))
    for i in range(n):
        c[i], g[i, 0], g[i, 1] = clearance_gradient(obs, inner, pts[i, 0], pts[i, 1])
    return c, g


@njit(cache=True)
def clearance_grid(
    obs: np.ndarray, inner: np.ndarray, x0: float, y0: float, res: float, nx: int, ny: int
) -> np.ndarray:
    """:func:`clearance` at the centres of an (ny, nx) grid of ``res``-metre cells whose lower-left
    corner is (x0, y0): cell [i, k] is centred at (x0 + (k + 1/2) res, y0 + (i + 1/2) res)."""
    out = np.empty((ny, nx))
    for i in range(ny):
        py = y0 + (i + 0.5) * res
        for k in range(nx):
            out[i, k] = clearance(obs, inner, x0 + (k + 0.5) * res, py)
    return out


@njit(cache=True)
def clearance_grid_capped(
    obs: np.ndarray, aabb: np.ndarray, inner: np.ndarray, x0: float, y0: float, res: float, nx: int, ny: int,
    cap: float,
) -> np.ndarray:  # fmt: skip
    """``min(clearance, cap)`` at the cell centres of :func:`clearance_grid`: each obstacle visits
    only the cells within ``cap`` of its bounding box (what a cost grid needs: its soft costs end at a
    clearance, so the cells farther from every obstacle all take ``cap``)."""
    out = np.empty((ny, nx))
    for i in range(ny):
        py = y0 + (i + 0.5) * res
        for k in range(nx):
            px = x0 + (k + 0.5) * res
            out[i, k] = min(px - inner[0], inner[2] - px, py - inner[1], inner[3] - py, cap)
    for j in range(obs.shape[0]):
        k0 = max(0, int(math.floor((aabb[j, 0] - cap - x0) / res - 0.5)))
        k1 = min(nx - 1, int(math.ceil((aabb[j, 2] + cap - x0) / res - 0.5)))
        i0 = max(0, int(math.floor((aabb[j, 1] - cap - y0) / res - 0.5)))
        i1 = min(ny - 1, int(math.ceil((aabb[j, 3] + cap - y0) / res - 0.5)))
        for i in range(i0, i1 + 1):
            py = y0 + (i + 0.5) * res
            for k in range(k0, k1 + 1):
                c = obstacle_clearance(obs, j, x0 + (k + 0.5) * res, py)
                if c < out[i, k]:
                    out[i, k] = c
    return out


@njit(cache=True)
def _in_inner(inner: np.ndarray, px: float, py: float) -> bool:
    return bool(inner[0] - EPS_M <= px <= inner[2] + EPS_M and inner[1] - EPS_M <= py <= inner[3] + EPS_M)


# --- broad phase ------------------------------------------------------------------------------------
@njit(cache=True)
def _bin(v: float, v0: float, inv: float, n: int) -> int:
    i = int(math.floor((v - v0) * inv))
    return min(n - 1, max(0, i))


@njit(cache=True)
def build_masks(aabb: np.ndarray, grid: np.ndarray, n_bins: int) -> tuple[np.ndarray, np.ndarray]:
    """Extent masks (Bruce 2006 §3.2.1): bit j of ``xmask[i]`` is set when obstacle j's grown box
    overlaps x bin i; the same along y. A query ORs the bins its box covers on each axis and ANDs
    the two axes, leaving only obstacles whose extent overlaps the query on both."""
    k = aabb.shape[0]
    words = max(1, (k + 63) // 64)
    xm = np.zeros((n_bins, words), dtype=np.uint64)
    ym = np.zeros((n_bins, words), dtype=np.uint64)
    for j in range(k):
        w = j // 64
        bit = np.uint64(1) << np.uint64(j % 64)
        for i in range(_bin(aabb[j, 0], grid[0], grid[2], n_bins), _bin(aabb[j, 2], grid[0], grid[2], n_bins) + 1):
            xm[i, w] |= bit
        for i in range(_bin(aabb[j, 1], grid[1], grid[3], n_bins), _bin(aabb[j, 3], grid[1], grid[3], n_bins) + 1):
            ym[i, w] |= bit
    return xm, ym


@njit(cache=True)
def build_aabb_tree(aabb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A top-down AABB tree (Bruce 2006 §3.2.2): each node splits its obstacles across the longer
    axis of their box at the split that minimises the summed areas of the two child boxes
    (a cheap balance heuristic for overlap-heavy scenes). One obstacle per leaf."""
    k = aabb.shape[0]
    n_nodes = max(1, 2 * k - 1)
    tbox = np.zeros((n_nodes, 4))
    tchild = -np.ones((n_nodes, 2), dtype=np.int32)
    tleaf = -np.ones(n_nodes, dtype=np.int32)
    if k == 0:
        tbox[0, 0], tbox[0, 1], tbox[0, 2], tbox[0, 3] = 1.0, 1.0, -1.0, -1.0  # empty box
        return tbox, tchild, tleaf
    order = np.arange(k)
    # explicit work stack of (node, lo, hi) ranges into ``order``
    stack = np.zeros((n_nodes, 3), dtype=np.int64)
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, 0, k
    top, used = 1, 1
    while top > 0:
        top -= 1
        node, lo, hi = stack[top, 0], stack[top, 1], stack[top, 2]
        bx0, by0, bx1, by1 = np.inf, np.inf, -np.inf, -np.inf
        for i in range(lo, hi):
            j = order[i]
            bx0, by0 = min(bx0, aabb[j, 0]), min(by0, aabb[j, 1])
            bx1, by1 = max(bx1, aabb[j, 2]), max(by1, aabb[j, 3])
        tbox[node, 0], tbox[node, 1], tbox[node, 2], tbox[node, 3] = bx0, by0, bx1, by1
        if hi - lo == 1:
            tleaf[node] = order[lo]
            continue
        axis = 0 if bx1 - bx0 >= by1 - by0 else 1
        centres = np.empty(hi - lo)
        for i in range(lo, hi):
            j = order[i]
            centres[i - lo] = aabb[j, axis] + aabb[j, axis + 2]
        sub = order[lo:hi][np.argsort(centres)]
        order[lo:hi] = sub
        best, split = np.inf, lo + (hi - lo) // 2
        for m in range(lo + 1, hi):
            cost = _range_area(aabb, order, lo, m) * (m - lo) + _range_area(aabb, order, m, hi) * (hi - m)
            if cost < best:
                best, split = cost, m
        left, right = used, used + 1
        used += 2
        tchild[node, 0], tchild[node, 1] = left, right
        stack[top, 0], stack[top, 1], stack[top, 2] = left, lo, split
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = right, split, hi
        top += 2
    return tbox, tchild, tleaf


@njit(cache=True)
def _range_area(aabb: np.ndarray, order: np.ndarray, lo: int, hi: int) -> float:
    bx0, by0, bx1, by1 = np.inf, np.inf, -np.inf, -np.inf
    for i in range(lo, hi):
        j = order[i]
        bx0, by0 = min(bx0, aabb[j, 0]), min(by0, aabb[j, 1])
        bx1, by1 = max(bx1, aabb[j, 2]), max(by1, aabb[j, 3])
    return (bx1 - bx0) * (by1 - by0)


@njit(cache=True)
def build_world(
    circles: np.ndarray, vel: np.ndarray, boxes: np.ndarray, bounds: np.ndarray, radius: float,
    t0: float, t1: float, mode: int, n_bins: int,
) -> CW:  # fmt: skip
    """The compiled world (see the module docstring) for a robot of ``radius`` over the time
    window [t0, t1]: circles (x, y, r) moving at ``vel`` become capsules, boxes get the radius as
    clearance, and the extent masks are built when ``mode`` asks for them (the AABB tree is the
    caller's: :class:`cmdragons.planning.world.CompiledWorld`)."""
    nc, nb = circles.shape[0], boxes.shape[0]
    k = nc + nb
    obs = np.empty((k, 6))
    aabb = np.empty((k, 4))
    for j in range(nc):
        obs[j, 0] = 0.0
        obs[j, 1], obs[j, 2] = circles[j, 0] + vel[j, 0] * t0, circles[j, 1] + vel[j, 1] * t0
        obs[j, 3], obs[j, 4] = circles[j, 0] + vel[j, 0] * t1, circles[j, 1] + vel[j, 1] * t1
        obs[j, 5] = circles[j, 2] + radius
    for i in range(nb):
        j = nc + i
        obs[j, 0] = 1.0
        obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4] = boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3]
        obs[j, 5] = radius
    for j in range(k):
        r = obs[j, 5]
        aabb[j, 0], aabb[j, 2] = min(obs[j, 1], obs[j, 3]) - r, max(obs[j, 1], obs[j, 3]) + r
        aabb[j, 1], aabb[j, 3] = min(obs[j, 2], obs[j, 4]) - r, max(obs[j, 2], obs[j, 4]) + r
    x0, y0, x1, y1 = bounds[0], bounds[1], bounds[2], bounds[3]
    inner = np.array([x0 + radius, y0 + radius, x1 - radius, y1 - radius])
    grid = np.array([x0, y0, n_bins / (x1 - x0), n_bins / (y1 - y0)])
    if mode == MODE_MASKS:
        xm, ym = build_masks(aabb, grid, n_bins)
    else:
        xm = np.zeros((1, 1), dtype=np.uint64)
        ym = np.zeros((1, 1), dtype=np.uint64)
    # the AABB tree is built by the caller (:func:`build_aabb_tree`) when the mode asks for it, so
    # that a run on another broad phase never compiles it
    tbox, tchild, tleaf = np.zeros((1, 4)), -np.ones((1, 2), dtype=np.int32), -np.ones(1, dtype=np.int32)
    return CW(obs, aabb, inner, mode, grid, xm, ym, tbox, tchild, tleaf)


@njit(cache=True)
def _box_overlap(b: np.ndarray, i: int, x0: float, y0: float, x1: float, y1: float) -> bool:
    return bool(b[i, 0] <= x1 and x0 <= b[i, 2] and b[i, 1] <= y1 and y0 <= b[i, 3])


@njit(cache=True)
def _segment_hits_any(cw: CW, ax: float, ay: float, bx: float, by: float) -> bool:
    obs, aabb, mode, grid, xm, ym = cw.obs, cw.aabb, cw.mode, cw.grid, cw.xmask, cw.ymask
    tbox, tchild, tleaf = cw.tbox, cw.tchild, cw.tleaf
    x0, x1 = min(ax, bx), max(ax, bx)
    y0, y1 = min(ay, by), max(ay, by)
    k = obs.shape[0]
    if mode == MODE_MASKS:
        nb = xm.shape[0]
        i0, i1 = _bin(x0, grid[0], grid[2], nb), _bin(x1, grid[0], grid[2], nb)
        k0, k1 = _bin(y0, grid[1], grid[3], nb), _bin(y1, grid[1], grid[3], nb)
        for w in range(xm.shape[1]):
            mx = np.uint64(0)
            for i in range(i0, i1 + 1):
                mx |= xm[i, w]
            my = np.uint64(0)
            for i in range(k0, k1 + 1):
                my |= ym[i, w]
            m = mx & my
            j = w * 64
            while m != np.uint64(0):
                if m & np.uint64(1):
                    if _box_overlap(aabb, j, x0, y0, x1, y1) and _hits_segment(obs, j, ax, ay, bx, by):
                        return True
                m >>= np.uint64(1)
                j += 1
        return False
    if mode == MODE_AABB_TREE:
        if k == 0:
            return False
        stack = np.empty(64, dtype=np.int32)
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            n = stack[top]
            if not _box_overlap(tbox, n, x0, y0, x1, y1):
                continue
            if tleaf[n] >= 0:
                if _hits_segment(obs, tleaf[n], ax, ay, bx, by):
                    return True
            else:
                stack[top] = tchild[n, 0]
                stack[top + 1] = tchild[n, 1]
                top += 2
        return False
    for j in range(k):
        if _box_overlap(aabb, j, x0, y0, x1, y1) and _hits_segment(obs, j, ax, ay, bx, by):
            return True
    return False


# --- queries ----------------------------------------------------------------------------------------
@njit(cache=True)
def segment_free(cw: CW, ax: float, ay: float, bx: float, by: float) -> bool:
    """Swept-circle check: the robot's disc moving from a to b touches no obstacle and stays in the
    field (the inner box is convex, so both endpoints inside is enough)."""
    inner = cw.inner
    if not (_in_inner(inner, ax, ay) and _in_inner(inner, bx, by)):
        return False
    return not _segment_hits_any(cw, ax, ay, bx, by)


@njit(cache=True)
def point_free(cw: CW, px: float, py: float) -> bool:
    """The robot's disc centred at p touches no obstacle and stays in the field."""
    return segment_free(cw, px, py, px, py)


@njit(cache=True)
def segments_free(cw: CW, seg: np.ndarray) -> np.ndarray:
    """:func:`segment_free` for each row (ax, ay, bx, by) of ``seg``."""
    out = np.empty(seg.shape[0], dtype=np.bool_)
    for i in range(seg.shape[0]):
        out[i] = segment_free(cw, seg[i, 0], seg[i, 1], seg[i, 2], seg[i, 3])
    return out


@njit(cache=True)
def path_free(cw: CW, path: np.ndarray) -> bool:
    """Every segment of the polyline ``path`` (n, 2) passes :func:`segment_free`."""
    if path.shape[0] == 1:
        return point_free(cw, path[0, 0], path[0, 1])
    for i in range(path.shape[0] - 1):
        if not segment_free(cw, path[i, 0], path[i, 1], path[i + 1, 0], path[i + 1, 1]):
            return False
    return True


@njit(cache=True)
def nearest_free_point(
    cw: CW, px: float, py: float, step_m: float, n_rings: int, n_angles: int
) -> tuple[float, float, bool]:
    """The free robot position nearest to p (Robust planning, Bruce 2006 §4.6.2).

    Candidates: p pushed straight out of each obstacle it overlaps (to the obstacle's surface plus
    a hair) and clamped into the field, then rings of ``n_angles`` points every ``step_m`` around p
    for the cases where pushing out of one obstacle lands in another. Returns (x, y, found)."""
    obs, inner = cw.obs, cw.inner
    margin = 10.0 * EPS_M
    best_d2, bx, by = np.inf, px, py
    cx = min(max(px, inner[0] + margin), inner[2] - margin)
    cy = min(max(py, inner[1] + margin), inner[3] - margin)
    if point_free(cw, cx, cy):
        best_d2, bx, by = (cx - px) ** 2 + (cy - py) ** 2, cx, cy
    for j in range(obs.shape[0]):
        if obstacle_clearance(obs, j, cx, cy) >= -EPS_M:
            continue
        r = obs[j, 5] + margin
        if obs[j, 0] == 0.0:
            # push away from the closest point of the capsule's core
            ax, ay, ex, ey = obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4]
            dx, dy = ex - ax, ey - ay
            den = dx * dx + dy * dy
            t = 0.0 if den == 0.0 else min(1.0, max(0.0, ((cx - ax) * dx + (cy - ay) * dy) / den))
            nx, ny = ax + t * dx, ay + t * dy
            ux, uy = cx - nx, cy - ny
            n = math.hypot(ux, uy)
            if n < 1e-12:
                ux, uy, n = 1.0, 0.0, 1.0
            cands = ((nx + ux / n * r, ny + uy / n * r),)
        else:
            x0, y0, x1, y1 = obs[j, 1], obs[j, 2], obs[j, 3], obs[j, 4]
            nx, ny = min(max(cx, x0), x1), min(max(cy, y0), y1)
            ux, uy = cx - nx, cy - ny
            n = math.hypot(ux, uy)
            if n > 1e-12:
                cands = ((nx + ux / n * r, ny + uy / n * r),)
            else:  # inside the box itself: out through the nearest face
                dl, dr, dd, du = cx - x0, x1 - cx, cy - y0, y1 - cy
                m = min(dl, dr, dd, du)
                if m == dl:
                    cands = ((x0 - r, cy),)
                elif m == dr:
                    cands = ((x1 + r, cy),)
                elif m == dd:
                    cands = ((cx, y0 - r),)
                else:
                    cands = ((cx, y1 + r),)
        for q in cands:
            d2 = (q[0] - px) ** 2 + (q[1] - py) ** 2
            if d2 < best_d2 and point_free(cw, q[0], q[1]):
                best_d2, bx, by = d2, q[0], q[1]
    for ring in range(1, n_rings + 1):
        rad = ring * step_m
        if rad * rad >= best_d2:
            break
        for a in range(n_angles):
            th = 2.0 * math.pi * a / n_angles
            qx, qy = cx + rad * math.cos(th), cy + rad * math.sin(th)
            d2 = (qx - px) ** 2 + (qy - py) ** 2
            if d2 < best_d2 and point_free(cw, qx, qy):
                best_d2, bx, by = d2, qx, qy
    return bx, by, best_d2 < np.inf


# --- nearest neighbour ------------------------------------------------------------------------------
@njit(cache=True)
def nearest_brute(nodes: np.ndarray, tree: np.ndarray, n: int, t: int, qx: float, qy: float) -> int:
    """Index of the node of tree ``t`` among the first ``n`` nearest to q (-1 if none)."""
    best, bi = np.inf, -1
    for i in range(n):
        if tree[i] != t:
            continue
        dx, dy = nodes[i, 0] - qx, nodes[i, 1] - qy
        d = dx * dx + dy * dy
        if d < best:
            best, bi = d, i
    return bi


@njit(cache=True)
def kd_insert(nodes: np.ndarray, kdc: np.ndarray, kdd: np.ndarray, root: int, i: int) -> None:
    """Insert node i below ``root`` of an incremental 2-d tree; kdc (n, 2) children, kdd split axis."""
    kdc[i, 0], kdc[i, 1] = -1, -1
    n = root
    while True:
        ax = kdd[n]
        side = 0 if nodes[i, ax] < nodes[n, ax] else 1
        if kdc[n, side] < 0:
            kdc[n, side] = i
            kdd[i] = 1 - ax
            return
        n = kdc[n, side]


@njit(cache=True)
def kd_nearest(
    nodes: np.ndarray, kdc: np.ndarray, kdd: np.ndarray, root: int, qx: float, qy: float, stack: np.ndarray
) -> int:  # noqa: E501
    """Nearest node to q in the 2-d tree at ``root``; ``stack`` (m, 2) is scratch space (node, bound)."""
    best, bi = np.inf, -1
    stack[0, 0], stack[0, 1] = root, 0.0
    top = 1
    while top > 0:
        top -= 1
        n, bound = int(stack[top, 0]), stack[top, 1]
        if bound >= best:
            continue
        dx, dy = nodes[n, 0] - qx, nodes[n, 1] - qy
        d = dx * dx + dy * dy
        if d < best:
            best, bi = d, n
        ax = kdd[n]
        diff = (qx if ax == 0 else qy) - nodes[n, ax]
        near, far = (kdc[n, 0], kdc[n, 1]) if diff < 0.0 else (kdc[n, 1], kdc[n, 0])
        if far >= 0 and top < stack.shape[0]:
            stack[top, 0], stack[top, 1] = far, diff * diff
            top += 1
        if near >= 0 and top < stack.shape[0]:
            stack[top, 0], stack[top, 1] = near, 0.0
            top += 1
    return bi


@njit(cache=True)
def _nearest(
    nodes: np.ndarray, tree: np.ndarray, n: int, t: int, qx: float, qy: float, nn: int,
    kdc: np.ndarray, kdd: np.ndarray, roots: np.ndarray, stack: np.ndarray,
) -> int:  # fmt: skip
    if nn == NN_KDTREE:
        return kd_nearest(nodes, kdc, kdd, roots[t], qx, qy, stack)
    return nearest_brute(nodes, tree, n, t, qx, qy)


@njit(cache=True)
def nearest_batch(nodes: np.ndarray, q: np.ndarray, nn: int, kdc: np.ndarray, kdd: np.ndarray) -> np.ndarray:
    """Nearest node (all in tree 0, KD root 0) for each query row; for measuring the two searches."""
    n = nodes.shape[0]
    tree = np.zeros(n, dtype=np.int8)
    roots = np.zeros(2, dtype=np.int32)
    stack = np.zeros((n, 2))
    out = np.empty(q.shape[0], dtype=np.int64)
    for i in range(q.shape[0]):
        out[i] = _nearest(nodes, tree, n, 0, q[i, 0], q[i, 1], nn, kdc, kdd, roots, stack)
    return out


# --- ERRT -------------------------------------------------------------------------------------------
@njit(cache=True)
def errt_grow(
    cw: CW,
    nodes: np.ndarray,
    parent: np.ndarray,
    tree: np.ndarray,
    cost: np.ndarray,
    kdc: np.ndarray,
    kdd: np.ndarray,
    roots: np.ndarray,
    stack: np.ndarray,
    state: np.ndarray,
    bridges: np.ndarray,
    rand: np.ndarray,
    waypoints: np.ndarray,
    p_goal: float,
    p_way: float,
    step: float,
    connect_r: float,
    max_ext: int,
    bidir: bool,
    max_br: int,
    extra: int,
    nn: int,
    node_limit: int,
) -> int:
    """Grow the ERRT trees (Bruce 2006 §4.3, §4.3.4) by one chunk of iterations, one row of ``rand``
    (three uniforms) per iteration.

    Tree 0 grows from the start (node 0), tree 1 holds the goal (node 1) and grows too when
    ``bidirectional``. An iteration picks a target: the other end with probability ``p_goal``, a
    cached waypoint with ``p_waypoint``, else a uniform point of the field; extends the nearest node
    of the growing tree toward it in steps of ``step_m`` up to ``max_extensions`` times (repeated
    extensions) while the swept check allows; then tries to bridge the newest node to the nearest
    node of the other tree by a straight free segment. A bridge (node of tree 0, node of tree 1) is
    stored with its path length; growth stops when ``max_bridges`` are found or ``extra_iterations``
    have passed since the first one (multi-bridge ERRT picks the shortest).

    ``p_goal``, ``p_way`` (the target probabilities), ``step`` (m), ``connect_r`` (the longest bridge,
    m), ``max_ext`` (repeated extensions), ``bidir``, ``max_br`` (bridges to collect), ``extra``
    (iterations after the first bridge) and ``nn`` (NN_BRUTE or NN_KDTREE) are ERRTParams' fields;
    ``node_limit`` is the work budget: the trees stop growing (GROW_FULL) before they would hold more
    nodes (at most the arrays' length).
    ``state = (n_nodes, n_bridges, iterations, first_bridge_iteration, waypoint_targets)``, the last
    counting the iterations that aimed at a cached waypoint. Returns a GROW_* code.
    """
    inner = cw.inner
    cap = min(node_limit, nodes.shape[0])
    n_way = waypoints.shape[0]
    for r in range(rand.shape[0]):
        if state[1] >= max_br or (state[1] > 0 and state[2] - state[3] > extra):
            return GROW_DONE
        n = state[0]
        if n + max_ext > cap:
            return GROW_FULL
        it = state[2]
        state[2] = it + 1
        t = 1 if (bidir and it % 2 == 1) else 0
        other = 1 - t
        # target: the other tree's root, a cached waypoint or a uniform point of the field
        u = rand[r, 0]
        if u < p_goal:
            tx, ty = nodes[other, 0], nodes[other, 1]
        elif u < p_goal + p_way and n_way > 0:
            w = min(n_way - 1, int(rand[r, 1] * n_way))
            state[4] += 1
            tx, ty = waypoints[w, 0], waypoints[w, 1]
        else:
            tx = inner[0] + rand[r, 1] * (inner[2] - inner[0])
            ty = inner[1] + rand[r, 2] * (inner[3] - inner[1])
        near = _nearest(nodes, tree, n, t, tx, ty, nn, kdc, kdd, roots, stack)
        cur = near
        for _ in range(max_ext):
            cx, cy = nodes[cur, 0], nodes[cur, 1]
            dx, dy = tx - cx, ty - cy
            d = math.hypot(dx, dy)
            if d < 1e-9:
                break
            s = min(step, d)
            nx, ny = cx + dx / d * s, cy + dy / d * s
            if not segment_free(cw, cx, cy, nx, ny):
                break
            k = state[0]
            nodes[k, 0], nodes[k, 1] = nx, ny
            parent[k], tree[k], cost[k] = cur, t, cost[cur] + s
            if nn == NN_KDTREE:
                kd_insert(nodes, kdc, kdd, roots[t], k)
            state[0] = k + 1
            cur = k
            if s < step:
                break
        if cur == near:
            continue
        # bridge the newest node to the other tree
        o = _nearest(nodes, tree, state[0], other, nodes[cur, 0], nodes[cur, 1], nn, kdc, kdd, roots, stack)
        if o < 0:
            continue
        gap = math.hypot(nodes[o, 0] - nodes[cur, 0], nodes[o, 1] - nodes[cur, 1])
        if gap <= connect_r and segment_free(cw, nodes[cur, 0], nodes[cur, 1], nodes[o, 0], nodes[o, 1]):
            b = state[1]
            if b >= bridges.shape[0]:
                return GROW_DONE
            a0, a1 = (cur, o) if t == 0 else (o, cur)
            bridges[b, 0], bridges[b, 1] = a0, a1
            bridges[b, 2] = cost[cur] + gap + cost[o]
            if b == 0:
                state[3] = it
            state[1] = b + 1
    if state[1] >= max_br or (state[1] > 0 and state[2] - state[3] > extra):
        return GROW_DONE
    return GROW_RUNNING


@njit(cache=True)
def resample(path: np.ndarray, spacing_m: float) -> np.ndarray:
    """The polyline's vertices plus points at most ``spacing_m`` apart along each segment."""
    n = path.shape[0]
    total = 1
    for i in range(n - 1):
        seg = math.hypot(path[i + 1, 0] - path[i, 0], path[i + 1, 1] - path[i, 1])
        total += max(1, int(math.ceil(seg / spacing_m)))
    out = np.empty((total, 2))
    out[0, 0], out[0, 1] = path[0, 0], path[0, 1]
    m = 1
    for i in range(n - 1):
        seg = math.hypot(path[i + 1, 0] - path[i, 0], path[i + 1, 1] - path[i, 1])
        parts = max(1, int(math.ceil(seg / spacing_m)))
        for p in range(1, parts + 1):
            f = p / parts
            out[m, 0] = path[i, 0] + f * (path[i + 1, 0] - path[i, 0])
            out[m, 1] = path[i, 1] + f * (path[i + 1, 1] - path[i, 1])
            m += 1
    return out


@njit(cache=True)
def cache_add(points: np.ndarray, meta: np.ndarray, pts: np.ndarray, u: np.ndarray, fifo: bool) -> int:
    """Store ``pts`` (k, 2) in the waypoint cache ``points`` (size, 2) (Bruce 2006 §4.3.3):
    ``meta = (count, next)``; while there is room a point takes the next free slot, then it replaces
    the oldest (``fifo``) or a random slot picked by the next uniform of ``u``. Returns how many
    uniforms it used."""
    size = points.shape[0]
    used = 0
    for i in range(max(0, pts.shape[0] - size), pts.shape[0]):
        if meta[0] < size:
            k = meta[0]
            meta[0] += 1
        elif fifo:
            k = meta[1]
            meta[1] = (k + 1) % size
        else:
            k = min(size - 1, int(u[used] * size))
            used += 1
        points[k, 0], points[k, 1] = pts[i, 0], pts[i, 1]
    return used


# --- smoothing --------------------------------------------------------------------------------------
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


# --- visibility graph -------------------------------------------------------------------------------
@njit(cache=True)
def vis_circles(obs: np.ndarray) -> np.ndarray:
    """The circles whose tangents make the visibility graph: each capsule's end circles and each box's
    four corner circles, all of radius R; rows (x, y, R, obstacle)."""
    k = obs.shape[0]
    out = np.empty((4 * k, 4))
    m = 0
    for j in range(k):
        r = obs[j, 5]
        if obs[j, 0] == 0.0:
            m = _put_circle(out, m, obs[j, 1], obs[j, 2], r, j)
            if obs[j, 1] != obs[j, 3] or obs[j, 2] != obs[j, 4]:
                m = _put_circle(out, m, obs[j, 3], obs[j, 4], r, j)
        else:
            m = _put_circle(out, m, obs[j, 1], obs[j, 2], r, j)
            m = _put_circle(out, m, obs[j, 3], obs[j, 2], r, j)
            m = _put_circle(out, m, obs[j, 1], obs[j, 4], r, j)
            m = _put_circle(out, m, obs[j, 3], obs[j, 4], r, j)
    return out[:m]


@njit(cache=True)
def _put_circle(out: np.ndarray, m: int, x: float, y: float, r: float, j: int) -> int:
    out[m, 0], out[m, 1], out[m, 2], out[m, 3] = x, y, r, j
    return m + 1


@njit(cache=True)
def _add_node(pts: np.ndarray, circ: np.ndarray, n: int, x: float, y: float, c: int) -> int:
    pts[n, 0], pts[n, 1] = x, y
    circ[n] = c
    return n + 1


@njit(cache=True)
def _arc_free(cw: CW, cx: float, cy: float, r: float, a0: float, a1: float, step_rad: float) -> bool:
    # the arc's own circle is at distance r, inside the tolerance; sample the arc against the rest
    n = max(1, int(math.ceil((a1 - a0) / step_rad)))
    for i in range(1, n):
        a = a0 + (a1 - a0) * i / n
        if not point_free(cw, cx + r * math.cos(a), cy + r * math.sin(a)):
            return False
    return True


@njit(cache=True)
def vis_start(cw: CW, sx: float, sy: float, gx: float, gy: float, circles: np.ndarray) -> tuple[Any, ...]:
    """The visibility graph's arrays (see :func:`visibility_graph`) holding start, goal, their straight
    edge when it is free and their point-circle tangents. Returns (pts, circ, e_a, e_b, e_w, counts)
    with counts = (nodes, edges, tangent checks)."""
    nc = circles.shape[0]
    cap = 2 + 4 * nc + 4 * nc * (nc - 1)
    pts = np.empty((cap, 2))
    circ = -np.ones(cap, dtype=np.int64)
    e_a = np.empty(cap * 2 + 1, dtype=np.int64)
    e_b = np.empty(cap * 2 + 1, dtype=np.int64)
    e_w = np.empty(cap * 2 + 1)
    n = _add_node(pts, circ, 0, sx, sy, -1)
    n = _add_node(pts, circ, n, gx, gy, -1)
    ne = 0
    checks = 1
    if segment_free(cw, sx, sy, gx, gy):
        e_a[ne], e_b[ne], e_w[ne] = 0, 1, math.hypot(gx - sx, gy - sy)
        ne += 1
    for p in range(2):
        px, py = pts[p, 0], pts[p, 1]
        for c in range(nc):
            cx, cy, r = circles[c, 0], circles[c, 1], circles[c, 2]
            d = math.hypot(px - cx, py - cy)
            if d <= r:
                continue
            base = math.atan2(py - cy, px - cx)
            half = math.acos(r / d)
            for sgn in (-1.0, 1.0):
                a = base + sgn * half
                tx, ty = cx + r * math.cos(a), cy + r * math.sin(a)
                checks += 1
                if segment_free(cw, px, py, tx, ty):
                    e_a[ne], e_b[ne], e_w[ne] = p, n, math.hypot(tx - px, ty - py)
                    ne += 1
                    n = _add_node(pts, circ, n, tx, ty, c)
    counts = np.array([n, ne, checks], dtype=np.int64)
    return pts, circ, e_a, e_b, e_w, counts


@njit(cache=True)
def vis_bitangents(
    cw: CW, circles: np.ndarray, pts: np.ndarray, circ: np.ndarray, e_a: np.ndarray, e_b: np.ndarray,
    e_w: np.ndarray, counts: np.ndarray, c_lo: int, c_hi: int,
) -> None:  # fmt: skip
    """Add the free circle-circle bitangents of the circles c1 in [c_lo, c_hi) with every later
    circle to the graph's arrays (in place; ``counts`` as :func:`vis_start`)."""
    nc = circles.shape[0]
    n, ne, checks = counts[0], counts[1], counts[2]
    # unit normal nv with nv.(C2 - C1) = r2 - r1, feet C_i - r_i nv
    for c1 in range(c_lo, min(c_hi, nc)):
        x1, y1, r1 = circles[c1, 0], circles[c1, 1], circles[c1, 2]
        for c2 in range(c1 + 1, nc):
            x2, y2, R2 = circles[c2, 0], circles[c2, 1], circles[c2, 2]
            ddx, ddy = x2 - x1, y2 - y1
            d = math.hypot(ddx, ddy)
            if d < 1e-12:
                continue
            ux, uy = ddx / d, ddy / d
            for s2 in (1.0, -1.0):
                r2 = s2 * R2
                kk = (r2 - r1) / d
                if abs(kk) > 1.0:
                    continue
                h = math.sqrt(max(0.0, 1.0 - kk * kk))
                for sg in (1.0, -1.0):
                    nx = kk * ux - sg * h * uy
                    ny = kk * uy + sg * h * ux
                    ax, ay = x1 - r1 * nx, y1 - r1 * ny
                    bx, by = x2 - r2 * nx, y2 - r2 * ny
                    checks += 1
                    if segment_free(cw, ax, ay, bx, by):
                        e_a[ne], e_b[ne], e_w[ne] = n, n + 1, math.hypot(bx - ax, by - ay)
                        ne += 1
                        n = _add_node(pts, circ, n, ax, ay, c1)
                        n = _add_node(pts, circ, n, bx, by, c2)
    counts[0], counts[1], counts[2] = n, ne, checks


@njit(cache=True)
def vis_search(
    cw: CW, circles: np.ndarray, pts: np.ndarray, circ: np.ndarray, e_a: np.ndarray, e_b: np.ndarray,
    e_w: np.ndarray, counts: np.ndarray, arc_step_rad: float,
) -> tuple[Any, ...]:  # fmt: skip
    """The free arcs between angularly consecutive tangent points on each circle, then Dijkstra from
    the start (node 0) to the goal (node 1). Returns as :func:`visibility_graph`."""
    n, ne = counts[0], counts[1]
    ang = np.zeros(n)
    for i in range(2, n):
        c = circ[i]
        ang[i] = math.atan2(pts[i, 1] - circles[c, 1], pts[i, 0] - circles[c, 0])
    order = np.argsort(circ[:n] * 10.0 + ang[:n])  # group by circle, then by angle (|angle| < 10)
    arcs_a = np.empty(n, dtype=np.int64)
    arcs_b = np.empty(n, dtype=np.int64)
    arcs_w = np.empty(n)
    na = 0
    i = 0
    while i < n:
        c = circ[order[i]]
        j = i
        while j < n and circ[order[j]] == c:
            j += 1
        if c >= 0 and j - i >= 2:
            cx, cy, r = circles[c, 0], circles[c, 1], circles[c, 2]
            for q in range(i, j):
                u = order[q]
                v = order[q + 1] if q + 1 < j else order[i]
                a0 = ang[u]
                span = (ang[v] - a0) % (2.0 * math.pi)  # counter-clockwise from u to v
                if _arc_free(cw, cx, cy, r, a0, a0 + span, arc_step_rad):
                    arcs_a[na], arcs_b[na], arcs_w[na] = u, v, r * span
                    na += 1
        i = j
    # adjacency (CSR), both directions
    total = ne + na
    ea = np.concatenate((e_a[:ne], arcs_a[:na]))
    eb = np.concatenate((e_b[:ne], arcs_b[:na]))
    ew = np.concatenate((e_w[:ne], arcs_w[:na]))
    deg = np.zeros(n + 1, dtype=np.int64)
    for e in range(total):
        deg[ea[e] + 1] += 1
        deg[eb[e] + 1] += 1
    start = np.cumsum(deg)
    fill = start[:-1].copy()
    adj = np.empty(2 * total, dtype=np.int64)
    adw = np.empty(2 * total)
    for e in range(total):
        adj[fill[ea[e]]], adw[fill[ea[e]]] = eb[e], ew[e]
        fill[ea[e]] += 1
        adj[fill[eb[e]]], adw[fill[eb[e]]] = ea[e], ew[e]
        fill[eb[e]] += 1
    dist, prev = astar(cw, pts[:n], start, adj, adw, 0, 1, np.ones(2 * total, dtype=np.int8))
    route = route_to(prev, 1) if dist[1] < np.inf else np.empty(0, dtype=np.int64)
    return dist[1], pts[:n].copy(), circ[:n].copy(), ang, route, circles, dist


@njit(cache=True)
def visibility_graph(cw: CW, sx: float, sy: float, gx: float, gy: float, arc_step_rad: float) -> tuple[Any, ...]:
    """Shortest path among the grown obstacles by the reduced visibility graph with exact tangents
    (Bruce 2006 §4.3.5 uses it as ERRT's optimum reference), in one call: :func:`vis_start`,
    :func:`vis_bitangents` over all circles, :func:`vis_search` (the planner runs the middle step in
    chunks to honour its termination).

    Nodes: start, goal and the tangent points of every free tangent segment between start, goal and
    the obstacle circles (point-circle: two, circle-circle: four bitangents). Edges: the free
    tangent segments and, on every circle, the arcs between angularly consecutive tangent points
    that no other obstacle covers (checked every ``arc_step_rad``). Dijkstra gives the exact length.

    Returns (cost_m, node_xy (n, 2), node_circle (n,), node_angle (n,), route (m,) node indices,
    circles (c, 4), distance from the start (n,)); cost is inf when there is no path."""
    circles = vis_circles(cw.obs)
    pts, circ, e_a, e_b, e_w, counts = vis_start(cw, sx, sy, gx, gy, circles)
    vis_bitangents(cw, circles, pts, circ, e_a, e_b, e_w, counts, 0, circles.shape[0])
    return vis_search(cw, circles, pts, circ, e_a, e_b, e_w, counts, arc_step_rad)


@njit(cache=True)
def route_to(prev: np.ndarray, dst: int) -> np.ndarray:
    """The node sequence from the source to ``dst`` along ``prev`` links."""
    m = 1
    v = dst
    while prev[v] >= 0:
        v = prev[v]
        m += 1
    out = np.empty(m, dtype=np.int64)
    v = dst
    for k in range(m - 1, -1, -1):
        out[k] = v
        v = prev[v]
    return out


# --- roadmap (dynamic PRM) --------------------------------------------------------------------------
@njit(cache=True)
def connect_sectors(
    cw: CW, pts: np.ndarray, first_new: int, n_sectors: int, radius_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Dynamic PRM connection by radial directions (Bruce 2006 §4.4): every node from ``first_new`` on
    links, in each of ``n_sectors`` equal angular sectors around it, to the nearest node within
    ``radius_m`` that it sees free. Returns the new undirected edges (a, b) and their lengths."""
    n = pts.shape[0]
    best = np.empty(n_sectors, dtype=np.int64)
    bestd = np.empty(n_sectors)
    ea = np.empty((max(1, (n - first_new)) * n_sectors, 2), dtype=np.int64)
    ew = np.empty(max(1, (n - first_new)) * n_sectors)
    m = 0
    r2 = radius_m * radius_m
    for i in range(first_new, n):
        best[:] = -1
        bestd[:] = np.inf
        for j in range(n):
            if j == i:
                continue
            dx, dy = pts[j, 0] - pts[i, 0], pts[j, 1] - pts[i, 1]
            d2 = dx * dx + dy * dy
            if d2 > r2:
                continue
            s = int((math.atan2(dy, dx) + math.pi) / (2.0 * math.pi) * n_sectors) % n_sectors
            if d2 < bestd[s]:
                bestd[s], best[s] = d2, j
        for s in range(n_sectors):
            j = best[s]
            if j < 0:
                continue
            if segment_free(cw, pts[i, 0], pts[i, 1], pts[j, 0], pts[j, 1]):
                ea[m, 0], ea[m, 1], ew[m] = i, j, math.sqrt(bestd[s])
                m += 1
    return ea[:m].copy(), ew[:m].copy()


@njit(cache=True)
def astar(
    cw: CW, pts: np.ndarray, start: np.ndarray, adj: np.ndarray, w: np.ndarray, src: int, dst: int, edge_ok: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A* over a CSR graph whose nodes are field points, with the straight-line distance as the
    heuristic (admissible: no path is shorter). Lazy validation for the roadmap (dynamic PRM): an
    edge whose ``edge_ok`` is 0 (unknown) is swept-checked against ``cw`` only when the search first
    relaxes it, and its node point-checked, the verdict kept (1 free, 2 blocked); edges marked 1 from
    the start (the visibility graph's) are never checked. Returns (cost from src, predecessor)."""
    n = pts.shape[0]
    gx, gy = pts[dst, 0], pts[dst, 1]
    g = np.full(n, np.inf)
    prev = -np.ones(n, dtype=np.int64)
    done = np.zeros(n, dtype=np.bool_)
    node_ok = np.zeros(n, dtype=np.int8)  # 0 unknown, 1 free, 2 blocked
    g[src] = 0.0
    heap = [(math.hypot(pts[src, 0] - gx, pts[src, 1] - gy), src)]
    while heap:
        _f, u = heapq.heappop(heap)
        if done[u]:
            continue
        done[u] = True
        if u == dst:
            break
        for e in range(start[u], start[u + 1]):
            v = adj[e]
            nd = g[u] + w[e]
            if done[v] or nd >= g[v]:
                continue
            if edge_ok[e] == 0:
                if node_ok[v] == 0:
                    node_ok[v] = 1 if point_free(cw, pts[v, 0], pts[v, 1]) else 2
                free = node_ok[v] == 1 and segment_free(cw, pts[u, 0], pts[u, 1], pts[v, 0], pts[v, 1])
                edge_ok[e] = 1 if free else 2
            if edge_ok[e] == 2:
                continue
            g[v] = nd
            prev[v] = u
            heapq.heappush(heap, (nd + math.hypot(pts[v, 0] - gx, pts[v, 1] - gy), v))
    return g, prev


# --- generic graph search (road maps and cell decompositions) ---------------------------------------
SEARCH_BFS = 0  # first in, first out: the fewest edges
SEARCH_DFS = 1  # last in, first out: the first path found
SEARCH_BEST_FIRST = 2  # greedy: the node nearest to the goal first (straight-line distance)
SEARCH_DIJKSTRA = 3  # the lowest cost from the source first
SEARCH_ASTAR = 4  # cost from the source plus the straight-line distance to the goal

FRONTIER_HEAD = 0  # slots of a search's ``counters``: the frontier's first entry (first in, first out),
FRONTIER_SIZE = 1  # one past its last entry (or the heap's size),
EXPANDED = 2  # the nodes expanded so far

# the neighbours of a grid cell (row, column), in the order both the grid graph and the grid search
# take them: the four sides, then the four corners
GRID_DI = np.array([0, 1, 0, -1, 1, 1, -1, -1])
GRID_DK = np.array([1, 0, -1, 0, 1, -1, 1, -1])


HEAP_ARITY = 4  # children per heap node: a shallower heap than a binary one, and its children side by side


@njit(cache=True, inline="always")
def _heap_push(heap: np.ndarray, size: int, k: float, v: int) -> int:
    """Push node v with key k on the 4-ary min-heap ``heap[:size]`` of (key, node) rows (the node a
    float, exact below 2**53: key and node in one cache line); returns the new size (a node may be
    in it more than once: a search skips the stale entries of expanded nodes)."""
    j = size
    while j > 0:
        parent = (j - 1) // HEAP_ARITY
        if heap[parent, 0] <= k:
            break
        heap[j, 0], heap[j, 1] = heap[parent, 0], heap[parent, 1]  # the hole moves up, the parent down
        j = parent
    heap[j, 0], heap[j, 1] = k, v
    return size + 1


@njit(cache=True, inline="always")
def _heap_pop(heap: np.ndarray, size: int) -> tuple[int, int]:
    """Remove the least key's node; returns (node, new size)."""
    top = int(heap[0, 1])
    size -= 1
    k, v = heap[size, 0], heap[size, 1]  # the last entry fills the hole that sinks from the root
    i = 0
    while True:
        first = HEAP_ARITY * i + 1
        if first >= size:
            break
        m, km = first, heap[first, 0]
        for c in range(first + 1, min(first + HEAP_ARITY, size)):
            if heap[c, 0] < km:
                m, km = c, heap[c, 0]
        if km >= k:
            break
        heap[i, 0], heap[i, 1] = km, heap[m, 1]
        i = m
    heap[i, 0], heap[i, 1] = k, v
    return top, size


@njit(cache=True, inline="always")
def _to_goal(dx: float, dy: float, octile: bool) -> float:
    """The heuristic distance over (dx, dy) to the goal: the straight line, or on a grid of axis and
    diagonal moves the octile distance (the unobstructed shortest path there, tighter)."""
    dx, dy = abs(dx), abs(dy)
    if octile:
        return max(dx, dy) + (math.sqrt(2.0) - 1.0) * min(dx, dy)
    return math.hypot(dx, dy)


@njit(cache=True, inline="always")
def _pop(mode: int, frontier: np.ndarray, head: int, size: int) -> tuple[int, int, int]:
    """The frontier's next node by ``mode``: (node, head, size)."""
    if mode == SEARCH_BFS:
        return int(frontier[head, 1]), head + 1, size
    if mode == SEARCH_DFS:
        return int(frontier[size - 1, 1]), head, size - 1
    u, size = _heap_pop(frontier, size)
    return u, head, size


@njit(cache=True, inline="always")
def _reach(mode: int, v: int, u: int, nd: float, dx: float, dy: float, octile: bool, g: np.ndarray,
           prev: np.ndarray, frontier: np.ndarray, size: int) -> int:  # fmt: skip
    """Node u reaches its neighbour v at cost ``nd``: record it and put v on the frontier as ``mode``
    does ((dx, dy): v's offset from the goal, for the heuristic). Returns the frontier's new size."""
    if mode == SEARCH_DIJKSTRA or mode == SEARCH_ASTAR:
        if nd >= g[v]:
            return size
        g[v], prev[v] = nd, u
        return _heap_push(frontier, size, nd + (_to_goal(dx, dy, octile) if mode == SEARCH_ASTAR else 0.0), v)
    if mode == SEARCH_DFS:
        g[v], prev[v] = nd, u  # the latest push is popped first: its parent is the tree's
        frontier[size, 1] = v
        return size + 1
    if g[v] != np.inf:  # breadth- and best-first: a node's parent is the one that found it
        return size
    g[v], prev[v] = nd, u
    if mode == SEARCH_BFS:
        frontier[size, 1] = v
        return size + 1
    return _heap_push(frontier, size, _to_goal(dx, dy, octile), v)


@njit(cache=True)
def graph_search(
    pts: np.ndarray, indptr: np.ndarray, adj: np.ndarray, w: np.ndarray, free: np.ndarray, res: float,
    connectivity: int, dst: int, mode: int, octile: bool, g: np.ndarray, prev: np.ndarray, closed: np.ndarray,
    frontier: np.ndarray, counters: np.ndarray, max_expand: int,
) -> int:  # fmt: skip
    """Run a graph search until ``dst`` is expanded, the frontier is empty or ``max_expand`` more
    nodes have been expanded, over either graph:

    * a CSR graph (``free`` empty): nodes ``pts`` (n, 2) in metres, node u's edges
      ``adj[indptr[u]:indptr[u + 1]]`` with lengths ``w``; ``octile``: the heuristic of a grid graph
      (:func:`_to_goal`);
    * a uniform grid (``free`` (ny, nx) with a border of blocked cells all round, the other graph
      arrays empty): the graph :func:`grid_graph` makes of it, without building it: node i * nx + k
      is cell (i, k), its neighbours the free cells around it in the order GRID_DI/GRID_DK
      (``connectivity`` of them), at ``res`` or its diagonal; the heuristic is the octile distance.

    The state lives in the arrays the caller made (:func:`cmdragons.planning.graphsearch.search`):
    ``g`` the cost from the source along ``prev``, ``closed`` the expanded nodes, the frontier
    ``frontier`` of (key, node) rows (a heap for the ordered modes, a queue or a stack of its nodes
    for breadth- and depth-first) and ``counters`` (FRONTIER_HEAD, FRONTIER_SIZE, EXPANDED), so that a search resumes
    where it stopped. ``mode`` is one of the SEARCH_* constants. Returns 1 when ``dst`` was reached,
    0 when the frontier ran empty, -1 when the expansion budget stopped it."""
    grid = free.shape[0] > 0
    ny, nx = free.shape
    cells = free.ravel()
    step = GRID_DI * nx + GRID_DK  # a neighbour's offset in the flat grid
    if grid:
        gx, gy = (dst % nx) * res, (dst // nx) * res
    else:
        gx, gy = pts[dst, 0], pts[dst, 1]
    head, size = counters[FRONTIER_HEAD], counters[FRONTIER_SIZE]
    diag = math.sqrt(2.0) * res
    expanded = 0
    outcome = 0
    while head < size:
        if expanded >= max_expand:
            outcome = -1
            break
        u, head, size = _pop(mode, frontier, head, size)
        if closed[u]:
            continue
        closed[u] = True
        expanded += 1
        if u == dst:
            outcome = 1
            break
        gu = g[u]
        if grid:
            ui, uk = u // nx, u % nx
            for d in range(connectivity):
                v = u + step[d]  # the blocked border keeps every neighbour of a free cell inside the grid
                if not cells[v] or closed[v]:
                    continue
                size = _reach(mode, v, u, gu + (res if d < 4 else diag), (uk + GRID_DK[d]) * res - gx,
                              (ui + GRID_DI[d]) * res - gy, True, g, prev, frontier, size)  # fmt: skip
        else:
            for e in range(indptr[u], indptr[u + 1]):
                v = adj[e]
                if closed[v]:
                    continue
                size = _reach(mode, v, u, gu + w[e], pts[v, 0] - gx, pts[v, 1] - gy, octile, g, prev, frontier, size)
    counters[FRONTIER_HEAD], counters[FRONTIER_SIZE] = head, size
    counters[EXPANDED] += expanded
    return outcome


# --- A* and Dijkstra on a uniform grid: exact keys in a radix heap ----------------------------------
# On a grid of axis moves (1) and diagonal moves (sqrt 2) a cost is a + b sqrt 2 with whole a and b,
# and so is the octile heuristic: the search keeps the two counts, so that equal keys are equal
# floats and a key is never below the last one taken (the heuristic is consistent), which is what a
# radix heap needs (Ahuja, Mehlhorn, Orlin and Tarjan 1990). Two different keys a + b sqrt 2 of a
# grid under a million cells across lie at least 1e-7 apart, far beyond the floats' rounding, so
# the floats' order is the keys' order.
RADIX_BUCKETS = 65  # bucket 0: keys equal to the last one taken; bucket k: highest bit k differs
GRID_LAST = 0  # slots of a grid search's ``counters``: the last key taken (its bits, as int64),
GRID_POOL = 1  # entries used in the heap's pool,
# (EXPANDED, slot 2, as for graph_search)


@njit(cache=True, inline="always")
def _bit_length(x: np.uint64) -> int:
    """The number of bits of ``x`` (0 for 0)."""
    n = 0
    for shift in (32, 16, 8, 4, 2, 1):
        if x >> np.uint64(shift):
            x >>= np.uint64(shift)
            n += shift
    return n + int(x)


@njit(cache=True, inline="always")
def _radix_put(bits: np.ndarray, nxt: np.ndarray, head: np.ndarray, i: int, last: np.uint64) -> None:
    """Link pool entry ``i`` (its key's bits ``bits[i]``) into its bucket for the last key ``last``."""
    x = bits[i] ^ last
    b = _bit_length(x) if x else 0
    nxt[i] = head[b]
    head[b] = i


@njit(cache=True)
def grid_astar(
    state: np.ndarray, nx: int, dst: int, heuristic: bool, connectivity: int, ga: np.ndarray, gb: np.ndarray,
    prev: np.ndarray, key: np.ndarray, node: np.ndarray, nxt: np.ndarray, head: np.ndarray, counters: np.ndarray,
    max_expand: int,
) -> int:  # fmt: skip
    """A* (``heuristic``: the octile distance, consistent on 4 and 8 neighbours) or Dijkstra on the
    graph :func:`graph_search` searches on a grid, in cell lengths, until ``dst`` is expanded, the
    heap runs empty or ``max_expand`` more cells have been expanded.

    ``state`` (flat, rows of ``nx`` with a blocked border all round): 1 for a free cell not yet
    expanded, 0 for a blocked or expanded one. A cell's cost from the source is ``ga + gb * sqrt 2``
    (axis and diagonal moves; ``ga`` -1: not reached), ``prev`` its parent. The heap's entries are a
    pool of (``key``, ``node``) linked into ``head``'s buckets by ``nxt``; ``counters`` as GRID_*
    and EXPANDED, so that a search resumes where it stopped. Keys equal to the last one taken sit
    in bucket 0, taken last in first out: a move that keeps the key (straight toward the goal) is
    expanded next. Returns 1 when ``dst`` was reached, 0 when the heap ran empty, -1 when the budget
    stopped it."""
    sq2 = math.sqrt(2.0)
    bits = key.view(np.uint64)
    gx, gy = dst % nx, dst // nx
    last = np.uint64(counters[GRID_LAST])
    pool = counters[GRID_POOL]
    expanded = 0
    outcome = 0
    while True:
        if head[0] < 0:  # the bucket of the least higher bit: its least key is the next last
            b = 1
            while b < RADIX_BUCKETS and head[b] < 0:
                b += 1
            if b == RADIX_BUCKETS:
                break
            i = head[b]
            least = bits[i]
            while i >= 0:
                least = min(least, bits[i])
                i = nxt[i]
            last = least
            i = head[b]
            head[b] = -1
            while i >= 0:  # every entry of the bucket moves to a lower one
                after = nxt[i]
                _radix_put(bits, nxt, head, i, last)
                i = after
        if expanded >= max_expand:
            outcome = -1
            break
        i = head[0]
        head[0] = nxt[i]
        u = node[i]
        if state[u] == 0:  # a stale entry of an expanded cell
            continue
        state[u] = 0
        expanded += 1
        if u == dst:
            outcome = 1
            break
        au, bu = ga[u], gb[u]
        ui = u // nx
        uk = u - ui * nx
        ex, ey = uk - gx, ui - gy
        for d in range(connectivity):
            v = u + GRID_DI[d] * nx + GRID_DK[d]  # the blocked border keeps it inside the grid
            if state[v] == 0:
                continue
            a, b = (au + 1, bu) if d < 4 else (au, bu + 1)
            if ga[v] >= 0 and a + b * sq2 >= ga[v] + gb[v] * sq2:
                continue
            ga[v], gb[v], prev[v] = a, b, u
            ka, kb = a, b
            if heuristic:  # the octile distance: |dx - dy| axis moves and min(dx, dy) diagonal ones
                dx, dy = abs(ex + GRID_DK[d]), abs(ey + GRID_DI[d])
                ka, kb = a + abs(dx - dy), b + min(dx, dy)
            key[pool], node[pool] = ka + kb * sq2, v
            _radix_put(bits, nxt, head, pool, last)
            pool += 1
    counters[GRID_LAST], counters[GRID_POOL] = np.int64(last), pool
    counters[EXPANDED] += expanded
    return outcome


@njit(cache=True)
def grid_graph(free: np.ndarray, x0: float, y0: float, res: float, connectivity: int) -> tuple[
        np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """The connectivity graph of a uniform grid's free cells (``free`` (ny, nx), cell (i, k) centred at
    x0 + (k + 1/2) res, y0 + (i + 1/2) res): 4 or 8 neighbours, edges weighted by the centres'
    distance. Returns (node of each cell or -1 (ny, nx), centres (n, 2), CSR indptr, adj, lengths)."""
    ny, nx = free.shape
    node = -np.ones((ny, nx), dtype=np.int64)
    n = 0
    for i in range(ny):
        for k in range(nx):
            if free[i, k]:
                node[i, k] = n
                n += 1
    pts = np.empty((n, 2))
    di, dk = GRID_DI, GRID_DK
    indptr = np.zeros(n + 1, dtype=np.int64)
    adj = np.empty(n * connectivity, dtype=np.int64)
    w = np.empty(n * connectivity)
    diag = math.sqrt(2.0) * res
    m = 0
    for i in range(ny):
        for k in range(nx):
            u = node[i, k]
            if u < 0:
                continue
            pts[u, 0], pts[u, 1] = x0 + (k + 0.5) * res, y0 + (i + 0.5) * res
            for d in range(connectivity):
                ii, kk = i + di[d], k + dk[d]
                if 0 <= ii < ny and 0 <= kk < nx and node[ii, kk] >= 0:
                    adj[m] = node[ii, kk]
                    w[m] = res if d < 4 else diag
                    m += 1
            indptr[u + 1] = m
    return node, pts, indptr, adj[:m], w[:m]
