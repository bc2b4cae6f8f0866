"""The pass chosen as it will happen, against the simulator: an opponent beside the lane, driving
its best at the ball's way, cuts the pass the lane's open angle prefers, and the attacker passes to
the other supporter instead, whose ball gets there first; the pass record judges."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, Kick, KickPurpose, PassReport, RobotCommand, RobotState, TeamReport
from cmdragons.runtime.pass_record import PassEnd, PassRecord, PassRecorder
from sim.world import BallParams, DribblerParams, KickerParams, PhysicsParams, RobotParams, World
from strategy.ballmodel import interception_times
from strategy.evaluation import PassParams, pass_values
from strategy.kicking import KickParams, decide_kick, pass_kick_speed
from strategy.passing import PassPlay, PassPlayParams, PassRecordParams
from strategy.plays import StrategyParams
from strategy.skills import SkillParams, pass_speed

LEAGUE = LeagueParams()
FIELD = Field(LEAGUE)
FRONT = LEAGUE.robot.front_distance_m + LEAGUE.ball.radius_m
R = StrategyParams().obstacle_radius_m
K, PASS, SKILLS = KickParams(), PassParams(), SkillParams()
X0 = -2.0  # the ball at (X0, 0), in our half: no shot worth it
NEAR, FAR = (X0 + 2.5, 0.0), (X0 + 1.0, 1.8)  # the two supporters: straight ahead, and off to the left
ON = (X0 + 0.6, -0.18)  # an opponent beside the lane to NEAR, near the passer
BALL = BallState(X0, 0.0, 0.0, 0.0)


def scripted_pass(target: tuple[float, float], kick_m_s: float, opponent: tuple[float, float],
                  mate: tuple[float, float] | None = None) -> PassRecord:
    """Blue 0 behind the ball at (``X0``, 0) kicks at ``kick_m_s`` toward ``target`` (blue 1 waits
    there facing it, dribbler on); yellow 0, from ``opponent``, drives every frame at full speed at
    the point where it can first be in the ball's way (the ball's model run from the true state);
    the pass record of that pass. With ``mate``, blue 2 stands there."""
    w = World(LEAGUE, PhysicsParams(), RobotParams(), BallParams(), KickerParams(), DribblerParams(),
              robots_per_team={"blue": 3, "yellow": 1})
    aim = math.atan2(target[1], target[0] - X0)
    w.place_robot("blue", 0, X0 - (FRONT + 0.003) * math.cos(aim), -(FRONT + 0.003) * math.sin(aim), aim)
    w.place_robot("blue", 1, *target, aim + math.pi)
    w.place_robot("yellow", 0, *opponent, math.pi)
    w.place_robot("blue", 2, *(mate or (X0, -2.5)), 0.0)
    w.place_ball(X0, 0.0)
    recorder = PassRecorder("blue", FIELD, LEAGUE.robot, LEAGUE.ball.radius_m, SKILLS.ball_model, PassRecordParams(),
                            timeout_s=3.0)
    reach = SKILLS.robot_radius_m + SKILLS.ball_radius_m
    for n in range(240):
        gt = w.ground_truth()
        recorder.truth(gt)
        if recorder.records:
            break
        recorder.report(TeamReport("blue", n, gt.t, actions={0: KickPurpose.PASS},
                                   passing=PassReport(0, 1, target, kicked=n > 0)))
        opp = next(r for r in gt.robots if r.team == "yellow")
        _, where = interception_times(np.array([[opp.x, opp.y]]), np.array([[opp.vx, opp.vy]]), (gt.ball.x, gt.ball.y),
                                      (gt.ball.vx, gt.ball.vy), SKILLS.ball_model, SKILLS.limits,
                                      SKILLS.robot.command_latency_s, reach, 3.0, 0.02)
        dx, dy = where[0, 0] - opp.x, where[0, 1] - opp.y
        top = SKILLS.robot.max_speed_m_s / max(math.hypot(dx, dy), 1e-9)
        chase = RobotCommand("yellow", 0, vx=top * dx, vy=top * dy)
        commands = [RobotCommand("blue", 0, kick_speed=kick_m_s if n < 5 else 0.0),
                    RobotCommand("blue", 1, dribbler=1.0), chase]
        for e in w.step_frame(commands):
            if isinstance(e, Kick) and e.team == "blue":
                recorder.kick(e, KickPurpose.PASS, gt)
    assert len(recorder.records) == 1
    return recorder.records[0]


def _robot(rid: int, xy: tuple[float, float]) -> RobotState:
    return RobotState("blue", rid, xy[0], xy[1], math.pi)


def test_the_lane_prefers_a_pass_an_opponent_cuts_in_the_simulator() -> None:
    ev = pass_values(np.array([X0, 0.0]), np.array([NEAR, FAR]), FIELD, 1.0, np.array([ON]), R, PASS)
    assert ev.values[0] > ev.values[1] >= K.pass_value  # by the open angles, NEAR is the better pass
    assert pass_kick_speed(BALL, NEAR, _robot(1, NEAR), np.array([ON]), np.zeros((1, 2)), K, SKILLS) is None
    rec = scripted_pass(NEAR, pass_speed(NEAR[0] - X0, SKILLS), ON)  # as it was kicked before
    assert rec.end is PassEnd.INTERCEPTED and rec.by == 0
    assert rec.opponent_s is not None and rec.opponent_s <= K.pass_cut_s


def test_the_attacker_passes_where_the_ball_gets_first() -> None:
    own = {0: RobotState("blue", 0, X0 - FRONT, 0.0, 0.0), 1: _robot(1, NEAR), 2: _robot(2, FAR)}
    kick = decide_kick(BALL, 0, own, [1, 2], PassPlay(PassPlayParams()), np.array([ON]), np.zeros((1, 2)), FIELD, 1.0,
                       R, K, PASS, SKILLS)
    assert kick.kind is KickPurpose.PASS and kick.receiver == 2 and kick.target == FAR
    rec = scripted_pass(FAR, kick.speed, ON)
    # the receiver has the ball first (the opponent, chasing on, may tackle it after), at the time the ball's
    # model said and at a speed a receiver controls
    assert rec.by == 1 and rec.end in (PassEnd.RECEIVED, PassEnd.TOO_FAST)
    assert rec.ball_s is not None and rec.ball_model_s == pytest.approx(rec.ball_s, abs=2.0 / 60.0)
    assert rec.touch_speed_m_s is not None and rec.touch_speed_m_s <= K.pass_control_m_s


def test_a_team_mate_in_the_lane_is_not_passed_through() -> None:
    # a team-mate (blue 2) stands on the way to NEAR, the opponent far off: the pass goes to FAR; kicked to NEAR
    # as before, the ball meets the team-mate first
    mate, far_off = (X0 + 1.2, 0.05), (X0 + 1.0, -2.5)
    own = {0: RobotState("blue", 0, X0 - FRONT, 0.0, 0.0), 1: _robot(1, NEAR), 2: _robot(2, mate), 3: _robot(3, FAR)}
    ev = pass_values(np.array([X0, 0.0]), np.array([NEAR, FAR]), FIELD, 1.0, np.array([far_off]), R, PASS)
    assert ev.values[0] > ev.values[1] >= K.pass_value  # the open angles count opponents only
    kick = decide_kick(BALL, 0, own, [1, 3], PassPlay(PassPlayParams()), np.array([far_off]), np.zeros((1, 2)), FIELD,
                       1.0, R, K, PASS, SKILLS)
    assert kick.kind is KickPurpose.PASS and kick.receiver == 3
    rec = scripted_pass(NEAR, pass_speed(NEAR[0] - X0, SKILLS), far_off, mate=mate)
    assert rec.by == 2 and rec.end is not PassEnd.RECEIVED
