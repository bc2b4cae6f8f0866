"""The dynamic window approach (Bruce 2006 §5.2, after Fox, Burgard and Thrun 1997), for holonomic
robots: the comparison for Dynamics Safety Search in ``cmdragons bench safety``.

Field frame, metres, seconds. Each robot on its own searches the velocities it can reach within
one control period (its window in velocity space); a velocity is admissible when the robot can
still brake to rest before the obstacles as they stand now; among those it takes the one closest to
its command, with a bonus for clearance. Unlike DSS, the other robots are taken as standing still
and nobody coordinates. It serves both interfaces: ``make_safe`` (a filter behind the controller)
and the local navigator's ``command(robot, goal, world) -> (vx, vy, omega)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams, MotionTarget, motion_command
from cmdragons.messages import RobotState, WorldState
from cmdragons.planning.world import CollisionWorld
from cmdragons.safety import _kernels as K
from cmdragons.safety.base import ArraySafety, SafetyResult, StaticObstacles

__all__ = ["DynamicWindow", "DynamicWindowParams"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class DynamicWindowParams(Validated):
    """configs/safety.yaml ``dynamic_window``."""

    margin_m: float = setting(0.03, lo=0.0, hi=1.0)  # kept between robot bodies
    static_margin_m: float = setting(0.01, lo=0.0, hi=1.0)  # kept from walls and static obstacles
    static_step_m: float = setting(0.02, lo=0.001, hi=0.5)  # sample spacing of the static check
    speed_levels: int = setting(3, lo=1, hi=50)  # rings of the velocity window
    directions: int = setting(12, lo=3, hi=360)  # directions per ring
    clearance_weight_1_s: float = setting(0.5, lo=0.0, hi=100.0)  # m/s of score per metre of clearance
    clearance_cap_m: float = setting(0.5, lo=0.0, hi=10.0)  # clearance beyond this earns nothing


class DynamicWindow(ArraySafety):
    """The dynamic window for one team; every robot decides on its own."""

    def __init__(
        self, params: DynamicWindowParams, control: ControlParams, robot_radius_m: float, static: CollisionWorld | None
    ) -> None:
        self.params = params
        self.control = control
        m = control.motion
        self.static = StaticObstacles.from_world(static, robot_radius_m)
        self.limits = np.array([m.max_speed_m_s, m.max_accel_m_s2, m.max_brake_m_s2])
        self.cfg = np.array([
            m.period_s, m.max_accel_m_s2, m.max_brake_m_s2, 2.0 * robot_radius_m + params.margin_m,
            params.static_margin_m, params.static_step_m, params.clearance_weight_1_s, params.clearance_cap_m,
        ])  # fmt: skip
        rings = np.arange(1, params.speed_levels + 1) / params.speed_levels
        angles = np.linspace(-math.pi, math.pi, params.directions, endpoint=False)
        grid = [(0.0, 0.0)] + [(r * math.cos(a), r * math.sin(a)) for r in rings for a in angles]
        self.window = np.array(grid, dtype=np.float64)

    def filter(self, states: ArrayLike, velocities: ArrayLike, opponents: ArrayLike) -> SafetyResult:
        s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 4)
        v = np.ascontiguousarray(velocities, dtype=np.float64).reshape(-1, 2)
        others = np.vstack([s, np.asarray(opponents, dtype=np.float64).reshape(-1, 4)])
        st = self.static
        out, status = K.dynamic_window(s, v, others, st.inner, st.boxes, st.circles, self.limits, self.cfg,
                                       self.window)  # fmt: skip
        return SafetyResult(np.asarray(out), np.asarray(status))

    def command(self, robot: RobotState, goal: MotionTarget, world: WorldState) -> tuple[float, float, float]:
        """The local navigator (DESIGN.md): the trapezoid controller's command toward ``goal``, then the
        window's choice among the velocities admissible in ``world``; field frame, m/s and rad/s."""
        desired = motion_command(robot, goal, self.control)
        safe = self.make_safe([desired], world)[0]
        return safe.vx, safe.vy, safe.omega
