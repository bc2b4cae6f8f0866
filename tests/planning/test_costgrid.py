"""The cost grid from a clearance grid: obstacles where the robot's centre has no room, soft costs
falling off with clearance, weighted regions on top, cells and field coordinates round trip."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from cmdragons.planning.grid.costgrid import CostGrid, CostParams, Region, SoftCost


@dataclass
class Grid:
    x0: float
    y0: float
    resolution_m: float
    values: np.ndarray


def disc_clearance(nx: int, ny: int, res: float, cx: float, cy: float, r: float) -> Grid:
    xs = (np.arange(nx) + 0.5) * res
    ys = (np.arange(ny) + 0.5) * res
    X, Y = np.meshgrid(xs, ys)
    return Grid(0.0, 0.0, res, np.hypot(X - cx, Y - cy) - r)


def test_obstacle_cells_and_the_soft_cost_falling_off_with_clearance() -> None:
    g = disc_clearance(60, 40, 0.05, 1.5, 1.0, 0.3)
    params = CostParams(obstacles=SoftCost(near_cost=2.0, falloff_m=0.3))
    cg = CostGrid.from_clearance(g, params)
    assert np.all(np.isinf(cg.cost[g.values < 0]))
    free = g.values >= 0
    assert np.all(cg.cost[free] >= 1.0)
    far = g.values >= 0.3
    assert np.all(cg.cost[far] == 1.0)
    ring = (g.values > 0.0) & (g.values < 0.3)
    expected = 1.0 + 2.0 * (1.0 - g.values[ring] / 0.3) ** 2
    assert np.allclose(cg.cost[ring], expected)


def test_regions_add_their_costs_without_blocking() -> None:
    g = disc_clearance(60, 40, 0.05, 1.5, 1.0, 0.3)
    region = disc_clearance(60, 40, 0.05, 0.5, 0.5, 0.1)
    base = CostGrid.from_clearance(g, CostParams())
    with_region = CostGrid.from_clearance(g, CostParams(), [Region(region.values, SoftCost(5.0, 0.5))])
    inside = region.values < 0
    assert np.all(np.isfinite(with_region.cost[inside & (g.values >= 0)]))
    assert np.all(with_region.cost >= base.cost)
    assert with_region.cost[inside].min() == pytest.approx(base.cost[inside].min() + 5.0)


def test_cells_and_field_coordinates_round_trip() -> None:
    cg = CostGrid.from_clearance(disc_clearance(60, 40, 0.05, 1.5, 1.0, 0.3), CostParams())
    assert cg.cell_of(0.026, 0.074) == (1, 0)
    assert cg.cell_of(-0.01, 0.5) is None
    pts = np.array([[0.0, 0.0], [10.0, 3.0]])
    back = cg.to_field(pts)
    assert np.allclose(back, [[0.025, 0.025], [0.525, 0.175]])
    assert np.allclose(np.array([cg.to_cell(*p) for p in back]), pts)
