"""The bug algorithms as local navigators (lecture notes 001, "Obstacle Avoidance: Bug1, Bug2"; 004
§2.5; tangent bug after Kamon, Rivlin and Rimon): a point robot in the configuration space (the
collision world grown by the robot's radius), with only a touch sensor (Bug1, Bug2) or a range
sensor (tangent bug).

Field frame, metres, seconds. The boundary is the level line of the clearance at
``follow_clearance_m``: obstacles that touch or stand closer than twice that are one obstacle to
it (the level line runs round the cluster). **Motion to goal**: straight for the goal (Bug2: along
the m-line, pulled back onto it by ``correction_gain_1_m``), the speed toward the nearest obstacle
held to what still stops on the level line. **Hitting**: the clearance falls to the level with the
goal's direction into the obstacle (the *contact*; Bug2 judges it on the m-line). **Boundary
following**: along the level line (the clearance's gradient turned a quarter to ``side``, pulled back onto the line by
``correction_gain_1_m``), at ``follow_speed_m_s`` under the speed that still rounds the line's
tightest turn (a circle of radius ``follow_clearance_m`` round a convex corner) within the
acceleration. The *hit point* of the circumnavigation is where the robot first moves along the line
the way it follows (a robot that meets the obstacle moving the other way turns round first).
**Leaving**:

* Bug1: each obstacle is circled once (back within ``leave_tolerance_m`` of the hit point), then
  followed on to the point of its boundary nearest the goal and left there;
* Bug2: on the m-line (start to goal, within ``m_line_tolerance_m``) nearer the goal than the
  contact, with the goal's direction free (where the m-line grazes an obstacle inside the level
  line's band, the robot slides along the line instead of being pulled onto the m-line);
* tangent bug: motion to goal heads for the goal when the sensor (``sensor_range_m``, ``rays``) sees
  the straight way free, else for the endpoint O of a boundary discontinuity nearer the goal than the
  robot that minimises the heuristic distance d(x, O) + d(O, goal); when no such endpoint is left or
  the heuristic stops falling (``progress_m``) the robot is at a local minimum and follows the
  boundary. d_followed is the least distance to the goal of the followed obstacle's sensed boundary
  (the rays that hit it without a discontinuity), d_reach that of the free space the sensor sees;
  the robot leaves once d_reach < d_followed and drives for the point that gives d_reach. The
  sensor's rays end where the clearance falls to the band the robot keeps (the level line, or its
  own clearance when inside it, less ``band_margin_m``): a gap the level line closes is closed to
  the sensor, so no endpoint or d_reach point lies beyond a gap narrower than the band (the robot
  would wedge in it between two obstacles).

:func:`bug2_path` is Bug2 as a whole path in one query on an occupancy grid (the robot stepping one
cell to one of its eight neighbours), the way the Robotics Toolbox's ``Bug2`` runs it: the same
method, cell by cell, for comparing the two on the same grids.

Coming back round to the hit point without a way to leave (Bug1 at its nearest point facing the
obstacle, Bug2 and the tangent bug at the hit point): the goal cannot be reached, status
``BLOCKED``.
"""

from __future__ import annotations

import enum
import math
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.messages import RobotState
from cmdragons.navigation import _bug_kernels as K
from cmdragons.navigation import _reactive_kernels as RK
from cmdragons.navigation.base import NavStatus
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams, toward
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.world import CollisionParams, CompiledWorld

__all__ = ["BugNavigator", "BugParams", "GridBug2", "GridBug2Status", "TangentBugParams", "boundary_direction",
           "bug2_path"]

Point = tuple[float, float]
BugVariant = Literal["bug1", "bug2", "tangent_bug"]
BUG_VARIANTS: tuple[str, ...] = typing.get_args(BugVariant)


@dataclass(frozen=True)
class BugParams(Validated):
    """configs/team.yaml ``bug`` (Bug1, Bug2 and the tangent bug)."""

    follow_clearance_m: float = setting(0.08, lo=0.005, hi=1.0)  # the level line followed round an obstacle
    follow_speed_m_s: float = setting(1.0, lo=0.05, hi=10.0)  # along it (at most; the turns cap it)
    correction_gain_1_m: float = setting(10.0, lo=0.0, hi=1000.0)  # pull back onto the line per metre off it
    side: Literal["left", "right"] = setting("left", choices=("left", "right"))  # turn this way on a hit
    m_line_tolerance_m: float = setting(0.03, lo=0.001, hi=1.0)  # Bug2: on the m-line within this
    leave_tolerance_m: float = setting(0.05, lo=0.001, hi=1.0)  # back at a point within this
    min_follow_m: float = setting(0.2, lo=0.0, hi=10.0)  # followed at least this far before leaving or circling
    grid_max_steps: int = setting(200_000, lo=1, hi=100_000_000)  # bug2_path: cell moves at most


@dataclass(frozen=True)
class TangentBugParams(Validated):
    """configs/team.yaml ``tangent_bug`` (with ``bug`` for following)."""

    sensor_range_m: float = setting(1.5, lo=0.05, hi=20.0)  # the range sensor's reach
    rays: int = setting(90, lo=8, hi=3600)  # its directions, evenly over the full turn
    discontinuity_m: float = setting(0.3, lo=0.01, hi=10.0)  # neighbouring rays this different: an endpoint
    progress_m: float = setting(0.01, lo=0.0, hi=1.0)  # the heuristic distance must fall by this to keep going
    # the rays end this far inside the level line followed (or the robot's own clearance, when less):
    # a gap the level line closes is closed to the sensor too
    band_margin_m: float = setting(0.002, lo=0.0, hi=0.5)


class GridBug2Status(enum.Enum):
    """How :func:`bug2_path` ended (a value, never an exception)."""

    REACHED = K.BUG2_REACHED  # the path ends at the goal
    BLOCKED = K.BUG2_BLOCKED  # round the obstacle back to the hit point: the goal cannot be reached
    OUT_OF_STEPS = K.BUG2_OUT_OF_STEPS  # ``max_steps`` moves made without either
    INVALID_START = K.BUG2_INVALID_START  # the start cell is occupied or off the grid
    INVALID_GOAL = K.BUG2_INVALID_GOAL  # the goal cell is occupied or off the grid


@dataclass(frozen=True)
class GridBug2:
    """:func:`bug2_path`'s answer: its status, the cells visited (k, 2) as (column, row), start
    first, and the path's length in cells (a diagonal move sqrt 2)."""

    status: GridBug2Status
    cells: NDArray[np.int64]
    length_cells: float


def bug2_path(occupied: NDArray[np.bool_], start: tuple[int, int], goal: tuple[int, int],
              params: BugParams | None = None) -> GridBug2:
    """Bug2's whole path on the occupancy grid ``occupied`` (row = y) from cell ``start`` to cell
    ``goal`` (each (column, row)), one cell a step (:func:`cmdragons.navigation._bug_kernels.bug2_grid`:
    along the m-line; round an obstacle it meets with it on the right (``params.side`` left) or
    left, until on the m-line nearer the goal than the hit point; blocked when back round at the hit
    point), at most ``params.grid_max_steps`` moves."""
    p = params or BugParams()
    grid = np.ascontiguousarray(occupied, dtype=np.bool_)
    if grid.ndim != 2:
        raise ValueError(f"occupied must be a 2-d grid, not of shape {grid.shape}")
    status, cells = K.bug2_grid(grid, int(start[0]), int(start[1]), int(goal[0]), int(goal[1]),
                                1 if p.side == "left" else -1, p.grid_max_steps)
    steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
    length = float(np.count_nonzero(steps == 1) + math.sqrt(2.0) * np.count_nonzero(steps == 2))
    return GridBug2(GridBug2Status(int(status)), cells, length)


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

    SECTIONS: ClassVar[Mapping[str, type]] = {**ReactiveNavigator.SECTIONS, "bug": BugParams,
                                               "tangent_bug": TangentBugParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> BugNavigator:
        """``bug1``, ``bug2`` or ``tangent_bug`` (the name is the variant) from the section ``bug``; the
        tangent bug adds its own section. All read the shared ``reactive`` and ``trajectory``."""
        if name not in BUG_VARIANTS:
            raise ValueError(f"a bug navigator is one of {', '.join(BUG_VARIANTS)}, not {name!r}")
        tangent = sections["tangent_bug"] if name == "tangent_bug" else None
        return cls(typing.cast(BugVariant, name), sections["bug"], sections["reactive"], control, robot_radius_m,
                   collision, sections["trajectory"], tangent)

    def __init__(self, variant: BugVariant, params: BugParams, reactive: ReactiveParams,
                 control: ControlParams, robot_radius_m: float, collision: CollisionParams | None = None,
                 follow: TrajectoryParams | None = None, tangent: TangentBugParams | None = None) -> None:
        super().__init__(reactive, control, robot_radius_m, collision, follow)
        self.name = variant
        self.variant = variant
        self.params = params
        self.tangent = tangent or TangentBugParams()
        n = self.tangent.rays
        self.angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
        self.cos, self.sin = np.cos(self.angles), np.sin(self.angles)
        self.side = 1.0 if params.side == "left" else -1.0
        m = control.motion
        self.turn_m_s2 = min(m.max_accel_m_s2, m.max_brake_m_s2)  # a velocity turns or slows at least this fast
        # the level line's tightest turn, round a convex corner, is a circle of radius follow_clearance_m
        self.follow_speed = min(params.follow_speed_m_s, math.sqrt(self.turn_m_s2 * params.follow_clearance_m))
        self.start: Point = (0.0, 0.0)
        self._clear_follow()

    def _clear_follow(self) -> None:
        self.contact_d = math.inf  # the goal's distance where the obstacle was met (Bug2's m-line point)
        self.hit: Point | None = None  # where following along the line began (the circumnavigation's start)
        self.followed = 0.0  # m along the boundary since
        self.away = 0.0  # the farthest (m) from the hit point since
        self.nearest: Point | None = None  # Bug1: the boundary point nearest the goal
        self.nearest_d = math.inf  # its distance; tangent bug: d_followed
        self.circled = False  # Bug1: back at the hit point once
        self._last: Point | None = None
        self._heuristic = math.inf  # tangent bug: the heuristic distance of the last frame
        self._overshoot = 0.0  # m the hit point lies off the level line followed
        self.via: Point | None = None  # tangent bug: the d_reach point it left the boundary for

    def restart(self, start: Point, goal: Point) -> None:
        self.start = start
        self._clear_follow()

    def want(self, robot: RobotState, cw: CompiledWorld, goal: Point) -> tuple[float, float]:
        here = (robot.x, robot.y)
        if self.status is NavStatus.BLOCKED:
            return 0.0, 0.0
        c, gx, gy = cw.clearance_gradient(*here)
        if self.status is NavStatus.FOLLOWING:
            ux, uy = self._along(c, gx, gy)
            if self.hit is None:  # met moving the other way: the circumnavigation starts once turned round
                if robot.vx * ux + robot.vy * uy > 0.0:
                    self.hit = self._last = here
                    self._overshoot = abs(c - self.params.follow_clearance_m)
            else:
                assert self._last is not None
                self.followed += math.dist(here, self._last)
                self.away = max(self.away, math.dist(here, self.hit))
                self._last = here
            if self._leave(cw, here, goal, c, gx, gy):
                self.status = NavStatus.MOVING
                via = self.via
                self._clear_follow()
                self.via = via
            else:  # following on (or BLOCKED, on which the base stops)
                return ux * self.follow_speed, uy * self.follow_speed
        if self.variant == "tangent_bug":
            return self._tangent(cw, here, goal, c, gx, gy)
        if self._hits(cw, here, goal, c, gx, gy):
            return self._begin_follow(here, goal, c, gx, gy)
        ux, uy = toward(here, goal, 1.0)
        mx, my = self._heading(here, goal)
        if c > self.params.follow_clearance_m + self.params.leave_tolerance_m or mx * gx + my * gy >= 0.0:
            ux, uy = mx, my  # back onto the m-line, unless that presses into the obstacle alongside
        return self._approach(ux, uy, self.cruise(here, goal), c, gx, gy)

    # --- motion ----------------------------------------------------------------------------------
    def _along(self, c: float, gx: float, gy: float) -> tuple[float, float]:
        p = self.params
        return boundary_direction(c, gx, gy, p.follow_clearance_m, p.correction_gain_1_m, self.side)

    def _heading(self, here: Point, goal: Point) -> tuple[float, float]:
        """Bug1: the goal's direction; Bug2: along the m-line, pulled back onto it."""
        ux, uy = toward(here, goal, 1.0)
        if self.variant != "bug2" or math.dist(self.start, goal) < 1e-9:
            return ux, uy
        tx, ty = toward(self.start, goal, 1.0)
        off = (here[0] - self.start[0]) * -ty + (here[1] - self.start[1]) * tx  # left of the line, m
        k = self.params.correction_gain_1_m * off
        dx, dy = ux + k * ty, uy - k * tx
        n = math.hypot(dx, dy)
        return (dx / n, dy / n) if n > 0.0 else (ux, uy)

    def _hits(self, cw: CompiledWorld, here: Point, goal: Point, c: float, gx: float, gy: float) -> bool:
        """Contact: the clearance down to the level line with the goal's direction into the obstacle.
        Bug2 judges it at the robot's foot on the m-line while the robot is near it (a robot that
        turns onto the m-line from the boundary swings off it by about half the level; the method's
        contacts are the m-line's)."""
        p = self.params
        q = here
        if self.variant == "bug2":
            foot = _foot(here, self.start, goal)
            if math.dist(here, foot) <= p.m_line_tolerance_m + p.follow_clearance_m:
                q = foot
                c, gx, gy = cw.clearance_gradient(*foot)
        ux, uy = toward(q, goal, 1.0)
        return c <= p.follow_clearance_m and ux * gx + uy * gy < 0.0

    def _approach(self, ux: float, uy: float, speed: float, c: float, gx: float, gy: float) -> tuple[float, float]:
        """(ux, uy) at ``speed``, its part toward the nearest obstacle held to what stops on the level line."""
        into = -(ux * gx + uy * gy)
        if into > 0.0:
            room = max(c - self.params.follow_clearance_m, 0.0)
            a = self.turn_m_s2
            speed = min(speed, (math.sqrt(2.0 * a * room) + a * self.control.motion.period_s) / into)
        return ux * speed, uy * speed

    def _begin_follow(self, here: Point, goal: Point, c: float, gx: float, gy: float) -> tuple[float, float]:
        self._clear_follow()
        self.status = NavStatus.FOLLOWING
        self.contact_d = math.dist(here, goal)
        self.nearest, self.nearest_d = here, self.contact_d
        ux, uy = self._along(c, gx, gy)
        return ux * self.follow_speed, uy * self.follow_speed

    def _free_toward(self, here: Point, goal: Point, c: float, gx: float, gy: float) -> bool:
        """The goal's direction does not run into the obstacle the robot stands beside (on its level
        line, within ``leave_tolerance_m``): into it is toward the goal no leave (an enclosed goal)."""
        dx, dy = toward(here, goal, 1.0)
        p = self.params
        return c > p.follow_clearance_m + p.leave_tolerance_m or dx * gx + dy * gy >= 0.0

    # --- leaving ---------------------------------------------------------------------------------
    def _leave(self, cw: CompiledWorld, here: Point, goal: Point, c: float, gx: float, gy: float) -> bool:
        p = self.params
        d = math.dist(here, goal)
        # back at the hit point: round the obstacle (not just turned round at it), the level line
        # passing within the hit's overshoot of it
        tol = p.leave_tolerance_m + self._overshoot
        back = self.hit is not None and self.followed > p.min_follow_m and self.away > 2.0 * tol \
            and math.dist(here, self.hit) < tol
        if self.variant == "bug2":
            if d < self.contact_d - p.leave_tolerance_m \
                    and _to_line(here, self.start, goal) < p.m_line_tolerance_m \
                    and self._free_toward(here, goal, c, gx, gy):
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
                if self._free_toward(here, goal, c, gx, gy):
                    return True
                self.status = NavStatus.BLOCKED  # the closest point of the obstacle faces it: enclosed
            return False
        # tangent bug: leave once the free space seen comes nearer the goal than the followed boundary
        r, inside = self._scan(cw, here, c)
        self.nearest_d = min(self.nearest_d, self._d_followed(here, goal, r, inside, gx, gy))
        reach, point = self._d_reach(cw, here, goal, r, inside)
        if reach < self.nearest_d - p.leave_tolerance_m:
            self.via = point
            return True
        if back:
            self.status = NavStatus.BLOCKED
        return False

    # --- the tangent bug's range sensor ----------------------------------------------------------
    def _scan(self, cw: CompiledWorld, here: Point, c: float) -> tuple[np.ndarray, float]:
        """The ranges of the rays, each to where the clearance falls to the band the robot keeps (the
        level line, or the robot's clearance ``c`` when it is inside it, less ``band_margin_m``), and
        how far that band lies inside the level line (m). Obstacles the level line runs round as one
        are one to the sensor: a ray through a narrower gap than the band's stops at it."""
        level = self.params.follow_clearance_m
        band = max(min(c, level) - self.tangent.band_margin_m, 0.0)
        r = RK.ranges(cw.obs, cw.inner, here[0], here[1], self.angles, self.tangent.sensor_range_m, band, 1e-3)
        return r, level - band

    def _sees(self, cw: CompiledWorld, here: Point, goal: Point, length: float) -> float:
        """How far (m) the straight way toward the goal keeps the level line's clearance, up to ``length``."""
        a = math.atan2(goal[1] - here[1], goal[0] - here[0])
        return RK.march(cw.obs, cw.inner, here[0], here[1], a, 0.0, length, self.params.follow_clearance_m, 1e-3)

    def _d_followed(self, here: Point, goal: Point, r: np.ndarray, inside: float, gx: float, gy: float) -> float:
        """The least distance to the goal of the followed obstacle's sensed boundary: the rays from the
        one toward the nearest obstacle on, each way, while they hit it without a discontinuity
        (their points taken on the level line, ``inside`` short of the ray's end, as :meth:`_d_reach`
        takes them)."""
        t = self.tangent
        n = len(r)
        k0 = int(round((math.atan2(-gy, -gx) + math.pi) / (2.0 * math.pi) * n)) % n
        hit = r < t.sensor_range_m - 1e-6
        if not hit[k0]:
            return math.inf
        s = np.maximum(r - inside, 0.0)
        dist = np.hypot(here[0] + s * self.cos - goal[0], here[1] + s * self.sin - goal[1])
        best = float(dist[k0])
        for step in (1, -1):
            i = k0
            for _ in range(n - 1):
                j = (i + step) % n
                if j == k0 or not hit[j] or abs(r[j] - r[i]) >= t.discontinuity_m:
                    break
                best = min(best, float(dist[j]))
                i = j
        return best

    def _d_reach(self, cw: CompiledWorld, here: Point, goal: Point, r: np.ndarray,
                 inside: float) -> tuple[float, Point]:
        """d_reach and its point: the free point the sensor sees nearest the goal (on each ray, on the
        level line's side of a hit, ``inside`` short of it; the straight way to the goal as far as it
        stays clear)."""
        rng = self.tangent.sensor_range_m
        dg = math.dist(here, goal)
        s = self._sees(cw, here, goal, min(dg, rng))
        best_d, best = dg - s, (here[0] + (goal[0] - here[0]) * s / max(dg, 1e-12),
                                here[1] + (goal[1] - here[1]) * s / max(dg, 1e-12))
        top = np.where(r < rng - 1e-6, np.maximum(r - inside, 0.0), rng)
        along = np.clip((goal[0] - here[0]) * self.cos + (goal[1] - here[1]) * self.sin, 0.0, top)
        xs, ys = here[0] + along * self.cos, here[1] + along * self.sin
        dist = np.hypot(xs - goal[0], ys - goal[1])
        k = int(np.argmin(dist))
        if dist[k] < best_d:
            best_d, best = float(dist[k]), (float(xs[k]), float(ys[k]))
        return best_d, best

    def _tangent(self, cw: CompiledWorld, here: Point, goal: Point, c: float, gx: float,
                 gy: float) -> tuple[float, float]:
        t = self.tangent
        dg = math.dist(here, goal)
        if self.via is not None and (dg <= math.dist(self.via, goal) + self.params.leave_tolerance_m
                                     or math.dist(here, self.via) < self.params.leave_tolerance_m):
            self.via = None  # as near the goal as the point it left the boundary for
        look = min(dg, t.sensor_range_m)
        if self._sees(cw, here, goal, look) >= look - 1e-6:  # the straight way free as far as the sensor sees
            self.via, self._heuristic = None, math.inf
            target = goal
        elif self.via is not None:
            target = self.via
        else:
            # the endpoints of the boundary discontinuities nearer the goal than the robot
            r, _ = self._scan(cw, here, c)
            n = len(r)
            best, best_h = None, math.inf
            for i in range(n):
                j = (i + 1) % n
                if abs(r[i] - r[j]) < t.discontinuity_m:
                    continue
                k = i if r[i] < r[j] else j  # the endpoint on the near obstacle's edge
                e = (here[0] + r[k] * self.cos[k], here[1] + r[k] * self.sin[k])
                de = math.dist(e, goal)
                if de >= dg:
                    continue
                h = math.dist(here, e) + de
                if h < best_h:
                    best, best_h = e, h
            if best is None or best_h > self._heuristic + t.progress_m:
                return self._begin_follow(here, goal, c, gx, gy)  # a local minimum of the heuristic distance
            self._heuristic = min(self._heuristic, best_h)
            target = best
        ux, uy = toward(here, target, 1.0)
        if c <= self.params.follow_clearance_m and ux * gx + uy * gy < 0.0:  # on the line: slide along it
            into = ux * gx + uy * gy
            p = self.params
            pull = p.correction_gain_1_m * (c - p.follow_clearance_m)
            dx, dy = ux - into * gx - pull * gx, uy - into * gy - pull * gy
            nn = math.hypot(dx, dy)
            if nn < 1e-9:
                return self._begin_follow(here, goal, c, gx, gy)
            return dx / nn * self.follow_speed, dy / nn * self.follow_speed
        return self._approach(ux, uy, self.cruise(here, goal), c, gx, gy)


def _foot(p: Point, a: Point, b: Point) -> Point:
    """The point of the segment ab nearest p."""
    ax, ay, bx, by = a[0], a[1], b[0], b[1]
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0 if den == 0.0 else min(1.0, max(0.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / den))
    return ax + t * dx, ay + t * dy


def _to_line(p: Point, a: Point, b: Point) -> float:
    """Distance (m) from p to the segment ab."""
    return math.dist(p, _foot(p, a, b))
