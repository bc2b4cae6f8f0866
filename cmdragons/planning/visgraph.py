"""Visibility-graph planner with exact tangents: the shortest path, the benchmark's optimum
(Bruce 2006 §4.3.5 compares ERRT against it).

Field frame, metres. Among discs (robots grown by the planning robot's radius) and grown boxes
(whose boundaries are straight edges joining four corner discs), the shortest path is made of
tangent segments and arcs of those discs. The kernel :func:`_kernels.visibility_graph` builds every
free tangent and arc and runs Dijkstra, so ``cost`` is exact up to rounding. The returned polyline
follows each arc by segments tangent to it (a circumscribed polygon, never cutting into the
obstacle), so it is a hair longer than ``cost``.

Termination: the work is counted in tangent checks (swept-circle queries of candidate tangents);
the bitangents are built a few circles at a time, with the termination checked in between
(TIMEOUT on the deadline, NO_PATH on the spent budget).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.planning import _visgraph_kernels as K
from cmdragons.planning.problem import PlanProblem, PlanResult, PlanStatus, Stateless, path_length, prepare
from cmdragons.planning.termination import Termination

__all__ = ["VisGraphParams", "VisibilityGraphPlanner"]

FloatArray = NDArray[np.float64]


CHUNK_CIRCLES = 4  # circles whose bitangents are built between two termination checks


@dataclass(frozen=True)
class VisGraphParams(Validated):
    """configs/planner.yaml ``visgraph``."""

    arc_check_step_deg: float = setting(2.0, lo=0.01, hi=45.0)  # spacing of the free-arc checks
    arc_polyline_step_deg: float = setting(10.0, lo=0.1, hi=90.0)  # segments of the polyline around an arc
    # tangent checks per query (the work budget of its termination); spent before the graph is whole: NO_PATH
    work_budget: int = setting(1_000_000, lo=1, hi=10**9)


class VisibilityGraphPlanner(Stateless):
    """Exact shortest paths among discs and boxes. Stateless."""

    name = "visgraph"

    def __init__(self, params: VisGraphParams, rng: np.random.Generator | None = None) -> None:
        self.params = params

    def solve(self, problem: PlanProblem, termination: Termination) -> PlanResult:
        """The shortest path from ``problem.start`` to ``problem.goal``, until ``termination`` (work:
        tangent checks)."""
        t0 = time.perf_counter()
        cw, ends = prepare(problem)
        if ends.failure is not None:
            return ends.fail(t0)
        (sx, sy), (gx, gy) = ends.start, ends.goal
        circles = K.vis_circles(cw.obs)
        pts, circ, e_a, e_b, e_w, counts = K.vis_start(cw.cw, sx, sy, gx, gy, circles)
        for lo in range(0, len(circles), CHUNK_CIRCLES):
            if termination.reached(float(counts[2])):
                stopped = PlanStatus.TIMEOUT if termination.expired() else PlanStatus.NO_PATH
                cut: dict[str, object] = {"checks": int(counts[2]), "ms": (time.perf_counter() - t0) * 1e3}
                return ends.finish(None, stopped, cut)
            K.vis_bitangents(cw.cw, circles, pts, circ, e_a, e_b, e_w, counts, lo, lo + CHUNK_CIRCLES)
        cost, pts, circ, ang, route, circles, dist = K.vis_search(
            cw.cw, circles, pts, circ, e_a, e_b, e_w, counts, math.radians(self.params.arc_check_step_deg)
        )
        stats: dict[str, object] = {"graph_nodes": int(len(pts)), "checks": int(counts[2])}
        if not np.isfinite(cost):
            stats["ms"] = (time.perf_counter() - t0) * 1e3
            return ends.finish(None, PlanStatus.NO_PATH, stats)
        path = self._polyline(pts, circ, ang, route, circles, dist)
        result = ends.finish(path, PlanStatus.SOLVED, stats)
        exact = float(cost) + (result.cost - path_length(path))  # the escape prefix is straight
        stats["ms"] = (time.perf_counter() - t0) * 1e3
        stats["polyline_length_m"] = result.cost
        return type(result)(result.status, result.path, exact, {**result.stats, **stats})

    def _polyline(self, pts: FloatArray, circ: NDArray[np.int64], ang: FloatArray, route: NDArray[np.int64],
                  circles: FloatArray, dist: FloatArray) -> FloatArray:
        """The route's nodes, with each arc between two tangent points replaced by segments tangent
        to the arc (vertices at radius r / cos(half step) keep the polyline outside the disc)."""
        out = [pts[route[0]]]
        step = math.radians(self.params.arc_polyline_step_deg)
        for u, v in zip(route[:-1], route[1:], strict=True):
            if circ[u] >= 0 and circ[u] == circ[v]:
                cx, cy, r = circles[circ[u], 0], circles[circ[u], 1], circles[circ[u], 2]
                ccw = (ang[v] - ang[u]) % (2 * math.pi)
                used = (dist[v] - dist[u]) / r if r > 0 else ccw
                # two tangent points on a disc have two arcs between them: the search took the one
                # whose length it added
                span, sign = (
                    (ccw, 1.0) if abs(used - ccw) <= abs(used - (2 * math.pi - ccw)) else (2 * math.pi - ccw, -1.0)
                )
                k = max(1, math.ceil(span / step))
                half = span / k / 2.0
                rr = r / math.cos(half)
                for i in range(k):
                    a = ang[u] + sign * (2 * i + 1) * half
                    out.append(np.array([cx + rr * math.cos(a), cy + rr * math.sin(a)]))
            out.append(pts[v])
        return np.array(out)
