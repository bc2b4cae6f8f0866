"""numba kernels of the collision world: distance primitives, clearance and its gradient, the broad
phases and the swept-segment queries. The one distance query of planners, navigators and safety, so
public: navigation and safety call these kernels from their own (references in
:mod:`cmdragons.planning.collision_reference`).

Everything here works in the field frame (metres) on plain numpy arrays. A compiled collision world
("cw") is one named tuple (:class:`CW`), built by :mod:`cmdragons.planning.world`, for one robot
radius and time window:

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

import math
from typing import NamedTuple

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
def away(obs: np.ndarray, j: int, px: float, py: float) -> tuple[float, float]:
    """The unit direction in which the clearance of a robot centre at p from obstacle j grows fastest
    ((0, 0) on a capsule's core, where every direction is as good)."""
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
            gx, gy = away(obs, j, px, py)
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
) -> np.ndarray:
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
) -> CW:
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
