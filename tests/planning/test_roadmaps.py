"""Road maps, cell decompositions and the graph searches over them (seed 001, "Road-Map Path
Planning"): the searches agree on least costs with scipy's csgraph (the reference), each planner
finds a path where one exists with every search and reports NO_PATH where none does, the Voronoi
roads keep more clearance than the visibility graph's shortest path, the trapezoids cover the free
space exactly, and the approximate cells are wholly free."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import shortest_path
from scipy.spatial import Delaunay

from cmdragons.geometry import Field
from cmdragons.planning import (
    PlannerParams,
    PlanProblem,
    PlanStatus,
    budget,
    field_world,
    make_planner,
    never,
)
from cmdragons.planning.cells import grid_graph, quadtree, uniform_cells
from cmdragons.planning.cspace import free_space
from cmdragons.planning.graphsearch import SEARCHES, Graph, SearchStatus, grid_search, search
from cmdragons.planning.trapezoidal import trapezoids
from tests.planning.conftest import problem, ring, wall_with_gap

ROADMAPS = ("voronoi", "trapezoidal", "uniform_cells", "quadtree")
OPTIMAL = ("dijkstra", "astar")


def delaunay_graph(seed: int) -> Graph:
    pts = np.random.default_rng(seed).uniform(0.0, 10.0, (400, 2))
    tri = Delaunay(pts).simplices
    e = np.sort(np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [0, 2]]]), axis=1)
    return Graph.from_edges(pts, np.unique(e, axis=0))


def unit_grid_graph(free: np.ndarray) -> Graph:
    """4 neighbours on a grid of unit cells: every edge weighs 1 (what breadth-first minimises)."""
    return grid_graph(free, 0.0, 0.0, 1.0, 4)


def csgraph_costs(graph: Graph, src: int, unweighted: bool = False) -> np.ndarray:
    m = csr_matrix((graph.w, graph.adj, graph.indptr), shape=(graph.n, graph.n))
    costs: np.ndarray = shortest_path(m, indices=src, unweighted=unweighted)
    return costs


def check_route(graph: Graph, route: np.ndarray, src: int, dst: int, cost: float) -> None:
    assert route[0] == src and route[-1] == dst
    total = 0.0
    for u, v in zip(route[:-1], route[1:], strict=True):
        row = graph.adj[graph.indptr[u] : graph.indptr[u + 1]]
        assert v in row, "the route takes an edge the graph does not have"
        total += float(graph.w[graph.indptr[u] + int(np.flatnonzero(row == v)[0])])
    assert cost == pytest.approx(total, rel=1e-12)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_searches_agree_with_csgraph_on_a_weighted_graph(seed: int) -> None:
    graph = delaunay_graph(seed)
    truth = csgraph_costs(graph, 0)
    for dst in (17, 250, 399):
        for method in SEARCHES:
            found = search(graph, 0, dst, method, never())
            assert found.status is SearchStatus.FOUND
            check_route(graph, found.route, 0, dst, found.cost)
            if method in OPTIMAL:
                assert found.cost == pytest.approx(truth[dst], rel=1e-12), method
            else:  # a valid route, and no shorter than the least
                assert found.cost >= truth[dst] - 1e-12


def test_breadth_first_dijkstra_and_astar_agree_on_a_unit_graph() -> None:
    free = np.random.default_rng(5).random((40, 60)) > 0.25
    free[0, 0] = free[-1, -1] = True
    graph = unit_grid_graph(free)
    hops = csgraph_costs(graph, 0, unweighted=True)
    for dst in np.flatnonzero(np.isfinite(hops))[::97]:
        costs = {m: search(graph, 0, int(dst), m, never()).cost for m in ("bfs", "dijkstra", "astar")}
        assert costs == {"bfs": hops[dst], "dijkstra": hops[dst], "astar": hops[dst]}, dst


def test_an_unreachable_node_and_a_spent_budget_are_statuses() -> None:
    free = np.ones((10, 10), dtype=bool)
    free[:, 5] = False  # a wall: the right half is out of reach
    graph = unit_grid_graph(free)
    for method in SEARCHES:
        assert search(graph, 0, graph.n - 1, method, never()).status is SearchStatus.UNREACHABLE
        stopped = search(graph, 0, 40, method, budget(3))
        assert stopped.status is SearchStatus.STOPPED and stopped.expanded == 3


def test_a_graph_with_links_is_the_graph_of_its_edges() -> None:
    graph = delaunay_graph(4)
    nodes, lengths = np.array([3, 70, 9]), np.array([1.5, 0.25, 2.0])
    linked = graph.with_links((5.0, 5.0), nodes, lengths)
    src = np.repeat(np.arange(graph.n), np.diff(graph.indptr))
    e = np.vstack([np.column_stack([src, graph.adj])[src < graph.adj], np.column_stack([nodes, np.full(3, graph.n)])])
    w = np.concatenate([graph.w[src < graph.adj], lengths])
    rebuilt = Graph.from_edges(np.vstack([graph.pts, [(5.0, 5.0)]]), e, w)
    np.testing.assert_array_equal(linked.indptr, rebuilt.indptr)
    for u in range(linked.n):
        a, b = slice(linked.indptr[u], linked.indptr[u + 1]), slice(rebuilt.indptr[u], rebuilt.indptr[u + 1])
        assert sorted(zip(linked.adj[a], linked.w[a], strict=True)) == sorted(
            zip(rebuilt.adj[b], rebuilt.w[b], strict=True)
        )


def test_the_grid_graph_kernel_matches_its_definition() -> None:
    free = np.random.default_rng(6).random((7, 9)) > 0.3
    graph = grid_graph(free, -1.0, 2.0, 0.5, 8)
    cells = np.argwhere(free)  # row-major: the kernel's node order
    np.testing.assert_allclose(
        graph.pts, np.column_stack([-1.0 + (cells[:, 1] + 0.5) * 0.5, 2.0 + (cells[:, 0] + 0.5) * 0.5])
    )
    for u, (i, k) in enumerate(cells):
        want = {(int(a), int(b)) for a, b in cells if max(abs(a - i), abs(b - k)) == 1}
        got = {tuple(cells[v]) for v in graph.adj[graph.indptr[u] : graph.indptr[u + 1]]}
        assert got == want
    np.testing.assert_allclose(
        graph.w, np.hypot(*(graph.pts[graph.adj] - np.repeat(graph.pts, np.diff(graph.indptr), axis=0)).T)
    )


@pytest.mark.parametrize("name", ROADMAPS)
@pytest.mark.parametrize("method", sorted(SEARCHES))
def test_each_road_map_finds_the_gap_with_each_search(name: str, method: str, field: Field) -> None:
    params = PlannerParams()
    section = getattr(params, name)
    params = type(params)(**{name: type(section)(**{**section.__dict__, "search": method})})
    prob = problem(wall_with_gap(field), (-3.0, -1.0), (3.0, -1.0))
    result = make_planner(params, name=name).solve(prob, never())
    assert result.status is PlanStatus.SOLVED, result.stats
    assert prob.compiled().path_free(result.path)
    np.testing.assert_allclose([result.path[0], result.path[-1]], [prob.start, prob.goal])


@pytest.mark.parametrize("name", ROADMAPS)
def test_each_road_map_reports_no_path_into_a_closed_ring(name: str, field: Field) -> None:
    prob = problem(field_world(field, ring((1.0, 0.5), 0.45, 16)), (-3.0, -1.0), (1.0, 0.5))
    assert make_planner(PlannerParams(), name=name).solve(prob, never()).status is PlanStatus.NO_PATH


def min_clearance(prob: PlanProblem, path: np.ndarray, step_m: float = 0.01) -> float:
    pts = [path[0]]
    for a, b in zip(path[:-1], path[1:], strict=True):
        k = max(1, int(np.ceil(np.hypot(*(b - a)) / step_m)))
        pts += list(a + (b - a) * (np.arange(1, k + 1)[:, None] / k))
    clearance, _ = prob.compiled().clearance_gradients(np.array(pts))
    return float(clearance.min())


def test_the_voronoi_road_keeps_more_clearance_than_the_visibility_graph(field: Field) -> None:
    # a column of robots with open gaps between start and goal, both far from everything
    robots = [(0.0, y) for y in np.arange(-2.4, 2.5, 0.8)] + [(-1.0, 0.5), (1.2, -0.6)]
    prob = problem(field_world(field, robots), (-2.5, 0.2), (2.5, -0.1))
    vor = make_planner(PlannerParams(), name="voronoi").solve(prob, never())
    vis = make_planner(PlannerParams(), name="visgraph").solve(prob, never())
    assert vor.status is PlanStatus.SOLVED and vis.status is PlanStatus.SOLVED
    assert min_clearance(prob, vis.path) < 0.01  # the shortest path grazes the robots
    assert min_clearance(prob, vor.path) > 0.15  # the road runs midway through the 0.44 m gaps
    assert vor.cost >= vis.cost


@pytest.mark.parametrize("seed", [3, 8])
def test_the_trapezoids_cover_the_free_space_exactly(seed: int, field: Field) -> None:
    rng = np.random.default_rng(seed)
    robots = rng.uniform((-4.0, -2.8), (4.0, 2.8), (15, 2))
    cw = problem(field_world(field, robots), (0.0, 0.0), (1.0, 0.0)).compiled()
    free = free_space(cw, 4)
    cells = trapezoids(free)
    polys = [
        shapely.Polygon([(x0, lo0), (x1, lo1), (x1, hi1), (x0, hi0)]) for x0, x1, lo0, hi0, lo1, hi1 in cells.cells
    ]
    union = shapely.unary_union(polys)
    assert cells.area() == pytest.approx(free.area, rel=1e-9)  # no gaps ...
    assert union.area == pytest.approx(free.area, rel=1e-9)  # ... and no overlaps
    assert free.symmetric_difference(union).area < 1e-9 * free.area
    # a point of the free polygon lies in a cell, and is free in the exact world
    for x, y in rng.uniform((-4.5, -3.2), (4.5, 3.2), (300, 2)):
        if free.contains(shapely.Point(x, y)):
            assert cells.locate(x, y) >= 0 and cw.point_free(x, y)


@pytest.mark.parametrize("kind", ["uniform", "quadtree"])
def test_approximate_cells_are_wholly_free(kind: str, field: Field) -> None:
    robots = np.random.default_rng(11).uniform((-4.0, -2.8), (4.0, 2.8), (15, 2))
    cw = problem(field_world(field, robots), (0.0, 0.0), (1.0, 0.0)).compiled()
    if kind == "uniform":
        graph, free = uniform_cells(cw, 0.1, 8)
        half = np.full(graph.n, 0.05)
        boxes = np.column_stack([graph.pts - half[:, None], graph.pts + half[:, None]])
        assert graph.n == free.sum() > 0.7 * free.size
    else:
        tree, graph = quadtree(cw, 0.05)
        boxes = tree.boxes
        assert len(np.unique(tree.levels)) >= 4  # big cells in the open, small ones at the obstacles
    # every corner and edge midpoint of every cell is free
    xs = np.stack([boxes[:, 0], (boxes[:, 0] + boxes[:, 2]) / 2, boxes[:, 2]], axis=1)
    ys = np.stack([boxes[:, 1], (boxes[:, 1] + boxes[:, 3]) / 2, boxes[:, 3]], axis=1)
    pts = np.stack(np.broadcast_arrays(xs[:, :, None], ys[:, None, :]), axis=-1).reshape(-1, 2)
    clearance, _ = cw.clearance_gradients(pts)
    assert clearance.min() >= -1e-9


@pytest.mark.parametrize("connectivity", [4, 8])
def test_the_grid_search_is_the_search_over_the_grid_graph(connectivity: int) -> None:
    free = np.random.default_rng(7).random((30, 45)) > 0.3
    cells = np.argwhere(free)
    graph = grid_graph(free, 0.0, 0.0, 0.1, connectivity)
    for a, b in ((0, len(cells) - 1), (10, 500), (77, 3)):
        start, goal = (int(cells[a][0]), int(cells[a][1])), (int(cells[b][0]), int(cells[b][1]))
        for method in SEARCHES:
            on_graph = search(graph, a, b, method, never())
            on_grid = grid_search(free, start, goal, method, never(), 0.1, connectivity)
            assert on_grid.status is on_graph.status
            if method == "best_first":  # greedy: which of equally near cells goes first is rounding's choice
                assert on_grid.cost >= search(graph, a, b, "dijkstra", never()).cost - 1e-12
                continue
            assert on_grid.cost == pytest.approx(on_graph.cost, rel=1e-12, abs=1e-12), method
            if method in ("bfs", "dfs"):  # no heuristic: the same order, the same route
                np.testing.assert_array_equal(np.argwhere(free.ravel())[:, 0][on_graph.route], on_grid.route)


@pytest.mark.parametrize("connectivity", [4, 8])
def test_the_grid_search_resumes_in_chunks_and_stays_optimal(connectivity: int) -> None:
    # Dijkstra and A* on the grid, stopped every few expansions and resumed, against Dijkstra over
    # the built graph: the least cost every time (exact move counts and the radix heap lose nothing)
    rng = np.random.default_rng(12)
    free = rng.random((60, 80)) > 0.35
    cells = np.argwhere(free)
    graph = grid_graph(free, 0.0, 0.0, 0.05, connectivity)
    for a, b in rng.integers(0, len(cells), (8, 2)):
        best = search(graph, int(a), int(b), "dijkstra", never())
        start, goal = (int(cells[a][0]), int(cells[a][1])), (int(cells[b][0]), int(cells[b][1]))
        for method in ("dijkstra", "astar"):
            whole = grid_search(free, start, goal, method, never(), 0.05, connectivity)
            pieces = grid_search(free, start, goal, method, never(), 0.05, connectivity, chunk=3)
            assert whole.status is pieces.status is best.status
            if best.status is not SearchStatus.FOUND:
                continue
            assert whole.cost == pytest.approx(best.cost, rel=1e-12)
            assert pieces.cost == pytest.approx(best.cost, rel=1e-12)
            route = pieces.route
            assert route[0] == start[0] * 80 + start[1] and route[-1] == goal[0] * 80 + goal[1]
            steps = np.abs(np.diff(np.column_stack([route // 80, route % 80]), axis=0))
            assert steps.max() <= 1 and steps.sum(axis=1).min() >= 1 and free.ravel()[route].all()
            if connectivity == 4:
                assert steps.sum(axis=1).max() == 1
            length = np.sum(np.where(steps.sum(axis=1) == 2, math.sqrt(2.0), 1.0)) * 0.05
            assert length == pytest.approx(best.cost, rel=1e-12)
