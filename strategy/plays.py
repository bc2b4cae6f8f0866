"""The team's play: game state and roles -> one :class:`~strategy.skills.Intent` per robot.

Roles in priority order (Bruce 2006, B.5): goalie, attacker (at the ball), defenders on the edge of
our defense area, supporters at the best receiving points of the pass evaluation, spread apart.
The attacker shoots when the open goal angle is good, passes to the best supporter when the pass
evaluation there is good, and otherwise shoots or clears forward. A supporter a pass is played to
meets the ball, with a one-touch shot when its point sees the goal well (B.6).

Game states: kickoff and free kick (ours: the attacker takes it; theirs: keep away), stop (every
robot at least ``stop_distance_m`` from the ball and slow), halt, normal play.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, Team
from cmdragons.messages import BallState, GameState, RobotState, WorldState
from strategy.evaluation import (
    PassEvaluation,
    PassParams,
    best_shot,
    candidate_grid,
    clearest_direction,
    one_touch_turn,
    pass_values,
)
from strategy.roles import Objective, RoleAssigner, RoleParams
from strategy.skills import (
    Intent,
    SkillParams,
    defend,
    drive_through,
    goalie_block,
    intercept,
    kick_to,
    mark,
    pass_speed,
    receive,
)

__all__ = ["Strategy", "StrategyParams", "keep_away"]


@dataclass(frozen=True)
class StrategyParams(Validated):
    """configs/strategy.yaml."""

    skills: SkillParams = SkillParams()
    passing: PassParams = PassParams()
    roles: RoleParams = RoleParams()
    defenders: int = setting(2, lo=0, hi=10)
    defender_spacing_m: float = setting(0.32, lo=0.0, hi=3.0)  # centre to centre: room to be pushed without touching
    shoot_value: float = setting(0.15, lo=0.0, hi=1.0)  # shot evaluation worth shooting at
    pass_value: float = setting(0.05, lo=0.0, hi=1.0)  # pass evaluation worth passing at
    one_touch_value: float = setting(0.1, lo=0.0, hi=1.0)  # shot value at the receiving point for a one-touch
    pass_timeout_s: float = setting(3.0, lo=0.1, hi=30.0)  # a pass not received by then is over
    pass_eval_every_frames: int = setting(6, lo=1, hi=600)  # the pass grid is re-evaluated this often
    supporter_spacing_m: float = setting(1.2, lo=0.0, hi=10.0)  # supporters' points at least this far apart
    supporter_min_ball_distance_m: float = setting(1.0, lo=0.0, hi=10.0)
    stop_distance_m: float = setting(0.65, lo=0.5, hi=3.0)  # rule: 0.5 m from the ball in a stop, plus margin
    stop_speed_m_s: float = setting(1.2, lo=0.1, hi=5.0)  # rule: 1.5 m/s in a stop, minus margin
    center_circle_margin_m: float = setting(0.15, lo=0.0, hi=2.0)  # kept outside the centre circle at their kickoff
    ball_room_m: float = setting(0.35, lo=0.0, hi=3.0)  # team-mates leave the ball handler this much room
    max_back_pass_m: float = setting(0.5, lo=0.0, hi=20.0)  # passes go at most this far back toward our goal
    meet_speed_m_s: float = setting(0.8, lo=0.0, hi=10.0)  # a ball this fast coming at the attacker is met on its path
    meet_cos: float = setting(0.7, lo=-1.0, hi=1.0)  # ... when its direction is this close to the attacker's
    clear_speed_m_s: float = setting(3.0, lo=0.1, hi=10.0)  # the ball played forward when nothing is good
    contest_m: float = setting(0.3, lo=0.0, hi=3.0)  # attacker and an opponent this near a slow ball: it is contested
    contest_ball_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # ... slower than this
    contest_turn_rad: float = setting(0.6, lo=0.0, hi=3.2)  # a contested ball is kicked at most this far off
    stall_s: float = setting(2.0, lo=0.0, hi=60.0)  # a contested ball that lay still this long is driven through
    stall_moved_m: float = setting(0.05, lo=0.0, hi=1.0)  # ... lying still: within this of where it was
    keep_pass_share: float = setting(0.5, lo=0.0, hi=1.0)  # a decided pass is kept while worth this share of pass_value


@dataclass
class _Pass:
    passer: int
    receiver: int
    point: tuple[float, float]
    t_start: float
    kicked: bool = False
    shoot_at: tuple[float, float] | None = None


@dataclass
class _Kick:
    """The attacker's decided kick: what for, where to, how hard, and for a pass to whom."""

    robot: int
    kind: str  # "shot", "pass" or "clear"
    target: tuple[float, float]
    speed: float
    receiver: int | None = None
    shoot_at: tuple[float, float] | None = None


@dataclass
class _Memory:
    frame: int = 0
    evaluation: PassEvaluation | None = None
    support_points: list[tuple[float, float]] = field(default_factory=list)
    passing: _Pass | None = None
    ball_still_at: tuple[float, float] = (math.inf, math.inf)  # where the ball lies still ...
    ball_still_since: float = math.inf  # ... since when


class Strategy:
    """One team's decisions, frame by frame."""

    def __init__(self, team: Team, pitch: Field, params: StrategyParams) -> None:
        self.team, self.field, self.p = team, pitch, params
        self.roles = RoleAssigner(params.roles)
        self.grid = candidate_grid(pitch, params.passing)
        self.mem = _Memory()
        self.last_action: dict[int, str] = {}  # robot id -> "shot", "pass" or "clear": what its kick is for
        self.obstacle_radius = params.skills.robot_radius_m + params.skills.ball_radius_m

    # --- geometry of our side -----------------------------------------------------------------
    def own_sign(self, game: GameState) -> float:
        blue_neg = game.blue_defends_negative_x
        return -1.0 if (self.team == "blue") == blue_neg else 1.0

    @property
    def pass_heat(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """The pass evaluation's last grid: receiving points (n, 2) and their values (n,), or None."""
        ev = self.mem.evaluation
        return None if ev is None else (ev.points, ev.values)

    def decide(self, world: WorldState, game: GameState) -> dict[int, Intent]:
        """An intent for each of our robots in ``world``."""
        self.mem.frame += 1
        own = {r.id: r for r in world.robots if r.team == self.team}
        opp = [r for r in world.robots if r.team != self.team]
        if not own:
            return {}
        own_sign = self.own_sign(game)
        ball = world.ball
        if game.command == "halt":
            return {rid: Intent(r.x, r.y, r.theta, max_speed_m_s=0.0) for rid, r in own.items()}
        if ball is None:
            return self._hold(own, own_sign)
        intents = self._normal(world.t, own, opp, ball, own_sign, game)
        ours = game.for_team == self.team
        if game.command == "stop" or (game.command in ("kickoff", "free_kick") and not ours):
            intents = keep_away(intents, ball, self.field, own_sign, self.p, game.command == "kickoff",
                                game.command == "stop")
        if game.command == "kickoff" and ours:
            attacker = next((rid for rid, role in self.roles.roles.items() if role == "attacker"), None)
            intents = self._own_half(intents, own_sign, keep=attacker)
        return intents

    # --- normal play ----------------------------------------------------------------------------
    def _normal(self, t: float, own: dict[int, RobotState], opp: list[RobotState], ball: BallState,
                own_sign: float, game: GameState) -> dict[int, Intent]:  # fmt: skip
        p, f = self.p, self.field
        attack_sign = -own_sign
        opp_xy = np.array([[r.x, r.y] for r in opp]) if opp else np.zeros((0, 2))
        ball_xy = np.array([ball.x, ball.y])
        still = self.mem.ball_still_at
        if math.hypot(ball.x - still[0], ball.y - still[1]) > p.stall_moved_m:
            self.mem.ball_still_at, self.mem.ball_still_since = (ball.x, ball.y), t
        if self.mem.evaluation is None or self.mem.frame % p.pass_eval_every_frames == 0:
            self.mem.evaluation = pass_values(ball_xy, self.grid, f, attack_sign, opp_xy, self.obstacle_radius,
                                              p.passing)  # fmt: skip
            self.mem.support_points = self._spread_points(self.mem.evaluation, ball_xy, len(own))

        goalie_id = p.roles.goalie_id if p.roles.goalie_id in own else None
        goal_x = own_sign * f.half_length
        objectives = [Objective("goalie", goal_x, 0.0, fixed_robot=goalie_id)]
        passing = self._update_pass(t, own, ball)
        if passing is not None:
            # the receiver of a pass, planned or under way, waits at (or meets the ball near) its point
            objectives.append(Objective("receiver", *passing.point, fixed_robot=passing.receiver))
        if passing is None or not passing.kicked:
            # the attacker's cost: the way to where each robot can meet the (moving) ball
            meet = {rid: intercept(r, ball, p.skills, f) for rid, r in own.items()}
            costs = {rid: math.hypot(m.x - own[rid].x, m.y - own[rid].y) for rid, m in meet.items()}
            objectives.append(Objective("attacker", ball.x, ball.y, costs=costs))
        half_span = 0.5 * p.defender_spacing_m * (p.defenders - 1)
        slots = [0.0] if p.defenders == 1 else list(np.linspace(-half_span, half_span, p.defenders))
        defenders = {}
        for k, slot in enumerate(slots):
            intent = defend(ball, f, own_sign, float(slot), p.skills)
            defenders[f"defender{k}"] = intent
            objectives.append(Objective(f"defender{k}", intent.x, intent.y))
        for k, (x, y) in enumerate(self.mem.support_points):
            objectives.append(Objective(f"supporter{k}", x, y))
        roles = self.roles.assign({rid: (r.x, r.y) for rid, r in own.items()}, objectives)
        by_role = {role: rid for rid, role in roles.items()}

        out: dict[int, Intent] = {}
        for rid, role in roles.items():
            r = own[rid]
            if role == "goalie":
                out[rid] = self._goalie(r, ball, own_sign)
            elif role == "attacker":
                out[rid] = self._attack(t, r, own, opp_xy, ball, by_role, attack_sign)
            elif role == "receiver" and passing is not None and not passing.kicked:
                x, y = passing.point
                out[rid] = Intent(x, y, math.atan2(ball.y - y, ball.x - x))
            elif role == "receiver":
                assert passing is not None
                out[rid] = receive(r, ball, passing.point, p.skills, passing.shoot_at,
                                   p.skills.max_kick_m_s if passing.shoot_at else 0.0)  # fmt: skip
            elif role.startswith("defender"):
                out[rid] = defenders[role]
            else:
                k = int(role[len("supporter"):])
                x, y = self.mem.support_points[k]
                out[rid] = Intent(x, y, math.atan2(ball.y - y, ball.x - x))
        for rid, r in own.items():  # robots without a role (more robots than objectives): mark or hold
            if rid not in out:
                out[rid] = mark(opp[rid % len(opp)], f, own_sign, p.skills) if opp else Intent(r.x, r.y, r.theta)
        # everyone but the goalie and the robot playing the ball leaves it room
        others = {rid: it for rid, it in out.items() if roles.get(rid) not in ("goalie", "attacker", "receiver")}
        out.update(keep_away(others, ball, f, own_sign, p, kickoff=False, slow=False, distance_m=p.ball_room_m))
        return out

    def _goalie(self, r: RobotState, ball: BallState, own_sign: float) -> Intent:
        f = self.field
        inside = f.in_defense_area(ball.x, ball.y) == int(own_sign)
        if inside and math.hypot(ball.vx, ball.vy) < 0.5:
            # clear the ball out of our area toward the opponent half, away from the middle
            target = (-own_sign * f.half_length * 0.5, math.copysign(f.half_width * 0.6, ball.y or 1.0))
            intent = kick_to(r, ball, target, 4.0, self.p.skills)
            self.last_action[r.id] = "clear"
            return Intent(intent.x, intent.y, intent.theta, intent.kick_speed, intent.chip, intent.dribbler,
                          intent.avoid_ball, True, intent.max_speed_m_s, intent.final_speed_m_s)  # fmt: skip
        return goalie_block(ball, f, own_sign, self.p.skills)

    def _attack(self, t: float, r: RobotState, own: dict[int, RobotState], opp_xy: np.ndarray, ball: BallState,
                by_role: dict[str, int], attack_sign: float) -> Intent:  # fmt: skip
        """Play the ball where the attacker can meet it: shoot, pass or play it forward."""
        p = self.p
        met = intercept(r, ball, p.skills, self.field)
        kick = self._decide_kick(r, own, opp_xy, met, by_role, attack_sign)
        if kick.kind == "pass" and kick.receiver is not None:
            planned = self.mem.passing
            if planned is None or (planned.receiver, planned.passer) != (kick.receiver, r.id):
                self.mem.passing = _Pass(r.id, kick.receiver, kick.target, t, shoot_at=kick.shoot_at)
        else:
            self.mem.passing = None
        self.last_action[r.id] = kick.kind
        speed = math.hypot(ball.vx, ball.vy)
        to_robot = math.hypot(r.x - ball.x, r.y - ball.y)
        toward = ((r.x - ball.x) * ball.vx + (r.y - ball.y) * ball.vy) / max(speed * to_robot, 1e-9)
        if speed > p.meet_speed_m_s and toward > p.meet_cos:
            # the ball comes at the attacker: meet it on its path, redirecting it at the target when the
            # turn allows a one-touch kick, else stopping it with the dribbler
            turn = float(one_touch_turn(np.array([ball.x, ball.y]), np.array([[met.x, met.y]]),
                                        np.array([kick.target]))[0])  # fmt: skip
            if turn <= p.passing.max_turn_rad:
                return receive(r, ball, (met.x, met.y), p.skills, kick.target, kick.speed)
            return receive(r, ball, (met.x, met.y), p.skills)
        contest = self._contest_angle(r, met, kick.target, opp_xy)
        if contest is not None:
            # an opponent at the ball and ours on the wrong side of it: going around would leave the ball to
            # the opponent, so the ball is played from the side the attacker is on, as near the aim as it can
            self.mem.passing = None
            self.last_action[r.id] = "clear"
            if t - self.mem.ball_still_since > p.stall_s:
                # lining up got nowhere (the point behind the ball is taken): drive through it from here
                return drive_through(met, contest, p.clear_speed_m_s, p.skills)
            target = (met.x + 1.5 * math.cos(contest), met.y + 1.5 * math.sin(contest))
            return kick_to(r, met, target, p.clear_speed_m_s, p.skills)
        return kick_to(r, met, kick.target, kick.speed, p.skills)

    def _contest_angle(self, r: RobotState, ball: BallState, target: tuple[float, float],
                       opp_xy: np.ndarray) -> float | None:  # fmt: skip
        """The kick direction nearest the aim that needs at most ``contest_turn_rad`` of way around the
        ball, when the ball is slow, the attacker at it and an opponent too; None otherwise."""
        p = self.p
        if math.hypot(ball.vx, ball.vy) > p.contest_ball_speed_m_s or len(opp_xy) == 0:
            return None
        if math.hypot(r.x - ball.x, r.y - ball.y) > p.contest_m:
            return None
        if float(np.min(np.hypot(opp_xy[:, 0] - ball.x, opp_xy[:, 1] - ball.y))) > p.contest_m:
            return None
        approach = math.atan2(ball.y - r.y, ball.x - r.x)
        off = math.remainder(math.atan2(target[1] - ball.y, target[0] - ball.x) - approach, 2 * math.pi)
        if abs(off) <= p.contest_turn_rad:
            return None
        return approach + math.copysign(p.contest_turn_rad, off)

    def _decide_kick(self, r: RobotState, own: dict[int, RobotState], opp_xy: np.ndarray,
                     ball: BallState, by_role: dict[str, int], attack_sign: float) -> _Kick:  # fmt: skip
        """Shoot when the open goal angle is good, else pass to the best supporter when its pass is
        good, else play the ball forward through the most open lane."""
        p, f = self.p, self.field
        ball_xy = np.array([ball.x, ball.y])
        _, aim, shot_value = best_shot(ball_xy, f, attack_sign, opp_xy, self.obstacle_radius, p.passing)
        if shot_value >= p.shoot_value:
            return _Kick(r.id, "shot", aim, p.skills.max_kick_m_s)
        planned = self.mem.passing
        if planned is not None and not planned.kicked and planned.passer == r.id and planned.receiver in own:
            # a pass already decided goes to the point its receiver waits at while it stays worth playing
            pt = np.array([planned.point])
            ev = pass_values(ball_xy, pt, f, attack_sign, opp_xy, self.obstacle_radius, p.passing)
            if ev.values[0] >= p.keep_pass_share * p.pass_value:
                return self._pass_kick(r.id, ball, planned.point, planned.receiver, planned.shoot_at)
        receivers = [(role, rid) for role, rid in by_role.items() if role.startswith("supporter")
                     and (own[rid].x - ball.x) * attack_sign > -p.max_back_pass_m]  # fmt: skip
        if receivers:
            pts = np.array([[own[rid].x, own[rid].y] for _, rid in receivers])
            ev = pass_values(ball_xy, pts, f, attack_sign, opp_xy, self.obstacle_radius, p.passing)
            k = int(np.argmax(ev.values))
            if ev.values[k] >= p.pass_value:
                rid = receivers[k][1]
                point = (float(pts[k, 0]), float(pts[k, 1]))
                _, shot_aim, value_there = best_shot(pts[k], f, attack_sign, opp_xy, self.obstacle_radius, p.passing)
                turn = float(one_touch_turn(ball_xy, pts[k : k + 1], np.array([shot_aim]))[0])
                one_touch = value_there >= p.one_touch_value and turn <= p.passing.max_turn_rad
                return self._pass_kick(r.id, ball, point, rid, shot_aim if one_touch else None)
        # nothing good: play the ball forward through the most open lane (around a blocker)
        toward = math.atan2(aim[1] - ball.y, aim[0] - ball.x)
        angle, _ = clearest_direction(ball_xy, toward, opp_xy, self.obstacle_radius)
        target = (ball.x + 1.5 * math.cos(angle), ball.y + 1.5 * math.sin(angle))
        shooting = (ball.x * attack_sign) > 0 and abs(angle - toward) < 0.2
        if shooting:
            return _Kick(r.id, "shot", target, p.skills.max_kick_m_s)
        return _Kick(r.id, "clear", target, p.clear_speed_m_s)

    def _pass_kick(self, passer: int, ball: BallState, point: tuple[float, float], receiver: int,
                   shoot_at: tuple[float, float] | None) -> _Kick:  # fmt: skip
        """A pass to ``point``, as fast as it must be kicked to arrive there at the receiving speed."""
        dist = math.hypot(point[0] - ball.x, point[1] - ball.y)
        return _Kick(passer, "pass", point, pass_speed(dist, self.p.skills), receiver, shoot_at)

    def _update_pass(self, t: float, own: dict[int, RobotState], ball: BallState) -> _Pass | None:
        """Follow a pass: kicked once the ball runs toward the receiver; over when received, lost
        or timed out."""
        ps = self.mem.passing
        if ps is None:
            return None
        if ps.receiver not in own or t - ps.t_start > self.p.pass_timeout_s:
            self.mem.passing = None
            return None
        speed = math.hypot(ball.vx, ball.vy)
        to_point = (ps.point[0] - ball.x, ps.point[1] - ball.y)
        heading_there = speed > 0.5 and (ball.vx * to_point[0] + ball.vy * to_point[1]) > 0.8 * speed * math.hypot(
            *to_point)
        if not ps.kicked and heading_there:
            ps.kicked = True
            ps.t_start = t  # the timeout runs from the kick
        elif ps.kicked and (speed < 0.2 or not heading_there):
            receiver = own[ps.receiver]
            if math.hypot(receiver.x - ball.x, receiver.y - ball.y) < 0.3 or speed < 0.2:
                self.mem.passing = None  # received (or died): the new attacker takes over
                return None
        return ps

    def _spread_points(self, ev: PassEvaluation, ball: np.ndarray, n_robots: int) -> list[tuple[float, float]]:
        """The best receiving points, at least ``supporter_spacing_m`` apart and off the ball."""
        k = max(0, n_robots - 2 - self.p.defenders)
        order = np.argsort(-ev.values)
        chosen: list[tuple[float, float]] = []
        for i in order:
            if len(chosen) >= k:
                break
            x, y = float(ev.points[i, 0]), float(ev.points[i, 1])
            if math.hypot(x - ball[0], y - ball[1]) < self.p.supporter_min_ball_distance_m:
                continue
            if all(math.hypot(x - a, y - b) >= self.p.supporter_spacing_m for a, b in chosen):
                chosen.append((x, y))
        return chosen

    # --- game states ----------------------------------------------------------------------------
    def _own_half(self, intents: dict[int, Intent], own_sign: float, keep: int | None) -> dict[int, Intent]:
        """At our kickoff everyone but the kicker stays in our half, outside the centre circle."""
        out = {}
        r_c = self.field.dims.center_circle_radius_m + self.p.center_circle_margin_m + self.p.skills.robot_radius_m
        for rid, it in intents.items():
            if rid == keep:
                out[rid] = it
                continue
            x = own_sign * max(own_sign * it.x, self.p.skills.robot_radius_m + 0.05)
            y = it.y
            if math.hypot(x, y) < r_c:
                y = math.copysign(r_c, y if y != 0 else 1.0)
            out[rid] = Intent(x, y, it.theta, it.kick_speed, it.chip, it.dribbler, it.avoid_ball,
                              it.allow_own_defense, it.max_speed_m_s, it.final_speed_m_s)  # fmt: skip
        return out

    def _hold(self, own: dict[int, RobotState], own_sign: float) -> dict[int, Intent]:
        """No ball seen yet: hold a defensive shape in our half."""
        out = {}
        for k, rid in enumerate(sorted(own)):
            x = own_sign * (self.field.half_length * 0.3 + 0.4 * (k % 3))
            y = (k - len(own) / 2) * 0.6
            out[rid] = Intent(x, y, 0.0 if own_sign < 0 else math.pi)
        return out


def keep_away(intents: dict[int, Intent], ball: BallState, pitch: Field, own_sign: float, p: StrategyParams,
              kickoff: bool, slow: bool, distance_m: float | None = None) -> dict[int, Intent]:  # fmt: skip
    """Every target at least ``distance_m`` (default ``stop_distance_m``: the rules' 0.5 m plus a
    margin) from the ball; at their kickoff also in our half and outside the centre circle; slow in
    a stop."""
    out = {}
    radius = p.skills.robot_radius_m
    d_min = (p.stop_distance_m if distance_m is None else distance_m) + radius
    r_c = pitch.dims.center_circle_radius_m + p.center_circle_margin_m + radius
    for rid, it in intents.items():
        x, y = it.x, it.y
        if kickoff:
            x = own_sign * max(own_sign * x, radius + 0.05)
            if math.hypot(x, y) < r_c:
                ang = math.atan2(y, x) if math.hypot(x, y) > 1e-6 else (0.0 if own_sign > 0 else math.pi)
                x, y = r_c * math.cos(ang), r_c * math.sin(ang)
        dx, dy = x - ball.x, y - ball.y
        d = math.hypot(dx, dy)
        if d < d_min:
            if d < 1e-6:
                dx, dy, d = own_sign, 0.0, 1.0
            # the nearest point of the circle around the ball that lies on the field (where the cameras see us)
            lim_x, lim_y = pitch.half_length - radius, pitch.half_width - radius
            base = math.atan2(dy, dx)
            for turn in (0.0, *(sign * k * math.pi / 12 for k in range(1, 13) for sign in (1.0, -1.0))):
                x, y = ball.x + d_min * math.cos(base + turn), ball.y + d_min * math.sin(base + turn)
                if abs(x) <= lim_x and abs(y) <= lim_y:
                    break
        out[rid] = Intent(x, y, it.theta, dribbler=0.0, avoid_ball=True, allow_own_defense=it.allow_own_defense,
                          max_speed_m_s=p.stop_speed_m_s if slow else it.max_speed_m_s)  # fmt: skip
    return out
