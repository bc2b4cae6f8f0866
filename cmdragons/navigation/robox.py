"""The Robox stack as a local navigator (Philippsen 2004 ch. 5: the global path -> the elastic band
-> the dynamic window).

Field frame, metres, seconds. The global planner's path (E* when ``planner.planner`` is ``estar``,
whatever is configured otherwise) starts an elastic band (§3.5,
:class:`~cmdragons.navigation.elastic_band.ElasticBand`); frame after frame the band deforms that
path as the obstacles move (contraction toward the straight line, repulsion from obstacles within
its range), its start following the robot and the bubbles the robot has passed dropped. The band
starts anew from the plan when the goal moves, when the band is no longer a clear path, or when
the plan is shorter than ``reseed_share`` of the band (the planner found a better way round). The
dynamic window (:class:`~cmdragons.navigation.dynamic_window.DynamicWindowNavigator`) executes the
band: the velocity it wants heads along the band (for its point ``lookahead_m`` ahead, as fast as
the rest of the band still allows stopping), and it takes the admissible velocity nearest to it;
the last ``lookahead_m`` are the window's own path following, which stops on the goal (or drives
through it) facing the arrival heading. A band that is not clear this frame hands the plan itself
to the window.

Work (the termination's unit): the dynamic window's candidate velocities; the band's update is a
fixed number of force steps (``elastic_band.iterations``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.geometry import path_length
from cmdragons.messages import RobotState
from cmdragons.navigation.base import STOP, Arrival, VelocityCommand
from cmdragons.navigation.dynamic_window import DynamicWindowNavigator, DynamicWindowParams
from cmdragons.navigation.elastic_band import BandParams, ElasticBand
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CollisionParams, CollisionWorld

__all__ = ["RoboxNavigator", "RoboxParams", "along"]


@dataclass(frozen=True)
class RoboxParams(Validated):
    """configs/team.yaml ``robox``."""

    # a plan shorter than this share of the band's length starts the band anew from it
    reseed_share: float = setting(0.8, lo=0.0, hi=1.0)
    goal_tolerance_m: float = setting(0.01, lo=0.0, hi=1.0)  # a goal that moves less than this keeps the band
    # the wanted velocity heads for the band's point this far ahead along it; within it of the goal
    # the window's own path following takes the last stretch (to stop on the goal, or drive through it)
    lookahead_m: float = setting(0.5, lo=0.01, hi=5.0)
    min_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # the wanted speed before the last stretch, at least


class RoboxNavigator:
    """The elastic band over the global path, executed by the dynamic window, for one robot."""

    name = "robox"

    SECTIONS: ClassVar[Mapping[str, type]] = {"elastic_band": BandParams, "robox": RoboxParams,
                                               "dynamic_window": DynamicWindowParams, "trajectory": TrajectoryParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> RoboxNavigator:
        """From the sections ``robox`` and ``elastic_band`` (its band), ``dynamic_window`` and ``trajectory``
        (the window that executes the band)."""
        return cls(sections["robox"], sections["elastic_band"], sections["dynamic_window"], control, robot_radius_m,
                   collision, sections["trajectory"])

    def __init__(
        self, params: RoboxParams, band: BandParams, window: DynamicWindowParams, control: ControlParams,
        robot_radius_m: float, collision: CollisionParams | None = None, follow: TrajectoryParams | None = None,
    ) -> None:
        self.params = params
        self.band_params = band
        self.radius = robot_radius_m
        self.control = control
        self.collision = collision or CollisionParams()
        self.window = DynamicWindowNavigator(window, control, robot_radius_m, self.collision, follow)
        self.band = ElasticBand(band)
        self.plan: NDArray[np.float64] = np.zeros((0, 2))
        self.arrival = Arrival()
        self._banded = False  # the band holds a path toward the plan's goal
        self.last_band_clear = False  # whether the window followed the band (True) or the plan last frame

    def set_plan(self, path: ArrayLike, arrival: Arrival) -> None:
        self.plan = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        self.arrival = arrival

    def sent(self, vx: float, vy: float) -> None:
        self.window.sent(vx, vy)

    def reset(self) -> None:
        self.window.reset()
        self.band = ElasticBand(self.band_params)
        self.plan = np.zeros((0, 2))
        self._banded = False

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        """The dynamic window's command along the band (the plan where the band is not clear)."""
        if termination.reached(0) or not len(self.plan):
            return STOP
        cw = world.compile(self.radius, 0.0, 0.0, self.collision)
        clearance = cw.clearance_gradients
        here = np.array([robot.x, robot.y])
        goal = self.plan[-1]
        plan = np.vstack([here, self.plan[1:]]) if len(self.plan) > 1 else np.vstack([here, goal])
        band = self.band
        fresh = (not self._banded or math.dist(tuple(band.points[-1]), tuple(goal)) > self.params.goal_tolerance_m
                 or path_length(plan) < self.params.reseed_share * band.length)
        if fresh:
            band.set_path(plan, clearance)
            self._banded = True
        else:
            band.advance(here)
        clear = band.update(clearance, here, goal)
        if not clear and not fresh:  # the old band is blocked: start it anew from this frame's plan
            band.set_path(plan, clearance)
            clear = band.update(clearance, here, goal)
        self.last_band_clear = clear
        path = band.points if clear else plan
        remaining = path_length(path)
        if remaining <= self.params.lookahead_m:  # the last stretch: the window's own path following,
            self.window.set_plan(np.vstack([here, goal]), self.arrival)  # which stops (or drives through) there
            return self.window.command(robot, world, termination)
        self.window.set_plan(path, self.arrival)  # for the heading's profile
        carrot = along(path, self.params.lookahead_m)
        u = (carrot - here) / max(math.dist(tuple(carrot), tuple(here)), 1e-9)
        # a hair under the limit: the window's step toward it must not round above it
        top = self.control.motion.max_speed_m_s * (1.0 - 1e-9)
        if self.arrival.max_speed_m_s is not None:
            top = min(top, self.arrival.max_speed_m_s)
        speed = min(top, math.sqrt(2.0 * self.control.motion.max_brake_m_s2 * (remaining - self.params.lookahead_m)))
        speed = max(speed, self.params.min_speed_m_s)  # the last stretch's profile takes over from this speed
        return self.window.command_toward(robot, world, termination, (float(u[0] * speed), float(u[1] * speed)))


def along(path: NDArray[np.float64], distance_m: float) -> NDArray[np.float64]:
    """The point ``distance_m`` along the polyline ``path`` (k, 2) from its start (its end when shorter)."""
    seg = np.hypot(*np.diff(path, axis=0).T)
    ends = np.cumsum(seg)
    k = int(np.searchsorted(ends, distance_m))
    if k >= len(seg):
        return np.asarray(path[-1], dtype=np.float64)
    t = (distance_m - (ends[k] - seg[k])) / max(seg[k], 1e-12)
    return np.asarray(path[k] + t * (path[k + 1] - path[k]), dtype=np.float64)
