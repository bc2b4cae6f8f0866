"""The attacker's kick: what to do with the ball (Bruce 2006, B.5), and how to play it.

The decision: shoot when the open goal angle is good; else keep a pass already decided while it
stays worth ``keep_pass_share`` of ``pass_value``; else pass to the best supporter when the pass
evaluation there is good (with a one-touch shot when that point sees the goal well, B.6); else
play the ball forward through the most open lane, a shot when that lane is the goal's: near our
goal hard, elsewhere only as far as the lane was checked (the ball stays in play, ours to follow).

The play: a ball coming at the attacker is met on its path (redirected one-touch when the turn
allows, else trapped); a ball held on the kicker face is turned with toward the aim and kicked; a
contested slow ball (an opponent at it too, ours on the wrong side or the kicking position taken by
the opponent) is kicked from the attacker's side, and driven through after ``stall_s`` lying still;
otherwise the attacker lines up behind the ball and kicks it. Driving through a slow ball, the kick
is kept for ``commit_s``, and a ball rolling away is closed in on at the push speed relative to it.
Field frame, metres, seconds, radians.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, wrap_angle
from cmdragons.messages import BallState, KickPurpose, RobotState
from strategy.evaluation import PassParams, best_shot, clearest_direction, one_touch_turn, pass_values
from strategy.passing import PassPlay
from strategy.skills import (
    Intent,
    SkillParams,
    drive_through,
    intercept,
    kick_to,
    pass_speed,
    receive,
    set_kick,
    turn_with_ball,
)

__all__ = ["Attacker", "Kick", "KickPurpose", "KickParams", "StillBall", "chase", "contest_angle", "decide_kick",
           "forward_kick", "kick_blocked"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class KickParams(Validated):
    shoot_value: float = setting(0.15, lo=0.0, hi=1.0)  # shot evaluation worth shooting at
    pass_value: float = setting(0.05, lo=0.0, hi=1.0)  # pass evaluation worth passing at
    one_touch_value: float = setting(0.1, lo=0.0, hi=1.0)  # shot value at the receiving point for a one-touch
    keep_pass_share: float = setting(0.5, lo=0.0, hi=1.0)  # a decided pass is kept while worth this share of pass_value
    max_back_pass_m: float = setting(0.5, lo=0.0, hi=20.0)  # passes go at most this far back toward our goal
    clear_speed_m_s: float = setting(3.0, lo=0.1, hi=10.0)  # nothing good, near our goal: the ball cleared
    clear_reach_m: float = setting(1.5, lo=0.1, hi=10.0)  # the lane checked for it, and its target this far out
    clear_zone_m: float = setting(2.0, lo=0.0, hi=20.0)  # ... near our goal: the ball this near our goal line (x)
    advance_arrival_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # elsewhere it arrives at the target this fast ...
    advance_margin_m: float = setting(0.4, lo=0.0, hi=3.0)  # ... the target this far inside the field lines
    clear_spread_rad: float = setting(1.5707963267948966, lo=0.0, hi=3.2)  # lanes within this of the goal's
    clear_samples: int = setting(13, lo=1, hi=361)  # ... so many of them, evenly spread
    clear_lane_cap_rad: float = setting(0.6, lo=0.01, hi=3.0)  # a lane this open on each side counts as fully open
    clear_turn_cost: float = setting(0.05, lo=0.0, hi=10.0)  # open angle given up per radian off the goal's lane
    shot_lane_rad: float = setting(0.2, lo=0.0, hi=3.2)  # a clear in their half this near the goal's lane: a shot
    meet_speed_m_s: float = setting(0.8, lo=0.0, hi=10.0)  # a ball this fast coming at the attacker is met on its path
    meet_cos: float = setting(0.7, lo=-1.0, hi=1.0)  # ... when its direction is this close to the attacker's
    contest_m: float = setting(0.3, lo=0.0, hi=3.0)  # attacker and an opponent this near a slow ball: it is contested
    contest_ball_speed_m_s: float = setting(0.5, lo=0.0, hi=10.0)  # ... slower than this
    contest_turn_rad: float = setting(0.6, lo=0.0, hi=3.2)  # a contested ball is kicked at most this far off
    contest_samples: int = setting(13, lo=2, hi=361)  # ... among so many directions, evenly spread
    contest_gap_m: float = setting(0.02, lo=0.0, hi=0.5)  # a kicking position this near an opponent's body is taken
    stall_s: float = setting(2.0, lo=0.0, hi=60.0)  # a contested ball that lay still this long is driven through
    commit_s: float = setting(0.5, lo=0.0, hi=5.0)  # driving through a slow ball: the kick kept this long
    stall_moved_m: float = setting(0.05, lo=0.0, hi=1.0)  # ... lying still: within this of where it was
    area_margin_m: float = setting(0.05, lo=0.0, hi=1.0)  # a ball met this near their defense area is left alone ...
    area_wait_m: float = setting(0.15, lo=0.0, hi=2.0)  # ... the attacker waiting by it, its edge this far off the area
    area_still_m: float = setting(0.02, lo=0.0, hi=1.0)  # ... unless it lay still stall_s this far outside the area


@dataclass(frozen=True)
class Kick:
    """The attacker's decided kick: what for, where to, how hard, and for a pass to whom."""

    kind: KickPurpose
    target: tuple[float, float]
    speed: float
    receiver: int | None = None
    shoot_at: tuple[float, float] | None = None  # a pass's one-touch aim


class StillBall:
    """Since when the ball lies still (within ``stall_moved_m`` of where it came to lie)."""

    def __init__(self, moved_m: float) -> None:
        self.moved_m = moved_m
        self.at: tuple[float, float] = (math.inf, math.inf)
        self.since = math.inf

    def update(self, t: float, ball: BallState) -> None:
        if math.hypot(ball.x - self.at[0], ball.y - self.at[1]) > self.moved_m:
            self.at, self.since = (ball.x, ball.y), t


def _pass_kick(ball: BallState, point: tuple[float, float], receiver: int, shoot_at: tuple[float, float] | None,
               skills: SkillParams) -> Kick:
    """A pass to ``point``, as fast as it must be kicked to arrive there at the receiving speed."""
    dist = math.hypot(point[0] - ball.x, point[1] - ball.y)
    return Kick(KickPurpose.PASS, point, pass_speed(dist, skills), receiver, shoot_at)


def decide_kick(ball: BallState, passer: int, own: Mapping[int, RobotState], supporters: Sequence[int],
                passes: PassPlay, opponents: Array, pitch: Field, attack_sign: float, radius: float, p: KickParams,
                passing: PassParams, skills: SkillParams) -> Kick:
    """The kick of ``passer`` at ``ball`` (where it meets the ball): a shot, a pass to one of
    ``supporters`` (robot ids), or a clear. ``radius``: the opponents' plus the ball's."""
    ball_xy = np.array([ball.x, ball.y])
    _, aim, shot_value = best_shot(ball_xy, pitch, attack_sign, opponents, radius, passing)
    if shot_value >= p.shoot_value:
        return Kick(KickPurpose.SHOT, aim, skills.max_kick_m_s)
    planned = passes.planned_by(passer, own)
    if planned is not None:
        # a pass already decided goes to the point its receiver waits at while it stays worth playing
        pt = np.array([planned.point])
        ev = pass_values(ball_xy, pt, pitch, attack_sign, opponents, radius, passing)
        if ev.values[0] >= p.keep_pass_share * p.pass_value:
            return _pass_kick(ball, planned.point, planned.receiver, planned.shoot_at, skills)
    receivers = [rid for rid in supporters if (own[rid].x - ball.x) * attack_sign > -p.max_back_pass_m]
    if receivers:
        pts = np.array([[own[rid].x, own[rid].y] for rid in receivers])
        ev = pass_values(ball_xy, pts, pitch, attack_sign, opponents, radius, passing)
        k = int(np.argmax(ev.values))
        if ev.values[k] >= p.pass_value:
            point = (float(pts[k, 0]), float(pts[k, 1]))
            _, shot_aim, value_there = best_shot(pts[k], pitch, attack_sign, opponents, radius, passing)
            turn = float(one_touch_turn(ball_xy, pts[k : k + 1], np.array([shot_aim]))[0])
            one_touch = value_there >= p.one_touch_value and turn <= passing.max_turn_rad
            return _pass_kick(ball, point, receivers[k], shot_aim if one_touch else None, skills)
    # nothing good: play the ball forward through the most open lane (around a blocker)
    toward = math.atan2(aim[1] - ball.y, aim[0] - ball.x)
    angle, _ = clearest_direction(ball_xy, toward, opponents, radius, p.clear_reach_m, p.clear_spread_rad,
                                  p.clear_samples, p.clear_lane_cap_rad, p.clear_turn_cost)
    if (ball.x * attack_sign) > 0 and abs(angle - toward) < p.shot_lane_rad:
        target = (ball.x + p.clear_reach_m * math.cos(angle), ball.y + p.clear_reach_m * math.sin(angle))
        return Kick(KickPurpose.SHOT, target, skills.max_kick_m_s)
    return forward_kick(ball, angle, pitch, attack_sign, p, skills)


def forward_kick(ball: BallState, angle: float, pitch: Field, attack_sign: float, p: KickParams,
                 skills: SkillParams) -> Kick:
    """The ball played along ``angle`` (rad) when no shot or pass is good: near our goal (within
    ``clear_zone_m`` of our goal line) cleared hard, ``clear_reach_m`` out at ``clear_speed_m_s``;
    elsewhere only as far as its lane was checked, to arrive ``clear_reach_m`` out (kept
    ``advance_margin_m`` inside the field lines) at ``advance_arrival_m_s``: it stays in play,
    ours to play again (kicked hard it rolled some 8 m, mostly out of the field)."""
    target = (ball.x + p.clear_reach_m * math.cos(angle), ball.y + p.clear_reach_m * math.sin(angle))
    if pitch.half_length + ball.x * attack_sign < p.clear_zone_m:
        return Kick(KickPurpose.CLEAR, target, p.clear_speed_m_s)
    lim_x, lim_y = pitch.half_length - p.advance_margin_m, pitch.half_width - p.advance_margin_m
    target = (min(max(target[0], -lim_x), lim_x), min(max(target[1], -lim_y), lim_y))
    speed = pass_speed(math.hypot(target[0] - ball.x, target[1] - ball.y), skills, p.advance_arrival_m_s)
    return Kick(KickPurpose.CLEAR, target, speed)


def contest_angle(robot: RobotState, ball: BallState, target: tuple[float, float], opponents: Array,
                  p: KickParams, skills: SkillParams) -> float | None:
    """When the ball is slow, the attacker at it and an opponent too: the kick direction nearest the
    aim among those that need at most ``contest_turn_rad`` of way around the ball and whose kicking
    position is free (:func:`kick_blocked`); None when the aim itself is such a direction, or the
    ball is not contested. With no free direction, the one of the turn nearest the aim."""
    if math.hypot(ball.vx, ball.vy) > p.contest_ball_speed_m_s or len(opponents) == 0:
        return None
    if math.hypot(robot.x - ball.x, robot.y - ball.y) > p.contest_m:
        return None
    if float(np.min(np.hypot(opponents[:, 0] - ball.x, opponents[:, 1] - ball.y))) > p.contest_m:
        return None
    approach = math.atan2(ball.y - robot.y, ball.x - robot.x)
    aim = math.atan2(target[1] - ball.y, target[0] - ball.x)
    off = wrap_angle(aim - approach)
    if abs(off) <= p.contest_turn_rad and not kick_blocked(ball, aim, opponents, p, skills):
        return None
    turns = np.linspace(-p.contest_turn_rad, p.contest_turn_rad, p.contest_samples)
    free = [approach + float(a) for a in turns if not kick_blocked(ball, approach + float(a), opponents, p, skills)]
    if not free:
        return approach + math.copysign(min(abs(off), p.contest_turn_rad), off)
    return min(free, key=lambda a: abs(wrap_angle(a - aim)))


def kick_blocked(ball: BallState, aim: float, opponents: Array, p: KickParams, skills: SkillParams) -> bool:
    """Whether an opponent stands where our robot must be to kick ``ball`` along ``aim`` (rad): its
    centre within two robot radii plus ``contest_gap_m`` of our centre with the ball on our kicker
    face. (Beside a contested ball, the planner and the safety search keep the robot out of that
    position, and lining up for the kick got nowhere.)"""
    if len(opponents) == 0:
        return False
    x, y = ball.x - skills.contact_m * math.cos(aim), ball.y - skills.contact_m * math.sin(aim)
    near = float(np.min(np.hypot(opponents[:, 0] - x, opponents[:, 1] - y)))
    return near < 2.0 * skills.robot_radius_m + p.contest_gap_m


def chase(intent: Intent, ball: BallState) -> Intent:
    """Driving through a ball that rolls away along the aim: the approach speeds of ``intent`` raised
    by the ball's speed along it, so the robot closes in at the push speed relative to the ball
    (at the push speed over the ground it crept after a ball rolling away, and an opponent got
    there first). Other intents as they are."""
    if intent.avoid_ball or intent.kick_speed <= 0.0 or intent.final_speed_m_s <= 0.0:
        return intent  # not driving through the ball (lining up, receiving it on its path)
    along = ball.vx * math.cos(intent.theta) + ball.vy * math.sin(intent.theta)
    if along <= 0.0:
        return intent
    top = None if intent.max_speed_m_s is None else intent.max_speed_m_s + along
    return replace(intent, max_speed_m_s=top, final_speed_m_s=intent.final_speed_m_s + along)


@dataclass(frozen=True)
class Commitment:
    """A kick the attacker drives through a slow ball with: kept for ``commit_s`` from ``since``."""

    robot: int
    since: float
    aim: float  # rad
    kick: Kick


class Attacker:
    """The robot playing the ball, frame by frame: its kick decided and played. Keeps how long the
    ball lies still and the kick it drives through a slow ball with; plans and cancels the team's pass."""

    def __init__(self, pitch: Field, params: KickParams, passing: PassParams, skills: SkillParams,
                 radius: float) -> None:
        self.field, self.p, self.passing, self.skills = pitch, params, passing, skills
        self.radius = radius  # a robot's plus the ball's: whether the ball gets past
        self.still = StillBall(params.stall_moved_m)
        self.commitment: Commitment | None = None

    def watch(self, t: float, ball: BallState) -> None:
        """Every frame, before the play: where the ball lies still and since when."""
        self.still.update(t, ball)

    def play(self, t: float, robot: RobotState, own: Mapping[int, RobotState], supporters: Sequence[int],
             opponents: Array, ball: BallState, attack_sign: float,
             passes: PassPlay, restart: bool = False) -> tuple[Intent, KickPurpose]:
        """Play the ball where ``robot`` can meet it: shoot, pass (planned in ``passes``) or play it
        forward; ``restart``: our restart's kick, its only touch (:func:`~strategy.skills.set_kick`).
        Returns the intent and what the kick is for."""
        p, skills = self.p, self.skills
        met = intercept(robot, ball, skills, self.field)
        lying = t - self.still.since > p.stall_s and self.field.in_defense_area(met.x, met.y, p.area_still_m) == 0
        if self.field.in_defense_area(met.x, met.y, p.area_margin_m) == int(attack_sign) and not lying:
            # the rules: an attacker touching the ball in their defense area is a foul; their keeper plays it
            # (but not a ball that lies outside the area: one lying by its line is ours to play after stall_s)
            passes.cancel()
            x, y = self.field.free_kick_spot(met.x, met.y, skills.robot_radius_m + p.area_wait_m)
            return Intent(x, y, math.atan2(ball.y - y, ball.x - x)), KickPurpose.WAIT
        slow = math.hypot(met.vx, met.vy) <= p.contest_ball_speed_m_s
        kept = self.commitment
        if (kept is not None and kept.robot == robot.id and t - kept.since <= p.commit_s and slow and not restart
                and math.hypot(robot.x - met.x, robot.y - met.y) <= p.contest_m):
            # driving through the ball already: the kick is kept (re-deciding frame by frame turned the aim
            # between passes, clears and contest angles, and the robot backed off to line up anew each time)
            self._plan(t, robot.id, kept.kick, passes)
            return chase(drive_through(robot, met, kept.aim, kept.kick.speed, skills), met), kept.kick.kind
        intent, kind, kick = self._play(t, robot, own, supporters, opponents, met, ball, attack_sign, passes, restart)
        through = not intent.avoid_ball and intent.kick_speed > 0.0 and slow and not restart
        if not through:
            self.commitment = None
        elif kept is None or kept.robot != robot.id or t - kept.since > p.commit_s:
            # the ball's way, kept: the robot's heading is that less what its motion adds (skills.aiming)
            aim = math.atan2(kick.target[1] - met.y, kick.target[0] - met.x)
            self.commitment = Commitment(robot.id, t, aim, replace(kick, kind=kind, speed=intent.kick_speed))
        return (intent if restart else chase(intent, met)), kind

    @staticmethod
    def _plan(t: float, passer: int, kick: Kick, passes: PassPlay) -> None:
        if kick.kind is KickPurpose.PASS and kick.receiver is not None:
            passes.plan(t, passer, kick.receiver, kick.target, kick.shoot_at)
        else:
            passes.cancel()

    def _play(self, t: float, robot: RobotState, own: Mapping[int, RobotState], supporters: Sequence[int],
              opponents: Array, met: BallState, ball: BallState, attack_sign: float, passes: PassPlay,
              restart: bool) -> tuple[Intent, KickPurpose, Kick]:
        """The kick decided afresh and how it is played (:meth:`play`)."""
        p, skills = self.p, self.skills
        kick = decide_kick(met, robot.id, own, supporters, passes, opponents, self.field, attack_sign, self.radius, p,
                           self.passing, skills)
        self._plan(t, robot.id, kick, passes)
        if restart:
            return set_kick(robot, met, kick.target, kick.speed, skills), kick.kind, kick
        speed = math.hypot(ball.vx, ball.vy)
        to_robot = math.hypot(robot.x - ball.x, robot.y - ball.y)
        toward = ((robot.x - ball.x) * ball.vx + (robot.y - ball.y) * ball.vy) / max(speed * to_robot, 1e-9)
        if speed > p.meet_speed_m_s and toward > p.meet_cos:
            # the ball comes at the attacker: meet it on its path, redirecting it at the target when the
            # turn allows a one-touch kick, else stopping it with the dribbler
            turn = float(one_touch_turn(np.array([ball.x, ball.y]), np.array([[met.x, met.y]]),
                                        np.array([kick.target]))[0])
            if turn <= self.passing.max_turn_rad:
                return receive(robot, ball, (met.x, met.y), skills, kick.target, kick.speed), kick.kind, kick
            return receive(robot, ball, (met.x, met.y), skills), kick.kind, kick
        held = None if speed > p.contest_ball_speed_m_s else turn_with_ball(robot, met, kick.target, kick.speed, skills)
        if held is not None:
            # the ball on our kicker face (trapped, or taken): turned with toward the aim, then kicked
            return held, kick.kind, kick
        contest = contest_angle(robot, met, kick.target, opponents, p, skills)
        if contest is not None:
            # an opponent at the ball, and ours on the wrong side of it or the kicking position taken by the
            # opponent's body: going around would leave the ball to the opponent, so the ball is played from
            # the side the attacker is on, as near the aim as it can
            passes.cancel()
            away = forward_kick(met, contest, self.field, attack_sign, p, skills)
            if t - self.still.since > p.stall_s:
                # lining up got nowhere (the point behind the ball is taken): drive through it from here
                return drive_through(robot, met, contest, away.speed, skills), KickPurpose.CLEAR, away
            return kick_to(robot, met, away.target, away.speed, skills), KickPurpose.CLEAR, away
        return kick_to(robot, met, kick.target, kick.speed, skills), kick.kind, kick
