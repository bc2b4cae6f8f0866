"""Approximate cell decomposition (seed 001, "Approximate Cell Decomposition": uniform or quadtree):
the cells wholly in the free space and their connectivity graph, edges weighted by the Euclidean
distance of the cells' centres.

Field frame, metres. A cell is free when the clearance at its centre (the compiled world's exact
clearance: the distance from the robot's centre to the nearest grown obstacle or wall) is at least
half its diagonal: the clearance is 1-Lipschitz, so every point of the cell is then free. Cells that
are not wholly free are lost (the method's inexactness: a passage narrower than a cell's diagonal
may vanish). The straight move between the centres of two free cells that share a side (or, on the
uniform grid, a corner) stays in their union, hence free.

* Uniform grid: cells of ``resolution_m`` over the field's boundary box, 4 or 8 neighbours.
* Quadtree: the boundary box split in four, and each part not wholly free split again until its
  side is below ``min_cell_m`` (a cell whose centre lies deeper than half its diagonal inside an
  obstacle is wholly blocked and not split). Free leaves are neighbours when they share a stretch of
  a side; they are found on a raster of the finest cells, each painted with its leaf.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import setting
from cmdragons.planning import _graphsearch_kernels as K
from cmdragons.planning.graphsearch import Graph
from cmdragons.planning.roadmap import GraphPlanner, GraphSearchParams
from cmdragons.planning.world import CompiledWorld

__all__ = [
    "QuadtreeParams",
    "QuadtreePlanner",
    "UniformCellsParams",
    "UniformCellsPlanner",
    "quadtree",
    "uniform_cells",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class UniformCellsParams(GraphSearchParams):
    """configs/planner.yaml ``uniform_cells``."""

    resolution_m: float = setting(0.05, lo=0.005, hi=1.0)  # cell side
    connectivity: int = setting(8, choices=(4, 8))  # neighbours of a cell


@dataclass(frozen=True)
class QuadtreeParams(GraphSearchParams):
    """configs/planner.yaml ``quadtree``."""

    min_cell_m: float = setting(0.05, lo=0.005, hi=1.0)  # a cell not wholly free is split while its side is longer


def uniform_cells(cw: CompiledWorld, resolution_m: float, connectivity: int) -> tuple[Graph, NDArray[np.bool_]]:
    """The uniform grid's connectivity graph and its free mask (ny, nx) over the boundary box."""
    grid = cw.clearance_grid(resolution_m, cap_m=resolution_m)
    free = grid.values >= resolution_m * math.sqrt(0.5)
    graph = grid_graph(free, grid.x0, grid.y0, resolution_m, connectivity)
    return graph, free


def grid_graph(free: NDArray[np.bool_], x0: float, y0: float, resolution_m: float, connectivity: int) -> Graph:
    """The connectivity graph of the free cells of a uniform grid (cell (i, k) centred at
    x0 + (k + 1/2) res, y0 + (i + 1/2) res)."""
    _node, pts, indptr, adj, w = K.grid_graph(np.ascontiguousarray(free), x0, y0, resolution_m, connectivity)
    return Graph(pts, indptr, adj, w, octile=True)


@dataclass(frozen=True, eq=False)
class Quadtree:
    """The free leaves: ``boxes`` (n, 4) x0, y0, x1, y1; ``levels`` (n,) their depth; with counts."""

    boxes: FloatArray
    levels: IntArray
    leaves_blocked: int
    depth: int


def quadtree(cw: CompiledWorld, min_cell_m: float) -> tuple[Quadtree, Graph]:
    """The quadtree decomposition of ``cw``'s boundary box and the graph of its free leaves."""
    x0, y0, x1, y1 = cw.world.bounds
    depth = max(0, math.ceil(math.log2(max(x1 - x0, y1 - y0) / min_cell_m)))
    # cells on the finest raster: (ix, iy) of the lower-left finest cell and the side in finest cells
    n = 1 << depth
    fx, fy = (x1 - x0) / n, (y1 - y0) / n
    cells = np.zeros((1, 3), dtype=np.int64)
    cells[0, 2] = n
    free_cells: list[NDArray[np.int64]] = []
    levels: list[IntArray] = []
    blocked = 0
    for level in range(depth + 1):
        side = cells[:, 2].astype(np.float64)
        cx = x0 + (cells[:, 0] + side / 2.0) * fx
        cy = y0 + (cells[:, 1] + side / 2.0) * fy
        half_diag = 0.5 * side * math.hypot(fx, fy)
        clearance, _ = cw.clearance_gradients(np.column_stack([cx, cy]))
        free = clearance >= half_diag
        solid = clearance <= -half_diag  # deeper inside than the cell reaches: wholly blocked
        free_cells.append(cells[free])
        levels.append(np.full(int(free.sum()), level, dtype=np.int64))
        split = ~free & ~solid
        blocked += int(solid.sum()) + (int(split.sum()) if level == depth else 0)
        parts = cells[split]
        if level == depth or not len(parts):
            break
        h = parts[:, 2] // 2
        cells = np.vstack([np.column_stack([parts[:, 0] + dx * h, parts[:, 1] + dy * h, h])
                           for dx in (0, 1) for dy in (0, 1)])
    leaves = np.vstack(free_cells) if free_cells else np.zeros((0, 3), np.int64)
    lo = np.column_stack([x0 + leaves[:, 0] * fx, y0 + leaves[:, 1] * fy])
    boxes = np.hstack([lo, lo + leaves[:, 2:3] * np.array([fx, fy])])
    tree = Quadtree(boxes, np.concatenate(levels), blocked, depth)
    return tree, _leaf_graph(leaves, n, boxes)


def _leaf_graph(leaves: NDArray[np.int64], n: int, boxes: FloatArray) -> Graph:
    """Leaves that share a stretch of a side, found on the finest raster painted with leaf ids."""
    raster = -np.ones((n, n), dtype=np.int64)  # [ix, iy]
    for k, (ix, iy, s) in enumerate(leaves):
        raster[ix : ix + s, iy : iy + s] = k
    pairs = []
    for a, b in ((raster[:-1, :], raster[1:, :]), (raster[:, :-1], raster[:, 1:])):
        m = (a >= 0) & (b >= 0) & (a != b)
        pairs.append(np.column_stack([a[m], b[m]]))
    e = np.sort(np.vstack(pairs), axis=1) if pairs else np.zeros((0, 2), np.int64)
    e = np.unique(e, axis=0)
    centres = np.column_stack([(boxes[:, 0] + boxes[:, 2]) / 2.0, (boxes[:, 1] + boxes[:, 3]) / 2.0])
    return Graph.from_edges(centres, e)


class UniformCellsPlanner(GraphPlanner):
    """The uniform grid decomposition, built from each query's world. Stateless."""

    name = "uniform_cells"

    def __init__(self, params: UniformCellsParams, rng: np.random.Generator | None = None) -> None:
        super().__init__(params)
        self.cells = params

    def graph(self, cw: CompiledWorld, stats: dict[str, Any]) -> Graph:
        graph, free = uniform_cells(cw, self.cells.resolution_m, self.cells.connectivity)
        stats["cells"], stats["free_cells"] = int(free.size), int(free.sum())
        return graph


class QuadtreePlanner(GraphPlanner):
    """The quadtree decomposition, built from each query's world. Stateless."""

    name = "quadtree"

    def __init__(self, params: QuadtreeParams, rng: np.random.Generator | None = None) -> None:
        super().__init__(params)
        self.quadtree = params

    def graph(self, cw: CompiledWorld, stats: dict[str, Any]) -> Graph:
        tree, graph = quadtree(cw, self.quadtree.min_cell_m)
        stats["free_leaves"], stats["blocked_leaves"], stats["depth"] = len(tree.boxes), tree.leaves_blocked, tree.depth
        return graph
