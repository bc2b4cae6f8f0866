"""The cost grid of the grid planners (Philippsen 2004 §3.6.1, §4.8): from the collision world's
clearance grid to each cell's traversal cost.

The clearance grid already is the configuration space: its values are the clearance of a robot
*centre* (obstacles grown by the robot's radius), negative inside an obstacle. A cell with clearance
below ``min_clearance_m`` is an obstacle (``inf``); a free cell costs 1 plus a soft cost that falls
off with its clearance (``near_cost`` at the obstacle's edge, 0 from ``falloff_m`` on), so paths keep
away from obstacles where room allows. Weighted regions add their own soft costs the same way from
their own clearance grids (the defense areas, the opponents: each region's grid is the clearance of
that region's obstacles alone), never making a cell an obstacle.

Field frame, metres; a grid has cell (row i, column k) centred at (x0 + (k + 1/2) r, y0 + (i + 1/2) r).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting

__all__ = ["CostGrid", "CostParams", "Region", "SoftCost"]

FloatArray = NDArray[np.float64]


class Clearances(Protocol):
    """What a clearance grid offers (cmdragons.planning.world.ClearanceGrid)."""

    @property
    def x0(self) -> float: ...
    @property
    def y0(self) -> float: ...
    @property
    def resolution_m(self) -> float: ...
    @property
    def values(self) -> FloatArray: ...


@dataclass(frozen=True)
class SoftCost(Validated):
    """A cost that falls off with clearance: ``near_cost`` at clearance 0, 0 from ``falloff_m``
    on, quadratically in between (a smooth rise toward the obstacle)."""

    near_cost: float = setting(2.0, lo=0.0, hi=1000.0)
    falloff_m: float = setting(0.3, lo=0.0, hi=10.0)

    def of(self, clearance: FloatArray) -> FloatArray:
        if self.falloff_m <= 0.0 or self.near_cost <= 0.0:
            return np.zeros_like(clearance)
        share = np.clip(1.0 - np.maximum(clearance, 0.0) / self.falloff_m, 0.0, 1.0)
        return np.asarray(self.near_cost * share * share, dtype=np.float64)


@dataclass(frozen=True)
class CostParams(Validated):
    """configs/planner.yaml ``grid``: the grid planners' cost grid."""

    resolution_m: float = setting(0.05, lo=0.005, hi=1.0)  # cell size
    min_clearance_m: float = setting(0.0, lo=0.0, hi=1.0)  # less clearance than this: an obstacle cell
    obstacles: SoftCost = SoftCost()  # near every obstacle
    defense_areas: SoftCost = SoftCost(near_cost=1.0, falloff_m=0.2)  # near the defense areas
    opponents: SoftCost = SoftCost(near_cost=3.0, falloff_m=0.4)  # around opponent robots


@dataclass(frozen=True)
class Region:
    """A weighted region: its obstacles' own clearance grid (the same cells as the main grid) and
    the soft cost it adds."""

    clearance: FloatArray
    cost: SoftCost


@dataclass(frozen=True)
class CostGrid:
    """Traversal costs per cell (>= 1; ``inf`` for obstacles) on the clearance grid's cells."""

    x0: float
    y0: float
    resolution_m: float
    cost: FloatArray  # (rows, cols)

    @classmethod
    def from_clearance(cls, grid: Clearances, params: CostParams, regions: Sequence[Region] = ()) -> CostGrid:
        c = np.asarray(grid.values, dtype=np.float64)
        cost = 1.0 + params.obstacles.of(c)
        for region in regions:
            if region.clearance.shape != c.shape:
                raise ValueError(f"a region's grid is {region.clearance.shape}, the clearance grid {c.shape}")
            cost = cost + region.cost.of(np.asarray(region.clearance, dtype=np.float64))
        cost = np.where(c < params.min_clearance_m, np.inf, cost)
        return cls(float(grid.x0), float(grid.y0), float(grid.resolution_m), np.ascontiguousarray(cost))

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.cost.shape[0]), int(self.cost.shape[1]))

    def to_cell(self, x: float, y: float) -> tuple[float, float]:
        """Field (x, y) in cell units (column, row; centres at integers)."""
        return ((x - self.x0) / self.resolution_m - 0.5, (y - self.y0) / self.resolution_m - 0.5)

    def cell_of(self, x: float, y: float) -> tuple[int, int] | None:
        """The (row, col) holding field point (x, y), or None outside the grid."""
        cx, cy = self.to_cell(x, y)
        r, c = int(math.floor(cy + 0.5)), int(math.floor(cx + 0.5))
        if 0 <= r < self.cost.shape[0] and 0 <= c < self.cost.shape[1]:
            return r, c
        return None

    def to_field(self, cells_xy: FloatArray) -> FloatArray:
        """Points in cell units (x along columns, y along rows) -> field frame (k, 2)."""
        p = np.asarray(cells_xy, dtype=np.float64).reshape(-1, 2)
        return np.stack([self.x0 + (p[:, 0] + 0.5) * self.resolution_m, self.y0 + (p[:, 1] + 0.5) * self.resolution_m],
                        axis=1)
