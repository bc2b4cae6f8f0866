"""numba kernels of ERRT (Bruce 2006 §4.3): nearest neighbour (brute force or an incremental 2-d
tree), the growth of the two trees, and the waypoint cache (references in
:mod:`cmdragons.planning._errt_reference`)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons.planning.collision import CW, segment_free

NN_BRUTE = 0
NN_KDTREE = 1

# ERRT kernel return codes
GROW_RUNNING = 0  # the iteration chunk is used up; call again
GROW_DONE = 1  # enough bridges between the trees (or to the goal)
GROW_FULL = 2  # the node budget is used up

# the growth's counters: slots of ``Trees.counts`` (int64), always read and written by these names
N_NODES = 0  # nodes in the two trees
N_BRIDGES = 1  # bridges found
ITERATIONS = 2  # iterations run
FIRST_BRIDGE_AT = 3  # the iteration that found the first bridge
WAYPOINT_TARGETS = 4  # iterations that aimed at a cached waypoint
N_COUNTS = 5


class Trees(NamedTuple):
    """The two ERRT trees, grown in place by :func:`errt_grow`: room for ``len(nodes)`` nodes, tree 0
    rooted at the start (node 0), tree 1 at the goal (node 1)."""

    nodes: np.ndarray  # (cap, 2) node positions, m
    parent: np.ndarray  # (cap,) int32 parent node, -1 at a root
    tree: np.ndarray  # (cap,) int8 the node's tree
    cost: np.ndarray  # (cap,) path length from the node's root, m
    kdc: np.ndarray  # (cap, 2) int32 children in the incremental 2-d tree, -1 for none
    kdd: np.ndarray  # (cap,) int32 the 2-d tree's split axis at the node
    roots: np.ndarray  # (2,) int32 each tree's 2-d tree root
    stack: np.ndarray  # (cap, 2) scratch space of the 2-d tree search
    counts: np.ndarray  # (N_COUNTS,) int64 counters, slots N_NODES ... WAYPOINT_TARGETS
    bridges: np.ndarray  # (max bridges, 3) node of tree 0, node of tree 1, path length m


class GrowConfig(NamedTuple):
    """ERRTParams' fields as the growth kernel takes them."""

    p_goal: float  # probability of aiming at the other tree's root
    p_waypoint: float  # ... at a cached waypoint (0 without the cache)
    step_m: float  # extension step
    connect_radius_m: float  # the longest bridge
    max_extensions: int  # repeated extensions toward one target
    bidirectional: bool  # the goal's tree grows too
    max_bridges: int  # bridges to collect
    extra_iterations: int  # iterations after the first bridge
    nearest: int  # NN_BRUTE or NN_KDTREE



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
) -> int:
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
def _grown_enough(counts: np.ndarray, cfg: GrowConfig) -> bool:
    return bool(counts[N_BRIDGES] >= cfg.max_bridges
                or (counts[N_BRIDGES] > 0 and counts[ITERATIONS] - counts[FIRST_BRIDGE_AT] > cfg.extra_iterations))


@njit(cache=True)
def errt_grow(cw: CW, trees: Trees, rand: np.ndarray, waypoints: np.ndarray, cfg: GrowConfig, node_limit: int) -> int:
    """Grow the ERRT trees (Bruce 2006 §4.3, §4.3.4) by one chunk of iterations, one row of ``rand``
    (three uniforms) per iteration.

    Tree 0 grows from the start (node 0), tree 1 holds the goal (node 1) and grows too when
    ``cfg.bidirectional``. An iteration picks a target: the other end with probability ``p_goal``, a
    cached waypoint of ``waypoints`` with ``p_waypoint``, else a uniform point of the field; extends
    the nearest node of the growing tree toward it in steps of ``step_m`` up to ``max_extensions``
    times (repeated extensions) while the swept check allows; then tries to bridge the newest node
    to the nearest node of the other tree by a straight free segment no longer than
    ``connect_radius_m``. A bridge (node of tree 0, node of tree 1) is stored with its path length;
    growth stops when ``max_bridges`` are found or ``extra_iterations`` have passed since the first
    one (multi-bridge ERRT picks the shortest).

    ``node_limit`` is the work budget: the trees stop growing (GROW_FULL) before they would hold more
    nodes (at most the arrays' length). ``trees.counts`` keeps the counters (N_NODES, N_BRIDGES,
    ITERATIONS, FIRST_BRIDGE_AT, WAYPOINT_TARGETS) across chunks. Returns a GROW_* code.
    """
    nodes, parent, tree, cost = trees.nodes, trees.parent, trees.tree, trees.cost
    kdc, kdd, roots, stack = trees.kdc, trees.kdd, trees.roots, trees.stack
    counts, bridges = trees.counts, trees.bridges
    p_goal, p_way, step, nn = cfg.p_goal, cfg.p_waypoint, cfg.step_m, cfg.nearest
    inner = cw.inner
    cap = min(node_limit, nodes.shape[0])
    n_way = waypoints.shape[0]
    for r in range(rand.shape[0]):
        if _grown_enough(counts, cfg):
            return GROW_DONE
        n = counts[N_NODES]
        if n + cfg.max_extensions > cap:
            return GROW_FULL
        it = counts[ITERATIONS]
        counts[ITERATIONS] = it + 1
        t = 1 if (cfg.bidirectional and it % 2 == 1) else 0
        other = 1 - t
        # target: the other tree's root, a cached waypoint or a uniform point of the field
        u = rand[r, 0]
        if u < p_goal:
            tx, ty = nodes[other, 0], nodes[other, 1]
        elif u < p_goal + p_way and n_way > 0:
            w = min(n_way - 1, int(rand[r, 1] * n_way))
            counts[WAYPOINT_TARGETS] += 1
            tx, ty = waypoints[w, 0], waypoints[w, 1]
        else:
            tx = inner[0] + rand[r, 1] * (inner[2] - inner[0])
            ty = inner[1] + rand[r, 2] * (inner[3] - inner[1])
        near = _nearest(nodes, tree, n, t, tx, ty, nn, kdc, kdd, roots, stack)
        cur = near
        for _ in range(cfg.max_extensions):
            cx, cy = nodes[cur, 0], nodes[cur, 1]
            dx, dy = tx - cx, ty - cy
            d = math.hypot(dx, dy)
            if d < 1e-9:
                break
            s = min(step, d)
            nx, ny = cx + dx / d * s, cy + dy / d * s
            if not segment_free(cw, cx, cy, nx, ny):
                break
            k = counts[N_NODES]
            nodes[k, 0], nodes[k, 1] = nx, ny
            parent[k], tree[k], cost[k] = cur, t, cost[cur] + s
            if nn == NN_KDTREE:
                kd_insert(nodes, kdc, kdd, roots[t], k)
            counts[N_NODES] = k + 1
            cur = k
            if s < step:
                break
        if cur == near:
            continue
        # bridge the newest node to the other tree
        o = _nearest(nodes, tree, counts[N_NODES], other, nodes[cur, 0], nodes[cur, 1], nn, kdc, kdd, roots, stack)
        if o < 0:
            continue
        gap = math.hypot(nodes[o, 0] - nodes[cur, 0], nodes[o, 1] - nodes[cur, 1])
        if gap <= cfg.connect_radius_m and segment_free(cw, nodes[cur, 0], nodes[cur, 1], nodes[o, 0], nodes[o, 1]):
            b = counts[N_BRIDGES]
            if b >= bridges.shape[0]:
                return GROW_DONE
            a0, a1 = (cur, o) if t == 0 else (o, cur)
            bridges[b, 0], bridges[b, 1] = a0, a1
            bridges[b, 2] = cost[cur] + gap + cost[o]
            if b == 0:
                counts[FIRST_BRIDGE_AT] = it
            counts[N_BRIDGES] = b + 1
    if _grown_enough(counts, cfg):
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
