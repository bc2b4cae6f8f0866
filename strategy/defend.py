"""The built-in defending opponent: plays on the true state with plain steering at our robots'
limits, and defends. A sparring partner that makes passes and shots earn their way, not a team.

Roles in priority order (:class:`~strategy.roles.RoleAssigner`, appendix B.5 of Bruce 2006): the
configured goalie (``strategy.roles.goalie_id``) keeps goal (blocking, or clearing a ball at rest
in its area: :func:`strategy.defense.goalie`); the attacker, the robot that meets the ball soonest
(:func:`strategy.skills.intercept`), shoots at the widest gap of the goal mouth
(:func:`strategy.evaluation.best_shot`) or, without one, kicks the ball along the most open lane
toward the goal, to come to rest ``advance_m`` on; the blocker stands on the ball's line to its
goal, ``block_distance_m`` in front of the ball, where a shot must pass; the markers stand in the
passing lanes of the opponents most dangerous to its goal (nearest to it first), on the line from
each receiver to the ball, ``mark_gap_m`` from the receiver; the robots left over defend the edge
of the defense area (:func:`strategy.skills.defend`). A marker keeps its receiver from frame to
frame: its role is the receiver's id.

The rules our referee enforces: no target inside either defense area but the goalie's (a defender
touching the ball in its own area gives a penalty, an attacker in the other a free kick); the ball
is waited for outside them; the rules' distance and speed in a stop and at the other team's
restarts, our kickoff in our half (:func:`strategy.game_states.restart_rules`); a restart's kick
taken lined up (:func:`strategy.skills.set_kick`) and its kicker off the ball until another robot
touched it (a double touch); placements, ours carried by the robot nearest the ball, theirs kept
off its line; penalties taken and kept as our team does. Near other robots the speed toward them
falls to ``closing_m_s`` and to nothing at touching (the rules' crash is a meeting faster than
1.5 m/s; a shove is pushing). Robots sent off the field it leaves alone.

Field frame, metres, seconds, radians.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, derived, setting
from cmdragons.control.motion import relative_kick
from cmdragons.geometry import Field, Team, wrap_angle
from cmdragons.messages import BallState, GameState, RefereeCommand, RobotCommand, RobotState, WorldState
from strategy.defense import DefenseParams, defender_slots, goalie
from strategy.evaluation import best_shot, clearest_direction
from strategy.game_states import (
    Placing,
    behind_ball,
    keep_off_line,
    keeper_on_line,
    own_goal_sign,
    penalty_rush,
    penalty_shot,
    place_ball,
    restart_rules,
)
from strategy.plays import StrategyParams, off_ball_line
from strategy.roles import Objective, Role, RoleAssigner, RoleKind
from strategy.simple import steer
from strategy.skills import Intent, defend, intercept, kick_to, pass_speed, set_kick

__all__ = ["DefendTeam", "DefendTeamParams", "block_point", "detour", "keep_off_robots", "mark_point", "threats"]

Array = NDArray[np.float64]

# the speed asked a hair under the robots' limit: its components, made back into a speed, must not round above it
_UNDER_LIMIT = 1.0 - 1e-9

GOALIE, ATTACKER, BLOCKER = Role(RoleKind.GOALIE), Role(RoleKind.ATTACKER), Role(RoleKind.BLOCKER)


@dataclass(frozen=True)
class DefendTeamParams(Validated):
    """configs/team.yaml ``defend_opponent``."""

    # our robots' limits: configured once, in field.yaml robot
    max_speed_m_s: float = derived("field.robot.max_speed_m_s", 3.0, lo=0.0, hi=10.0)
    max_omega_rad_s: float = derived("field.robot.max_omega_rad_s", 20.0, lo=0.0, hi=100.0)
    max_brake_m_s2: float = derived("field.robot.max_brake_m_s2", 6.0, lo=0.0, hi=50.0)
    brake_share: float = setting(0.8, lo=0.05, hi=1.0)  # steering plans to stop at this share of the braking limit
    position_gain_1_s: float = setting(3.0, lo=0.0, hi=100.0)  # speed per metre of position error
    heading_gain_1_s: float = setting(6.0, lo=0.0, hi=100.0)
    shot_speed_m_s: float = setting(6.0, lo=0.0, hi=6.5)  # shots (rule: a ball over 6.5 m/s is a foul)
    shot_min_open_rad: float = setting(0.06, lo=0.0, hi=3.0)  # a goal gap this wide is shot at ...
    shot_range_m: float = setting(4.0, lo=0.0, hi=20.0)  # ... from this near the goal line's centre
    advance_m: float = setting(2.0, lo=0.1, hi=10.0)  # else the ball goes along the most open lane this far ...
    advance_arrival_m_s: float = setting(0.5, lo=0.0, hi=6.0)  # ... kicked to arrive there this fast ...
    advance_margin_m: float = setting(0.4, lo=0.0, hi=2.0)  # ... the target this far inside the field lines
    blockers: int = setting(1, lo=0, hi=10)  # robots on the ball's line to its goal ...
    block_distance_m: float = setting(0.6, lo=0.2, hi=5.0)  # ... this far in front of the ball (centres)
    on_ball_m: float = setting(0.5, lo=0.0, hi=5.0)  # the opponent nearest the ball within this plays it: not marked
    mark_gap_m: float = setting(0.45, lo=0.2, hi=5.0)  # a marker stands this far from its receiver toward the ball
    mark_lane_share: float = setting(0.5, lo=0.0, hi=1.0)  # ... at most this share of the way to the ball
    mark_gap_stopped_m: float = setting(0.8, lo=0.2, hi=5.0)  # ... in a stop and a placement (robots on their way)
    detour_share: float = setting(1.2, lo=1.0, hi=3.0)  # in a stop, a way through the ball's circle goes round
    # it this share of its radius out
    area_margin_m: float = setting(0.1, lo=0.0, hi=1.0)  # targets keep the robot's edge this far off the areas
    near_gap_m: float = setting(0.3, lo=0.01, hi=3.0)  # another robot within this gap (body to body) ...
    closing_m_s: float = setting(1.0, lo=0.0, hi=5.0)  # ... is approached no faster than this, falling to 0 at touching


def threats(opponents: Sequence[RobotState], ball: BallState, pitch: Field, own_sign: float,
            p: DefendTeamParams) -> list[RobotState]:
    """The opponents to mark, most dangerous first (nearest our goal's centre): all but the one
    playing the ball (the nearest to it, within ``on_ball_m``) and those in their own defense area
    (their keeper)."""
    gx = own_sign * pitch.half_length
    on_ball = min(opponents, key=lambda r: math.hypot(r.x - ball.x, r.y - ball.y), default=None)
    if on_ball is not None and math.hypot(on_ball.x - ball.x, on_ball.y - ball.y) > p.on_ball_m:
        on_ball = None
    out = [r for r in opponents if r is not on_ball and pitch.in_defense_area(r.x, r.y) != -int(own_sign)]
    return sorted(out, key=lambda r: (math.hypot(r.x - gx, r.y), r.id))


def _legal(x: float, y: float, pitch: Field, radius: float, p: DefendTeamParams) -> tuple[float, float]:
    """(x, y) moved onto the field and out of both defense areas, the robot's edge ``area_margin_m`` off."""
    return pitch.free_kick_spot(x, y, radius + p.area_margin_m)


def mark_point(receiver: RobotState, ball: BallState, pitch: Field, radius: float, p: DefendTeamParams,
               gap_m: float | None = None) -> Intent:
    """A marker in the passing lane: on the line from ``receiver`` to the ball, ``gap_m`` (default
    ``mark_gap_m``) from the receiver (at most ``mark_lane_share`` of the way), facing the ball; off
    the defense areas."""
    dx, dy = ball.x - receiver.x, ball.y - receiver.y
    lane = math.hypot(dx, dy)
    if lane < 1e-6:
        return Intent(*_legal(receiver.x, receiver.y, pitch, radius, p), 0.0)
    gap = min(p.mark_gap_m if gap_m is None else gap_m, p.mark_lane_share * lane)
    x, y = _legal(receiver.x + dx / lane * gap, receiver.y + dy / lane * gap, pitch, radius, p)
    return Intent(x, y, math.atan2(ball.y - y, ball.x - x))


def block_point(ball: BallState, pitch: Field, own_sign: float, radius: float, p: DefendTeamParams) -> Intent:
    """A shot blocker: on the line from the ball to our goal's centre, ``block_distance_m`` in front
    of the ball (never past the goal line), facing the ball; off the defense areas."""
    gx = own_sign * pitch.half_length
    dx, dy = gx - ball.x, -ball.y
    d = math.hypot(dx, dy)
    k = min(p.block_distance_m, d) / max(d, 1e-9)
    x, y = _legal(ball.x + dx * k, ball.y + dy * k, pitch, radius, p)
    return Intent(x, y, math.atan2(ball.y - y, ball.x - x))


def detour(start: tuple[float, float], goal: tuple[float, float], centre: tuple[float, float], radius: float,
           share: float) -> tuple[float, float]:
    """Where to head from ``start`` for ``goal`` without crossing the circle of ``radius`` round
    ``centre``: ``goal`` when the straight way keeps out of it, else a point on the circle of
    ``share`` times the radius, round from ``start``'s side toward ``goal``'s by at most the angle
    that leaves the inner circle no nearer (asked again each frame, the robot goes round); from
    inside the circle, straight out unless the way to ``goal`` leads away from the centre already."""
    (sx, sy), (gx, gy), (cx, cy) = start, goal, centre
    dx, dy = gx - sx, gy - sy
    length2 = dx * dx + dy * dy
    out = math.hypot(sx - cx, sy - cy)
    if length2 < 1e-12 or out < 1e-9:
        return goal
    if out < radius:
        if dx * (sx - cx) + dy * (sy - cy) >= 0.0:
            return goal
        return cx + (sx - cx) / out * radius * share, cy + (sy - cy) / out * radius * share
    u = max(0.0, min(1.0, ((cx - sx) * dx + (cy - sy) * dy) / length2))
    if math.hypot(sx + u * dx - cx, sy + u * dy - cy) >= radius:
        return goal
    at = math.atan2(sy - cy, sx - cx)
    turn = wrap_angle(math.atan2(gy - cy, gx - cx) - at)
    step = math.copysign(min(abs(turn), math.acos(1.0 / share)), turn if turn != 0.0 else 1.0)
    return cx + radius * share * math.cos(at + step), cy + radius * share * math.sin(at + step)


def keep_off_robots(cmd: RobotCommand, robot: RobotState, others: Sequence[RobotState], radius: float,
                    p: DefendTeamParams) -> RobotCommand:
    """``cmd`` with its velocity toward each robot within ``near_gap_m`` (body to body) cut to
    ``closing_m_s`` times the share of that gap still open (nothing at touching: following a robot
    that backs off while touching it is pushing), less the other's speed toward it; it is only ever
    slowed toward a robot, never turned back."""
    vx, vy = cmd.vx, cmd.vy
    for o in others:
        dx, dy = o.x - robot.x, o.y - robot.y
        d = math.hypot(dx, dy)
        gap = d - 2.0 * radius
        if d < 1e-9 or gap >= p.near_gap_m:
            continue
        nx, ny = dx / d, dy / d
        toward = vx * nx + vy * ny
        allowed = p.closing_m_s * max(gap, 0.0) / p.near_gap_m + min(o.vx * nx + o.vy * ny, 0.0)
        cut = min(toward - allowed, toward)
        if cut > 0.0:
            vx, vy = vx - cut * nx, vy - cut * ny
    return replace(cmd, vx=vx, vy=vy)


class DefendTeam:
    """The defending opponent of one team, frame by frame: the same interface as
    :class:`strategy.simple.SimpleTeam`."""

    def __init__(self, team: Team, pitch: Field, params: DefendTeamParams, strategy: StrategyParams) -> None:
        self.team, self.field, self.p, self.sp = team, pitch, params, strategy
        self.roles = RoleAssigner(strategy.roles)
        self._placing: Placing | None = None  # its ball placement, frame to frame
        self._taker: int | None = None  # the kicker of its kickoff or free kick under way
        self._barred: int | None = None  # ... after the kick, until another robot touched the ball

    def commands(self, world: WorldState, game: GameState) -> list[RobotCommand]:
        """This frame's commands of its robots on the field (standing still in a halt)."""
        on = self._on_field(world)
        own = sorted((r for r in on if r.team == self.team), key=lambda r: r.id)
        if not own or world.ball is None or game.command.halted:
            return [RobotCommand(self.team, r.id) for r in own]
        intents = self.intents(world, game)
        ball = world.ball
        if game.command == RefereeCommand.STOP or (game.command.kick_restart and game.for_team != self.team):
            # the rules' distance kept on the way too, not only at the places keep_away found
            keep = self.sp.game_states.stop_distance_m + self.sp.robot_radius_m
            for r in own:
                it = intents[r.id]
                x, y = detour((r.x, r.y), (it.x, it.y), (ball.x, ball.y), keep, self.p.detour_share)
                intents[r.id] = replace(it, x=x, y=y)
        robot = self.field.league.robot
        return [relative_kick(self._steer(r, intents[r.id], on), r.theta, (r.vx, r.vy), robot) for r in own]

    def _on_field(self, world: WorldState) -> list[RobotState]:
        """The robots in play (one sent off by a card stands outside the field)."""
        f = self.field
        return [r for r in world.robots if f.in_field(r.x, r.y, -f.dims.boundary_width_m)]

    def intents(self, world: WorldState, game: GameState) -> dict[int, Intent]:
        """Where each of its robots on the field goes this frame, and what it does there (none
        without a ball)."""
        f = self.field
        on = self._on_field(world)
        own = sorted((r for r in on if r.team == self.team), key=lambda r: r.id)
        opp = [r for r in on if r.team != self.team]
        ball = world.ball
        if not own or ball is None:
            return {}
        own_sign = own_goal_sign(self.team, game)
        ours = game.for_team == self.team
        restart = ours and game.command.kick_restart
        self._barred = self._double_touch_bar(game, own, opp, ball)
        by_id = {r.id: r for r in own}
        stopped = game.command in (RefereeCommand.STOP, RefereeCommand.BALL_PLACEMENT)
        goalie_id = self._goalie(own)
        intents, attacker = self._normal(by_id, goalie_id, opp, ball, own_sign, restart and game.ready,
                                         self.p.mark_gap_stopped_m if stopped else None)
        self._taker = attacker if restart and game.ready else None
        gs, radius = self.sp.game_states, self.sp.robot_radius_m
        if game.command == RefereeCommand.BALL_PLACEMENT and game.placement is not None:
            intents = keep_off_line(intents, (ball.x, ball.y), game.placement, f, gs, radius)
            if ours:
                players = [r for r in own if r.id != goalie_id] or own
                placer = min(players, key=lambda r: math.hypot(r.x - ball.x, r.y - ball.y))
                intents[placer.id], self._placing = place_ball(placer, ball, game.placement, self.sp.skills, gs,
                                                               world.t, self._placing)
            return intents
        if game.command == RefereeCommand.PENALTY:
            return self._penalty(intents, own, goalie_id, opp, ball, game, ours, own_sign)
        kicker = attacker if restart and game.ready else None
        return restart_rules(intents, game, ours, ball, f, own_sign, gs, radius, kicker)

    def _goalie(self, own: Sequence[RobotState]) -> int | None:
        """Its keeper: the configured goalie (``strategy.roles.goalie_id``, the id the referee knows
        as the keeper) while it is on the field, else none; with -1, its lowest id."""
        gid = self.sp.roles.goalie_id
        if gid < 0:
            return own[0].id
        return gid if any(r.id == gid for r in own) else None

    def _steer(self, r: RobotState, it: Intent, on: Sequence[RobotState]) -> RobotCommand:
        """Plain steering toward ``it`` at our robots' limits (slow enough to stop on the target at
        ``brake_share`` of the braking limit), kept off the other robots."""
        p = self.p
        stop = math.sqrt(2.0 * p.brake_share * p.max_brake_m_s2 * math.hypot(it.x - r.x, it.y - r.y))
        cap = min(stop + it.final_speed_m_s, it.max_speed_m_s if it.max_speed_m_s is not None else math.inf,
                  p.max_speed_m_s * _UNDER_LIMIT)
        cmd = steer(self.team, r.id, r.x, r.y, r.theta, replace(it, max_speed_m_s=cap), p)
        others = [o for o in on if not (o.team == self.team and o.id == r.id)]
        return keep_off_robots(cmd, r, others, self.sp.robot_radius_m, p)

    def _double_touch_bar(self, game: GameState, own: Sequence[RobotState], opp: Sequence[RobotState],
                          ball: BallState) -> int | None:
        """The robot that may not touch the ball now: its restart's kicker, from the normal start
        after the restart until another robot comes within touching reach of the ball."""
        barred = self._barred
        if game.command == RefereeCommand.NORMAL and self._taker is not None:
            barred = self._taker
        if barred is None or game.command != RefereeCommand.NORMAL:
            return None
        reach = self.sp.robot_radius_m + self.sp.ball_radius_m + self.sp.touched_m
        others = [r for r in (*own, *opp) if not (r.team == self.team and r.id == barred)]
        if any(math.hypot(r.x - ball.x, r.y - ball.y) < reach for r in others):
            return None
        return barred

    def _normal(self, own: Mapping[int, RobotState], goalie_id: int | None, opp: Sequence[RobotState], ball: BallState,
                own_sign: float, set_piece: bool, mark_gap_m: float | None) -> tuple[dict[int, Intent], int | None]:
        """Normal play: every robot's intent and the attacker's id (``set_piece``: its kick is a
        restart's; ``mark_gap_m``: the markers' gap, default ``mark_gap_m``)."""
        p, sp, f = self.p, self.sp, self.field
        radius = sp.robot_radius_m
        marks = {Role(RoleKind.MARKER, r.id): mark_point(r, ball, f, radius, p, mark_gap_m)
                 for r in threats(opp, ball, f, own_sign, p)}
        block = block_point(ball, f, own_sign, radius, p)
        meet = {rid: intercept(r, ball, sp.skills, f) for rid, r in own.items()}
        costs = {rid: math.hypot(m.x - own[rid].x, m.y - own[rid].y) for rid, m in meet.items()}
        if self._barred in costs:  # its restart's kicker plays the ball again only when nobody else can
            costs[self._barred] = math.inf
        field_players = len(own) - (goalie_id is not None)
        n_blockers = min(p.blockers, max(field_players - 1, 0))
        n_markers = min(len(marks), max(field_players - 1 - n_blockers, 0))
        n_defenders = max(field_players - 1 - n_blockers - n_markers, 0)  # the rest
        slots = defender_slots(DefenseParams(defenders=n_defenders,
                                             defender_spacing_m=sp.defense.defender_spacing_m)) if n_defenders else []
        defenders = {Role(RoleKind.DEFENDER, k): defend(ball, f, own_sign, s, sp.skills) for k, s in enumerate(slots)}
        keeps = goalie_id is not None
        objectives = [Objective(GOALIE, own_sign * f.half_length, 0.0, fixed_robot=goalie_id)] if keeps else []
        objectives.append(Objective(ATTACKER, ball.x, ball.y, costs=costs))
        objectives += [Objective(Role(RoleKind.BLOCKER, k), block.x, block.y) for k in range(n_blockers)]
        objectives += [Objective(role, it.x, it.y) for role, it in list(marks.items())[:n_markers]]
        objectives += [Objective(role, it.x, it.y) for role, it in defenders.items()]
        roles = self.roles.assign({rid: (r.x, r.y) for rid, r in own.items()}, objectives)
        out: dict[int, Intent] = {}
        attacker = None
        for rid, r in own.items():
            role = roles.get(rid)
            if role == GOALIE:
                out[rid], _ = goalie(r, ball, f, own_sign, sp.defense, sp.skills)
            elif role == ATTACKER:
                attacker = rid
                out[rid] = self._attack(r, meet[rid], opp, own_sign, set_piece)
            elif role is not None and role.kind is RoleKind.BLOCKER:
                out[rid] = block
            elif role is not None and role.kind is RoleKind.MARKER:
                out[rid] = marks[role]
            elif role is not None and role.kind is RoleKind.DEFENDER:
                out[rid] = defenders[role]
        barred = self._barred
        if barred is not None and barred in out and barred != attacker:  # it must not meet the ball it kicked
            out[barred] = off_ball_line(own[barred], replace(out[barred], kick_speed=0.0), ball, f, radius,
                                        sp.barred_near_m, sp.barred_clear_m, sp.barred_rolling_m_s)
        return out, attacker

    def _attack(self, robot: RobotState, meet: BallState, opp: Sequence[RobotState], own_sign: float,
                set_piece: bool) -> Intent:
        """The attacker: a shot at the widest gap of the goal mouth from within ``shot_range_m``, else
        the ball along the most open lane toward the goal; a ball in either defense area waited for
        outside it; a restart's kick lined up first."""
        p, sp, f = self.p, self.sp, self.field
        radius = sp.robot_radius_m
        if f.in_defense_area(meet.x, meet.y, radius):
            x, y = _legal(meet.x, meet.y, f, radius, p)
            return Intent(x, y, math.atan2(meet.y - y, meet.x - x))
        attack = -own_sign
        goal = (attack * f.half_length, 0.0)
        at = np.array([meet.x, meet.y])
        others = np.array([[r.x, r.y] for r in opp]).reshape(-1, 2)
        target: tuple[float, float]
        open_rad, aim, _ = best_shot(at, f, attack, others, sp.obstacle_radius_m, sp.passing)
        if open_rad >= p.shot_min_open_rad and math.hypot(goal[0] - meet.x, goal[1] - meet.y) <= p.shot_range_m:
            target, speed = aim, p.shot_speed_m_s
        else:
            kp = sp.kicking
            toward = math.atan2(goal[1] - meet.y, goal[0] - meet.x)
            angle, _ = clearest_direction(at, toward, others, sp.obstacle_radius_m, kp.clear_reach_m,
                                          kp.clear_spread_rad, kp.clear_samples, kp.clear_lane_cap_rad,
                                          kp.clear_turn_cost)
            target = (meet.x + p.advance_m * math.cos(angle), meet.y + p.advance_m * math.sin(angle))
            lim_x, lim_y = f.half_length - p.advance_margin_m, f.half_width - p.advance_margin_m
            target = (min(max(target[0], -lim_x), lim_x), min(max(target[1], -lim_y), lim_y))
            speed = pass_speed(math.hypot(target[0] - meet.x, target[1] - meet.y), sp.skills, p.advance_arrival_m_s)
        if set_piece:
            return set_kick(robot, meet, target, speed, sp.skills)
        return kick_to(robot, meet, target, speed, sp.skills)

    def _penalty(self, intents: dict[int, Intent], own: list[RobotState], goalie_id: int | None,
                 opp: Sequence[RobotState], ball: BallState, game: GameState, ours: bool,
                 own_sign: float) -> dict[int, Intent]:
        """A penalty: its taker plays it from the normal start, everyone else behind the ball;
        theirs, its keeper on the line until the normal start, then out at the ball once it is in
        play."""
        f, sp, gs = self.field, self.sp, self.sp.game_states
        if ours:
            attack = -own_sign
            players = [r for r in own if r.id != goalie_id] or own
            taker = min(players, key=lambda r: math.hypot(r.x - ball.x, r.y - ball.y))
            their_keeper = min(opp, key=lambda r: abs(r.x - attack * f.half_length) + abs(r.y), default=None)
            out = behind_ball({k: v for k, v in intents.items() if k != taker.id}, ball, attack, f, gs,
                              sp.robot_radius_m)
            out[taker.id] = penalty_shot(taker, ball, attack, their_keeper, f, sp.skills, gs, game.ready)
            return out
        out = behind_ball({k: v for k, v in intents.items() if k != goalie_id}, ball, own_sign, f, gs,
                          sp.robot_radius_m)
        keeper = next((r for r in own if r.id == goalie_id), None)
        if keeper is None:
            return out
        if not game.ready:
            out[keeper.id] = keeper_on_line(ball, f, own_sign, sp.skills, gs)
        else:
            rush = penalty_rush(keeper, ball, game.placement, f, own_sign, sp.skills, sp.defense, gs)
            out[keeper.id] = intents[keeper.id] if rush is None else rush
        return out
