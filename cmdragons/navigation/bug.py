"""The bug algorithms as local navigators (lecture notes 001, "Obstacle Avoidance: Bug1, Bug2"; 004
§2.5; tangent bug after Kamon, Rivlin and Rimon): a point robot in the configuration space (the
collision world grown by the robot's radius), with only a touch sensor (Bug1, Bug2) or a range
sensor (tangent bug).

Field frame, metres, seconds. **Motion to goal**: straight for the goal. **Hitting** an obstacle:
the robot's clearance falls to ``follow_clearance_m`` with the goal's direction into the obstacle.
**Boundary following**: along the level line of the clearance at ``follow_clearance_m`` (the
clearance's gradient turned a quarter to ``side``, pulled back onto the line by
``correction_gain_1_m``), at ``follow_speed_m_s``. **Leaving**:

* Bug1: each obstacle is circled once (back within ``leave_tolerance_m`` of the hit point), then
  followed on to the point of its boundary nearest the goal and left there;
* Bug2: on the m-line (start to goal, within ``m_line_tolerance_m``) nearer the goal than the hit
  point, with the goal's direction free;
* tangent bug: motion to goal heads for the goal or, when the sensor (``sensor_range_m``, ``rays``)
  sees it blocked, for the endpoint of a boundary discontinuity that minimises the distance via it
  to the goal; when that heuristic distance stops falling, it follows the boundary and leaves once
  some sensed free point is nearer the goal than the nearest boundary point it has followed.

Coming back round to the hit point without a way to leave (Bug1 at its nearest point facing the
obstacle, Bug2 at the hit point): the goal cannot be reached, status ``BLOCKED``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.messages import RobotState
from cmdragons.navigation import _kernels as K
from cmdragons.navigation.base import NavStatus
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams, toward
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.world import CollisionParams, CompiledWorld

__all__ = ["BugNavigator", "BugParams", "TangentBugParams", "boundary_direction"]

Point = tuple[float, float]


@dataclass(frozen=True)
class BugParams(Validated):
    """configs/team.yaml ``bug`` (Bug1, Bug2 and the tangent bug)."""

    follow_clearance_m: float = setting(0.08, lo=0.005, hi=1.0)  # the level line followed round an obstacle
    follow_speed_m_s: float = setting(1.0, lo=0.05, hi=10.0)  # along it
    correction_gain_1_m: float = setting(10.0, lo=0.0, hi=1000.0)  # pull back onto the line per metre off it
    side: Literal["left", "right"] = setting("left", choices=("left", "right"))  # turn this way on a hit
    m_line_tolerance_m: float = setting(0.03, lo=0.001, hi=1.0)  # Bug2: on the m-line within this
    leave_tolerance_m: float = setting(0.05, lo=0.001, hi=1.0)  # back at a point within this
    min_follow_m: float = setting(0.2, lo=0.0, hi=10.0)  # followed at least this far before leaving or circling


@dataclass(frozen=True)
class TangentBugParams(Validated):
    """configs/team.yaml ``tangent_bug`` (with ``bug`` for following)."""

    sensor_range_m: float = setting(1.5, lo=0.05, hi=20.0)  # the range sensor's reach
    rays: int = setting(90, lo=8, hi=3600)  # its directions, evenly over the full turn
    discontinuity_m: float = setting(0.3, lo=0.01, hi=10.0)  # neighbouring rays this different: an endpoint
    progress_m: float = setting(0.01, lo=0.0, hi=1.0)  # the heuristic distance must fall by this to keep going


def boundary_direction(c: float, gx: float, gy: float, level: float, gain: float, side: float) -> tuple[float, float]:
    """The unit direction along the clearance's level line ``level`` at a point of clearance ``c``
    and gradient (gx, gy): the gradient turned by a quarter (``side`` +1: the obstacle on the right,
    turning left), plus ``gain`` (c - level) back toward the line."""
    tx, ty = -gy * side, gx * side
    k = gain * (c - level)
    dx, dy = tx - k * gx, ty - k * gy
    n = math.hypot(dx, dy)
    return (dx / n, dy / n) if n > 0.0 else (0.0, 0.0)


class BugNavigator(ReactiveNavigator):
    """Bug1, Bug2 or the tangent bug (``variant``) for one robot."""

    def __init__(self, variant: Literal["bug1", "bug2", "tangent_bug"], params: BugParams, reactive: ReactiveParams,
                 control: ControlParams, robot_radius_m: float, collision: CollisionParams | None = None,
                 follow: TrajectoryParams | None = None, tangent: TangentBugParams | None = None) -> None:  # fmt: skip
        super().__init__(reactive, control, robot_radius_m, collision, follow)
        self.name = variant
        self.variant = variant
        self.params = params
        self.tangent = tangent or TangentBugParams()
        n = self.tangent.rays
        self.angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
        self.side = 1.0 if params.side == "left" else -1.0
        self.start: Point = (0.0, 0.0)
        self._clear_follow()

    def _clear_follow(self) -> None:
        self.hit: Point | None = None  # where the boundary following began
        self.followed = 0.0  # m along the boundary since
        self.nearest: Point | None = None  # Bug1: the boundary point nearest the goal; tangent bug: its distance below
        self.nearest_d = math.inf
        self.circled = False  # Bug1: back at the hit point once
        self._last: Point | None = None
        self._heuristic = math.inf  # tangent bug: the best distance via an endpoint so far
        self._overshoot = 0.0  # m the hit point lies off the level line followed

    def restart(self, start: Point, goal: Point) -> None:
        self.start = start
        self._clear_follow()

    def want(self, robot: RobotState, cw: CompiledWorld, goal: Point) -> tuple[float, float]:
        here = (robot.x, robot.y)
        p = self.params
        if self.status is NavStatus.BLOCKED:
            return 0.0, 0.0
        c, gx, gy = cw.clearance_gradient(*here)
        if self.status is NavStatus.FOLLOWING:
            if self._last is not None:
                self.followed += math.dist(here, self._last)
            self._last = here
            if self._leave(cw, here, goal, c, gx, gy):
                self.status = NavStatus.MOVING
                self._clear_follow()
            else:  # following on (or BLOCKED, on which the base stops)
                ux, uy = boundary_direction(c, gx, gy, p.follow_clearance_m, p.correction_gain_1_m, self.side)
                return ux * p.follow_speed_m_s, uy * p.follow_speed_m_s
        if self.variant == "tangent_bug":
            return self._tangent(cw, here, goal, c, gx, gy)
        dgx, dgy = toward(here, goal, 1.0)
        if c <= p.follow_clearance_m and dgx * gx + dgy * gy < 0.0:  # hit: the goal lies into the obstacle
            self._begin_follow(here, goal, c)
            ux, uy = boundary_direction(c, gx, gy, p.follow_clearance_m, p.correction_gain_1_m, self.side)
            return ux * p.follow_speed_m_s, uy * p.follow_speed_m_s
        return toward(here, goal, self.cruise(here, goal))

    def _begin_follow(self, here: Point, goal: Point, c: float) -> None:
        self._clear_follow()
        self._overshoot = abs(c - self.params.follow_clearance_m)
        self.status = NavStatus.FOLLOWING
        self.hit = self._last = here
        self.nearest, self.nearest_d = here, math.dist(here, goal)

    def _free_toward(self, cw: CompiledWorld, here: Point, goal: Point, c: float, gx: float, gy: float) -> bool:
        dx, dy = toward(here, goal, 1.0)
        return c > self.params.follow_clearance_m or dx * gx + dy * gy >= 0.0

    def _leave(self, cw: CompiledWorld, here: Point, goal: Point, c: float, gx: float, gy: float) -> bool:
        p = self.params
        assert self.hit is not None
        d = math.dist(here, goal)
        # back at the hit point: the level line passes within the hit's overshoot of it
        back = self.followed > p.min_follow_m and math.dist(here, self.hit) < p.leave_tolerance_m + self._overshoot
        if self.variant == "bug2":
            if self.followed > p.min_follow_m and d < math.dist(self.hit, goal) - p.leave_tolerance_m \
                    and _to_line(here, self.start, goal) < p.m_line_tolerance_m \
                    and self._free_toward(cw, here, goal, c, gx, gy):  # fmt: skip
                return True
            if back:
                self.status = NavStatus.BLOCKED
            return False
        if self.variant == "bug1":
            if not self.circled:
                if d < self.nearest_d:
                    self.nearest, self.nearest_d = here, d
                if back:
                    self.circled = True
                return False
            assert self.nearest is not None
            if math.dist(here, self.nearest) < p.leave_tolerance_m:
                if self._free_toward(cw, here, goal, c, gx, gy):
                    return True
                self.status = NavStatus.BLOCKED
            return False
        # tangent bug: d_followed, the least distance to the goal on the boundary followed; leave once
        # some free point the sensor sees is nearer the goal than it
        self.nearest_d = min(self.nearest_d, d)
        reach = self._reach(cw, here, goal)
        if reach < self.nearest_d - p.leave_tolerance_m:
            self._heuristic = math.inf
            return True
        if back:
            self.status = NavStatus.BLOCKED
        return False

    def _scan(self, cw: CompiledWorld, here: Point) -> np.ndarray:
        return K.ranges(cw.obs, cw.inner, here[0], here[1], self.angles, self.tangent.sensor_range_m, 1e-3)

    def _reach(self, cw: CompiledWorld, here: Point, goal: Point) -> float:
        # d_reach: the least distance to the goal of a point the sensor sees free (the goal itself
        # when its direction is clear up to it)
        dg = math.dist(here, goal)
        a = math.atan2(goal[1] - here[1], goal[0] - here[0])
        if K.march(cw.obs, cw.inner, here[0], here[1], a, 0.0, min(dg, self.tangent.sensor_range_m), 0.0, 1e-3) \
                >= min(dg, self.tangent.sensor_range_m) - 1e-6:  # fmt: skip
            return max(dg - self.tangent.sensor_range_m, 0.0)
        r = self._scan(cw, here)
        xs = here[0] + r * np.cos(self.angles)
        ys = here[1] + r * np.sin(self.angles)
        return float(np.min(np.hypot(xs - goal[0], ys - goal[1])))

    def _tangent(self, cw: CompiledWorld, here: Point, goal: Point, c: float, gx: float,
                 gy: float) -> tuple[float, float]:  # fmt: skip
        t = self.tangent
        dg = math.dist(here, goal)
        a = math.atan2(goal[1] - here[1], goal[0] - here[0])
        look = min(dg, t.sensor_range_m)
        free = K.march(cw.obs, cw.inner, here[0], here[1], a, 0.0, look, 0.0, 1e-3)
        if free >= look - 1e-6 and (c > self.params.follow_clearance_m or self._free_toward(cw, here, goal, c, gx, gy)):
            self._heuristic = math.inf
            return toward(here, goal, self.cruise(here, goal))
        # the goal's direction is blocked within range: the best endpoint of a boundary discontinuity
        r = self._scan(cw, here)
        n = len(r)
        best, best_h = None, math.inf
        for i in range(n):
            j = (i + 1) % n
            if abs(r[i] - r[j]) < t.discontinuity_m:
                continue
            k = i if r[i] < r[j] else j  # the endpoint on the near obstacle's edge
            ex, ey = here[0] + r[k] * math.cos(self.angles[k]), here[1] + r[k] * math.sin(self.angles[k])
            h = math.dist(here, (ex, ey)) + math.dist((ex, ey), goal)
            if h < best_h:
                best, best_h = (ex, ey), h
        if best is None or best_h > self._heuristic - t.progress_m or c <= self.params.follow_clearance_m:
            # the heuristic distance stops falling (or the robot touches the boundary): follow it
            if best is None or best_h > self._heuristic - t.progress_m:
                self._begin_follow(here, goal, c)
                p = self.params
                ux, uy = boundary_direction(c, gx, gy, p.follow_clearance_m, p.correction_gain_1_m, self.side)
                return ux * p.follow_speed_m_s, uy * p.follow_speed_m_s
        self._heuristic = min(self._heuristic, best_h)
        assert best is not None
        return toward(here, best, self.cruise(here, goal))


def _to_line(p: Point, a: Point, b: Point) -> float:
    """Distance (m) from p to the segment ab."""
    ax, ay, bx, by = a[0], a[1], b[0], b[1]
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0 if den == 0.0 else min(1.0, max(0.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / den))
    return math.hypot(p[0] - (ax + t * dx), p[1] - (ay + t * dy))
