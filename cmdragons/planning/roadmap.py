"""What the road-map planners share (Voronoi road map, trapezoidal, uniform-grid and quadtree
cell decompositions; seed 001, "Road-Map Path Planning"): build a graph of the free space, join the
start and the goal to it, search it (:mod:`cmdragons.planning.graphsearch`, any of its methods), and
return the route through the graph's nodes.

Field frame, metres. Each planner builds its graph from the problem's compiled world every query
(the robots move between frames); the planner's graph is collision-free by its construction, and
the start and goal join it by straight moves the exact swept-disc query passed. The final path is
checked once more by the exact query. Work (the termination's unit): nodes expanded by the search.
"""

from __future__ import annotations

import abc
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.planning.graphsearch import SEARCHES, Graph, SearchStatus, link_point, search
from cmdragons.planning.problem import PlanProblem, PlanResult, PlanStatus, Stateless, prepare
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CompiledWorld

__all__ = ["GraphPlanner", "GraphSearchParams"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class GraphSearchParams(Validated):
    """The part every road-map planner's config section shares."""

    search: str = setting("astar", choices=tuple(SEARCHES))  # bfs | dfs | best_first | dijkstra | astar
    link_candidates: int = setting(16, lo=1, hi=10000)  # start and goal try this many nearest nodes ...
    link_radius_m: float = setting(2.0, lo=0.0, hi=100.0)  # ... within this, keeping those they see
    work_budget: int = setting(1_000_000, lo=1, hi=10**9)  # nodes expanded per query; then NO_PATH


class GraphPlanner(Stateless, abc.ABC):
    """A road map or cell decomposition, searched by ``params.search``."""

    name = "graph"

    def __init__(self, params: GraphSearchParams) -> None:
        self.params = params

    @abc.abstractmethod
    def graph(self, cw: CompiledWorld, stats: dict[str, Any]) -> Graph:
        """The planner's graph of the free space of ``cw`` (its counters go into ``stats``)."""

    def links(self, cw: CompiledWorld, graph: Graph, point: tuple[float, float]) -> tuple[IntArray, FloatArray]:
        """The nodes ``point`` joins and their distances: by default the nearest it sees."""
        p = self.params
        return link_point(cw, graph.pts, point, p.link_candidates, p.link_radius_m)

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult:
        """A path from ``problem.start`` to ``problem.goal`` through the graph, until ``termination``."""
        t0 = time.perf_counter()
        cw, ends = prepare(problem)
        if ends.failure is not None:
            return ends.fail(t0)
        stats: dict[str, Any] = {}

        def done(path: FloatArray | None, status: PlanStatus) -> PlanResult:
            stats["ms"] = (time.perf_counter() - t0) * 1e3
            return ends.finish(path, status, stats)

        if termination.expired():
            return done(None, PlanStatus.TIMEOUT)
        if cw.segment_free(ends.start, ends.goal):
            stats["direct"] = True
            return done(np.array([ends.start, ends.goal], dtype=np.float64), PlanStatus.SOLVED)
        graph = self.graph(cw, stats)
        stats["graph_nodes"] = graph.n
        if termination.expired():
            return done(None, PlanStatus.TIMEOUT)
        s_nodes, s_d = self.links(cw, graph, ends.start)
        g_nodes, g_d = self.links(cw, graph, ends.goal)
        if not len(s_nodes) or not len(g_nodes):
            stats["unlinked"] = "start" if not len(s_nodes) else "goal"
            return done(None, PlanStatus.NO_PATH)
        full = graph.with_links(ends.start, s_nodes, s_d).with_links(ends.goal, g_nodes, g_d)
        found = search(full, graph.n, graph.n + 1, self.params.search, termination)
        stats["expanded"] = found.expanded
        if found.status is SearchStatus.STOPPED:
            return done(None, PlanStatus.TIMEOUT if termination.expired() else PlanStatus.NO_PATH)
        if found.status is SearchStatus.UNREACHABLE:
            return done(None, PlanStatus.NO_PATH)
        path = np.vstack([[ends.start], full.pts[found.route[1:-1]], [ends.goal]])
        if not cw.path_free(path):  # the construction says it cannot happen: a bug if it does
            stats["graph_path_collides"] = True
            return done(None, PlanStatus.NO_PATH)
        return done(path, PlanStatus.SOLVED)
