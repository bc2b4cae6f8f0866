"""numba kernels of graph search over road maps, cell decompositions and uniform grids: the generic
search (BFS, DFS, best-first, Dijkstra, A*) on a CSR graph, A* with lazy edge validation over field
points (the roadmap's and the visibility graph's), exact A* and Dijkstra on a grid in a radix
heap, the grid's connectivity graph, and the route back along the predecessor links."""

from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

from cmdragons.planning.collision import CW, point_free, segment_free


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
           prev: np.ndarray, frontier: np.ndarray, size: int) -> int:
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
) -> int:
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
                              (ui + GRID_DI[d]) * res - gy, True, g, prev, frontier, size)
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
) -> int:
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
        np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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
