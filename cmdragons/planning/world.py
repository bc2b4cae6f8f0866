"""The collision world of motion planning (Bruce 2006 ch. 3).

Field frame, metres, seconds. A :class:`CollisionWorld` holds what a robot must not touch:

* circles: other robots (radius 0.09 m) and the ball when it must be avoided, each with its velocity
  (m/s), so a query can ask about a time window;
* boxes: axis-aligned rectangles, such as the defense areas and the goal walls;
* the field boundary: the robot's whole disc stays inside it.

Queries are about a robot *disc* of a given radius: :meth:`CollisionWorld.compile` grows every
obstacle by that radius (the robot radius as clearance) and sweeps each moving circle over the time
window ``[t0_s, t1_s]`` into a capsule, so that the rest is about the robot's centre point and its
straight moves (the swept-circle segment query). The compiled world carries its broad phase
(extent masks, an AABB tree or a plain scan, §3.2) and hands the numba kernels one named tuple.

It is the one world query of the team: point and swept-disc checks (planners), the signed
clearance to the nearest obstacle and its gradient (navigators, DSS's static check, potential
fields), and the clearance rasterised to a grid (:class:`ClearanceGrid`, where grid planners such
as NF1 and E* start).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field
from cmdragons.planning import collision as K

__all__ = ["BROAD_PHASES", "ClearanceGrid", "CollisionParams", "CollisionWorld", "CompiledWorld", "field_world"]

BroadPhase = Literal["linear", "masks", "aabb_tree"]
BROAD_PHASES: dict[str, int] = {"linear": K.MODE_LINEAR, "masks": K.MODE_MASKS, "aabb_tree": K.MODE_AABB_TREE}

FloatArray = NDArray[np.float64]
Point = Sequence[float] | FloatArray  # (x, y), metres


@dataclass(frozen=True)
class CollisionParams(Validated):
    """configs/planner.yaml ``collision``: how queries are answered (not what collides)."""

    # broad phase, Bruce 2006 §3.2: extent masks won the 10-40 obstacle measurement (cmdragons bench planning)
    broad_phase: BroadPhase = setting("masks", choices=("linear", "masks", "aabb_tree"))
    mask_bins: int = setting(32, lo=1, hi=1024)  # extent-mask bins per axis over the field
    grid_resolution_m: float = setting(0.05, lo=0.001, hi=1.0)  # cell size of the clearance grid


@dataclass(frozen=True, eq=False)
class ClearanceGrid:
    """The clearance (m, signed, < 0 in collision) of a robot centre at the centres of square cells:
    ``values[i, k]`` at (x0 + (k + 1/2) resolution_m, y0 + (i + 1/2) resolution_m), field frame."""

    x0: float
    y0: float
    resolution_m: float
    values: FloatArray

    def centres(self) -> tuple[FloatArray, FloatArray]:
        """The cell centres' x (nx,) and y (ny,) coordinates."""
        ny, nx = self.values.shape
        xs = self.x0 + (np.arange(nx, dtype=np.float64) + 0.5) * self.resolution_m
        ys = self.y0 + (np.arange(ny, dtype=np.float64) + 0.5) * self.resolution_m
        return np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64)


def _as_rows(a: ArrayLike | None, width: int, name: str) -> FloatArray:
    if a is None:
        return np.zeros((0, width))
    arr = np.asarray(a, dtype=np.float64).reshape(-1, width) if np.size(a) else np.zeros((0, width))
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    return arr


@dataclass(frozen=True, eq=False)
class CollisionWorld:
    """Obstacles in the field frame (metres, m/s).

    ``bounds``: (x0, y0, x1, y1), the walls the robot's disc stays within; ``circles`` (n, 3):
    x, y, radius; ``velocities`` (n, 2): each circle's velocity (zeros when omitted); ``boxes``
    (m, 4): x0, y0, x1, y1 with x0 <= x1, y0 <= y1.
    """

    bounds: tuple[float, float, float, float]
    circles: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    velocities: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    boxes: FloatArray = field(default_factory=lambda: np.zeros((0, 4)))
    _cache: dict[tuple[float, float, float, CollisionParams], CompiledWorld] = field(
        default_factory=dict, init=False, repr=False
    )

    def __post_init__(self) -> None:
        circles = _as_rows(self.circles, 3, "circles")
        vel = _as_rows(self.velocities, 2, "velocities") if np.size(self.velocities) else np.zeros((len(circles), 2))
        boxes = _as_rows(self.boxes, 4, "boxes")
        if vel.shape[0] != circles.shape[0]:
            raise ValueError(f"velocities has {vel.shape[0]} rows for {circles.shape[0]} circles")
        if np.any(circles[:, 2] < 0) or np.any(boxes[:, 2] < boxes[:, 0]) or np.any(boxes[:, 3] < boxes[:, 1]):
            raise ValueError("circle radii must be >= 0 and boxes must have x0 <= x1, y0 <= y1")
        x0, y0, x1, y1 = (float(v) for v in self.bounds)
        if not (x0 < x1 and y0 < y1):
            raise ValueError(f"bounds {self.bounds} must be (x0, y0, x1, y1) with x0 < x1, y0 < y1")
        object.__setattr__(self, "bounds", (x0, y0, x1, y1))
        object.__setattr__(self, "circles", circles)
        object.__setattr__(self, "velocities", vel)
        object.__setattr__(self, "boxes", boxes)

    @property
    def n_obstacles(self) -> int:
        return int(self.circles.shape[0] + self.boxes.shape[0])

    def subset(
        self, circles: NDArray[np.bool_] | None = None, boxes: NDArray[np.bool_] | None = None
    ) -> CollisionWorld:
        """The world keeping only the circles and boxes whose mask entry is True (all when a mask is
        None), in their order: one world per frame, each robot's view leaving itself out. The rows
        are this world's, already checked."""
        keep_c = self.circles if circles is None else self.circles[circles]
        keep_v = self.velocities if circles is None else self.velocities[circles]
        keep_b = self.boxes if boxes is None else self.boxes[boxes]
        return self._checked(keep_c, keep_v, keep_b)

    def with_circles(self, circles: ArrayLike, velocities: ArrayLike) -> CollisionWorld:
        """This world's bounds and boxes with ``circles`` (n, 3: x, y, radius) moving at ``velocities``
        (n, 2) in place of its own circles (a frame's robots in the field's static world)."""
        c = np.asarray(circles, dtype=np.float64).reshape(-1, 3)
        v = np.asarray(velocities, dtype=np.float64).reshape(-1, 2)
        if len(v) != len(c) or not (np.isfinite(c).all() and np.isfinite(v).all()) or np.any(c[:, 2] < 0.0):
            raise ValueError("circles (n, 3) and velocities (n, 2) must be finite, radii >= 0")
        return self._checked(c, v, self.boxes)

    def _checked(self, circles: FloatArray, velocities: FloatArray, boxes: FloatArray) -> CollisionWorld:
        # a world of rows already checked (the constructor's checks cost more than a frame can spare)
        w = object.__new__(CollisionWorld)
        for name, value in (("bounds", self.bounds), ("circles", circles), ("velocities", velocities),
                            ("boxes", boxes), ("_cache", {})):
            object.__setattr__(w, name, value)
        return w

    def static_part(self) -> CollisionWorld:
        """The same bounds and boxes without the circles (what a roadmap may precompute against)."""
        return CollisionWorld(self.bounds, boxes=self.boxes)

    def compile(
        self, radius_m: float, t0_s: float = 0.0, t1_s: float = 0.0, params: CollisionParams | None = None
    ) -> CompiledWorld:
        """The world as seen by a robot of ``radius_m`` over the time window [t0_s, t1_s] (seconds
        from now): circles grown by the radius and swept along their velocity over the window.
        Cached per (radius, window, params): planners of one frame share it."""
        p = params or CollisionParams()
        key = (float(radius_m), float(t0_s), float(t1_s), p)
        hit = self._cache.get(key)
        if hit is None:
            hit = CompiledWorld(self, float(radius_m), float(t0_s), float(t1_s), p)
            self._cache[key] = hit
        return hit


class CompiledWorld:
    """A :class:`CollisionWorld` grown by one robot radius over one time window, with its broad phase
    built; the point and swept-segment queries of all planners go through it."""

    def __init__(
        self, world: CollisionWorld, radius_m: float, t0_s: float, t1_s: float, params: CollisionParams
    ) -> None:
        if not radius_m >= 0.0 or not t1_s >= t0_s:
            raise ValueError("radius_m must be >= 0 and t1_s >= t0_s")
        self.world = world
        self.radius_m = radius_m
        self.window_s = (t0_s, t1_s)
        self.params = params
        bounds = np.array(world.bounds)
        mode = BROAD_PHASES[params.broad_phase]
        self.cw: K.CW = K.build_world(
            world.circles, world.velocities, world.boxes, bounds, radius_m, t0_s, t1_s, mode, params.mask_bins
        )
        if mode == K.MODE_AABB_TREE:
            tbox, tchild, tleaf = K.build_aabb_tree(self.cw.aabb)
            self.cw = self.cw._replace(tbox=tbox, tchild=tchild, tleaf=tleaf)
        self.obs, self.aabb, self.inner = self.cw.obs, self.cw.aabb, self.cw.inner

    # --- queries (field frame, metres) ------------------------------------------------------------
    def point_free(self, x: float, y: float) -> bool:
        """The robot's disc at (x, y) touches no obstacle and lies inside the field boundary."""
        return bool(K.point_free(self.cw, float(x), float(y)))

    def segment_free(self, a: Point, b: Point) -> bool:
        """Swept-circle query: the robot's disc moving straight from a to b touches nothing."""
        return bool(K.segment_free(self.cw, float(a[0]), float(a[1]), float(b[0]), float(b[1])))

    def segments_free(self, segments: ArrayLike) -> NDArray[np.bool_]:
        """:meth:`segment_free` for each row (ax, ay, bx, by)."""
        return np.asarray(K.segments_free(self.cw, np.ascontiguousarray(segments, dtype=np.float64).reshape(-1, 4)))

    def path_free(self, path: ArrayLike) -> bool:
        """Every segment of the polyline (n, 2) passes the swept-circle query."""
        return bool(K.path_free(self.cw, np.ascontiguousarray(path, dtype=np.float64).reshape(-1, 2)))

    def clearance(self, x: float, y: float) -> float:
        """Signed distance (m) from the robot's disc at (x, y) to the nearest obstacle or wall; < 0 in
        collision."""
        return float(K.clearance(self.obs, self.inner, float(x), float(y)))

    def clearance_gradient(self, x: float, y: float) -> tuple[float, float, float]:
        """:meth:`clearance` at (x, y) and its gradient: (clearance m, gx, gy), the gradient the unit
        direction away from the nearest obstacle or wall ((0, 0) on an obstacle's core line)."""
        c, gx, gy = K.clearance_gradient(self.obs, self.inner, float(x), float(y))
        return float(c), float(gx), float(gy)

    def clearance_gradients(self, points: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """:meth:`clearance_gradient` at each row of ``points`` (n, 2): clearances (n,) and gradients
        (n, 2), in one kernel call (the elastic band's query)."""
        pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        c, g = K.clearance_gradients(self.obs, self.inner, pts)
        return np.asarray(c), np.asarray(g)

    def clearance_grid(self, resolution_m: float | None = None, walls: bool = True,
                       cap_m: float = math.inf) -> ClearanceGrid:
        """The clearance rasterised over the field boundary in square cells of ``resolution_m``
        (default the params' ``grid_resolution_m``); cells cover the boundary box, the last row and
        column reaching up to one cell past it. ``walls=False``: the clearance from the obstacles
        alone, the boundary left out (a weighted region's own grid); ``cap_m``: the clearance capped
        there, each obstacle touching only the cells within that of it (much faster)."""
        res = float(resolution_m if resolution_m is not None else self.params.grid_resolution_m)
        if not res > 0.0:
            raise ValueError(f"resolution_m must be > 0, not {res}")
        x0, y0, x1, y1 = self.world.bounds
        nx, ny = max(1, int(np.ceil((x1 - x0) / res - 1e-9))), max(1, int(np.ceil((y1 - y0) / res - 1e-9)))
        inner = self.inner if walls else np.array([-np.inf, -np.inf, np.inf, np.inf])
        if math.isfinite(cap_m):
            values = K.clearance_grid_capped(self.obs, self.aabb, inner, x0, y0, res, nx, ny, float(cap_m))
        else:
            values = K.clearance_grid(self.obs, inner, x0, y0, res, nx, ny)
        return ClearanceGrid(x0, y0, res, np.asarray(values))

    def nearest_free(self, x: float, y: float, step_m: float = 0.02, n_rings: int = 50) -> tuple[float, float] | None:
        """The free robot position nearest to (x, y) (Robust planning, Bruce 2006 §4.6.2), or None
        when none lies within ``step_m * n_rings``."""
        qx, qy, ok = K.nearest_free_point(self.cw, float(x), float(y), step_m, n_rings, 32)
        return (float(qx), float(qy)) if ok else None


def field_world(
    field: Field,
    robots: ArrayLike | None = None,
    velocities: ArrayLike | None = None,
    robot_radius_m: float | None = None,
    *,
    defense_areas: bool | Literal[-1, 1] = True,
    goal_walls: bool = True,
    extra_circles: ArrayLike | None = None,
) -> CollisionWorld:
    """The collision world of a small-size field: the boundary walls, the defense areas (when the
    robot must stay out of them) and the goal walls as boxes, ``robots`` (n, 2) as circles of the
    league's robot radius moving at ``velocities`` (n, 2), plus ``extra_circles`` (x, y, r) such as
    the ball.

    ``defense_areas``: True both, False neither, -1 or +1 only the one at x < 0 or x > 0 (a goalie
    may enter its own defense area but not the opponent's: pass the opponent's side)."""
    r = field.league.robot.radius_m if robot_radius_m is None else robot_radius_m
    pos = _as_rows(robots, 2, "robots")
    circles = np.column_stack([pos, np.full(len(pos), r)]) if len(pos) else np.zeros((0, 3))
    vel = _as_rows(velocities, 2, "velocities") if velocities is not None else np.zeros((len(pos), 2))
    extra = _as_rows(extra_circles, 3, "extra_circles")
    circles = np.vstack([circles, extra])
    vel = np.vstack([vel, np.zeros((len(extra), 2))])
    boxes: list[tuple[float, float, float, float]] = []
    hl, dw, dd = field.half_length, field.dims.defense_width_m / 2.0, field.dims.defense_depth_m
    if isinstance(defense_areas, bool):
        sides: tuple[float, ...] = (1.0, -1.0) if defense_areas else ()
    elif defense_areas in (-1, 1):
        sides = (float(defense_areas),)
    else:
        raise ValueError(f"defense_areas must be True, False, -1 or 1, not {defense_areas!r}")
    for side in sides:
        boxes.append((hl - dd, -dw, hl, dw) if side > 0 else (-hl, -dw, -hl + dd, dw))
    if goal_walls:
        boxes += field.goal_walls(1.0) + field.goal_walls(-1.0)
    bounds = (
        -field.boundary_half_length,
        -field.boundary_half_width,
        field.boundary_half_length,
        field.boundary_half_width,
    )
    return CollisionWorld(bounds, circles, vel, np.array(boxes, dtype=np.float64).reshape(-1, 4))
