"""The dynamic window approach (Bruce 2006 §5.2, after Fox, Burgard and Thrun 1997) as a local
navigator for a holonomic robot.

Field frame, metres, seconds. The trajectory navigator's command along the path is the velocity the
robot wants; the window holds the velocities it can reach within one control period (rings and
directions of the acceleration set A(v)); a velocity is admissible when the robot, moving at it
and then braking at full strength, stops short of every obstacle as it stands now (robots and the
ball where they are, the walls, the areas it may not enter); among those it takes the one closest
to the wanted one, with a bonus for clearance. It decides alone: DSS then makes the team's commands
safe together. Work (the termination's unit): candidate velocities evaluated, the wanted one first.
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
from cmdragons.messages import RobotState
from cmdragons.navigation import _dynamic_window_kernels as K
from cmdragons.navigation.base import STOP, Arrival, VelocityCommand
from cmdragons.navigation.trajectory import TrajectoryNavigator, TrajectoryParams
from cmdragons.planning.termination import Termination
from cmdragons.planning.world import CollisionParams, CollisionWorld

__all__ = ["DynamicWindowNavigator", "DynamicWindowParams", "window_points"]


@dataclass(frozen=True)
class DynamicWindowParams(Validated):
    """configs/team.yaml ``dynamic_window``."""

    margin_m: float = setting(0.03, lo=0.0, hi=1.0)  # kept from every obstacle (robot bodies, walls, areas)
    step_m: float = setting(0.02, lo=0.001, hi=0.5)  # sample spacing of the admissibility check
    speed_levels: int = setting(3, lo=1, hi=50)  # rings of the velocity window
    directions: int = setting(12, lo=3, hi=360)  # directions per ring
    clearance_weight_1_s: float = setting(0.5, lo=0.0, hi=100.0)  # m/s of score per metre of clearance
    clearance_cap_m: float = setting(0.5, lo=0.0, hi=10.0)  # clearance beyond this earns nothing


def window_points(params: DynamicWindowParams) -> NDArray[np.float64]:
    """The window's points in the unit disc (k, 2): the centre (keep the velocity), then
    ``speed_levels`` rings of ``directions`` points, mapped into A(v) by the kernel."""
    rings = np.arange(1, params.speed_levels + 1) / params.speed_levels
    angles = np.linspace(-math.pi, math.pi, params.directions, endpoint=False)
    grid = [(0.0, 0.0)] + [(r * math.cos(a), r * math.sin(a)) for r in rings for a in angles]
    return np.array(grid, dtype=np.float64)


class DynamicWindowNavigator:
    """The dynamic window for one robot."""

    name = "dynamic_window"

    SECTIONS: ClassVar[Mapping[str, type]] = {"dynamic_window": DynamicWindowParams, "trajectory": TrajectoryParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> DynamicWindowNavigator:
        """From the section ``dynamic_window``; it follows the path as ``trajectory`` says."""
        return cls(sections["dynamic_window"], control, robot_radius_m, collision, sections["trajectory"])

    def __init__(
        self, params: DynamicWindowParams, control: ControlParams, robot_radius_m: float,
        collision: CollisionParams | None = None, follow: TrajectoryParams | None = None,
    ) -> None:
        """``follow``: how the wanted velocity follows the path (the trajectory navigator's section)."""
        self.params = params
        self.control = control
        self.radius = robot_radius_m
        self.collision = collision or CollisionParams()
        self.follow = TrajectoryNavigator(follow or TrajectoryParams(), control, robot_radius_m)
        self.window = window_points(params)
        self.cfg = K.WindowConfig(dt=control.motion.period_s, margin=params.margin_m, step=params.step_m,
                                  clearance_weight=params.clearance_weight_1_s,
                                  clearance_cap=params.clearance_cap_m)
        self.last_evaluated = 0  # candidates the last command evaluated
        self.last_choice = -1  # the candidate it took: 0 the wanted velocity, -1 none (the stop)

    def set_plan(self, path: ArrayLike, arrival: Arrival) -> None:
        self.follow.set_plan(path, arrival)

    def sent(self, vx: float, vy: float) -> None:
        self.follow.sent(vx, vy)

    def reset(self) -> None:
        self.follow.reset()

    def command(self, robot: RobotState, world: CollisionWorld, termination: Termination) -> VelocityCommand:
        """The admissible velocity of the window closest to the path's command, the path's omega."""
        if termination.reached(0):
            return STOP
        vx_want, vy_want, omega = self.follow.command(robot, world, termination)
        return self._choose(robot, world, termination, vx_want, vy_want, omega)

    def command_toward(self, robot: RobotState, world: CollisionWorld, termination: Termination,
                       want: tuple[float, float]) -> VelocityCommand:
        """The admissible velocity of the window closest to ``want`` (m/s, field frame: a velocity the
        caller chose, such as the Robox stack's heading along its band), the path's omega."""
        if termination.reached(0):
            return STOP
        _, _, omega = self.follow.command(robot, world, termination)
        return self._choose(robot, world, termination, want[0], want[1], omega)

    def _choose(self, robot: RobotState, world: CollisionWorld, termination: Termination, vx_want: float,
                vy_want: float, omega: float) -> VelocityCommand:
        start = self.follow.start_state(robot)
        cw = world.compile(self.radius, 0.0, 0.0, self.collision)
        limits = self.follow.target(robot)[1].motion.limits()
        limit = termination.work_left(0, len(self.window) + 1)
        vx, vy, evaluated, chosen = K.dynamic_window(cw.obs, cw.inner, robot.x, robot.y, start.vx, start.vy, vx_want,
                                                     vy_want, self.window, limits, self.cfg, limit)
        self.last_evaluated, self.last_choice = int(evaluated), int(chosen)
        return float(vx), float(vy), omega
