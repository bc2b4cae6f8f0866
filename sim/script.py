"""Scripted motion for ``cmdragons sim``: robots drive between random waypoints and the robot
nearest to a resting ball goes behind it and kicks it toward a random point.

Works on the simulator's true state (it is part of the simulator, not the team); every random
choice comes from the generator it is given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.geometry import TEAMS, Field, wrap_angle
from cmdragons.messages import RobotCommand
from sim.snapshot import Snapshot

__all__ = ["ScriptParams", "ScriptedPlay"]


@dataclass(frozen=True)
class ScriptParams(Validated):
    cruise_speed_m_s: float = setting(1.5, lo=0.0, hi=10.0)
    position_gain_1_s: float = setting(2.5, lo=0.0, hi=100.0)  # speed command per metre of error
    heading_gain_1_s: float = setting(6.0, lo=0.0, hi=100.0)
    waypoint_tolerance_m: float = setting(0.1, lo=0.01, hi=2.0)
    kick_speed_range_m_s: tuple[float, float] = (1.5, 5.0)
    kick_timeout_s: float = setting(4.0, lo=0.1, hi=60.0)  # give up a kick attempt after this
    ball_rest_speed_m_s: float = setting(0.3, lo=0.0, hi=10.0)  # slower than this: go and kick it
    field_margin_m: float = setting(0.3, lo=0.0, hi=2.0)  # waypoints stay this far inside the lines


class ScriptedPlay:
    """Per frame: a command for every robot of the snapshot."""

    def __init__(self, field: Field, robot_radius: float, params: ScriptParams, rng: np.random.Generator) -> None:
        self.field, self.params, self.rng = field, params, rng
        self.robot_radius = robot_radius
        self.waypoints: dict[tuple[int, int], tuple[float, float, float]] = {}
        self.kicker: tuple[int, int] | None = None
        self.kick_target: tuple[float, float] = (0.0, 0.0)
        self.kick_speed = 0.0
        self.kick_started = 0.0

    def _random_point(self) -> tuple[float, float]:
        m = self.params.field_margin_m
        return (float(self.rng.uniform(-self.field.half_length + m, self.field.half_length - m)),
                float(self.rng.uniform(-self.field.half_width + m, self.field.half_width - m)))

    def _drive_to(self, key: tuple[int, int], row: np.ndarray, x: float, y: float, theta: float,
                  speed: float) -> RobotCommand:
        dx, dy = x - row[2], y - row[3]
        dist = math.hypot(dx, dy)
        v = min(speed, self.params.position_gain_1_s * dist)
        vx, vy = (dx / dist * v, dy / dist * v) if dist > 1e-6 else (0.0, 0.0)
        omega = self.params.heading_gain_1_s * wrap_angle(theta - row[4])
        return RobotCommand(TEAMS[key[0]], key[1], vx, vy, omega)

    def commands(self, snap: Snapshot) -> list[RobotCommand]:
        p = self.params
        bx, by, _, bvx, bvy, _ = snap.ball
        keys = [(int(r[0]), int(r[1])) for r in snap.robots]
        rows = {k: r for k, r in zip(keys, snap.robots, strict=True)}
        ball_in = self.field.in_field(bx, by, margin=0.15)
        if self.kicker is not None and (snap.t - self.kick_started > p.kick_timeout_s or not ball_in):
            self.kicker = None
        if self.kicker is None and keys and ball_in and math.hypot(bvx, bvy) < p.ball_rest_speed_m_s:
            d = [math.hypot(rows[k][2] - bx, rows[k][3] - by) for k in keys]
            self.kicker = keys[int(np.argmin(d))]
            self.kick_target = self._random_point()
            self.kick_speed = float(self.rng.uniform(*p.kick_speed_range_m_s))
            self.kick_started = snap.t
        out = []
        for k in keys:
            row = rows[k]
            if k == self.kicker:
                out.append(self._kick_command(k, row, bx, by))
                continue
            wp = self.waypoints.get(k)
            if wp is None or math.hypot(wp[0] - row[2], wp[1] - row[3]) < p.waypoint_tolerance_m:
                wp = (*self._random_point(), float(self.rng.uniform(-math.pi, math.pi)))
                self.waypoints[k] = wp
            out.append(self._drive_to(k, row, wp[0], wp[1], wp[2], p.cruise_speed_m_s))
        return out

    def _kick_command(self, k: tuple[int, int], row: np.ndarray, bx: float, by: float) -> RobotCommand:
        aim = math.atan2(self.kick_target[1] - by, self.kick_target[0] - bx)
        behind = self.robot_radius + 0.12
        # first get behind the ball facing the target, then drive through it with the kicker armed
        px, py = bx - behind * math.cos(aim), by - behind * math.sin(aim)
        rel = np.array([row[2] - bx, row[3] - by])
        along = rel @ np.array([math.cos(aim), math.sin(aim)])
        across = abs(rel @ np.array([-math.sin(aim), math.cos(aim)]))
        lined_up = along < -0.05 and across < 0.03 and abs(wrap_angle(aim - row[4])) < 0.1
        if lined_up:
            cmd = self._drive_to(k, row, bx, by, aim, 0.6)
            return RobotCommand(cmd.team, cmd.id, cmd.vx, cmd.vy, cmd.omega, kick_speed=self.kick_speed)
        if along > -0.1 and across < behind:  # on the wrong side: go around the ball
            side = 1.0 if (rel @ np.array([-math.sin(aim), math.cos(aim)])) >= 0 else -1.0
            px += side * behind * -math.sin(aim)
            py += side * behind * math.cos(aim)
        return self._drive_to(k, row, px, py, aim, self.params.cruise_speed_m_s)
