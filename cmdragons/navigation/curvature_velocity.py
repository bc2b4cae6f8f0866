"""The curvature velocity method (CVM, Simmons 1996) and the lane curvature method (LCM, Ko and
Simmons 1998) as local navigators (lecture notes 001, "Obstacle Avoidance: Curvature Velocity
Methods").

Field frame, metres, seconds, radians. The robot travels on arcs: its direction of motion (the
velocity's direction; the goal's at rest) turns at omega = v c for curvature c. Obstacles become
constraints in velocity space: along each arc of the candidates (``curvatures`` between
+-``max_curvature_1_m``) the free length d(c) up to ``horizon_m`` is marched in the collision world
(obstacles grown by the robot's radius plus ``margin_m``), and a speed is admissible on it when the
robot still stops within it, v <= sqrt(2 b d(c)). Of the admissible (v, c) (``speeds`` levels up to
the cruise speed) the method takes the one maximising
f = speed_weight v / vmax + distance_weight d(c) / horizon + heading_weight (1 - |theta_t - theta - v c T_c| / pi),
theta_t the goal's direction, T_c = ``time_constant_s``.

**LCM** (section ``lane_curvature``): first the best *lane*: straight corridors in ``lanes``
directions about the goal's, each at the ``lane_widths_m`` (the robot's centre keeps half the
width of clearance), of the free length L(phi, w); the lane maximising
length_weight L / horizon + width_weight w / max width + goal_weight (1 - |phi - theta_goal| / pi)
gives the direction CVM's heading term then aims at (narrow openings: a lane through them is
long where every arc toward the goal is short).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams
from cmdragons.geometry import wrap_angle
from cmdragons.messages import RobotState
from cmdragons.navigation import _reactive_kernels as K
from cmdragons.navigation.base import NavStatus
from cmdragons.navigation.reactive import ReactiveNavigator, ReactiveParams
from cmdragons.navigation.trajectory import TrajectoryParams
from cmdragons.planning.world import CollisionParams, CompiledWorld

__all__ = ["CurvatureParams", "CurvatureVelocityNavigator", "LaneParams"]


@dataclass(frozen=True)
class CurvatureParams(Validated):
    """configs/team.yaml ``curvature_velocity`` (LCM reads it too)."""

    max_curvature_1_m: float = setting(4.0, lo=0.0, hi=100.0)  # the sharpest arc, 1/m
    curvatures: int = setting(21, lo=1, hi=1001)  # arcs between -max and +max
    speeds: int = setting(6, lo=1, hi=100)  # speed levels up to the cruise speed
    horizon_m: float = setting(2.0, lo=0.05, hi=20.0)  # arcs are marched this far
    margin_m: float = setting(0.03, lo=0.0, hi=1.0)  # kept from every obstacle along an arc
    speed_weight: float = setting(1.0, lo=0.0, hi=100.0)  # alpha1
    distance_weight: float = setting(1.0, lo=0.0, hi=100.0)  # alpha2
    heading_weight: float = setting(2.0, lo=0.0, hi=100.0)  # alpha3
    time_constant_s: float = setting(0.5, lo=0.0, hi=10.0)  # T_c of the heading term


@dataclass(frozen=True)
class LaneParams(Validated):
    """configs/team.yaml ``lane_curvature``."""

    lanes: int = setting(37, lo=1, hi=721)  # lane directions, evenly within +-span of the goal's
    span_rad: float = setting(math.pi, lo=0.0, hi=math.pi)
    lane_widths_m: tuple[float, ...] = setting((0.0, 0.1, 0.2))  # the widths tried (the centre keeps half)
    length_weight: float = setting(1.0, lo=0.0, hi=100.0)
    width_weight: float = setting(0.5, lo=0.0, hi=100.0)
    goal_weight: float = setting(1.0, lo=0.0, hi=100.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.lane_widths_m or any(not (0.0 <= w <= 5.0) for w in self.lane_widths_m):
            raise ValueError(f"lane_widths_m must be one or more widths within [0, 5] m, not {self.lane_widths_m}")


class CurvatureVelocityNavigator(ReactiveNavigator):
    """CVM, or LCM (``lanes`` given), for one robot."""

    SECTIONS: ClassVar[Mapping[str, type]] = {**ReactiveNavigator.SECTIONS, "curvature_velocity": CurvatureParams,
                                               "lane_curvature": LaneParams}

    @classmethod
    def configure(cls, name: str, sections: Mapping[str, Any], control: ControlParams, robot_radius_m: float,
                  collision: CollisionParams) -> CurvatureVelocityNavigator:
        """``curvature_velocity`` from its section; ``lane_curvature`` adds its own section to it. Both
        read the shared ``reactive`` and ``trajectory``."""
        lanes = sections["lane_curvature"] if name == "lane_curvature" else None
        return cls(sections["curvature_velocity"], sections["reactive"], control, robot_radius_m, collision,
                   sections["trajectory"], lanes)

    def __init__(self, params: CurvatureParams, reactive: ReactiveParams, control: ControlParams,
                 robot_radius_m: float, collision: CollisionParams | None = None,
                 follow: TrajectoryParams | None = None, lanes: LaneParams | None = None) -> None:
        super().__init__(reactive, control, robot_radius_m, collision, follow)
        self.params = params
        self.lanes = lanes
        self.name = "lane_curvature" if lanes is not None else "curvature_velocity"
        k = params.max_curvature_1_m
        self.kappas = np.linspace(-k, k, params.curvatures) if params.curvatures > 1 else np.zeros(1)
        self.last_choice: tuple[float, float] = (0.0, 0.0)  # (v m/s, curvature 1/m) of the last command
        self.last_lane: tuple[float, float] | None = None  # LCM: (direction rad, width m) of the last lane

    def _lane(self, cw: CompiledWorld, here: tuple[float, float], goal_dir: float) -> float:
        q, p = self.lanes, self.params
        assert q is not None
        widest = max(q.lane_widths_m) or 1.0
        best, best_f = goal_dir, -math.inf
        offsets = np.linspace(-q.span_rad, q.span_rad, q.lanes) if q.lanes > 1 else np.zeros(1)
        for off in offsets:
            phi = goal_dir + float(off)
            for w in q.lane_widths_m:
                length = K.march(cw.obs, cw.inner, here[0], here[1], phi, 0.0, p.horizon_m, 0.5 * w + p.margin_m, 1e-3)
                f = q.length_weight * length / p.horizon_m + q.width_weight * w / widest \
                    + q.goal_weight * (1.0 - abs(float(off)) / math.pi)
                if f > best_f:
                    best, best_f = phi, f
                    self.last_lane = (phi, w)
        return best

    def want(self, robot: RobotState, cw: CompiledWorld, goal: tuple[float, float]) -> tuple[float, float]:
        p = self.params
        here = (robot.x, robot.y)
        goal_dir = math.atan2(goal[1] - here[1], goal[0] - here[0])
        speed_now = math.hypot(robot.vx, robot.vy)
        theta = math.atan2(robot.vy, robot.vx) if speed_now > 0.05 else goal_dir
        aim = self._lane(cw, here, goal_dir) if self.lanes is not None else goal_dir
        top = self.cruise(here, goal)
        vmax = self.control.motion.max_speed_m_s
        brake = self.control.motion.max_brake_m_s2
        best, best_f = None, -math.inf
        # a robot already nearer than the margin may still move away from it
        keep = min(p.margin_m, max(cw.clearance(*here) - 1e-3, 0.0))
        for kappa in self.kappas:
            d = K.march(cw.obs, cw.inner, here[0], here[1], theta, float(kappa), p.horizon_m, keep, 1e-3)
            v_ok = math.sqrt(2.0 * brake * d)
            for i in range(1, p.speeds + 1):
                v = top * i / p.speeds
                if v > v_ok:
                    break
                head = 1.0 - abs(wrap_angle(aim - theta - v * float(kappa) * p.time_constant_s)) / math.pi
                f = p.speed_weight * v / vmax + p.distance_weight * d / p.horizon_m + p.heading_weight * head
                if f > best_f:
                    best, best_f = (v, float(kappa)), f
        if best is None:
            self.status = NavStatus.BLOCKED
            self.last_choice = (0.0, 0.0)
            return 0.0, 0.0
        self.status = NavStatus.MOVING
        self.last_choice = best
        v, kappa = best
        a = theta + v * kappa * self.control.motion.period_s  # the direction of motion one period on
        return v * math.cos(a), v * math.sin(a)
