"""The team's play: game state and roles -> one :class:`~strategy.skills.Intent` per robot.

Roles in priority order (Bruce 2006, B.5): goalie, the receiver of a pass decided or under way,
attacker (at the ball), defenders on the edge of our defense area, supporters at the best
receiving points of the pass evaluation, spread apart. Each part is its own unit: the roles
(:mod:`strategy.roles`), the attacker's kick (:mod:`strategy.kicking`), the pass state machine
(:mod:`strategy.passing`), the supporters' points (:mod:`strategy.support`), the goalie and the
defenders (:mod:`strategy.defense`) and the game states (:mod:`strategy.game_states`); this
module puts them together frame by frame.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, Team
from cmdragons.messages import BallState, GameState, PassReport, RefereeCommand, RobotState, WorldState
from strategy.defense import DefenseParams, defender_slots, goalie
from strategy.evaluation import PassParams
from strategy.game_states import (
    GameStateParams,
    Placing,
    behind_ball,
    halt,
    hold_shape,
    keep_away,
    keep_off_line,
    keeper_on_line,
    kickoff_places,
    leave_field,
    leaver,
    own_goal_sign,
    penalty_rush,
    penalty_shot,
    place_ball,
    restart_rules,
)
from strategy.kicking import Attacker, KickParams, KickPurpose
from strategy.passing import PassPlay, PassPlayParams, PassRecordParams
from strategy.roles import Objective, Role, RoleAssigner, RoleKind, RoleParams
from strategy.skills import Intent, SkillParams, defend, held_ball, intercept, mark, receive
from strategy.support import Supporters, SupportParams

__all__ = ["Strategy", "StrategyParams", "off_ball_line"]

Array = NDArray[np.float64]

GOALIE, ATTACKER, RECEIVER = Role(RoleKind.GOALIE), Role(RoleKind.ATTACKER), Role(RoleKind.RECEIVER)
_BALL_PLAYERS = frozenset({GOALIE, ATTACKER, RECEIVER})  # the roles team-mates do not leave room for


@dataclass(frozen=True)
class StrategyParams(Validated):
    """configs/strategy.yaml."""

    skills: SkillParams = SkillParams()
    passing: PassParams = PassParams()  # the pass and shot evaluation
    roles: RoleParams = RoleParams()
    defense: DefenseParams = DefenseParams()
    kicking: KickParams = KickParams()
    pass_play: PassPlayParams = PassPlayParams()
    pass_record: PassRecordParams = PassRecordParams()  # the match statistics' judge of each pass
    support: SupportParams = SupportParams()
    game_states: GameStateParams = GameStateParams()
    ball_room_m: float = setting(0.35, lo=0.0, hi=3.0)  # team-mates leave the ball handler this much room
    touched_m: float = setting(0.03, lo=0.0, hi=0.5)  # a robot's body this near the ball's has touched it
    barred_near_m: float = setting(1.0, lo=0.0, hi=10.0)  # our restart's kicker this near the rolling ball ...
    barred_clear_m: float = setting(0.4, lo=0.0, hi=3.0)  # ... steps this far off its line
    barred_rolling_m_s: float = setting(0.3, lo=0.0, hi=10.0)  # ... while it rolls this fast

    @property
    def robot_radius_m(self) -> float:
        """Our robots' radius, as strategy reads it everywhere."""
        return self.skills.robot_radius_m

    @property
    def ball_radius_m(self) -> float:
        return self.skills.ball_radius_m

    @property
    def obstacle_radius_m(self) -> float:
        """A robot's radius plus the ball's: whether the ball gets past a robot."""
        return self.robot_radius_m + self.ball_radius_m

    @property
    def pass_timeout_s(self) -> float:
        return self.pass_play.timeout_s


def _facing_ball(x: float, y: float, ball: BallState) -> Intent:
    return Intent(x, y, math.atan2(ball.y - y, ball.x - x))


def off_ball_line(robot: RobotState, intent: Intent, ball: BallState, pitch: Field, radius: float, near_m: float,
                  clear_m: float, rolling_m_s: float) -> Intent:
    """A robot that may not touch the ball (our restart's kicker, the rules' double touch) within
    ``near_m`` of it while it rolls faster than ``rolling_m_s``: sideways out of its way, ``clear_m``
    off its line on the robot's side, facing it (going its own way it ran alongside the ball and
    into it); its ``intent`` otherwise."""
    speed = math.hypot(ball.vx, ball.vy)
    if speed < rolling_m_s or math.hypot(robot.x - ball.x, robot.y - ball.y) > near_m:
        return intent
    ux, uy = ball.vx / speed, ball.vy / speed
    rx, ry = robot.x - ball.x, robot.y - ball.y
    along, side = rx * ux + ry * uy, ux * ry - uy * rx  # side > 0: left of the ball's way
    lateral = math.copysign(max(abs(side), clear_m), side if side != 0.0 else 1.0)
    lim_x, lim_y = pitch.half_length - radius, pitch.half_width - radius
    x = max(-lim_x, min(lim_x, ball.x + along * ux - lateral * uy))
    y = max(-lim_y, min(lim_y, ball.y + along * uy + lateral * ux))
    return _facing_ball(x, y, ball)


class Strategy:
    """One team's decisions, frame by frame."""

    def __init__(self, team: Team, pitch: Field, params: StrategyParams) -> None:
        self.team, self.field, self.p = team, pitch, params
        self.roles = RoleAssigner(params.roles)
        self.passes = PassPlay(params.pass_play, params.skills.ball_model)
        self.supporters = Supporters(pitch, params.passing, params.support, params.obstacle_radius_m)
        self.attacker = Attacker(pitch, params.kicking, params.passing, params.skills, params.obstacle_radius_m)
        self.frame = 0
        self.last_action: dict[int, KickPurpose] = {}  # robot id -> what its kick is for
        self._placing: Placing | None = None  # our ball placement, frame to frame
        self._taker: int | None = None  # the kicker of our kickoff or free kick under way
        self._barred: int | None = None  # our restart's taker, until another robot touched the ball
        self._too_many_since: float | None = None  # since when more of ours are on the field than allowed
        self._leaver: int | None = None  # the robot of ours driving out

    def retune(self, params: StrategyParams) -> None:
        """Decide with ``params`` from now on (the ball model as measured in play: pass speeds, kicks,
        intercepts), keeping what is kept from frame to frame (roles, the pass under way, placements)."""
        self.p = params
        self.attacker.skills = params.skills
        self.passes.model = params.skills.ball_model

    def own_sign(self, game: GameState) -> float:
        """-1 when we defend the goal at negative x, else +1."""
        return own_goal_sign(self.team, game)

    @property
    def pass_heat(self) -> tuple[Array, Array] | None:
        """The last pass evaluation over the candidate grid: points (n, 2) and values (n,), read-only;
        None before the first."""
        ev = self.supporters.evaluation
        if ev is None:
            return None
        points, values = ev.points.view(), ev.values.view()
        points.flags.writeable = values.flags.writeable = False
        return points, values

    @property
    def pass_report(self) -> PassReport | None:
        """The pass planned or under way after the last :meth:`decide` (None: none)."""
        ps = self.passes.current
        if ps is None:
            return None
        return PassReport(ps.passer, ps.receiver, ps.point, ps.shoot_at, ps.kicked)

    @property
    def pass_heat_redone(self) -> bool:
        """Whether the last :meth:`decide` evaluated the passes anew (:attr:`pass_heat` is new)."""
        return self.supporters.evaluation is not None and self.supporters.evaluated_frame == self.frame

    def decide(self, world: WorldState, game: GameState) -> dict[int, Intent]:
        """An intent for each of our robots in ``world``; with more on the field than the referee
        allows for ``leave_after_s``, one of them drives out (:func:`leaver`, :func:`leave_field`)
        and the others play."""
        self.frame += 1
        out = self._leaving(world, game)
        if out is None or game.command.halted:
            return self._decide(world, game)
        rest = dataclasses.replace(world, robots=tuple(r for r in world.robots
                                                       if (r.team, r.id) != (self.team, out)))
        intents = self._decide(rest, game)
        intents[out] = leave_field(next(r for r in world.robots if (r.team, r.id) == (self.team, out)), self.field,
                                   self.p.game_states)
        return intents

    def _leaving(self, world: WorldState, game: GameState) -> int | None:
        """The robot of ours that drives out now, if any: while more of ours are seen on the field
        (its margin included) than ``game`` allows, from ``leave_after_s`` on, the same one until
        it is off."""
        margin = self.field.dims.boundary_width_m
        on = {r.id: r for r in world.robots
              if r.team == self.team and r.visible and self.field.in_field(r.x, r.y, -margin)}
        if len(on) <= game.team_info(self.team).max_robots:
            self._too_many_since, self._leaver = None, None
            return None
        if self._too_many_since is None:
            self._too_many_since = world.t
        if world.t - self._too_many_since < self.p.game_states.leave_after_s:
            return None
        if self._leaver not in on:
            self._leaver = leaver(on, game.team_info(self.team).goalkeeper, self.field)
        return self._leaver

    def _decide(self, world: WorldState, game: GameState) -> dict[int, Intent]:
        own = {r.id: r for r in world.robots if r.team == self.team}
        opp = [r for r in world.robots if r.team != self.team]
        if not own:
            return {}
        own_sign = self.own_sign(game)
        ball = world.ball
        if game.command.halted:
            return halt(own)
        if ball is None:
            return hold_shape(own, self.field, own_sign, self.p.game_states)
        ball = held_ball(ball, own.values(), self.p.skills)  # a ball one of ours turns with is no moving ball
        ours = game.for_team == self.team
        restart = ours and game.command.kick_restart
        self._barred = self._double_touch_bar(game, own, opp, ball)
        stopped = not (game.command.running or restart)  # the ball not ours to play now: a pass waits
        intents = self._normal(world.t, own, opp, ball, own_sign, restart, stopped,
                               restart and game.command == RefereeCommand.KICKOFF)
        self._taker = self._restart_taker(ball) if restart else None
        if game.command == RefereeCommand.BALL_PLACEMENT and game.placement is not None:
            return self._placement(world.t, intents, own, ball, game.placement, ours, own_sign)
        if game.command == RefereeCommand.PENALTY:
            return self._penalty(intents, own, opp, ball, game, ours, own_sign)
        kicker = next((rid for rid, role in self.roles.roles.items() if role == ATTACKER), None)
        if game.command == RefereeCommand.KICKOFF and not game.ready:
            kicker = None  # prepared, not started: nobody plays the ball yet
        return restart_rules(intents, game, ours, ball, self.field, own_sign, self.p.game_states,
                             self.p.robot_radius_m, kicker)

    def _double_touch_bar(self, game: GameState, own: Mapping[int, RobotState], opp: list[RobotState],
                          ball: BallState) -> int | None:
        """The robot that may not touch the ball now (the rules: a restart's kicker touches it again
        only after another robot has; else a free kick for them): the taker of our kickoff or free
        kick from the normal start that followed it (the ball moved: the restart was taken) until
        another robot, ours or theirs, comes within ``touched_m`` of the ball or the command changes."""
        barred = self._barred
        if game.command == RefereeCommand.NORMAL and self._taker is not None:
            barred = self._taker  # the command was our restart the frame before
        if barred is None or game.command != RefereeCommand.NORMAL:
            return None
        reach = self.p.robot_radius_m + self.p.ball_radius_m + self.p.touched_m
        others = [r for r in (*own.values(), *opp) if not (r.team == self.team and r.id == barred)]
        if any(math.hypot(r.x - ball.x, r.y - ball.y) < reach for r in others):
            return None
        return barred

    def _restart_taker(self, ball: BallState) -> int | None:
        """Our restart's kicker this frame: the attacker while the ball lies still; once it rolls
        (``barred_rolling_m_s``: kicked, the normal start not yet given) the one found before, or
        the passer of a pass under way. (The attacker's role goes to nobody once a pass is kicked, or
        to a robot nearer the rolling ball: the kicker, unbarred, played the ball again in grSim.)"""
        attacker = self._role_robot(ATTACKER)
        if math.hypot(ball.vx, ball.vy) < self.p.barred_rolling_m_s:
            return attacker
        passing = self.passes.current
        if self._taker is None and passing is not None and passing.kicked:
            return passing.passer
        return self._taker if self._taker is not None else attacker

    def _role_robot(self, role: Role) -> int | None:
        return next((rid for rid, r in self.roles.roles.items() if r == role), None)

    def _placement(self, t: float, intents: dict[int, Intent], own: Mapping[int, RobotState], ball: BallState,
                   target: tuple[float, float], ours: bool, own_sign: float) -> dict[int, Intent]:
        """Ball placement: ours, the robot nearest the ball (the goalie only when alone) places it
        and the others keep off its way; theirs, everyone keeps off the line to the target."""
        p, f, gs = self.p, self.field, self.p.game_states
        if not ours:
            return keep_off_line(intents, (ball.x, ball.y), target, f, gs, p.robot_radius_m)
        goalie_id = self._role_robot(GOALIE)
        players = [rid for rid in own if rid != goalie_id] or list(own)
        carrier = min(players, key=lambda rid: math.hypot(own[rid].x - ball.x, own[rid].y - ball.y))
        others = {rid: it for rid, it in intents.items() if rid != carrier}
        others = keep_off_line(others, (ball.x, ball.y), target, f, gs, p.robot_radius_m)
        out = dict(keep_away(others, ball, f, own_sign, gs, p.robot_radius_m, kickoff=False, slow=False))
        out[carrier], self._placing = place_ball(own[carrier], ball, target, p.skills, gs, t, self._placing)
        return out

    def _penalty(self, intents: dict[int, Intent], own: Mapping[int, RobotState], opp: list[RobotState],
                 ball: BallState, game: GameState, ours: bool, own_sign: float) -> dict[int, Intent]:
        """A penalty kick: ours, the taker plays it from the normal start (:func:`penalty_shot`),
        everyone else behind the ball; theirs, our keeper on its line until the normal start, then
        out at the ball once it is in play (:func:`penalty_rush`), everyone else behind the ball."""
        p, f, gs = self.p, self.field, self.p.game_states
        ready = game.ready
        goalie_id = self._role_robot(GOALIE)
        if ours:
            attack = -own_sign
            players = [rid for rid in own if rid != goalie_id] or list(own)
            taker = min(players, key=lambda rid: math.hypot(own[rid].x - ball.x, own[rid].y - ball.y))
            keeper = min(opp, key=lambda r: abs(r.x - attack * f.half_length) + abs(r.y), default=None)
            out = behind_ball({rid: it for rid, it in intents.items() if rid != taker}, ball, attack, f, gs,
                              p.robot_radius_m)
            out[taker] = penalty_shot(own[taker], ball, attack, keeper, f, p.skills, gs, ready)
            return out
        out = behind_ball({rid: it for rid, it in intents.items() if rid != goalie_id}, ball, own_sign, f, gs,
                          p.robot_radius_m)
        if goalie_id is not None and not ready:
            out[goalie_id] = keeper_on_line(ball, f, own_sign, p.skills, gs)
        elif goalie_id is not None:
            rush = penalty_rush(own[goalie_id], ball, game.placement, f, own_sign, p.skills, p.defense, gs)
            out[goalie_id] = intents[goalie_id] if rush is None else rush
        return out

    def _objectives(self, own: Mapping[int, RobotState], ball: BallState, own_sign: float,
                    defenders: Mapping[Role, Intent]) -> list[Objective]:
        """This frame's roles in priority order, each with where it is played."""
        p, f = self.p, self.field
        goalie_id = p.roles.goalie_id if p.roles.goalie_id in own else None
        objectives = [Objective(GOALIE, own_sign * f.half_length, 0.0, fixed_robot=goalie_id)]
        passing = self.passes.current
        if passing is not None:
            # the receiver of a pass, planned or under way, waits at (or meets the ball near) its point
            objectives.append(Objective(RECEIVER, *passing.point, fixed_robot=passing.receiver))
        if passing is None or not passing.kicked:
            # the attacker's cost: the way to where each robot can meet the (moving) ball
            meet = {rid: intercept(r, ball, p.skills, f) for rid, r in own.items()}
            costs = {rid: math.hypot(m.x - own[rid].x, m.y - own[rid].y) for rid, m in meet.items()}
            if self._barred in costs:  # our restart's taker plays the ball again only when nobody else can
                costs[self._barred] = math.inf
            objectives.append(Objective(ATTACKER, ball.x, ball.y, costs=costs))
        objectives += [Objective(role, it.x, it.y) for role, it in defenders.items()]
        objectives += [Objective(Role(RoleKind.SUPPORTER, k), x, y) for k, (x, y) in enumerate(self.supporters.points)]
        return objectives

    def _normal(self, t: float, own: dict[int, RobotState], opp: list[RobotState], ball: BallState,
                own_sign: float, restart: bool = False, stopped: bool = False,
                kickoff: bool = False) -> dict[int, Intent]:
        """Normal play; ``restart``: our kickoff or free kick (the attacker's kick its only touch);
        ``stopped``: the ball is not ours to play (a stop, their restart or placement), a pass decided
        waits for as long as that lasts; ``kickoff``: our kickoff."""
        p, f = self.p, self.field
        attack_sign = -own_sign
        opp_xy = np.array([[r.x, r.y] for r in opp]) if opp else np.zeros((0, 2))
        self.attacker.watch(t, ball)
        count = max(0, len(own) - 2 - p.defense.defenders)  # supporters: the robots besides goalie, attacker, defenders
        passing = self.passes.follow(t, own, ball)
        # while play is stopped, the receiver of a decided pass waits for as long as the stoppage lasts
        # at the best point, where it stood as a supporter: the next supporter was sent to that point
        # too and drove into it. In normal play the pass is kicked within moments (kept clear then too,
        # our simulator's default play scored in 9 of 20 seeds instead of 14)
        taken = [passing.point] if passing is not None and stopped else []
        places = None
        if kickoff:  # our kickoff: the supporters wait in our half, where the rules let them stand
            places = functools.partial(kickoff_places, pitch=f, own_sign=own_sign, p=p.game_states,
                                       radius=p.robot_radius_m)
        self.supporters.update(self.frame, np.array([ball.x, ball.y]), attack_sign, opp_xy, count, taken,
                               hold=kickoff, place=places)

        defenders = {Role(RoleKind.DEFENDER, k): defend(ball, f, own_sign, slot, p.skills)
                     for k, slot in enumerate(defender_slots(p.defense))}
        roles = self.roles.assign({rid: (r.x, r.y) for rid, r in own.items()},
                                  self._objectives(own, ball, own_sign, defenders))
        supporters = [rid for rid, role in roles.items() if role.kind is RoleKind.SUPPORTER]

        out: dict[int, Intent] = {}
        for rid, role in roles.items():
            r = own[rid]
            if role == GOALIE:
                out[rid], clears = goalie(r, ball, f, own_sign, p.defense, p.skills)
                if clears:
                    self.last_action[rid] = KickPurpose.CLEAR
            elif role == ATTACKER and rid == self._barred:
                out[rid] = _facing_ball(r.x, r.y, ball)  # nobody else to play it: wait for theirs to touch it
            elif role == ATTACKER:
                out[rid], kind = self.attacker.play(t, r, own, supporters, opp_xy, ball, attack_sign, self.passes,
                                                    restart)
                self.last_action[rid] = kind
            elif role == RECEIVER and passing is not None and not passing.kicked:
                out[rid] = _facing_ball(*passing.point, ball)
            elif role == RECEIVER:
                assert passing is not None
                out[rid] = receive(r, ball, passing.point, p.skills, passing.shoot_at,
                                   p.skills.max_kick_m_s if passing.shoot_at else 0.0)
                if passing.shoot_at is not None:
                    self.last_action[rid] = KickPurpose.SHOT  # the one-touch shot at the goal
            elif role.kind is RoleKind.DEFENDER:
                out[rid] = defenders[role]
            else:
                out[rid] = _facing_ball(*self.supporters.points[role.index], ball)
        for rid, r in own.items():  # robots without a role (more robots than objectives): mark or hold
            if rid not in out:
                out[rid] = mark(opp[rid % len(opp)], f, own_sign, p.skills) if opp else Intent(r.x, r.y, r.theta)
        # everyone but the goalie and the robot playing the ball leaves it room
        others = {rid: it for rid, it in out.items() if roles.get(rid) not in _BALL_PLAYERS or rid == self._barred}
        out.update(keep_away(others, ball, f, own_sign, p.game_states, p.robot_radius_m, kickoff=False, slow=False,
                             distance_m=p.ball_room_m))
        if self._barred in out:  # whatever its role, it must not meet the ball it kicked on its way
            out[self._barred] = off_ball_line(own[self._barred], out[self._barred], ball, f, p.robot_radius_m,
                                              p.barred_near_m, p.barred_clear_m, p.barred_rolling_m_s)
        return out
