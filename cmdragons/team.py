"""One frame of the team's brain: WorldState -> commands.

Strategy decides an intent per robot (roles, passes, game state); each robot's own planner (ERRT
with its waypoint cache, Bruce 2006 §4.3) finds a path among the other robots, the ball when it
must be avoided and the defense areas it may not enter; motion control turns the path into the
command for the next frame (B.4); the Dynamics Safety Search makes the whole team's commands safe
together (ch. 5). Each stage's wall-clock time is kept for summaries.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections import defaultdict
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.control.motion import ControlParams, MotionTarget, follow_path, motion_command
from cmdragons.geometry import Team
from cmdragons.messages import GameState, RobotCommand, RobotState, WorldState
from cmdragons.planning import Planner, PlanProblem, PlanStatus, deadline_in, field_world, make_planner
from cmdragons.safety import Safety, make_safety
from strategy.plays import Strategy
from strategy.simple import SimpleTeamParams
from strategy.skills import Intent

if TYPE_CHECKING:  # the settings compose this module's params: import them only for the types
    from cmdragons.runtime.settings import Settings

__all__ = ["Brain", "BrainParams", "RobotPlan", "TeamParams"]


@dataclass(frozen=True)
class BrainParams(Validated):
    """configs/team.yaml ``brain``."""

    # planning is bounded by the planner's node budget (configs/planner.yaml), so the same seed gives
    # the same match whatever the machine's load; this deadline is only the safety net
    plan_deadline_s: float = setting(0.25, lo=0.0001, hi=1.0)
    ball_clearance_m: float = setting(0.05, lo=0.0, hi=1.0)  # kept from the ball when it is an obstacle
    arrive_tolerance_m: float = setting(0.01, lo=0.0, hi=1.0)  # closer than this to the goal: no planning
    # the motion profile starts from the last command sent while the measured velocity is within this
    # of it: a robot held back by an opponent keeps pressing on instead of starting from rest every frame
    command_slip_m_s: float = setting(0.5, lo=0.0, hi=10.0)


@dataclass(frozen=True)
class TeamParams:
    """configs/team.yaml: our brain, and the built-in simple opponent."""

    brain: BrainParams = BrainParams()
    simple_opponent: SimpleTeamParams = SimpleTeamParams()


@dataclass(frozen=True)
class RobotPlan:
    """What the brain did for one robot this frame (for overlays and logs)."""

    intent: Intent
    path: np.ndarray  # (k, 2) from the robot to its goal
    status: str
    command: RobotCommand  # before safety


class Brain:
    """The team's brain for one team colour."""

    def __init__(self, team: Team, settings: Settings, params: BrainParams | None = None) -> None:
        self.team = team
        self.settings = settings
        self.params = params or settings.team.brain
        self.field = settings.field_geometry()
        self.radius = settings.field.robot.radius_m
        self.strategy = Strategy(team, self.field, settings.strategy)
        self.planners: dict[int, Planner] = {}
        static = field_world(self.field, defense_areas=False)
        stream = 0 if team == "blue" else 1
        self.safety: Safety = make_safety(settings.safety, settings.control, self.radius, static, stream=stream)
        self.times: dict[str, list[float]] = defaultdict(list)
        self.plans: dict[int, RobotPlan] = {}
        self.braking: dict[int, np.ndarray] = {}  # robot id -> the braking path DSS checked, (k, 2)
        self._control_cache: dict[float, ControlParams] = {}
        self._last_seen: dict[int, tuple[float, RobotState]] = {}  # own robots as the world last showed them
        self._sent: dict[int, tuple[float, float]] = {}  # the last safe velocity command of each robot

    def _planner(self, rid: int) -> Planner:
        planner = self.planners.get(rid)
        if planner is None:
            planner = self.planners[rid] = make_planner(self.settings.planner, robot_id=rid)
        return planner

    def _control(self, max_speed: float | None) -> ControlParams:
        base = self.settings.control
        if max_speed is None or max_speed >= base.motion.max_speed_m_s:
            return base
        c = self._control_cache.get(max_speed)
        if c is None:
            motion = dataclasses.replace(base.motion, max_speed_m_s=max(max_speed, 0.01))
            c = self._control_cache[max_speed] = dataclasses.replace(base, motion=motion)
        return c

    def step(self, world: WorldState, game: GameState) -> list[RobotCommand]:
        """Commands for our robots seen in ``world`` (field frame)."""
        t0 = time.perf_counter()
        intents = self.strategy.decide(world, game)
        t1 = time.perf_counter()
        own = {r.id: r for r in world.robots if r.team == self.team}
        commands = [self._navigate(own[rid], intent, world, game) for rid, intent in sorted(intents.items())]
        t2 = time.perf_counter()
        if commands:
            lost = self._lost_robots(world)
            stops = [RobotCommand(self.team, r.id) for r in lost]
            safe = self.safety.make_safe(commands + stops, dataclasses.replace(world, robots=world.robots + lost))
        else:
            safe = []
        self._sent = {c.id: (c.vx, c.vy) for c in safe}
        t3 = time.perf_counter()
        self.times["strategy"].append((t1 - t0) * 1e3)
        self.times["planning_control"].append((t2 - t1) * 1e3)
        self.times["safety"].append((t3 - t2) * 1e3)
        self.times["brain"].append((t3 - t0) * 1e3)
        return safe

    def _lost_robots(self, world: WorldState) -> tuple[RobotState, ...]:
        """Own robots the world no longer shows (the tracker lost them, e.g. off the cameras' view).
        Each is told to stop, and the safety search keeps it as a robot that stops: braking at full
        strength from the state the world last showed, so that team-mates do not drive into a robot
        nobody sees (field frame, m, s)."""
        shown = {r.id for r in world.robots if r.team == self.team}
        for r in world.robots:
            if r.team == self.team:
                self._last_seen[r.id] = (world.t, r)
        brake = self.settings.control.motion.max_brake_m_s2
        lost = []
        for rid, (t_seen, r) in sorted(self._last_seen.items()):
            if rid in shown:
                continue
            speed = math.hypot(r.vx, r.vy)
            tau = min(max(world.t - t_seen, 0.0), speed / brake)
            k = (speed - 0.5 * brake * tau) * tau / speed if speed > 0.0 else 0.0  # distance / speed
            f = (speed - brake * tau) / speed if speed > 0.0 else 0.0
            lost.append(dataclasses.replace(r, x=r.x + r.vx * k, y=r.y + r.vy * k, vx=r.vx * f, vy=r.vy * f,
                                            omega=0.0, visible=False))  # fmt: skip
        return tuple(lost)

    def _navigate(self, robot: RobotState, it: Intent, world: WorldState, game: GameState) -> RobotCommand:
        if it.max_speed_m_s == 0.0:
            cmd = RobotCommand(self.team, robot.id)
            self.plans[robot.id] = RobotPlan(it, np.array([[robot.x, robot.y]]), "halt", cmd)
            return cmd
        start = (robot.x, robot.y)
        goal = (it.x, it.y)
        path = np.array([start, goal])
        status = "direct"
        if math.dist(start, goal) > self.params.arrive_tolerance_m:
            others = [r for r in world.robots if not (r.team == self.team and r.id == robot.id)]
            xy = np.array([[r.x, r.y] for r in others]).reshape(-1, 2)
            vel = np.array([[r.vx, r.vy] for r in others]).reshape(-1, 2)
            ball = None
            if it.avoid_ball and world.ball is not None:
                ball = np.array([[world.ball.x, world.ball.y,
                                  self.settings.field.ball.radius_m + self.params.ball_clearance_m]])  # fmt: skip
            own_sign = self.strategy.own_sign(game)
            # the goalie may enter our own area: keep only the opponent's (at x of sign -own_sign)
            defense: bool | Literal[-1, 1] = (1 if own_sign < 0 else -1) if it.allow_own_defense else True
            cworld = field_world(self.field, xy, vel, defense_areas=defense, extra_circles=ball)
            result = self._planner(robot.id).solve(PlanProblem(start, goal, self.radius, cworld),
                                                   deadline_in(self.params.plan_deadline_s))  # fmt: skip
            status = result.status.name.lower()
            if result.status in (PlanStatus.SOLVED, PlanStatus.APPROXIMATE) and len(result.path) >= 2:
                path = np.asarray(result.path)
        control = self._control(it.max_speed_m_s)
        target = follow_path(start, path, it.theta, control)
        if it.final_speed_m_s > 0.0 and math.dist((target.x, target.y), goal) < 1e-9:
            # drive through the goal point (onto the ball) instead of stopping on it
            d = math.dist(start, goal)
            if d > 1e-6:
                ux, uy = (goal[0] - start[0]) / d, (goal[1] - start[1]) / d
                target = MotionTarget(goal[0] + ux * 0.05, goal[1] + uy * 0.05, ux * it.final_speed_m_s,
                                      uy * it.final_speed_m_s, it.theta)  # fmt: skip
        sent = self._sent.get(robot.id)
        if sent is not None and math.hypot(sent[0] - robot.vx, sent[1] - robot.vy) <= self.params.command_slip_m_s:
            robot = dataclasses.replace(robot, vx=sent[0], vy=sent[1])
        move = motion_command(robot, target, control)
        cmd = RobotCommand(self.team, robot.id, move.vx, move.vy, move.omega, it.kick_speed, it.chip, it.dribbler)
        self.plans[robot.id] = RobotPlan(it, path, status, cmd)
        return cmd
