"""E* and NF1 as global planners (Philippsen 2004 §4.8, the GridPlanner; §3.6 for NF1).

Field frame, metres. Each frame the problem's compiled world (its obstacles grown by the robot's
radius: the configuration space) is rasterised to a clearance grid and turned into a cost grid
(:class:`~cmdragons.planning.grid.costgrid.CostGrid`): obstacle cells where the clearance is
below ``grid.min_clearance_m``, a soft cost near every obstacle, and the weighted regions of
``grid`` on top (the boxes of the world, i.e. the defense areas and goal walls, and its circles,
i.e. the other robots and the ball: the problem does not tell teams apart). The planner works from
the goal: the free cells within ``connect_radius_m`` of the goal that see it in a straight line
(the exact swept-disc query) start at their distance to it; the start joins the grid the same way,
through the cell that sees it and gives the lowest total. The path is the descent of the navigation
function (E*: its interpolated gradient, §4.6.3; NF1: steepest descent over the wavefront), then
shortcut and pulled taut against the exact world (Bruce 2006 §4.6.1, the smoothing ERRT uses).

Why the path is collision-free: a cell is an obstacle below ``min_clearance_m``, and that is at
least half a cell's diagonal (checked in the params), so every point of a free cell has clearance
>= 0 (the clearance is 1-Lipschitz); the descent moves only through free cells and never across a
blocked corner, and its two ends are joined by segments the exact query passed. The final path
is checked once more by the exact query.

E* keeps its navigation function across frames (one planner object per robot): while the goal and
the cells next to it stay the same, the new frame's cost grid is compared with the last one and only
the changed cells go to :meth:`EStar.set_costs`, whose event-driven repair (§4.3) updates only what
they affect, and only until the start's value is final. Work (the termination's unit): cells
propagated (E*), cells of the wavefront (NF1).
"""

from __future__ import annotations

import abc
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.planning.errt import SmoothingParams, smooth
from cmdragons.planning.grid.costgrid import CostGrid, CostParams, Region
from cmdragons.planning.grid.planners import EStar, descend_nf1, nf1
from cmdragons.planning.problem import PlanProblem, PlanResult, PlanStatus, RobustEnds, prepare
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CompiledWorld

__all__ = ["EStarParams", "EStarPlanner", "GridParams", "NF1Params", "NF1Planner", "cost_grid"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class GridParams(CostParams):
    """configs/planner.yaml ``grid``: the cost grid of both grid planners (a cost grid whose obstacle
    cells keep every free cell's area free)."""

    resolution_m: float = setting(0.1, lo=0.005, hi=1.0)  # cell size
    min_clearance_m: float = setting(0.071, lo=0.0, hi=1.0)  # less clearance: an obstacle cell

    def __post_init__(self) -> None:
        super().__post_init__()
        half_diagonal = self.resolution_m * math.sqrt(0.5)
        if self.min_clearance_m < half_diagonal - 1e-12:
            raise ValueError(f"min_clearance_m must be at least half a cell's diagonal ({half_diagonal:.4f} m for "
                             f"{self.resolution_m} m cells), so that a path through free cells is free")


@dataclass(frozen=True)
class EStarParams(Validated):
    """configs/planner.yaml ``estar``."""

    neighbours: int = setting(8, choices=(4, 8))  # interpolation kernel: 4 (the thesis') or 8 (also diagonals)
    connect_radius_m: float = setting(0.3, lo=0.0, hi=5.0)  # start and goal join the grid within this
    # more changed cells than this share of the grid: recompute instead of repairing
    repair_share: float = setting(0.05, lo=0.0, hi=1.0)
    goal_tolerance_m: float = setting(0.01, lo=0.0, hi=1.0)  # a goal that moves less than this is the same goal
    chunk_cells: int = setting(4096, lo=1, hi=10**8)  # cells propagated between termination checks
    work_budget: int = setting(1_000_000, lo=1, hi=10**9)  # cells propagated per robot and frame; then NO_PATH
    smoothing: SmoothingParams = SmoothingParams()


@dataclass(frozen=True)
class NF1Params(Validated):
    """configs/planner.yaml ``nf1``."""

    connectivity: int = setting(8, choices=(4, 8))  # wavefront moves: 4 or 8 neighbours
    connect_radius_m: float = setting(0.3, lo=0.0, hi=5.0)  # start and goal join the grid within this
    work_budget: int = setting(1_000_000, lo=1, hi=10**9)  # wavefront cells per robot and frame; fewer free: NO_PATH
    smoothing: SmoothingParams = SmoothingParams()


def cost_grid(cw: CompiledWorld, params: CostParams) -> CostGrid:
    """The cost grid of a compiled world (Philippsen 2004 §4.8): its clearance grid with the soft
    cost near every obstacle, and as weighted regions the clearance from its boxes alone
    (``defense_areas``) and from its circles alone (``opponents``); each clearance capped where its
    soft cost ends (the grid's cells beyond every obstacle's reach cost the same)."""
    res = params.resolution_m
    world = cw.world
    regions = []
    for region, circles, boxes in ((params.defense_areas, False, True), (params.opponents, True, False)):
        if region.near_cost > 0.0 and region.falloff_m > 0.0:
            part = world.subset(np.full(len(world.circles), circles), np.full(len(world.boxes), boxes))
            if part.n_obstacles:
                grid = part.compile(cw.radius_m, *cw.window_s, cw.params).clearance_grid(res, False, region.falloff_m)
                regions.append(Region(grid.values, region))
    # beyond the soft cost's reach and the obstacle threshold every clearance counts the same
    cap = max(params.obstacles.falloff_m, params.min_clearance_m) + res
    return CostGrid.from_clearance(cw.clearance_grid(res, cap_m=cap), params, regions)


def _links(cw: CompiledWorld, grid: CostGrid, point: tuple[float, float],
           radius_m: float) -> tuple[NDArray[np.int64], FloatArray]:
    """The free cells within ``radius_m`` of ``point`` (at least its own cell's neighbours) whose centre
    the robot reaches from ``point`` in a straight line: (k, 2) rows (row, col), and each one's
    distance to the point in cell lengths."""
    res = grid.resolution_m
    cx, cy = grid.to_cell(*point)
    span = max(1, int(math.ceil(radius_m / res)))
    r0, c0 = int(math.floor(cy + 0.5)), int(math.floor(cx + 0.5))
    h, w = grid.shape
    rows = np.arange(max(0, r0 - span), min(h, r0 + span + 1))
    cols = np.arange(max(0, c0 - span), min(w, c0 + span + 1))
    r2, c2 = np.meshgrid(rows, cols, indexing="ij")
    d = np.hypot(c2.ravel() - cx, r2.ravel() - cy)
    keep = np.isfinite(grid.cost[r2.ravel(), c2.ravel()]) & (d <= max(radius_m / res, 1.5))
    rr, cc, d = r2.ravel()[keep], c2.ravel()[keep], d[keep]
    if not len(rr):
        return np.zeros((0, 2), np.int64), np.zeros(0)
    centres = grid.to_field(np.column_stack([cc, rr]).astype(np.float64))
    seg = np.column_stack([np.broadcast_to(point, centres.shape), centres])
    free = cw.segments_free(seg)
    return np.column_stack([rr[free], cc[free]]).astype(np.int64), d[free]


class _GridPlanner(abc.ABC):
    """What E* and NF1 share: the robust ends, the direct path, the cost grid, the links of start
    and goal to it, the smoothing and the final check."""

    name = "grid"

    def __init__(self, grid: GridParams, connect_radius_m: float, smoothing: SmoothingParams) -> None:
        self.grid = grid
        self.connect_radius_m = connect_radius_m
        self.smoothing = smoothing

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult:
        """A path from ``problem.start`` to ``problem.goal`` on the grid, until ``termination``."""
        t0 = time.perf_counter()
        cw, ends = prepare(problem)
        if ends.failure is not None:
            return ends.fail(t0)
        stats: dict[str, Any] = {}
        if termination.expired():
            return ends.finish(None, PlanStatus.TIMEOUT, {"ms": (time.perf_counter() - t0) * 1e3})
        if cw.segment_free(ends.start, ends.goal):
            path = np.array([ends.start, ends.goal], dtype=np.float64)
            return ends.finish(path, PlanStatus.SOLVED, {"direct": True, "ms": (time.perf_counter() - t0) * 1e3})
        grid = cost_grid(cw, self.grid)
        goal_cells, goal_d = _links(cw, grid, ends.goal, self.connect_radius_m)
        start_cells, start_d = _links(cw, grid, ends.start, self.connect_radius_m)
        if not len(goal_cells) or not len(start_cells):
            stats["ms"] = (time.perf_counter() - t0) * 1e3
            stats["unlinked"] = "goal" if not len(goal_cells) else "start"
            return ends.finish(None, PlanStatus.NO_PATH, stats)
        status, cells = self._descend(grid, goal_cells, goal_d, start_cells, start_d, ends, termination, stats)
        if status is not PlanStatus.SOLVED:
            stats["ms"] = (time.perf_counter() - t0) * 1e3
            return ends.finish(None, status, stats)
        middle = grid.to_field(cells)
        path = np.vstack([[ends.start], middle])
        path = path[np.r_[True, np.hypot(*np.diff(path, axis=0).T) > 1e-9]]  # no repeated points
        if len(path) > 1 and math.dist(tuple(path[-1]), ends.goal) <= 1e-9:
            path = path[:-1]  # the descent's last point is the goal in cell units: the goal itself follows
        path = np.vstack([path, [ends.goal]])
        smoothed = smooth(cw, path, self.smoothing)
        stats["ms"] = (time.perf_counter() - t0) * 1e3
        if not cw.path_free(smoothed):  # the margin argument above says it cannot happen: a bug if it does
            stats["grid_path_collides"] = True
            return ends.finish(None, PlanStatus.NO_PATH, stats)
        return ends.finish(smoothed, PlanStatus.SOLVED, stats)

    @abc.abstractmethod
    def _descend(self, grid: CostGrid, goal_cells: NDArray[np.int64], goal_d: FloatArray,
                 start_cells: NDArray[np.int64], start_d: FloatArray, ends: RobustEnds, termination: Termination,
                 stats: dict[str, Any]) -> tuple[PlanStatus, FloatArray]:
        """The status and the descent's points in cell units (x along columns, y along rows) from a
        start link (rows of ``start_cells``, ``start_d`` cells from the start) to a goal link."""


class EStarPlanner(_GridPlanner):
    """E* as a global planner for one robot, its navigation function repaired across frames."""

    name = "estar"

    def __init__(self, params: EStarParams, grid: GridParams, rng: np.random.Generator | None = None) -> None:
        super().__init__(grid, params.connect_radius_m, params.smoothing)
        self.params = params
        self._estar: EStar | None = None
        self._key: tuple[Any, ...] | None = None  # (goal, grid origin and shape, goal cells and values)
        self._cost: FloatArray | None = None

    def reset(self) -> None:
        """Forget the navigation function."""
        self._estar, self._key, self._cost = None, None, None

    def _field(self, grid: CostGrid, goal_cells: NDArray[np.int64], values: FloatArray,
               goal: tuple[float, float]) -> tuple[EStar, bool]:
        """The navigation function toward ``goal``: the last frame's, repaired where the costs changed,
        when the goal and its cells are the same; else a fresh one. Returns it and whether it was kept."""
        key = (grid.x0, grid.y0, grid.resolution_m, grid.shape, goal_cells.tobytes(), values.tobytes())
        last = self._estar
        same_goal = self._key is not None and math.dist(self._key[0], goal) <= self.params.goal_tolerance_m
        if last is not None and self._cost is not None and same_goal and self._key is not None and self._key[1:] == key:
            changed = np.argwhere(grid.cost != self._cost)
            if len(changed) <= self.params.repair_share * grid.cost.size:
                last.set_costs(changed, grid.cost[changed[:, 0], changed[:, 1]])
                self._cost = grid.cost
                return last, True
        e = EStar(grid.cost, [(int(r), int(c)) for r, c in goal_cells], self.params.neighbours, list(values))
        e.goal_point = grid.to_cell(*goal)
        self._estar, self._cost, self._key = e, grid.cost, (goal, *key)
        return e, False

    def _descend(self, grid: CostGrid, goal_cells: NDArray[np.int64], goal_d: FloatArray,
                 start_cells: NDArray[np.int64], start_d: FloatArray, ends: RobustEnds, termination: Termination,
                 stats: dict[str, Any]) -> tuple[PlanStatus, FloatArray]:
        values = goal_d * grid.cost[goal_cells[:, 0], goal_cells[:, 1]]
        e, kept = self._field(grid, goal_cells, values, ends.goal)
        stats["repaired"] = kept
        nearest = start_cells[int(np.argmin(start_d))]
        until = (int(nearest[0]), int(nearest[1]))
        work = 0
        if not kept and termination.work >= grid.cost.size:
            e.compute()  # the whole field in the one-pass kernel: the budget covers every cell
            work = e.pops
        else:
            while True:
                left = termination.work_left(work, self.params.chunk_cells)
                done = left > 0 and e.compute(until, max_cells=left)
                work += e.pops if left > 0 else 0
                if done:
                    break
                if termination.reached(work):
                    stats["cells"] = work
                    return (PlanStatus.TIMEOUT if termination.expired() else PlanStatus.NO_PATH), np.zeros((0, 2))
        stats["cells"] = work
        v = e.value[start_cells[:, 0], start_cells[:, 1]]
        total = v + start_d * grid.cost[start_cells[:, 0], start_cells[:, 1]]
        if not np.isfinite(total).any():
            return PlanStatus.NO_PATH, np.zeros((0, 2))
        r, c = start_cells[int(np.argmin(total))]
        descent = e.path((float(c), float(r)))
        if not descent.found:
            return PlanStatus.NO_PATH, np.zeros((0, 2))
        return PlanStatus.SOLVED, descent.points


class NF1Planner(_GridPlanner):
    """NF1 as a global planner: the wavefront from the goal's cell each frame, the steepest descent."""

    name = "nf1"

    def __init__(self, params: NF1Params, grid: GridParams, rng: np.random.Generator | None = None) -> None:
        super().__init__(grid, params.connect_radius_m, params.smoothing)
        self.params = params

    def reset(self) -> None:
        """Nothing to forget: the wavefront is computed each frame."""

    def _descend(self, grid: CostGrid, goal_cells: NDArray[np.int64], goal_d: FloatArray,
                 start_cells: NDArray[np.int64], start_d: FloatArray, ends: RobustEnds, termination: Termination,
                 stats: dict[str, Any]) -> tuple[PlanStatus, FloatArray]:
        free = np.isfinite(grid.cost)
        stats["cells"] = int(free.sum())
        if termination.reached(float(free.sum())):  # the wavefront visits every free cell it reaches
            return (PlanStatus.TIMEOUT if termination.expired() else PlanStatus.NO_PATH), np.zeros((0, 2))
        g = goal_cells[int(np.argmin(goal_d))]
        dist = nf1(free, (int(g[0]), int(g[1])), self.params.connectivity)
        steps = dist[start_cells[:, 0], start_cells[:, 1]].astype(np.float64)
        steps[steps < 0] = np.inf
        if not np.isfinite(steps).any():
            return PlanStatus.NO_PATH, np.zeros((0, 2))
        r, c = start_cells[int(np.lexsort((start_d, steps))[0])]
        cells = descend_nf1(dist, (int(r), int(c)), self.params.connectivity)
        return PlanStatus.SOLVED, np.array([(cc, rr) for rr, cc in cells], dtype=np.float64)
