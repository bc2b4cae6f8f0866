"""The visibility graph is exact: analytic shortest paths around a disc and around a box."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.geometry import Field
from cmdragons.planning import (
    CollisionWorld,
    PlanProblem,
    PlanStatus,
    VisGraphParams,
    VisibilityGraphPlanner,
    deadline,
    path_length,
)

BOUNDS = (-5.0, -5.0, 5.0, 5.0)


def solve(world: CollisionWorld, start: tuple[float, float], goal: tuple[float, float], radius: float):  # type: ignore[no-untyped-def]
    prob = PlanProblem(start, goal, radius, world)
    return prob, VisibilityGraphPlanner(VisGraphParams()).solve(prob, deadline(60.0))


@pytest.mark.parametrize(("r_obstacle", "radius", "d"), [(0.09, 0.09, 2.0), (0.5, 0.09, 1.0), (0.3, 0.0, 3.0)])
def test_around_a_disc(r_obstacle: float, radius: float, d: float) -> None:
    world = CollisionWorld(BOUNDS, [[0.0, 0.0, r_obstacle]])
    prob, res = solve(world, (-d, 0.0), (d, 0.0), radius)
    big_r = r_obstacle + radius
    # two tangents of length sqrt(d^2 - R^2) and the arc between their feet
    exact = 2 * math.sqrt(d * d - big_r * big_r) + big_r * (math.pi - 2 * math.acos(big_r / d))
    assert res.status is PlanStatus.SOLVED
    assert res.cost == pytest.approx(exact, rel=1e-9)
    assert prob.compiled().path_free(res.path)
    assert path_length(res.path) == pytest.approx(exact, rel=2e-3)  # the polyline hugs the arc from outside


def test_around_a_box() -> None:
    world = CollisionWorld(BOUNDS, boxes=[[-0.5, -0.5, 0.5, 0.5]])
    r = 0.1
    prob, res = solve(world, (-2.0, 0.0), (2.0, 0.0), r)
    # tangent to the rounded corner at (-0.5, 0.5), along the top edge, and down to the goal
    d = math.hypot(1.5, 0.5)
    theta = math.atan2(0.5, 1.5) + math.asin(r / d)  # the tangent's climb = the arc at the corner
    exact = 2 * (math.sqrt(d * d - r * r) + r * theta) + 1.0
    assert res.cost == pytest.approx(exact, rel=1e-9)
    assert prob.compiled().path_free(res.path)


def test_overlapping_discs_are_one_obstacle() -> None:
    # two overlapping discs: no path squeezes between them, the arcs inside each other are not used
    world = CollisionWorld(BOUNDS, [[0.0, 0.15, 0.2], [0.0, -0.15, 0.2]])
    prob, res = solve(world, (-1.0, 0.0), (1.0, 0.0), 0.0)
    assert res.status is PlanStatus.SOLVED
    assert prob.compiled().path_free(res.path)
    assert res.cost > 2.0 + 0.05


def test_matches_a_fine_grid_search_on_a_field(field: Field) -> None:
    # a brute-force check of optimality: no densely sampled free polyline through a 3-point detour is shorter
    from cmdragons.planning import field_world

    world = field_world(field, [[0.0, 0.0], [0.5, 0.6], [-0.4, -0.5], [1.0, -0.3]])
    prob, res = solve(world, (-2.0, 0.1), (2.0, 0.0), 0.09)
    cw = prob.compiled()
    g = np.stack(np.meshgrid(np.linspace(-1.5, 1.5, 61), np.linspace(-1.5, 1.5, 61)), -1).reshape(-1, 2)
    free = np.array([cw.point_free(*p) for p in g])
    best = np.inf
    s, e = np.array(prob.start), np.array(prob.goal)
    for p in g[free]:
        if cw.segment_free(s, p) and cw.segment_free(p, e):
            best = min(best, np.hypot(*(p - s)) + np.hypot(*(e - p)))
    assert res.cost <= best + 1e-9


def test_no_path_when_walled_in() -> None:
    ring = [[math.cos(a), math.sin(a), 0.3] for a in np.linspace(0, 2 * math.pi, 12, endpoint=False)]
    _, res = solve(CollisionWorld(BOUNDS, ring), (0.0, 0.0), (3.0, 0.0), 0.05)
    assert res.status is PlanStatus.NO_PATH and res.cost == math.inf
