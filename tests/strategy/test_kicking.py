"""The attacker's kick decision and the contested ball, in constructed scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cmdragons.geometry import Field, LeagueParams
from cmdragons.messages import BallState, RobotState
from strategy.evaluation import PassParams
from strategy.kicking import (
    Attacker,
    Kick,
    KickParams,
    KickPurpose,
    StillBall,
    chase,
    contest_angle,
    decide_kick,
    forward_kick,
    kick_blocked,
)
from strategy.passing import PassPlay, PassPlayParams
from strategy.plays import StrategyParams
from strategy.skills import Intent, SkillParams, drive_through, pass_speed

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


@pytest.mark.parametrize(("ball_x", "hard"), [
    (-FIELD.half_length + K.clear_zone_m - 0.3, True),  # near our goal: cleared hard
    (-1.0, False),  # elsewhere: played only as far as its lane was checked, to stay in play
])
def test_no_pass_far_back_and_no_supporter_means_a_clear(ball_x: float, hard: bool) -> None:
    ball = BallState(ball_x, 0.0, 0.0, 0.0)
    own = {1: _robot(1, ball_x - 0.2, 0.0), 3: _robot(3, ball_x - K.max_back_pass_m - 0.5, 1.5)}  # behind the ball
    kick = _decide(ball, own, [3], NONE)
    assert kick.kind is KickPurpose.CLEAR
    assert math.hypot(kick.target[0] - ball.x, kick.target[1] - ball.y) == pytest.approx(K.clear_reach_m)
    assert kick.target[0] > ball.x  # forward, toward their goal
    if hard:
        assert kick.speed == K.clear_speed_m_s
    else:  # the ball model: it arrives at the lane's end no faster than asked (a kick of at least pass_min_m_s)
        assert kick.speed == pytest.approx(pass_speed(K.clear_reach_m, SKILLS, K.advance_arrival_m_s))
        assert kick.speed < K.clear_speed_m_s
        assert SKILLS.ball_model.speed_after(kick.speed, K.clear_reach_m) <= max(
            K.advance_arrival_m_s, SKILLS.ball_model.speed_after(SKILLS.pass_min_m_s, K.clear_reach_m)) + 1e-6


def test_a_ball_played_forward_stays_in_the_field() -> None:
    # by the touch line, the most open lane toward their goal runs along it: the target stays inside
    ball = BallState(0.0, FIELD.half_width - 0.15, 0.0, 0.0)
    kick = forward_kick(ball, math.pi / 2 - 0.3, FIELD, 1.0, K, SKILLS)
    assert kick.kind is KickPurpose.CLEAR
    assert abs(kick.target[1]) <= FIELD.half_width - K.advance_margin_m + 1e-9
    assert abs(kick.target[0]) <= FIELD.half_length - K.advance_margin_m + 1e-9


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
    angle = contest_angle(robot, ball, (FIELD.half_length, 0.0), np.array([opponent]), K, SKILLS)
    if not contested:
        assert angle is None
        return
    assert angle is not None
    approach = math.pi
    assert abs(math.remainder(angle - approach, 2 * math.pi)) == pytest.approx(K.contest_turn_rad)


def test_an_aim_within_the_turn_is_not_contested() -> None:
    ball = BallState(2.0, 0.5, 0.0, 0.0)
    robot = _robot(1, 1.8, 0.5)  # behind the ball on the way to their goal
    assert contest_angle(robot, ball, (FIELD.half_length, 0.5), np.array([[2.2, 0.6]]), K, SKILLS) is None


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
    # through the ball from its side, to stay in play (as a ball played forward in their half)
    assert after.kick_speed == forward_kick(ball, after.theta, FIELD, 1.0, K, SKILLS).speed and not after.avoid_ball
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


def test_a_kicking_position_taken_by_an_opponent_is_not_aimed_through() -> None:
    """An opponent's body beside the ball where ours must stand to kick it at the goal: the kick goes
    the nearest way whose kicking position is free, within the turn (lining up for the taken one got
    nowhere: the planner and the safety search keep the robot out of it)."""
    ball = BallState(2.0, 0.3, 0.0, 0.0)
    robot = _robot(1, 1.75, 0.3)  # behind the ball, the goal's centre within the turn
    opponents = np.array([[1.95, 0.13]])  # beside the ball, touching neither it nor our robot
    goal = (FIELD.half_length, 0.0)
    aim = math.atan2(goal[1] - ball.y, goal[0] - ball.x)
    assert kick_blocked(ball, aim, opponents, K, SKILLS)
    angle = contest_angle(robot, ball, goal, opponents, K, SKILLS)
    assert angle is not None and not kick_blocked(ball, angle, opponents, K, SKILLS)
    assert abs(math.remainder(angle, 2 * math.pi)) <= K.contest_turn_rad + 1e-9  # from the side we come from
    x, y = ball.x - SKILLS.contact_m * math.cos(angle), ball.y - SKILLS.contact_m * math.sin(angle)
    assert math.hypot(x - 1.95, y - 0.13) >= 2 * SKILLS.robot_radius_m + K.contest_gap_m
    # an opponent at the ball whose body leaves the kicking position free leaves the aim as it is
    assert contest_angle(robot, ball, goal, np.array([[2.05, 0.05]]), K, SKILLS) is None


def test_the_attacker_keeps_its_kick_while_driving_through_a_slow_ball() -> None:
    """Lined up and driving through, the kick (aim, speed, purpose) holds for ``commit_s`` though the
    decision would now be another; then it is decided afresh."""
    attacker, passes = _attacker(), PassPlay(PassPlayParams())
    ball = BallState(FIELD.half_length - 1.5, 0.0, 0.0, 0.0)
    robot = _robot(1, ball.x - SKILLS.contact_m - 0.02, 0.0)  # lined up for the open goal
    attacker.watch(0.0, ball)
    first, kind = attacker.play(0.0, robot, {1: robot}, [], NONE, ball, 1.0, passes)
    assert kind is KickPurpose.SHOT and not first.avoid_ball and first.kick_speed == SKILLS.max_kick_m_s
    wall = np.array([[FIELD.half_length - 0.25, y] for y in np.linspace(-0.6, 0.6, 7)])  # the goal now shut
    assert _decide(ball, {1: robot}, [], wall, passes).kind is not KickPurpose.SHOT
    t = K.commit_s * 0.8
    held, kind = attacker.play(t, robot, {1: robot}, [], wall, ball, 1.0, passes)
    assert kind is KickPurpose.SHOT and not held.avoid_ball
    assert held.theta == pytest.approx(first.theta) and held.kick_speed == first.kick_speed
    later, kind = attacker.play(K.commit_s * 1.5, robot, {1: robot}, [], wall, ball, 1.0, passes)
    assert kind is not KickPurpose.SHOT


@pytest.mark.parametrize(("ball_v", "faster"), [((0.6, 0.0), 0.6), ((-0.6, 0.0), 0.0), ((0.0, 0.6), 0.0)])
def test_a_ball_rolling_away_is_driven_through_at_the_push_speed_relative_to_it(
    ball_v: tuple[float, float], faster: float
) -> None:
    ball = BallState(1.0, 0.0, *ball_v)
    through = drive_through(RobotState("blue", 1, 0.9, 0.0, 0.0), ball, 0.0, 3.0, SKILLS)
    chased = chase(through, ball)
    assert chased.max_speed_m_s == pytest.approx(SKILLS.push_speed_m_s + faster)
    assert chased.final_speed_m_s == pytest.approx(SKILLS.push_speed_m_s + faster)
    assert (chased.x, chased.y, chased.theta, chased.kick_speed) == (through.x, through.y, through.theta, 3.0)
    lining_up = Intent(0.5, 0.0, 0.0)  # not driving through: as it is
    assert chase(lining_up, ball) == lining_up


@pytest.mark.parametrize(("outside_m", "played"), [
    (K.area_still_m + 0.01, True),  # by the line, outside: their keeper does not come out for it
    (-0.05, False),  # inside: theirs however long it lies
])
def test_a_ball_lying_by_their_defense_area_is_played_after_the_stall_time(outside_m: float, played: bool) -> None:
    assert K.area_still_m + 0.01 < K.area_margin_m  # within the margin: waited for at first
    attacker, passes = _attacker(), PassPlay(PassPlayParams())
    ball = BallState(FIELD.half_length - FIELD.dims.defense_depth_m - outside_m, 0.3, 0.0, 0.0)
    r = _robot(1, ball.x - 0.5, 0.3)
    attacker.watch(0.0, ball)
    _, kind = attacker.play(0.0, r, {1: r}, [], NONE, ball, 1.0, passes)
    assert kind is KickPurpose.WAIT
    attacker.watch(K.stall_s + 0.1, ball)
    _, kind = attacker.play(K.stall_s + 0.1, r, {1: r}, [], NONE, ball, 1.0, passes)
    assert (kind is not KickPurpose.WAIT) is played
