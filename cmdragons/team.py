"""One frame of the team's brain: WorldState -> commands.

Strategy decides an intent per robot (roles, passes, game state). Per robot, its global planner
(``planner.planner`` of configs/planner.yaml: ERRT with its waypoint cache by default, Bruce 2006
§4.3) finds a path among the other robots, the ball when it must be avoided and the defense areas
it may not enter; its local navigator (``team.navigator``: trajectory following by default, B.4)
turns path and world into this frame's command; the Dynamics Safety Search makes the whole team's
commands safe together (ch. 5). The brain knows neither which planner nor which navigator runs.

The ball model and the robots' limits are field.yaml's until the tracker has measured them off
(:meth:`Brain.use_physics`): then the measured values replace the configured ones in every part
that reads them, through the settings the brain holds (``settings``; ``configured`` keeps what the
configuration says).

Each frame turns the world's robots into arrays once and builds one collision world; each robot's
queries see it without the robot itself (and without the ball or its own defense area where its
intent allows). A frame's result is one value (:class:`BrainOutput`): the commands and what viewers
and statistics need, each part's wall-clock time included.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import FrozenMap, Validated, override_derived, sections, setting
from cmdragons.control.motion import predict_braking, relative_kick
from cmdragons.geometry import Team
from cmdragons.messages import (
    GameState,
    KickPurpose,
    PassReport,
    PhysicsFacts,
    RefereeCommand,
    RobotCommand,
    RobotState,
    WorldState,
)
from cmdragons.navigation import NAVIGATORS, Arrival, Navigator, config_sections, make_navigator
from cmdragons.planning import (
    CollisionWorld,
    Planner,
    PlanProblem,
    PlanStatus,
    deadline,
    field_world,
    make_planner,
    make_termination,
)
from cmdragons.safety import Safety, make_safety
from strategy.defend import DefendTeamParams
from strategy.plays import Strategy
from strategy.simple import SimpleTeamParams
from strategy.skills import Intent

if TYPE_CHECKING:
    from cmdragons.control.motion import ControlParams
    from cmdragons.geometry import Field, LeagueParams
    from cmdragons.planning.registry import PlannerParams
    from cmdragons.safety.registry import SafetyParams
    from strategy.plays import StrategyParams

__all__ = ["Brain", "BrainOutput", "BrainParams", "RobotPlan", "RobotPlanStatus", "TeamParams", "TeamSettings"]


# which defense areas a robot must keep out of: both, or only the one at x of the sign given
_DEFENSE_SIDES: tuple[tuple[str, bool | Literal[-1, 1]], ...] = (("both", True), ("+x", 1), ("-x", -1),
                                                                  ("none", False))

# the concerns of a team's settings whose derived fields (the ball model, the robots' limits) the
# measured physics facts replace
_TUNED = ("planner", "control", "safety", "strategy", "team")


@dataclass(frozen=True)
class BrainParams(Validated):
    """configs/team.yaml ``brain``."""

    ball_clearance_m: float = setting(0.05, lo=0.0, hi=1.0)  # kept from the ball when it is an obstacle
    # ... and in a stop, at their restarts and placements (rules: 0.5 m from the ball), this much
    keep_away_clearance_m: float = setting(0.65, lo=0.0, hi=3.0)
    escape_margin_m: float = setting(0.03, lo=0.0, hi=1.0)  # a robot with no path inside that circle leaves it by this
    arrive_tolerance_m: float = setting(0.01, lo=0.0, hi=1.0)  # closer than this to the goal: no planning
    # a navigator's deadline per robot and frame: only the safety net of a stalled machine
    navigate_deadline_ms: float = setting(50.0, lo=0.01, hi=10000.0)


@dataclass(frozen=True)
class TeamParams(Validated):
    """configs/team.yaml: our brain, its navigator, and the built-in opponents. Beside them sit
    the registered navigators' config sections (each navigator declares the ones it reads:
    cmdragons/navigation/registry.py); they are parsed and checked with the file, and the navigator
    reads its own when it is built."""

    navigator: str = setting("trajectory", choices=lambda: tuple(NAVIGATORS))  # which of NAVIGATORS drives each robot
    navigator_sections: FrozenMap[str, Any] = sections(config_sections)  # section name -> its navigator's params
    brain: BrainParams = BrainParams()
    simple_opponent: SimpleTeamParams = SimpleTeamParams()
    defend_opponent: DefendTeamParams = DefendTeamParams()

    def with_section(self, name: str, params: Any) -> TeamParams:
        """These params with navigator section ``name`` replaced by ``params``."""
        return dataclasses.replace(self, navigator_sections=FrozenMap({**self.navigator_sections, name: params}))


class RobotPlanStatus(enum.Enum):
    """How a robot's path of the frame came about: its planner's status (:class:`PlanStatus`, same
    values), or no planning (halted, already at its goal) or the way out of the ball's circle."""

    SOLVED = "solved"
    APPROXIMATE = "approximate"
    NO_PATH = "no_path"
    TIMEOUT = "timeout"
    INVALID_START = "invalid_start"
    INVALID_GOAL = "invalid_goal"
    HALT = "halt"  # told to stand: no path
    DIRECT = "direct"  # at its goal already: straight there, no planning
    ESCAPE = "escape"  # no path from inside the ball's circle: straight off the ball

    @classmethod
    def planned(cls, status: PlanStatus) -> RobotPlanStatus:
        return cls(status.value)


@dataclass(frozen=True)
class RobotPlan:
    """What the brain did for one robot this frame (for overlays and logs)."""

    intent: Intent
    path: np.ndarray  # (k, 2) from the robot to its goal
    status: RobotPlanStatus
    command: RobotCommand  # before safety


@dataclass(frozen=True, eq=False)
class BrainOutput:
    """One frame of the brain: our robots' commands (after safety) and, for viewers, logs and
    statistics, what led to them. Only robots in this frame's world (or, lost, still braking) are
    in it."""

    commands: tuple[RobotCommand, ...]
    plans: Mapping[int, RobotPlan]  # robot id -> its plan of this frame
    braking: Mapping[int, NDArray[np.float64]]  # robot id -> (k, 2) the braking path DSS checked, m
    # the pass evaluation over the candidate grid, points (n, 2) m and values (n,): only on the
    # frames it was redone
    pass_heat: tuple[NDArray[np.float64], NDArray[np.float64]] | None
    last_actions: Mapping[int, KickPurpose]  # robot id -> what its armed kick is for ("shot", "pass", "clear")
    times_ms: Mapping[str, float]  # each part's wall-clock time this frame (strategy, planning_control, safety, brain)
    passing: PassReport | None = None  # the pass planned or under way


@dataclass(frozen=True, eq=False)
class Frame:
    """One frame's robots as arrays (in the world's order) and its collision world: every robot as a
    circle moving at its velocity, then the ball (when shown), the defense areas and the goal walls."""

    robots: tuple[RobotState, ...]
    xy: NDArray[np.float64]  # (n, 2) m
    vel: NDArray[np.float64]  # (n, 2) m/s
    own: NDArray[np.bool_]  # (n,) our robots
    world: CollisionWorld
    has_ball: bool


class TeamSettings(Protocol):
    """What a team's brain is built from: the league (field, robots, ball) and the team's own
    concerns (the run's settings have them, as has a team's own config in a match)."""

    @property
    def field(self) -> LeagueParams: ...

    @property
    def planner(self) -> PlannerParams: ...

    @property
    def control(self) -> ControlParams: ...

    @property
    def safety(self) -> SafetyParams: ...

    @property
    def strategy(self) -> StrategyParams: ...

    @property
    def team(self) -> TeamParams: ...

    def field_geometry(self) -> Field: ...


class Brain:
    """The team's brain for one team colour."""

    def __init__(self, team: Team, settings: TeamSettings, params: TeamParams | None = None) -> None:
        self.team = team
        self.configured = settings  # what the configuration says
        self.settings = settings  # ... with the physics facts in use (:meth:`use_physics`)
        self._physics: dict[str, float] = {}
        self.params = params or settings.team
        self.field = settings.field_geometry()
        self.radius = settings.field.robot.radius_m
        self.strategy = Strategy(team, self.field, settings.strategy)
        self.planners: dict[int, Planner] = {}
        self.navigators: dict[int, Navigator] = {}
        self.safety: Safety = self._safety()
        self.times: dict[str, float] = {}  # each part's ms, the frame in progress
        self.plans: dict[int, RobotPlan] = {}  # robot id -> its plan, the frame in progress
        self.braking: dict[int, np.ndarray] = {}  # robot id -> (k, 2) the braking path DSS checked last frame
        self._last_seen: dict[int, tuple[float, RobotState]] = {}  # own robots as the world last showed them
        # which boxes of the frame's world (both defense areas, then the goal walls) each intent keeps:
        # both areas, or only the one at x of the sign given (a goalie may enter its own)
        self._field = field_world(self.field)  # the boundary, both defense areas, the goal walls
        every = self._field.boxes
        self._boxes: dict[str, NDArray[np.bool_]] = {
            key: np.array([any(np.array_equal(row, b) for b in field_world(self.field, defense_areas=side).boxes)
                           for row in every])
            for key, side in _DEFENSE_SIDES
        }

    def _safety(self) -> Safety:
        static = field_world(self.field, defense_areas=False)
        stream = 0 if self.team == "blue" else 1
        return make_safety(self.settings.safety, self.settings.control, self.radius, static, stream=stream)

    def use_physics(self, facts: PhysicsFacts) -> None:
        """The physics facts our tracker measured: those in use (confident and off the configuration)
        replace field.yaml's ball model and robot limits wherever the brain reads them (pass speeds,
        kicks and intercepts, the navigators' profiles, the safety search); the others stay as
        configured. Strategy keeps its state; navigators and the safety search start afresh."""
        values = facts.in_use()
        if values == self._physics:
            return
        self._physics = values
        base: Any = self.configured
        self.settings = dataclasses.replace(base, **{name: override_derived(getattr(base, name), values)
                                                     for name in _TUNED})
        self.strategy.retune(self.settings.strategy)
        self.safety = self._safety()
        self.navigators.clear()

    def _planner(self, rid: int) -> Planner:
        planner = self.planners.get(rid)
        if planner is None:
            planner = self.planners[rid] = make_planner(self.settings.planner, robot_id=rid)
        return planner

    def _navigator(self, rid: int) -> Navigator:
        nav = self.navigators.get(rid)
        if nav is None:
            nav = self.navigators[rid] = make_navigator(self.params.navigator, self.params.navigator_sections,
                                                        self.settings.control, self.radius,
                                                        self.settings.planner.collision)
        return nav

    def step(self, world: WorldState, game: GameState) -> BrainOutput:
        """This frame's commands for our robots seen in ``world`` (field frame) and what led to them."""
        t0 = time.perf_counter()
        self.times = {}
        intents = self.strategy.decide(world, game)
        t1 = time.perf_counter()
        self.times["strategy"] = (t1 - t0) * 1e3
        safe = self.drive(world, intents, game)
        self.times["brain"] = (time.perf_counter() - t0) * 1e3
        ours = {r.id for r in world.robots if r.team == self.team}
        # what a kick is for, of the robots whose kicker is armed (a robot's kick as another role's is not)
        actions = {rid: a for rid, a in self.strategy.last_action.items()
                   if rid in ours and rid in intents and intents[rid].kick_speed > 0.0}
        return BrainOutput(tuple(safe), dict(sorted(self.plans.items())), dict(self.braking),
                           self.strategy.pass_heat if self.strategy.pass_heat_redone else None, actions,
                           dict(self.times), self.strategy.pass_report)

    def drive(self, world: WorldState, intents: Mapping[int, Intent], game: GameState) -> list[RobotCommand]:
        """Everything after strategy: each robot's planner and navigator toward its intent, then team
        safety (the loop ``cmdragons bench safety`` measures). Robots of ``intents`` must be ours and
        in ``world``."""
        t1 = time.perf_counter()
        self.plans = {}
        frame = self._frame(world, game)
        index = {r.id: i for i, r in enumerate(world.robots) if r.team == self.team}
        commands = [self._navigate(frame, index[rid], intent, game) for rid, intent in sorted(intents.items())]
        t2 = time.perf_counter()
        safe = self._make_safe(frame, commands, world) if commands else []
        pose = {r.id: (r.theta, (r.vx, r.vy)) for r in world.robots if r.team == self.team}
        gain = self.settings.control.motion.kick_gain
        robot = self.settings.field.robot
        safe = [relative_kick(c, *pose.get(c.id, (0.0, (0.0, 0.0))), robot, gain) for c in safe]
        sent = {c.id for c in safe}
        for c in safe:
            nav = self.navigators.get(c.id)
            if nav is not None:
                nav.sent(c.vx, c.vy)
        for rid, nav in self.navigators.items():
            if rid not in sent:
                nav.reset()  # nothing sent this frame: its next profile starts from what it measures
        t3 = time.perf_counter()
        self.times["planning_control"] = (t2 - t1) * 1e3
        self.times["safety"] = (t3 - t2) * 1e3
        return safe

    def _ball_clearance(self, game: GameState) -> float:
        """How far paths keep from the ball: the rules' distance where they ask for one."""
        theirs = game.command.kick_restart or game.command in (RefereeCommand.BALL_PLACEMENT, RefereeCommand.PENALTY)
        keep = game.command == RefereeCommand.STOP or (theirs and game.for_team != self.team)
        b = self.params.brain
        return b.keep_away_clearance_m if keep else b.ball_clearance_m

    def _frame(self, world: WorldState, game: GameState) -> Frame:
        robots = world.robots
        xy = np.array([(r.x, r.y) for r in robots], dtype=np.float64).reshape(-1, 2)
        vel = np.array([(r.vx, r.vy) for r in robots], dtype=np.float64).reshape(-1, 2)
        own = np.array([r.team == self.team for r in robots], dtype=np.bool_)
        ball = None
        if world.ball is not None:
            ball = np.array([[world.ball.x, world.ball.y,
                              self.settings.field.ball.radius_m + self._ball_clearance(game)]])
        circles = np.column_stack([xy, np.full(len(xy), self.radius)])
        if ball is not None:
            circles, vel_all = np.vstack([circles, ball]), np.vstack([vel, np.zeros((1, 2))])
        else:
            vel_all = vel
        return Frame(robots, xy, vel, own, self._field.with_circles(circles, vel_all), ball is not None)

    def _robot_world(self, frame: Frame, i: int, it: Intent, game: GameState) -> CollisionWorld:
        """The frame's world as robot ``i`` must avoid it: without itself, without the ball unless its
        intent avoids it, without our own defense area (or both) when it may enter it."""
        circles = np.ones(len(frame.world.circles), dtype=np.bool_)
        circles[i] = False
        if frame.has_ball and not it.avoid_ball:
            circles[-1] = False
        # the goalie may enter our own area: keep only the opponent's (at x of sign -own_sign)
        key = "both"
        if it.allow_any_defense:
            key = "none"
        elif it.allow_own_defense:
            key = "+x" if self.strategy.own_sign(game) < 0 else "-x"
        return frame.world.subset(circles, self._boxes[key])

    def _lost_robots(self, world: WorldState) -> tuple[RobotState, ...]:
        """Own robots the world no longer shows (the tracker lost them, e.g. off the cameras' view).
        Each is told to stop, and the safety search keeps it as a robot that stops: braking at full
        strength from the state the world last showed, so that team-mates do not drive into a robot
        nobody sees (field frame, m, s)."""
        shown = {r.id for r in world.robots if r.team == self.team}
        for r in world.robots:
            if r.team == self.team:
                self._last_seen[r.id] = (world.t, r)
        motion = self.settings.control.motion
        lost = []
        for rid, (t_seen, r) in sorted(self._last_seen.items()):
            if rid in shown:
                continue
            x, y, vx, vy = predict_braking(r.x, r.y, r.vx, r.vy, world.t - t_seen, motion)
            lost.append(dataclasses.replace(r, x=x, y=y, vx=vx, vy=vy, omega=0.0, visible=False))
        return tuple(lost)

    def _make_safe(self, frame: Frame, commands: list[RobotCommand], world: WorldState) -> list[RobotCommand]:
        """The commands made safe together (DSS), with the lost robots stopping among them; the
        braking paths it checked are kept in :attr:`braking`."""
        lost = self._lost_robots(world)
        stops = [RobotCommand(self.team, r.id) for r in lost]
        ids = [r.id for r in frame.robots if r.team == self.team] + [r.id for r in lost]
        states = np.vstack([np.hstack([frame.xy[frame.own], frame.vel[frame.own]]),
                            np.array([(r.x, r.y, r.vx, r.vy) for r in lost]).reshape(-1, 4)])
        opponents = np.hstack([frame.xy[~frame.own], frame.vel[~frame.own]])
        by_id = {c.id: c for c in commands + stops}
        asked = np.array([(by_id[i].vx, by_id[i].vy) if i in by_id else (0.0, 0.0) for i in ids]).reshape(-1, 2)
        result = self.safety.filter(states, asked, opponents)
        safe_v = {rid: result.velocities[k] for k, rid in enumerate(ids) if rid in by_id}
        self.braking = {rid: result.braking[k] for k, rid in enumerate(ids)}
        out = []
        for c in commands + stops:
            v = safe_v.get(c.id)
            out.append(c if v is None else RobotCommand(c.team, c.id, float(v[0]), float(v[1]), c.omega, c.kick_speed,
                                                        c.chip, c.dribbler))
        return out

    def _ball_escape(self, frame: Frame, start: tuple[float, float], it: Intent) -> tuple[float, float] | None:
        """Where a robot that found no path, standing inside the circle its paths keep round the ball,
        gets out of it the short way (straight off the ball); None when it is not inside. (Without a
        path it drove straight at its goal: from beside the ball, across it.)"""
        if not (frame.has_ball and it.avoid_ball):
            return None
        bx, by, br = frame.world.circles[-1]
        need = br + self.radius + self.params.brain.escape_margin_m
        d = math.hypot(start[0] - bx, start[1] - by)
        if d >= need:
            return None
        ux, uy = ((start[0] - bx) / d, (start[1] - by) / d) if d > 1e-6 else (1.0, 0.0)
        return float(bx + ux * need), float(by + uy * need)

    def _navigate(self, frame: Frame, i: int, it: Intent, game: GameState) -> RobotCommand:
        robot = frame.robots[i]
        if it.max_speed_m_s == 0.0:
            cmd = RobotCommand(self.team, robot.id)
            self.plans[robot.id] = RobotPlan(it, np.array([[robot.x, robot.y]]), RobotPlanStatus.HALT, cmd)
            self._navigator(robot.id)  # it hears what is sent, for when it moves again
            return cmd
        start = (robot.x, robot.y)
        goal = (it.x, it.y)
        path = np.array([start, goal])
        status = RobotPlanStatus.DIRECT
        cworld = self._robot_world(frame, i, it, game)
        if math.dist(start, goal) > self.params.brain.arrive_tolerance_m:
            p = self.settings.planner
            problem = PlanProblem(start, goal, self.radius, cworld, p.horizon_s, p.collision)
            result = self._planner(robot.id).solve(problem, make_termination(p))
            status = RobotPlanStatus.planned(result.status)
            if result.status in (PlanStatus.SOLVED, PlanStatus.APPROXIMATE) and len(result.path) >= 2:
                path = np.asarray(result.path)
            elif (escape := self._ball_escape(frame, start, it)) is not None:
                path, status = np.array([start, escape]), RobotPlanStatus.ESCAPE
        # drive through the goal only where the path ends at it (not at a stand-in for a blocked goal)
        through = max(it.final_speed_m_s, 0.0) if math.dist(tuple(path[-1]), goal) < 1e-9 else 0.0
        nav = self._navigator(robot.id)
        nav.set_plan(path, Arrival(it.theta, through, it.max_speed_m_s, it.max_omega_rad_s))
        vx, vy, omega = nav.command(robot, cworld, deadline(self.params.brain.navigate_deadline_ms * 1e-3))
        cmd = RobotCommand(self.team, robot.id, vx, vy, omega, it.kick_speed, it.chip, it.dribbler)
        self.plans[robot.id] = RobotPlan(it, path, status, cmd)
        return cmd
