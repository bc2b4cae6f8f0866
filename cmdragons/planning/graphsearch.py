"""Graph search over road maps and connectivity graphs: breadth-first, depth-first, best-first,
Dijkstra and A* (the lecture notes' "path / graph search strategies", seed 001).

Field frame, metres. A :class:`Graph` is nodes at field points with undirected edges weighted by
their length, held as CSR arrays; every road map (Voronoi, visibility) and every cell decomposition
(trapezoidal, uniform grid, quadtree) hands its graph to :func:`search`. What each search returns:

* ``bfs``: the route with the fewest edges (its cost is that route's length, not the least);
* ``dfs``: the first route depth-first finds (any route; the least cost only by chance);
* ``best_first``: greedy on the straight-line distance to the goal (fast, not optimal);
* ``dijkstra`` and ``astar``: the least-cost route (A*'s straight-line heuristic is admissible and
  consistent on graphs whose edge weights are at least the distance of their ends; on a grid graph
  of axis and diagonal moves it takes the octile distance, which is too).

Work (a termination's unit): nodes expanded. The search runs in chunks of ``chunk`` expansions
(:func:`cmdragons.planning._graphsearch_kernels.graph_search`), checking the termination between them.
:func:`grid_search` is the same search on a uniform grid's graph without building it (the cells'
neighbours found by index), for large grids.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.planning import _graphsearch_kernels as K
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CompiledWorld

__all__ = ["SEARCHES", "Graph", "SearchResult", "SearchStatus", "grid_search", "link_point", "search"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

SEARCHES: dict[str, int] = {
    "bfs": K.SEARCH_BFS,
    "dfs": K.SEARCH_DFS,
    "best_first": K.SEARCH_BEST_FIRST,
    "dijkstra": K.SEARCH_DIJKSTRA,
    "astar": K.SEARCH_ASTAR,
}
CHUNK = 4096  # expansions between two termination checks
GRID_CHUNK = 16384  # the same for Dijkstra and A* on a grid (about a millisecond of expansions)
# the kernel's arrays of the graph it is not searching (a CSR graph or a grid)
_NO_GRID = np.zeros((0, 0), dtype=np.bool_)
_NO_POINTS = np.zeros((0, 2))
_NO_INDEX = np.zeros(0, dtype=np.int64)
_NO_WEIGHTS = np.zeros(0)


@dataclass(frozen=True, eq=False)
class Graph:
    """Nodes ``pts`` (n, 2) and CSR adjacency: node u's neighbours ``adj[indptr[u]:indptr[u + 1]]``
    at edge lengths ``w`` (both directions of every undirected edge are stored)."""

    pts: FloatArray
    indptr: IntArray
    adj: IntArray
    w: FloatArray
    # a grid graph of axis and diagonal moves (weights their lengths): A* and best-first take the
    # octile distance to the goal, the unobstructed shortest path there, for the straight line
    octile: bool = False

    @property
    def n(self) -> int:
        return int(self.pts.shape[0])

    @staticmethod
    def from_edges(pts: FloatArray, edges: IntArray, weights: FloatArray | None = None) -> Graph:
        """The graph of undirected ``edges`` (m, 2) between ``pts``; ``weights`` default to the
        edges' lengths."""
        pts = np.ascontiguousarray(pts, dtype=np.float64).reshape(-1, 2)
        e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        wt = np.hypot(*(pts[e[:, 1]] - pts[e[:, 0]]).T) if weights is None else np.asarray(weights, np.float64)
        a = np.concatenate([e[:, 0], e[:, 1]])
        b = np.concatenate([e[:, 1], e[:, 0]])
        ww = np.concatenate([wt, wt])
        order = np.argsort(a, kind="stable")
        indptr = np.zeros(len(pts) + 1, dtype=np.int64)
        np.add.at(indptr, a + 1, 1)
        return Graph(pts, np.cumsum(indptr), b[order], ww[order])

    def with_links(self, point: tuple[float, float], nodes: IntArray, lengths: FloatArray) -> Graph:
        """This graph plus one node at ``point`` (its index is the old ``n``) linked both ways to the
        distinct ``nodes`` at ``lengths``; the old edges keep their order, each back edge goes last
        in its node's row."""
        n, m = self.n, len(self.adj)
        count = np.diff(self.indptr)
        grown = count.copy()
        grown[nodes] += 1
        indptr = np.zeros(n + 2, dtype=np.int64)
        indptr[1:-1] = np.cumsum(grown)
        indptr[-1] = indptr[-2] + len(nodes)
        adj = np.empty(indptr[-1], dtype=np.int64)
        w = np.empty(indptr[-1])
        old_pos = np.repeat(indptr[:n], count) + (np.arange(m) - np.repeat(self.indptr[:n], count))
        adj[old_pos], w[old_pos] = self.adj, self.w
        back = indptr[nodes + 1] - 1
        adj[back], w[back] = n, lengths
        adj[indptr[n] :], w[indptr[n] :] = nodes, lengths
        return Graph(np.vstack([self.pts, [point]]), indptr, adj, w, self.octile)


class SearchStatus(enum.Enum):
    FOUND = "found"
    UNREACHABLE = "unreachable"  # the source's component does not hold the goal
    STOPPED = "stopped"  # the termination came first


@dataclass(frozen=True)
class SearchResult:
    """``route``: node indices from the source to the goal (empty unless FOUND); ``cost``: its length
    (inf unless FOUND); ``expanded``: nodes expanded."""

    status: SearchStatus
    route: IntArray
    cost: float
    expanded: int


class _Frontier:
    """The state of one search: costs, parents, expanded marks and the frontier arrays (sized for
    ``n`` nodes and ``m`` directed edges), as the kernels take them."""

    def __init__(self, n: int, m: int, src: int, mode: int) -> None:
        self.g = np.full(n, np.inf)
        self.prev = np.full(n, -1, dtype=np.int32)
        self.closed = np.zeros(n, dtype=np.bool_)
        size = m + 1  # lazy deletion: every edge pushes at most once, the source once (int32 nodes: < 2**31)
        self.frontier = np.empty((size, 2))  # (key, node) rows
        self.counters = np.zeros(3, dtype=np.int64)
        self.g[src], self.frontier[0], self.counters[K.FRONTIER_SIZE] = 0.0, (0.0, src), 1
        self.mode = mode

    @property
    def expanded(self) -> int:
        return int(self.counters[K.EXPANDED])

    def run(self, step: Callable[[int], int], dst: int, termination: Termination, work_done: float,
            chunk: int) -> SearchResult:
        """Call the kernel ``step(max_expand)`` in chunks until it ends or ``termination`` stops it."""
        while True:
            left = termination.work_left(work_done + self.expanded, chunk)
            if left <= 0 or termination.expired():
                return SearchResult(SearchStatus.STOPPED, np.zeros(0, np.int64), np.inf, self.expanded)
            outcome = step(left)
            if outcome == 1:
                route: IntArray = K.route_to(self.prev, dst)
                return SearchResult(SearchStatus.FOUND, route, float(self.g[dst]), self.expanded)
            if outcome == 0:
                return SearchResult(SearchStatus.UNREACHABLE, np.zeros(0, np.int64), np.inf, self.expanded)


def _mode(method: str) -> int:
    if method not in SEARCHES:
        raise ValueError(f"unknown graph search {method!r}; known: {', '.join(SEARCHES)}")
    return SEARCHES[method]


def search(graph: Graph, src: int, dst: int, method: str, termination: Termination, work_done: float = 0.0,
           chunk: int = CHUNK) -> SearchResult:
    """Search ``graph`` from node ``src`` to node ``dst`` by ``method`` (a key of :data:`SEARCHES`)
    until ``termination`` (work: nodes expanded, counted on from ``work_done``)."""
    f = _Frontier(graph.n, len(graph.adj), src, _mode(method))

    def step(left: int) -> int:
        return int(K.graph_search(graph.pts, graph.indptr, graph.adj, graph.w, _NO_GRID, 1.0, 0, dst, f.mode,
                                  graph.octile, f.g, f.prev, f.closed, f.frontier, f.counters, left))

    return f.run(step, dst, termination, work_done, chunk)


def grid_search(free: NDArray[np.bool_], start: tuple[int, int], goal: tuple[int, int], method: str,
                termination: Termination, resolution_m: float = 1.0, connectivity: int = 8,
                chunk: int = GRID_CHUNK) -> SearchResult:
    """:func:`search` on the connectivity graph of a uniform grid's free cells (``free`` (ny, nx),
    cells (row, column), ``resolution_m`` apart, 4 or 8 neighbours; the heuristic the octile
    distance), without building the graph: the same search as over
    :func:`cmdragons.planning.cells.grid_graph`, faster. Dijkstra and A* count each cost in axis and
    diagonal moves and keep the frontier in a radix heap (:func:`cmdragons.planning._graphsearch_kernels.grid_astar`);
    the others run :func:`cmdragons.planning._graphsearch_kernels.graph_search` on the grid. ``route`` is cell
    indices row * nx + column."""
    ny, nx = free.shape
    mode = _mode(method)
    width = nx + 2
    src, dst = (start[0] + 1) * width + start[1] + 1, (goal[0] + 1) * width + goal[1] + 1
    if mode in (K.SEARCH_DIJKSTRA, K.SEARCH_ASTAR):
        found = _GridFrontier(free, src, connectivity).run(dst, mode == K.SEARCH_ASTAR, resolution_m, termination,
                                                            chunk)
    else:
        grid = np.zeros((ny + 2, width), dtype=np.bool_)  # a blocked border: no neighbour falls outside
        grid[1:-1, 1:-1] = free
        f = _Frontier(grid.size, connectivity * grid.size, src, mode)

        def step(left: int) -> int:
            return int(K.graph_search(_NO_POINTS, _NO_INDEX, _NO_INDEX, _NO_WEIGHTS, grid, resolution_m,
                                      connectivity, dst, f.mode, True, f.g, f.prev, f.closed, f.frontier,
                                      f.counters, left))

        found = f.run(step, dst, termination, work_done=0.0, chunk=chunk)
    route = (found.route // width - 1) * nx + found.route % width - 1  # back to the unbordered grid's cells
    return SearchResult(found.status, route, found.cost, found.expanded)


class _GridFrontier:
    """The state of one Dijkstra or A* search on a grid (with a blocked border), as
    :func:`cmdragons.planning._graphsearch_kernels.grid_astar` takes it."""

    def __init__(self, free: NDArray[np.bool_], src: int, connectivity: int) -> None:
        ny, nx = free.shape
        self.width = nx + 2
        self.state = np.zeros((ny + 2) * self.width, dtype=np.uint8)  # 1: free and not expanded
        self.state.reshape(ny + 2, self.width)[1:-1, 1:-1] = free
        n = self.state.size
        self.connectivity = connectivity
        # only what the search reads before it writes is filled: a cell's diagonal count and parent
        # are read only once it is reached (its axis count not -1), and the route ends at the source
        self.ga = np.full(n, -1, dtype=np.int32)  # the cost in axis moves (-1: not reached) ...
        self.gb = np.empty(n, dtype=np.int32)  # ... and in diagonal ones
        self.prev = np.empty(n, dtype=np.int32)
        size = connectivity * n + 1  # every edge pushes at most once, the source once
        self.key, self.node, self.nxt = np.empty(size), np.empty(size, dtype=np.int32), np.empty(size, dtype=np.int32)
        self.head = np.full(K.RADIX_BUCKETS, -1, dtype=np.int32)
        self.counters = np.zeros(3, dtype=np.int64)
        self.ga[src], self.gb[src], self.prev[src] = 0, 0, -1
        self.key[0], self.node[0], self.nxt[0], self.head[0] = 0.0, src, -1, 0
        self.counters[K.GRID_POOL] = 1

    def run(self, dst: int, heuristic: bool, resolution_m: float, termination: Termination,
            chunk: int) -> SearchResult:
        """Call the kernel in chunks until it ends or ``termination`` stops it."""
        while True:
            expanded = int(self.counters[K.EXPANDED])
            left = termination.work_left(expanded, chunk)
            if left <= 0 or termination.expired():
                return SearchResult(SearchStatus.STOPPED, np.zeros(0, np.int64), np.inf, expanded)
            outcome = K.grid_astar(self.state, self.width, dst, heuristic, self.connectivity, self.ga,
                                   self.gb, self.prev, self.key, self.node, self.nxt, self.head, self.counters,
                                   left)
            expanded = int(self.counters[K.EXPANDED])
            if outcome == 1:
                cost = (float(self.ga[dst]) + float(self.gb[dst]) * math.sqrt(2.0)) * resolution_m
                return SearchResult(SearchStatus.FOUND, K.route_to(self.prev, dst), cost, expanded)
            if outcome == 0:
                return SearchResult(SearchStatus.UNREACHABLE, np.zeros(0, np.int64), np.inf, expanded)


def link_point(cw: CompiledWorld, pts: FloatArray, point: tuple[float, float], k: int,
               radius_m: float = np.inf) -> tuple[IntArray, FloatArray]:
    """The nodes among the ``k`` nearest of ``pts`` (within ``radius_m``) that the robot reaches from
    ``point`` in a straight line (the exact swept-disc query): their indices and distances."""
    if not len(pts):
        return np.zeros(0, np.int64), np.zeros(0)
    d = np.hypot(pts[:, 0] - point[0], pts[:, 1] - point[1])
    near = np.argpartition(d, k - 1)[:k] if len(d) > k else np.arange(len(d))
    near = near[np.argsort(d[near], kind="stable")]
    near = near[d[near] <= radius_m]
    seg = np.column_stack([np.broadcast_to(point, (len(near), 2)), pts[near]])
    ok = cw.segments_free(seg) if len(near) else np.zeros(0, np.bool_)
    return near[ok].astype(np.int64), d[near[ok]]
