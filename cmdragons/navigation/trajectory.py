"""Trajectory following with trapezoidal profiles (Bruce 2006 appendix B.4): the default navigator.

Field frame, metres, seconds, radians. The target is the first waypoint of the path not yet reached,
arrived at with the speed that still lets the robot stop at the end and turn into the next leg
(:func:`~cmdragons.control.motion.follow_path`); at the end of the path the robot stops, or drives
through the goal when the plan asks for a speed there (onto the ball). The command is the 2D
trapezoid's velocity one control period ahead, held to the robot's limits. The profile starts from
the command last sent while the measured velocity is within ``command_slip_m_s`` of it: a robot
held back by an opponent keeps pressing on instead of starting from rest every frame.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams, MotionTarget, follow_path, motion_command
from cmdragons.messages import RobotState
from cmdragons.navigation.base import STOP, Arrival, VelocityCommand
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CollisionParams, CollisionWorld

__all__ = ["TrajectoryNavigator", "TrajectoryParams", "capped_control"]


@dataclass(frozen=True)
class TrajectoryParams(Validated):
    """configs/team.yaml ``trajectory``."""

    # the profile starts from the last command sent while the measured velocity is within this of it
    command_slip_m_s: float = setting(0.5, lo=0.0, hi=10.0)
    # driving through the goal: the target lies this far beyond it on the line from the robot
    through_beyond_m: float = setting(0.05, lo=0.0, hi=1.0)


def capped_control(control: ControlParams, max_speed_m_s: float | None,
                   max_omega_rad_s: float | None = None) -> ControlParams:
    """``control`` with its speed limit lowered to ``max_speed_m_s`` and its turn rate limit to
    ``max_omega_rad_s`` (None or above: unchanged)."""
    motion = control.motion
    if max_speed_m_s is not None and max_speed_m_s < motion.max_speed_m_s:
        motion = dataclasses.replace(motion, max_speed_m_s=max(max_speed_m_s, 0.01))
    if max_omega_rad_s is not None and max_omega_rad_s < motion.max_omega_rad_s:
        motion = dataclasses.replace(motion, max_omega_rad_s=max(max_omega_rad_s, 0.01))
    return control if motion is control.motion else dataclasses.replace(control, motion=motion)


class TrajectoryNavigator:
    """Path following with trapezoidal profiles for one robot (work: one profile a frame)."""

    name = "trajectory"

    SECTIONS: ClassVar[Mapping[str, type]] = {"trajectory": TrajectoryParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> TrajectoryNavigator:
        """From the section ``trajectory``."""
        return cls(sections["trajectory"], control, robot_radius_m)

    def __init__(self, params: TrajectoryParams, control: ControlParams, robot_radius_m: float) -> None:
        self.params = params
        self.control = control
        self.path: NDArray[np.float64] = np.zeros((0, 2))
        self.arrival = Arrival()
        self._next = 1  # the first waypoint of the path not yet passed
        self._sent: tuple[float, float] | None = None
        self._capped: dict[tuple[float | None, float | None], ControlParams] = {}

    def set_plan(self, path: ArrayLike, arrival: Arrival) -> None:
        self.path = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        self.arrival = arrival
        self._next = 1

    def sent(self, vx: float, vy: float) -> None:
        self._sent = (vx, vy)

    def reset(self) -> None:
        self.path = np.zeros((0, 2))
        self.arrival = Arrival()
        self._next = 1
        self._sent = None

    def target(self, robot: RobotState) -> tuple[MotionTarget, ControlParams]:
        """Where the profile leads this frame (field frame) and the limits it runs under."""
        cap = (self.arrival.max_speed_m_s, self.arrival.max_omega_rad_s)
        control = self._capped.get(cap)
        if control is None:
            control = self._capped[cap] = capped_control(self.control, *cap)
        start = (robot.x, robot.y)
        # a waypoint once passed stays passed while the plan lasts (the brain plans anew each frame)
        reached = control.path.waypoint_reached_m
        while self._next < len(self.path) - 1 and math.dist(start, self.path[self._next]) <= reached:
            self._next += 1
        moving = self.start_state(robot)
        target = follow_path(start, self.path[self._next - 1 :], self.arrival.heading_rad, control,
                             (moving.vx, moving.vy))
        through = self.arrival.through_speed_m_s
        if through > 0.0 and len(self.path) and math.dist((target.x, target.y), self.path[-1]) < 1e-9:
            # drive through the goal point (onto the ball) instead of stopping on it
            gx, gy = float(self.path[-1, 0]), float(self.path[-1, 1])
            d = math.dist(start, (gx, gy))
            if d > 1e-6:
                ux, uy = (gx - start[0]) / d, (gy - start[1]) / d
                beyond = self.params.through_beyond_m
                target = MotionTarget(gx + ux * beyond, gy + uy * beyond, ux * through, uy * through,
                                      self.arrival.heading_rad)
        return target, control

    def start_state(self, robot: RobotState) -> RobotState:
        """The state the profile starts from: the velocity last sent while the robot keeps up with it
        (within ``command_slip_m_s``), else the measured one."""
        sent = self._sent
        if sent is not None and math.hypot(sent[0] - robot.vx, sent[1] - robot.vy) <= self.params.command_slip_m_s:
            return RobotState(robot.team, robot.id, robot.x, robot.y, robot.theta, sent[0], sent[1], robot.omega,
                              robot.visible)
        return robot

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        """The trapezoid's command one control period ahead; the stop when it may not work at all."""
        if termination.reached(0):
            return STOP
        target, control = self.target(robot)
        move = motion_command(self.start_state(robot), target, control)
        return move.vx, move.vy, move.omega
