"""Voronoi road map (seed 001, "Road-Map Path Planning: Voronoi Diagram"; seed 004 §2.4): the
generalised Voronoi diagram of the obstacle boundaries, the roads that keep the robot as far from
the nearest two obstacles as it can be.

Field frame, metres. The boundaries of the configuration-space obstacles and the walls are sampled
every ``sample_step_m`` (:func:`cmdragons.planning.cspace.boundary_points`, each point labelled
with its obstacle); scipy's Voronoi diagram of the points has, among its ridges, the ones between
points of two different obstacles: those approximate the generalised Voronoi diagram (the ridges
between two points of one obstacle lie inside it or along it, and are dropped). A ridge is a road
when both its ends are free and the robot's disc sweeps it free (the exact query). The start and the
goal enter and leave the roads at the nearest road points they see (the "highway entry" and "exit"
of seed 004), and the route between them is the graph search's along the roads.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from cmdragons.config import setting
from cmdragons.planning.cspace import boundary_points
from cmdragons.planning.graphsearch import Graph
from cmdragons.planning.roadmap import GraphPlanner, GraphSearchParams
from cmdragons.planning.world import CompiledWorld

__all__ = ["VoronoiParams", "VoronoiPlanner", "voronoi_roads"]


@dataclass(frozen=True)
class VoronoiParams(GraphSearchParams):
    """configs/planner.yaml ``voronoi``."""

    sample_step_m: float = setting(0.05, lo=0.005, hi=1.0)  # spacing of the boundary points
    quad_segs: int = setting(4, lo=1, hi=64)  # polygon segments a quarter circle of a round obstacle


def voronoi_roads(cw: CompiledWorld, params: VoronoiParams) -> tuple[Graph, dict[str, Any]]:
    """The road graph: the free ridges of the generalised Voronoi diagram, their vertices as nodes
    (only those on a road)."""
    # imported here: every run imports the planners' registry, and scipy.spatial costs it 0.2 s
    from scipy.spatial import Voronoi

    pts, labels = boundary_points(cw, params.sample_step_m, params.quad_segs)
    vor = Voronoi(pts)
    rv = np.asarray(vor.ridge_vertices, dtype=np.int64)
    rp = np.asarray(vor.ridge_points, dtype=np.int64)
    keep = (rv >= 0).all(axis=1) & (labels[rp[:, 0]] != labels[rp[:, 1]])
    rv = rv[keep]
    verts = np.asarray(vor.vertices, dtype=np.float64)
    used = np.unique(rv)
    x0, y0, x1, y1 = cw.inner
    inside = (verts[used, 0] >= x0) & (verts[used, 0] <= x1) & (verts[used, 1] >= y0) & (verts[used, 1] <= y1)
    ok = np.zeros(len(verts), dtype=np.bool_)
    cand = used[inside]
    ok[cand] = cw.segments_free(np.hstack([verts[cand], verts[cand]]))
    rv = rv[ok[rv[:, 0]] & ok[rv[:, 1]]]
    rv = rv[cw.segments_free(np.hstack([verts[rv[:, 0]], verts[rv[:, 1]]]))] if len(rv) else rv
    nodes, inverse = np.unique(rv, return_inverse=True)
    edges = inverse.reshape(-1, 2)
    stats = {"boundary_points": len(pts), "ridges": int(keep.sum()), "roads": len(edges)}
    return Graph.from_edges(verts[nodes], edges), stats


class VoronoiPlanner(GraphPlanner):
    """The Voronoi road map, built from each query's world. Stateless."""

    name = "voronoi"

    def __init__(self, params: VoronoiParams, rng: np.random.Generator | None = None) -> None:
        super().__init__(params)
        self.voronoi = params

    def graph(self, cw: CompiledWorld, stats: dict[str, Any]) -> Graph:
        graph, counts = voronoi_roads(cw, self.voronoi)
        stats.update(counts)
        return graph
