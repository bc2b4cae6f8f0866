"""Exact cell decomposition into trapezoids (seed 001, "Exact Cell Decomposition", with the
Euclidean metric): the vertical sweep over the free space's polygon.

Field frame, metres. The free space (:func:`cmdragons.planning.cspace.free_space`: the box inside
the walls less polygons that contain the obstacles) is cut by a vertical line through every vertex
of its boundary. Between two neighbouring cut lines no vertex lies, so the boundary edges that span
the slab do not cross and split it into pieces bounded by two of them: trapezoids (free and
obstacle pieces alternate from the bottom, which is outside). Two trapezoids of neighbouring slabs
are adjacent when their sides on the shared cut line overlap. The graph's nodes are the midpoints of
those shared sides ("nodes placed at the centre of the cell boundary"), joined within each cell
(a trapezoid is convex: the straight move between two points of its boundary stays inside it) with
their distance as the weight. Start and goal join the nodes on the boundary of the cell they lie in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from cmdragons.config import setting
from cmdragons.planning.cspace import free_space
from cmdragons.planning.graphsearch import Graph, link_point
from cmdragons.planning.roadmap import GraphPlanner, GraphSearchParams
from cmdragons.planning.world import CompiledWorld

__all__ = ["Trapezoids", "TrapezoidalParams", "TrapezoidalPlanner", "trapezoids"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

EPS_M = 1e-9  # slabs and overlaps narrower than this count as none


@dataclass(frozen=True)
class TrapezoidalParams(GraphSearchParams):
    """configs/planner.yaml ``trapezoidal``."""

    quad_segs: int = setting(4, lo=1, hi=64)  # polygon segments a quarter circle of a round obstacle


@dataclass(frozen=True, eq=False)
class Trapezoids:
    """The decomposition: cell c spans x in [x0[c], x1[c]] between its bottom edge (from (x0, ylo0)
    to (x1, ylo1)) and its top edge ((x0, yhi0) to (x1, yhi1)); ``cells`` (n, 6) holds
    x0, x1, ylo0, yhi0, ylo1, yhi1. ``portals`` (m, 2): the midpoints of shared sides, and
    ``portal_cells`` (m, 2) the cells on their left and right."""

    cells: FloatArray
    portals: FloatArray
    portal_cells: IntArray

    def area(self) -> float:
        c = self.cells
        return float(np.sum((c[:, 1] - c[:, 0]) * ((c[:, 3] - c[:, 2]) + (c[:, 5] - c[:, 4])) / 2.0))

    def locate(self, x: float, y: float) -> int:
        """The cell holding (x, y), or -1 (a point on a shared side: the one on its left)."""
        c = self.cells
        t = np.where(c[:, 1] > c[:, 0], (x - c[:, 0]) / np.maximum(c[:, 1] - c[:, 0], EPS_M), 0.0)
        lo = c[:, 2] + t * (c[:, 4] - c[:, 2])
        hi = c[:, 3] + t * (c[:, 5] - c[:, 3])
        hit = np.flatnonzero((c[:, 0] <= x) & (x <= c[:, 1]) & (lo <= y) & (y <= hi))
        return int(hit[0]) if len(hit) else -1


def _edges(free: shapely.Polygon | shapely.MultiPolygon) -> FloatArray:
    """Every boundary edge (ax, ay, bx, by) of the free space, left end first, vertical ones left out."""
    rings = [r for poly in getattr(free, "geoms", [free]) for r in (poly.exterior, *poly.interiors)]
    out = []
    for ring in rings:
        p = np.asarray(ring.coords)
        seg = np.column_stack([p[:-1], p[1:]])
        swap = seg[:, 2] < seg[:, 0]
        seg[swap] = seg[swap][:, [2, 3, 0, 1]]
        out.append(seg[seg[:, 2] - seg[:, 0] > EPS_M])
    return np.vstack(out) if out else np.zeros((0, 4))


def trapezoids(free: shapely.Polygon | shapely.MultiPolygon) -> Trapezoids:
    """The vertical trapezoidal decomposition of ``free`` (see the module docstring)."""
    edges = _edges(free)
    xs = np.unique(edges[:, [0, 2]]) if len(edges) else np.zeros(0)
    xs = xs[np.r_[True, np.diff(xs) > EPS_M]]  # cut lines closer than EPS_M are one
    cells: list[tuple[float, ...]] = []
    slab_cells: list[list[int]] = []
    for a, b in zip(xs[:-1], xs[1:], strict=True):
        span = edges[(edges[:, 0] <= a + EPS_M) & (edges[:, 2] >= b - EPS_M)]
        dx = span[:, 2] - span[:, 0]
        ya = span[:, 1] + (a - span[:, 0]) / dx * (span[:, 3] - span[:, 1])
        yb = span[:, 1] + (b - span[:, 0]) / dx * (span[:, 3] - span[:, 1])
        order = np.argsort((ya + yb) / 2.0, kind="stable")
        ya, yb = ya[order], yb[order]
        here = []
        for k in range(0, len(order) - 1, 2):  # below the lowest edge is outside: free pieces alternate
            here.append(len(cells))
            cells.append((a, b, ya[k], ya[k + 1], yb[k], yb[k + 1]))
        slab_cells.append(here)
    portals: list[tuple[float, float]] = []
    pairs: list[tuple[int, int]] = []
    for left, right in zip(slab_cells[:-1], slab_cells[1:], strict=True):
        for i in left:
            lo_i, hi_i = cells[i][4], cells[i][5]
            for j in right:
                lo, hi = max(lo_i, cells[j][2]), min(hi_i, cells[j][3])
                if hi - lo > EPS_M:
                    portals.append((cells[i][1], (lo + hi) / 2.0))
                    pairs.append((i, j))
    return Trapezoids(
        np.array(cells, dtype=np.float64).reshape(-1, 6),
        np.array(portals, dtype=np.float64).reshape(-1, 2),
        np.array(pairs, dtype=np.int64).reshape(-1, 2),
    )


def portal_graph(cells: Trapezoids) -> Graph:
    """The graph of the shared sides' midpoints, each joined to every other on its two cells."""
    n_cells = len(cells.cells)
    on_cell: list[list[int]] = [[] for _ in range(n_cells)]
    for p, (i, j) in enumerate(cells.portal_cells):
        on_cell[i].append(p)
        on_cell[j].append(p)
    edges = [(a, b) for ps in on_cell for k, a in enumerate(ps) for b in ps[k + 1 :]]
    return Graph.from_edges(cells.portals, np.array(edges, dtype=np.int64).reshape(-1, 2))


class TrapezoidalPlanner(GraphPlanner):
    """Exact trapezoidal cell decomposition, built from each query's world. Nothing lives across
    queries (the cells are kept only while the query links its start and goal to them)."""

    name = "trapezoidal"

    def __init__(self, params: TrapezoidalParams, rng: np.random.Generator | None = None) -> None:
        super().__init__(params)
        self.trapezoidal = params
        self._cells: Trapezoids | None = None

    def graph(self, cw: CompiledWorld, stats: dict[str, Any]) -> Graph:
        self._cells = trapezoids(free_space(cw, self.trapezoidal.quad_segs))
        stats["cells"] = len(self._cells.cells)
        return portal_graph(self._cells)

    def links(self, cw: CompiledWorld, graph: Graph, point: tuple[float, float]) -> tuple[IntArray, FloatArray]:
        """The midpoints of the sides of the cell ``point`` lies in; a point in no cell (free, but
        within the polygons' margin) joins the nearest nodes it sees."""
        cells = self._cells
        c = cells.locate(*point) if cells is not None else -1
        if c < 0 or cells is None:
            return super().links(cw, graph, point)
        nodes = np.flatnonzero((cells.portal_cells == c).any(axis=1)).astype(np.int64)
        d = np.hypot(graph.pts[nodes, 0] - point[0], graph.pts[nodes, 1] - point[1])
        if not len(nodes):  # a cell with no neighbour: the nearest it sees, if any
            return link_point(cw, graph.pts, point, self.params.link_candidates, math.inf)
        return nodes, d
