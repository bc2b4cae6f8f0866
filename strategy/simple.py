"""The built-in simple opponent: plays on the true state with plain steering, no planning.

Its lowest id keeps goal (and clears a ball at rest in its area), the robot nearest the ball goes
behind it and shoots at the goal's centre, the others hold a shape in their half that follows the
ball sideways. It keeps the rules' distance in a stop and at our restarts, places the ball with its
chaser, keeps off the line of our placements, and takes and defends penalties the plain way (its
chaser shoots, its goalie blocks). Robots sent off the field it leaves alone. A sparring partner for
matches and benchmarks, not a team.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from cmdragons.config import Validated, setting
from cmdragons.control.motion import relative_kick
from cmdragons.geometry import Field, Team, wrap_angle
from cmdragons.messages import BallState, GameState, RefereeCommand, RobotCommand, RobotState, WorldState
from strategy.defense import ball_to_clear, clear_target
from strategy.evaluation import clearest_direction
from strategy.game_states import (
    Placing,
    behind_ball,
    keep_away,
    keep_off_line,
    keeper_on_line,
    own_goal_sign,
    penalty_shot,
    place_ball,
)
from strategy.plays import StrategyParams
from strategy.skills import Intent, goalie_block, kick_to

__all__ = ["SimpleTeam", "SimpleTeamParams", "Steering", "steer"]


@dataclass(frozen=True)
class SimpleTeamParams(Validated):
    max_speed_m_s: float = setting(2.0, lo=0.0, hi=10.0)
    position_gain_1_s: float = setting(3.0, lo=0.0, hi=100.0)  # speed per metre of position error
    heading_gain_1_s: float = setting(5.0, lo=0.0, hi=100.0)
    max_omega_rad_s: float = setting(8.0, lo=0.0, hi=100.0)
    shot_speed_m_s: float = setting(5.0, lo=0.0, hi=10.0)
    shot_reach_m: float = setting(2.0, lo=0.1, hi=10.0)  # the chaser aims at a point this far along the open lane
    shape_depth_share: float = setting(0.55, lo=0.0, hi=1.0)  # the others stand this share of their half deep ...
    shape_step_share: float = setting(0.3, lo=0.0, hi=1.0)  # ... every second one this share further up
    shape_follow_share: float = setting(0.4, lo=0.0, hi=1.0)  # ... following this share of the ball's y
    shape_spacing_m: float = setting(1.2, lo=0.0, hi=5.0)  # ... this far apart across the field


class Steering(Protocol):
    """What :func:`steer` reads of a team's parameters."""

    @property
    def max_speed_m_s(self) -> float: ...
    @property
    def position_gain_1_s(self) -> float: ...  # speed per metre of position error
    @property
    def heading_gain_1_s(self) -> float: ...
    @property
    def max_omega_rad_s(self) -> float: ...


def steer(team: Team, rid: int, x: float, y: float, theta: float, it: Intent, p: Steering) -> RobotCommand:
    """Proportional steering toward an intent, field frame; no obstacle avoidance."""
    dx, dy = it.x - x, it.y - y
    d = math.hypot(dx, dy)
    cap = p.max_speed_m_s if it.max_speed_m_s is None else min(p.max_speed_m_s, it.max_speed_m_s)
    v = min(cap, p.position_gain_1_s * d + it.final_speed_m_s)
    vx, vy = (dx / d * v, dy / d * v) if d > 1e-6 else (0.0, 0.0)
    top = p.max_omega_rad_s if it.max_omega_rad_s is None else min(p.max_omega_rad_s, it.max_omega_rad_s)
    omega = max(-top, min(top, p.heading_gain_1_s * wrap_angle(it.theta - theta)))
    return RobotCommand(team, rid, vx, vy, omega, it.kick_speed, it.chip, it.dribbler)


class SimpleTeam:
    def __init__(self, team: Team, pitch: Field, params: SimpleTeamParams, strategy: StrategyParams) -> None:
        self.team, self.field, self.p, self.sp = team, pitch, params, strategy
        self._placing: Placing | None = None  # its ball placement, frame to frame

    def commands(self, world: WorldState, game: GameState) -> list[RobotCommand]:
        f = self.field
        # robots off the field (a card's) are out of play
        on = [r for r in world.robots if r.team == self.team and f.in_field(r.x, r.y, -f.dims.boundary_width_m)]
        own = sorted(on, key=lambda r: r.id)
        ball = world.ball
        if not own or ball is None or game.command.halted:
            return [RobotCommand(self.team, r.id) for r in own]
        own_sign = own_goal_sign(self.team, game)
        goal = (-own_sign * f.half_length, 0.0)
        goalie = own[0]
        intents: dict[int, Intent] = {goalie.id: goalie_block(ball, f, own_sign, self.sp.skills)}
        if ball_to_clear(ball, f, own_sign, self.sp.defense):
            # the ball at rest in its own area: the goalie clears it up the field, away from the middle
            clear_to = clear_target(ball, f, own_sign, self.sp.defense)
            intents[goalie.id] = kick_to(goalie, ball, clear_to, self.p.shot_speed_m_s, self.sp.skills)
        field_players = own[1:]
        if field_players:
            chaser = min(field_players, key=lambda r: math.hypot(r.x - ball.x, r.y - ball.y))
            others_xy = np.array([[r.x, r.y] for r in world.robots if r.team != self.team]).reshape(-1, 2)
            toward = math.atan2(goal[1] - ball.y, goal[0] - ball.x)
            kp = self.sp.kicking
            angle, _ = clearest_direction(np.array([ball.x, ball.y]), toward, others_xy, self.sp.obstacle_radius_m,
                                          kp.clear_reach_m, kp.clear_spread_rad, kp.clear_samples,
                                          kp.clear_lane_cap_rad, kp.clear_turn_cost)
            target = (ball.x + self.p.shot_reach_m * math.cos(angle), ball.y + self.p.shot_reach_m * math.sin(angle))
            intents[chaser.id] = kick_to(chaser, ball, target, self.p.shot_speed_m_s, self.sp.skills)
            others = [r for r in field_players if r.id != chaser.id]
            for k, r in enumerate(others):
                x = own_sign * f.half_length * (self.p.shape_depth_share - self.p.shape_step_share * (k % 2))
                y = ball.y * self.p.shape_follow_share + (k - (len(others) - 1) / 2) * self.p.shape_spacing_m
                intents[r.id] = Intent(x, y, math.atan2(ball.y - y, ball.x - x))
        ours = game.for_team == self.team
        gs, radius = self.sp.game_states, self.sp.robot_radius_m
        if game.command == RefereeCommand.STOP or (game.command.kick_restart and not ours):
            intents = keep_away(intents, ball, f, own_sign, gs, radius, game.command == RefereeCommand.KICKOFF,
                                game.command == RefereeCommand.STOP)
        elif game.command == RefereeCommand.BALL_PLACEMENT and game.placement is not None:
            intents = keep_off_line(intents, (ball.x, ball.y), game.placement, f, gs, radius)
            if ours and field_players:
                placed = place_ball(chaser, ball, game.placement, self.sp.skills, gs, world.t, self._placing)
                intents[chaser.id], self._placing = placed
        elif game.command == RefereeCommand.PENALTY:
            intents = self._penalty(intents, own, world, ball, game.ready, ours, own_sign)
        return [relative_kick(steer(self.team, r.id, r.x, r.y, r.theta, intents[r.id], self.p), r.theta,
                              (r.vx, r.vy), self.field.league.robot) for r in own]

    def _penalty(self, intents: dict[int, Intent], own: list[RobotState], world: WorldState, ball: BallState,
                 ready: bool, ours: bool, own_sign: float) -> dict[int, Intent]:
        """Its chaser takes the penalty, everyone else behind the ball; defending, its goalie on the line."""
        f, gs, radius = self.field, self.sp.game_states, self.sp.robot_radius_m
        goalie = own[0]
        if ours:
            taker = min(own[1:] or own, key=lambda r: math.hypot(r.x - ball.x, r.y - ball.y))
            attack = -own_sign
            keeper = min((r for r in world.robots if r.team != self.team),
                         key=lambda r: abs(r.x - attack * f.half_length) + abs(r.y), default=None)
            out = behind_ball({k: v for k, v in intents.items() if k != taker.id}, ball, attack, f, gs, radius)
            shot = penalty_shot(taker, ball, attack, keeper, f, self.sp.skills, gs, ready)
            out[taker.id] = replace(shot, kick_speed=min(shot.kick_speed, self.p.shot_speed_m_s))
            return out
        out = behind_ball({k: v for k, v in intents.items() if k != goalie.id}, ball, own_sign, f, gs, radius)
        out[goalie.id] = intents[goalie.id] if ready else keeper_on_line(ball, f, own_sign, self.sp.skills, gs)
        return out
