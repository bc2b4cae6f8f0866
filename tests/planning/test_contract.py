"""The planner contract (after OMPL's PlannerTest): every registered planner on the same scenes.

Checked for each: the path is collision-free under the swept-circle check and inside the field,
runs from the start to the goal, its cost is its length; solvable scenes are solved; impossible
ones end in a clean NO_PATH; a start in an obstacle is left by the shortest way; a blocked goal
gives the nearest free one; the deadline is kept; the same seed gives the same path.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from cmdragons.geometry import Field
from cmdragons.planning import (
    PLANNERS,
    PlannerParams,
    PlanProblem,
    PlanStatus,
    Termination,
    budget,
    deadline,
    field_world,
    make_planner,
    path_length,
)
from cmdragons.planning.scenes import random_scene
from tests.planning.conftest import RADIUS_M, problem, ring, wall_with_gap

NAMES = sorted(PLANNERS)
# their work is finite: a hard scene ends before any deadline
FINITE = ("visgraph", "estar", "nf1", "voronoi", "trapezoidal", "uniform_cells", "quadtree")
GENEROUS_S = 60.0  # deadline for scenes that must be solved: far beyond any planner's need, and any first-use compile


def within(name: str) -> Termination:
    """The generous deadline and the planner's configured work budget."""
    return deadline(GENEROUS_S) | budget(getattr(PlannerParams(), name).work_budget)


def check_path(prob: PlanProblem, path: np.ndarray, from_index: int = 0) -> None:
    cw = prob.compiled()
    assert path.ndim == 2 and path.shape[1] == 2 and len(path) >= 2
    assert cw.path_free(path[from_index:]), "path collides (swept-circle check)"
    x0, y0, x1, y1 = prob.world.bounds
    inside = (path[:, 0] >= x0 + RADIUS_M - 1e-9) & (path[:, 0] <= x1 - RADIUS_M + 1e-9)
    inside &= (path[:, 1] >= y0 + RADIUS_M - 1e-9) & (path[:, 1] <= y1 - RADIUS_M + 1e-9)
    assert inside[from_index:].all(), "path leaves the field"


def solvable_scenes(field: Field) -> list[PlanProblem]:
    rng = np.random.default_rng(2024)
    scenes = [random_scene(field, rng).problem(field) for _ in range(12)]
    return scenes + [problem(wall_with_gap(field), (-3.0, -1.0), (3.0, -1.0))]


@pytest.mark.parametrize("name", NAMES)
def test_solvable_scenes_are_solved_with_valid_paths(name: str, field: Field) -> None:
    planner = make_planner(PlannerParams(), name=name)
    for prob in solvable_scenes(field):
        planner.reset()
        result = planner.solve(prob, within(name))
        assert result.status is PlanStatus.SOLVED, (name, prob.start, prob.goal, result.stats)
        check_path(prob, result.path)
        assert tuple(result.path[0]) == prob.start and tuple(result.path[-1]) == prob.goal
        assert result.cost == pytest.approx(path_length(result.path), rel=2e-3)  # visgraph: exact arcs


@pytest.mark.parametrize("name", NAMES)
def test_straight_line_when_free(name: str, field: Field) -> None:
    prob = problem(field_world(field), (-2.0, 1.0), (2.5, -1.0))
    result = make_planner(PlannerParams(), name=name).solve(prob, within(name))
    assert result.status is PlanStatus.SOLVED
    np.testing.assert_allclose(result.path, [prob.start, prob.goal])


@pytest.mark.parametrize("name", NAMES)
def test_unreachable_goal_is_a_clean_no_path(name: str, field: Field) -> None:
    # the goal is free but walled in by a ring of touching robots
    world = field_world(field, ring((1.0, 0.5), 0.45, 16))
    prob = problem(world, (-3.0, -1.0), (1.0, 0.5))
    assert prob.compiled().point_free(1.0, 0.5)
    result = make_planner(PlannerParams(), name=name).solve(prob, within(name))
    assert result.status is PlanStatus.NO_PATH
    assert result.cost == float("inf")
    assert tuple(result.path[0]) == prob.start
    check_path(prob, result.path) if len(result.path) > 1 else None


@pytest.mark.parametrize("name", NAMES)
def test_start_inside_an_obstacle_leaves_by_the_shortest_way(name: str, field: Field) -> None:
    world = field_world(field, [[0.0, 0.0], [1.0, 0.4], [1.0, -0.4]])
    prob = problem(world, (0.05, 0.0), (3.0, 0.0))  # 5 cm from a robot's centre: deep inside
    result = make_planner(PlannerParams(), name=name).solve(prob, within(name))
    assert result.status is PlanStatus.SOLVED and result.stats["escaped_start"]
    assert tuple(result.path[0]) == prob.start
    np.testing.assert_allclose(result.path[1], [0.18, 0.0], atol=1e-4)  # straight out, radially
    check_path(prob, result.path, from_index=1)
    assert tuple(result.path[-1]) == prob.goal


@pytest.mark.parametrize("name", NAMES)
def test_goal_inside_an_obstacle_gives_the_nearest_free_goal(name: str, field: Field) -> None:
    prob = problem(field_world(field, [[1.0, 1.0]]), (-2.0, 0.0), (1.0, 1.1))
    result = make_planner(PlannerParams(), name=name).solve(prob, within(name))
    assert result.status is PlanStatus.APPROXIMATE and result.stats["goal_moved"]
    np.testing.assert_allclose(result.path[-1], [1.0, 1.18], atol=1e-4)
    check_path(prob, result.path)
    prob = problem(field_world(field), (0.0, 0.0), (4.0, 0.5))  # in the defense area: out of its front
    result = make_planner(PlannerParams(), name=name).solve(prob, within(name))
    assert result.status is PlanStatus.APPROXIMATE
    np.testing.assert_allclose(result.path[-1], [3.5 - RADIUS_M, 0.5], atol=1e-4)


@pytest.mark.parametrize("name", NAMES)
def test_invalid_start_is_a_status(name: str, field: Field) -> None:
    prob = problem(field_world(field), (float("nan"), 0.0), (1.0, 0.0))
    result = make_planner(PlannerParams(), name=name).solve(prob, within(name))
    assert result.status is PlanStatus.INVALID_START


@pytest.mark.parametrize("name", [n for n in NAMES if n not in FINITE])  # the finite ones: below
def test_deadline_is_kept(name: str, field: Field) -> None:
    # a hard scene (a ring closed around the goal) and no work budget: only the deadline stops it
    params = PlannerParams()
    params = type(params)(errt=type(params.errt)(bidirectional=False),
                          prm=type(params.prm)(n_nodes=50, max_nodes=10**6, grow_nodes=5))
    world = field_world(field, ring((1.0, 0.5), 0.45, 16))
    prob = problem(world, (-3.0, -1.0), (1.0, 0.5))
    planner = make_planner(params, name=name)
    planner.solve(prob, deadline(0.001))  # compile and build roadmaps outside the timed call
    # the work budget alone would keep it busy for seconds: a deadline, passed or near, ends it as a
    # timeout (how close to the deadline it stops is a matter of speed, not of this test)
    for ahead_s in (-1.0, 0.002, 0.02):
        result = planner.solve(prob, Termination(deadline_s=time.perf_counter() + ahead_s))
        assert result.status is PlanStatus.TIMEOUT, (name, ahead_s, result.stats)


@pytest.mark.parametrize("name", NAMES)
def test_a_spent_work_budget_ends_in_no_path(name: str, field: Field) -> None:
    # the ring closed around the goal: no path exists, and a small work budget ends the search, on
    # any machine, with the deadline far away
    prob = problem(field_world(field, ring((1.0, 0.5), 0.45, 16)), (-3.0, -1.0), (1.0, 0.5))
    small = make_planner(PlannerParams(), name=name).solve(prob, deadline(GENEROUS_S) | budget(50))
    assert small.status is PlanStatus.NO_PATH
    # the same budget twice: the same work, the same answer
    again = make_planner(PlannerParams(), name=name).solve(prob, deadline(GENEROUS_S) | budget(50))
    assert again.status is PlanStatus.NO_PATH
    np.testing.assert_array_equal(again.path, small.path)


@pytest.mark.parametrize("name", FINITE)
def test_a_planner_with_finite_work_keeps_its_deadline(name: str, field: Field) -> None:
    # a deadline already passed stops it before its graph or grid is built: TIMEOUT, no path (also
    # for a grid planner that keeps its field from the frame before)
    prob = problem(field_world(field, ring((1.0, 0.5), 0.45, 16)), (-3.0, -1.0), (3.0, 0.5))
    planner = make_planner(PlannerParams(), name=name)
    assert planner.solve(prob, within(name)).status is PlanStatus.SOLVED
    late = planner.solve(prob, Termination(deadline_s=time.perf_counter()))
    assert late.status is PlanStatus.TIMEOUT and not np.isfinite(late.cost)


@pytest.mark.parametrize("name", NAMES)
def test_same_seed_same_path(name: str, field: Field) -> None:
    prob = solvable_scenes(field)[3]
    paths = [make_planner(PlannerParams(seed=9), name=name).solve(prob, within(name)).path for _ in range(2)]
    np.testing.assert_array_equal(paths[0], paths[1])
