"""The attacker's kick decision and the contested ball, in constructed scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, RobotState
from strategy.evaluation import PassParams
from strategy.kicking import Attacker, Kick, KickParams, KickPurpose, StillBall, contest_angle, decide_kick
from strategy.passing import PassPlay, PassPlayParams
from strategy.plays import StrategyParams
from strategy.skills import SkillParams, pass_speed

FIELD = Field(LeagueParams())
R = StrategyParams().obstacle_radius_m
K, PASS, SKILLS = KickParams(), PassParams(), SkillParams()
NONE = np.zeros((0, 2))


def _robot(rid: int, x: float, y: float, theta: float = 0.0) -> RobotState:
    return RobotState("blue", rid, x, y, theta)


def _decide(ball: BallState, own: dict[int, RobotState], supporters: list[int], opponents: np.ndarray,
            passes: PassPlay | None = None) -> Kick:
    return decide_kick(ball, 1, own, supporters, passes or PassPlay(PassPlayParams()), opponents, FIELD, 1.0, R, K,
                       PASS, SKILLS)


def test_the_kinds_keep_the_match_statistics_names() -> None:
    assert [k.value for k in KickPurpose] == ["shot", "pass", "clear", "wait"]


def test_an_open_goal_near_by_is_shot_at_full_speed() -> None:
    ball = BallState(FIELD.half_length - 1.5, 0.0, 0.0, 0.0)
    kick = _decide(ball, {1: _robot(1, ball.x - 0.2, 0.0)}, [], NONE)
    assert kick.kind is KickPurpose.SHOT and kick.speed == SKILLS.max_kick_m_s
    assert kick.target[0] == FIELD.half_length and abs(kick.target[1]) < FIELD.goal_half_width


def test_a_free_supporter_gets_a_pass_at_the_speed_that_arrives() -> None:
    # far from their goal (no shot worth it), one supporter ahead with a free lane
    ball = BallState(-2.0, 0.0, 0.0, 0.0)
    own = {1: _robot(1, -2.2, 0.0), 3: _robot(3, 0.5, 1.0)}
    kick = _decide(ball, own, [3], np.array([[0.0, -2.5]]))
    assert kick.kind is KickPurpose.PASS and kick.receiver == 3 and kick.target == (0.5, 1.0)
    assert kick.speed == pytest.approx(pass_speed(math.hypot(2.5, 1.0), SKILLS))


def test_no_pass_far_back_and_no_supporter_means_a_clear() -> None:
    ball = BallState(-1.0, 0.0, 0.0, 0.0)
    own = {1: _robot(1, -1.2, 0.0), 3: _robot(3, -1.0 - K.max_back_pass_m - 0.5, 1.5)}  # behind the ball
    kick = _decide(ball, own, [3], NONE)
    assert kick.kind is KickPurpose.CLEAR and kick.speed == K.clear_speed_m_s
    assert math.hypot(kick.target[0] - ball.x, kick.target[1] - ball.y) == pytest.approx(K.clear_reach_m)
    assert kick.target[0] > ball.x  # forward, toward their goal


def test_a_decided_pass_is_kept_to_its_point() -> None:
    ball = BallState(-2.0, 0.0, 0.0, 0.0)
    own = {1: _robot(1, -2.2, 0.0), 3: _robot(3, 0.9, 1.4)}  # the receiver drifted from its point
    passes = PassPlay(PassPlayParams())
    passes.plan(0.0, passer=1, receiver=3, point=(0.5, 1.0), shoot_at=None)
    kick = _decide(ball, own, [3], np.array([[0.0, -2.5]]), passes)
    assert kick.kind is KickPurpose.PASS and kick.target == (0.5, 1.0)


@pytest.mark.parametrize(("ball_v", "opponent", "contested"), [
    ((0.0, 0.0), (1.8, 0.5), True),
    ((1.0, 0.0), (1.8, 0.5), False),  # the ball rolls: not contested
    ((0.0, 0.0), (1.0, 0.5), False),  # the opponent is not at the ball
])
def test_a_contested_ball_is_kicked_from_the_attackers_side(
    ball_v: tuple[float, float], opponent: tuple[float, float], contested: bool
) -> None:
    ball = BallState(2.0, 0.5, *ball_v)
    robot = _robot(1, 2.2, 0.5, math.pi)  # on the goal side of the ball: its way to the ball points at -x
    angle = contest_angle(robot, ball, (FIELD.half_length, 0.0), np.array([opponent]), K)
    if not contested:
        assert angle is None
        return
    assert angle is not None
    approach = math.pi
    assert abs(math.remainder(angle - approach, 2 * math.pi)) == pytest.approx(K.contest_turn_rad)


def test_an_aim_within_the_turn_is_not_contested() -> None:
    ball = BallState(2.0, 0.5, 0.0, 0.0)
    robot = _robot(1, 1.8, 0.5)  # behind the ball on the way to their goal
    assert contest_angle(robot, ball, (FIELD.half_length, 0.5), np.array([[2.2, 0.6]]), K) is None


def test_the_ball_lies_still_since_it_stopped_moving() -> None:
    still = StillBall(moved_m=0.05)
    still.update(0.0, BallState(0.0, 0.0, 0.0, 0.0))
    still.update(1.0, BallState(0.03, 0.0, 0.0, 0.0))  # within the tolerance
    assert still.since == 0.0
    still.update(2.0, BallState(0.2, 0.0, 0.0, 0.0))
    assert still.since == 2.0 and still.at == (0.2, 0.0)


def _attacker() -> Attacker:
    return Attacker(FIELD, K, PASS, SKILLS, R)


def test_a_ball_coming_at_the_attacker_is_met_on_its_path() -> None:
    attacker, passes = _attacker(), PassPlay(PassPlayParams())
    robot = _robot(1, 0.0, 0.0)
    ball = BallState(-2.0, 0.0, 2.5, 0.0)  # straight at the robot
    attacker.watch(0.0, ball)
    intent, kind = attacker.play(0.0, robot, {1: robot}, [], NONE, ball, 1.0, passes)
    assert not intent.avoid_ball  # the ball is met, not avoided
    assert abs(intent.y) < 1e-9 and -2.0 < intent.x <= 0.0  # on its path, between it and the robot
    assert kind in (KickPurpose.SHOT, KickPurpose.CLEAR)


def test_a_contested_ball_lying_still_is_driven_through_after_the_stall_time() -> None:
    attacker, passes = _attacker(), PassPlay(PassPlayParams())
    robot = _robot(1, 2.2, 0.5, math.pi)
    ball = BallState(2.0, 0.5, 0.0, 0.0)
    opponents = np.array([[1.8, 0.5]])
    attacker.watch(0.0, ball)
    before, kind = attacker.play(0.0, robot, {1: robot}, [], opponents, ball, 1.0, passes)
    assert kind is KickPurpose.CLEAR and before.avoid_ball  # lining up on its side, at the contest angle
    assert abs(math.remainder(before.theta - math.pi, 2 * math.pi)) == pytest.approx(K.contest_turn_rad)
    attacker.watch(K.stall_s + 0.1, ball)
    after, kind = attacker.play(K.stall_s + 0.1, robot, {1: robot}, [], opponents, ball, 1.0, passes)
    assert kind is KickPurpose.CLEAR
    assert after.kick_speed == K.clear_speed_m_s and not after.avoid_ball  # through the ball from its side
    assert abs(math.remainder(after.theta - math.pi, 2 * math.pi)) == pytest.approx(K.contest_turn_rad)
    assert passes.current is None


@pytest.mark.parametrize(("ball", "robot"), [
    (BallState(FIELD.half_length - 0.5, 0.3, 0.0, 0.0), (FIELD.half_length - 1.5, 0.3)),  # deep in their area
    (BallState(FIELD.half_length - FIELD.dims.defense_depth_m - 0.03, 0.5, 0.0, 0.0),  # just outside: the margin
     (FIELD.half_length - 1.6, 0.5)),
    (BallState(FIELD.half_length - 1.6, 0.2, 1.5, 0.0), (FIELD.half_length - 1.4, -0.8)),  # rolling into it
])
def test_a_ball_in_or_at_their_defense_area_is_left_to_them(ball: BallState, robot: tuple[float, float]) -> None:
    """The rules: an attacker touching the ball in the opponent's defense area is a foul. The attacker
    waits by the area, facing the ball, its edge ``area_wait_m`` off it."""
    attacker, passes = _attacker(), PassPlay(PassPlayParams())
    r = _robot(1, *robot)
    attacker.watch(0.0, ball)
    intent, kind = attacker.play(0.0, r, {1: r}, [], NONE, ball, 1.0, passes)
    assert kind is KickPurpose.WAIT and intent.avoid_ball and intent.kick_speed == 0.0
    assert FIELD.in_defense_area(intent.x, intent.y, SKILLS.robot_radius_m + K.area_wait_m - 1e-9) == 0
    assert FIELD.in_defense_area(intent.x, intent.y, SKILLS.robot_radius_m + K.area_wait_m + 0.01) == 1  # by it
    assert intent.theta == pytest.approx(math.atan2(ball.y - intent.y, ball.x - intent.x))
    assert passes.current is None


def test_a_ball_clear_of_their_defense_area_is_played() -> None:
    attacker, passes = _attacker(), PassPlay(PassPlayParams())
    ball = BallState(FIELD.half_length - FIELD.dims.defense_depth_m - K.area_margin_m - 0.02, 0.5, 0.0, 0.0)
    r = _robot(1, ball.x - 0.5, 0.5)
    attacker.watch(0.0, ball)
    intent, kind = attacker.play(0.0, r, {1: r}, [], NONE, ball, 1.0, passes)
    assert kind is KickPurpose.SHOT  # lining up behind the ball for it
    assert math.hypot(intent.x - ball.x, intent.y - ball.y) < 0.5 and intent.x < ball.x
