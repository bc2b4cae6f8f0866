"""Grid navigation functions against their ground truth: NF1 against breadth-first search, the
8-connected search against Dijkstra and the Moving AI optima, E* against fast marching, Euclidean
distance on an empty grid, and its repair against recomputation from scratch."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cmdragons.planning.grid import EStar, descend_nf1, nf1, octile_path, read_map, read_scenarios
from cmdragons.planning.grid import _reference as ref

BENCH = Path(__file__).resolve().parents[3] / "shared" / "benchdata" / "moving_ai"


def random_free(rng: np.random.Generator, h: int, w: int, density: float) -> np.ndarray:
    free = rng.random((h, w)) > density
    free[0, 0] = free[h - 1, w - 1] = True
    return free


def as_cost(free: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
    cost = np.where(free, 1.0, np.inf)
    if rng is not None:  # weighted regions: costs from 1 to 4
        cost = np.where(free, 1.0 + 3.0 * rng.random(free.shape), np.inf)
    return cost


@pytest.mark.parametrize("connectivity", [4, 8])
@pytest.mark.parametrize("seed", range(4))
def test_nf1_equals_breadth_first_distances(connectivity: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    free = random_free(rng, 37, 53, 0.3)
    goal = (int(rng.integers(37)), int(rng.integers(53)))
    free[goal] = True
    dist = nf1(free, goal, connectivity)
    assert np.array_equal(dist, ref.bfs(free, goal, connectivity == 8))
    starts = np.argwhere(dist > 0)
    for start in starts[:: max(1, len(starts) // 10)]:
        path = descend_nf1(dist, (int(start[0]), int(start[1])), connectivity)
        assert path[-1] == goal and len(path) == dist[tuple(start)] + 1
        steps = np.abs(np.diff(np.array(path), axis=0))
        assert steps.max() <= 1 and (connectivity == 8 or np.all(steps.sum(axis=1) == 1))


@pytest.mark.parametrize("weighted", [False, True])
@pytest.mark.parametrize("seed", range(3))
def test_octile_search_is_exact(weighted: bool, seed: int) -> None:
    rng = np.random.default_rng(10 + seed)
    free = random_free(rng, 30, 40, 0.25)
    cost = as_cost(free, rng if weighted else None)
    for _ in range(5):
        cells = np.argwhere(free)
        s, g = (tuple(int(v) for v in cells[rng.integers(len(cells))]) for _ in range(2))
        expected = ref.octile_dijkstra(cost, s, g)
        for astar in (False, True):
            p = octile_path(cost, s, g, astar=astar)
            assert p.length == pytest.approx(expected, abs=1e-9) if math.isfinite(expected) else not p.found


@pytest.mark.slow
@pytest.mark.skipif(not BENCH.is_dir(), reason="the Moving AI benchmark data (../shared/benchdata) is not here")
@pytest.mark.parametrize("name", ["8room_000", "random512-10-0"])
def test_octile_search_matches_the_moving_ai_optima(name: str) -> None:
    free = read_map(BENCH / f"{name}.map")
    cost = as_cost(free)
    scenarios = read_scenarios(BENCH / f"{name}.map.scen")
    for sc in scenarios[:: max(1, len(scenarios) // 40)]:
        p = octile_path(cost, (sc.start[1], sc.start[0]), (sc.goal[1], sc.goal[0]))
        assert p.length == pytest.approx(sc.optimal, abs=1e-6), sc


@pytest.mark.parametrize("neighbours", [4, 8])
@pytest.mark.parametrize("weighted", [False, True])
def test_estar_equals_fast_marching(weighted: bool, neighbours: int) -> None:
    rng = np.random.default_rng(3)
    free = random_free(rng, 40, 45, 0.2)
    cost = as_cost(free, rng if weighted else None)
    goals = [(5, 7), (30, 40)]
    for g in goals:
        cost[g] = 1.0
    e = EStar(cost, goals, neighbours)
    assert e.compute()
    # the one-pass kernel of a first compute and the event propagation agree bit for bit
    events = EStar(cost, goals, neighbours)
    assert events.compute(max_cells=10**9)
    assert np.array_equal(e.value, events.value)
    expected = ref.fast_marching(cost, goals, neighbours == 8)
    assert np.array_equal(np.isfinite(e.value), np.isfinite(expected))
    fin = np.isfinite(expected)
    assert np.max(np.abs(e.value[fin] - expected[fin])) < 1e-9


def test_estar_on_an_empty_grid_is_within_two_percent_of_euclidean_distance() -> None:
    n = 201
    e = EStar.from_point(np.ones((n, n)), (100.0, 100.0))
    e.compute()
    rows, cols = np.mgrid[0:n, 0:n]
    euclid = np.hypot(rows - 100, cols - 100)
    far = euclid > 0
    err = np.abs(e.value[far] - euclid[far]) / euclid[far]
    assert err.max() < 0.02, err.max()
    # a point seed alone on the 4-neighbourhood: first-order fast marching, 7% off at ten cells
    e4 = EStar(np.ones((n, n)), [(100, 100)], neighbours=4)
    e4.compute()
    near = (euclid >= 10) & (euclid <= 11)
    assert np.max(np.abs(e4.value[near] - euclid[near]) / euclid[near]) > 0.05
    # and the path from a corner runs straight at the goal
    p = e.path((0.0, 0.0))
    assert p.found and p.length == pytest.approx(100 * math.sqrt(2), rel=0.01)


@pytest.mark.parametrize("neighbours", [4, 8])
@pytest.mark.parametrize("seed", range(5))
def test_estar_repair_equals_recomputation_cell_for_cell(seed: int, neighbours: int) -> None:
    rng = np.random.default_rng(20 + seed)
    h, w = 48, 64
    free = random_free(rng, h, w, 0.15)
    cost = as_cost(free, rng if seed % 2 else None)
    goal = (int(rng.integers(h)), int(rng.integers(w)))
    cost[goal] = 1.0
    e = EStar(cost, [goal], neighbours)
    e.compute()
    for _ in range(6):
        # a robot-sized blob appears, moves or goes; some cells change their weight
        r, c = int(rng.integers(h)), int(rng.integers(w))
        blob = np.array([(r + dr, c + dc) for dr in range(-2, 3) for dc in range(-2, 3)
                         if 0 <= r + dr < h and 0 <= c + dc < w and (r + dr, c + dc) != goal])
        new = np.full(len(blob), np.inf) if rng.random() < 0.6 else 1.0 + 3.0 * rng.random(len(blob))
        e.set_costs(blob, new)
        cost[blob[:, 0], blob[:, 1]] = new
        e.compute()
        fresh = EStar(cost, [goal], neighbours)
        fresh.compute()
        same_inf = np.isinf(e.value) == np.isinf(fresh.value)
        assert same_inf.all()
        fin = np.isfinite(fresh.value)
        assert np.max(np.abs(e.value[fin] - fresh.value[fin]), initial=0.0) <= 1e-9


def test_estar_repair_touches_only_what_a_change_affects() -> None:
    n = 200
    cost = np.ones((n, n))
    e = EStar.from_point(cost, (10.0, 100.0))
    e.compute()
    full = e.pops
    blob = np.array([(r, c) for r in range(98, 103) for c in range(175, 180)])  # far from the goal
    e.set_costs(blob, np.inf)
    e.compute()
    # only the blob's shadow behind it (seen from the goal) changes
    assert e.pops < full / 10
    e.set_costs(blob, 1.0)
    e.compute()
    fresh = EStar.from_point(cost, (10.0, 100.0))
    fresh.compute()
    assert np.max(np.abs(e.value - fresh.value)) <= 1e-9


def test_estar_paths_descend_to_the_goal_around_obstacles() -> None:
    cost = np.ones((60, 60))
    cost[10:50, 30] = np.inf  # a wall between start and goal
    e = EStar.from_point(cost, (55.0, 30.0))
    e.compute()
    p = e.path((5.0, 30.0))
    assert p.found
    assert tuple(p.points[-1]) == (55.0, 30.0)
    cells = np.round(p.points).astype(int)
    assert np.all(np.isfinite(cost[cells[:, 1], cells[:, 0]]))  # never through the wall
    best = octile_path(cost, (30, 5), (30, 55))
    assert 0.9 * best.length <= p.length <= best.length


def test_an_unreachable_start_has_no_path() -> None:
    cost = np.ones((20, 20))
    cost[:, 10] = np.inf
    e = EStar(cost, [(5, 15)])
    e.compute()
    assert not e.path((2.0, 5.0)).found
    assert not octile_path(cost, (5, 2), (5, 15)).found
