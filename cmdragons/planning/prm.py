"""Dynamic PRM (Bruce 2006 §4.4): a roadmap of the static field, searched among the moving robots.

Field frame, metres. The roadmap is built once per static world (boundary, defense areas, goal
walls) and robot radius, and kept in the planner across frames: nodes sampled uniformly in the free
field, each linked to the nearest node it sees in every one of ``n_sectors`` directions (the radial
connection technique of §4.4). A query links the start and the goal into it the same way, then runs
A* that checks nodes and edges against the current robots only when it reaches them (lazy
validation). When the robots cut every route, it adds random nodes to the roadmap and searches
again until the roadmap is full or the termination stops it (work: roadmap nodes added by this
query, drawn). The path is smoothed like ERRT's.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.planning import _graphsearch_kernels as G
from cmdragons.planning import _prm_kernels as K
from cmdragons.planning.errt import SmoothingParams, smooth
from cmdragons.planning.problem import PlanProblem, PlanResult, PlanStatus, RobustEnds, prepare
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CompiledWorld

__all__ = ["DynamicPRMParams", "DynamicPRMPlanner"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class DynamicPRMParams(Validated):
    """configs/planner.yaml ``prm``."""

    n_nodes: int = setting(300, lo=2, hi=100000)  # roadmap nodes sampled in the static free field
    n_sectors: int = setting(8, lo=1, hi=64)  # radial connection directions per node
    connect_radius_m: float = setting(1.5, lo=0.01, hi=100.0)  # longest roadmap edge
    grow_nodes: int = setting(50, lo=1, hi=100000)  # nodes added when the robots cut every route
    max_nodes: int = setting(1000, lo=2, hi=1000000)  # the roadmap's size limit; then NO_PATH
    # roadmap nodes one query may add (the work budget of its termination); spent: NO_PATH
    work_budget: int = setting(1000, lo=1, hi=1000000)
    smoothing: SmoothingParams = SmoothingParams()


class Roadmap:
    """Nodes (n, 2) and undirected edges of a roadmap, free of the static obstacles; CSR adjacency."""

    def __init__(self, static_cw: CompiledWorld, params: DynamicPRMParams) -> None:
        self.cw = static_cw
        self.params = params
        self.pts = np.zeros((0, 2))
        self.edges = np.zeros((0, 2), dtype=np.int64)
        self.lengths = np.zeros(0)

    def grow(self, rng: np.random.Generator, n: int) -> None:
        """Add up to ``n`` nodes sampled uniformly in the free field and link them (radial sectors)."""
        x0, y0, x1, y1 = self.cw.inner
        cand = rng.uniform((x0, y0), (x1, y1), size=(n, 2))
        seg = np.hstack([cand, cand])
        cand = cand[self.cw.segments_free(seg)]
        self.link(cand)

    def link(self, new: FloatArray) -> None:
        first = len(self.pts)
        self.pts = np.vstack([self.pts, new])
        ea, ew = K.connect_sectors(self.cw.cw, self.pts, first, self.params.n_sectors, self.params.connect_radius_m)
        edges = np.vstack([self.edges, np.sort(ea, axis=1)])
        lengths = np.concatenate([self.lengths, ew])
        edges, keep = np.unique(edges, axis=0, return_index=True)  # an edge found from both ends once
        self.edges, self.lengths = edges, lengths[keep]

    def csr(self, extra: FloatArray) -> tuple[FloatArray, NDArray[np.int64], NDArray[np.int64], FloatArray]:
        """Points and CSR adjacency of the roadmap plus ``extra`` query nodes linked into it (the
        query nodes' links are checked only against the static world here, like all roadmap edges)."""
        first = len(self.pts)
        pts = np.vstack([self.pts, extra])
        ea, ew = K.connect_sectors(self.cw.cw, pts, first, self.params.n_sectors, self.params.connect_radius_m)
        a = np.concatenate([self.edges[:, 0], self.edges[:, 1], ea[:, 0], ea[:, 1]])
        b = np.concatenate([self.edges[:, 1], self.edges[:, 0], ea[:, 1], ea[:, 0]])
        w = np.concatenate([self.lengths, self.lengths, ew, ew])
        order = np.argsort(a, kind="stable")
        start = np.zeros(len(pts) + 1, dtype=np.int64)
        np.add.at(start, a + 1, 1)
        return pts, np.cumsum(start), b[order].astype(np.int64), w[order]


class DynamicPRMPlanner:
    """Dynamic PRM for one robot; the roadmap of the static field lives across frames."""

    name = "prm"

    def __init__(self, params: DynamicPRMParams, rng: np.random.Generator) -> None:
        self.params = params
        self.rng = rng
        self._roadmap: Roadmap | None = None
        self._key: tuple[object, ...] | None = None

    def reset(self) -> None:
        self._roadmap = None
        self._key = None

    def roadmap(self, problem: PlanProblem) -> Roadmap:
        """The roadmap of the problem's static world, built on first use and kept while it stays."""
        static = problem.world.static_part()
        key = (static.bounds, static.boxes.tobytes(), problem.radius_m)
        if self._roadmap is None or key != self._key:
            self._roadmap = Roadmap(static.compile(problem.radius_m, params=problem.collision), self.params)
            self._roadmap.grow(self.rng, self.params.n_nodes)
            self._key = key
        return self._roadmap

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult:
        """Plan from ``problem.start`` to ``problem.goal`` until ``termination`` (work: roadmap nodes
        added by this query)."""
        t0 = time.perf_counter()
        cw, ends = prepare(problem)
        if ends.failure is not None:
            return ends.fail(t0)
        s, g = ends.start, ends.goal
        if cw.segment_free(s, g):
            return self._finish(ends, np.array([s, g]), PlanStatus.SOLVED, {"searches": 0}, t0)
        rm = self.roadmap(problem)
        searches = 0
        added = 0
        while True:
            pts, start, adj, w = rm.csr(np.array([s, g]))
            src, dst = len(pts) - 2, len(pts) - 1
            cost, prev = G.astar(cw.cw, pts, start, adj, w, src, dst, np.zeros(len(adj), dtype=np.int8))
            route: NDArray[np.int64] = G.route_to(prev, dst) if np.isfinite(cost[dst]) else np.zeros(0, np.int64)
            searches += 1
            stats: dict[str, object] = {"searches": searches, "roadmap_nodes": len(rm.pts), "added": added}
            if len(route):
                return self._finish(ends, smooth(cw, pts[route], self.params.smoothing), PlanStatus.SOLVED, stats, t0)
            room = min(self.params.max_nodes - len(rm.pts), termination.work_left(added, self.params.grow_nodes))
            if room <= 0:
                return self._finish(ends, None, PlanStatus.NO_PATH, stats, t0)
            if termination.expired():
                return self._finish(ends, None, PlanStatus.TIMEOUT, stats, t0)
            rm.grow(self.rng, room)
            added += room  # nodes drawn, the free ones kept

    @staticmethod
    def _finish(
        ends: RobustEnds, path: FloatArray | None, status: PlanStatus, stats: dict[str, object], t0: float
    ) -> PlanResult:
        stats["ms"] = (time.perf_counter() - t0) * 1e3
        return ends.finish(path, status, stats)
