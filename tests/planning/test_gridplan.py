"""E* and NF1 as global planners: the repaired navigation function gives the plan a fresh one gives,
the capped clearance grid is the clearance grid capped, and a cell size the obstacle threshold does
not cover is refused."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.geometry import Field
from cmdragons.planning import PlannerParams, PlanStatus, budget, deadline, field_world, make_planner
from cmdragons.planning.gridplan import EStarParams, GridParams
from tests.planning.conftest import problem, wall_with_gap


def test_a_repaired_plan_is_the_plan_of_a_fresh_field(field: Field) -> None:
    # always repair (repair_share 1): each frame one robot of the wall moves a few centimetres
    params = PlannerParams(estar=EStarParams(repair_share=1.0))
    kept = make_planner(params, name="estar")
    base = wall_with_gap(field)
    for i, dx in enumerate((0.0, 0.02, 0.05, 0.09)):
        circles = base.circles.copy()
        circles[3, 0] += dx
        prob = problem(base.with_circles(circles, base.velocities), (-3.0, -1.0), (3.0, -1.0))
        repaired = kept.solve(prob, deadline(60.0) | budget(10**7))
        fresh = make_planner(params, name="estar").solve(prob, deadline(60.0) | budget(10**7))
        assert repaired.status is PlanStatus.SOLVED and fresh.status is PlanStatus.SOLVED
        assert repaired.stats["repaired"] is (i > 0) and fresh.stats["repaired"] is False
        np.testing.assert_allclose(repaired.path, fresh.path, atol=1e-9)


@pytest.mark.parametrize("walls", [True, False])
@pytest.mark.parametrize("cap", [0.05, 0.3, 2.0])
def test_the_capped_clearance_grid_is_the_clearance_grid_capped(field: Field, walls: bool, cap: float) -> None:
    rng = np.random.default_rng(4)
    world = field_world(field, rng.uniform(-3.0, 3.0, (12, 2)), rng.normal(0.0, 1.0, (12, 2)))
    cw = world.compile(0.09, 0.0, 0.2)
    exact = cw.clearance_grid(0.1, walls=walls).values
    capped = cw.clearance_grid(0.1, walls=walls, cap_m=cap).values
    np.testing.assert_allclose(capped, np.minimum(exact, cap), atol=1e-12)


def test_an_obstacle_threshold_below_half_a_cell_diagonal_is_refused() -> None:
    GridParams(resolution_m=0.1, min_clearance_m=0.0711)
    with pytest.raises(ValueError, match="half a cell's diagonal"):
        GridParams(resolution_m=0.1, min_clearance_m=0.05)
