"""What the reactive navigators of the lecture notes share (potential fields, the bug family, VFH,
the curvature velocity methods, escape and evade): each turns the robot's state and the world into
the velocity it wants this frame, and this base holds that to the robot's limits.

Field frame, metres, seconds. A reactive method steers toward the goal, the end of the planned
path (the methods are planners of their own; the path's earlier points only set the heading's
profile). Three things are the same for every one of them:

* the **final approach**: within ``handover_m`` of the goal with the straight way there free, the
  trajectory navigator's own profile takes over and stops on the goal (or drives through it) at the
  arrival heading; the reactive methods only say where to go, not how to stop on a point;
* the **brake guard**: the component of the wanted velocity toward each obstacle and wall is held
  to the speed that still stops ``brake_margin_m`` short of it (sideways and away stay free);
* the **limits**: the velocity reachable from the last command within one period in the
  acceleration set A(v), under the speed limit or the arrival's cap; omega is the heading profile's.

Work (the termination's unit): one step of the method per frame.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.acceleration import limit_velocity
from cmdragons.control.motion import ControlParams
from cmdragons.control.trapezoid import heading_command
from cmdragons.messages import RobotState
from cmdragons.navigation import _reactive_kernels as K
from cmdragons.navigation.base import STOP, Arrival, NavStatus, VelocityCommand
from cmdragons.navigation.trajectory import TrajectoryNavigator, TrajectoryParams
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CollisionParams, CollisionWorld, CompiledWorld

__all__ = ["ReactiveNavigator", "ReactiveParams", "toward"]


@dataclass(frozen=True)
class ReactiveParams(Validated):
    """configs/team.yaml ``reactive``: shared by every reactive navigator."""

    handover_m: float = setting(0.3, lo=0.0, hi=5.0)  # this near the goal, the way free: the trajectory's approach
    brake_margin_m: float = setting(0.03, lo=0.0, hi=1.0)  # the speed toward the nearest obstacle stops this short
    goal_tolerance_m: float = setting(0.01, lo=0.0, hi=1.0)  # a goal that moves less than this keeps the method's state


def toward(here: tuple[float, float], goal: tuple[float, float], speed: float) -> tuple[float, float]:
    """The velocity (m/s) from ``here`` toward ``goal`` at ``speed`` ((0, 0) on the goal)."""
    d = math.dist(here, goal)
    if d < 1e-12:
        return 0.0, 0.0
    return (goal[0] - here[0]) / d * speed, (goal[1] - here[1]) / d * speed


class ReactiveNavigator(ABC):
    """The base of the reactive navigators: a subclass implements :meth:`want` (and :meth:`restart`
    for its own state)."""

    name = "reactive"
    # the config sections every reactive navigator reads; each adds its own
    SECTIONS: ClassVar[Mapping[str, type]] = {"reactive": ReactiveParams, "trajectory": TrajectoryParams}

    def __init__(self, reactive: ReactiveParams, control: ControlParams, robot_radius_m: float,
                 collision: CollisionParams | None = None, follow: TrajectoryParams | None = None) -> None:
        self.reactive = reactive
        self.control = control
        self.radius = robot_radius_m
        self.collision = collision or CollisionParams()
        self.follow = TrajectoryNavigator(follow or TrajectoryParams(), control, robot_radius_m)
        self.plan: NDArray[np.float64] = np.zeros((0, 2))
        self.arrival = Arrival()
        self.goal: tuple[float, float] | None = None
        self.status = NavStatus.IDLE
        self.steps = 0  # frames since the goal was set
        self.world: CollisionWorld | None = None  # this frame's world, for a method that needs it uncompiled
        self.approached = False  # the trajectory navigator holds the last stretch, not the plan

    # --- the navigator interface -----------------------------------------------------------------
    def set_plan(self, path: ArrayLike, arrival: Arrival) -> None:
        self.plan = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        self.arrival = arrival
        self.follow.set_plan(self.plan, arrival)
        self.approached = False
        if not len(self.plan):
            return
        goal = (float(self.plan[-1, 0]), float(self.plan[-1, 1]))
        if self.goal is None or math.dist(goal, self.goal) > self.reactive.goal_tolerance_m:
            self.goal = goal
            self.steps = 0
            self.status = NavStatus.MOVING
            self.restart((float(self.plan[0, 0]), float(self.plan[0, 1])), goal)

    def sent(self, vx: float, vy: float) -> None:
        self.follow.sent(vx, vy)

    def reset(self) -> None:
        self.follow.reset()
        self.plan = np.zeros((0, 2))
        self.goal = None
        self.status = NavStatus.IDLE

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        """The method's velocity held to the limits; the trajectory's approach on the last stretch."""
        if termination.reached(0) or self.goal is None:
            return STOP
        self.world = world
        cw = world.compile(self.radius, 0.0, 0.0, self.collision)
        here, goal = (robot.x, robot.y), self.goal
        self.steps += 1
        if self.hands_over() and math.dist(here, goal) <= self.reactive.handover_m and cw.segment_free(here, goal):
            self.status = NavStatus.ARRIVING
            self.follow.set_plan(np.array([here, goal]), self.arrival)
            self.approached = True
            return self.follow.command(robot, world, termination)
        wx, wy = self.want(robot, cw, goal)
        if self.status in (NavStatus.BLOCKED, NavStatus.LOCAL_MINIMUM):
            wx, wy = 0.0, 0.0  # a method that is stuck stops (its status says why)
        # the heading's profile toward the trajectory's target (the rotation of its command: the rest
        # of that command, a 2D trapezoid, would be thrown away); the target's limits and the start
        # state serve the guard below too, each taken once a frame
        target, control = self.follow.target(robot)
        start = self.follow.start_state(robot)
        motion = control.motion
        omega = STOP[2]
        if not termination.reached(0):
            omega = heading_command(start.theta, start.omega, target.theta, motion.max_omega_rad_s,
                                    motion.max_alpha_rad_s2, motion.period_s)
        # a turned velocity changes at the smaller of the two: the guard must hold while turning too
        wx, wy = K.brake_guard(cw.obs, cw.inner, here[0], here[1], wx, wy, self.reactive.brake_margin_m,
                               min(motion.max_accel_m_s2, motion.max_brake_m_s2), motion.period_s)
        top = motion.max_speed_m_s * (1.0 - 1e-9)  # a hair under: the step toward it must not round above
        speed = math.hypot(wx, wy)
        if speed > top:
            wx, wy = wx * top / speed, wy * top / speed
        decel = min(motion.max_accel_m_s2, motion.max_brake_m_s2)
        vx, vy = limit_velocity(start.vx, start.vy, wx, wy, top, motion.max_accel_m_s2, motion.max_brake_m_s2,
                                motion.period_s)
        gx, gy = K.brake_guard(cw.obs, cw.inner, here[0], here[1], vx, vy, self.reactive.brake_margin_m, decel,
                               motion.period_s)
        if (gx, gy) != (vx, vy):  # the step toward the wanted velocity closes too fast: brake along the normals
            bx, by = K.brake_guard(cw.obs, cw.inner, here[0], here[1], start.vx, start.vy,
                                   self.reactive.brake_margin_m, decel, motion.period_s)
            vx, vy = limit_velocity(start.vx, start.vy, bx, by, top, motion.max_accel_m_s2, motion.max_brake_m_s2,
                                    motion.period_s)
        return float(vx), float(vy), omega

    # --- for the methods -------------------------------------------------------------------------
    def restart(self, start: tuple[float, float], goal: tuple[float, float]) -> None:
        """A new goal: forget what the method learnt on the way to the last one (by default,
        a method that keeps nothing between goals, nothing)."""
        return None

    def hands_over(self) -> bool:
        """Whether the trajectory's approach may take the last stretch this frame."""
        return True

    @abstractmethod
    def want(self, robot: RobotState, cw: CompiledWorld, goal: tuple[float, float]) -> tuple[float, float]:
        """The velocity (m/s, field frame) the method wants this frame; it may set :attr:`status`."""

    def cruise(self, here: tuple[float, float], goal: tuple[float, float]) -> float:
        """The speed (m/s) that still stops on the goal from here, under the limit and the cap."""
        m = self.control.motion
        cap = self.arrival.max_speed_m_s
        top = m.max_speed_m_s if cap is None else min(m.max_speed_m_s, cap)
        return min(top, math.sqrt(2.0 * m.max_brake_m_s2 * math.dist(here, goal)))
