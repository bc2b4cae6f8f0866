"""Potential fields as a local navigator (lecture notes 001, "Potential Field Path Planning"; the
extended potential field of Khatib and Chatila).

Field frame, metres, seconds. The robot is a point under the force -grad E of the potential
E = the goal's parabolic well 1/2 k |x - goal|^2 (conic beyond ``goal_well_m``, so that the pull
stays bounded far away) + each obstacle's and wall's source: a Gaussian beta exp(-gamma/2 r^2) on
the distance r to the obstacle's core, or the inverse-distance (FIRAS) potential 1/2 eta (1/d - 1/d0)^2
on the clearance d of the robot's disc, both from the collision world's distance-and-gradient query.
Gradient descent: the robot heads along -grad E, as fast as ``descent_gain_1_s`` |grad E| asks
(a ball rolling down the hill slows where the field flattens).

**Local minima** (the notes: "local minima proliferate with multiple obstacles", Koditschek 1987):
the robot that has not come ``stall_distance_m`` nearer the goal in ``stall_time_s`` is stuck where
the forces cancel; the status says ``LOCAL_MINIMUM`` and it stops, or with ``escape: nf1`` it
leaves along NF1's wavefront path (the notes' "combine with wavefront propagation"), the goal's well
moving along that path ``escape_lookahead_m`` ahead of the robot (status ``ESCAPING``).

**The extended field** (section ``extended_potential_field``): the rotation potential weighs each
source by the robot's direction of motion toward it (``rotation_floor`` for an obstacle abeam or
behind, 1 straight ahead) and the task potential leaves out every obstacle outside the sector of
``sector_half_angle_rad`` ahead: obstacles the robot moves past no longer push it.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.messages import RobotState
from cmdragons.navigation import _potential_field_kernels as K
from cmdragons.navigation.base import NavStatus
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams
from cmdragons.navigation.robox import along
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.grid.planners import descend_nf1, nf1
from cmdragons.planning.world import CollisionParams, CompiledWorld

__all__ = ["ExtendedFieldParams", "PotentialFieldNavigator", "PotentialFieldParams", "escape_path",
           "potential_config"]


@dataclass(frozen=True)
class PotentialFieldParams(Validated):
    """configs/team.yaml ``potential_field``."""

    goal_gain: float = setting(1.0, lo=0.0, hi=100.0)  # k of the goal's well (E in m^2)
    goal_well_m: float = setting(1.0, lo=0.01, hi=20.0)  # parabolic within this of the goal, conic beyond
    obstacle: Literal["gaussian", "inverse"] = setting("gaussian", choices=("gaussian", "inverse"))
    gaussian_height_m2: float = setting(1.0, lo=0.0, hi=100.0)  # beta
    gaussian_sigma_m: float = setting(0.25, lo=0.01, hi=5.0)  # gamma = 1 / sigma^2
    inverse_gain_m4: float = setting(0.005, lo=0.0, hi=10.0)  # eta
    influence_m: float = setting(0.5, lo=0.01, hi=5.0)  # d0: sources farther than this exert nothing
    min_distance_m: float = setting(0.01, lo=1e-4, hi=1.0)  # the inverse potential's distance, at least
    descent_gain_1_s: float = setting(3.0, lo=0.01, hi=100.0)  # speed (m/s) per metre of |grad E|
    stall_time_s: float = setting(1.0, lo=0.05, hi=30.0)  # no progress for this long: a local minimum ...
    stall_distance_m: float = setting(0.05, lo=0.0, hi=5.0)  # ... progress: this much nearer the goal
    escape: Literal["none", "nf1"] = setting("nf1", choices=("none", "nf1"))  # what to do in a local minimum
    escape_resolution_m: float = setting(0.05, lo=0.005, hi=1.0)  # NF1's cells
    escape_clearance_m: float = setting(0.02, lo=0.0, hi=1.0)  # NF1's free cells keep this clearance
    escape_lookahead_m: float = setting(0.3, lo=0.01, hi=5.0)  # the goal's well this far along the NF1 path


@dataclass(frozen=True)
class ExtendedFieldParams(Validated):
    """configs/team.yaml ``extended_potential_field`` (with ``potential_field`` for the rest)."""

    rotation_floor: float = setting(0.2, lo=0.0, hi=1.0)  # weight of a source abeam or behind the motion
    sector_half_angle_rad: float = setting(1.75, lo=0.0, hi=math.pi)  # the task sector ahead


def potential_config(p: PotentialFieldParams, radius_m: float, extended: ExtendedFieldParams | None = None
                     ) -> K.PotentialConfig:
    """The kernel's numbers from the config sections (``extended`` None: the plain field)."""
    floor, cos_sector = 1.0, -2.0
    if extended is not None:
        floor, cos_sector = extended.rotation_floor, math.cos(extended.sector_half_angle_rad)
    return K.PotentialConfig(p.goal_gain, p.goal_well_m, K.GAUSSIAN if p.obstacle == "gaussian" else K.INVERSE,
                             p.gaussian_height_m2, 1.0 / p.gaussian_sigma_m**2, p.inverse_gain_m4, p.influence_m,
                             p.min_distance_m, radius_m, floor, cos_sector)


def escape_path(cw: CompiledWorld, start: tuple[float, float], goal: tuple[float, float], resolution_m: float,
                clearance_m: float) -> NDArray[np.float64]:
    """NF1's path (k, 2), field frame, from ``start`` to ``goal`` over the cells of ``resolution_m``
    whose centre keeps ``clearance_m`` (8-connected wavefront, steepest descent), the exact start
    and goal at its ends; empty when the goal's cell cannot be reached."""
    grid = cw.clearance_grid(resolution_m, cap_m=clearance_m + resolution_m)
    free = grid.values > clearance_m
    ny, nx = free.shape

    def cell(p: tuple[float, float]) -> tuple[int, int]:
        i = int(np.clip((p[1] - grid.y0) / resolution_m, 0, ny - 1))
        k = int(np.clip((p[0] - grid.x0) / resolution_m, 0, nx - 1))
        return i, k

    s, g = cell(start), cell(goal)
    free[s] = free[g] = True
    dist = nf1(free, g, connectivity=8)
    cells = descend_nf1(dist, s, connectivity=8)
    if not cells:
        return np.zeros((0, 2))
    xs, ys = grid.centres()
    pts = np.array([(xs[k], ys[i]) for i, k in cells], dtype=np.float64)
    return np.vstack([start, pts[1:-1], goal]) if len(pts) > 2 else np.array([start, goal], dtype=np.float64)


class PotentialFieldNavigator(ReactiveNavigator):
    """Gradient descent on the potential field, with local-minimum detection and the NF1 escape."""

    name = "potential_field"

    SECTIONS: ClassVar[Mapping[str, type]] = {**ReactiveNavigator.SECTIONS, "potential_field": PotentialFieldParams,
                                               "extended_potential_field": ExtendedFieldParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> PotentialFieldNavigator:
        """``potential_field`` from its section; ``extended_potential_field`` adds its own section to it.
        Both read the shared ``reactive`` and ``trajectory``."""
        extended = sections["extended_potential_field"] if name == "extended_potential_field" else None
        return cls(sections["potential_field"], sections["reactive"], control, robot_radius_m, collision,
                   sections["trajectory"], extended)

    def __init__(self, params: PotentialFieldParams, reactive: ReactiveParams, control: ControlParams,
                 robot_radius_m: float, collision: CollisionParams | None = None,
                 follow: TrajectoryParams | None = None,
                 extended: ExtendedFieldParams | None = None) -> None:
        super().__init__(reactive, control, robot_radius_m, collision, follow)
        self.params = params
        self.extended = extended
        if extended is not None:
            self.name = "extended_potential_field"
        self.cfg = potential_config(params, robot_radius_m, extended)
        self._window = max(1, round(params.stall_time_s / control.motion.period_s))
        self._progress: deque[float] = deque(maxlen=self._window + 1)
        self.escape: NDArray[np.float64] = np.zeros((0, 2))
        self.last_gradient = (0.0, 0.0)  # grad E at the robot last frame (m)

    def restart(self, start: tuple[float, float], goal: tuple[float, float]) -> None:
        self._progress.clear()
        self.escape = np.zeros((0, 2))

    def want(self, robot: RobotState, cw: CompiledWorld, goal: tuple[float, float]) -> tuple[float, float]:
        here = (robot.x, robot.y)
        if self.status is NavStatus.LOCAL_MINIMUM or self.status is NavStatus.BLOCKED:
            return 0.0, 0.0
        attract = goal
        if len(self.escape):
            attract = self._carrot(here)
        elif self._stuck(here, goal):
            if self.params.escape == "none":
                self.status = NavStatus.LOCAL_MINIMUM
                return 0.0, 0.0
            self.escape = escape_path(cw, here, goal, self.params.escape_resolution_m, self.params.escape_clearance_m)
            if not len(self.escape):
                self.status = NavStatus.BLOCKED
                return 0.0, 0.0
            self.status = NavStatus.ESCAPING
            attract = self._carrot(here)
        speed = math.hypot(robot.vx, robot.vy)
        mx, my = (robot.vx / speed, robot.vy / speed) if speed > 0.05 else (0.0, 0.0)
        if self.extended is not None and speed <= 0.05:  # at rest: the motion it is about to start
            dg = math.dist(here, attract)
            mx, my = ((attract[0] - here[0]) / dg, (attract[1] - here[1]) / dg) if dg > 0.0 else (0.0, 0.0)
        _, ex, ey = K.potential(cw.obs, cw.inner, here[0], here[1], attract[0], attract[1], mx, my, self.cfg)
        self.last_gradient = (ex, ey)
        g = math.hypot(ex, ey)
        if g == 0.0:
            return 0.0, 0.0
        v = min(self.params.descent_gain_1_s * g, self.cruise(here, goal))
        return -ex / g * v, -ey / g * v

    def _stuck(self, here: tuple[float, float], goal: tuple[float, float]) -> bool:
        d = math.dist(here, goal)
        self._progress.append(d)
        if len(self._progress) <= self._window:
            return False
        return min(self._progress) > self._progress[0] - self.params.stall_distance_m

    def _carrot(self, here: tuple[float, float]) -> tuple[float, float]:
        # the point escape_lookahead_m along the NF1 path beyond the path's point nearest the robot
        path = self.escape
        k = int(np.argmin(np.hypot(path[:, 0] - here[0], path[:, 1] - here[1])))
        self.escape = path = path[k:]
        p = along(path, self.params.escape_lookahead_m) if len(path) > 1 else path[-1]
        return float(p[0]), float(p[1])
