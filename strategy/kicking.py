"""The attacker's kick: what to do with the ball (Bruce 2006, B.5), and how to play it.

The decision: shoot when the open goal angle is good; else keep a pass already decided while it
stays worth ``keep_pass_share`` of ``pass_value``; else pass to the best supporter when the pass
evaluation there is good (with a one-touch shot when that point sees the goal well, B.6); else
play the ball forward through the most open lane, a shot when that lane is the goal's.

The play: a ball coming at the attacker is met on its path (redirected one-touch when the turn
allows, else trapped); a contested slow ball (an opponent at it too, ours on the wrong side) is
kicked from the attacker's side, and driven through after ``stall_s`` lying still; otherwise the
attacker lines up behind the ball and kicks it. Field frame, metres, seconds, radians.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from cmdragons.geometry import Field, wrap_angle
from cmdragons.messages import BallState, KickPurpose, RobotState
from strategy.evaluation import PassParams, best_shot, clearest_direction, one_touch_turn, pass_values
from strategy.passing import PassPlay
from strategy.skills import Intent, SkillParams, drive_through, intercept, kick_to, pass_speed, receive, set_kick

__all__ = ["Attacker", "Kick", "KickPurpose", "KickParams", "StillBall", "contest_angle", "decide_kick"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class KickParams(Validated):
    shoot_value: float = setting(0.15, lo=0.0, hi=1.0)  # shot evaluation worth shooting at
    pass_value: float = setting(0.05, lo=0.0, hi=1.0)  # pass evaluation worth passing at
    one_touch_value: float = setting(0.1, lo=0.0, hi=1.0)  # shot value at the receiving point for a one-touch
    keep_pass_share: float = setting(0.5, lo=0.0, hi=1.0)  # a decided pass is kept while worth this share of pass_value
    max_back_pass_m: float = setting(0.5, lo=0.0, hi=20.0)  # passes go at most this far back toward our goal
    clear_speed_m_s: float = setting(3.0, lo=0.1, hi=10.0)  # the ball played forward when nothing is good
    clear_reach_m: float = setting(1.5, lo=0.1, hi=10.0)  # the lane checked for it, and its target this far out
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
    stall_s: float = setting(2.0, lo=0.0, hi=60.0)  # a contested ball that lay still this long is driven through
    stall_moved_m: float = setting(0.05, lo=0.0, hi=1.0)  # ... lying still: within this of where it was
    area_margin_m: float = setting(0.05, lo=0.0, hi=1.0)  # a ball met this near their defense area is left alone ...
    area_wait_m: float = setting(0.15, lo=0.0, hi=2.0)  # ... the attacker waiting by it, its edge this far off the area


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
    target = (ball.x + p.clear_reach_m * math.cos(angle), ball.y + p.clear_reach_m * math.sin(angle))
    if (ball.x * attack_sign) > 0 and abs(angle - toward) < p.shot_lane_rad:
        return Kick(KickPurpose.SHOT, target, skills.max_kick_m_s)
    return Kick(KickPurpose.CLEAR, target, p.clear_speed_m_s)


def contest_angle(robot: RobotState, ball: BallState, target: tuple[float, float], opponents: Array,
                  p: KickParams) -> float | None:
    """The kick direction nearest the aim that needs at most ``contest_turn_rad`` of way around the
    ball, when the ball is slow, the attacker at it and an opponent too; None otherwise."""
    if math.hypot(ball.vx, ball.vy) > p.contest_ball_speed_m_s or len(opponents) == 0:
        return None
    if math.hypot(robot.x - ball.x, robot.y - ball.y) > p.contest_m:
        return None
    if float(np.min(np.hypot(opponents[:, 0] - ball.x, opponents[:, 1] - ball.y))) > p.contest_m:
        return None
    approach = math.atan2(ball.y - robot.y, ball.x - robot.x)
    off = wrap_angle(math.atan2(target[1] - ball.y, target[0] - ball.x) - approach)
    if abs(off) <= p.contest_turn_rad:
        return None
    return approach + math.copysign(p.contest_turn_rad, off)


class Attacker:
    """The robot playing the ball, frame by frame: its kick decided and played. Keeps how long the
    ball lies still; plans and cancels the team's pass."""

    def __init__(self, pitch: Field, params: KickParams, passing: PassParams, skills: SkillParams,
                 radius: float) -> None:
        self.field, self.p, self.passing, self.skills = pitch, params, passing, skills
        self.radius = radius  # a robot's plus the ball's: whether the ball gets past
        self.still = StillBall(params.stall_moved_m)

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
        if self.field.in_defense_area(met.x, met.y, p.area_margin_m) == int(attack_sign):
            # the rules: an attacker touching the ball in their defense area is a foul; their keeper plays it
            passes.cancel()
            x, y = self.field.free_kick_spot(met.x, met.y, skills.robot_radius_m + p.area_wait_m)
            return Intent(x, y, math.atan2(ball.y - y, ball.x - x)), KickPurpose.WAIT
        kick = decide_kick(met, robot.id, own, supporters, passes, opponents, self.field, attack_sign, self.radius, p,
                           self.passing, skills)
        if kick.kind is KickPurpose.PASS and kick.receiver is not None:
            passes.plan(t, robot.id, kick.receiver, kick.target, kick.shoot_at)
        else:
            passes.cancel()
        if restart:
            return set_kick(robot, met, kick.target, kick.speed, skills), kick.kind
        speed = math.hypot(ball.vx, ball.vy)
        to_robot = math.hypot(robot.x - ball.x, robot.y - ball.y)
        toward = ((robot.x - ball.x) * ball.vx + (robot.y - ball.y) * ball.vy) / max(speed * to_robot, 1e-9)
        if speed > p.meet_speed_m_s and toward > p.meet_cos:
            # the ball comes at the attacker: meet it on its path, redirecting it at the target when the
            # turn allows a one-touch kick, else stopping it with the dribbler
            turn = float(one_touch_turn(np.array([ball.x, ball.y]), np.array([[met.x, met.y]]),
                                        np.array([kick.target]))[0])
            if turn <= self.passing.max_turn_rad:
                return receive(robot, ball, (met.x, met.y), skills, kick.target, kick.speed), kick.kind
            return receive(robot, ball, (met.x, met.y), skills), kick.kind
        contest = contest_angle(robot, met, kick.target, opponents, p)
        if contest is not None:
            # an opponent at the ball and ours on the wrong side of it: going around would leave the ball to
            # the opponent, so the ball is played from the side the attacker is on, as near the aim as it can
            passes.cancel()
            if t - self.still.since > p.stall_s:
                # lining up got nowhere (the point behind the ball is taken): drive through it from here
                return drive_through(met, contest, p.clear_speed_m_s, skills), KickPurpose.CLEAR
            target = (met.x + p.clear_reach_m * math.cos(contest), met.y + p.clear_reach_m * math.sin(contest))
            return kick_to(robot, met, target, p.clear_speed_m_s, skills), KickPurpose.CLEAR
        return kick_to(robot, met, kick.target, kick.speed, skills), kick.kind
