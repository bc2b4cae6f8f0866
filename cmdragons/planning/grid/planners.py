"""Grid navigation functions: NF1, 8-connected Dijkstra / A*, and E* (Philippsen 2004).

All work on a cost grid, shape (rows, cols): each free cell's traversal cost per cell length (>= 1),
``inf`` for an obstacle. Cells are addressed as (row, col); points on paths as (x, y) in cell units
with x along columns and y along rows, cell centres at integers. Converting to the field frame is the
grid's business (:class:`cmdragons.planning.grid.costgrid.CostGrid`).

- :func:`nf1`: the wavefront of Latombe's NF1 (thesis §3.6, A.2): steps to the goal over 4- or
  8-connected moves, the path by steepest descent.
- :func:`octile_path`: the exact 8-connected shortest path (straight 1, diagonal sqrt 2, scaled by
  the cells' cost; never through a blocked corner) by Dijkstra or A*.
- :class:`EStar`: the interpolated navigation function (ch. 4): fast-marching interpolation of the
  distance to the goal, propagated as events so that a change of cost repairs only the cells it
  affects (the D*-like dynamic replanning of §4.3), the path by gradient descent on the field.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.geometry import path_length
from cmdragons.planning.grid import _kernels as k

__all__ = ["EStar", "GridPath", "descend_nf1", "nf1", "octile_path"]

Cell = tuple[int, int]
FloatArray = NDArray[np.float64]
# the kernels' indexed heap: keys, items, positions, size
Heap = tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]


@dataclass(frozen=True)
class GridPath:
    """A path in cell units (x along columns, y along rows), its length, and the work done."""

    points: FloatArray  # (k, 2); empty when there is no path
    length: float
    expanded: int

    @property
    def found(self) -> bool:
        return len(self.points) > 0


def _padded(cost: FloatArray) -> FloatArray:
    """The grid with a border of obstacle cells one cell wide, flattened (what E*'s kernels take)."""
    padded = np.full((cost.shape[0] + 2, cost.shape[1] + 2), np.inf)
    padded[1:-1, 1:-1] = cost
    return padded.ravel()


def _check(cost: FloatArray) -> tuple[int, int]:
    if cost.ndim != 2 or cost.dtype != np.float64:
        raise ValueError("a cost grid is a 2-D float64 array")
    return cost.shape[0], cost.shape[1]


def nf1(free: NDArray[np.bool_], goal: Cell, connectivity: int = 4) -> NDArray[np.int64]:
    """NF1: steps from every free cell to ``goal`` (row, col), -1 where the goal cannot be reached;
    4- or 8-connected, every move one step."""
    if connectivity not in (4, 8):
        raise ValueError("connectivity must be 4 or 8")
    h, w = free.shape
    flat = np.ascontiguousarray(free, dtype=np.bool_).ravel()
    return k.nf1(flat, h, w, goal[0] * w + goal[1], connectivity == 8).reshape(h, w)


def descend_nf1(dist: NDArray[np.int64], start: Cell, connectivity: int = 4) -> list[Cell]:
    """The cells from ``start`` down an NF1 wavefront to its goal (each step to the lowest
    neighbour, the first in a fixed order on ties); empty when ``start`` is unreachable."""
    h, w = dist.shape
    if dist[start] < 0:
        return []
    moves = [(-1, 0), (1, 0), (0, -1), (0, 1)] + ([(-1, -1), (-1, 1), (1, -1), (1, 1)] if connectivity == 8 else [])
    path = [start]
    r, c = start
    while dist[r, c] > 0:
        best = None
        for dr, dc in moves:
            rr, cc = r + dr, c + dc
            if 0 <= rr < h and 0 <= cc < w and 0 <= dist[rr, cc] < dist[r, c]:
                if best is None or dist[rr, cc] < dist[best]:
                    best = (rr, cc)
        assert best is not None  # a wavefront value > 0 always has a lower neighbour
        r, c = best
        path.append(best)
    return path


def octile_path(cost: FloatArray, start: Cell, goal: Cell, astar: bool = True) -> GridPath:
    """The shortest 8-connected path from ``start`` to ``goal`` (row, col): A* with the octile
    distance (``astar``) or Dijkstra; both exact."""
    h, w = _check(cost)
    parent = np.empty(h * w, np.int64)
    flat = np.ascontiguousarray(cost).ravel()
    s, g = start[0] * w + start[1], goal[0] * w + goal[1]
    if not (math.isfinite(flat[s]) and math.isfinite(flat[g])):
        return GridPath(np.zeros((0, 2)), math.inf, 0)
    length, expanded = k.octile_search(flat, h, w, s, g, astar, parent)
    if not math.isfinite(length):
        return GridPath(np.zeros((0, 2)), math.inf, expanded)
    cells = [g]
    while cells[-1] != s:
        cells.append(int(parent[cells[-1]]))
    pts = np.array([(c % w, c // w) for c in reversed(cells)], dtype=np.float64)
    return GridPath(pts, float(length), expanded)


class EStar:
    """E* on one cost grid toward a set of goal cells (Philippsen 2004, ch. 4).

    ``compute()`` propagates until every reachable cell holds its value (the full navigation
    function); ``set_costs(cells, costs)`` changes cells' costs and queues only what they affect, so
    the next ``compute()`` repairs the field (a raised region first goes to infinity and is then
    lowered again, as D*'s raise and lower events); ``path(start)`` descends the field from a point.
    The repaired field equals a recomputation from scratch cell for cell."""

    def __init__(self, cost: FloatArray, goals: Sequence[Cell], neighbours: int = 8,
                 goal_values: Sequence[float] | None = None, *, padded: FloatArray | None = None) -> None:
        """``neighbours``: the interpolation on the 4-neighbourhood (first-order fast marching) or
        on the 8-neighbourhood (also along the diagonals: about 1% of Euclidean distance instead of
        up to 7%); ``goal_values``: each goal cell's own starting value (default 0), e.g. exact
        distances on a disc around a goal point; ``padded``: ``cost`` already with its border
        (:func:`_padded`), taken as the field's own."""
        if neighbours not in (4, 8):
            raise ValueError("neighbours must be 4 or 8")
        self.eight = neighbours == 8
        self.h, self.w = _check(cost)
        # inside, the grid carries a border of obstacle cells: every cell has all its neighbours
        self.W = self.w + 2
        self.cost = _padded(cost) if padded is None else padded
        n = len(self.cost)
        self.v = np.full(n, np.inf)
        self.rhs = self.v.copy()
        self.goal = np.zeros(n, np.bool_)
        self._heap: Heap | None = None
        self.pops = 0  # cells processed by the last compute()
        values = [0.0] * len(goals) if goal_values is None else list(goal_values)
        seeds = []
        for (r, c), value in zip(goals, values, strict=True):
            i = self._index(r, c)
            if not math.isfinite(self.cost[i]):
                raise ValueError(f"goal cell {(r, c)} is an obstacle")
            self.goal[i] = True
            self.rhs[i] = value
            seeds.append(i)
        self._seeds = (np.array(seeds, dtype=np.int64), np.array(values, dtype=np.float64))
        self._fresh = True  # nothing computed yet: a first full compute() takes the one-pass kernel
        # a goal point whose surrounding cells start at their straight-line distance (from_point):
        # a path that reaches one of them goes on straight to it
        self.goal_point: tuple[float, float] | None = None

    @classmethod
    def from_point(cls, cost: FloatArray, goal: tuple[float, float], neighbours: int = 8,
                   exact_radius: float = 5.0) -> EStar:
        """E* toward the point ``goal`` (x, y in cell units): the cells within ``exact_radius`` cells of
        it that see it in a straight line start at their exact distance times their cost, so that the
        grid's error near the source (up to 7% at ten cells for a point seed) does not spread; beyond
        the disc the field stays within about 1.5% of the Euclidean distance on an even grid."""
        h, w = _check(cost)
        gx, gy = goal
        r0, c0 = int(round(gy)), int(round(gx))
        if not (0 <= r0 < h and 0 <= c0 < w) or not math.isfinite(cost[r0, c0]):
            raise ValueError(f"goal {goal} is outside the grid or in an obstacle")
        span = int(math.ceil(exact_radius))
        padded = _padded(cost)
        cells, values = [], []
        for r in range(max(0, r0 - span), min(h, r0 + span + 1)):
            for c in range(max(0, c0 - span), min(w, c0 + span + 1)):
                d = math.hypot(c - gx, r - gy)
                if (d <= exact_radius or (r, c) == (r0, c0)) and k.sight(padded, w + 2, gx + 1, gy + 1, c + 1, r + 1):
                    cells.append((r, c))
                    values.append(d * cost[r, c])
        e = cls(cost, cells, neighbours, values, padded=padded)
        e.goal_point = (float(gx), float(gy))
        return e

    def _index(self, r: int, c: int) -> int:
        if not (0 <= r < self.h and 0 <= c < self.w):
            raise ValueError(f"cell {(r, c)} is outside the {self.h} x {self.w} grid")
        return (r + 1) * self.W + c + 1

    @property
    def heap(self) -> Heap:
        """The repair queue (keys, items, positions, size), made when a repair first needs it: a
        field computed once in one pass never does."""
        if self._heap is None:
            self._heap = k.new_heap(len(self.cost))
        return self._heap

    def _queue_seeds(self) -> None:
        """The goal cells onto the repair queue (before the first compute, when the one-pass kernel
        is not used)."""
        if self._fresh:
            self._fresh = False
            for i, value in zip(*self._seeds, strict=True):
                k.heap_set(*self.heap, int(i), float(value))

    @property
    def value(self) -> FloatArray:
        """The navigation function, shape (rows, cols): cost-weighted distance to the nearest goal
        in cell lengths (inf: unreachable or not yet computed)."""
        return self.v.reshape(self.h + 2, self.W)[1:-1, 1:-1]

    @property
    def pending(self) -> int:
        """Cells queued for (re)computation."""
        return (0 if self._heap is None else int(self._heap[3][0])) + (len(self._seeds[0]) if self._fresh else 0)

    def compute(self, until: Cell | None = None, max_cells: int = -1) -> bool:
        """Propagate queued changes: everywhere, or (``until``) only until that cell's value is final;
        at most ``max_cells`` cells (< 0: no limit). Returns whether it finished."""
        if self._fresh and until is None and max_cells < 0:
            self._fresh = False
            self.pops = int(k.estar_full(self.v, self.rhs, self.cost, self.W, self.goal, *self._seeds, self.eight))
            return True
        self._queue_seeds()
        stop = -1 if until is None else self._index(*until)
        self.pops, done = k.estar_propagate(self.v, self.rhs, self.cost, self.W, self.goal, *self.heap, stop,
                                            max_cells, self.eight)
        return bool(done)

    def set_costs(self, cells: NDArray[np.int64], costs: FloatArray | float) -> int:
        """New costs for ``cells`` (rows of (row, col)); returns how many changed."""
        self._queue_seeds()
        cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
        if len(cells) and ((cells < 0).any() or (cells >= (self.h, self.w)).any()):
            raise ValueError("cells outside the grid")
        flat = (cells[:, 0] + 1) * self.W + cells[:, 1] + 1
        values = np.broadcast_to(np.asarray(costs, dtype=np.float64), flat.shape).copy()
        if np.any(self.goal[flat] & ~np.isfinite(values)):
            raise ValueError("a goal cell cannot become an obstacle")
        return int(k.estar_set_costs(self.v, self.rhs, self.cost, self.W, self.goal, *self.heap, flat, values,
                                     self.eight))

    def path(self, start_xy: tuple[float, float], step: float = 0.5, max_steps: int | None = None,
             taut: bool = True) -> GridPath:
        """Gradient descent from ``start_xy`` (cell units) to a goal cell, then onto its centre (or
        straight on to the goal point of :meth:`from_point`); ``taut``: the descent's points pulled
        taut (a point dropped wherever the one before sees the one after in a straight line). Empty
        when the start's cell is unknown (unreachable or not computed)."""
        x, y = start_xy
        r, c = int(round(y)), int(round(x))
        if not (0 <= r < self.h and 0 <= c < self.w) or not math.isfinite(self.v[self._index(r, c)]):
            return GridPath(np.zeros((0, 2)), math.inf, 0)
        limit = max_steps if max_steps is not None else int(4 * (self.h + self.w) / step) + 16
        out = np.empty((limit + 1, 2))
        n = k.estar_descend(self.v, self.h + 2, self.W, float(x) + 1.0, float(y) + 1.0, step, limit, out)
        if n == 0:
            return GridPath(np.zeros((0, 2)), math.inf, 0)
        pts = out[:n]
        if taut:
            pts = k.pull_taut(self.cost, self.W, pts)
        pts = pts - 1.0
        end = (float(round(pts[-1, 0])), float(round(pts[-1, 1])))
        if self.goal_point is not None:
            end = self.goal_point  # the last cell sees the goal point in a straight line
        if (pts[-1, 0], pts[-1, 1]) != end:
            pts = np.vstack([pts, end])
        return GridPath(pts, path_length(pts), 0)
