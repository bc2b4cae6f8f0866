"""The configuration-space obstacles of a compiled world as polygons (for the road maps and cell
decompositions that need a polygonal free space) and as points along their boundaries (the
generators of the Voronoi road map).

Field frame, metres. A compiled world's obstacles are already grown by the robot's radius
(:mod:`cmdragons.planning.collision`): capsules (a moving robot swept over the query's window, a disc
when it stands) and boxes with a clearance. Each becomes the shapely buffer of its core with the
radius scaled by ``1 / cos(pi / (4 quad_segs))``, so that the polygon's straight edges are tangent to
the true round boundary or outside it: the polygon contains the obstacle, and a point outside every
polygon is free (conservative by under 2 % of the radius at 4 segments a quarter circle).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from numpy.typing import NDArray

from cmdragons.planning.world import CompiledWorld

__all__ = ["boundary_points", "free_space", "obstacle_polygons"]

FloatArray = NDArray[np.float64]


def obstacle_polygons(cw: CompiledWorld, quad_segs: int) -> list[shapely.Polygon]:
    """Each obstacle of ``cw`` as a polygon that contains it (see the module docstring)."""
    scale = 1.0 / math.cos(math.pi / (4 * quad_segs))
    out = []
    for kind, a, b, c, d, r in cw.obs:
        core = (shapely.LineString([(a, b), (c, d)]) if (a, b) != (c, d) else shapely.Point(a, b)) if kind == 0.0 \
            else shapely.box(a, b, c, d)
        out.append(core.buffer(r * scale, quad_segs=quad_segs))
    return out


def free_space(cw: CompiledWorld, quad_segs: int) -> shapely.Polygon | shapely.MultiPolygon:
    """The free space of the robot's centre: the box inside the walls less the union of the
    obstacle polygons (a polygon with holes, or several)."""
    x0, y0, x1, y1 = cw.inner
    room = shapely.box(x0, y0, x1, y1)
    polys = obstacle_polygons(cw, quad_segs)
    free = room.difference(shapely.unary_union(polys)) if polys else room
    return shapely.normalize(free)


def boundary_points(cw: CompiledWorld, step_m: float, quad_segs: int) -> tuple[FloatArray, NDArray[np.int64]]:
    """Points at most ``step_m`` apart along the boundary of every obstacle polygon and along the
    walls (the inner box's four sides), and each point's label: its obstacle's index, or
    ``len(cw.obs) + side`` for a wall. Points inside another obstacle are left out (they bound
    nothing the robot can reach)."""
    pts: list[FloatArray] = []
    labels: list[NDArray[np.int64]] = []
    for j, poly in enumerate(obstacle_polygons(cw, quad_segs)):
        ring = np.asarray(shapely.segmentize(poly.exterior, step_m).coords)[:-1]
        pts.append(ring)
        labels.append(np.full(len(ring), j, dtype=np.int64))
    x0, y0, x1, y1 = cw.inner
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    for side in range(4):
        (ax, ay), (bx, by) = corners[side], corners[side + 1]
        k = max(1, math.ceil(math.hypot(bx - ax, by - ay) / step_m))
        t = np.arange(k) / k
        pts.append(np.column_stack([ax + t * (bx - ax), ay + t * (by - ay)]))
        labels.append(np.full(k, len(cw.obs) + side, dtype=np.int64))
    p = np.vstack(pts)
    lab = np.concatenate(labels)
    clearance, _ = cw.clearance_gradients(p)
    keep = clearance > -step_m  # on its own boundary (or a hair outside it), not deep in another
    return p[keep], lab[keep]
