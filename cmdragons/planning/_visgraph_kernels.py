"""numba kernels of the visibility graph among grown obstacles: the tangent circles, the bitangents
between them, the free arcs and Dijkstra from start to goal."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from cmdragons.planning._graphsearch_kernels import astar, route_to
from cmdragons.planning.collision import CW, point_free, segment_free


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
) -> None:
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
) -> tuple[Any, ...]:
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
